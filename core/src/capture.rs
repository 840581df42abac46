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
///
/// A contact longer than the buffer is not cut: once the buffer is full (a filter's lead-in
/// gives way first), [`Self::extend_decimating`] halves what it holds in place (the mean of
/// each pair) and goes on taking the mean of each 2, 4, 8 … samples, as often as needed, so
/// the buffer always holds the whole impact at the finest step that fits ([`Self::step`]);
/// value `k` holds the samples from stream index `held_from() + k step`.
pub struct Capture<const CAP: usize> {
    samples: [i16; CAP],
    /// Samples held (`<= self.capacity()`): stored values, each the mean of `step` samples.
    len: usize,
    /// The buffer's length in use: 0 for all `CAP` (a host's capture set to the board's).
    limit: usize,
    /// log2 of the step: each stored value is the mean of `1 << log2` consecutive samples.
    log2: u8,
    /// The sum and count of the group being gathered (fewer than `step` samples).
    pending_sum: i32,
    pending_n: u32,
    summary: Summary,
}

/// The coarsest step a capture goes to: 2^12 samples (1 s of a contact in 16 000 values at
/// 64 MS/s); an impact longer than that at that step fills it, as before decimation.
pub const MAX_DECIMATION_LOG2: u8 = 12;

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
            limit: 0,
            log2: 0,
            pending_sum: 0,
            pending_n: 0,
            summary: Summary::EMPTY,
        }
    }

    /// Uses only the first `len` samples of the buffer (at least 64, at most `CAP`): a host
    /// analysing with the board's capture length.
    pub fn set_capacity(&mut self, len: usize) {
        self.limit = Self::capacity_for(len);
        self.clear();
    }

    /// The length [`Self::set_capacity`] would use for `len`, without using it.
    pub fn capacity_for(len: usize) -> usize {
        len.clamp(64.min(CAP), CAP)
    }

    /// The buffer's length in use, samples.
    pub fn capacity(&self) -> usize {
        match self.limit {
            0 => CAP,
            n => n.min(CAP),
        }
    }

    /// Samples per stored value: 1, or the power of two the capture was decimated to.
    pub fn step(&self) -> u32 {
        1 << self.log2
    }

    /// The impact's window (valid once handed over): the raw samples from stream index
    /// `summary().first_index` to `summary().end_index`, as far as the buffer held them (each
    /// the mean of [`Self::step`] samples, from the value holding `first_index` on). Every
    /// unfiltered field is measured over these.
    pub fn samples(&self) -> &[i16] {
        let s = &self.summary;
        let lead = s.filter_lead as usize;
        let window =
            usize::try_from(s.end_index.saturating_sub(s.first_index)).unwrap_or(usize::MAX);
        let end = lead
            .saturating_add(window)
            .div_ceil(self.step() as usize)
            .min(self.len);
        self.samples.get(self.window_lead()..end).unwrap_or(&[])
    }

    /// The values of [`Self::held`] before [`Self::samples`] (the filter's lead-in, in values;
    /// valid once handed over).
    pub fn window_lead(&self) -> usize {
        self.summary.filter_lead as usize >> self.log2
    }

    /// Stream index of the first sample of [`Self::samples`]' first value (`first_index`, or
    /// up to a step before it on a decimated capture; valid once handed over).
    pub fn window_from(&self) -> u64 {
        self.held_from() + ((self.window_lead() as u64) << self.log2)
    }

    /// The stream time (a fractional sample index) value `k` of [`Self::held`] stands at: the
    /// middle of its group of [`Self::step`] samples (valid once handed over).
    pub fn value_time(&self, k: f64) -> f64 {
        let step = f64::from(self.step());
        self.held_from() as f64 + k * step + (step - 1.0) / 2.0
    }

    /// Stream index of the first sample held (valid once handed over): the window's first
    /// less the filter's lead-in.
    pub fn held_from(&self) -> u64 {
        let s = &self.summary;
        s.first_index.saturating_sub(u64::from(s.filter_lead))
    }

    /// The value of [`Self::held`] that holds stream index `i`, if held (valid once handed
    /// over).
    pub fn value_at(&self, i: u64) -> Option<usize> {
        let k = usize::try_from(i.checked_sub(self.held_from())? >> self.log2).ok()?;
        (k < self.len).then_some(k)
    }

    /// The value of [`Self::samples`] that holds stream index `i`, if held.
    pub fn window_value_at(&self, i: u64) -> Option<usize> {
        self.value_at(i)?.checked_sub(self.window_lead())
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

    /// True if the buffer holds as many values as it can at its step (only
    /// [`Self::extend_decimating`] takes more, at a coarser one).
    pub fn is_full(&self) -> bool {
        self.len >= self.capacity()
    }

    pub(crate) fn clear(&mut self) {
        self.len = 0;
        self.log2 = 0;
        self.pending_sum = 0;
        self.pending_n = 0;
    }

    /// Appends what fits at the step the capture holds (a decimated capture takes groups,
    /// but never halves here); returns how many samples did.
    pub(crate) fn extend(&mut self, samples: &[i16]) -> usize {
        if self.log2 > 0 {
            return self.extend_grouped(samples, false);
        }
        let cap = self.capacity();
        let free = self.samples.get_mut(self.len..cap).unwrap_or(&mut []);
        let fits = free.len().min(samples.len());
        crate::signal::copy::copy_samples(free, samples);
        self.len += fits;
        fits
    }

    /// Appends every sample, halving what the buffer holds whenever it is full (up to
    /// [`MAX_DECIMATION_LOG2`]); returns how many samples it took.
    pub(crate) fn extend_decimating(&mut self, samples: &[i16]) -> usize {
        if self.log2 > 0 {
            return self.extend_grouped(samples, true);
        }
        let took = self.extend(samples);
        let rest = samples.get(took..).unwrap_or(&[]);
        took + self.extend_grouped(rest, true)
    }

    /// Appends samples as groups of [`Self::step`] (halving what the buffer holds when full
    /// if `halve`); returns how many it took.
    fn extend_grouped(&mut self, samples: &[i16], halve: bool) -> usize {
        let mut rest = samples;
        let cap = self.capacity();
        while !rest.is_empty() {
            if self.len >= cap {
                if !halve || self.log2 >= MAX_DECIMATION_LOG2 || !self.halve() {
                    break;
                }
                continue;
            }
            let step = self.step();
            // The group being gathered: the next samples up to a whole step.
            let n = ((step - self.pending_n) as usize).min(rest.len());
            let (group, after) = rest.split_at(n);
            self.pending_sum += group.iter().map(|&x| i32::from(x)).sum::<i32>();
            self.pending_n += n as u32;
            rest = after;
            if self.pending_n == step {
                let mean = rounded_shift(self.pending_sum, self.log2);
                if let Some(slot) = self.samples.get_mut(self.len) {
                    *slot = mean;
                }
                self.len += 1;
                self.pending_sum = 0;
                self.pending_n = 0;
            }
        }
        samples.len() - rest.len()
    }

    /// Doubles the step in place: each pair of values becomes its mean (rounded to the
    /// nearest, ties to even: no drift); an odd last value becomes the group being gathered.
    /// False if the buffer holds too few values.
    fn halve(&mut self) -> bool {
        if self.len < 2 {
            return false;
        }
        let pairs = self.len / 2;
        for k in 0..pairs {
            let a = self.samples.get(2 * k).map_or(0, |&x| i32::from(x));
            let b = self.samples.get(2 * k + 1).map_or(0, |&x| i32::from(x));
            if let Some(slot) = self.samples.get_mut(k) {
                *slot = rounded_shift(a + b, 1);
            }
        }
        let odd = self
            .samples
            .get(2 * pairs)
            .copied()
            .filter(|_| self.len % 2 == 1);
        // The group being gathered was a part of a value at the old step.
        let old_step = self.step() as i32;
        self.log2 += 1;
        self.len = pairs;
        if let Some(x) = odd {
            self.pending_sum += i32::from(x) * old_step;
            self.pending_n += old_step as u32;
        }
        true
    }

    /// Drops the first `n` samples held (a filter's lead-in that would crowd out the window;
    /// before any decimation).
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

/// `sum / 2^log2` rounded to the nearest, ties to even (no drift on any data), in i16
/// (`log2 <= MAX_DECIMATION_LOG2`: the mean of i16 samples).
fn rounded_shift(sum: i32, log2: u8) -> i16 {
    let q = sum >> log2;
    let r = sum - (q << log2);
    let half = (1i32 << log2) >> 1;
    let up = log2 > 0 && (r > half || (r == half && q & 1 == 1));
    (q + i32::from(up)).clamp(i16::MIN as i32, i16::MAX as i32) as i16
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

    /// The mean of each `step` samples of `x` from its first, rounded as the capture rounds
    /// a fresh group (half up).
    fn means(x: &[i16], step: usize) -> impl Iterator<Item = f64> + '_ {
        x.chunks_exact(step)
            .map(move |g| g.iter().map(|&v| f64::from(v)).sum::<f64>() / step as f64)
    }

    #[test]
    fn a_capture_that_overflows_holds_everything_at_the_finest_step_that_fits() {
        let mut x = [0i16; 1000];
        for (i, v) in x.iter_mut().enumerate() {
            *v = ((i * 37) % 211) as i16 - 100;
        }
        let mut c = Capture::<256>::new();
        // In uneven parts, as the stream hands them over.
        let mut taken = 0;
        for part in x.chunks(77) {
            taken += c.extend_decimating(part);
        }
        assert_eq!(taken, x.len());
        // 1000 samples in 256 values: a step of 4 (250 values).
        assert_eq!(c.step(), 4);
        assert_eq!(c.held().len(), 250);
        assert!(!c.is_full());
        // Each value is its group's mean within a count per halving (the rounding).
        for (k, (&v, m)) in c.held().iter().zip(means(&x, 4)).enumerate() {
            assert!((f64::from(v) - m).abs() <= 1.0, "value {k}: {v} for {m}");
        }
        // The rounding has no drift: the values' sum is the samples' within a few counts.
        let sum: f64 = c.held().iter().map(|&v| f64::from(v) * 4.0).sum();
        let exact: f64 = x.iter().map(|&v| f64::from(v)).sum();
        assert!((sum - exact).abs() <= 4.0 * 16.0, "{sum} vs {exact}");
    }

    #[test]
    fn an_undecimated_capture_stops_where_it_is_full() {
        let mut c = Capture::<128>::new();
        assert_eq!(c.extend(&[1; 200]), 128);
        assert!(c.is_full());
        assert_eq!(c.step(), 1);
        // Cleared, it starts again at every sample.
        c.clear();
        assert_eq!(c.extend_decimating(&[3; 300]), 300);
        assert_eq!((c.step(), c.held().len()), (4, 75));
        assert!(c.held().iter().all(|&v| v == 3));
        // Once decimated, a plain extend goes on at its step, but never halves.
        assert_eq!(c.extend(&[3; 100]), 100);
        assert_eq!((c.step(), c.held().len()), (4, 100));
        assert_eq!(c.extend(&[3; 200]), 112);
        assert!(c.is_full() && c.step() == 4);
    }

    #[test]
    fn a_capacity_below_the_buffer_decimates_at_its_length() {
        let mut c = Capture::<1024>::new();
        c.set_capacity(100);
        assert_eq!(c.capacity(), 100);
        c.extend_decimating(&[7; 1000]);
        assert_eq!((c.step(), c.held().len()), (16, 62));
        // Extremes do not wrap.
        c.clear();
        c.extend_decimating(&[i16::MAX; 1000]);
        c.extend_decimating(&[i16::MIN; 1000]);
        assert!(c.held().first() == Some(&i16::MAX) && c.held().last() == Some(&i16::MIN));
    }

    #[test]
    fn the_coarsest_step_fills() {
        let mut c = Capture::<64>::new();
        let chunk = [5i16; 4096];
        let mut taken = 0;
        for _ in 0..(64 << MAX_DECIMATION_LOG2) / chunk.len() + 8 {
            taken += c.extend_decimating(&chunk);
        }
        assert_eq!(c.step(), 1 << MAX_DECIMATION_LOG2);
        assert!(c.is_full());
        assert_eq!(taken, 64 << MAX_DECIMATION_LOG2);
    }
}
