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
use super::rise::{Fall, Rise};
use super::{Stream, FLANK_EDGES, REACH};
use crate::capture::{Sink, Summary};
use crate::report::{self, Status};
use crate::signal::baseline::Deviation;
use crate::signal::baseline::{Stats, STRIDE};
use crate::signal::flank::{crossing, Flank};
use crate::signal::power_flank;

/// The impact being followed.
pub(super) struct Active {
    /// Stream index of the window's first sample.
    first_index: u64,
    /// Samples captured before `first_index` (the filter's lead-in).
    filter_lead: u32,
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
    /// The falling foot: from where the signal last came down through the foot's top after
    /// the latest peak to the separation (so its fit sees the whole foot, averaged, for any
    /// split of the stream), and the stream index of its first sample.
    fall: Fall,
    fall_start: u64,
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
    /// The baseline moved to another level since the previous impact.
    level_change: bool,
    /// The signal did not come back, and the onset came more than the settle time before the
    /// peak: the pulse rode on drift.
    drift: bool,
    /// The rising flank's straight line reaches zero inside the previous impact's contact.
    line_in_previous: bool,
    /// The whole lobe before the onset: where it crosses the baseline (relative to the
    /// onset, samples), its samples and `Σ d` over them.
    lobe_touch: f32,
    lobe_len: u32,
    lobe_c: i64,
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
    /// Samples the in-impact loop takes at a time (a board's block, or half the ring).
    const CHUNK: usize = if PRE / 2 < 256 { PRE / 2 } else { 256 };
    /// How far behind a separation the falling flank is read from the ring: as far as the
    /// flanks reach and the ring is sure to hold, with the newest sample at most a chunk
    /// beyond the separation.
    const LOOKBACK: usize = (if REACH < PRE { REACH } else { PRE }).saturating_sub(Self::CHUNK + 2);

    /// The trigger fired at `self.index`: find the onset in the ring, fix the baseline from
    /// the samples before it, fit the rising flank, and replay the pre-trigger samples into
    /// the capture (if the sink has a buffer) and the running sums.
    pub(super) fn start<const CAP: usize>(
        &mut self,
        sink: &mut impl Sink<CAP>,
        trigger_x: i16,
        level_change: bool,
    ) {
        // The impact is measured from the level just before it: the baseline (which moved to
        // the level the signal settled at since it was learned, if it did: `level_change`).
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
        // The ring's samples within the flanks' reach, newest first.
        let ring = &self.ring;
        let back = |i: usize| ring.back(i).filter(|_| i < REACH);
        let pd = |i: usize| back(i).map(|x| sign * deviation.of(x) as i64);
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
        let line_in_previous = touch_offset < touch_floor;
        let touch_offset = touch_offset.max(touch_floor);
        // The whole samples from first touch to the onset (its foot below the edge level).
        let lead = libm::floorf(-touch_offset).max(0.0) as usize;
        let lead_c: i64 = (pulse..pulse + lead)
            .map_while(|i| back(i).map(|x| deviation.of(x) as i64))
            .sum();
        // The whole lobe: the samples before the onset still on the pulse's side of the
        // baseline (a pad's or felt's slow compression before the main pulse decelerates the
        // body too), back to where the signal crosses the baseline.
        let since_last =
            usize::try_from(self.index - self.window_end.min(self.index)).unwrap_or(usize::MAX);
        let lobe_limit = since_last.min(REACH).saturating_sub(pulse);
        let mut lobe_len = 0usize;
        let mut lobe_c = 0i64;
        while lobe_len < lobe_limit {
            match pd(pulse + lobe_len) {
                Some(y) if y > 0 => {
                    lobe_c += sign * y;
                    lobe_len += 1;
                }
                _ => break,
            }
        }
        // A lobe is a ramp from the baseline up to the edge level, not the signal sitting on
        // the pulse's side of the baseline (drag, an offset, noise): its newest quarter
        // averages at least half the edge level, its oldest quarter at most a quarter of it
        // (three samples or fewer are the crossing itself).
        let quarter = lobe_len / 4;
        if lobe_len > 3 {
            let mean = |from: usize| {
                let sum: i64 = (from..from + quarter).filter_map(pd).sum();
                sum.checked_div(quarter as i64).unwrap_or(0)
            };
            let (newest, oldest) = (mean(pulse), mean(pulse + lobe_len - quarter));
            if 2 * newest < edge_d || 4 * oldest > edge_d {
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
        // The rise so far: the onset to the newest sample.
        let mut rise = Rise::new();
        rise.take(0, pulse, |k| pd(pulse.saturating_sub(1 + k)).unwrap_or(0));
        // The window from `margin` samples before the onset (as far as the ring reaches, and
        // not into the previous impact's window).
        let reach = self.ring.len().min(REACH).min(CAP / 2);
        let margin = (pulse + self.hold as usize / 2)
            .min(reach)
            .min(since_last.max(pulse));
        let first_index = self.index - margin as u64;
        // With a CFC, the capture also takes the samples the filter needs to settle before
        // the onset (the true history, the previous impact's too): no streaming field sees
        // them.
        let lead = (pulse + self.filter_pad as usize)
            .min(self.ring.len())
            .min(CAP / 2)
            .saturating_sub(margin);
        let mut capture = sink.buffer();
        if let Some(c) = capture.as_mut() {
            c.clear();
        }
        let mut a = Active {
            first_index,
            filter_lead: lead as u32,
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
            fall: Fall::new(),
            fall_start: 0,
            sign,
            lead_c,
            pre_onset_c: 0,
            peak_d: 0,
            peak_index: self.index,
            total_c: 0,
            samples: 0,
            clipped: false,
            cut_at_start,
            level_change,
            drift: false,
            line_in_previous,
            lobe_touch,
            lobe_len: lobe_len.min(u32::MAX as usize) as u32,
            lobe_c,
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
        let (older, newer) = self.ring.last(lead + margin);
        // The lead-in into the capture only; the window into the sums too.
        let (lead_runs, window_runs) = split_runs(older, newer, lead);
        if let Some(c) = capture.as_mut() {
            for run in lead_runs {
                a.full |= c.extend(run) < run.len();
            }
        }
        let before_onset = margin.saturating_sub(pulse);
        let (w, s) = (base_n, base_sum);
        for run in window_runs {
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
        // The falling side so far: from the peak to the newest sample.
        let after_peak = self.index.saturating_sub(a.peak_index) as usize;
        let (older, newer) = self.ring.last(after_peak);
        record_fall(
            &mut a,
            older,
            self.index - (older.len() + newer.len()) as u64,
        );
        record_fall(&mut a, newer, self.index - newer.len() as u64);
        self.active = Some(a);
    }

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
            let (runs, _) = split_runs(older, newer, STRIDE);
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

    /// Feeds samples to the active impact until it ends; returns how many it used.
    pub(super) fn run_active<const CAP: usize>(
        &mut self,
        samples: &[i16],
        sink: &mut impl Sink<CAP>,
    ) -> usize {
        // At most a chunk at a time: a separation is located within a chunk of the newest
        // sample, so what the ring still holds behind it is the same for any split.
        let chunk = samples.get(..Self::CHUNK).unwrap_or(samples);
        let (used, end) = self.run_part(chunk, sink);
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
        // Where the rise's record closes (stream index) for a peak at stream index `p`, and
        // where it closed in this call if a later peak came after that.
        let onset = a.onset_index;
        let rise_closing = |p: u64| onset + Rise::closing(p.saturating_sub(onset));
        let mut peak_at = a.peak_index;
        let mut rise_closes: Option<u64> = None;
        let mut separation = a.separation;
        let open_at_start = separation.is_none();
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
                        // The rise's record closed if the samples went past its closing
                        // point for the peak so far before this one came (it lies at least
                        // 16 samples past that peak: a peak close after it cannot).
                        let near = new_peak.is_some_and(|(kp, _)| k - kp <= 16);
                        if !near
                            && rise_closes.is_none()
                            && start + k as u64 > rise_closing(peak_at)
                        {
                            rise_closes = Some(rise_closing(peak_at));
                        }
                        peak_at = start + k as u64;
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
        // The capture keeps the first CAP samples of the impact (a filter's lead-in gives way
        // to them).
        if a.captured && !a.full {
            a.full = match sink.buffer() {
                Some(c) => {
                    let held = c.held().len();
                    if a.filter_lead > 0 && held + kept.len() > CAP {
                        c.drop_front(a.filter_lead as usize);
                        a.filter_lead = 0;
                    }
                    c.extend(kept) < kept.len()
                }
                None => true,
            };
        }
        if let Some((k, d)) = new_peak {
            a.peak_d = d as i64;
            a.peak_index = start + k as u64;
        }
        // The falling foot: from a new peak on, or going on until the separation.
        let from = match new_peak {
            Some((k, _)) => Some(k),
            None if open_at_start => Some(0),
            None => None,
        };
        if let Some(from) = from {
            let to = separation.map_or(kept.len() as u64, |s| s.saturating_sub(start));
            let to = (to as usize).min(kept.len());
            let run = kept.get(from..to).unwrap_or(&[]);
            record_fall(a, run, start + from as u64);
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
            // Up to where it closes: for the last peak, unless it closed before it.
            let close = rise_closes.unwrap_or_else(|| rise_closing(a.peak_index));
            let n = (close + 1).saturating_sub(start).min(kept.len() as u64) as usize;
            let sign = a.sign;
            a.rise.take(start.saturating_sub(a.onset_index), n, |k| {
                kept.get(k).map_or(0, |&x| sign * deviation.of(x) as i64)
            });
            if start + kept.len() as u64 > close {
                a.rise.close();
            }
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
            self.end_unreturned(Status::TooLong, sink);
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
                    self.end_unreturned(Status::Settled, sink);
                }
                self.relearn_baseline();
                return;
            }
        };
        self.end(status, sink);
    }

    /// The active impact ends without the signal coming back to its baseline (`status`: too
    /// long, settled elsewhere, or the stream ended). A pulse whose onset came more than the
    /// settle time before its peak rode on drift or an orientation change: flagged `drift`.
    pub(super) fn end_unreturned<const CAP: usize>(
        &mut self,
        status: Status,
        sink: &mut impl Sink<CAP>,
    ) {
        let settle = u64::from(self.settle);
        if let Some(a) = self.active.as_mut() {
            a.drift = a.peak_index.saturating_sub(a.onset_index) > settle;
        }
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
    /// straight line's (`touch_offset`, `lead_c`); and whether it lies inside the previous
    /// impact's contact (then it is that contact's end).
    fn touch(&mut self, a: &Active) -> (f32, i64, bool) {
        let line = (a.touch_offset, a.lead_c, a.line_in_previous);
        let peak = a.peak_d.unsigned_abs() as f32;
        match self.rise_foot(a) {
            Some(foot) => {
                if foot.clear {
                    self.foot_power = Some(foot.power);
                }
                let touch = foot.zero.max(a.touch_floor);
                let lead = libm::floorf(-touch).max(0.0) as i64;
                let c = foot.sum(-lead, 0) * peak * a.sign as f32;
                (touch, c as i64, foot.zero < a.touch_floor)
            }
            None => line,
        }
    }

    /// First touch where the whole lobe begins, if that is earlier than `touch` (first touch,
    /// `Σ d` before the onset, inside the previous contact): a slow ramp below the edge
    /// level before the pulse (a pad or felt compressing) is part of the contact. Not where
    /// the lobe runs back more than twice the pulse's length above the edge level (the
    /// signal then sat on the pulse's side of the baseline, not rising to it), nor into the
    /// previous contact.
    fn lobe(&self, a: &Active, touch: (f32, i64, bool)) -> (f32, i64, bool) {
        let above = a
            .separation
            .unwrap_or(self.index)
            .saturating_sub(a.onset_index);
        let longer = a.lobe_touch < touch.0;
        let fits = u64::from(a.lobe_len) <= 2 * above && a.lobe_touch >= a.touch_floor;
        if longer && fits {
            (a.lobe_touch, a.lobe_c, false)
        } else {
            touch
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
    /// falling foot (the falling side's record up to the separation) is a power curve: its
    /// rising foot's power ([`power_flank`]).
    fn fall(&self, a: &Active, separation: u64) -> Option<(f32, i64, Option<f32>)> {
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
    /// extrapolated to zero, the zero crossing for a sign flip across the whole edge band,
    /// or the edge crossing between the last sample beyond the edge and the first within it.
    fn separation_offset(&self, a: &Active, separation: u64) -> f32 {
        let deviation = a.deviation();
        // The ring ends at `self.index - 1`: sample `i` is `back(index - 1 - i)`; no further
        // than the look-back before the separation.
        let oldest = separation.saturating_sub(1 + Self::LOOKBACK as u64);
        let d_at = |i: u64| {
            let back = self.index.checked_sub(1)?.checked_sub(i)?;
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
        let touch = self.touch(&a);
        let (touch_offset, lead_c, in_previous) = self.lobe(&a, touch);
        let touch = a.onset_index as f64 + touch_offset as f64;
        let (v0, bounce) = self.train.approach(&self.scene, touch, self.v0);
        let summary = Summary {
            index: self.counters.impacts.min(u32::MAX as u64) as u32,
            status,
            clipped: a.clipped,
            cut_at_start: a.cut_at_start,
            level_change: a.level_change,
            drift: a.drift,
            in_previous,
            first_index: a.first_index,
            filter_lead: a.filter_lead,
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
                // With a CFC the capture goes on after the window for the filter's padding
                // after the contact (as far as it holds), unless nothing more will come.
                let contact_end = a.separation.unwrap_or(summary.end_index);
                let until = contact_end.saturating_add(u64::from(self.filter_pad));
                let more = !matches!(status, Status::StreamEnded | Status::Gap);
                if self.filter_pad > 0 && more && !a.full && !c.is_full() && until > self.index {
                    self.tail = Some(until);
                } else {
                    sink.captured(&self.scene);
                    self.handed_over = true;
                }
            }
            _ => {
                self.counters.analyses_skipped += 1;
                sink.skipped(&report::streaming(&summary, &self.scene));
            }
        }
    }
}

/// The falling foot's record takes `run` (its first sample at stream index `at`, after the
/// latest peak): from just after its last sample above the foot's top (its fraction of the
/// peak, [`power_flank::FOOT`]) on, where the record starts again. The samples above are
/// found a stride at a time, from the end, by their extremes.
fn record_fall(a: &mut Active, run: &[i16], at: u64) {
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

/// Splits the two runs `first`, `second` (one sequence) at position `at`: the runs before it
/// and the runs from it on.
fn split_runs<'a>(
    first: &'a [i16],
    second: &'a [i16],
    at: usize,
) -> ([&'a [i16]; 2], [&'a [i16]; 2]) {
    let (a0, a1) = first.split_at(at.min(first.len()));
    let rest = at.saturating_sub(first.len());
    let (b0, b1) = second.split_at(rest.min(second.len()));
    ([a0, b0], [a1, b1])
}
