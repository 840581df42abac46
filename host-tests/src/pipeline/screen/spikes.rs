//! Isolated glitches: found a block at a time ([`SpikeScan`]), removed (the line between
//! their neighbours put in their place) and listed, so that one far above everything else
//! sets neither the scale nor the trigger level.

use crate::report::Spike;

/// A glitch must stand this many times further from the line between its neighbours than the
/// neighbours' own steps, and this many times further from the median than any other sample
/// of the recording.
pub(super) const SPIKE_RATIO: f64 = 10.0;

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

    /// The same spike's removal from another channel of the recording (an axis), whose
    /// neighbours of it are `before_m_s2` and `after_m_s2`.
    pub fn between(&self, before_m_s2: f64, after_m_s2: f64) -> Self {
        Self {
            spike: self.spike.clone(),
            before_m_s2,
            after_m_s2,
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
    fill(removals, x);
    removals.iter().map(|r| r.timed(t0_s, rate_hz)).collect()
}

/// Replaces each removal's samples in `x` by its straight line.
pub fn fill(removals: &[Removal], x: &mut [f64]) {
    for r in removals {
        for j in 0..r.spike.samples as usize {
            if let Some(v) = x.get_mut(r.spike.sample as usize + j) {
                *v = r.value(j);
            }
        }
    }
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
    pub fn finish(mut self, median: f64) -> Result<Vec<Removal>, TooManyGlitches> {
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
            return Err(TooManyGlitches);
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
pub(super) fn isolated(w: &[f64], len: usize) -> bool {
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
/// More than [`MAX_GLITCHES`] isolated glitches dwarfed the rest of a recording: too many to
/// be glitches, so none is removed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error(
    "more than {MAX_GLITCHES} isolated glitches each far beyond the rest of the \
     recording: not screened (give --keep-spikes to analyse it as it is)"
)]
pub struct TooManyGlitches;
