//! The hand-off from the streaming stage to the per-impact analysis: one impact's raw samples
//! and everything the streaming stage learned about them.
//!
//! The streaming stage ([`crate::stream::Stream`]) asks a [`Sink`] for a free [`Capture`] when
//! an impact starts, fills it as the samples come, and hands it over when the impact ends. A
//! sink with no free buffer (every one waiting for or in analysis) is not an error: the
//! impact is still followed to its end and reported from the streaming fields alone.

use crate::report::{ImpactReport, Status};
use crate::scene::Scene;
use crate::train::Bounce;

/// What the streaming stage knows of one impact when it ends: positions, and exact integer
/// sums of the baseline-removed raw counts `d = W x - S` (`S / W` is the frozen baseline).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Summary {
    /// 0 for the stream's first impact.
    pub index: u32,
    pub status: Status,
    /// A sample reached the scene's rails.
    pub clipped: bool,
    /// Stream index of the capture's first sample (the pre-trigger margin before the onset).
    pub first_index: u64,
    /// Stream index of the first sample beyond the edge level.
    pub onset_index: u64,
    /// First touch relative to `onset_index`, samples (≤ 0): the rising flank extrapolated to
    /// zero, or the edge crossing.
    pub touch_offset: f32,
    /// Stream index of the first sample back within the edge level after the peak, if any.
    pub separation_index: Option<u64>,
    /// Separation relative to `separation_index`, samples (the falling flank extrapolated to
    /// zero, or the edge crossing; between -1 and a few samples).
    pub separation_offset: f32,
    /// Stream index just after the impact's last sample (the end of the hold, or the cut).
    pub end_index: u64,
    /// Baseline as the rational `base_sum / base_n` counts.
    pub base_sum: i64,
    pub base_n: i64,
    /// The first largest `|d|` and its stream index.
    pub peak_d: i64,
    pub peak_index: u64,
    /// `Σ d` over the whole impact (also beyond a full capture), in `W · counts`.
    pub total_c: i64,
    /// `Σ d` over the contact, from the onset to the separation (exclusive), if the signal
    /// came back.
    pub contact_c: Option<i64>,
    /// The approach speed of this impact, m/s: the scene's (or a light gate's), or, in a
    /// bounce train, the bounce's ([`crate::train`]).
    pub v0_m_s: Option<f32>,
    /// The impact continues a bounce train: both measures of its approach speed.
    pub bounce: Option<Bounce>,
}

impl Summary {
    /// A placeholder (all zero).
    pub const EMPTY: Self = Self {
        index: 0,
        status: Status::Complete,
        clipped: false,
        first_index: 0,
        onset_index: 0,
        touch_offset: 0.0,
        separation_index: None,
        separation_offset: 0.0,
        end_index: 0,
        base_sum: 0,
        base_n: 0,
        peak_d: 0,
        peak_index: 0,
        total_c: 0,
        contact_c: None,
        v0_m_s: None,
        bounce: None,
    };
}

/// One impact's raw samples (up to `CAP` of them, from the pre-trigger margin on) and its
/// [`Summary`]. `Capture::new()` is all zeros, so a `static` of captures starts in `.bss`.
pub struct Capture<const CAP: usize> {
    samples: [i16; CAP],
    /// Samples held (`<= CAP`).
    len: usize,
    summary: Summary,
}

impl<const CAP: usize> Default for Capture<CAP> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const CAP: usize> Capture<CAP> {
    /// An empty capture.
    pub const fn new() -> Self {
        Self {
            samples: [0; CAP],
            len: 0,
            summary: Summary::EMPTY,
        }
    }

    /// The raw samples, from stream index `summary().first_index` on.
    pub fn samples(&self) -> &[i16] {
        self.samples.get(..self.len).unwrap_or(&[])
    }

    /// What the streaming stage measured (valid once the capture has been handed over).
    pub fn summary(&self) -> &Summary {
        &self.summary
    }

    /// True if the impact had more samples than the buffer holds.
    pub fn is_full(&self) -> bool {
        self.len >= CAP
    }

    pub(crate) fn clear(&mut self) {
        self.len = 0;
    }

    /// Appends what fits; returns how many samples did.
    pub(crate) fn extend(&mut self, samples: &[i16]) -> usize {
        let free = self.samples.get_mut(self.len..).unwrap_or(&mut []);
        let fits = free.len().min(samples.len());
        crate::signal::copy::copy_samples(free, samples);
        self.len += fits;
        fits
    }

    pub(crate) fn set_summary(&mut self, summary: Summary) {
        self.summary = summary;
    }
}

/// Where the streaming stage gets capture buffers and hands over finished impacts.
///
/// On the host the sink analyses each capture at once ([`crate::Monitor`]); on the firmware
/// the buffers are the slots of a queue to a lower-priority analysis task, and an impact that
/// finds every slot busy is reported from its streaming fields alone.
pub trait Sink<const CAP: usize> {
    /// The buffer the impact starting now is captured into, `None` if none is free. Called
    /// again while the impact goes on, it must return the same buffer until
    /// [`Self::captured`].
    fn buffer(&mut self) -> Option<&mut Capture<CAP>>;
    /// The impact in [`Self::buffer`] is over; its summary is in it.
    fn captured(&mut self, scene: &Scene);
    /// An impact without a buffer is over: its report has the streaming fields only
    /// (`analysis: skipped`).
    fn skipped(&mut self, report: &ImpactReport);
}
