//! The stream inside an impact: from the trigger (onset, rising flank, pre-trigger replay)
//! through the in-impact loop (exact sums, peak, separation, end) to the hand-over of the
//! summary.
//!
//! An impact ends when the signal has stayed within the edge level for `hold` samples; or,
//! once it has come back to the baseline for at least an eighth of the hold (not a ringing
//! crossing), when a new hit in the same direction crosses the trigger level (the next impact
//! starts there); or when it settles at a new level for `hold` samples
//! (rest, free fall: the baseline is learned again, and a level change without a pulse is no
//! impact at all); or for the reasons of [`Status`].

use super::level::LevelWatch;
use super::rise::Rise;
use super::{Stream, FLANK_EDGES};
use crate::capture::{Sink, Summary};
use crate::report::{self, Status};
use crate::signal::baseline::Deviation;
use crate::signal::baseline::{Stats, STRIDE};
use crate::signal::flank::{crossing, Flank};
use crate::signal::power_flank;

/// The impact being followed.
pub(super) struct Active {
    /// Stream index of the capture's first sample.
    first_index: u64,
    /// Stream index of the sample that fired the trigger.
    trigger_index: u64,
    onset_index: u64,
    touch_offset: f32,
    /// The earliest first touch relative to the onset (the previous contact's end), samples.
    touch_floor: f32,
    base_sum: i64,
    base_n: i64,
    /// Edge level in units of `d = W x - S`.
    edge_d: i64,
    /// Flank level in units of `d`.
    flank_d: i64,
    /// The trigger thresholds in units of `d` (a sample fires when `d > d_hi` or `d < d_lo`).
    d_hi: i32,
    d_lo: i32,
    quiet: u32,
    /// Since the latest peak, the signal stayed within the edge level for at least an
    /// eighth of the hold (so a new hit is a new impact, not ringing).
    returned: bool,
    /// Stream index of the first sample back within the edge level (or across it, a sign
    /// flip) after the peak (separation: later ringing does not move it unless it brings a
    /// new peak).
    separation: Option<u64>,
    /// `Σ d` from `first_index` to the separation (exclusive).
    separation_c: i64,
    /// The separation, its offset and the falling foot's `Σ d` beyond it (where the foot is
    /// a power curve: [`Stream::fall`], else [`Stream::separation_offset`] and 0), found while
    /// its flank was still in the ring (a long ring-down after it would push it out).
    separation_at: Option<(u64, f32, i64)>,
    /// The rising side, for the foot's fit at the end; the pulse's sign; `Σ d` over the whole
    /// samples from the straight-line first touch to the onset.
    rise: Rise,
    sign: i64,
    lead_c: i64,
    /// `Σ d` over the samples before the onset.
    pre_onset_c: i64,
    peak_d: i64,
    peak_index: u64,
    total_c: i64,
    /// Samples since `first_index`.
    samples: u64,
    clipped: bool,
    /// The walk back to the onset reached the stream's first sample still beyond the edge.
    cut_at_start: bool,
    /// The sink gave a buffer for this impact.
    captured: bool,
    /// The buffer overflowed.
    full: bool,
    /// The pulse was already under way when the last gap ended: its start is unknown.
    began_in_gap: bool,
    /// Stream index just after the latest sample within the edge level.
    last_quiet: u64,
    /// Where the impact's window ends if not at the current position (a next hit began
    /// after the last quiet sample).
    end_at: Option<u64>,
    level: LevelWatch,
}

impl Active {
    pub(super) fn deviation(&self) -> Deviation {
        Deviation::new(self.base_sum, self.base_n)
    }
}

/// How a run of samples ended the impact.
enum End {
    /// Back within the edge level for the hold time.
    Quiet,
    /// A new hit after separation: the next impact starts at the sample not used.
    NextHit,
    /// Settled at a new level.
    Settled(super::level::Settled),
}

impl<const PRE: usize> Stream<PRE> {
    /// The trigger fired at `self.index`: find the onset in the ring, fix the baseline from
    /// the samples before it, fit the rising flank, and replay the pre-trigger samples into
    /// the capture (if the sink has a buffer) and the running sums.
    pub(super) fn start<const CAP: usize>(&mut self, sink: &mut impl Sink<CAP>, trigger_x: i16) {
        let (base_sum, base_n) = self.baseline.rational();
        let deviation = Deviation::new(base_sum, base_n);
        let edge_d = (self.edge_counts * base_n as f32) as i64;
        let (lo, hi) = self.current_thresholds();
        let d_hi = hi as i64 * base_n - base_sum;
        let d_lo = lo as i64 * base_n - base_sum;
        // The flank level: FLANK_EDGES edges, or just under the trigger thresholds.
        let flank_d = (FLANK_EDGES * edge_d).min(d_hi.min(-d_lo)).max(edge_d);
        // Deviations signed so that the pulse (the trigger sample's direction) is positive:
        // samples of the other sign just before it are ringing (an anti-alias filter's
        // before a sharp edge), not the pulse.
        let sign: i64 = if deviation.of(trigger_x) >= 0 { 1 } else { -1 };
        let ring = &self.ring;
        let pd = |i: usize| ring.back(i).map(|x| sign * deviation.of(x) as i64);
        // Walk back from the newest sample while it is beyond the edge level that way.
        let mut pulse = 0usize;
        while let Some(y) = pd(pulse) {
            if y <= edge_d {
                break;
            }
            pulse += 1;
        }
        // The rising flank from the onset forwards (the trigger sample, next, ends it).
        let mut flank = Flank::default();
        for k in 0..pulse {
            match pd(pulse - 1 - k) {
                Some(y) if y <= flank_d && flank.add(k as i64, y) => {}
                _ => break,
            }
        }
        let onset_index = self.index - pulse as u64;
        let cut_at_start = onset_index == 0 && pd(pulse).is_none();
        let touch_offset = match flank.zero(true, -1.0, edge_d as f64) {
            Some(z) => z as f32,
            // The edge crossing between the last sample before the pulse and the onset (the
            // trigger sample itself when the pulse starts there).
            None => {
                let onset = match pulse.checked_sub(1) {
                    Some(i) => pd(i),
                    None => Some(sign * deviation.of(trigger_x) as i64),
                };
                match (pd(pulse), onset) {
                    (Some(y0), Some(y1)) => {
                        (crossing(y0 as f64, y1 as f64, edge_d as f64) - 1.0) as f32
                    }
                    _ => 0.0,
                }
            }
        };
        // First touch cannot come before the previous contact ended: reports never overlap.
        let earliest = self.last_end as f64 - onset_index as f64;
        let touch_floor = earliest.min(0.0) as f32;
        let touch_offset = touch_offset.max(touch_floor);
        // The whole samples from first touch to the onset (its foot below the edge level).
        let lead = libm::floorf(-touch_offset).max(0.0) as usize;
        let lead_c: i64 = (pulse..pulse + lead)
            .map_while(|i| ring.back(i).map(|x| deviation.of(x) as i64))
            .sum();
        // The rise so far: the onset to the newest sample.
        let mut rise = Rise::new();
        rise.take(0, pulse, pulse as u64, |k| {
            pd(pulse.saturating_sub(1 + k)).unwrap_or(0)
        });
        // Capture from `margin` samples before the onset (as far as the ring reaches, and not
        // into the previous impact's window).
        let since_last =
            usize::try_from(self.index - self.window_end.min(self.index)).unwrap_or(usize::MAX);
        // With a CFC filter, the samples it needs to settle before the onset.
        let pad = self.scene.cfc.map_or(0, |c| {
            c.padding_samples(self.scene.calibration.sample_rate_hz) as usize
        });
        let margin = (pulse + (self.hold as usize / 2).max(pad))
            .min(self.ring.len())
            .min(CAP / 2)
            .min(since_last.max(pulse));
        let first_index = self.index - margin as u64;
        let mut capture = sink.buffer();
        if let Some(c) = capture.as_mut() {
            c.clear();
        }
        let mut a = Active {
            first_index,
            trigger_index: self.index,
            onset_index,
            touch_offset,
            touch_floor,
            base_sum,
            base_n,
            edge_d,
            flank_d,
            d_hi: d_hi.clamp(i32::MIN as i64, i32::MAX as i64) as i32,
            d_lo: d_lo.clamp(i32::MIN as i64, i32::MAX as i64) as i32,
            quiet: 0,
            returned: false,
            separation: None,
            separation_c: 0,
            separation_at: None,
            rise,
            sign,
            lead_c,
            pre_onset_c: 0,
            peak_d: 0,
            peak_index: self.index,
            total_c: 0,
            samples: 0,
            clipped: false,
            cut_at_start,
            captured: capture.is_some(),
            full: false,
            // The walk back reached the gap: the pulse began while samples were lost.
            began_in_gap: self.gap_end.is_some_and(|g| onset_index <= g),
            last_quiet: onset_index,
            end_at: None,
            level: LevelWatch::new(
                base_n,
                base_sum,
                self.edge_counts,
                self.scene.clip_counts,
                u64::from(self.settle),
            ),
        };
        let (clip_lo, clip_hi) = self.scene.clip_counts;
        let (older, newer) = self.ring.last(margin);
        let before_onset = margin.saturating_sub(pulse);
        let (w, s) = (base_n, base_sum);
        for run in [older, newer] {
            if let Some(c) = capture.as_mut() {
                a.full |= c.extend(run) < run.len();
            }
            // A stride at a time (split at the onset), from the stride statistics: Σd
            // exactly, the peak from the extremes (its first sample found only when it
            // beats the peak so far), the rails from min and max.
            let mut rest = run;
            while !rest.is_empty() {
                let pos = a.samples as usize;
                let to_onset = before_onset.checked_sub(pos).filter(|&n| n > 0);
                let n = rest.len().min(STRIDE).min(to_onset.unwrap_or(usize::MAX));
                let (part, after) = rest.split_at(n);
                let st = Stats::of(part);
                let c = w * i64::from(st.sum) - n as i64 * s;
                a.total_c += c;
                if to_onset.is_some() {
                    a.pre_onset_c += c;
                }
                let extreme = (deviation.of(st.max) as i64).max(-(deviation.of(st.min) as i64));
                if extreme.unsigned_abs() > a.peak_d.unsigned_abs() {
                    for (k, &x) in part.iter().enumerate() {
                        let d = deviation.of(x) as i64;
                        if d.unsigned_abs() > a.peak_d.unsigned_abs() {
                            a.peak_d = d;
                            a.peak_index = a.first_index + (pos + k) as u64;
                        }
                    }
                }
                a.clipped |= st.min <= clip_lo || st.max >= clip_hi;
                a.samples += n as u64;
                rest = after;
            }
        }
        self.active = Some(a);
    }

    /// Feeds samples to the active impact until it ends; returns how many it used.
    pub(super) fn run_active<const CAP: usize>(
        &mut self,
        samples: &[i16],
        sink: &mut impl Sink<CAP>,
    ) -> usize {
        let (used, end) = self.run_part(samples, sink);
        if let Some(end) = end {
            self.finish_impact(end, sink);
        }
        used
    }

    /// The in-impact loop: returns how many samples it took and how the impact ended, if it
    /// did.
    ///
    /// The level watch runs first, over whole strides of raw samples: where the signal
    /// settles (if it does) is known before the per-sample loop, which stops there. The
    /// running state lives in locals (the compiler cannot keep fields of `self` in registers
    /// across the capture's push) and is written back once per call.
    fn run_part<const CAP: usize>(
        &mut self,
        samples: &[i16],
        sink: &mut impl Sink<CAP>,
    ) -> (usize, Option<End>) {
        let hold = self.hold;
        // A return to the baseline that lets a new hit start a new impact.
        let min_gap = (hold / 8).max(2);
        let first_mark = min_gap.min(hold);
        let (lo, hi) = self.scene.clip_counts;
        let max_samples = self.max_samples;
        let Some(a) = self.active.as_mut() else {
            return (0, None);
        };
        // At most the samples that keep the impact within its longest duration.
        let room = max_samples
            .saturating_sub(a.samples)
            .min(samples.len() as u64) as usize;
        let samples = samples.get(..room).unwrap_or(&[]);
        let scan = a.level.scan(samples);
        let samples = samples.get(..scan.used).unwrap_or(&[]);
        let deviation = a.deviation();
        // edge_d >= 0: the scene's edge level is positive (validated).
        let edge = a.edge_d.clamp(0, u32::MAX as i64) as u32;
        let start = a.first_index + a.samples;
        let mut peak_abs = a.peak_d.unsigned_abs().min(u32::MAX as u64) as u32;
        let mut peak_positive = a.peak_d >= 0;
        let mut new_peak: Option<(usize, i32)> = None;
        let mut separation = a.separation;
        let mut separation_c = a.separation_c;
        let mut quiet = a.quiet;
        // Back at the baseline long enough since the peak for a new hit to be a new impact.
        let mut returned = a.returned;
        // `k` after the latest quiet sample before a louder one, in this call.
        let mut last_quiet_k: Option<usize> = None;
        let mut sum: i64 = 0;
        let mut used = samples.len();
        let mut ended = None;
        let (d_hi, d_lo) = (a.d_hi, a.d_lo);
        let n = samples.len();
        let mut k = 0;
        // Alternating stretches of samples beyond the edge level (loud) and within it
        // (quiet), each in a tight loop; what is rare (a new peak, a sign flip, a new hit,
        // the hold reached) leaves the tight loop for the full test.
        'scan: while k < n {
            // Loud: `e` is the deviation signed so that the peak's direction is positive.
            // Anything that may matter lies outside `lo..=hi`: a new peak either way, a sign
            // flip while there is no separation, a new hit beyond the trigger once the
            // signal has returned.
            let marks = |peak_abs: u32, positive: bool, returned: bool, open: bool| {
                let peak = peak_abs.min(i32::MAX as u32) as i32;
                let trigger = if positive {
                    d_hi
                } else {
                    d_lo.saturating_neg()
                };
                let hi = if returned { trigger.min(peak) } else { peak };
                let lo = if open { 0 } else { -peak };
                (if positive { 1 } else { -1 }, trigger, lo, hi)
            };
            let (mut sign, mut trigger, mut lo, mut hi) =
                marks(peak_abs, peak_positive, returned, separation.is_none());
            while let Some(&x) = samples.get(k) {
                let d = deviation.of(x);
                let abs = d.unsigned_abs();
                if abs <= edge {
                    break;
                }
                let e = d.wrapping_mul(sign);
                if e > hi || e < lo {
                    if returned && e > trigger {
                        // Back at the baseline, then a new hit the same way beyond the
                        // trigger: the next impact starts with this sample.
                        ended = Some(End::NextHit);
                        used = k;
                        break 'scan;
                    }
                    if abs > peak_abs {
                        peak_abs = abs;
                        peak_positive = d >= 0;
                        new_peak = Some((k, d));
                        separation = None;
                        returned = false;
                    } else if separation.is_none() && e < 0 {
                        // Across the whole band between two samples (a sign flip): the
                        // signal came back between them.
                        separation = Some(start + k as u64);
                        separation_c = a.total_c + sum;
                    }
                    (sign, trigger, lo, hi) =
                        marks(peak_abs, peak_positive, returned, separation.is_none());
                }
                if quiet > 0 {
                    last_quiet_k = Some(k);
                    quiet = 0;
                }
                sum += d as i64;
                k += 1;
            }
            // Quiet: the first quiet sample after the peak is the separation.
            if k < n && separation.is_none() {
                separation = Some(start + k as u64);
                separation_c = a.total_c + sum;
            }
            while let Some(&x) = samples.get(k) {
                let d = deviation.of(x);
                if d.unsigned_abs() > edge {
                    break;
                }
                quiet += 1;
                sum += d as i64;
                if quiet >= first_mark {
                    returned |= quiet >= min_gap;
                    if quiet >= hold && start + k as u64 > a.trigger_index {
                        ended = Some(End::Quiet);
                        used = k + 1;
                        break 'scan;
                    }
                }
                k += 1;
            }
        }
        let kept = samples.get(..used).unwrap_or(&[]);
        // Only when the samples reach a rail does it matter which of them did.
        if scan.min <= lo || scan.max >= hi {
            a.clipped |= kept.iter().any(|&x| x <= lo || x >= hi);
        }
        // The capture keeps the first CAP samples of the impact.
        if a.captured && !a.full {
            a.full = match sink.buffer() {
                Some(c) => c.extend(kept) < kept.len(),
                None => true,
            };
        }
        if let Some((k, d)) = new_peak {
            a.peak_d = d as i64;
            a.peak_index = start + k as u64;
        }
        // Just after the latest quiet sample: the end of the run of quiet samples that
        // is still going, or the one before the latest louder sample.
        if quiet > 0 {
            a.last_quiet = start + used as u64;
        } else if let Some(k) = last_quiet_k {
            a.last_quiet = start + k as u64;
        }
        if matches!(ended, Some(End::NextHit)) {
            a.end_at = Some(a.last_quiet);
        }
        if !a.rise.done() {
            let sign = a.sign;
            a.rise.take(
                start.saturating_sub(a.onset_index),
                kept.len(),
                a.peak_index.saturating_sub(a.onset_index),
                |k| kept.get(k).map_or(0, |&x| sign * deviation.of(x) as i64),
            );
        }
        a.total_c += sum;
        a.separation = separation;
        a.separation_c = separation_c;
        a.quiet = quiet;
        a.returned = returned;
        a.samples += used as u64;
        if ended.is_none() {
            ended = scan.settled.map(End::Settled);
        }
        let too_long = ended.is_none() && a.samples >= max_samples;
        // The ring keeps following the stream: the separation flank and the next impact's
        // pre-trigger history come from it.
        self.keep(kept);
        self.locate_separation();
        if too_long {
            self.end(Status::TooLong, sink);
            return (used, None);
        }
        (used, ended)
    }

    /// The impact ended (see [`End`]): hand it over, or, for a level change without a pulse,
    /// drop it; learn the baseline again after a level change.
    fn finish_impact<const CAP: usize>(&mut self, end: End, sink: &mut impl Sink<CAP>) {
        let Some(a) = self.active.as_mut() else {
            return;
        };
        let status = match end {
            End::Quiet | End::NextHit => {
                if a.began_in_gap {
                    Status::Gap
                } else if a.full {
                    Status::BufferFull
                } else {
                    Status::Complete
                }
            }
            End::Settled(s) => {
                // The flat run began `run_n` samples ago: the contact ended there at the
                // latest.
                if a.separation.is_none() {
                    a.separation = Some(self.index - s.run_n);
                    a.separation_c = a.total_c - s.run_d;
                }
                // A pulse is a peak beyond the trigger from the new level too; else the
                // "impact" was the level change itself.
                let trigger_d = a.d_hi.min(-a.d_lo) as f64;
                if libm::fabs(a.peak_d as f64 - s.level_d) <= trigger_d {
                    self.active = None;
                    self.counters.level_changes += 1;
                } else {
                    self.end(Status::Settled, sink);
                }
                self.relearn_baseline();
                return;
            }
        };
        self.end(status, sink);
    }

    /// Locates a new separation while its flank is in the ring (just after the samples that
    /// set it were kept).
    #[inline(never)]
    fn locate_separation(&mut self) {
        let Some(a) = self.active.as_ref() else {
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
            self.foot_power = clear;
        }
        if let Some(a) = self.active.as_mut() {
            a.separation_at = Some((s, offset, tail));
        }
    }

    /// First touch relative to the onset and `Σ d` over the foot before the onset: where the
    /// rising foot, fitted as a power curve ([`power_flank`]), reaches zero force, else the
    /// straight line's (`touch_offset`, `lead_c`).
    fn touch(&mut self, a: &Active) -> (f32, i64) {
        let line = (a.touch_offset, a.lead_c);
        let peak = a.peak_d.unsigned_abs() as f32;
        match self.rise_foot(a) {
            Some(foot) => {
                if foot.clear {
                    self.foot_power = Some(foot.power);
                }
                let touch = foot.zero.max(a.touch_floor);
                let lead = libm::floorf(-touch).max(0.0) as i64;
                let c = foot.sum(-lead, 0) * peak * a.sign as f32;
                (touch, c as i64)
            }
            None => line,
        }
    }

    /// The rising foot (from the rise record) fitted as a power curve, if it is one.
    fn rise_foot(&self, a: &Active) -> Option<power_flank::Foot> {
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
            prior: self.foot_power,
        };
        power_flank::zero(points, true, -1.0, a.edge_d as f32 / peak, choice)
    }

    /// The separation relative to `separation` and `Σ d` over the foot beyond it, where the
    /// falling foot (in the ring) is a power curve: its rising foot's power
    /// ([`power_flank`]).
    fn fall(&self, a: &Active, separation: u64) -> Option<(f32, i64, Option<f32>)> {
        // (None for a zero peak, too.)
        let rise = self.rise_foot(a)?;
        let deviation = a.deviation();
        let peak = a.peak_d.unsigned_abs() as f32;
        let sign: i64 = if a.peak_d >= 0 { 1 } else { -1 };
        // `y(k)`: sample `separation - 1 - k` over the peak (the ring ends at `index - 1`).
        let y = |k: u64| {
            let back = self.index.checked_sub(separation)?.checked_add(k)?;
            let x = self.ring.back(usize::try_from(back).ok()?)?;
            Some((sign * deviation.of(x) as i64) as f32 / peak)
        };
        let limit = separation
            .saturating_sub(a.peak_index + 1)
            .min(self.ring.len() as u64);
        // The foot's end to within `step` (at most 256 looks).
        let step = (limit / 256).max(1);
        let mut len = 0u64;
        while len < limit && y(len).is_some_and(|v| v <= power_flank::FOOT) {
            len += step;
        }
        let len = len.min(limit);
        let stride = len.div_ceil(power_flank::MAX_FOOT_POINTS as u64).max(1);
        let points = (0..len).step_by(stride as usize).filter_map(|k| {
            let v = y(k)?;
            (v > 0.0).then_some((-(k as f32) - 1.0, v))
        });
        let choice = power_flank::Choice::Only(rise.power);
        let foot = power_flank::zero(points, false, 0.0, a.edge_d as f32 / peak, choice)?;
        let tail = libm::ceilf(foot.zero).max(0.0) as i64;
        let c = foot.sum(0, tail) * peak * sign as f32;
        Some((foot.zero, c as i64, rise.clear.then_some(rise.power)))
    }

    /// The separation relative to `separation_index`: the falling flank (from the ring)
    /// extrapolated to zero, the zero crossing for a sign flip across the whole edge band,
    /// or the edge crossing between the last sample beyond the edge and the first within it.
    fn separation_offset(&self, a: &Active, separation: u64) -> f32 {
        let deviation = a.deviation();
        // The ring ends at `self.index - 1`: sample `i` is `back(index - 1 - i)`.
        let d_at = |i: u64| {
            let back = self.index.checked_sub(1)?.checked_sub(i)?;
            let x = self.ring.back(usize::try_from(back).ok()?)?;
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
                (Some(y0), Some(y1)) => {
                    (crossing(y0 as f64, y1 as f64, a.edge_d as f64) - 1.0) as f32
                }
                _ => 0.0,
            },
        }
    }

    /// Hands the active impact over and returns to idle.
    pub(super) fn end<const CAP: usize>(&mut self, status: Status, sink: &mut impl Sink<CAP>) {
        let Some(a) = self.active.take() else { return };
        self.thresholds = None;
        self.baseline.restart_stride();
        self.last_end = a.separation.unwrap_or(self.index);
        self.window_end = a.end_at.unwrap_or(self.index);
        let level = self.baseline.mean() as f64;
        if let Some(f) = self.trigger_filter.as_mut() {
            f.reset(level);
        }
        // The separation located while its flank was in the ring, else from the ring now.
        let (separation_offset, tail_c) = match (a.separation, a.separation_at) {
            (Some(s), Some((at, offset, tail))) if at == s => (offset, tail),
            (Some(s), _) => (self.separation_offset(&a, s), 0),
            (None, _) => (0.0, 0),
        };
        // A rising foot that is a power curve puts first touch where it reaches zero force;
        // the contact's Δv runs from touch to separation, the feet below the edge included.
        let (touch_offset, lead_c) = self.touch(&a);
        let touch = a.onset_index as f64 + touch_offset as f64;
        let (v0, bounce) = self.train.approach(&self.scene, touch, self.v0);
        let summary = Summary {
            index: self.counters.impacts.min(u32::MAX as u64) as u32,
            status,
            clipped: a.clipped,
            cut_at_start: a.cut_at_start,
            first_index: a.first_index,
            onset_index: a.onset_index,
            touch_offset,
            separation_index: a.separation,
            separation_offset,
            end_index: a.end_at.unwrap_or(self.index),
            base_sum: a.base_sum,
            base_n: a.base_n,
            peak_d: a.peak_d,
            peak_index: a.peak_index,
            total_c: a.total_c,
            contact_c: a
                .separation
                .map(|_| a.separation_c - a.pre_onset_c + lead_c + tail_c),
            v0_m_s: v0,
            bounce: bounce.into(),
        };
        self.train.ended(&summary, &self.scene);
        self.counters.impacts += 1;
        if status != Status::Complete {
            self.counters.incomplete += 1;
        }
        if status == Status::TooLong {
            // The baseline moved (or the sensor is stuck): learn it again.
            self.relearn_baseline();
        }
        match sink.buffer() {
            Some(c) if a.captured => {
                c.set_summary(summary);
                sink.captured(&self.scene);
            }
            _ => {
                self.counters.analyses_skipped += 1;
                sink.skipped(&report::streaming(&summary, &self.scene));
            }
        }
    }
}
