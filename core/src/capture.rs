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
    pub bounce: BounceSlot,
}

/// A summary's bounce, all zeros when the impact continues no train: `Option<Bounce>` keeps
/// `None` in a non-zero tag (the niche of its `Option<f32>`), which would put every static
/// capture in `.data` (its image in flash, copied at start-up) instead of `.bss`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BounceSlot {
    /// The bounce's number (1 for the first bounce after the train's first impact); 0 for no
    /// bounce.
    number: u32,
    flight_s: f32,
    v0_flight_m_s: f32,
    v0_rebound_m_s: f32,
    has_rebound: bool,
}

impl BounceSlot {
    /// No bounce.
    pub const NONE: Self = Self {
        number: 0,
        flight_s: 0.0,
        v0_flight_m_s: 0.0,
        v0_rebound_m_s: 0.0,
        has_rebound: false,
    };

    /// The bounce kept (a bounce's number is at least 1).
    pub fn get(&self) -> Option<Bounce> {
        (self.number > 0).then_some(Bounce {
            number: self.number,
            flight_s: self.flight_s,
            v0_flight_m_s: self.v0_flight_m_s,
            v0_rebound_m_s: self.has_rebound.then_some(self.v0_rebound_m_s),
        })
    }
}

impl From<Option<Bounce>> for BounceSlot {
    fn from(b: Option<Bounce>) -> Self {
        match b {
            Some(b) => Self {
                number: b.number.max(1),
                flight_s: b.flight_s,
                v0_flight_m_s: b.v0_flight_m_s,
                v0_rebound_m_s: b.v0_rebound_m_s.unwrap_or(0.0),
                has_rebound: b.v0_rebound_m_s.is_some(),
            },
            None => Self::NONE,
        }
    }
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
        bounce: BounceSlot::NONE,
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_empty_summary_has_no_bounce_and_a_bounce_survives_the_slot() {
        // NONE is the all-zero value (Default): an empty capture is all zeros, so its statics
        // go to `.bss` (the firmware's memory check reads it off the ELF).
        assert_eq!(BounceSlot::NONE, BounceSlot::default());
        assert_eq!(Capture::<64>::new().summary.bounce.get(), None);
        let b = Bounce {
            number: 3,
            flight_s: 0.1,
            v0_flight_m_s: 0.5,
            v0_rebound_m_s: None,
        };
        assert_eq!(BounceSlot::from(Some(b)).get(), Some(b));
        let b = Bounce {
            v0_rebound_m_s: Some(0.4),
            ..b
        };
        assert_eq!(BounceSlot::from(Some(b)).get(), Some(b));
        assert_eq!(BounceSlot::from(None), BounceSlot::NONE);
    }
}
