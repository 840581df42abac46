//! Where the contact begins and ends, as the physics defines them (where the contact force is
//! zero): the feet of the pulse fitted as power curves ([`power_flank`]), the whole lobe where
//! a ramp rises into the onset, a step past the flank level placed from its three samples
//! ([`power_flank::steep_zero`]) and so an onset just past the edge level whose three lie on
//! a power curve ([`power_flank::head_zero`]), the falling flank's straight line, zero
//! crossing or edge crossing otherwise; and the falling foot's record.

use super::active::{Active, FlankTouch};
use super::rise::Fall;
use super::{Stream, REACH};
use crate::signal::baseline::{Deviation, Stats, STRIDE};
use crate::signal::flank::{crossing, Flank};
use crate::signal::power_flank;

/// Where a pulse left the edge level, as the trigger found it: samples from the newest back
/// to the onset (the walk back), the pulse's sign, the baseline, the edge level (units of
/// `d`), the trigger sample, and samples since the previous impact's window (since the
/// record's start if none came before: `after_impact` false).
pub(super) struct OnsetWalk {
    pub pulse: usize,
    pub sign: i64,
    pub deviation: Deviation,
    pub edge_d: i64,
    pub trigger_x: i16,
    pub since_last: usize,
    pub after_impact: bool,
}

/// A dip to the baseline ends a slow ramp's lobe only where this many samples from it back
/// average within [`LOBE_SHARE`] of it too ([`Stream::lobe_before`]): a 64-sample mean's
/// noise is an eighth of a sample's.
pub(super) const LOBE_LOOK: usize = 64;

/// The share of the edge level (its inverse) within which [`LOBE_LOOK`] samples back from
/// a dip end a slow ramp's lobe: a sixteenth (2.5 times the mean's noise where the edge
/// level is 5 times a sample's), so its foot left below is a small part of its area.
pub(super) const LOBE_SHARE: i64 = 16;

/// A lobe replaces the fitted first touch only where it begins more than this many samples
/// before it, and the sum of its samples before it stands out of the noise
/// ([`LOBE_SIGNIFICANCE`]): else they are the same foot's samples within the noise, walked
/// back to the first sample the noise put at the baseline (0.4 to 7 samples early, after a
/// flight whose baseline was learnt in a few strides).
pub(super) const LOBE_BEYOND_FIT: f32 = 2.0;

/// See [`LOBE_BEYOND_FIT`]: the sum of `n` samples before the fitted touch stands out of the
/// noise above this many edge levels times `√n`: three standard deviations of a noise whose
/// own is a fifth of the edge level. (A walk that stops at the first sample at the baseline
/// crosses only samples above it, 0.8 σ each on average: it stands out only past 14 samples,
/// where it is a foot.)
pub(super) const LOBE_SIGNIFICANCE: f32 = 0.6;

/// The whole lobe before an onset ([`Stream::lobe_before`]).
pub(super) struct Lobe {
    /// Where it crosses the baseline, relative to the onset, samples.
    pub touch: f32,
    /// `Σ d` over its samples (0 for none).
    pub c: i64,
    /// It runs back to the previous impact's window, still above the baseline there: the
    /// pulse was under way before that window ended, and its Δv covers the part after it.
    pub in_previous: bool,
    /// A ramp that runs back beyond the flanks' reach: the pulse's start, so its Δv,
    /// unknown. (Not at the record's start: a record that starts on a ramp learns its
    /// baseline there, and the walk stops where the ramp crosses it; that baseline is
    /// flagged by [`crate::signal::baseline::Baseline::unconfirmed`].)
    pub cut: bool,
    /// The sample just before the onset (`d`, the pulse's side positive), if the ring held
    /// it.
    pub before: Option<i64>,
}

impl<const PRE: usize> Stream<PRE> {
    /// The whole lobe before the onset: the samples still on the pulse's side of the
    /// baseline (a pad's or felt's slow compression before the main pulse decelerates the
    /// body too), back to where the signal reaches it, if they rise in a ramp to the edge
    /// level. A lobe that its noise ended while it was still high is walked on through the
    /// dips: one ends it where the [`LOBE_LOOK`] samples from it back average within a
    /// [`LOBE_SHARE`]th of the edge level of the baseline (a slow ramp's noise dips to the
    /// baseline long before the ramp does: a 20 ms ramp to 5 g under 0.3 g of noise was cut
    /// where it stood at half the edge level, and rejected, Δv 3.8 % low). Where it crosses
    /// (relative to the onset, samples), its samples, `Σ d` over them, and whether the ramp
    /// runs back beyond the flanks' reach: its start, and so the pulse's Δv, unknown.
    pub(super) fn lobe_before(&self, o: OnsetWalk) -> Lobe {
        let OnsetWalk {
            pulse,
            sign,
            deviation,
            edge_d,
            trigger_x,
            since_last,
            after_impact,
        } = o;
        let pd = |i: usize| {
            self.ring
                .back(i)
                .filter(|_| i < REACH)
                .map(|x| sign * deviation.of(x) as i64)
        };
        let lobe_limit = since_last.min(REACH).saturating_sub(pulse);
        // The walk from `len` samples into the lobe (`Σ d` so far `c`) back to where it
        // stops: at a sample at or past the baseline; with `through`, not where the
        // `LOBE_LOOK` samples from it back (a window slid along) average beyond the
        // `LOBE_SHARE`th of the edge level. Its length, `Σ d`, and whether its stop was
        // judged (a whole window, or no `through`).
        let walk = |mut len: usize, mut c: i64, through: bool| {
            let (mut ahead, mut n) = (0i64, 0usize);
            if through {
                for y in (len..(len + LOBE_LOOK).min(lobe_limit)).filter_map(|k| pd(pulse + k)) {
                    ahead += y;
                    n += 1;
                }
            }
            while len < lobe_limit {
                let Some(y) = pd(pulse + len) else { break };
                let crossed =
                    through && n == LOBE_LOOK && LOBE_SHARE * ahead > edge_d * LOBE_LOOK as i64;
                if y <= 0 && !crossed {
                    break;
                }
                c += sign * y;
                if through {
                    ahead -= y;
                    n -= 1;
                    let next = len + LOBE_LOOK;
                    if let Some(z) = pd(pulse + next).filter(|_| next < lobe_limit) {
                        ahead += z;
                        n += 1;
                    }
                }
                len += 1;
            }
            (len, c, !through || n == LOBE_LOOK)
        };
        // A lobe is a ramp from the baseline up to the edge level, not the signal sitting on
        // the pulse's side of the baseline (drag, an offset, noise): its newest quarter
        // averages at least half the edge level, its oldest quarter at most a quarter of it
        // or of the newest (a ramp that goes on past the edge level before the onset)
        // (three samples or fewer are the crossing itself). The two quarters' means.
        let quarters = |len: usize| {
            let quarter = len / 4;
            let mean = |from: usize| {
                let sum: i64 = (from..from + quarter).filter_map(pd).sum();
                sum.checked_div(quarter as i64).unwrap_or(0)
            };
            (len > 3).then(|| (mean(pulse), mean(pulse + len - quarter)))
        };
        let (mut lobe_len, mut lobe_c, _) = walk(0, 0, false);
        // The onset itself lies in the previous impact's window (the walk back from the
        // trigger, above the edge level, reached into it: no lobe is left to walk), or it is
        // the window's first sample after its end with the window's last sample still half
        // the edge level up (a window that ends on a new hit ends just before its onset: a
        // sharp hit after quiet starts there from the baseline, and is no continuation): the
        // pulse was under way before that window ended, as a lobe that runs into it.
        let onset_in_window = after_impact
            && since_last <= REACH
            && (pulse > since_last
                || (pulse == since_last && pd(pulse).is_some_and(|y| 2 * y >= edge_d)));
        let (mut cut, mut in_previous) = (false, onset_in_window);
        if let Some((newest, oldest)) = quarters(lobe_len) {
            if lobe_len >= LOBE_LOOK && 2 * newest >= edge_d && 4 * oldest > edge_d.max(newest) {
                // A ramp that reaches the pulse, ended by its noise while still high: walk
                // on through its dips (a lobe shorter than the window is no slow ramp, and
                // the window could not judge it: a piezo's offset before its pulse). Ran out
                // (stopped where fewer than `LOBE_LOOK` samples were left to judge a dip by,
                // at the flanks' reach; not at the previous impact's window, where a lobe
                // stops): the ramp began further back.
                let (len, c, judged) = walk(lobe_len, lobe_c, true);
                (lobe_len, lobe_c) = (len, c);
                // Ran out at the previous impact's window (nearer than the reach): the
                // ramp was under way before it ended.
                let at_window = !judged && after_impact && since_last <= REACH;
                let at_reach = !judged && since_last > REACH;
                // A ramp whose start the walk found rises quarter by quarter (a wandering
                // signal, which the walk crosses too, does not): else no lobe.
                let quarter = |q: usize| -> i64 {
                    let n = len / 4;
                    let from = pulse + q * n;
                    let sum: i64 = (from..from + n).filter_map(pd).sum();
                    sum.checked_div(n as i64).unwrap_or(0)
                };
                let rises = quarter(3) <= quarter(2)
                    && quarter(2) <= quarter(1)
                    && quarter(1) <= quarter(0);
                // Ran out, it is a ramp if it climbs from its oldest quarter to its second
                // newest by a sixteenth of the edge level (the newest may hold the pulse's
                // foot; a quarter's mean is far steadier than a sample): an offset that began
                // beyond the walk leaves the pulse's own Δv, whatever its noise.
                let climbs = rises && 16 * (quarter(1) - quarter(3)) > edge_d;
                cut = at_reach && climbs;
                in_previous = at_window && climbs;
                if !(cut || rises) {
                    lobe_len = 0;
                    lobe_c = 0;
                }
            }
        }
        if let Some((newest, oldest)) = quarters(lobe_len) {
            let ramp = 2 * newest >= edge_d && 4 * oldest <= edge_d.max(newest);
            if !(ramp || in_previous) || cut {
                lobe_len = 0;
                lobe_c = 0;
            }
        }
        // Where it crosses the baseline, relative to the onset (between the last sample on the
        // other side and the lobe's first; at its first if the ring holds nothing older).
        let first = match lobe_len.checked_sub(1) {
            Some(i) => pd(pulse + i),
            None => pulse
                .checked_sub(1)
                .map_or(Some(sign * deviation.of(trigger_x) as i64), pd),
        };
        let lobe_touch = match (pd(pulse + lobe_len), first) {
            (Some(y0), Some(y1)) if y1 > y0 => {
                (crossing(y0 as f64, y1 as f64, 0.0) - 1.0) as f32 - lobe_len as f32
            }
            _ => -(lobe_len as f32),
        };
        Lobe {
            touch: lobe_touch,
            c: lobe_c,
            in_previous,
            cut,
            before: pd(pulse),
        }
    }

    /// Locates a new separation while its flank is in the ring (just after the samples that
    /// set it were kept).
    #[inline(never)]
    pub(super) fn locate_separation(&mut self) {
        let Some(a) = self.run.active.as_ref() else {
            return;
        };
        let Some(s) = a.separation else {
            return;
        };
        if a.separation_at.is_some_and(|(at, _, _)| at == s) {
            return;
        }
        let (offset, tail, clear) = self
            .fall(a, s)
            .unwrap_or_else(|| (self.separation_offset(a, s), 0, None));
        if clear.is_some() {
            self.run.foot_power = clear;
        }
        if let Some(a) = self.run.active.as_mut() {
            a.separation_at = Some((s, offset, tail));
        }
    }

    /// First touch relative to the onset, `Σ d` over the foot before the onset, and whether
    /// it lies inside the previous impact's contact (then it is that contact's end): where the
    /// rising foot, fitted as a power curve ([`power_flank`]), reaches zero force; where the
    /// flank stepped past the flank level, or the flank held too few samples for a line and
    /// the onset's three lie on a power curve, from those three ([`Self::head_touch`]); else
    /// the trigger's estimate (`touch_offset`, `lead_c`). And whether it is a fit's zero (not
    /// the edge crossing, late by design), and, where it lies in a jump's interval (its
    /// middle, or a steep line's zero) clear of the previous contact
    /// ([`crate::capture::Summary::touch_jump`]), its reach
    /// ([`crate::capture::Summary::touch_reach`]).
    pub(super) fn touch(&mut self, a: &Active) -> ((f32, i64, bool), bool, Option<f32>) {
        let trigger = (a.touch_offset, a.lead_c, a.line_in_previous);
        let peak = a.peak_d.unsigned_abs() as f32;
        let foot = self.rise_foot(a).filter(|foot| {
            // The foot's straight line (where no power is clearly better) stands where the
            // trigger's flank had too few samples for a line (its zero before the onset,
            // [`power_flank::zero`]), or near the interval a step crossed.
            foot.power != 1.0
                || match a.flank_touch {
                    FlankTouch::Crossing => true,
                    // (The sample before the step may already be on the foot, within the
                    // edge level: its zero may lie before that sample, not before the next.)
                    FlankTouch::Steep => (-2.0..=0.0).contains(&foot.zero),
                    FlankTouch::Line | FlankTouch::Refused => false,
                }
        });
        match foot {
            Some(foot) => {
                if foot.clear {
                    self.run.foot_power = Some(foot.power);
                }
                let touch = foot.zero.max(a.touch_floor);
                let lead = libm::floorf(-touch).max(0.0) as i64;
                let c = foot.sum(-lead, 0) * peak * a.sign as f32;
                ((touch, c as i64, foot.zero < a.touch_floor), true, None)
            }
            None => match self.head_touch(a) {
                Some((z, reach)) => {
                    let touch = z.max(a.touch_floor);
                    // (A jump's whole interval clear of the previous contact: the analysis
                    // may place touch anywhere in it.)
                    let jump = reach.filter(|_| a.touch_floor <= -1.0);
                    // Touch before the sample before the onset ([`earlier_foot`]): that
                    // sample is the foot's, in `Σ d` as the kinematics integrate it (the
                    // trigger's touch, a step's middle or the edge crossing, had none).
                    let c = match a.before_d {
                        Some(before) if touch < -1.0 => a.sign * i64::from(before),
                        _ => a.lead_c,
                    };
                    ((touch, c, z < a.touch_floor), true, jump)
                }
                // (A step's middle is no edge crossing either.)
                None => (
                    trigger,
                    matches!(a.flank_touch, FlankTouch::Line | FlankTouch::Steep),
                    None,
                ),
            },
        }
    }

    /// First touch relative to the onset from the onset and the next two samples (the rise
    /// record's head): where the onset stepped past the flank level
    /// ([`FlankTouch::Steep`]), [`power_flank::steep_zero`] (its line's zero in the interval
    /// before the onset is a jump's too, a jump onto a ramp, smaller than a sample's rise,
    /// reading as a ramp that began earlier: the analysis places touch from the compression's
    /// law where that holds, and the line's zero stands where its fit refuses a jump); where it lies just past the edge
    /// level and the flank had no line ([`FlankTouch::Crossing`]), [`power_flank::head_zero`]
    /// if the three lie on a power curve (a Hertz foot at 20 kS/s, its onset a tenth of a
    /// sample in: else the walk back to the baseline puts touch up to a sample early) and
    /// the sample before the onset is quiet, as that curve says (within half the edge level:
    /// a foot that began earlier is the lobe's). Either way, where that curve reaches zero
    /// before the sample before the onset and reads that sample there ([`earlier_foot`]),
    /// its zero.
    /// And, where touch is in a jump's interval ([`crate::capture::Summary::touch_jump`]),
    /// how far from it touch may lie ([`crate::capture::Summary::touch_reach`]).
    fn head_touch(&self, a: &Active) -> Option<(f32, Option<f32>)> {
        let head = a.rise.head().map(|y| y.map(|d| d as f32))?;
        match a.flank_touch {
            FlankTouch::Steep => Some(match power_flank::steep_line(head) {
                // (A jump's interval too: Kelvin–Voigt's `c v0` below a sample's `k v0 dt`
                // had touch 0.7 samples early at 20 kS/s, `x_m` +11 %. Its reach from a
                // line's zero to the onset; a power curve's zero is a foot's.)
                Some((zero, line)) => (zero, Some(if line { -zero } else { 0.0 })),
                None => earlier_foot(a, head)
                    .unwrap_or((power_flank::JUMP_MIDDLE, Some(JUMP_MIDDLE_REACH))),
            }),
            FlankTouch::Crossing => power_flank::head_zero(head)
                .filter(|_| a.quiet_before())
                .map(|zero| (zero, None))
                .or_else(|| earlier_foot(a, head)),
            FlankTouch::Line | FlankTouch::Refused => None,
        }
    }

    /// First touch where the whole lobe begins, if that is earlier than `touch` (first touch,
    /// `Σ d` before the onset, inside the previous contact; `fitted`: a fit's zero, not the
    /// edge crossing): a slow ramp below the edge level before the pulse (a pad or felt
    /// compressing) is part of the contact, however long it is against the pulse (a lobe
    /// that does not rise to the pulse is none: [`Self::lobe_before`]). Not into the
    /// previous contact. Against a fit's zero, only a lobe that begins more than
    /// [`LOBE_BEYOND_FIT`] samples before it with a sum before it that stands out of the
    /// noise ([`LOBE_SIGNIFICANCE`]): nearer, or within the noise, it is the same foot,
    /// walked back to the first sample the noise put at the baseline, and the fit stands. A
    /// lobe into the previous impact's window always says so (`in_previous`), wherever it
    /// puts touch.
    pub(super) fn lobe(
        &self,
        a: &Active,
        touch: (f32, i64, bool),
        fitted: bool,
    ) -> (f32, i64, bool) {
        let longer = a.lobe_touch < touch.0;
        let fits = a.lobe_touch >= a.touch_floor;
        if !(longer && fits) {
            return (touch.0, touch.1, touch.2 || a.lobe_in_previous);
        }
        // The lobe's samples before the fitted touch: a foot's or a ramp's sum stands out of
        // the noise; the noise's that a walk to the first sample at the baseline crosses
        // does not. (The difference of the lobe's sum and the fit's over the samples after
        // its touch: where that is the fitted curve's, not the samples', their noise enters
        // too, and the test is a little looser than its 3σ.)
        let before = touch.0 - a.lobe_touch;
        let sum = (a.sign * (a.lobe_c - touch.1)) as f32;
        let ramp = sum > LOBE_SIGNIFICANCE * a.edge_d as f32 * libm::sqrtf(before.max(0.0));
        if !fitted || a.lobe_in_previous || (before > LOBE_BEYOND_FIT && ramp) {
            (a.lobe_touch, a.lobe_c, a.lobe_in_previous)
        } else {
            touch
        }
    }

    /// The rising foot (from the rise record) fitted as a power curve, if it is one.
    pub(super) fn rise_foot(&self, a: &Active) -> Option<power_flank::Foot> {
        let peak = a.peak_d.unsigned_abs() as f32;
        if !(peak > 0.0) {
            return None;
        }
        let top = power_flank::FOOT * peak;
        let n = a
            .rise
            .points()
            .take_while(|&(_, d)| d as f32 <= top)
            .count();
        let stride = n.div_ceil(power_flank::MAX_FOOT_POINTS).max(1);
        let points = a
            .rise
            .points()
            .take(n)
            .step_by(stride)
            .filter(|&(_, d)| d > 0)
            .map(|(p, d)| (p as f32, d as f32 / peak));
        let choice = power_flank::Choice::Free {
            prior: self.run.foot_power,
            line: matches!(a.flank_touch, FlankTouch::Crossing | FlankTouch::Steep),
        };
        power_flank::zero(points, true, -1.0, a.edge_d as f32 / peak, choice)
    }

    /// The separation relative to `separation` and `Σ d` over the foot beyond it, where the
    /// falling foot (the falling side's record up to the separation) is a power curve: its
    /// rising foot's power ([`power_flank`]).
    pub(super) fn fall(&self, a: &Active, separation: u64) -> Option<(f32, i64, Option<f32>)> {
        // (None for a zero peak, too.)
        let rise = self.rise_foot(a)?;
        let peak = a.peak_d.unsigned_abs() as f32;
        let sign: i64 = if a.peak_d >= 0 { 1 } else { -1 };
        // Point `i` of the record: position relative to the separation (negative), and the
        // deviation over the peak.
        let point = |i: usize| {
            let (p, d) = a.fall.get(i)?;
            let x = a.fall_start as f64 + p as f64 - separation as f64;
            Some((x as f32, d / peak))
        };
        // The foot: the record's last points up to the foot's top.
        let n = a.fall.len();
        let len = (0..n)
            .rev()
            .take_while(|&i| point(i).is_some_and(|(_, v)| v <= power_flank::FOOT))
            .count();
        let stride = len.div_ceil(power_flank::MAX_FOOT_POINTS).max(1);
        let points = (0..len)
            .step_by(stride)
            .filter_map(|j| point(n - 1 - j))
            .filter(|&(_, v)| v > 0.0);
        let choice = power_flank::Choice::Only(rise.power);
        let foot = power_flank::zero(points, false, 0.0, a.edge_d as f32 / peak, choice)?;
        let tail = libm::ceilf(foot.zero).max(0.0) as i64;
        let c = foot.sum(0, tail) * peak * sign as f32;
        Some((foot.zero, c as i64, rise.clear.then_some(rise.power)))
    }

    /// The separation relative to `separation_index`: the falling flank (from the ring)
    /// extrapolated to zero, the zero crossing for a sign flip across the whole edge band; a
    /// step down from beyond the flank level within one sample placed from its three samples
    /// ([`power_flank::steep_zero`], mirrored), or at the zero crossing where the first quiet
    /// sample has crossed zero; else the edge crossing between the last sample beyond the
    /// edge and the first within it.
    pub(super) fn separation_offset(&self, a: &Active, separation: u64) -> f32 {
        let deviation = a.deviation();
        // The ring ends at `self.run.index - 1`: sample `i` is `back(index - 1 - i)`; no further
        // than the look-back before the separation.
        let oldest = separation.saturating_sub(1 + Self::LOOKBACK as u64);
        let d_at = |i: u64| {
            let back = self.run.index.checked_sub(1)?.checked_sub(i)?;
            let x = self
                .ring
                .back(usize::try_from(back).ok().filter(|_| i >= oldest)?)?;
            Some(deviation.of(x) as i64)
        };
        let Some(last) = separation.checked_sub(1) else {
            return 0.0;
        };
        // Deviations signed so that the pulse's last sample (beyond the edge) is positive.
        let sign = if d_at(last).is_some_and(|d| d < 0) {
            -1
        } else {
            1
        };
        let pd = |i: u64| d_at(i).map(|d| sign * d);
        if let (Some(d0), Some(d1)) = (d_at(last), d_at(separation)) {
            if d1.abs() > a.edge_d && (d0 >= 0) != (d1 >= 0) {
                // Where the line between the two samples crosses zero.
                return (d0 as f64 / (d0 - d1) as f64 - 1.0) as f32;
            }
        }
        let mut flank = Flank::default();
        let mut j = 0u64;
        while let Some(i) = last.checked_sub(j) {
            match pd(i) {
                Some(y) if y <= a.flank_d && flank.add(-(j as i64), y) => j += 1,
                _ => break,
            }
        }
        // Positions relative to `last`: the first quiet sample is at +1.
        match flank.zero(false, 1.0, a.edge_d as f64) {
            Some(z) => (z - 1.0) as f32,
            None => match (pd(last), pd(separation)) {
                // A step down from beyond the flank level within one sample to a sample that
                // has not crossed zero: a foot steeper than the sampling resolves, or a law
                // whose force steps to zero (a damper's `c v` at separation). (Mirrored: the
                // last sample, and the two before it. Where the next sample has crossed, the
                // zero lies between the two, as the line between them says.)
                (Some(y0), Some(y1)) if y0 > a.flank_d && y1 > 0 => {
                    // (A sample the ring no longer holds is none: `steep_zero` refuses NaN.)
                    let at = |j: u64| {
                        last.checked_sub(j)
                            .and_then(pd)
                            .map_or(f32::NAN, |y| y as f32)
                    };
                    -1.0 - power_flank::steep_zero([y0 as f32, at(1), at(2)])
                }
                (Some(y0), Some(y1)) if y0 > a.flank_d => {
                    (crossing(y0 as f64, y1 as f64, 0.0) - 1.0) as f32
                }
                (Some(y0), Some(y1)) => {
                    (crossing(y0 as f64, y1 as f64, a.edge_d as f64) - 1.0) as f32
                }
                _ => 0.0,
            },
        }
    }
}

/// The falling foot's record takes `run` (its first sample at stream index `at`, after the
/// latest peak): from just after its last sample above the foot's top (its fraction of the
/// peak, [`power_flank::FOOT`]) on, where the record starts again. The samples above are
/// found a stride at a time, from the end, by their extremes.
pub(super) fn record_fall(a: &mut Active, run: &[i16], at: u64) {
    let sign: i64 = if a.peak_d >= 0 { 1 } else { -1 };
    let (w, s) = (a.base_n, a.base_sum);
    let top = (power_flank::FOOT * a.peak_d.unsigned_abs() as f32) as i64;
    let above = |x: i16| sign * (w * i64::from(x) - s) > top;
    let mut end = run.len();
    let mut cut = None;
    while end > 0 {
        let begin = end.saturating_sub(STRIDE);
        let chunk = run.get(begin..end).unwrap_or(&[]);
        let st = Stats::of(chunk);
        if above(if sign > 0 { st.max } else { st.min }) {
            cut = chunk.iter().rposition(|&x| above(x)).map(|i| begin + i + 1);
            break;
        }
        end = begin;
    }
    let from = match cut {
        Some(c) => {
            a.fall = Fall::new();
            a.fall_start = at + c as u64;
            c
        }
        None => 0,
    };
    a.fall.take(run.get(from..).unwrap_or(&[]), w, s, sign);
}

/// Samples first touch may lie from the middle of a jump's interval, where nothing narrowed
/// it ([`power_flank::JUMP_MIDDLE`]).
const JUMP_MIDDLE_REACH: f32 = 0.5;

/// First touch relative to the onset where the foot began before the sample before the
/// onset (`before`, within the edge level), clear of the previous contact: where that sample
/// stands out of the noise (over half the edge level) and lies with the onset's first two on
/// a power curve ([`power_flank::head_zero`]: within [`power_flank::HEAD_BEND`]) whose zero
/// lies in the interval before it (a foot whose first
/// sample stayed within the edge level: seed 001's law at 20 kS/s, that sample at 0.8 of
/// it, the onset's head too bent by the deceleration for a power curve of its own: taken for
/// a jump, `x_m` −8.6 %); else where the onset's three samples lie on a power curve
/// ([`power_flank::head_reach`]) whose zero lies in the interval before that sample and the
/// curve reads that sample there within half the edge level (its noise). A force rising from zero with touch
/// just before a sample the sampling put at the baseline (a Hertz foot at 20 kS/s, touch
/// 0.009 of a sample before it: the onset stepped past the flank level, the interval before
/// it was taken for a jump's and touch put in its middle, half a sample late, `x_m` 7.5 %
/// low). A jump onto a ramp (`c v0 + k v0 t`, the first sample `τ` after touch) has a quiet
/// sample before it where the head's line reads `c v0 − (1 − τ) k v0 dt`: refused where that
/// exceeds half the edge level, which a jump of a few samples' rise does (the jump's fit in
/// the analysis places it); a smaller jump may be taken for a ramp that began up to a sample
/// earlier, as [`power_flank::steep_zero`] says of its own line: where the head is a
/// straight line, its zero is given as a jump's too, with how far touch may lie from it
/// (as far as the onset; as far as the sample before it where that sample stands out of the
/// noise: its force says touch came earlier). Kelvin–Voigt's `c v0` equal to a sample's
/// `k v0 dt` at 20 kS/s, touch 0.05 of a sample after a sample, had it a sample early,
/// `x_m` +6.5 %, unflagged.
fn earlier_foot(a: &Active, head: [f32; 3]) -> Option<(f32, Option<f32>)> {
    let before = a.before_d? as f32;
    let [y0, y1, _] = head;
    let noise = 0.5 * a.edge_d as f32;
    // (Only a sample that stands out of the noise: a jump's quiet sample before it, a little
    // above the baseline, would put a jump onto a ramp on a curve within `HEAD_BEND` of the
    // jump's size.)
    let stands_out = before > noise;
    let on_foot = stands_out
        .then(|| power_flank::head_zero_line([before, y0, y1]))
        .flatten();
    let (zero, line) = match on_foot {
        // That sample on the foot, the onset's first two on its curve: its zero, from it.
        Some((zero, line)) => (zero - 1.0, line),
        None => {
            let reach = power_flank::head_reach(head, -1.0)?;
            (libm::fabsf(before - reach.at) <= noise).then_some((reach.zero, reach.line))?
        }
    };
    // A line's zero may be a jump's onto a ramp after it: before the sample before the onset
    // where that sample stands out (its force says touch came earlier), else before the onset.
    let reach = line.then_some(if stands_out { -1.0 - zero } else { -zero });
    ((-2.0..-1.0).contains(&zero) && zero >= a.touch_floor).then_some((zero, reach))
}
