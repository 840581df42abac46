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

use super::active::{Active, FlankTouch};
use super::feet::{record_fall, OnsetWalk};
use super::level::LevelWatch;
use super::rise::{Fall, Rise};
use super::walk::{End, Levels, Walk};
use super::{Stream, FLANK_EDGES, REACH};
use crate::capture::{Sink, Summary};
use crate::report::{self, Status};
use crate::signal::baseline::Deviation;
use crate::signal::baseline::{Stats, STRIDE};
use crate::signal::flank::{crossing, Flank};

impl<const PRE: usize> Stream<PRE> {
    /// The trigger fired at `self.run.index`: find the onset in the ring, fix the baseline from
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
        // The record's first zero, learned from a few strides the signal never came back to
        // (a record that starts on a ramp into its pulse): not the sensor's. (A level the
        // signal settled at, a free fall's, is learned from what it held, however short.)
        let counters = self.run.counters;
        let unconfirmed =
            counters.impacts == 0 && counters.level_changes == 0 && self.baseline.unconfirmed();
        let deviation = Deviation::new(base_sum, base_n);
        let edge_d = (self.limits.edge_counts * base_n as f32) as i64;
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
        let back = |i: usize| ring.back(i).filter(|_| i < REACH);
        let pd = |i: usize| back(i).map(|x| sign * deviation.of(x) as i64);
        let (pulse, touch_offset, flank_touch) =
            self.rising_flank(sign, deviation, edge_d, flank_d, trigger_x);
        let onset_index = self.run.index - pulse as u64;
        let cut_at_start = onset_index == 0 && pd(pulse).is_none();
        // First touch cannot come before the previous contact ended: reports never overlap.
        let earliest = self.run.last_end as f64 - onset_index as f64;
        let touch_floor = earliest.min(0.0) as f32;
        let line_in_previous = touch_offset < touch_floor;
        let touch_offset = touch_offset.max(touch_floor);
        // The whole samples from first touch to the onset (its foot below the edge level).
        let line_lead = libm::floorf(-touch_offset).max(0.0) as usize;
        let lead_c: i64 = (pulse..pulse + line_lead)
            .map_while(|i| back(i).map(|x| deviation.of(x) as i64))
            .sum();
        let since_last = usize::try_from(self.run.index - self.run.window_end.min(self.run.index))
            .unwrap_or(usize::MAX);
        let lobe = self.lobe_before(OnsetWalk {
            pulse,
            sign,
            deviation,
            edge_d,
            trigger_x,
            since_last,
            after_impact: self.run.counters.impacts > 0,
        });
        // The rise so far: the onset to the newest sample.
        let mut rise = Rise::new();
        rise.take(0, pulse, |k| pd(pulse.saturating_sub(1 + k)).unwrap_or(0));
        // The window from `margin` samples before the onset (as far as the ring reaches, and
        // not into the previous impact's window).
        let half_capture = self.capture_len::<CAP>() / 2;
        let reach = self.ring.len().min(REACH).min(half_capture);
        let margin = (pulse + self.limits.hold as usize / 2)
            .min(reach)
            .min(since_last.max(pulse));
        let first_index = self.run.index - margin as u64;
        // With a CFC, the capture also takes the samples the filter needs to settle before
        // the onset (the true history, the previous impact's too): no streaming field sees
        // them.
        let lead = (pulse + self.limits.filter_pad as usize)
            .min(self.ring.len())
            .min(half_capture)
            .saturating_sub(margin);
        let mut capture = sink.buffer();
        if let Some(c) = capture.as_mut() {
            c.clear();
        }
        let mut a = Active {
            first_index,
            filter_lead: lead as u32,
            trigger_index: self.run.index,
            onset_index,
            touch_offset,
            flank_touch,
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
            peak_index: self.run.index,
            total_c: 0,
            samples: 0,
            clipped: false,
            cut_at_start,
            level_change,
            // A ramp into the pulse from beyond the flanks' reach, or a baseline the signal
            // never came back to: it rode on it.
            drift: lobe.cut || unconfirmed,
            line_in_previous,
            lobe_touch: lobe.touch,
            lobe_c: lobe.c,
            lobe_in_previous: lobe.in_previous,
            before_d: lobe.before.and_then(|d| i32::try_from(d).ok()),
            captured: capture.is_some(),
            full: false,
            // The walk back reached the gap: the pulse began while samples were lost.
            began_in_gap: self.run.gap_end.is_some_and(|g| onset_index <= g),
            last_quiet: onset_index,
            end_at: None,
            level: LevelWatch::new(
                base_n,
                base_sum,
                self.limits.edge_counts,
                self.scene.clip_counts,
                u64::from(self.limits.settle),
            ),
        };
        let before_onset = margin.saturating_sub(pulse);
        self.replay_window(&mut a, capture, lead, margin, before_onset, deviation);
        // The falling side so far: from the peak to the newest sample.
        let after_peak = self.run.index.saturating_sub(a.peak_index) as usize;
        let (older, newer) = self.ring.last(after_peak);
        record_fall(
            &mut a,
            older,
            self.run.index - (older.len() + newer.len()) as u64,
        );
        record_fall(&mut a, newer, self.run.index - newer.len() as u64);
        self.start_online(&a, deviation, pulse, before_onset, line_lead);
        self.run.active = Some(a);
    }

    /// The kinematics' sums from the onset (`pulse` samples back, `before_onset` into the
    /// window, the line's touch `line_lead` whole samples before it), towards the crush a
    /// provisional approach speed gives (the one known now: the scene's, or a bounce's from
    /// the line's touch).
    fn start_online(
        &mut self,
        a: &Active,
        deviation: Deviation,
        pulse: usize,
        before_onset: usize,
        line_lead: usize,
    ) {
        let scene = &self.scene;
        let touch = a.onset_index as f64 + a.touch_offset as f64;
        let v0 = self
            .run
            .train
            .approach(scene, touch, self.run.v0, self.run.v0_measured)
            .v0_m_s;
        let c_stop = v0.and_then(|v0| {
            crate::report::motion::Scale::new(v0 as f64, scene, a.base_n, 0.0).c_stop()
        });
        let lobe_lead = libm::floorf(-a.lobe_touch).max(0.0) as usize;
        self.run.online.start(
            deviation,
            crate::report::motion::motion_deviation(a.base_sum, a.base_n, scene),
            &self.ring,
            pulse,
            before_onset,
            [line_lead, lobe_lead],
            c_stop,
            // The largest |d| of the window so far (the pulse's included).
            a.peak_d.saturating_abs(),
        );
    }

    /// The pulse's rising flank, walking back from the newest sample (the trigger's) while
    /// it is beyond the edge level the pulse's way (`sign`): how many samples the pulse has
    /// risen for (the onset is that many back) and first touch, fractional samples from the
    /// onset (the flank's line through zero, or the edge crossing before the onset, or the
    /// middle of the sample interval a step past the flank level crossed), and which of
    /// these it is.
    fn rising_flank(
        &self,
        sign: i64,
        deviation: Deviation,
        edge_d: i64,
        flank_d: i64,
        trigger_x: i16,
    ) -> (usize, f32, FlankTouch) {
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
        let mut how = if flank.len() < 3 {
            FlankTouch::Crossing
        } else {
            FlankTouch::Refused
        };
        let touch_offset = match flank.zero(true, -1.0, edge_d as f64) {
            Some(z) => {
                how = FlankTouch::Line;
                z as f32
            }
            // The edge crossing between the last sample before the pulse and the onset (the
            // trigger sample itself when the pulse starts there).
            None => {
                let onset = match pulse.checked_sub(1) {
                    Some(i) => pd(i),
                    None => Some(sign * deviation.of(trigger_x) as i64),
                };
                match (pd(pulse), onset) {
                    // A step past the flank level within one sample: a foot steeper than the
                    // sampling resolves, or a jump (Kelvin–Voigt's `c v0`).
                    // (The middle of the interval before it until the next sample tells more:
                    // [`Stream::touch`].)
                    (Some(_), Some(y1)) if y1 > flank_d => {
                        how = FlankTouch::Steep;
                        -0.5
                    }
                    (Some(y0), Some(y1)) => {
                        (crossing(y0 as f64, y1 as f64, edge_d as f64) - 1.0) as f32
                    }
                    _ => 0.0,
                }
            }
        };
        (pulse, touch_offset, how)
    }

    /// The window's samples the ring holds, replayed into the impact at its start: the
    /// filter's `lead` samples into the capture only, then the `margin` samples from the
    /// window's first (`before_onset` of them before the onset) into the capture and the
    /// running sums (Σd, the part before the onset, the peak, the rails).
    fn replay_window<const CAP: usize>(
        &self,
        a: &mut Active,
        mut capture: Option<&mut crate::capture::Capture<CAP>>,
        lead: usize,
        margin: usize,
        before_onset: usize,
        deviation: Deviation,
    ) {
        let (clip_lo, clip_hi) = self.scene.clip_counts;
        let (older, newer) = self.ring.last(lead + margin);
        // The lead-in into the capture only; the window into the sums too.
        let (lead_runs, window_runs) = crate::signal::ring::split_runs(older, newer, lead);
        if let Some(c) = capture.as_mut() {
            for run in lead_runs {
                a.full |= c.extend(run) < run.len();
            }
        }
        let (w, s) = (a.base_n, a.base_sum);
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

    /// The in-impact loop ([`super::walk`]) over a chunk: returns how many samples it took
    /// and how the impact ended, if it did.
    ///
    /// The level watch runs first, over whole strides of raw samples: where the signal
    /// settles (if it does) is known before the per-sample loop, which stops there.
    fn run_part<const CAP: usize>(
        &mut self,
        samples: &[i16],
        sink: &mut impl Sink<CAP>,
    ) -> (usize, Option<End>) {
        let (lo, hi) = self.scene.clip_counts;
        let max_samples = self.limits.max_samples;
        let hold = self.limits.hold;
        let Some(a) = self.run.active.as_mut() else {
            return (0, None);
        };
        // At most the samples that keep the impact within its longest duration.
        let room = max_samples
            .saturating_sub(a.samples)
            .min(samples.len() as u64) as usize;
        let samples = samples.get(..room).unwrap_or(&[]);
        let scan = a.level.scan(samples);
        let samples = samples.get(..scan.used).unwrap_or(&[]);
        let levels = Levels::of(a, hold, a.first_index + a.samples);
        let deviation = a.deviation();
        let mut walk = Walk::load(a, samples.len());
        walk.run(samples, deviation, &levels);
        let kept = samples.get(..walk.used).unwrap_or(&[]);
        // Σ d' = Σ d - n G; Σ C' from Σ of the running Σ d: exact, once per call.
        self.run.online.advance(kept, walk.sum, walk.sum2, scan.max);
        // Only when the samples reach a rail does it matter which of them did.
        if scan.min <= lo || scan.max >= hi {
            a.clipped |= kept.iter().any(|&x| x <= lo || x >= hi);
        }
        capture_part(a, kept, sink);
        let ended = walk.store(a, kept, &levels, deviation);
        let ended = ended.or(scan.settled.map(End::Settled));
        let too_long = ended.is_none() && a.samples >= max_samples;
        // The ring keeps following the stream: the separation flank and the next impact's
        // pre-trigger history come from it.
        self.keep(kept);
        self.locate_separation();
        if let Some((onset, Some((at, offset, _)))) = self
            .run
            .active
            .as_ref()
            .map(|a| (a.onset_index, a.separation_at))
        {
            self.run
                .online
                .follow_separation(&self.ring, self.run.index, onset, at, offset);
        }
        if too_long {
            self.end_unreturned(Status::TooLong, sink);
            return (kept.len(), None);
        }
        (kept.len(), ended)
    }

    /// The impact ended (see [`End`]): hand it over, or, for a level change without a pulse,
    /// drop it; learn the baseline again after a level change.
    fn finish_impact<const CAP: usize>(&mut self, end: End, sink: &mut impl Sink<CAP>) {
        let Some(a) = self.run.active.as_mut() else {
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
                    a.separation = Some(self.run.index - s.run_n);
                    a.separation_c = a.total_c - s.run_d;
                }
                // A pulse is a peak beyond the trigger from the new level too; else the
                // "impact" was the level change itself.
                let trigger_d = a.d_hi.min(-a.d_lo) as f64;
                if libm::fabs(a.peak_d as f64 - s.level_d) <= trigger_d {
                    self.run.active = None;
                    self.run.counters.level_changes += 1;
                } else {
                    self.end_unreturned(Status::Settled, sink);
                }
                self.relearn_baseline();
                return;
            }
        };
        self.end(status, sink);
    }

    /// Whether the tail of `a`'s capture decimates it once full (at stream index `fills_to`):
    /// where that serves, for a verdict whose window after the peak reaches beyond, or for a
    /// filter whose padding before the contact is held (else the filter cannot run, and the
    /// window at every sample keeps the fits).
    fn tail_decimates(&self, a: &Active, fills_to: u64) -> bool {
        let rate = self.scene.calibration.sample_rate_hz;
        let verdict_short = self.scene.spec.is_some_and(|s| {
            a.peak_index
                .saturating_add(u64::from(s.padding_samples(rate)))
                > fills_to
        });
        let held_from = a.first_index.saturating_sub(u64::from(a.filter_lead));
        let before = a.onset_index.saturating_sub(held_from);
        let filter_served = self.scene.window_filter().is_some_and(|c| {
            before >= u64::from(c.padding_samples(rate)) || (held_from == 0 && !a.cut_at_start)
        });
        verdict_short || filter_served
    }

    /// The active impact ends without the signal coming back to its baseline (`status`: too
    /// long, settled elsewhere, or the stream ended). A pulse whose onset came more than the
    /// settle time before its peak rode on drift or an orientation change: flagged `drift`.
    pub(super) fn end_unreturned<const CAP: usize>(
        &mut self,
        status: Status,
        sink: &mut impl Sink<CAP>,
    ) {
        let settle = u64::from(self.limits.settle);
        if let Some(a) = self.run.active.as_mut() {
            a.drift |= a.peak_index.saturating_sub(a.onset_index) > settle;
        }
        self.end(status, sink);
    }

    /// Hands the active impact over and returns to idle.
    pub(super) fn end<const CAP: usize>(&mut self, status: Status, sink: &mut impl Sink<CAP>) {
        let Some(a) = self.run.active.take() else {
            return;
        };
        self.run.thresholds = None;
        self.baseline.restart_stride();
        self.run.last_end = a.separation.unwrap_or(self.run.index);
        self.run.window_end = a.end_at.unwrap_or(self.run.index);
        let level = self.baseline.mean() as f64;
        if let Some(f) = self.run.trigger_filter.as_mut() {
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
        let (touch, fitted, jump) = self.touch(&a);
        let (touch_offset, lead_c, in_previous) = self.lobe(&a, touch, fitted);
        // (A lobe that begins earlier is no jump.)
        let reach = jump.filter(|_| touch_offset == touch.0 && !in_previous);
        let touch = a.onset_index as f64 + touch_offset as f64;
        let approach =
            self.run
                .train
                .approach(&self.scene, touch, self.run.v0, self.run.v0_measured);
        // A light gate's reading is the next impact's approach speed, not its bounces'.
        if self.run.v0_measured {
            self.run.v0 = self.scene.v0_m_s();
            self.run.v0_measured = false;
        }
        let mut summary = Summary {
            index: self.run.counters.impacts.min(u32::MAX as u64) as u32,
            status,
            clipped: a.clipped,
            cut_at_start: a.cut_at_start,
            level_change: a.level_change,
            drift: a.drift,
            in_previous,
            approach_unknown: approach.unknown,
            first_index: a.first_index,
            filter_lead: a.filter_lead,
            onset_index: a.onset_index,
            touch_offset,
            touch_jump: reach.is_some(),
            touch_reach: reach.unwrap_or(0.0),
            separation_index: a.separation,
            separation_offset,
            end_index: a.end_at.unwrap_or(self.run.index),
            base_sum: a.base_sum,
            base_n: a.base_n,
            peak_d: a.peak_d,
            peak_index: a.peak_index,
            total_c: a.total_c,
            contact_c: a
                .separation
                .map(|_| a.separation_c - a.pre_onset_c + lead_c + tail_c),
            v0_m_s: approach.v0_m_s,
            bounce: approach.bounce.into(),
            motion: crate::report::motion::Record::NONE,
        };
        // The online sums' crush and separation, now that touch and speed are final.
        if let Some(s) = a.separation {
            self.run.online.follow_separation(
                &self.ring,
                self.run.index,
                a.onset_index,
                s,
                separation_offset,
            );
        }
        summary.motion = self.run.online.finish(&summary, &self.scene);
        self.run.train.ended(&summary, &self.scene);
        self.run.counters.impacts += 1;
        if status != Status::Complete {
            self.run.counters.incomplete += 1;
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
                let until = contact_end.saturating_add(u64::from(self.limits.filter_pad));
                let more = !matches!(status, Status::StreamEnded | Status::Gap);
                // The stream index a capture filled at its step would reach.
                let fills_to =
                    c.held_from() + (c.capacity() as u64).saturating_mul(u64::from(c.step()));
                let decimate = self.tail_decimates(&a, fills_to);
                let room = !c.is_full() || decimate;
                // (`is_full`: no room at the capture's step; only a decimating tail makes it.)
                if self.limits.filter_pad > 0 && more && !a.full && room && until > self.run.index {
                    self.run.tail = Some((until, decimate));
                } else {
                    sink.captured(&self.scene);
                    self.run.handed_over = true;
                }
            }
            _ => {
                self.run.counters.analyses_skipped += 1;
                sink.skipped(&report::skipped(&summary, &self.scene));
            }
        }
    }
}

/// The capture keeps the whole impact `a`: a filter's lead-in gives way to it first (the
/// window at every sample keeps the fits), then it goes on at a coarser step
/// (`Capture::extend_decimating`).
fn capture_part<const CAP: usize>(a: &mut Active, kept: &[i16], sink: &mut impl Sink<CAP>) {
    if a.captured && !a.full {
        a.full = match sink.buffer() {
            Some(c) => {
                if a.filter_lead > 0 && c.held().len() + kept.len() > c.capacity() {
                    c.drop_front(a.filter_lead as usize);
                    a.filter_lead = 0;
                }
                c.extend_decimating(kept) < kept.len()
            }
            None => true,
        };
    }
}
