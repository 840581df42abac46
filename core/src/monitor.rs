//! The whole pipeline in one object: the streaming stage with one capture buffer, each impact
//! analysed as soon as it ends. The host (`impact analyze`), the tests and the benchmarks use
//! it; the firmware runs the same two halves in tasks of different priorities.

use crate::analysis::{analyse, Workspace};
use crate::capture::{Capture, Sink};
use crate::error::Error;
use crate::report::ImpactReport;
use crate::scene::Scene;
use crate::stream::{Counters, Stream};

/// Streams samples of one channel through a [`Scene`] and reports every impact in full.
///
/// `PRE` (a power of two) is the ring of recent samples (pre-trigger history, baseline
/// window); `CAP` the capture length (samples from just before the onset to the end of the
/// hold).
pub struct Monitor<const PRE: usize, const CAP: usize> {
    stream: Stream<PRE>,
    capture: Capture<CAP>,
    work: Workspace<CAP>,
}

/// The sink that analyses each capture at once.
struct Inline<'a, const CAP: usize, F: FnMut(&ImpactReport)> {
    capture: &'a mut Capture<CAP>,
    work: &'a mut Workspace<CAP>,
    out: &'a mut F,
}

impl<const CAP: usize, F: FnMut(&ImpactReport)> Sink<CAP> for Inline<'_, CAP, F> {
    fn buffer(&mut self) -> Option<&mut Capture<CAP>> {
        Some(self.capture)
    }

    // Not inlined: the analysis's report and locals stay off the stream's `push_block`,
    // whose per-sample loop paid 2.8 instructions a sample in an impact when they were in
    // its frame (`impact bench m4`).
    #[inline(never)]
    fn captured(&mut self, scene: &Scene) {
        let report = analyse(self.capture, scene, self.work);
        (self.out)(&report);
    }

    fn skipped(&mut self, report: &ImpactReport) {
        (self.out)(report);
    }
}

impl<const PRE: usize, const CAP: usize> Monitor<PRE, CAP> {
    /// A monitor for `scene`; fails on an invalid scene or sizes.
    pub fn new(scene: Scene) -> Result<Self, Error> {
        let mut m = Self::unconfigured();
        m.configure(scene)?;
        Ok(m)
    }

    /// A monitor evaluated at compile time, for a `static`: the buffers are too big to build
    /// on a small stack and move into place. It runs a placeholder scene until
    /// [`Self::configure`] gives it the real one.
    ///
    /// ```
    /// use impact_core::Monitor;
    /// static M: Monitor<4096, 8192> = Monitor::unconfigured();
    /// ```
    pub const fn unconfigured() -> Self {
        Self {
            stream: Stream::unconfigured(),
            capture: Capture::new(),
            work: Workspace::new(),
        }
    }

    /// Starts over with `scene`, in place; fails on an invalid scene or sizes (the hold must
    /// be under half the capture), and then leaves the monitor as it was.
    pub fn configure(&mut self, scene: Scene) -> Result<(), Error> {
        self.stream.configure_for(scene, self.capture.capacity())?;
        self.work.prepare(&scene);
        Ok(())
    }

    /// As [`Self::configure`], with captures of `len` samples (at least 64, at most `CAP`): a
    /// host analysing with the board's capture length. A contact longer than the capture is
    /// kept at a coarser step ([`Capture::extend_decimating`]).
    ///
    /// The scene and the length are checked before either is used: on a failure the capture
    /// keeps what it holds (it used to be emptied, an impact under way cut).
    pub fn configure_with_capture(&mut self, scene: Scene, len: usize) -> Result<(), Error> {
        self.stream
            .configure_for(scene, Capture::<CAP>::capacity_for(len))?;
        self.capture.set_capacity(len);
        self.work.prepare(&scene);
        Ok(())
    }

    /// The scene in use.
    pub fn scene(&self) -> &Scene {
        self.stream.scene()
    }

    /// Counters so far.
    pub fn counters(&self) -> Counters {
        self.stream.counters()
    }

    /// True while an impact is being captured.
    pub fn in_impact(&self) -> bool {
        self.stream.in_impact()
    }

    /// True once a baseline has been learned (impacts can be detected).
    pub fn is_armed(&self) -> bool {
        self.stream.is_armed()
    }

    /// Sets the approach speed for the next impacts (a light gate's reading), m/s.
    pub fn set_approach_speed(&mut self, v0_m_s: Option<f32>) {
        self.stream.set_approach_speed(v0_m_s);
    }

    /// One sample.
    pub fn push(&mut self, sample: i16, out: &mut impl FnMut(&ImpactReport)) {
        self.push_block(core::slice::from_ref(&sample), out);
    }

    /// A block of samples. Calls `out` once per finished impact.
    pub fn push_block(&mut self, block: &[i16], out: &mut impl FnMut(&ImpactReport)) {
        let mut sink = Inline {
            capture: &mut self.capture,
            work: &mut self.work,
            out,
        };
        self.stream.push_block(block, &mut sink);
    }

    /// `lost` samples never arrived: see [`Stream::gap`].
    pub fn gap(&mut self, lost: u64, out: &mut impl FnMut(&ImpactReport)) {
        let mut sink = Inline {
            capture: &mut self.capture,
            work: &mut self.work,
            out,
        };
        self.stream.gap(lost, &mut sink);
    }

    /// Ends the stream: an impact in progress is reported as
    /// [`crate::Status::StreamEnded`].
    pub fn finish(&mut self, out: &mut impl FnMut(&ImpactReport)) {
        let mut sink = Inline {
            capture: &mut self.capture,
            work: &mut self.work,
            out,
        };
        self.stream.finish(&mut sink);
    }
}

#[cfg(test)]
mod peak_tests {
    use crate::{Approach, Calibration, ImpactReport, Monitor, Scene};

    /// Reports of many pulses (both signs, flat tops with ties, noise, several gains): the
    /// report's peak from the stream's integer peak must equal a scan of the window
    /// (`analysis::analyse` asserts it under `cfg(test)`).
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

/// What the monitor's tests below share: a 500 kS/s scene and its half-sine pulse.
#[cfg(test)]
mod pulses {
    extern crate std;
    use crate::{Calibration, Scene};

    /// 500 kS/s, 0.39 m/s² a count, a 10 m/s² trigger, a 1 m/s² edge and a 2 ms hold.
    pub fn pulse_scene() -> Scene {
        let mut s = Scene::new(
            Calibration {
                gain_m_s2_per_count: 0.390625,
                sample_rate_hz: 500_000.0,
            },
            10.0,
        );
        s.edge_m_s2 = 1.0;
        s.hold_s = 2e-3;
        s
    }

    /// A half-sine of 50 counts over 2000 samples (4 ms) on a level of 100, appended to `v`.
    pub fn push_pulse(v: &mut std::vec::Vec<i16>) {
        for k in 0..2000 {
            v.push(100 + (50.0 * libm::sinf(core::f32::consts::PI * k as f32 / 2000.0)) as i16);
        }
    }
}

#[cfg(test)]
mod next_hit_tests {
    extern crate std;
    use super::pulses::{pulse_scene, push_pulse};
    use crate::{ImpactReport, Monitor};

    /// Two pulses 0.6 ms apart with noise that flickers at the edge level on their flanks:
    /// the signal came back for longer than an eighth of the hold, so they are two impacts,
    /// the second starting where the first's window ends.
    #[test]
    fn a_second_hit_after_a_return_to_the_baseline_is_its_own_impact() {
        let s = pulse_scene();
        let mut m = Monitor::<4096, 32768>::new(s).unwrap();
        let mut v = std::vec::Vec::new();
        v.extend(core::iter::repeat_n(100i16, 5000));
        push_pulse(&mut v);
        v.extend(core::iter::repeat_n(100i16, 300));
        push_pulse(&mut v);
        v.extend(core::iter::repeat_n(100i16, 5000));
        let mut state = 1u32;
        for x in v.iter_mut() {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            *x += (state % 3) as i16 - 1;
        }
        let mut out = std::vec::Vec::new();
        for b in v.chunks(256) {
            m.push_block(b, &mut |r: &ImpactReport| out.push(*r));
        }
        m.finish(&mut |r: &ImpactReport| out.push(*r));
        assert_eq!(out.len(), 2, "{out:#?}");
        assert_eq!(out[0].end_sample, out[1].start_sample);
        // The second pulse leaves the edge band ~32 samples after it starts at 7300.
        assert!((out[1].start_sample as i64 - 7332).abs() < 20, "{out:#?}");
        let dv = (out[0].delta_v_m_s.unwrap(), out[1].delta_v_m_s.unwrap());
        assert!((dv.0 / dv.1 - 1.0).abs() < 0.01, "{dv:?}");
    }
}

#[cfg(test)]
mod configure_tests {
    extern crate std;
    use super::pulses::{pulse_scene, push_pulse};
    use crate::{ImpactReport, Monitor};

    /// A scene refused half way through an impact leaves the monitor as it was: the impact's
    /// report is the one a monitor never asked gives, to the bit.
    #[test]
    fn a_refused_capture_length_leaves_an_impact_under_way_whole() {
        let s = pulse_scene();
        let mut v = std::vec![100i16; 5000];
        push_pulse(&mut v);
        v.extend(core::iter::repeat_n(100i16, 5000));
        let run = |refuse: bool| {
            let mut m = Monitor::<4096, 32768>::new(s).unwrap();
            let mut out = std::vec::Vec::new();
            for (i, b) in v.chunks(256).enumerate() {
                if refuse && i == 24 {
                    assert!(m.in_impact());
                    // A hold of 1000 samples does not fit under half of 1024.
                    assert!(m.configure_with_capture(s, 1024).is_err());
                }
                m.push_block(b, &mut |r: &ImpactReport| out.push(*r));
            }
            m.finish(&mut |r: &ImpactReport| out.push(*r));
            out
        };
        let (refused, asked_nothing) = (run(true), run(false));
        assert_eq!(asked_nothing.len(), 1);
        assert_eq!(
            std::format!("{refused:?}"),
            std::format!("{asked_nothing:?}")
        );
    }
}
