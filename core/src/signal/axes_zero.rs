//! Three axes zeroed each on its own before their magnitude, `|f − f₀|`, as SAE J211 and
//! ISO 6487 zero every channel before a resultant is formed: not `|f| − |f₀|`. A sled's 12.6 g
//! pulse along x with gravity's 1 g on z peaks 7.6 % low as a difference of magnitudes
//! (`sqrt(12.6² + 1) − 1`), and one along −z 16 % low; zeroed first, both are 12.6 g.
//!
//! Each axis's zero is a [`Baseline`] of its quiet strides (every sample within the edge
//! level of it, the stride's mean within its own noise: a slow pulse's flank cannot drag it
//! along). Free fall ([`FreeFall`]: the magnitude well below g for a while) is the sensor's
//! zero force in any orientation and becomes the zero at once (a dropped recorder tumbling
//! between bounces). A
//! level the three axes move to and hold, flat, for the settle time (a recorder turned onto
//! another face at rest) becomes the new zero, as the stream's own level watch does for one
//! channel; not after a fall (a body that fell and came to rest is the stream's `settled`). Integer counts in and out, f32 maths: the
//! same on the board and on the host.

use super::baseline::{Baseline, STRIDE};

/// Quiet strides each axis's zero is the mean of (1 024 samples).
const ZERO_STRIDES: usize = 16;

/// Three axes (counts) into the magnitude of their deviations from their zeros (counts).
pub struct AxesZero {
    zeros: [Baseline<ZERO_STRIDES>; 3],
    /// Each axis's first sample: its zero until a first quiet stride is learned.
    first: Option<[i16; 3]>,
    /// The edge level, counts: a quiet sample lies within it of the zero.
    edge: f32,
    /// Strides a new level must hold, flat, to become the zero.
    settle_strides: u32,
    /// The stride being accumulated (from the first sample, as the zeros' own until a free
    /// fall restarts theirs): Σ, min, max per axis.
    sum: [i32; 3],
    min: [i16; 3],
    max: [i16; 3],
    filled: usize,
    /// The run of flat strides at one level: its first stride's mean, Σ per axis, length.
    run_first: [f32; 3],
    run_sum: [i64; 3],
    run_strides: u32,
    /// Free fall: the magnitude below this (counts, squared) for `fall_samples` in a row.
    fall_below_sq: f32,
    fall_samples: u32,
    /// Samples in a row of free fall so far.
    falling: u32,
    /// Each axis's rails (counts): a stride touching one is no level.
    rails: [(i16, i16); 3],
    /// Whether any stride of the run varied at all (a level without noise is a stuck
    /// sensor, not a level).
    run_varies: bool,
}

/// What [`AxesZero`] is set with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    /// The edge level, counts (the scene's): a quiet sample lies within it of the zero.
    pub edge_counts: f32,
    /// A new level becomes the zero after this many samples (the scene's settle time).
    pub settle_samples: u32,
    pub free_fall: FreeFall,
    /// Each axis's rails, counts (`(i16::MIN, i16::MAX)`: none known).
    pub rails: [(i16, i16); 3],
}

/// What [`AxesZero`] takes as free fall: the three axes' magnitude below `below_counts` (a
/// quarter of g: at rest a sensor reads g in any orientation) for `samples` in a row (long
/// enough that a pulse crossing zero on its way is not it). Free fall is the sensor's zero
/// force, whatever the orientation (a body tumbling between bounces), so 0 becomes the zero
/// at once, without waiting for the level to settle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FreeFall {
    pub below_counts: f32,
    pub samples: u32,
}

impl AxesZero {
    /// Axes zeroed with `settings` (a new level after at least one stride; a non-finite or
    /// negative edge or free-fall level taken as 0).
    pub fn new(settings: Settings) -> Self {
        let Settings {
            edge_counts,
            settle_samples,
            free_fall,
            rails,
        } = settings;
        let finite = |v: f32| if v.is_finite() && v > 0.0 { v } else { 0.0 };
        let edge = finite(edge_counts);
        let below = finite(free_fall.below_counts);
        Self {
            zeros: [Baseline::new(), Baseline::new(), Baseline::new()],
            first: None,
            edge,
            settle_strides: settle_samples.div_ceil(STRIDE as u32).max(1),
            sum: [0; 3],
            min: [i16::MAX; 3],
            max: [i16::MIN; 3],
            filled: 0,
            run_first: [0.0; 3],
            run_sum: [0; 3],
            run_strides: 0,
            fall_below_sq: below * below,
            fall_samples: free_fall.samples.max(1),
            falling: 0,
            rails,
            run_varies: false,
        }
    }

    /// Starts from `zero` (each axis's zero until a quiet stride is learned) rather than
    /// the first sample: a record that begins inside a pulse ([`Self::first_quiet`]).
    pub fn seed(&mut self, zero: [i16; 3]) {
        self.first = Some(zero);
        // Learned as one quiet stride: later strides are quiet only near it.
        for (z, &v) in self.zeros.iter_mut().zip(&zero) {
            z.restart_at(i64::from(v) * STRIDE as i64, STRIDE as i64);
        }
    }

    /// The mean of the first stride of `samples` that is flat on every axis (each within
    /// twice `edge_counts`, touching no rail, varying), rounded: a record's zero, found
    /// ahead when the record is at hand.
    pub fn first_quiet(samples: &[[i16; 3]], settings: &Settings) -> Option<[i16; 3]> {
        samples.chunks_exact(STRIDE).find_map(|stride| {
            let mut sum = [0i32; 3];
            let mut min = [i16::MAX; 3];
            let mut max = [i16::MIN; 3];
            for s in stride {
                for i in 0..3 {
                    sum[i] += i32::from(s[i]);
                    min[i] = min[i].min(s[i]);
                    max[i] = max[i].max(s[i]);
                }
            }
            let flat = (0..3).all(|i| {
                f32::from(max[i]) - f32::from(min[i]) <= 2.0 * settings.edge_counts
                    && min[i] > settings.rails[i].0
                    && max[i] < settings.rails[i].1
            });
            let varies = (0..3).any(|i| max[i] > min[i]);
            (flat && varies).then(|| {
                sum.map(|v| libm::roundf(v as f32 / STRIDE as f32).clamp(-32768.0, 32767.0) as i16)
            })
        })
    }

    /// Each axis's zero, counts (its first sample until a quiet stride is learned; 0 before
    /// any sample).
    pub fn zeros(&self) -> [f32; 3] {
        let first = self.first.unwrap_or([0; 3]);
        core::array::from_fn(|i| {
            if self.zeros[i].is_armed() {
                self.zeros[i].mean()
            } else {
                f32::from(first[i])
            }
        })
    }

    /// The magnitude of `sample`'s deviation from the zeros, counts (rounded, at most
    /// `i16::MAX`); then the sample is learned from.
    pub fn push(&mut self, sample: [i16; 3]) -> i16 {
        if self.first.is_none() {
            self.first = Some(sample);
        }
        let zeros = self.zeros();
        let d: [f32; 3] = core::array::from_fn(|i| f32::from(sample[i]) - zeros[i]);
        let m = libm::sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        let out = libm::roundf(m).min(f32::from(i16::MAX)) as i16;
        self.learn(sample, zeros);
        out
    }

    fn learn(&mut self, sample: [i16; 3], zeros: [f32; 3]) {
        // Free fall: 0 becomes the zero once held, unless the zeros are there already.
        let sq = |v: [f32; 3]| v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        if sq(sample.map(f32::from)) < self.fall_below_sq {
            self.falling = self.falling.saturating_add(1);
            if self.falling >= self.fall_samples && sq(zeros) >= self.fall_below_sq {
                for zero in &mut self.zeros {
                    zero.restart_at(0, STRIDE as i64);
                }
                self.run_strides = 0;
            }
        } else {
            self.falling = 0;
        }
        for (i, &x) in sample.iter().enumerate() {
            self.zeros[i].add(&[x], self.edge);
            self.sum[i] += i32::from(x);
            self.min[i] = self.min[i].min(x);
            self.max[i] = self.max[i].max(x);
        }
        self.filled += 1;
        if self.filled < STRIDE {
            return;
        }
        self.stride_done(zeros);
        self.sum = [0; 3];
        self.min = [i16::MAX; 3];
        self.max = [i16::MIN; 3];
        self.filled = 0;
    }

    /// A completed stride: flat on every axis and at the run's level, it lengthens the run;
    /// a run beyond the edge level from the zeros for the settle time becomes the zeros.
    fn stride_done(&mut self, zeros: [f32; 3]) {
        let span = 2.0 * self.edge;
        // Flat: within twice the edge level, at no rail (a clipped or stuck axis is no level).
        let flat = (0..3).all(|i| {
            f32::from(self.max[i]) - f32::from(self.min[i]) <= span
                && self.min[i] > self.rails[i].0
                && self.max[i] < self.rails[i].1
        });
        let varies = (0..3).any(|i| self.max[i] > self.min[i]);
        let mean: [f32; 3] = core::array::from_fn(|i| self.sum[i] as f32 / STRIDE as f32);
        let beyond = (0..3).any(|i| libm::fabsf(mean[i] - zeros[i]) > self.edge);
        // A body that fell and came to rest keeps free fall as its zero: its rest is the
        // stream's to name (`settled`), not a new zero that would end its contact.
        let falling =
            zeros[0] * zeros[0] + zeros[1] * zeros[1] + zeros[2] * zeros[2] < self.fall_below_sq;
        if !(flat && beyond) || falling {
            self.run_strides = 0;
            return;
        }
        let same = (0..3).all(|i| libm::fabsf(mean[i] - self.run_first[i]) <= self.edge);
        if self.run_strides > 0 && same {
            self.run_strides += 1;
            self.run_varies |= varies;
            for i in 0..3 {
                self.run_sum[i] += i64::from(self.sum[i]);
            }
        } else {
            self.run_strides = 1;
            self.run_varies = varies;
            self.run_first = mean;
            self.run_sum = self.sum.map(i64::from);
        }
        if self.run_strides >= self.settle_strides && self.run_varies {
            let n = i64::from(self.run_strides) * STRIDE as i64;
            // The newest strides only, as many as a zero holds.
            let keep = n.min((ZERO_STRIDES * STRIDE) as i64);
            for i in 0..3 {
                let sum = self.run_sum[i] * keep / n;
                self.zeros[i].restart_at(sum, keep);
            }
            self.run_strides = 0;
        }
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;

    /// 1 g is 100 counts: free fall below 25 for 50 samples; no rails.
    const FALL: FreeFall = FreeFall {
        below_counts: 25.0,
        samples: 50,
    };

    fn zeroed(edge_counts: f32, settle_samples: u32) -> AxesZero {
        AxesZero::new(Settings {
            edge_counts,
            settle_samples,
            free_fall: FALL,
            rails: [(i16::MIN, i16::MAX); 3],
        })
    }

    /// Noise of about ±`amp` counts (deterministic).
    fn noise(k: u32, axis: u32, amp: f32) -> f32 {
        let h = (k.wrapping_add(axis * 7919)).wrapping_mul(2_654_435_761) >> 16;
        amp * ((h % 1000) as f32 / 500.0 - 1.0)
    }

    /// A half-sine of `peak` counts along `dir` (a unit vector), 600 samples long from sample
    /// 2 000, on `rest` counts per axis, with ±2 counts of noise: the largest output.
    fn peak_of(rest: [f32; 3], dir: [f32; 3], peak: f32) -> i16 {
        let mut z = zeroed(10.0, 5_000);
        let mut best = 0;
        for k in 0..4_000u32 {
            let t = k as f32 - 2_000.0;
            let p = if (0.0..600.0).contains(&t) {
                peak * libm::sinf(core::f32::consts::PI * t / 600.0)
            } else {
                0.0
            };
            let s: [i16; 3] = core::array::from_fn(|i| {
                libm::roundf(rest[i] + dir[i] * p + noise(k, i as u32, 2.0)) as i16
            });
            best = best.max(z.push(s));
        }
        best
    }

    #[test]
    fn a_pulse_is_its_own_size_whatever_the_gravity_beside_or_against_it() {
        // 1 g = 100 counts on z; a 1 260-count (12.6 g) pulse along x, along -z, along +z.
        for (dir, what) in [
            ([1.0, 0.0, 0.0], "x beside gravity"),
            ([0.0, 0.0, -1.0], "-z against gravity"),
            ([0.0, 0.0, 1.0], "+z with gravity"),
            ([0.6, 0.8, 0.0], "in the xy plane"),
        ] {
            let p = peak_of([0.0, 0.0, 100.0], dir, 1260.0);
            assert!((f32::from(p) - 1260.0).abs() <= 4.0, "{what}: {p}");
        }
    }

    #[test]
    fn a_level_held_for_the_settle_time_becomes_the_zero_and_a_pulse_does_not() {
        let mut z = zeroed(10.0, 2_000);
        // At rest on z (100 counts), then in free fall (0 on every axis) for 4 000 samples.
        for k in 0..3_000u32 {
            z.push([0, 0, 100 + (k % 3) as i16 - 1]);
        }
        assert!((z.zeros()[2] - 100.0).abs() < 1.0);
        let mut out = 0;
        for k in 0..4_000u32 {
            out = z.push([0, 0, (k % 3) as i16 - 1]);
        }
        assert!(z.zeros()[2].abs() < 1.0, "{:?}", z.zeros());
        assert!(out <= 2, "{out}");
        // A slow pulse (a 3 000-sample half-sine of 400 counts, shorter than the settle time)
        // does not move the zero.
        for k in 0..3_000u32 {
            let p = 400.0 * libm::sinf(core::f32::consts::PI * k as f32 / 3_000.0);
            z.push([libm::roundf(p) as i16, 0, 0]);
        }
        assert!(z.zeros()[0].abs() < 1.0, "{:?}", z.zeros());
    }

    #[test]
    fn a_tumbling_body_reads_zero_in_flight_and_its_rest_after_the_fall_is_g() {
        let mut z = zeroed(5.0, 2_000);
        let run = |z: &mut AxesZero, n: u32, s: &dyn Fn(u32) -> [i16; 3]| {
            (0..n).map(|k| z.push(s(k))).collect::<std::vec::Vec<i16>>()
        };
        // At rest on its z face, released: free fall, a hit along x, a flight spinning (a
        // centripetal 10 counts on y), then at rest on its x face.
        run(&mut z, 3_000, &|k| [0, 0, 100 + (k % 3) as i16 - 1]);
        let fall = run(&mut z, 1_000, &|_| [0, 0, 0]);
        assert!(fall[100..].iter().all(|&v| v == 0), "{:?}", &fall[..60]);
        let hit = run(&mut z, 300, &|k| {
            let p = 1_000.0 * libm::sinf(core::f32::consts::PI * k as f32 / 300.0);
            [libm::roundf(p) as i16, 0, 0]
        });
        assert_eq!(*hit.iter().max().unwrap(), 1_000);
        let flight = run(&mut z, 1_000, &|_| [0, 10, 0]);
        assert!(flight.iter().all(|&v| v == 10), "{:?}", &flight[..10]);
        // At rest after the fall: the zero stays free fall (the rest is the stream's
        // `settled`), the magnitude g.
        let rest = run(&mut z, 6_000, &|k| [100 + (k % 3) as i16 - 1, 0, 0]);
        assert!(
            rest.iter().all(|&v| (99..=101).contains(&v)),
            "{:?}",
            z.zeros()
        );
    }

    #[test]
    fn a_recorder_turned_onto_another_face_at_rest_is_zeroed_there() {
        let mut z = zeroed(5.0, 2_000);
        for k in 0..3_000u32 {
            z.push([0, 0, 100 + (k % 3) as i16 - 1]);
        }
        let mut last = 0;
        for k in 0..6_000u32 {
            last = z.push([100 + (k % 3) as i16 - 1, 0, 0]);
        }
        assert!(last <= 2, "{:?}", z.zeros());
        assert!((z.zeros()[0] - 100.0).abs() < 1.0 && z.zeros()[2].abs() < 1.0);
    }

    #[test]
    fn an_axis_stuck_at_its_rail_or_without_noise_is_no_new_zero() {
        let rails = [(-1_000, 1_000); 3];
        for (stuck, what) in [(1_000, "at its rail"), (400, "without noise")] {
            let mut z = AxesZero::new(Settings {
                edge_counts: 5.0,
                settle_samples: 500,
                free_fall: FALL,
                rails,
            });
            for k in 0..3_000u32 {
                z.push([0, 0, 100 + (k % 3) as i16 - 1]);
            }
            let mut last = 0;
            for _ in 0..5_000 {
                last = z.push([stuck, 0, 100]);
            }
            assert_eq!(last, stuck, "{what}: {:?}", z.zeros());
        }
    }

    #[test]
    fn a_record_that_starts_inside_a_pulse_is_zeroed_from_its_first_quiet_stride() {
        // 600 samples of a decaying pulse on x, then rest on z.
        let samples: std::vec::Vec<[i16; 3]> = (0..3_000u32)
            .map(|k| {
                let p = if k < 600 {
                    libm::roundf(1_000.0 * libm::cosf(core::f32::consts::PI * k as f32 / 1_200.0))
                        as i16
                } else {
                    0
                };
                [p, 0, 100 + (k % 3) as i16 - 1]
            })
            .collect();
        let settings = Settings {
            edge_counts: 5.0,
            settle_samples: 500,
            free_fall: FALL,
            rails: [(i16::MIN, i16::MAX); 3],
        };
        let zero = AxesZero::first_quiet(&samples, &settings).unwrap();
        assert_eq!(zero, [0, 0, 100]);
        let mut z = AxesZero::new(settings);
        z.seed(zero);
        let out: std::vec::Vec<i16> = samples.iter().map(|&s| z.push(s)).collect();
        // The pulse from its first sample, then the rest at 0: no step, no plateau.
        assert!((i32::from(out[0]) - 1_000).abs() <= 2, "{}", out[0]);
        assert!(out[700..].iter().all(|&v| v <= 2));
    }

    #[test]
    fn any_input_gives_a_count_and_no_panic() {
        let mut z = AxesZero::new(Settings {
            edge_counts: f32::NAN,
            settle_samples: 0,
            free_fall: FreeFall {
                below_counts: f32::NAN,
                samples: 0,
            },
            rails: [(0, 0); 3],
        });
        for s in [
            [i16::MIN; 3],
            [i16::MAX; 3],
            [i16::MIN, i16::MAX, 0],
            [0; 3],
            [i16::MAX, i16::MIN, i16::MAX],
        ] {
            for _ in 0..100 {
                assert!(z.push(s) >= 0);
            }
        }
        let mut z = AxesZero::new(Settings {
            edge_counts: f32::INFINITY,
            settle_samples: u32::MAX,
            free_fall: FreeFall {
                below_counts: f32::INFINITY,
                samples: u32::MAX,
            },
            rails: [(i16::MAX, i16::MIN); 3],
        });
        let stuck = [[7i16; 3]; 128];
        assert_eq!(
            AxesZero::first_quiet(
                &stuck,
                &Settings {
                    edge_counts: f32::NAN,
                    settle_samples: 0,
                    free_fall: FreeFall {
                        below_counts: 0.0,
                        samples: 0
                    },
                    rails: [(i16::MIN, i16::MAX); 3],
                }
            ),
            None
        );
        assert_eq!(z.push([i16::MIN; 3]), 0);
        assert_eq!(z.push([i16::MAX; 3]), i16::MAX);
    }
}
