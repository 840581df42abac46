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
    /// The stride being accumulated: Σx, min, max, samples.
    sum: i64,
    min: i16,
    max: i16,
    filled: usize,
    /// The current run of flat strides at one level: Σd over it and its length (samples),
    /// and whether any of its strides varied at all.
    run_d: i64,
    run_n: u64,
    run_varies: bool,
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

impl LevelWatch {
    pub(super) fn new() -> Self {
        Self {
            sum: 0,
            min: i16::MAX,
            max: i16::MIN,
            filled: 0,
            run_d: 0,
            run_n: 0,
            run_varies: false,
        }
    }

    /// Samples still missing to complete the current stride.
    pub(super) fn to_stride_end(&self) -> usize {
        STRIDE - self.filled
    }

    /// Adds samples (at most [`Self::to_stride_end`]); when that completes a stride, returns
    /// the settled level if the run of flat strides at one level beyond the edge level from
    /// the baseline now holds at least `settle` samples. `w` and `s` give `d = w x - s`;
    /// `edge_counts` is the edge level in raw counts; `rails` the scene's clip counts.
    pub(super) fn add(
        &mut self,
        samples: &[i16],
        w: i64,
        s: i64,
        edge_counts: f32,
        rails: (i16, i16),
        settle: u64,
    ) -> Option<Settled> {
        let st = Stats::of(samples);
        self.sum += i64::from(st.sum);
        self.min = self.min.min(st.min);
        self.max = self.max.max(st.max);
        self.filled += st.len;
        if self.filled < STRIDE {
            return None;
        }
        let n = self.filled as i64;
        let stride_d = w * self.sum - n * s;
        let flat = (self.max as f32 - self.min as f32) <= 2.0 * edge_counts
            && self.min > rails.0
            && self.max < rails.1;
        let varies = self.max > self.min;
        let edge_d = edge_counts as f64 * w as f64;
        let mean_d = stride_d as f64 / n as f64;
        let beyond = libm::fabs(mean_d) > edge_d;
        let at_run_level =
            self.run_n == 0 || libm::fabs(mean_d - self.run_d as f64 / self.run_n as f64) <= edge_d;
        if flat && beyond && at_run_level {
            self.run_d += stride_d;
            self.run_n += n as u64;
            self.run_varies |= varies;
        } else if flat && beyond {
            self.run_d = stride_d;
            self.run_n = n as u64;
            self.run_varies = varies;
        } else {
            self.run_d = 0;
            self.run_n = 0;
            self.run_varies = false;
        }
        self.sum = 0;
        self.min = i16::MAX;
        self.max = i16::MIN;
        self.filled = 0;
        (self.run_varies && self.run_n >= settle.max(STRIDE as u64)).then(|| Settled {
            level_d: self.run_d as f64 / self.run_n as f64,
            run_d: self.run_d,
            run_n: self.run_n,
        })
    }
}
