//! The streaming stage: raw samples in (any block size), impacts detected, captured and
//! summarised out; the per-sample half of the pipeline, cheap enough for any sample rate.
//!
//! ```text
//! idle ──|a| > trigger──► active ──|a| < edge for `hold`──► summary ──► idle
//!   ▲ ring of PRE samples (history for     capture (if the sink has a free buffer) from
//!   │ the pre-trigger and the flanks);     before the onset; exact integer Δv and peak
//!   │ baseline from quiet strides          over the whole impact
//! ```
//! Idle samples go into the ring and the stride sums of the baseline, and are compared with
//! two integer thresholds fixed per stride. Everything the stage reports is computed from raw
//! integer samples and stream positions, so feeding a stream in blocks of any size, or one
//! sample at a time, gives identical results. The per-impact analysis of a captured impact
//! (widths, kinematics, filtering, fits) is [`crate::analysis`], run by whoever receives the
//! capture from the [`Sink`].

mod active;
mod feet;
mod impact;
mod level;
mod online;
mod onset;
mod rise;
mod state;
mod tail;
pub mod train;
mod walk;

use crate::capture::Sink;
use crate::consts::STANDARD_GRAVITY;
use crate::error::Error;
use crate::report::Status;
use crate::scene::{Approach, FitSet, Scene};
use crate::signal::baseline::{Baseline, Stats, STRIDE};
use crate::signal::ring::Ring;
use crate::signal::Calibration;
use onset::Onset;
use state::{Limits, Run};

/// Quiet strides in the baseline window (`64 * STRIDE` = 4096 samples).
const BASELINE_STRIDES: usize = 64;
/// Samples in a full baseline, the largest `W` of `d = W x - S`.
const BASELINE_SPAN: usize = BASELINE_STRIDES * STRIDE;
// `Deviation` computes d in i32: |x| <= 2^15 and W <= 2^12 keep |S| below 2^27 and |d|
// below 2^28.
const _: () = assert!(BASELINE_SPAN <= 1 << 12);

/// How far back from the newest sample the flanks are followed and fitted, samples (the
/// board's pre-trigger ring): a longer ring (the host's, for a filter's lead-in) changes no
/// streaming field.
pub const REACH: usize = 4096;

/// The flanks are fitted between the edge level and this many times it (or the trigger level,
/// if lower, so the trigger sample always ends the rising flank).
const FLANK_EDGES: i64 = 4;

/// Counters that cannot wrap: 2^64 samples at 2.4 MS/s is 240 000 years.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Counters {
    /// Samples processed.
    pub samples: u64,
    /// Impacts reported.
    pub impacts: u64,
    /// Reports with a status other than complete.
    pub incomplete: u64,
    /// Impacts that found no free capture buffer (reported without analysis).
    pub analyses_skipped: u64,
    /// Samples the source lost (announced with [`Stream::gap`]).
    pub samples_lost: u64,
    /// Gaps announced.
    pub gaps: u64,
    /// Times the signal settled at a new level without a pulse (a DC sensor's free fall or
    /// rest): not impacts; the baseline is learned again.
    pub level_changes: u64,
}

/// The streaming stage of one channel through a [`Scene`]. `PRE` (a power of two) is the
/// ring of recent samples: the pre-trigger history, the baseline window and the reach of the
/// flank fits.
pub struct Stream<const PRE: usize> {
    scene: Scene,
    /// The scene in counts and samples.
    limits: Limits,
    ring: Ring<PRE>,
    baseline: Baseline<BASELINE_STRIDES>,
    /// Everything else running changes.
    run: Run,
}

impl<const PRE: usize> Stream<PRE> {
    /// Samples the in-impact loop takes at a time (a board's block, or half the ring).
    pub(super) const CHUNK: usize = if PRE / 2 < 256 { PRE / 2 } else { 256 };
    /// How far behind a separation the falling flank is read from the ring: as far as the
    /// flanks reach and the ring is sure to hold, with the newest sample at most a chunk
    /// beyond the separation.
    pub(super) const LOOKBACK: usize =
        (if REACH < PRE { REACH } else { PRE }).saturating_sub(Self::CHUNK + 2);

    /// A stream for `scene`; fails on an invalid scene or ring size.
    pub fn new(scene: Scene) -> Result<Self, Error> {
        let mut s = Self::unconfigured();
        s.configure(scene)?;
        Ok(s)
    }

    /// A stream evaluated at compile time, for a `static` on a small MCU. It runs a
    /// placeholder scene (1 S/s, 1 m/s² per count, no mass, no fits) until
    /// [`Self::configure`] gives it the real one.
    pub const fn unconfigured() -> Self {
        Self {
            scene: Scene {
                calibration: Calibration {
                    gain_m_s2_per_count: 1.0,
                    sample_rate_hz: 1.0,
                },
                mass_kg: None,
                approach: Approach::Unknown,
                trigger_m_s2: 1.0,
                edge_m_s2: 0.25,
                hold_s: 1.0,
                max_impact_s: 1.0,
                settle_s: 1.0,
                clip_counts: (i16::MIN, i16::MAX),
                cfc: None,
                lowpass: None,
                trigger_cfc: None,
                gravity_m_s2: STANDARD_GRAVITY as f32,
                vertical: false,
                v0_every: false,
                train: None,
                spectrum: None,
                spec: None,
                waveform_every: 0,
                target: None,
                fits: FitSet {
                    two_phase: false,
                    nonlinear: false,
                    fit_exponent: false,
                    nonlinear_exponent: 1.0,
                    hertz: false,
                },
            },
            limits: Limits::PLACEHOLDER,
            ring: Ring::new(),
            baseline: Baseline::new(),
            run: Run::new(),
        }
    }

    /// Starts over with `scene`, in place: the stream, the baseline, the counters and the
    /// approach speed are reset. Captures of `CAP` samples must hold more than twice the
    /// hold time. Fails on an invalid scene or sizes, and then leaves the stream as it was.
    pub fn configure_for(&mut self, scene: Scene, cap: usize) -> Result<(), Error> {
        scene.validate()?;
        let hold = scene.samples(scene.hold_s);
        if cap < 4 * STRIDE || (hold as usize) >= cap / 2 {
            return Err(Error::InvalidParameter {
                name: "hold",
                reason: "hold time at this sample rate must be under half the capture length (shorten the hold or lower the rate)",
            });
        }
        self.configure(scene)?;
        self.limits.capture_len = cap;
        Ok(())
    }

    /// The capture's length in use for captures of `CAP` samples.
    fn capture_len<const CAP: usize>(&self) -> usize {
        match self.limits.capture_len {
            0 => CAP,
            n => n.min(CAP),
        }
    }

    /// As [`Self::configure_for`], without a capture length to check.
    pub fn configure(&mut self, scene: Scene) -> Result<(), Error> {
        scene.validate()?;
        if PRE < STRIDE || !PRE.is_power_of_two() {
            return Err(Error::InvalidParameter {
                name: "pre-trigger",
                reason: "ring must be a power of two of at least 64 samples",
            });
        }
        self.scene = scene;
        self.limits = Limits::of(&scene);
        self.ring.clear();
        self.baseline.clear();
        self.run.restart(&scene);
        Ok(())
    }

    /// The scene in use.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// Counters so far.
    pub fn counters(&self) -> Counters {
        self.run.counters
    }

    /// True while an impact is being followed.
    pub fn in_impact(&self) -> bool {
        self.run.active.is_some()
    }

    /// True once a baseline has been learned (impacts can be detected).
    pub fn is_armed(&self) -> bool {
        self.baseline.is_armed()
    }

    /// Stream index of the next sample.
    pub fn position(&self) -> u64 {
        self.run.index
    }

    /// Sets the approach speed of the next impact (a light gate's reading), m/s: it holds for
    /// that impact only (after it the scene's is back), so no bounce takes it.
    pub fn set_approach_speed(&mut self, v0_m_s: Option<f32>) {
        self.run.v0 = v0_m_s.filter(|v| v.is_finite() && *v > 0.0);
        self.run.v0_measured = self.run.v0.is_some();
    }

    /// A block of samples (whatever the DMA hands over). Impacts go to `sink`.
    pub fn push_block<const CAP: usize>(&mut self, block: &[i16], sink: &mut impl Sink<CAP>) {
        let mut rest = block;
        while !rest.is_empty() {
            let used = self.push_to_impact_end(rest, sink);
            rest = rest.get(used..).unwrap_or(&[]);
        }
    }

    /// As [`Self::push_block`], but returns after the first impact that ends in `block`, or
    /// the first capture handed over (a filter's tail ends after its impact): the number of
    /// samples taken (all of them if neither happened). A caller that must have a free
    /// capture buffer for every impact (the emulator's lossless replay) waits for one between
    /// calls; the reports are the same for any split of the stream.
    pub fn push_to_impact_end<const CAP: usize>(
        &mut self,
        block: &[i16],
        sink: &mut impl Sink<CAP>,
    ) -> usize {
        let mut rest = block;
        self.run.handed_over = false;
        while !rest.is_empty() {
            if self.run.trigger_pending {
                // The trigger fired on this sample in the previous call.
                self.run.trigger_pending = false;
                let x = rest.first().copied().unwrap_or(0);
                match self.onset(x) {
                    Onset::Pulse(level) => self.pulse(sink, x, level),
                    // (Not reached: the same samples said "pulse" in the previous call.)
                    Onset::Moved((sum, n)) => self.move_baseline(sum, n),
                }
                continue;
            }
            if self.run.handed_over {
                break;
            }
            if self.run.active.is_some() {
                let used = self.run_active(rest, sink);
                rest = rest.get(used..).unwrap_or(&[]);
                if self.run.active.is_none() {
                    break;
                }
                continue;
            }
            // Idle: learn a first baseline stride, then look for the first sample beyond the
            // thresholds, one stride segment at a time. Every decision depends on stream
            // positions only, so any split of the stream gives the same reports.
            let segment_len = self.baseline.to_stride_end().min(rest.len());
            let (segment, after) = rest.split_at(segment_len);
            if !self.baseline.is_armed() {
                self.idle(segment, sink);
                rest = after;
                if self.baseline.is_armed() {
                    let level = self.baseline.mean() as f64;
                    if let Some(f) = self.run.trigger_filter.as_mut() {
                        f.reset(level);
                    }
                    // The first baseline: look again at the history it did not cover, so an
                    // impact at the very start of the stream is not lost.
                    self.replay_history(sink);
                }
                continue;
            }
            let (lo, hi) = self.current_thresholds();
            let found = match self.run.trigger_filter.as_mut() {
                None => {
                    // One vectorised pass for the stride statistics; the samples are
                    // scanned one by one only when the segment crosses a threshold.
                    let stats = Stats::of(segment);
                    if stats.within(lo, hi) {
                        // A run of quiet strides: the baseline (and so the thresholds)
                        // follows each one, the ring and the counters take the run at once.
                        self.learn(&stats);
                        let mut run = segment.len();
                        while let Some(next) = rest.get(run..run + self.baseline.to_stride_end()) {
                            let (lo, hi) = self.current_thresholds();
                            let stats = Stats::of(next);
                            if !stats.within(lo, hi) {
                                break;
                            }
                            self.learn(&stats);
                            run += next.len();
                        }
                        let (quiet, after) = rest.split_at(run.min(rest.len()));
                        self.keep_idle(quiet, sink);
                        rest = after;
                        continue;
                    }
                    segment
                        .iter()
                        .position(|&x| (x as i32) > hi || (x as i32) < lo)
                }
                Some(f) => segment.iter().position(|&x| {
                    let y = f.step(x as f64);
                    y > hi as f64 || y < lo as f64
                }),
            };
            match found {
                None => {
                    self.idle(segment, sink);
                    rest = after;
                }
                Some(at) => {
                    // `at` lies inside `segment`, a prefix of `rest` (written with `get` so
                    // the target build has no panic path here).
                    self.idle(rest.get(..at).unwrap_or(&[]), sink);
                    rest = rest.get(at..).unwrap_or(&[]);
                    let x = rest.first().copied().unwrap_or(0);
                    let level = match self.onset(x) {
                        Onset::Pulse(level) => level,
                        Onset::Moved((sum, n)) => {
                            // No pulse: the baseline follows the signal to its new level,
                            // and the trigger sample is an idle one there.
                            self.move_baseline(sum, n);
                            self.idle(rest.get(..1).unwrap_or(&[]), sink);
                            rest = rest.get(1..).unwrap_or(&[]);
                            continue;
                        }
                    };
                    if self.run.tail.is_some() || self.run.handed_over {
                        // The previous capture goes first (its tail ends here); the caller
                        // may wait for a free buffer before this impact starts.
                        self.hand_over(sink);
                        self.run.trigger_pending = true;
                        break;
                    }
                    self.pulse(sink, x, level);
                }
            }
        }
        block.len() - rest.len()
    }

    /// `lost` samples never arrived (the source overran): an impact in progress ends with
    /// [`Status::Gap`], the stream position moves on by `lost`, and the history before the
    /// gap is forgotten (the baseline is kept). A pulse already under way when the samples
    /// come back is reported with [`Status::Gap`] too: its start is unknown.
    pub fn gap<const CAP: usize>(&mut self, lost: u64, sink: &mut impl Sink<CAP>) {
        if lost == 0 {
            return;
        }
        if self.run.active.is_some() {
            self.end(Status::Gap, sink);
        }
        self.hand_over(sink);
        self.run.index += lost;
        self.run.gap_end = Some(self.run.index);
        self.run.counters.samples_lost += lost;
        self.run.counters.gaps += 1;
        self.ring.clear();
        self.baseline.restart_stride();
        let level = self.baseline.mean() as f64;
        if let Some(f) = self.run.trigger_filter.as_mut() {
            f.reset(level);
        }
    }

    /// Ends the stream: an impact in progress ends with [`Status::StreamEnded`].
    pub fn finish<const CAP: usize>(&mut self, sink: &mut impl Sink<CAP>) {
        self.run.trigger_pending = false;
        if self.run.active.is_some() {
            self.end_unreturned(Status::StreamEnded, sink);
        }
        self.hand_over(sink);
    }

    /// Idle samples: into the ring and the baseline (and the tail of a capture).
    #[inline]
    fn idle<const CAP: usize>(&mut self, samples: &[i16], sink: &mut impl Sink<CAP>) {
        self.keep_idle(samples, sink);
        self.learn(&Stats::of(samples));
    }

    /// Idle samples into the ring and the stream position, and into the tail of the capture
    /// of the impact that ended last, if it still takes one.
    #[inline]
    fn keep_idle<const CAP: usize>(&mut self, samples: &[i16], sink: &mut impl Sink<CAP>) {
        if let Some(until) = self.run.tail {
            self.extend_tail(until, samples, sink);
        }
        self.keep(samples);
    }

    /// Samples into the ring and the stream position.
    #[inline]
    fn keep(&mut self, samples: &[i16]) {
        self.ring.extend(samples);
        self.run.index += samples.len() as u64;
        self.run.counters.samples += samples.len() as u64;
    }

    /// A stretch of idle samples into the baseline (not while the history is replayed).
    #[inline]
    fn learn(&mut self, stats: &Stats) {
        if !self.run.replaying && self.baseline.add_stats(stats, self.limits.edge_counts) {
            self.run.thresholds = None;
        }
    }

    /// The trigger thresholds for the current baseline (computed once per change).
    #[inline]
    fn current_thresholds(&mut self) -> (i32, i32) {
        match self.run.thresholds {
            Some(t) => t,
            None => {
                let t = self.thresholds();
                self.run.thresholds = Some(t);
                t
            }
        }
    }

    /// Runs the samples held in the ring through the idle path again, with the baseline just
    /// learned (and without learning from them twice). The ring replays its own history in
    /// place, a stride at a time, so no copy of it sits on the stack.
    #[inline(never)]
    fn replay_history<const CAP: usize>(&mut self, sink: &mut impl Sink<CAP>) {
        let n = self.ring.take_history();
        self.run.index -= n as u64;
        self.run.counters.samples -= n as u64;
        self.run.replaying = true;
        let mut chunk = [0i16; STRIDE];
        let mut k = 0;
        while k < n {
            let m = (n - k).min(STRIDE);
            let part = chunk.get_mut(..m).unwrap_or(&mut []);
            self.ring.replayed(k, part);
            self.push_block(part, sink);
            k += m;
        }
        self.run.replaying = false;
    }

    /// Forgets the baseline and the history (the level moved, or the sensor is stuck): the
    /// next quiet stride arms the stream again.
    fn relearn_baseline(&mut self) {
        self.ring.clear();
        self.baseline.clear();
        self.run.thresholds = None;
        self.run.moved = true;
    }

    /// Trigger thresholds in raw counts around the baseline.
    fn thresholds(&self) -> (i32, i32) {
        let mean = self.baseline.mean();
        let lo = floor(mean - self.limits.trigger_counts);
        let hi = -floor(-(mean + self.limits.trigger_counts));
        (clamp_i32(lo), clamp_i32(hi))
    }
}

/// `floorf` by the FPU's conversions (libm's is a software bit-twiddle, ~30 instructions on the
/// Cortex-M4): exact for |v| < 2^23; larger values are integers already; NaN stays NaN.
fn floor(v: f32) -> f32 {
    if libm::fabsf(v) < 8_388_608.0 {
        let t = v as i32 as f32;
        if t > v {
            t - 1.0
        } else {
            t
        }
    } else {
        v
    }
}

fn clamp_i32(v: f32) -> i32 {
    if v >= i32::MAX as f32 {
        i32::MAX
    } else if v <= i32::MIN as f32 {
        i32::MIN
    } else {
        v as i32
    }
}

#[cfg(test)]
mod floor_tests {
    #[test]
    fn floor_matches_libm() {
        for k in 0..200_000 {
            // Both signs, every magnitude up to 3e7 and fractions near the integers.
            let v = (k as f32 - 100_000.0) * 300.013 + (k % 7) as f32 * 0.125;
            for x in [v, v / 1e3, v / 1e6, v * 1e-4 + 0.5] {
                assert_eq!(super::floor(x), libm::floorf(x), "{x}");
            }
        }
        assert!(super::floor(f32::NAN).is_nan());
        assert_eq!(super::floor(f32::INFINITY), f32::INFINITY);
        assert_eq!(super::floor(-0.5), -1.0);
    }
}
