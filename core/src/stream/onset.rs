//! What fired the trigger: a pulse, measured from the level just before it, or the signal
//! creeping past the trigger level (drift), which moves the baseline instead.

use super::{Stream, REACH};
use crate::capture::Sink;
use crate::signal::baseline::{Stats, STRIDE};

/// What fired the trigger ([`Stream::onset`]).
pub(super) enum Onset {
    /// A pulse, from the baseline or from the level (`(Σx, n)` of raw counts) the signal
    /// settled at since.
    Pulse(Option<(i64, i64)>),
    /// No pulse: the level (`(Σx, n)`) the baseline moves to.
    Moved((i64, i64)),
}

impl<const PRE: usize> Stream<PRE> {
    /// The steady level just before the pulse, if the signal moved away from the baseline
    /// since it was learned (a step below the trigger, an orientation change, drift): walking
    /// back from the trigger past the pulse's rise (the strides that are not flat), a run of
    /// flat strides (each spanning at most twice the edge level) within the edge level of one
    /// another, beyond the edge level from the baseline, lasting at least the settle time (and
    /// one stride). `(Σx, n)` over the run, as the baseline's rational; `None` for no such
    /// run within the flanks' reach.
    pub(super) fn level_before(&self) -> Option<(i64, i64)> {
        let edge = self.edge_counts;
        let mean = self.baseline.mean();
        // Stride `k` back from the newest sample: Σx, least and greatest sample.
        let stride = |k: usize| -> Option<(i32, i16, i16)> {
            let reach = (k + 1) * STRIDE;
            if reach > REACH.min(self.ring.len()) {
                return None;
            }
            let (older, newer) = self.ring.last(reach);
            let (runs, _) = crate::signal::ring::split_runs(older, newer, STRIDE);
            let (a, b) = (Stats::of(runs[0]), Stats::of(runs[1]));
            Some((a.sum + b.sum, a.min.min(b.min), a.max.max(b.max)))
        };
        let flat = |(_, min, max): (i32, i16, i16)| (max as f32 - min as f32) <= 2.0 * edge;
        let level = |(sum, _, _): (i32, i16, i16)| sum as f32 / STRIDE as f32;
        let mut k = 0;
        let first = loop {
            let st = stride(k)?;
            if flat(st) {
                break st;
            }
            k += 1;
        };
        let at = level(first);
        if libm::fabsf(at - mean) <= 2.0 * edge {
            return None;
        }
        let (mut sum, mut n) = (0i64, 0i64);
        let mut varies = false;
        while let Some(st) = stride(k).filter(|&st| flat(st) && libm::fabsf(level(st) - at) <= edge)
        {
            sum += i64::from(st.0);
            n += STRIDE as i64;
            varies |= st.2 > st.1;
            k += 1;
        }
        (varies && n >= i64::from(self.settle).max(STRIDE as i64)).then_some((sum, n))
    }

    /// What fired the trigger at sample `x` (the next one): a pulse, measured from the baseline
    /// or from the level the signal settled at since ([`Self::level_before`]); or no pulse,
    /// and the level the baseline moves to. No pulse when the signal crept past the trigger
    /// level instead of rising through it (it left the edge level on the trigger's side more
    /// than half the settle time before, or since the stream began: drift, an orientation
    /// change, a sensor warming; a pulse rises from the edge level to the trigger level
    /// faster), or when `x` is no further than the trigger level from the level the signal
    /// settled at.
    pub(super) fn onset(&self, x: i16) -> Onset {
        let level = self.level_before();
        let last_stride = || {
            let sum: i64 = (0..STRIDE)
                .map(|i| self.ring.back(i).map_or(0, i64::from))
                .sum();
            (sum, STRIDE as i64)
        };
        if let Some((sum, n)) = level {
            let from_level = x as f32 - sum as f32 / n as f32;
            if libm::fabsf(from_level) <= self.trigger_counts {
                return Onset::Moved((sum, n));
            }
        }
        let window = (self.settle as usize / 2)
            .clamp(2, REACH)
            .min(self.ring.len());
        let mean = self.baseline.mean();
        let edge = self.edge_counts;
        let above = x as f32 > mean;
        let crept = window >= 2
            && self.ring.len() >= STRIDE
            && (0..window).all(|i| {
                self.ring.back(i).is_some_and(|y| {
                    if above {
                        y as f32 > mean + edge
                    } else {
                        (y as f32) < mean - edge
                    }
                })
            });
        if crept {
            Onset::Moved(level.unwrap_or_else(last_stride))
        } else {
            Onset::Pulse(level)
        }
    }

    /// A pulse fired the trigger at `x`: from the level the signal settled at since the
    /// baseline was learned, if it did (the baseline moves there first), else from the
    /// baseline.
    pub(super) fn pulse<const CAP: usize>(
        &mut self,
        sink: &mut impl Sink<CAP>,
        x: i16,
        level: Option<(i64, i64)>,
    ) {
        if let Some((sum, n)) = level {
            self.move_baseline(sum, n);
        }
        let moved = core::mem::take(&mut self.moved);
        self.start(sink, x, moved);
    }

    /// The baseline moves to the level `sum / n` (a level change without a pulse).
    #[cold]
    pub(super) fn move_baseline(&mut self, sum: i64, n: i64) {
        self.baseline.restart_at(sum, n);
        self.thresholds = None;
        self.counters.level_changes += 1;
        self.moved = true;
        let level = self.baseline.mean() as f64;
        if let Some(f) = self.trigger_filter.as_mut() {
            f.reset(level);
        }
    }
}
