//! The in-impact loop: one pass over a call's raw samples, in the impact, that finds a new
//! peak, the separation, a return to the baseline and the end, and keeps the running `Σ d`
//! (and `Σ` of it, for the online kinematics). Its running state lives in a [`Walk`] of
//! locals (the compiler cannot keep fields of the stream in registers across the capture's
//! push), loaded from the active impact before the call and written back after it.
//!
//! ```text
//!  loud (|d| > edge)            quiet (|d| <= edge)
//!  ├ new peak: record, reset    ├ first quiet sample after a peak: separation
//!  ├ sign flip: separation      ├ min_gap quiet: returned (a new hit is a new impact)
//!  └ returned and beyond the    └ hold quiet after the trigger: End::Quiet
//!    trigger: End::NextHit
//! ```

use super::active::Active;
use super::feet::record_fall;
use super::rise::Rise;
use crate::signal::baseline::Deviation;

/// How a run of samples ended the impact.
pub(super) enum End {
    /// Back within the edge level for the hold time.
    Quiet,
    /// A new hit after separation: the next impact starts at the sample not used.
    NextHit,
    /// Settled at a new level.
    Settled(super::level::Settled),
}

/// What a call's pass compares with: fixed for the call.
pub(super) struct Levels {
    /// The edge level in units of `d` (`>= 0`).
    pub edge: u32,
    /// The trigger thresholds in units of `d`.
    pub d_hi: i32,
    pub d_lo: i32,
    /// Quiet samples after which the return is looked at, and that make it a return.
    pub first_mark: u32,
    pub min_gap: u32,
    /// Quiet samples that end the impact (after its trigger).
    pub hold: u32,
    pub trigger_index: u64,
    /// Stream indices of the onset and of the call's first sample.
    pub onset: u64,
    pub start: u64,
}

impl Levels {
    /// The levels of the impact `a` for a call starting at stream index `start`.
    #[inline(always)]
    pub fn of(a: &Active, hold: u32, start: u64) -> Levels {
        // A return to the baseline that lets a new hit start a new impact.
        let min_gap = (hold / 8).max(2);
        Levels {
            // edge_d >= 0: the scene's edge level is positive (validated).
            edge: a.edge_d.clamp(0, u32::MAX as i64) as u32,
            d_hi: a.d_hi,
            d_lo: a.d_lo,
            first_mark: min_gap.min(hold),
            min_gap,
            hold,
            trigger_index: a.trigger_index,
            onset: a.onset_index,
            start,
        }
    }

    /// Where the rise's record closes (stream index) for a peak at stream index `p`.
    #[inline(always)]
    fn rise_closing(&self, p: u64) -> u64 {
        self.onset + Rise::closing(p.saturating_sub(self.onset))
    }

    /// The band a loud sample's `e` (its deviation signed so that the peak's direction is
    /// positive) stays inside unless it may matter: a new peak either way, a sign flip
    /// while there is no separation, a new hit beyond the trigger once the signal has
    /// returned. (sign, trigger, lo, hi).
    #[inline(always)]
    fn marks(
        &self,
        peak_abs: u32,
        positive: bool,
        returned: bool,
        open: bool,
    ) -> (i32, i32, i32, i32) {
        let peak = peak_abs.min(i32::MAX as u32) as i32;
        let trigger = if positive {
            self.d_hi
        } else {
            self.d_lo.saturating_neg()
        };
        let hi = if returned { trigger.min(peak) } else { peak };
        let lo = if open { 0 } else { -peak };
        (if positive { 1 } else { -1 }, trigger, lo, hi)
    }
}

/// The pass's running state.
pub(super) struct Walk {
    pub peak_abs: u32,
    pub peak_positive: bool,
    /// A new peak in this call: its index in the call and its `d`.
    pub new_peak: Option<(usize, i32)>,
    /// Stream index of the latest peak.
    peak_at: u64,
    /// Where the rise's record closed in this call (stream index), if a later peak came
    /// after that point.
    pub rise_closes: Option<u64>,
    pub separation: Option<u64>,
    pub separation_c: i64,
    /// `Σ d` of the impact before this call.
    total_c: i64,
    pub quiet: u32,
    /// Back at the baseline long enough since the peak for a new hit to be a new impact.
    pub returned: bool,
    /// `k` after the latest quiet sample before a louder one, in this call.
    pub last_quiet_k: Option<usize>,
    /// `Σ d` over the call's samples, and `Σ` of the running `Σ d` per sample.
    pub sum: i64,
    pub sum2: i64,
    /// Samples taken, and how the impact ended if it did.
    pub used: usize,
    pub ended: Option<End>,
}

impl Walk {
    /// The state of the impact `a` before a call of `n` samples.
    #[inline(always)]
    pub fn load(a: &Active, n: usize) -> Walk {
        Walk {
            peak_abs: a.peak_d.unsigned_abs().min(u32::MAX as u64) as u32,
            peak_positive: a.peak_d >= 0,
            new_peak: None,
            peak_at: a.peak_index,
            rise_closes: None,
            separation: a.separation,
            separation_c: a.separation_c,
            total_c: a.total_c,
            quiet: a.quiet,
            returned: a.returned,
            last_quiet_k: None,
            sum: 0,
            sum2: 0,
            used: n,
            ended: None,
        }
    }

    /// Runs over `samples`: alternating stretches of samples beyond the edge level (loud)
    /// and within it (quiet). The samples that only add to the sums (a loud one inside its
    /// band on the pulse's side once the quiet count is reset; a quiet one before the next
    /// count that matters) go through [`run_in`], out of line so that its few values stay
    /// in registers; what is rare (the first loud sample after quiet ones, a new peak, a
    /// sign flip, a new hit, the counts that mark a return or the end) is taken here, one
    /// sample at a time, with the same operations in the same order as one loop over every
    /// sample would.
    #[inline(always)]
    pub fn run(&mut self, samples: &[i16], deviation: Deviation, l: &Levels) {
        let n = samples.len();
        let edge = l.edge;
        let start = l.start;
        let mut k = 0;
        'scan: while k < n {
            let (mut sign, mut trigger, mut lo, mut hi) = l.marks(
                self.peak_abs,
                self.peak_positive,
                self.returned,
                self.separation.is_none(),
            );
            let mut band = Band::loud(sign, lo, hi, edge);
            loop {
                // Loud samples inside the band add to the sums only.
                if let (0, Some(band)) = (self.quiet, band) {
                    let rest = samples.get(k..).unwrap_or(&[]);
                    k += run_in(rest, deviation, band, &mut self.sum, &mut self.sum2);
                }
                let Some(&x) = samples.get(k) else {
                    break 'scan;
                };
                let d = deviation.of(x);
                let abs = d.unsigned_abs();
                if abs <= edge {
                    break;
                }
                let e = d.wrapping_mul(sign);
                if e > hi || e < lo {
                    if self.returned && e > trigger {
                        // Back at the baseline, then a new hit the same way beyond the
                        // trigger: the next impact starts with this sample.
                        self.ended = Some(End::NextHit);
                        self.used = k;
                        break 'scan;
                    }
                    if abs > self.peak_abs {
                        self.peak(k, d, abs, l);
                    } else if self.separation.is_none() && e < 0 {
                        // Across the whole band between two samples (a sign flip): the
                        // signal came back between them.
                        self.separation = Some(start + k as u64);
                        self.separation_c = self.total_c + self.sum;
                    }
                    (sign, trigger, lo, hi) = l.marks(
                        self.peak_abs,
                        self.peak_positive,
                        self.returned,
                        self.separation.is_none(),
                    );
                    band = Band::loud(sign, lo, hi, edge);
                }
                if self.quiet > 0 {
                    self.last_quiet_k = Some(k);
                    self.quiet = 0;
                }
                self.sum += d as i64;
                self.sum2 = self.sum2.wrapping_add(self.sum);
                k += 1;
            }
            // Quiet: the first quiet sample after the peak is the separation.
            if self.separation.is_none() {
                self.separation = Some(start + k as u64);
                self.separation_c = self.total_c + self.sum;
            }
            while k < n {
                // Quiet samples up to the next count that matters: the one that makes it a
                // return (`min_gap`), the hold, or past the hold the first sample beyond the
                // trigger.
                let q = self.quiet;
                let mut take = n - k;
                if !self.returned && q < l.min_gap {
                    take = take.min((l.min_gap - q) as usize);
                }
                if q < l.hold {
                    take = take.min((l.hold - q) as usize);
                } else {
                    let beyond =
                        (l.trigger_index.saturating_add(1)).saturating_sub(start + k as u64);
                    take = take.min(beyond.saturating_add(1).min(n as u64) as usize);
                }
                let run = samples.get(k..k + take).unwrap_or(&[]);
                let got = match Band::quiet(edge) {
                    Some(band) => run_in(run, deviation, band, &mut self.sum, &mut self.sum2),
                    None => 0,
                };
                self.quiet = self.quiet.saturating_add(got as u32);
                k += got;
                // The last sample taken, `k - 1`, as one loop would check it (the counts
                // only grow, so what any sample taken would set, the last sets; the end
                // cannot come before it: `take` stops at the first sample where it can).
                if got > 0 && self.quiet >= l.first_mark {
                    self.returned |= self.quiet >= l.min_gap;
                    if self.quiet >= l.hold && start + (k - 1) as u64 > l.trigger_index {
                        self.ended = Some(End::Quiet);
                        self.used = k;
                        break 'scan;
                    }
                }
                if got < take {
                    // A loud sample at `k` (by the loud phase's own test: it takes it).
                    continue 'scan;
                }
            }
        }
    }

    /// A new peak `d` (`|d|` = `abs`) at `k`.
    #[inline(always)]
    fn peak(&mut self, k: usize, d: i32, abs: u32, l: &Levels) {
        let at = l.start + k as u64;
        // The rise's record closed if the samples went past its closing point for the peak
        // so far before this one came (it lies at least 16 samples past that peak: a peak
        // close after it cannot).
        let near = self.new_peak.is_some_and(|(kp, _)| k - kp <= 16);
        if !near && self.rise_closes.is_none() && at > l.rise_closing(self.peak_at) {
            self.rise_closes = Some(l.rise_closing(self.peak_at));
        }
        self.peak_at = at;
        self.peak_abs = abs;
        self.peak_positive = d >= 0;
        self.new_peak = Some((k, d));
        self.separation = None;
        self.returned = false;
    }

    /// Where the rise's record closes (stream index): for the call's last peak, unless it
    /// closed before it.
    #[inline(always)]
    pub fn rise_close(&self, l: &Levels, peak_index: u64) -> u64 {
        self.rise_closes
            .unwrap_or_else(|| l.rise_closing(peak_index))
    }

    /// Writes the pass over `kept` (the samples it took) back into `a`: the new peak, the
    /// falling foot's record, the latest quiet sample, the rise's record, the sums and
    /// counts. Returns how the impact ended, if it did in the pass.
    #[inline(always)]
    pub fn store(
        &mut self,
        a: &mut Active,
        kept: &[i16],
        l: &Levels,
        deviation: Deviation,
    ) -> Option<End> {
        let start = l.start;
        let open_at_start = a.separation.is_none();
        if let Some((k, d)) = self.new_peak {
            a.peak_d = d as i64;
            a.peak_index = start + k as u64;
        }
        // The falling foot: from a new peak on, or going on until the separation.
        let from = match self.new_peak {
            Some((k, _)) => Some(k),
            None if open_at_start => Some(0),
            None => None,
        };
        if let Some(from) = from {
            let to = self
                .separation
                .map_or(kept.len() as u64, |s| s.saturating_sub(start));
            let to = (to as usize).min(kept.len());
            let run = kept.get(from..to).unwrap_or(&[]);
            record_fall(a, run, start + from as u64);
        }
        // Just after the latest quiet sample: the end of the run of quiet samples that
        // is still going, or the one before the latest louder sample.
        if self.quiet > 0 {
            a.last_quiet = start + self.used as u64;
        } else if let Some(k) = self.last_quiet_k {
            a.last_quiet = start + k as u64;
        }
        if matches!(self.ended, Some(End::NextHit)) {
            a.end_at = Some(a.last_quiet);
        }
        if !a.rise.done() {
            // Up to where it closes: for the last peak, unless it closed before it.
            let close = self.rise_close(l, a.peak_index);
            let n = (close + 1).saturating_sub(start).min(kept.len() as u64) as usize;
            let sign = a.sign;
            a.rise.take(start.saturating_sub(a.onset_index), n, |k| {
                kept.get(k).map_or(0, |&x| sign * deviation.of(x) as i64)
            });
            if start + kept.len() as u64 > close {
                a.rise.close();
            }
        }
        a.total_c += self.sum;
        a.separation = self.separation;
        a.separation_c = self.separation_c;
        a.quiet = self.quiet;
        a.returned = self.returned;
        a.samples += self.used as u64;
        self.ended.take()
    }
}

/// An interval of `d`, `from..=to`, tested as `d - from <= width` unsigned (exact for every
/// `d`: `to >= from`, both in i32).
#[derive(Clone, Copy)]
pub(super) struct Band {
    from: i32,
    width: u32,
}

impl Band {
    /// `from..=to` met with i32's range (`d` is an i32), in i64; `None` if that is empty.
    #[inline(always)]
    fn new(from: i64, to: i64) -> Option<Band> {
        let (from, to) = (from.max(i64::from(i32::MIN)), to.min(i64::from(i32::MAX)));
        (from <= to).then(|| Band {
            from: from as i32,
            width: (to as i32 as u32).wrapping_sub(from as i32 as u32),
        })
    }

    /// The loud samples inside a loud sample's band on the pulse's side: `lo <= d * sign <=
    /// hi` (`sign = ±1`) and `d * sign > edge`. (A loud sample inside the band on the other
    /// side, `d * sign < -edge`, is the loop's own to take.)
    #[inline(always)]
    fn loud(sign: i32, lo: i32, hi: i32, edge: u32) -> Option<Band> {
        let (lo, hi, edge) = (i64::from(lo), i64::from(hi), i64::from(edge));
        let lo = lo.max(edge + 1);
        if sign >= 0 {
            Band::new(lo, hi)
        } else {
            Band::new(-hi, -lo)
        }
    }

    /// The quiet samples: `|d| <= edge`.
    #[inline(always)]
    fn quiet(edge: u32) -> Option<Band> {
        Band::new(-i64::from(edge), i64::from(edge))
    }

    /// `from <= d <= to`: `d - from` and `to - from` taken mod 2^32 (exact: `to >= from`).
    #[inline(always)]
    fn holds(self, d: i32) -> bool {
        (d as u32).wrapping_sub(self.from as u32) <= self.width
    }
}

/// The leading samples of `samples` whose `d` lies in `band`, added to the sums (`sum +=
/// d`, `sum2 += sum`, wrapping as the loop's); how many. Out of line: its dozen values stay
/// in registers (about 12 instructions a sample on the M4).
#[inline(never)]
fn run_in(
    samples: &[i16],
    deviation: Deviation,
    band: Band,
    sum: &mut i64,
    sum2: &mut i64,
) -> usize {
    let (mut s, mut s2) = (*sum, *sum2);
    let mut rest = samples;
    while let [x, tail @ ..] = rest {
        let d = deviation.of(*x);
        if !band.holds(d) {
            break;
        }
        s += d as i64;
        s2 = s2.wrapping_add(s);
        rest = tail;
    }
    (*sum, *sum2) = (s, s2);
    samples.len() - rest.len()
}

#[cfg(test)]
#[path = "walk_tests.rs"]
mod tests;
