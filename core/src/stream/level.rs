//! Whether the signal inside an impact has settled at a new level: a run of strides, each flat
//! (every sample within the edge level of the stride's own mean), all at the same level, and
//! that level beyond the edge level from the baseline. A free fall seen by a DC accelerometer
//! (1 g to 0 g), a body coming to rest after its last bounce (0 g to 1 g), a tumbling recorder
//! settling on another face: none of these is an impact, and none comes back to the old
//! baseline, so without this the stream would call them one long impact. A level at a rail,
//! or one without any noise, is not a level change but a disconnected or stuck sensor: those
//! runs do not count (the impact goes on, to `too-long`).

use crate::signal::baseline::{Stats, STRIDE};

/// The strides of one impact, aligned to stream positions (from the trigger sample on), so
/// that any split of the stream into blocks sees the same strides.
#[derive(Clone, Debug, Default)]
pub(super) struct LevelWatch {
    /// The thresholds, fixed for the impact (see [`LevelWatch::new`]).
    limits: Limits,
    /// The stride being accumulated: Σx, min, max, samples.
    sum: i64,
    min: i16,
    max: i16,
    filled: usize,
    /// The current run of flat strides at one level: Σd over it and its length (strides),
    /// and whether any of its strides varied at all.
    run_d: i64,
    run_strides: u64,
    run_varies: bool,
}

/// A level watch's thresholds, in integers so the per-stride test needs no float.
#[derive(Clone, Copy, Debug, Default)]
struct Limits {
    /// `d = w x - s`.
    w: i64,
    s: i64,
    /// A flat stride spans at most this many counts (twice the edge level).
    flat_span: i32,
    /// A stride's Σd beyond this is beyond the edge level from the baseline (the edge level
    /// times `w` times the stride length).
    edge_stride_d: i64,
    /// The rails (scene clip counts): a stride touching one is not flat.
    rails: (i16, i16),
    /// Strides the run must hold.
    settle_strides: u64,
}

/// What a completed stride says.
pub(super) struct Settled {
    /// The new level, in units of `d = W x - S`.
    pub level_d: f64,
    /// Σd over the flat run (from its first sample to now).
    pub run_d: i64,
    /// Samples in the flat run.
    pub run_n: u64,
}

/// What [`LevelWatch::scan`] found.
pub(super) struct Scan {
    /// Samples taken: all, or up to the end of the stride that settled.
    pub used: usize,
    /// The settled level, if a stride completed the run.
    pub settled: Option<Settled>,
    /// Least and greatest raw sample taken.
    pub min: i16,
    pub max: i16,
}

impl LevelWatch {
    /// A watch for an impact measured from `d = w x - s`, with the edge level in raw counts,
    /// the scene's rails (clip counts) and the settle time in samples.
    pub(super) fn new(w: i64, s: i64, edge_counts: f32, rails: (i16, i16), settle: u64) -> Self {
        // `max - min <= 2 e` for integers is `max - min <= floor(2 e)`.
        let flat_span = libm::floorf(2.0 * edge_counts).clamp(0.0, i32::MAX as f32) as i32;
        let edge_stride_d = libm::floor(edge_counts as f64 * w as f64 * STRIDE as f64)
            .clamp(0.0, i64::MAX as f64) as i64;
        Self {
            limits: Limits {
                w,
                s,
                flat_span,
                edge_stride_d,
                rails,
                settle_strides: settle.div_ceil(STRIDE as u64).max(1),
            },
            sum: 0,
            min: i16::MAX,
            max: i16::MIN,
            filled: 0,
            run_d: 0,
            run_strides: 0,
            run_varies: false,
        }
    }

    /// Takes samples a stride at a time until the run of flat strides at one level beyond
    /// the edge level from the baseline holds the settle time (then stops at the end of that
    /// stride) or the samples run out.
    pub(super) fn scan(&mut self, samples: &[i16]) -> Scan {
        let mut used = 0;
        let (mut min, mut max) = (i16::MAX, i16::MIN);
        while used < samples.len() {
            let n = (STRIDE - self.filled).min(samples.len() - used);
            let st = Stats::of(samples.get(used..used + n).unwrap_or(&[]));
            used += n;
            min = min.min(st.min);
            max = max.max(st.max);
            self.sum += i64::from(st.sum);
            self.min = self.min.min(st.min);
            self.max = self.max.max(st.max);
            self.filled += n;
            if self.filled >= STRIDE {
                if let Some(settled) = self.stride_done() {
                    return Scan {
                        used,
                        settled: Some(settled),
                        min,
                        max,
                    };
                }
            }
        }
        Scan {
            used,
            settled: None,
            min,
            max,
        }
    }

    /// A stride is complete: extend, restart or drop the run; the settled level if the run
    /// now holds the settle time.
    fn stride_done(&mut self) -> Option<Settled> {
        let l = self.limits;
        let stride_d = l.w.saturating_mul(self.sum) - (STRIDE as i64).saturating_mul(l.s);
        let flat = i32::from(self.max) - i32::from(self.min) <= l.flat_span
            && self.min > l.rails.0
            && self.max < l.rails.1;
        let varies = self.max > self.min;
        self.sum = 0;
        self.min = i16::MAX;
        self.max = i16::MIN;
        self.filled = 0;
        if !(flat && stride_d.saturating_abs() > l.edge_stride_d) {
            self.run_d = 0;
            self.run_strides = 0;
            self.run_varies = false;
            return None;
        }
        // At the run's level: |stride_d - run_d / m| <= edge, times m (m strides in the run).
        let m = self.run_strides as i64;
        let at_run_level = m == 0
            || stride_d
                .saturating_mul(m)
                .saturating_sub(self.run_d)
                .saturating_abs()
                <= l.edge_stride_d.saturating_mul(m);
        if at_run_level {
            self.run_d = self.run_d.saturating_add(stride_d);
            self.run_strides += 1;
            self.run_varies |= varies;
        } else {
            self.run_d = stride_d;
            self.run_strides = 1;
            self.run_varies = varies;
        }
        let run_n = self.run_strides * STRIDE as u64;
        (self.run_varies && self.run_strides >= l.settle_strides).then(|| Settled {
            level_d: self.run_d as f64 / run_n as f64,
            run_d: self.run_d,
            run_n,
        })
    }
}
