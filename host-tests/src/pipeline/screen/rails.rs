//! Clipped stretches: the sensor's rails, from its range ([`from_range`]) or from flat tops
//! found a block at a time ([`FlatTops`]), so that a reading driven past the range does not
//! pass for a peak.

use crate::report::Clipping;

/// A reading within this fraction of the full scale counts as at the rail: 1 %, where a
/// sensor's output rails with noise on it (a phone's accelerometer declared ±16 g rails at
/// 156.86 m/s², its neighbours up to 1 % lower).
pub const RAIL_FRACTION: f64 = 0.99;

/// Clipping levels from the sensor's full scale, m/s² (readings at ±[`RAIL_FRACTION`] of it
/// and beyond are at the rail).
pub fn from_range(full_scale_m_s2: f64) -> Clipping {
    Clipping {
        low_m_s2: Some(-RAIL_FRACTION * full_scale_m_s2),
        high_m_s2: Some(RAIL_FRACTION * full_scale_m_s2),
        from: "range".into(),
    }
}

/// Flat tops by their shape alone: a run of at least three equal readings at the
/// recording's maximum (or minimum), entered or left at a slope no smooth peak has at its top
/// ([`FlatTops`] over the whole slice; the survey also wants them beyond the noise floor).
pub fn flat_tops(x: &[f64]) -> Option<Clipping> {
    let mut f = FlatTops::default();
    f.push(x);
    f.finish()
}

/// The steepest entry or exit (over one or two samples) of the runs of equal readings at one
/// level: runs of 8 and more, and each length from 3 to 7.
#[derive(Clone, Copy, Debug)]
pub(super) struct RunsAt {
    level: f64,
    long: f64,
    short: [f64; 5],
}

impl RunsAt {
    fn new(level: f64) -> Self {
        Self {
            level,
            long: f64::NEG_INFINITY,
            short: [f64::NEG_INFINITY; 5],
        }
    }

    /// Whether a run here is clipped at the recording's resolution `q`.
    fn clipped(&self, q: f64) -> bool {
        // A run of `len` is clipped when its slope is at least 2q and 16q / len (the first
        // for 8 and more, where 16q / len <= 2q holds exactly).
        self.long >= 2.0 * q
            || self
                .short
                .iter()
                .enumerate()
                .any(|(k, &slope)| slope >= 2.0 * q && slope >= 16.0 * q / (k + 3) as f64)
    }
}

/// A run of equal readings being read: its level, length and entry slope.
#[derive(Clone, Copy, Debug)]
pub(super) struct Run {
    level: f64,
    len: u64,
    entry: f64,
}

/// Flat tops in a stream read a block at a time, in constant memory.
///
/// With `q` the recording's resolution (its smallest non-zero step) and `L` a run's length,
/// a smooth peak quantised by `q` holds its top for `L` samples only if it arrives there with
/// a slope of about `4 q / L`; a clipped pulse arrives with its full slope. So a run of at
/// least three equal readings at the recording's maximum (or minimum) counts as clipped when
/// the steeper of its entry and exit (over one or two samples) is at least `16 q / L` and at
/// least `2 q`.
pub struct FlatTops {
    /// The two readings before the current one.
    prev: [Option<f64>; 2],
    q: f64,
    high: Option<RunsAt>,
    low: Option<RunsAt>,
    run: Option<Run>,
    /// A run that has ended, with the exit step to its first next reading, waiting for the
    /// second.
    ended: Option<(Run, f64)>,
    /// The first [`STEP_SAMPLE`] non-zero steps, to tell whether the smallest is the
    /// recording's quantum ([`FlatTops::quantum`]).
    steps: Vec<f64>,
}

/// Non-zero steps kept to check the resolution against.
const STEP_SAMPLE: usize = 4096;

impl Default for FlatTops {
    fn default() -> Self {
        Self {
            prev: [None; 2],
            q: f64::INFINITY,
            high: None,
            low: None,
            run: None,
            ended: None,
            steps: Vec::new(),
        }
    }
}

impl FlatTops {
    pub fn push(&mut self, block: &[f64]) {
        // The resolution: the smallest non-zero step (four running minima, so no step
        // waits for the one before).
        let nonzero = |d: f64| if d > 0.0 { d } else { f64::INFINITY };
        let mut q = self.q;
        if let (Some(p), Some(&first)) = (self.prev[0], block.first()) {
            q = q.min(nonzero((first - p).abs()));
        }
        if self.steps.len() < STEP_SAMPLE {
            let room = STEP_SAMPLE - self.steps.len();
            let steps = block
                .windows(2)
                .map(|w| (w[1] - w[0]).abs())
                .filter(|d| *d > 0.0 && d.is_finite());
            self.steps.extend(steps.take(room));
        }
        let mut m = [q; 4];
        let quads = block.len().saturating_sub(1) / 4;
        for c in 0..quads {
            let w = &block[4 * c..4 * c + 5];
            for k in 0..4 {
                let d = nonzero((w[k + 1] - w[k]).abs());
                m[k] = if d < m[k] { d } else { m[k] };
            }
        }
        let rest = block
            .windows(2)
            .skip(quads * 4)
            .fold(q, |q, w| q.min(nonzero((w[1] - w[0]).abs())));
        self.q = m.iter().fold(rest, |a, &b| a.min(b));
        let mut i = 0;
        while i < block.len() {
            // Readings strictly between the extremes so far, with no run there to follow,
            // change nothing but the two last readings.
            if let (None, None, Some(_), Some(_)) = (self.run, self.ended, self.high, self.low) {
                let start = i;
                while i < block.len() {
                    let (h, l) = (self.high_level(), self.low_level());
                    // Eight at a time while each lies strictly between the extremes, or at
                    // one of them in a run of fewer than three (nothing changes for either;
                    // the same tests as below, in a loop without branches).
                    while i + 10 <= block.len()
                        && block[i..i + 10].windows(3).fold(true, |all, w| {
                            let v = w[0];
                            let short = !((w[1] == v) & (w[2] == v));
                            all & ((v < h) & (v > l) | ((v == h) | (v == l)) & short)
                        })
                    {
                        i += 8;
                    }
                    if i == block.len() {
                        break;
                    }
                    let v = block[i];
                    if v < h && v > l {
                        i += 1;
                        continue;
                    }
                    // At or beyond an extreme: a run of fewer than three readings only moves
                    // the extremes.
                    if i + 2 < block.len() && !(block[i + 1] == v && block[i + 2] == v) {
                        if v > h {
                            self.high = Some(RunsAt::new(v));
                        }
                        if v < l {
                            self.low = Some(RunsAt::new(v));
                        }
                        i += 1;
                        continue;
                    }
                    break;
                }
                if i > start {
                    let before = if i - start >= 2 {
                        Some(block[i - 2])
                    } else {
                        self.prev[0]
                    };
                    self.prev = [Some(block[i - 1]), before];
                }
                if i == block.len() {
                    break;
                }
            }
            self.sample(block[i]);
            i += 1;
        }
    }

    fn high_level(&self) -> f64 {
        self.high.map_or(f64::NAN, |h| h.level)
    }

    fn low_level(&self) -> f64 {
        self.low.map_or(f64::NAN, |l| l.level)
    }

    /// One reading past the resolution's update.
    #[inline]
    fn sample(&mut self, v: f64) {
        if let Some((run, one)) = self.ended.take() {
            self.close(run, one.max((v - run.level).abs() / 2.0));
        }
        if let Some(run) = &mut self.run {
            if run.level == v {
                run.len += 1;
                self.prev = [Some(v), self.prev[0]];
                return;
            }
            self.ended = Some((*run, (v - run.level).abs()));
            self.run = None;
        }
        // A new run: followed only at (or beyond) an extreme so far, the only levels that
        // can be the recording's extremes (they only grow apart).
        let high = match self.high {
            Some(h) if v < h.level => false,
            Some(h) if v == h.level => true,
            _ => {
                self.high = Some(RunsAt::new(v));
                true
            }
        };
        let low = match self.low {
            Some(l) if v > l.level => false,
            Some(l) if v == l.level => true,
            _ => {
                self.low = Some(RunsAt::new(v));
                true
            }
        };
        if high || low {
            let one = self.prev[0].map_or(0.0, |p| (p - v).abs());
            let two = self.prev[1].map_or(0.0, |p| (p - v).abs() / 2.0);
            self.run = Some(Run {
                level: v,
                len: 1,
                entry: one.max(two),
            });
        }
        self.prev = [Some(v), self.prev[0]];
    }

    /// Records a run that has ended with its steeper slope.
    fn close(&mut self, run: Run, exit: f64) {
        if run.len < 3 {
            return;
        }
        let slope = run.entry.max(exit);
        for at in [&mut self.high, &mut self.low].into_iter().flatten() {
            if at.level == run.level {
                match run.len {
                    3..=7 => {
                        let k = (run.len - 3) as usize;
                        at.short[k] = at.short[k].max(slope);
                    }
                    _ => at.long = at.long.max(slope),
                }
            }
        }
    }

    /// The recording's resolution so far: its smallest non-zero step (infinite if none) when
    /// that is its quantum; 0 when it is not (below).
    pub fn resolution(&self) -> f64 {
        self.quantum()
    }

    /// The smallest non-zero step if the recording is quantised by it (nine in ten of the
    /// first steps are whole multiples of it: an ADC's codes, a CSV's last decimal), else 0:
    /// a noise-free or smooth recording shows no quantum (its smallest step is the signal's
    /// own, at a clipped top's entry as likely as anywhere), and then a run of three or more
    /// equal readings at an extreme, which a smooth peak never holds, is a flat top.
    fn quantum(&self) -> f64 {
        let q = self.q;
        if !q.is_finite() || self.steps.is_empty() {
            return q;
        }
        let whole = self
            .steps
            .iter()
            .filter(|&&d| {
                let m = d / q;
                (m - m.round()).abs() <= 1e-3
            })
            .count();
        if 10 * whole >= 9 * self.steps.len() {
            q
        } else {
            0.0
        }
    }

    /// The clipping levels found, `None` if none (or the recording has no non-zero step).
    pub fn finish(mut self) -> Option<Clipping> {
        if let Some((run, one)) = self.ended.take() {
            self.close(run, one);
        }
        if let Some(run) = self.run.take() {
            self.close(run, 0.0);
        }
        let q = self.quantum();
        if !q.is_finite() {
            return None;
        }
        let high = self.high.filter(|h| h.clipped(q)).map(|h| h.level);
        let low = self.low.filter(|l| l.clipped(q)).map(|l| l.level);
        (high.is_some() || low.is_some()).then(|| Clipping {
            low_m_s2: low,
            high_m_s2: high,
            from: "flat-top".into(),
        })
    }
}
