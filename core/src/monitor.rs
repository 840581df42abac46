//! The streaming state machine: raw samples in (any block size), one report per impact out.
//!
//! ```text
//! idle ──|a| > trigger──► active ──|a| < edge for `hold`──► report ──► idle
//!   ▲ ring of PRE samples (pre-trigger     capture of CAP samples from before the
//!   │ history); baseline from quiet strides onset; exact integer Δv over the whole impact
//! ```
//! Idle samples go into the pre-trigger ring and the stride sums of the baseline, and are
//! compared with two integer thresholds fixed per stride; all per-impact work (baseline refinement, edges, widths,
//! integration, filtering, fits) happens once the impact is over. Feeding a stream in blocks
//! of any size, or one sample at a time, gives identical reports.

use heapless::Vec;

use crate::metrics::{report, ImpactReport, Status, Window};
use crate::scene::{Approach, FitSet, Scene};
use crate::signal::baseline::{Baseline, Stats, STRIDE};
use crate::signal::ring::Ring;
use crate::signal::Calibration;
use crate::solve::Error;

/// Quiet strides in the baseline window (`64 * STRIDE` = 4096 samples).
const BASELINE_STRIDES: usize = 64;
/// Samples in a full baseline, the largest `W` of `d = W x - S`.
const BASELINE_SPAN: usize = BASELINE_STRIDES * crate::signal::baseline::STRIDE;
// `Deviation` computes d in i32: |x| <= 2^15 and W <= 2^12 keep |S| below 2^27 and |d|
// below 2^28.
const _: () = assert!(BASELINE_SPAN <= 1 << 12);

/// `d = W x - S` for one impact's frozen baseline, in i32: exact, since `W <= BASELINE_SPAN`
/// (the wrapping operations never wrap), and the FPU converts i32 while i64 arithmetic and
/// conversions are longer or soft-float calls on the Cortex-M4.
#[derive(Clone, Copy)]
struct Deviation {
    w: i32,
    s: i32,
}

impl Deviation {
    #[inline]
    fn of(self, x: i16) -> i32 {
        (x as i32).wrapping_mul(self.w).wrapping_sub(self.s)
    }
}

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
}

struct Active {
    /// Stream index of `capture[0]`.
    first_index: u64,
    /// Stream index of the sample that fired the trigger.
    trigger_index: u64,
    /// Capture index of the onset.
    onset: usize,
    base_sum: i64,
    base_n: i64,
    /// Edge level in units of `d = W x - S`.
    edge_d: i64,
    quiet: u32,
    /// Capture index of the first sample back within the edge level after the peak
    /// (separation: later ringing or a second hit within the hold does not move it unless it
    /// brings a new peak).
    separation: Option<usize>,
    peak_d: i64,
    peak_index: u64,
    total_c: i64,
    samples: u64,
    clipped: bool,
    full: bool,
}

impl Active {
    fn deviation(&self) -> Deviation {
        Deviation {
            w: self.base_n as i32,
            s: self.base_sum as i32,
        }
    }
}

/// Streams samples of one channel through a [`Scene`].
///
/// `PRE` (a power of two) is the pre-trigger ring and baseline window; `CAP` the capture
/// length (samples from just before the onset to the end of the hold).
pub struct Monitor<const PRE: usize, const CAP: usize> {
    scene: Scene,
    ring: Ring<PRE>,
    baseline: Baseline<BASELINE_STRIDES>,
    capture: Vec<i16, CAP>,
    /// Acceleration of the captured samples, m/s² (filtered if the scene asks).
    accel: [f32; CAP],
    active: Option<Active>,
    /// Stream index of the next sample.
    index: u64,
    v0: Option<f32>,
    counters: Counters,
    trigger_counts: f32,
    edge_counts: f32,
    hold: u32,
    max_samples: u64,
    /// Trigger thresholds (raw counts) in force until the next refresh.
    thresholds: Option<(i32, i32)>,
    /// The ring's history is being run again after the first baseline (see `replay_history`).
    replaying: bool,
    /// The causal trigger filter, if the scene asks for one.
    trigger_filter: Option<crate::signal::cfc::Causal>,
}

impl<const PRE: usize, const CAP: usize> Monitor<PRE, CAP> {
    /// A monitor for `scene`; fails on an invalid scene or sizes.
    pub fn new(scene: Scene) -> Result<Self, Error> {
        let mut m = Self::unconfigured();
        m.configure(scene)?;
        Ok(m)
    }

    /// A monitor evaluated at compile time, for a `static` on a small MCU: the capture is too
    /// big to build on the stack and move into place (`Monitor::new` returns it by value).
    /// It runs a placeholder scene (1 S/s, 1 m/s² per count, no mass, no fits) until
    /// [`Self::configure`] gives it the real one.
    ///
    /// ```
    /// use impact_core::Monitor;
    /// // On the firmware: `static_cell::ConstStaticCell::new(Monitor::unconfigured())`.
    /// static M: Monitor<4096, 8192> = Monitor::unconfigured();
    /// ```
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
                clip_counts: (i16::MIN, i16::MAX),
                cfc: None,
                trigger_cfc: None,
                fits: FitSet {
                    two_phase: false,
                    nonlinear: false,
                    fit_exponent: false,
                    nonlinear_exponent: 1.0,
                    hertz: false,
                },
            },
            ring: Ring::new(),
            baseline: Baseline::new(),
            capture: Vec::new(),
            accel: [0.0; CAP],
            active: None,
            index: 0,
            v0: None,
            counters: Counters {
                samples: 0,
                impacts: 0,
                incomplete: 0,
            },
            trigger_counts: 1.0,
            edge_counts: 0.25,
            hold: 1,
            max_samples: 1,
            thresholds: None,
            replaying: false,
            trigger_filter: None,
        }
    }

    /// Starts over with `scene`, in place (no stack copy of the buffers): the stream, the
    /// baseline, the counters and the approach speed are reset. Fails on an invalid scene or
    /// sizes, and then leaves the monitor as it was.
    pub fn configure(&mut self, scene: Scene) -> Result<(), Error> {
        scene.validate()?;
        if PRE < STRIDE || !PRE.is_power_of_two() {
            return Err(Error::InvalidParameter {
                name: "pre-trigger",
                reason: "ring must be a power of two of at least 64 samples",
            });
        }
        let hold = scene.samples(scene.hold_s);
        if CAP < 4 * STRIDE || (hold as usize) >= CAP / 2 {
            return Err(Error::InvalidParameter {
                name: "hold",
                reason: "hold time must be under half the capture length",
            });
        }
        let gain = libm::fabsf(scene.calibration.gain_m_s2_per_count);
        self.scene = scene;
        self.ring.clear();
        self.baseline.clear();
        self.capture.clear();
        self.active = None;
        self.index = 0;
        self.v0 = scene.approach.v0_m_s();
        self.counters = Counters::default();
        self.trigger_counts = scene.trigger_m_s2 / gain;
        self.edge_counts = scene.edge_m_s2 / gain;
        self.hold = hold;
        self.max_samples = scene.samples(scene.max_impact_s) as u64;
        self.thresholds = None;
        self.replaying = false;
        // At rest at 0 until the first baseline resets it to the baseline's level.
        self.trigger_filter = scene
            .trigger_cfc
            .and_then(|class| {
                crate::signal::cfc::Biquad::cfc(class, scene.calibration.sample_rate_hz as f64)
            })
            .map(|b| crate::signal::cfc::Causal::new(b, 0.0));
        Ok(())
    }

    /// The scene in use.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// Counters so far.
    pub fn counters(&self) -> Counters {
        self.counters
    }

    /// True while an impact is being captured.
    pub fn in_impact(&self) -> bool {
        self.active.is_some()
    }

    /// Sets the approach speed for the next impacts (a light gate's reading), m/s.
    pub fn set_approach_speed(&mut self, v0_m_s: Option<f32>) {
        self.v0 = v0_m_s.filter(|v| v.is_finite() && *v > 0.0);
    }

    /// One sample.
    pub fn push(&mut self, sample: i16, out: &mut impl FnMut(&ImpactReport)) {
        self.push_block(core::slice::from_ref(&sample), out);
    }

    /// A block of samples (whatever the DMA hands over). Calls `out` once per finished impact.
    pub fn push_block(&mut self, block: &[i16], out: &mut impl FnMut(&ImpactReport)) {
        let mut rest = block;
        while !rest.is_empty() {
            if self.active.is_some() {
                let used = self.run_active(rest, out);
                rest = rest.get(used..).unwrap_or(&[]);
                continue;
            }
            // Idle: learn a first baseline stride, then look for the first sample beyond the
            // thresholds, one stride segment at a time. Every decision depends on stream
            // positions only, so any split of the stream gives the same reports.
            let segment_len = self.baseline.to_stride_end().min(rest.len());
            let (segment, after) = rest.split_at(segment_len);
            if !self.baseline.is_armed() {
                self.idle(segment);
                rest = after;
                if self.baseline.is_armed() {
                    let level = self.baseline.mean() as f64;
                    if let Some(f) = self.trigger_filter.as_mut() {
                        f.reset(level);
                    }
                    // The first baseline: look again at the history it did not cover, so an
                    // impact at the very start of the stream is not lost.
                    self.replay_history(out);
                }
                continue;
            }
            let (lo, hi) = self.current_thresholds();
            let found = match self.trigger_filter.as_mut() {
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
                        self.keep(quiet);
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
                    self.idle(segment);
                    rest = after;
                }
                Some(at) => {
                    // `at` lies inside `segment`, a prefix of `rest` (written with `get` so
                    // the target build has no panic path here).
                    self.idle(rest.get(..at).unwrap_or(&[]));
                    self.start();
                    rest = rest.get(at..).unwrap_or(&[]);
                }
            }
        }
    }

    /// Ends the stream: an impact in progress is reported as [`Status::StreamEnded`].
    pub fn finish(&mut self, out: &mut impl FnMut(&ImpactReport)) {
        if self.active.is_some() {
            self.end(Status::StreamEnded, out);
        }
    }

    /// Idle samples: into the ring and the baseline.
    #[inline]
    fn idle(&mut self, samples: &[i16]) {
        self.keep(samples);
        self.learn(&Stats::of(samples));
    }

    /// Idle samples into the pre-trigger ring and the stream position.
    #[inline]
    fn keep(&mut self, samples: &[i16]) {
        self.ring.extend(samples);
        self.index += samples.len() as u64;
        self.counters.samples += samples.len() as u64;
    }

    /// A stretch of idle samples into the baseline (not while the history is replayed).
    #[inline]
    fn learn(&mut self, stats: &Stats) {
        if !self.replaying && self.baseline.add_stats(stats, self.edge_counts) {
            self.thresholds = None;
        }
    }

    /// The trigger thresholds for the current baseline (computed once per change).
    #[inline]
    fn current_thresholds(&mut self) -> (i32, i32) {
        match self.thresholds {
            Some(t) => t,
            None => {
                let t = self.thresholds();
                self.thresholds = Some(t);
                t
            }
        }
    }

    /// Runs the samples held in the ring through the idle path again, with the baseline just
    /// learned (and without learning from them twice).
    // Never inlined: its `PRE`-sample copy of the history would otherwise sit in every
    // `push_block` frame, twice over since it calls `push_block` (17 KiB of stack at PRE = 4096,
    // more than the STM32F407 has left beside the monitor).
    #[inline(never)]
    fn replay_history(&mut self, out: &mut impl FnMut(&ImpactReport)) {
        let n = self.ring.len();
        let mut history = [0i16; PRE];
        for (slot, x) in history.iter_mut().zip(self.ring.iter_oldest_first()) {
            *slot = x;
        }
        self.ring.clear();
        self.index -= n as u64;
        self.counters.samples -= n as u64;
        self.replaying = true;
        self.push_block(history.get(..n).unwrap_or(&[]), out);
        self.replaying = false;
    }

    /// True once a baseline has been learned (impacts can be detected).
    pub fn is_armed(&self) -> bool {
        self.baseline.is_armed()
    }

    /// Trigger thresholds in raw counts around the baseline.
    fn thresholds(&self) -> (i32, i32) {
        let mean = self.baseline.mean();
        let lo = floor(mean - self.trigger_counts);
        let hi = -floor(-(mean + self.trigger_counts));
        (clamp_i32(lo), clamp_i32(hi))
    }

    /// The trigger fired at `self.index`: find the onset in the ring, fix the baseline from the
    /// samples before it, and replay the pre-trigger samples into the capture.
    fn start(&mut self) {
        let ring = &self.ring;
        let edge = self.edge_counts;
        let (base_sum, base_n) = self.baseline.rational();
        let mean = self.baseline.mean();
        // Walk back from the newest sample while it is beyond the edge level.
        let mut pulse = 0usize;
        while let Some(x) = ring.back(pulse) {
            if libm::fabsf(x as f32 - mean) <= edge {
                break;
            }
            pulse += 1;
        }
        // Capture from `margin` samples before the onset (as far as the ring reaches).
        let margin = (pulse + self.hold as usize / 2)
            .min(ring.len())
            .min(CAP / 2);
        self.capture.clear();
        let first_index = self.index - margin as u64;
        let edge_d = (edge * base_n as f32) as i64;
        self.active = Some(Active {
            first_index,
            trigger_index: self.index,
            onset: margin - pulse.min(margin),
            base_sum,
            base_n,
            edge_d,
            quiet: 0,
            separation: None,
            peak_d: 0,
            peak_index: self.index,
            total_c: 0,
            samples: 0,
            clipped: false,
            full: false,
        });
        let mut replay = [0i16; 64];
        let mut left = margin;
        while left > 0 {
            let n = left.min(replay.len());
            for (k, slot) in replay.iter_mut().take(n).enumerate() {
                *slot = self.ring.back(left - 1 - k).unwrap_or(0);
            }
            self.capture_samples(&replay[..n]);
            left -= n;
        }
    }

    /// Adds samples to the active impact's capture and running sums (no end detection:
    /// used for the pre-trigger replay).
    fn capture_samples(&mut self, samples: &[i16]) {
        let Some(a) = self.active.as_mut() else {
            return;
        };
        let (lo, hi) = self.scene.clip_counts;
        let deviation = a.deviation();
        for (k, &x) in samples.iter().enumerate() {
            let d = deviation.of(x) as i64;
            a.total_c += d;
            let at = a.first_index + a.samples + k as u64;
            if d.unsigned_abs() > a.peak_d.unsigned_abs() {
                a.peak_d = d;
                a.peak_index = at;
            }
            a.clipped |= x <= lo || x >= hi;
            a.full |= self.capture.push(x).is_err();
        }
        a.samples += samples.len() as u64;
    }

    /// Feeds samples to the active impact until it ends; returns how many it used.
    ///
    /// The hot loop of an impact: the running state lives in locals (the compiler cannot
    /// keep fields of `self` in registers across the capture's push) and is written back
    /// once per call.
    fn run_active(&mut self, samples: &[i16], out: &mut impl FnMut(&ImpactReport)) -> usize {
        let hold = self.hold;
        let (lo, hi) = self.scene.clip_counts;
        let max_samples = self.max_samples;
        let capture = &mut self.capture;
        let Some(a) = self.active.as_mut() else {
            return 0;
        };
        // At most the samples that keep the impact within its longest duration.
        let room = max_samples
            .saturating_sub(a.samples)
            .min(samples.len() as u64) as usize;
        let samples = samples.get(..room).unwrap_or(&[]);
        let deviation = a.deviation();
        // edge_d >= 0: the scene's edge level is positive (validated).
        let edge = a.edge_d.clamp(0, u32::MAX as i64) as u32;
        let before = a.samples;
        let mut peak_abs = a.peak_d.unsigned_abs().min(u32::MAX as u64) as u32;
        let mut new_peak: Option<(usize, i32)> = None;
        let (mut separation, mut quiet, mut clipped) = (a.separation, a.quiet, a.clipped);
        let mut sum: i64 = 0;
        let mut used = samples.len();
        let mut ended = None;
        for (k, &x) in samples.iter().enumerate() {
            let d = deviation.of(x);
            sum += d as i64;
            let abs = d.unsigned_abs();
            if abs > peak_abs {
                peak_abs = abs;
                new_peak = Some((k, d));
                separation = None;
            }
            clipped |= x <= lo || x >= hi;
            if abs <= edge {
                if separation.is_none() {
                    separation = Some(before as usize + k);
                }
                quiet += 1;
                if quiet >= hold && a.first_index + before + k as u64 > a.trigger_index {
                    ended = Some(());
                    used = k + 1;
                    break;
                }
            } else {
                quiet = 0;
            }
        }
        // The capture keeps the first CAP samples of the impact.
        let kept = samples.get(..used).unwrap_or(&[]);
        let fits = CAP.saturating_sub(capture.len()).min(kept.len());
        a.full |= capture
            .extend_from_slice(kept.get(..fits).unwrap_or(&[]))
            .is_err()
            || fits < kept.len();
        if let Some((k, d)) = new_peak {
            a.peak_d = d as i64;
            a.peak_index = a.first_index + before + k as u64;
        }
        a.total_c += sum;
        a.separation = separation;
        a.quiet = quiet;
        a.clipped = clipped;
        a.samples += used as u64;
        let ended = match ended {
            Some(()) if a.full => Some(Status::BufferFull),
            Some(()) => Some(Status::Complete),
            None if a.samples >= max_samples => Some(Status::TooLong),
            None => None,
        };
        self.index += used as u64;
        self.counters.samples += used as u64;
        if let Some(status) = ended {
            self.end(status, out);
        }
        used
    }

    /// Reports the active impact and returns to idle.
    fn end(&mut self, status: Status, out: &mut impl FnMut(&ImpactReport)) {
        let Some(a) = self.active.take() else { return };
        self.thresholds = None;
        self.baseline.restart_stride();
        let level = self.baseline.mean() as f64;
        if let Some(f) = self.trigger_filter.as_mut() {
            f.reset(level);
        }
        let n = self.capture.len();
        let gain = self.scene.calibration.gain_m_s2_per_count;
        let per_count = gain / a.base_n as f32;
        let deviation = a.deviation();
        for (slot, &x) in self.accel.iter_mut().zip(self.capture.iter()) {
            *slot = deviation.of(x) as f32 * per_count;
        }
        #[cfg(feature = "cfc")]
        if let Some(class) = self.scene.cfc {
            if let Some(b) =
                crate::signal::cfc::Biquad::cfc(class, self.scene.calibration.sample_rate_hz as f64)
            {
                b.phaseless_f32(self.accel.get_mut(..n).unwrap_or(&mut []));
            }
        }
        let separation = a.separation;
        let window = Window {
            samples: &self.capture,
            accel: self.accel.get(..n).unwrap_or(&[]),
            first_index: a.first_index,
            onset: a.onset,
            separation,
            total_c: a.total_c,
            base_sum: a.base_sum,
            base_n: a.base_n,
            peak_d: a.peak_d,
            peak_index: a.peak_index,
            status,
            clipped: a.clipped,
        };
        let index = self.counters.impacts.min(u32::MAX as u64) as u32;
        let r = report(&window, &self.scene, index, self.v0);
        self.counters.impacts += 1;
        if status != Status::Complete {
            self.counters.incomplete += 1;
        }
        if status == Status::TooLong {
            // The baseline moved (or the sensor is stuck): learn it again.
            self.ring.clear();
            self.baseline.clear();
        }
        out(&r);
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

#[cfg(test)]
mod peak_tests {
    use crate::{Approach, Calibration, ImpactReport, Monitor, Scene};

    /// Reports of many pulses (both signs, flat tops with ties, noise, several gains): the
    /// report's peak from the monitor's integer peak must equal a scan of the window
    /// (`metrics::report` asserts it under `cfg(test)`).
    #[test]
    fn peak_from_the_integer_peak_equals_the_scan() {
        for gain in [1600.0 / 4096.0, 0.0123, -0.5] {
            let mut s = Scene::new(
                Calibration {
                    gain_m_s2_per_count: gain,
                    sample_rate_hz: 100_000.0,
                },
                40.0 * libm::fabsf(gain),
            );
            s.edge_m_s2 = 8.0 * libm::fabsf(gain);
            s.hold_s = 1e-3;
            s.mass_kg = Some(0.1);
            s.approach = Approach::Speed { v0_m_s: 0.5 };
            let mut m = Monitor::<1024, 4096>::new(s).unwrap();
            let mut state = 12345u32;
            let mut noise = move || {
                state ^= state << 13;
                state ^= state >> 17;
                state ^= state << 5;
                (state % 5) as i16 - 2
            };
            let mut n = 0;
            let mut out = |_: &ImpactReport| n += 1;
            let mut block = [0i16; 100];
            for pulse in 0..60i32 {
                let amplitude = (pulse % 7 + 1) * 60 * if pulse % 2 == 0 { 1 } else { -1 };
                let width = 50 + (pulse % 5) * 40;
                let mut k = 0i32;
                while k < 3000 {
                    for x in block.iter_mut() {
                        let shape = if (0..width).contains(&(k - 1000)) {
                            // A flat top over the middle third: ties at the peak.
                            let t = ((k - 1000) as f32 / width as f32).clamp(0.33, 0.67);
                            libm::sinf(core::f32::consts::PI * t)
                        } else {
                            0.0
                        };
                        *x = 2048 + (amplitude as f32 * shape) as i16 + noise();
                        k += 1;
                    }
                    m.push_block(&block, &mut out);
                }
            }
            assert!(n >= 55, "gain {gain}: {n} reports");
        }
    }
}
