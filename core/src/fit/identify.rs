//! The least-squares identification itself (feature `fit`).

use super::{Fits, HertzFit, NonlinearFit, TwoPhaseFit};
use crate::real::pow;
use crate::solve::roots::golden_max;

/// Points the least-squares sums see per pass at most: a contact of 12 600 samples (the seed
/// bench at 500 kS/s) is thinned to every 7th, which changes no fitted value beyond its noise
/// and cuts the exponent search on the Cortex-M4 several-fold.
const MAX_POINTS: usize = 2048;

/// The measured impact, from first touch to separation.
pub struct Trajectory<'a> {
    /// Deceleration per sample, m/s².
    pub accel: &'a [f32],
    /// First sample of the contact.
    pub onset: usize,
    /// First sample after separation.
    pub separation: usize,
    /// Approach speed, m/s.
    pub v0: f32,
    /// Sample period, s.
    pub dt: f32,
    pub mass_kg: f32,
    /// Measured maximum deformation, m (the deformation scale).
    pub x_m: f32,
    /// Deformation already reached at the onset sample (first touch is a fraction of a
    /// sample earlier), m.
    pub x0_m: f32,
}

/// One sample of the loop in scaled units: deformation, rate, force.
#[derive(Clone, Copy)]
struct Point {
    x: f64,
    v: f64,
    f: f64,
}

impl Trajectory<'_> {
    /// The peak force magnitude, N.
    fn peak_force(&self) -> f32 {
        self.contact().fold(0.0f32, |m, &a| m.max(libm::fabsf(a))) * self.mass_kg
    }

    fn contact(&self) -> impl Iterator<Item = &f32> {
        self.accel.iter().take(self.separation).skip(self.onset)
    }

    /// Calls `f` with scaled samples (every sample up to `MAX_POINTS`, then evenly thinned);
    /// velocity and deformation are integrated (trapezoid) over every sample from `v0` at the
    /// onset.
    fn for_each(&self, f_scale: f32, mut f: impl FnMut(Point)) {
        let every = (self.separation.saturating_sub(self.onset) / MAX_POINTS).max(1);
        let (v0, dt) = (self.v0 as f64, self.dt as f64);
        let (inv_x, inv_v, inv_f) = (1.0 / self.x_m as f64, 1.0 / v0, 1.0 / f_scale as f64);
        let m = self.mass_kg as f64;
        let (mut v, mut x) = (v0, self.x0_m as f64);
        for (k, &a) in self.contact().enumerate() {
            let v_next = v - dt * a as f64;
            x += dt * (v + v_next) / 2.0;
            v = v_next;
            if k % every != 0 {
                continue;
            }
            f(Point {
                x: (x * inv_x).max(0.0),
                v: v * inv_v,
                f: m * a as f64 * inv_f,
            });
        }
    }
}

/// Solves the 3×3 system `A θ = b` by Gaussian elimination with partial pivoting.
#[allow(clippy::needless_range_loop)]
fn solve3(mut a: [[f64; 3]; 3], mut b: [f64; 3]) -> Option<[f64; 3]> {
    for col in 0..3 {
        let pivot =
            (col..3).max_by(|&i, &j| libm::fabs(a[i][col]).total_cmp(&libm::fabs(a[j][col])))?;
        if !(libm::fabs(a[pivot][col]) > 1e-300) {
            return None;
        }
        a.swap(col, pivot);
        b.swap(col, pivot);
        for row in col + 1..3 {
            let f = a[row][col] / a[col][col];
            for k in col..3 {
                a[row][k] -= f * a[col][k];
            }
            b[row] -= f * b[col];
        }
    }
    let mut x = [0.0; 3];
    for row in (0..3).rev() {
        let mut s = b[row];
        for k in row + 1..3 {
            s -= a[row][k] * x[k];
        }
        x[row] = s / a[row][row];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// Two-phase Kelvin–Voigt.
fn two_phase(t: &Trajectory<'_>, f_pk: f32) -> Option<TwoPhaseFit> {
    let (mut sfx, mut sxx) = (0.0, 0.0);
    let mut a = [[0.0f64; 3]; 3];
    let mut b = [0.0f64; 3];
    let mut restitution = false;
    t.for_each(f_pk, |p| {
        if !restitution && p.v <= 0.0 {
            restitution = true;
        }
        if restitution {
            let phi = [p.x, -1.0, p.v];
            for i in 0..3 {
                for j in 0..3 {
                    a[i][j] += phi[i] * phi[j];
                }
                b[i] += phi[i] * p.f;
            }
        } else {
            sfx += p.f * p.x;
            sxx += p.x * p.x;
        }
    });
    let kc = sfx / sxx;
    let [kr, krxp, c] = solve3(a, b)?;
    if !(kc.is_finite() && kr > 0.0) {
        return None;
    }
    // Residual pass.
    let (mut rss, mut count) = (0.0, 0u32);
    let mut restitution = false;
    t.for_each(f_pk, |p| {
        if !restitution && p.v <= 0.0 {
            restitution = true;
        }
        let model = if restitution {
            kr * p.x - krxp + c * p.v
        } else {
            kc * p.x
        };
        rss += (p.f - model) * (p.f - model);
        count += 1;
    });
    let (xs, vs, fs) = (t.x_m as f64, t.v0 as f64, f_pk as f64);
    Some(TwoPhaseFit {
        kc_n_m: (kc * fs / xs) as f32,
        kr_n_m: (kr * fs / xs) as f32,
        c_n_s_m: (c * fs / vs) as f32,
        permanent_m: (krxp / kr * xs) as f32,
        residual: libm::sqrt(rss / count.max(1) as f64) as f32,
    })
}

/// Nonlinear law at exponent `n`: `(k_s, q_s, rms)` in scaled units (`F = k_s X^n + q_s X^n V`).
fn nonlinear_at(t: &Trajectory<'_>, f_pk: f32, n: f64) -> Option<(f64, f64, f64)> {
    let (mut a11, mut a12, mut a22, mut b1, mut b2, mut ff) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let mut count = 0u32;
    t.for_each(f_pk, |p| {
        let xn = pow(p.x, n);
        let xnv = xn * p.v;
        a11 += xn * xn;
        a12 += xn * xnv;
        a22 += xnv * xnv;
        b1 += xn * p.f;
        b2 += xnv * p.f;
        ff += p.f * p.f;
        count += 1;
    });
    let det = a11 * a22 - a12 * a12;
    if !(det > 1e-300) {
        return None;
    }
    let k = (b1 * a22 - b2 * a12) / det;
    let q = (a11 * b2 - a12 * b1) / det;
    let rss = (ff - k * b1 - q * b2).max(0.0);
    Some((k, q, libm::sqrt(rss / count.max(1) as f64)))
}

fn nonlinear(t: &Trajectory<'_>, f_pk: f32, set: &crate::scene::FitSet) -> Option<NonlinearFit> {
    let n = if set.fit_exponent {
        let (n, _) = golden_max(
            |n: f64| nonlinear_at(t, f_pk, n).map_or(f64::MIN, |(_, _, r)| -r),
            1.0,
            2.5,
            // 1.5 * 0.618^16 ≈ 6e-4: far below what the data can tell.
            16,
        );
        n
    } else {
        set.nonlinear_exponent as f64
    };
    let (k, q, rms) = nonlinear_at(t, f_pk, n)?;
    if !(k > 0.0) {
        return None;
    }
    let (xs, vs, fs) = (t.x_m as f64, t.v0 as f64, f_pk as f64);
    Some(NonlinearFit {
        k: (k * fs / pow(xs, n)) as f32,
        c_s_m: (q / (k * vs)) as f32,
        n: n as f32,
        residual: rms as f32,
    })
}

fn hertz(t: &Trajectory<'_>, f_pk: f32) -> Option<HertzFit> {
    let (mut sfx, mut sxx, mut ff, mut count) = (0.0, 0.0, 0.0, 0u32);
    t.for_each(f_pk, |p| {
        let x15 = p.x * libm::sqrt(p.x);
        sfx += p.f * x15;
        sxx += x15 * x15;
        ff += p.f * p.f;
        count += 1;
    });
    let k = sfx / sxx;
    if !(k > 0.0 && k.is_finite()) {
        return None;
    }
    let rss = (ff - k * sfx).max(0.0);
    Some(HertzFit {
        k: (k * f_pk as f64 / pow(t.x_m as f64, 1.5)) as f32,
        residual: libm::sqrt(rss / count.max(1) as f64) as f32,
    })
}

/// Runs the fits the scene asks for.
pub fn fit(t: &Trajectory<'_>, set: &crate::scene::FitSet) -> Fits {
    let f_pk = t.peak_force();
    if !(f_pk > 0.0 && t.x_m > 0.0 && t.v0 > 0.0 && t.separation > t.onset + 4) {
        return Fits::default();
    }
    Fits {
        two_phase: if set.two_phase {
            two_phase(t, f_pk)
        } else {
            None
        },
        nonlinear: if set.nonlinear {
            nonlinear(t, f_pk, set)
        } else {
            None
        },
        hertz: if set.hertz { hertz(t, f_pk) } else { None },
    }
}
