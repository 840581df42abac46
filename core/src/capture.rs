//! The hand-off from the streaming stage to the per-impact analysis: one impact's raw samples
//! and everything the streaming stage learned about them.
//!
//! The streaming stage ([`crate::stream::Stream`]) asks a [`Sink`] for a free [`Capture`] when
//! an impact starts, fills it as the samples come, and hands it over when the impact ends. A
//! sink with no free buffer (every one waiting for or in analysis) is not an error: the
//! impact is still followed to its end and reported from the streaming fields alone.

pub use crate::report::summary::Summary;
use crate::report::ImpactReport;
use crate::scene::Scene;

/// One impact's raw samples (up to `CAP` of them, from the pre-trigger margin on, with a CFC
/// also the filter's lead-in before it and its tail after the window) and its [`Summary`]. `Capture::new()` is all zeros, so a `static` of captures starts in `.bss`.
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

    /// The impact's window (valid once handed over): the raw samples from stream index
    /// `summary().first_index` to `summary().end_index`, as far as the buffer held them.
    /// Every unfiltered field is measured over these.
    pub fn samples(&self) -> &[i16] {
        let s = &self.summary;
        let lead = s.filter_lead as usize;
        let window =
            usize::try_from(s.end_index.saturating_sub(s.first_index)).unwrap_or(usize::MAX);
        let end = lead.saturating_add(window).min(self.len);
        self.samples.get(lead..end).unwrap_or(&[])
    }

    /// Every sample held: the filter's lead-in (`summary().filter_lead` samples), the window
    /// and the filter's tail after it, from stream index `first_index - filter_lead` on.
    pub fn held(&self) -> &[i16] {
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

    /// Drops the first `n` samples held (a filter's lead-in that would crowd out the window).
    pub(crate) fn drop_front(&mut self, n: usize) {
        let held = self.samples.get_mut(..self.len).unwrap_or(&mut []);
        let n = n.min(held.len());
        // (Written with `get` so the board's build keeps no panic path; rare: once an impact.)
        for i in n..held.len() {
            if let Some(x) = held.get(i).copied() {
                if let Some(slot) = held.get_mut(i - n) {
                    *slot = x;
                }
            }
        }
        self.len -= n;
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
