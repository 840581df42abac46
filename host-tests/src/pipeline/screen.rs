//! Screening a recorded channel before it is quantised: isolated glitches (removed and
//! listed) and clipped stretches (the sensor's rails, from its range or from flat tops).
//!
//! A recording is scaled to i16 counts by its own extremes, and the default trigger level
//! follows its range, so one glitch far above everything else would set both and hide the
//! real impacts. And a sensor driven past its range reads a flat top that must not pass for a
//! peak.

use crate::report::{Clipping, Spike};

/// A glitch must stand this many times further from the line between its neighbours than the
/// neighbours' own steps, and this many times further from the median than any other sample
/// of the recording.
const SPIKE_RATIO: f64 = 10.0;

/// At most this many glitches that dwarf the rest of a recording are held while it is read;
/// a recording with more is refused (give `--keep-spikes`).
pub const MAX_GLITCHES: usize = 1 << 16;

/// A spike found, and the neighbours the straight line that replaces it joins.
#[derive(Clone, Debug, PartialEq)]
pub struct Removal {
    pub spike: Spike,
    /// The readings just before and just after it, m/s².
    pub before_m_s2: f64,
    pub after_m_s2: f64,
}

impl Removal {
    /// The spike, timed from the first sample's time `t0_s` at `rate_hz` (as the impacts are).
    pub fn timed(&self, t0_s: f64, rate_hz: f64) -> Spike {
        Spike {
            time_s: t0_s + self.spike.sample as f64 / rate_hz,
            ..self.spike.clone()
        }
    }

    /// The value that replaces its sample `j` (0 or 1): on the straight line between the
    /// neighbours.
    pub fn value(&self, j: usize) -> f64 {
        let (a, b) = (self.before_m_s2, self.after_m_s2);
        a + (b - a) * (j + 1) as f64 / (self.spike.samples + 1) as f64
    }
}

/// Replaces each removal's samples in `x` by its straight line; the spikes, timed from the
/// first sample's time `t0_s` at `rate_hz` (as the impacts are).
pub fn apply(removals: &[Removal], x: &mut [f64], t0_s: f64, rate_hz: f64) -> Vec<Spike> {
    let mut spikes = Vec::with_capacity(removals.len());
    for r in removals {
        for j in 0..r.spike.samples as usize {
            if let Some(v) = x.get_mut(r.spike.sample as usize + j) {
                *v = r.value(j);
            }
        }
        spikes.push(r.timed(t0_s, rate_hz));
    }
    spikes
}

/// A one- or two-sample stretch that stands out from the line between its neighbours.
#[derive(Clone, Debug)]
struct Candidate {
    at: u64,
    len: usize,
    values: [f64; 2],
    before: f64,
    after: f64,
}

/// Isolated spikes in a stream read a block at a time, in bounded memory.
///
/// A spike is one or two samples of the same sign of deviation that stand [`SPIKE_RATIO`]
/// times further from the line joining their neighbours than any step among the two samples
/// on either side (a candidate), and whose distance from the recording's median is
/// [`SPIKE_RATIO`] times that of every sample outside the candidates. The second rule keeps
/// a real pulse that is only one or two samples wide on a slow channel (the IMpack 40 g
/// channel's water entry is one): only a reading that dwarfs the whole recording is taken
/// for a glitch.
///
/// The median is known only at the end, so candidates are held until then; one is dropped
/// as soon as the samples outside the candidates prove it cannot dwarf them (it lies within
/// four times their spread of them: a spike lies nine times the largest distance from the
/// median beyond them, which is at least half their spread).
#[derive(Default)]
pub struct SpikeScan {
    /// Samples from index `base` on (the last few of the previous blocks, then this one).
    buf: Vec<f64>,
    base: u64,
    /// The next sample to try as a candidate's start (the first two cannot be).
    next: u64,
    /// Samples seen; the range of those outside the candidates.
    seen: u64,
    outside: Option<(f64, f64)>,
    /// Of samples 0 and 1, how many are counted in `outside`.
    firsts: u64,
    held: Vec<Candidate>,
    /// Hold this many before dropping the ones the range rules out.
    prune_at: usize,
    /// More than [`MAX_GLITCHES`] could not be dropped.
    overflow: bool,
}

impl SpikeScan {
    pub fn push(&mut self, block: &[f64]) {
        if self.next == 0 {
            self.next = 2;
        }
        self.buf.extend_from_slice(block);
        self.seen += block.len() as u64;
        // The first two samples are never a candidate's start.
        while self.firsts < 2.min(self.seen) {
            let v = self.at(self.firsts);
            self.outside_sample(v);
            self.firsts += 1;
        }
        // (Locals, so the loop keeps them in registers.)
        let buf = std::mem::take(&mut self.buf);
        let base = self.base;
        let (mut lo, mut hi) = self.outside.unwrap_or((f64::INFINITY, f64::NEG_INFINITY));
        let mut j = (self.next - base) as usize;
        let finite = buf.iter().fold(true, |all, v| all & v.is_finite());
        while j + 3 < buf.len() {
            // Almost every sample fails the first test of `isolated` (for both lengths):
            // eight at a time while none passes, with the range updates as below. (Only
            // where every reading is finite: no step is NaN, so `may_stand_out`, with plain
            // maxima and minima in a loop without branches, is `stands_out` for both. The
            // readers refuse readings that are not finite; one that overflows with the
            // units is an error at the survey's end.)
            let (mut low, mut high) = ([lo; 8], [hi; 8]);
            while finite && j + 11 <= buf.len() {
                let w = &buf[j - 2..j + 11];
                if (0..8).fold(false, |any, k| any | may_stand_out(&w[k..k + 6])) {
                    break;
                }
                for k in 0..8 {
                    let v = w[k + 2];
                    low[k] = if v < low[k] { v } else { low[k] };
                    high[k] = if v > high[k] { v } else { high[k] };
                }
                j += 8;
            }
            lo = low.iter().fold(lo, |l, &v| if v < l { v } else { l });
            hi = high.iter().fold(hi, |h, &v| if v > h { v } else { h });
            if j + 3 >= buf.len() {
                break;
            }
            let w = &buf[j - 2..j + 4];
            // A candidate's first sample steps from the one before at least 9.5 times the
            // step before that, and by more than 0 (a cheap test that most samples fail).
            let step = (w[2] - w[1]).abs();
            let stands = step > 0.0 && step >= 9.0 * (w[1] - w[0]).abs();
            let len = if stands {
                (1..=2).find(|&len| isolated(w, len))
            } else {
                None
            };
            // The sample counted outside the candidates: this one, or the one after the
            // candidate.
            let (outside, candidate) = match len {
                Some(len) => {
                    let c = Candidate {
                        at: base + j as u64,
                        len,
                        values: [w[2], if len == 2 { w[3] } else { w[2] }],
                        before: w[1],
                        after: w[2 + len],
                    };
                    j += len + 1;
                    (w[2 + len], Some(c))
                }
                None => {
                    j += 1;
                    (w[2], None)
                }
            };
            lo = if outside < lo { outside } else { lo };
            hi = if outside > hi { outside } else { hi };
            // Held against the range up to here, whatever the blocks: what is held, and
            // whether too many are, does not depend on how the recording was cut.
            if let Some(c) = candidate {
                self.outside = Some((lo, hi));
                self.hold(c);
            }
        }
        self.next = base + j as u64;
        self.buf = buf;
        if lo <= hi {
            self.outside = Some((lo, hi));
        }
        // Keep the samples the next tries look back on.
        let keep_from = self.next.saturating_sub(2).max(self.base);
        self.buf.drain(..(keep_from - self.base) as usize);
        self.base = keep_from;
    }

    /// The spikes, given the recording's median (the samples never tried, at the end, lie
    /// outside the candidates). An error if more than [`MAX_GLITCHES`] glitches dwarfed the
    /// rest of the recording while it was read.
    pub fn finish(mut self, median: f64) -> Result<Vec<Removal>, String> {
        // The samples never tried are outside the candidates (0 and 1 are counted in push).
        let end = self.seen;
        let mut k = self.next.max(2).min(end);
        while k < end {
            let v = self.at(k);
            self.outside_sample(v);
            k += 1;
        }
        // Those the whole recording's range rules out go first.
        let held = std::mem::take(&mut self.held);
        self.held = held.into_iter().filter(|c| self.may_dwarf(c)).collect();
        if self.overflow || self.held.len() > MAX_GLITCHES {
            return Err(format!(
                "more than {MAX_GLITCHES} isolated glitches each far beyond the rest of the \
                 recording: not screened (give --keep-spikes to analyse it as it is)"
            ));
        }
        let rest = self.outside.map_or(0.0, |(lo, hi)| {
            (hi - median).abs().max((lo - median).abs()).max(0.0)
        });
        let mut out = Vec::new();
        for c in self.held {
            let extreme = c.values[..c.len]
                .iter()
                .copied()
                .max_by(|a, b| (a - median).abs().total_cmp(&(b - median).abs()))
                .unwrap_or(c.values[0]);
            if (extreme - median).abs() < SPIKE_RATIO * rest {
                continue;
            }
            out.push(Removal {
                spike: Spike {
                    sample: c.at,
                    time_s: 0.0,
                    samples: c.len as u32,
                    value_m_s2: extreme,
                },
                before_m_s2: c.before,
                after_m_s2: c.after,
            });
        }
        Ok(out)
    }

    fn at(&self, k: u64) -> f64 {
        self.buf[(k - self.base) as usize]
    }

    fn outside_sample(&mut self, v: f64) {
        self.outside = Some(match self.outside {
            None => (v, v),
            Some((lo, hi)) => (lo.min(v), hi.max(v)),
        });
    }

    fn hold(&mut self, c: Candidate) {
        if self.overflow || !self.may_dwarf(&c) {
            return;
        }
        self.held.push(c);
        if self.held.len() >= self.prune_at.max(64) {
            let held = std::mem::take(&mut self.held);
            self.held = held.into_iter().filter(|c| self.may_dwarf(c)).collect();
            self.prune_at = 2 * self.held.len();
            if self.held.len() > MAX_GLITCHES {
                // finish reports it; nothing more is held.
                self.overflow = true;
                self.held = Vec::new();
            }
        }
    }

    /// Whether the candidate may still dwarf the samples outside the candidates.
    fn may_dwarf(&self, c: &Candidate) -> bool {
        let Some((lo, hi)) = self.outside else {
            return true;
        };
        let spread = hi - lo;
        c.values[..c.len]
            .iter()
            .any(|&v| (lo - v).max(v - hi) >= 4.0 * spread)
    }
}

/// The first test of [`isolated`], which almost every sample fails: the first sample steps
/// from the one before by more than 0 and at least 9 times the steps around (its deviation
/// is at least 10 of them, and the line starts within half of one of its neighbour, so it
/// steps by at least 9.5: a test without a division).
#[inline(always)]
fn stands_out(w: &[f64], len: usize) -> bool {
    let (a, b) = (w[1], w[2 + len]);
    let local = (a - w[0])
        .abs()
        .max((w[3 + len] - b).abs())
        .max((b - a).abs());
    let step = (w[2] - a).abs();
    step > 0.0 && step >= 9.0 * local
}

/// Whether [`stands_out`] may hold for either length, for finite `w` (six samples).
#[inline(always)]
fn may_stand_out(w: &[f64]) -> bool {
    let max = |a: f64, b: f64| if a > b { a } else { b };
    let min = |a: f64, b: f64| if a < b { a } else { b };
    let (a, step, before) = (w[1], (w[2] - w[1]).abs(), (w[1] - w[0]).abs());
    let one = max(max(before, (w[4] - w[3]).abs()), (w[3] - a).abs());
    let two = max(max(before, (w[5] - w[4]).abs()), (w[4] - a).abs());
    (step > 0.0) & (step >= 9.0 * min(one, two))
}

/// Whether the middle of `w` (`w[2..2 + len]`) stands out from the line between `w[1]` and
/// `w[2 + len]`; `w` holds two samples before it and two after.
fn isolated(w: &[f64], len: usize) -> bool {
    if !stands_out(w, len) {
        return false;
    }
    let (a, b) = (w[1], w[2 + len]);
    let local = (a - w[0])
        .abs()
        .max((w[3 + len] - b).abs())
        .max((b - a).abs());
    let mut sign = 0.0;
    let mut least = f64::INFINITY;
    for j in 0..len {
        let d = w[2 + j] - (a + (b - a) * (j + 1) as f64 / (len + 1) as f64);
        if d == 0.0 || (sign != 0.0 && d.signum() != sign) {
            return false;
        }
        sign = d.signum();
        least = least.min(d.abs());
    }
    least >= SPIKE_RATIO * local && least > 0.0
}

/// A reading within this fraction of the full scale counts as at the rail.
pub const RAIL_FRACTION: f64 = 0.995;

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
struct RunsAt {
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
struct Run {
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
}

impl Default for FlatTops {
    fn default() -> Self {
        Self {
            prev: [None; 2],
            q: f64::INFINITY,
            high: None,
            low: None,
            run: None,
            ended: None,
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

    /// The recording's resolution so far: its smallest non-zero step (infinite if none).
    pub fn resolution(&self) -> f64 {
        self.q
    }

    /// The clipping levels found, `None` if none (or the recording has no non-zero step).
    pub fn finish(mut self) -> Option<Clipping> {
        if let Some((run, one)) = self.ended.take() {
            self.close(run, one);
        }
        if let Some(run) = self.run.take() {
            self.close(run, 0.0);
        }
        let q = self.q;
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A half-sine pulse on a baseline with ±0.01 of deterministic dither, rounded to 0.01.
    fn pulse(n: usize, at: usize, width: usize, peak: f64) -> Vec<f64> {
        (0..n)
            .map(|i| {
                let v = if i >= at && i < at + width {
                    peak * (std::f64::consts::PI * (i - at) as f64 / width as f64).sin()
                } else {
                    0.0
                };
                let dither = 0.01 * ((i * 7919 % 3) as f64 - 1.0);
                (v * 100.0).round() / 100.0 + dither
            })
            .collect()
    }

    /// Finds isolated spikes in `x` and replaces each by the straight line between its
    /// neighbours ([`SpikeScan`] over the whole slice, `median` the recording's).
    fn remove_spikes(x: &mut [f64], median: f64) -> Result<Vec<Spike>, String> {
        let mut scan = SpikeScan::default();
        scan.push(x);
        Ok(apply(&scan.finish(median)?, x, 0.0, 1.0))
    }

    fn median(x: &[f64]) -> f64 {
        let mut v = x.to_vec();
        let mid = v.len() / 2;
        *v.select_nth_unstable_by(mid, f64::total_cmp).1
    }

    fn remove(x: &mut [f64]) -> Vec<Spike> {
        let m = median(x);
        remove_spikes(x, m).unwrap()
    }

    /// The rules written over a whole slice, as they were before they were streamed.
    fn spikes_in_one_go(x: &mut [f64], median: f64) -> Vec<Spike> {
        let n = x.len();
        let mut candidates: Vec<(usize, usize)> = Vec::new();
        let mut i = 2;
        while i + 3 < n {
            match (1..=2).find(|&len| isolated(&x[i - 2..i + len + 2], len)) {
                Some(len) => {
                    candidates.push((i, len));
                    i += len + 1;
                }
                None => i += 1,
            }
        }
        let mut in_candidate = vec![false; n];
        for &(i, len) in &candidates {
            in_candidate[i..i + len].fill(true);
        }
        let rest = x
            .iter()
            .zip(&in_candidate)
            .filter(|(_, &c)| !c)
            .fold(0.0f64, |m, (v, _)| m.max((v - median).abs()));
        let mut spikes = Vec::new();
        for (i, len) in candidates {
            let extreme = x[i..i + len]
                .iter()
                .copied()
                .max_by(|a, b| (a - median).abs().total_cmp(&(b - median).abs()))
                .unwrap();
            if (extreme - median).abs() < SPIKE_RATIO * rest {
                continue;
            }
            let (a, b) = (x[i - 1], x[i + len]);
            for j in 0..len {
                x[i + j] = a + (b - a) * (j + 1) as f64 / (len + 1) as f64;
            }
            spikes.push(Spike {
                sample: i as u64,
                time_s: 0.0,
                samples: len as u32,
                value_m_s2: extreme,
            });
        }
        spikes
    }

    fn flat_tops_in_one_go(x: &[f64]) -> Option<Clipping> {
        let q = x
            .windows(2)
            .map(|w| (w[1] - w[0]).abs())
            .filter(|d| *d > 0.0)
            .fold(f64::INFINITY, f64::min);
        if !q.is_finite() {
            return None;
        }
        let max = x.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let min = x.iter().copied().fold(f64::INFINITY, f64::min);
        let run_at = |level: f64| {
            let mut i = 0;
            while i < x.len() {
                if x[i] != level {
                    i += 1;
                    continue;
                }
                let start = i;
                while i < x.len() && x[i] == level {
                    i += 1;
                }
                let len = i - start;
                if len < 3 {
                    continue;
                }
                let slope_at = |a: Option<usize>, b: Option<usize>| {
                    let one = a.map_or(0.0, |a| (x[a] - level).abs());
                    let two = b.map_or(0.0, |b| (x[b] - level).abs() / 2.0);
                    one.max(two)
                };
                let entry = slope_at(start.checked_sub(1), start.checked_sub(2));
                let exit = slope_at(
                    (i < x.len()).then_some(i),
                    (i + 1 < x.len()).then_some(i + 1),
                );
                let slope = entry.max(exit);
                if slope >= 2.0 * q && slope >= 16.0 * q / len as f64 {
                    return true;
                }
            }
            false
        };
        let high = run_at(max).then_some(max);
        let low = run_at(min).then_some(min);
        (high.is_some() || low.is_some()).then(|| Clipping {
            low_m_s2: low,
            high_m_s2: high,
            from: "flat-top".into(),
        })
    }

    /// Signals with glitches, clipped runs of each length, steps at block edges.
    fn hostile(seed: u64, n: usize) -> Vec<f64> {
        let mut state = seed | 1;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let mut x: Vec<f64> = (0..n).map(|_| ((next() % 7) as f64 - 3.0) * 0.01).collect();
        for _ in 0..n / 50 {
            let at = (next() as usize) % n;
            match next() % 6 {
                0 => x[at] = ((next() % 2000) as f64 - 1000.0) * 10.0,
                1 => {
                    let len = 1 + (next() % 12) as usize;
                    let level = if next() % 2 == 0 { 2.0 } else { -2.0 };
                    for v in x.iter_mut().skip(at).take(len) {
                        *v = level;
                    }
                }
                2 => {
                    let v = ((next() % 200) as f64 - 100.0) * 1e3;
                    x[at] = v;
                    if at + 1 < n {
                        x[at + 1] = v * 0.7;
                    }
                }
                3 => {
                    let w = 2 + (next() % 30) as usize;
                    for k in 0..w.min(n - at) {
                        x[at + k] += 1.5 * (std::f64::consts::PI * k as f64 / w as f64).sin();
                    }
                }
                // Signed zeros, and readings near the end of f64's range (steps overflow).
                4 => x[at] = if next() % 2 == 0 { 0.0 } else { -0.0 },
                5 if seed % 3 == 0 => x[at] = if next() % 2 == 0 { 1e308 } else { -1e308 },
                _ => {}
            }
        }
        x
    }

    #[test]
    fn streamed_in_any_blocks_the_screen_finds_what_the_whole_slice_rules_find() {
        for seed in 1..40u64 {
            let n = 20 + (seed as usize * 997) % 5000;
            let x = hostile(seed, n);
            let m = median(&x);
            let mut want = x.clone();
            let want_spikes = spikes_in_one_go(&mut want, m);
            for block in [1, 2, 3, 5, 64, 4096, n] {
                let mut scan = SpikeScan::default();
                let mut flat = FlatTops::default();
                for b in x.chunks(block) {
                    scan.push(b);
                    flat.push(b);
                }
                let removals = scan.finish(m).unwrap();
                let got: Vec<Spike> = removals.iter().map(|r| r.spike.clone()).collect();
                assert_eq!(got, want_spikes, "seed {seed}, blocks of {block}");
                let mut y = x.clone();
                for r in &removals {
                    for j in 0..r.spike.samples as usize {
                        y[r.spike.sample as usize + j] = r.value(j);
                    }
                }
                assert_eq!(y, want, "seed {seed}, blocks of {block}");
                assert_eq!(
                    flat.finish(),
                    flat_tops_in_one_go(&x),
                    "seed {seed}, {block}"
                );
            }
        }
    }

    #[test]
    fn the_glitch_limit_does_not_depend_on_the_blocks() {
        // Many glitches early that a real impact later dwarfs: none is a spike, however the
        // recording is cut.
        let n = 3 * (MAX_GLITCHES + 100) + 5000;
        let mut x: Vec<f64> = (0..n).map(|i| (i % 3) as f64 * 0.01).collect();
        for k in 0..MAX_GLITCHES + 100 {
            x[3 * k + 10] = 1000.0;
        }
        for k in 0..1000 {
            x[n - 2000 + k] += 500.0 * (std::f64::consts::PI * k as f64 / 1000.0).sin();
        }
        let m = median(&x);
        let whole = remove_spikes(&mut x.clone(), m).unwrap();
        assert!(whole.is_empty());
        for block in [7, 4096, 65536] {
            let mut scan = SpikeScan::default();
            x.chunks(block).for_each(|b| scan.push(b));
            assert!(scan.finish(m).unwrap().is_empty(), "blocks of {block}");
        }
    }

    #[test]
    fn too_many_glitches_are_refused_not_dropped() {
        let mut x = vec![0.0; 10 * (MAX_GLITCHES + 10)];
        for k in 0..MAX_GLITCHES + 5 {
            x[10 * k + 5] = 1e6 + k as f64;
        }
        let e = remove_spikes(&mut x.clone(), 0.0).unwrap_err();
        assert!(e.contains("--keep-spikes"), "{e}");
    }

    #[test]
    fn a_glitch_far_above_the_recording_is_removed_and_listed() {
        let mut x = pulse(2000, 500, 50, 50.0);
        let clean = x.clone();
        x[1500] = 1e4;
        let spikes = remove(&mut x);
        assert_eq!(spikes.len(), 1);
        assert_eq!(spikes[0].sample, 1500);
        assert_eq!(spikes[0].value_m_s2, 1e4);
        assert!((x[1500] - clean[1500]).abs() < 0.05);
        assert_eq!(&x[..1500], &clean[..1500]);
    }

    #[test]
    fn a_two_sample_glitch_is_removed() {
        let mut x = pulse(2000, 500, 50, 50.0);
        x[1500] = -3e3;
        x[1501] = -2e3;
        let spikes = remove(&mut x);
        assert_eq!(spikes.len(), 1);
        assert_eq!((spikes[0].sample, spikes[0].samples), (1500, 2));
        assert_eq!(spikes[0].value_m_s2, -3e3);
    }

    #[test]
    fn a_real_short_pulse_stays() {
        // A two-sample pulse that does not dwarf the rest of the recording.
        let mut x = pulse(2000, 500, 50, 50.0);
        x[1500] = 200.0;
        x[1501] = 150.0;
        let before = x.clone();
        assert!(remove(&mut x).is_empty());
        assert_eq!(x, before);
        // A smooth pulse is never a spike, however large.
        let mut y = pulse(2000, 500, 5, 1e6);
        let before = y.clone();
        assert!(remove(&mut y).is_empty());
        assert_eq!(y, before);
    }

    #[test]
    fn a_clipped_half_sine_is_a_flat_top_and_a_smooth_one_is_not() {
        let x = pulse(4000, 1000, 1000, 40.0);
        assert_eq!(flat_tops(&x), None);
        let clipped: Vec<f64> = x.iter().map(|v| v.min(16.0)).collect();
        let c = flat_tops(&clipped).expect("flat top");
        assert_eq!(c.high_m_s2, Some(16.0));
        assert_eq!(c.low_m_s2, None);
        // Three samples at a steep edge are enough.
        let mut short = pulse(4000, 1000, 8, 40.0);
        let top = 36.0;
        short[1003..1006].fill(top);
        assert!(flat_tops(&short).is_some_and(|c| c.high_m_s2 == Some(top)));
    }

    #[test]
    fn range_levels_are_just_inside_full_scale() {
        let c = from_range(16.0 * 9.80665);
        assert!(c.high_m_s2.unwrap() < 16.0 * 9.80665);
        assert!(c.high_m_s2.unwrap() > 15.9 * 9.80665);
        assert_eq!(c.low_m_s2, c.high_m_s2.map(|v| -v));
    }
}
