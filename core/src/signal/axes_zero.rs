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
    /// The stride being accumulated (aligned with the zeros' own): Σ, min, max per axis.
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
    /// Axes whose quiet samples lie within `edge_counts` of their zero (the scene's edge
    /// level in counts), a new level becoming the zero after `settle_samples` (the scene's
    /// settle time; at least one stride). A non-finite or negative edge is taken as 0.
    pub fn new(edge_counts: f32, settle_samples: u32, free_fall: FreeFall) -> Self {
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
        }
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
        let flat = (0..3).all(|i| f32::from(self.max[i]) - f32::from(self.min[i]) <= span);
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
            for i in 0..3 {
                self.run_sum[i] += i64::from(self.sum[i]);
            }
        } else {
            self.run_strides = 1;
            self.run_first = mean;
            self.run_sum = self.sum.map(i64::from);
        }
        if self.run_strides >= self.settle_strides {
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

    /// 1 g is 100 counts: free fall below 25 for 50 samples.
    const FALL: FreeFall = FreeFall {
        below_counts: 25.0,
        samples: 50,
    };

    /// Noise of about ±`amp` counts (deterministic).
    fn noise(k: u32, axis: u32, amp: f32) -> f32 {
        let h = (k.wrapping_add(axis * 7919)).wrapping_mul(2_654_435_761) >> 16;
        amp * ((h % 1000) as f32 / 500.0 - 1.0)
    }

    /// A half-sine of `peak` counts along `dir` (a unit vector), 600 samples long from sample
    /// 2 000, on `rest` counts per axis, with ±2 counts of noise: the largest output.
    fn peak_of(rest: [f32; 3], dir: [f32; 3], peak: f32) -> i16 {
        let mut z = AxesZero::new(10.0, 5_000, FALL);
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
        let mut z = AxesZero::new(10.0, 2_000, FALL);
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
        let mut z = AxesZero::new(5.0, 2_000, FALL);
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
        let mut z = AxesZero::new(5.0, 2_000, FALL);
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
    fn any_input_gives_a_count_and_no_panic() {
        let mut z = AxesZero::new(
            f32::NAN,
            0,
            FreeFall {
                below_counts: f32::NAN,
                samples: 0,
            },
        );
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
        let mut z = AxesZero::new(
            f32::INFINITY,
            u32::MAX,
            FreeFall {
                below_counts: f32::INFINITY,
                samples: u32::MAX,
            },
        );
        assert_eq!(z.push([i16::MIN; 3]), 0);
        assert_eq!(z.push([i16::MAX; 3]), i16::MAX);
    }
}
