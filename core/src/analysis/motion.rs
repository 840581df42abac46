//! The measured motion of one impact: velocity and deformation from exact integer sums of the
//! raw counts, in one pass over the capture that gives the kinematics (crush time, maximum and
//! permanent deformation) and, for the fits, the deformation and velocity at evenly spaced
//! points of the contact.
//!
//! With the baseline frozen as the rational `S / W`, sample `j` contributes the integer
//! `d_j = W x_j - S`. After `k` samples from the onset, `C_k = Σ_{j<k} d_j` and
//! `Q_k = Σ_{j=1..k} C_j` are exact (i64: `|d| < 2^29`, gravity's shift included, and at
//! most 2^17 samples keep `|Q| <= |d| k (k + 1) / 2` below 2^62), and
//!
//! ```text
//! v_k = v0 - kv C_k                          (kv = gain / (W fs), m/s per unit of C)
//! x_k = x_lead + dt (k v0 - kv T_k / 2)      (trapezoid; T_k = 2 Q_k - C_k)
//! ```
//!
//! Samples are instants (sample `j` at time `j`, in samples from the onset, as every
//! position the stream reports), each standing for the interval `[j - ½, j + ½)` (the
//! midpoint rule): `v_k` is the velocity at time `k - ½`, and `x_k` the deformation then
//! (`x_lead` is the deformation at `-½`). Counting a sample's interval from its instant
//! instead put every crush half a sample late.
//!
//! So nothing drifts however long the capture; the only rounding is the conversion of the
//! sums at the few points where a value is needed. Per sample the pass costs two i64
//! additions (no floating point), which is what makes it cheap on the Cortex-M4.

use crate::signal::baseline::Deviation;

/// Longest run the sums may cover, samples (keeps `Q` within i64).
pub const MAX_SAMPLES: usize = 1 << 17;

/// What the pass needs to turn sums into metres and metres per second.
#[derive(Clone, Copy, Debug)]
pub struct Scale {
    /// Approach speed, m/s.
    pub v0: f64,
    /// Velocity per unit of `C`, m/s (`gain / (W fs)`).
    pub kv: f64,
    /// Sample period, s.
    pub dt: f64,
    /// Deformation at half a sample before the onset sample, m (first touch came a fraction
    /// of a sample earlier or later, at `v0`: negative if later, the body still approaching).
    pub x_lead: f64,
}

impl Scale {
    fn velocity(&self, c: i64) -> f64 {
        self.v0 - self.kv * c as f64
    }

    /// Deformation after `k` samples, with `t = T_k`.
    fn deformation(&self, k: usize, t: i64) -> f64 {
        self.x_lead + self.dt * (k as f64 * self.v0 - self.kv * t as f64 / 2.0)
    }
}

/// Where the fit points go: `x[i]` and `v[i]` get the deformation (m) and the velocity (in
/// units of `v0`) after sample `every * i` of the contact, for `i < x.len()`.
pub struct PointsOut<'a> {
    pub x: &'a mut [f32],
    pub v: &'a mut [f32],
    pub every: usize,
}

/// The kinematics the pass found, in samples from the onset and metres.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Found {
    /// When the velocity reached zero (fractional samples from the onset sample's instant).
    pub crush: f64,
    /// The deformation then, m.
    pub x_max: f64,
    /// The deformation at the separation, m.
    pub x_sep: f64,
}

/// `v` as f32 by the FPU's 32-bit conversions (two of them, a multiply-add; `i64 as f32` is
/// a soft-float call on the Cortex-M4): within two f32 roundings of the exact value.
#[inline]
fn to_f32(v: i64) -> f32 {
    // Sign and magnitude: both halves non-negative, so nothing cancels.
    let m = v.unsigned_abs();
    let f = (m >> 32) as u32 as f32 * 4_294_967_296.0 + m as u32 as f32;
    if v < 0 {
        -f
    } else {
        f
    }
}

/// The running sums: after `k` samples, `(c, q) = (C_k, Q_k)`.
#[derive(Clone, Copy)]
struct Sums {
    k: usize,
    c: i64,
    q: i64,
}

impl Sums {
    fn t(&self) -> i64 {
        2 * self.q - self.c
    }

    /// Integrates `samples` (the next ones), without looking for the crush.
    #[inline]
    fn run(&mut self, samples: &[i16], dev: Deviation) {
        let (mut c, mut q) = (self.c, self.q);
        for &x in samples {
            c += dev.of(x) as i64;
            q += c;
        }
        self.c = c;
        self.q = q;
        self.k += samples.len();
    }

    /// Integrates `samples` until `C` first reaches `c_stop` (it is below it on entry):
    /// returns the state before the sample that reached it and `C` after it, and stops there.
    #[inline]
    fn run_to_stop(&mut self, samples: &[i16], dev: Deviation, c_stop: i64) -> Option<(Sums, i64)> {
        let (mut c, mut q) = (self.c, self.q);
        let mut rest = samples.iter();
        let mut hit = None;
        for &x in rest.by_ref() {
            let c_next = c + dev.of(x) as i64;
            if c_next >= c_stop {
                hit = Some(c_next);
                break;
            }
            c = c_next;
            q += c;
        }
        // Samples integrated before the hit (the hit itself is the one taken out last).
        let before = samples.len() - rest.len() - usize::from(hit.is_some());
        let at = Sums {
            k: self.k + before,
            c,
            q,
        };
        match hit {
            Some(c_next) => {
                *self = Sums {
                    k: at.k + 1,
                    c: c_next,
                    q: q + c_next,
                };
                Some((at, c_next))
            }
            None => {
                *self = at;
                None
            }
        }
    }
}

/// Runs the sums over `samples` (the raw samples from the onset; `dev` removes the
/// baseline): the crush (first zero of the velocity) and the deformation at `separation`
/// (fractional samples from the onset), and the fit points if asked. `None` if the velocity
/// never reaches zero or the separation lies beyond the samples.
pub fn integrate(
    samples: &[i16],
    dev: Deviation,
    scale: &Scale,
    separation: f64,
    mut points: Option<PointsOut<'_>>,
) -> Option<Found> {
    let samples = samples.get(..samples.len().min(MAX_SAMPLES)).unwrap_or(&[]);
    if !(scale.kv > 0.0 && scale.kv.is_finite() && scale.v0 > 0.0 && separation >= 0.0) {
        return None;
    }
    // Stopped (v <= 0) once C >= v0 / kv.
    let c_stop = libm::ceil(scale.v0 / scale.kv);
    let c_stop = if c_stop < i64::MAX as f64 {
        c_stop as i64
    } else {
        i64::MAX
    };
    // The deformation at time `s` is the sums' after `s + ½` samples (midpoint rule).
    let sep_at = separation + 0.5;
    let sep_floor = libm::floor(sep_at) as usize;
    let n_points = points.as_ref().map_or(0, |p| p.x.len().min(p.v.len()));
    let every = points.as_ref().map_or(1, |p| p.every.max(1));
    // The points in f32 (one conversion of each sum, a multiply-add): the velocity in units
    // of v0, V = 1 - (kv / v0) C, and the deformation x = x_lead + k v0 dt - (kv dt / 2) T.
    let pv = (scale.kv / scale.v0) as f32;
    let px = (
        scale.x_lead as f32,
        (scale.v0 * scale.dt) as f32,
        (scale.kv * scale.dt / 2.0) as f32,
    );

    // Events in order of k: point i at k = every i + 1 (the state after sample every i), the
    // separation's two samples. Between events the sums run in tight loops.
    let mut s = Sums { k: 0, c: 0, q: 0 };
    let mut crush: Option<(Sums, i64)> = None;
    let mut at_sep: [Option<Sums>; 2] = [None, None];
    let mut point = 0usize;
    loop {
        let next_point = if point < n_points {
            every * point + 1
        } else {
            usize::MAX
        };
        let next_sep = match at_sep {
            [None, _] => sep_floor,
            [Some(_), None] => sep_floor + 1,
            _ => usize::MAX,
        };
        let next = next_point.min(next_sep);
        if next > samples.len() {
            break;
        }
        let run = samples.get(s.k..next).unwrap_or(&[]);
        if crush.is_none() {
            if let Some(found) = s.run_to_stop(run, dev, c_stop) {
                crush = Some(found);
                s.run(samples.get(s.k..next).unwrap_or(&[]), dev);
            }
        } else {
            s.run(run, dev);
        }
        if next_point == next {
            if let Some(p) = points.as_mut() {
                if let (Some(x), Some(v)) = (p.x.get_mut(point), p.v.get_mut(point)) {
                    *v = 1.0 - pv * to_f32(s.c);
                    *x = (px.0 + px.1 * s.k as f32 - px.2 * to_f32(s.t())).max(0.0);
                }
            }
            point += 1;
        }
        if next_sep == next {
            if let Some(slot) = at_sep.get_mut(next - sep_floor) {
                *slot = Some(s);
            }
        }
    }
    // The crush may come after the last event.
    if crush.is_none() {
        crush = s.run_to_stop(samples.get(s.k..).unwrap_or(&[]), dev, c_stop);
    }
    let (at, c_next) = crush?;
    let (v, v_next) = (scale.velocity(at.c), scale.velocity(c_next));
    let f = v / (v - v_next);
    let x_max = scale.deformation(at.k, at.t()) + scale.dt * f * v / 2.0;
    let [Some(s0), Some(s1)] = at_sep else {
        return None;
    };
    let frac = sep_at - sep_floor as f64;
    let (x0, x1) = (
        scale.deformation(s0.k, s0.t()),
        scale.deformation(s1.k, s1.t()),
    );
    Some(Found {
        crush: at.k as f64 + f - 0.5,
        x_max,
        x_sep: x0 + frac * (x1 - x0),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A constant deceleration of `a` counts from the onset: v = v0 - kv a k, exactly.
    #[test]
    fn the_two_part_conversion_is_within_two_roundings() {
        for v in [
            0i64,
            1,
            -1,
            123_456_789_012,
            -(1 << 62) + 12_345,
            (1 << 40) + 7,
            i64::MAX,
        ] {
            let exact = v as f64;
            let got = to_f32(v) as f64;
            assert!(
                (got - exact).abs() <= exact.abs() * 2.0 * f32::EPSILON as f64,
                "{v}"
            );
        }
    }

    #[test]
    fn a_constant_deceleration_stops_where_the_algebra_says() {
        let dev = Deviation::new(0, 1);
        let samples = [10i16; 1000];
        let scale = Scale {
            v0: 1.0,
            kv: 1e-3,
            dt: 1e-3,
            x_lead: 0.0,
        };
        // The sums start half a sample before the onset's instant (x_lead there): v reaches 0
        // after 1 / (1e-3 * 10) = 100 samples, at 99.5; x then is v0^2 / (2 a) with
        // a = 10 * kv / dt = 10 m/s²: 0.05 m.
        let mut x = [0f32; 4];
        let mut v = [0f32; 4];
        let f = integrate(
            &samples,
            dev,
            &scale,
            150.5,
            Some(PointsOut {
                x: &mut x,
                v: &mut v,
                every: 40,
            }),
        )
        .unwrap();
        assert!((f.crush - 99.5).abs() < 1e-9, "{}", f.crush);
        assert!((f.x_max - 0.05).abs() < 1e-9, "{}", f.x_max);
        // At 150.5 samples, 151 after the start: 0.05 - 10 (0.051)^2 / 2 (moving back out).
        let want = 0.05 - 10.0 * 0.051f64.powi(2) / 2.0;
        assert!((f.x_sep - want).abs() < 2e-6, "{} {want}", f.x_sep);
        // Point i: after sample 40 i, k = 40 i + 1: v = 1 - 0.01 k.
        for (i, (&x, &v)) in x.iter().zip(&v).enumerate() {
            let k = (40 * i + 1) as f64;
            assert!((v as f64 - (1.0 - 0.01 * k)).abs() < 1e-6, "{i}: {v}");
            let want = 1e-3 * k - 10.0 * (1e-3 * k).powi(2) / 2.0;
            assert!((x as f64 - want).abs() < 1e-7, "{i}: {x} {want}");
        }
        // No stop within the samples: nothing.
        assert!(integrate(&samples[..50], dev, &scale, 40.0, None).is_none());
    }
}
