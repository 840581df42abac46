//! The three fits over the points of one impact.

use super::sums::Sums;
use super::{HertzFit, NonlinearFit, TwoPhaseFit};
use crate::real::Real;

/// `x^1.5` with the FPU's square root on the Cortex-M4 (`Real::sqrt`); 0 for a point a
/// hair below zero (where an elastic contact lets go: the sums' own rounding).
fn pow15(x: f32) -> f32 {
    // (A compare and select: `f32::max` is a libm call on the M4, which has no `VMAXNM`.)
    let x = if x > 0.0 { x } else { 0.0 };
    x * <f32 as Real>::sqrt(x)
}
use crate::numeric::roots::brent_min;

/// Bracket of the nonlinear exponent search.
const EXPONENT_RANGE: (f64, f64) = (1.0, 2.5);
/// Resolution of the exponent search (the pipeline tests recover n to 0.5 %). Brent's bracket
/// ends up to 4 times this wide, and the residual's own noise (its f32 block sums, 1.5e-6
/// relative, on a residual nearly flat in n) spreads the minimum over about ±1.5e-3 in n:
/// what limits n on a law the fit does not describe (the seed's two-phase impact), where a
/// rounding elsewhere moves it by that much.
const EXPONENT_TOL: f64 = 5e-4;
/// Most residual evaluations the exponent search may take (it needs about ten).
const EXPONENT_EVALS: u32 = 30;
/// Points the exponent search reads at most: of more, every `stride`-th, `stride` the
/// fewest that keeps them within this (the seed bench's 1 786 points: every 4th, 447). `k`
/// and `c` at the exponent found come from every point.
const SEARCH_POINTS: usize = 512;

/// The measured force–deformation loop at evenly spaced points of the contact, scaled:
/// `x[i] = x / x_m`, `v[i] = v / v0`, `f[i] = m a / f_peak`; the same length each.
pub struct Points<'a> {
    pub x: &'a [f32],
    pub v: &'a [f32],
    pub f: &'a [f32],
    /// Maximum deformation, m.
    pub x_m: f32,
    /// Approach speed, m/s.
    pub v0: f32,
    /// Peak force, N.
    pub f_peak: f32,
}

impl Points<'_> {
    fn len(&self) -> usize {
        self.x.len().min(self.v.len()).min(self.f.len())
    }

    /// `(x, v, f)` of each point.
    fn iter(&self) -> impl Iterator<Item = (f32, f32, f32)> + '_ {
        let n = self.len();
        self.x[..n]
            .iter()
            .zip(&self.v[..n])
            .zip(&self.f[..n])
            .map(|((&x, &v), &f)| (x, v, f))
    }

    /// Enough points and positive scales to fit anything.
    fn usable(&self) -> bool {
        self.len() > 4 && self.x_m > 0.0 && self.v0 > 0.0 && self.f_peak > 0.0
    }
}

/// Solves the N×N system `A θ = b` by Gaussian elimination with partial pivoting.
#[allow(clippy::needless_range_loop)]
pub(crate) fn solve<const N: usize>(mut a: [[f64; N]; N], mut b: [f64; N]) -> Option<[f64; N]> {
    for col in 0..N {
        let pivot =
            (col..N).max_by(|&i, &j| libm::fabs(a[i][col]).total_cmp(&libm::fabs(a[j][col])))?;
        // (`pivot < N` always; said, so that no bounds check is left to panic.)
        if pivot >= N || !(libm::fabs(a[pivot][col]) > 1e-300) {
            return None;
        }
        a.swap(col, pivot);
        b.swap(col, pivot);
        for row in col + 1..N {
            let f = a[row][col] / a[col][col];
            for k in col..N {
                a[row][k] -= f * a[col][k];
            }
            b[row] -= f * b[col];
        }
    }
    let mut x = [0.0; N];
    for row in (0..N).rev() {
        let mut s = b[row];
        for k in row + 1..N {
            s -= a[row][k] * x[k];
        }
        x[row] = s / a[row][row];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// RMS of the residuals `f - model(x, v)` over the points, relative to the peak force.
fn residual(p: &Points<'_>, mut model: impl FnMut(f32, f32) -> f32) -> f32 {
    let mut s = Sums::<1>::new();
    for (x, v, f) in p.iter() {
        let r = f - model(x, v);
        s.add([r * r]);
    }
    let [rss] = s.get();
    libm::sqrt(rss / p.len().max(1) as f64) as f32
}

/// Two-phase Kelvin–Voigt: compression (up to the first point moving back out) `F = kc x`;
/// restitution `F = kr (x - x_p) + c v`, fitted as `kr (X - 1) + b + c V` (columns centred
/// at the maximum deformation, where `X` and 1 would be nearly collinear); `line` is
/// [`restitution`]'s, fitted once for this fit and the [`set`].
// (Not inlined: each fit's frame stays out of the analysis task's.)
#[inline(never)]
pub fn two_phase(p: &Points<'_>, line: Option<Restitution>) -> Option<TwoPhaseFit> {
    if !p.usable() {
        return None;
    }
    let mut compression = Sums::<2>::new();
    let mut restoring = false;
    for (x, v, f) in p.iter() {
        restoring |= v <= 0.0;
        if !restoring {
            compression.add([f * x, x * x]);
        }
    }
    let [sfx, sxx] = compression.get();
    let kc = sfx / sxx;
    let Restitution { kr, b, c } = line?;
    if !(kc.is_finite() && kr > 0.0) {
        return None;
    }
    // F = kr X - (kr - b) + c V: kr x_p (scaled) = kr - b.
    let krxp = kr - b;
    let (kc32, kr32, krxp32, c32) = (kc as f32, kr as f32, krxp as f32, c as f32);
    let mut restoring = false;
    let rms = residual(p, |x, v| {
        restoring |= v <= 0.0;
        if restoring {
            kr32 * x - krxp32 + c32 * v
        } else {
            kc32 * x
        }
    });
    let (xs, vs, fs) = (p.x_m as f64, p.v0 as f64, p.f_peak as f64);
    Some(TwoPhaseFit {
        kc_n_m: (kc * fs / xs) as f32,
        kr_n_m: (kr * fs / xs) as f32,
        c_n_s_m: (c * fs / vs) as f32,
        permanent_m: (krxp / kr * xs) as f32,
        residual: rms,
    })
}

/// The points of the restitution: after the first one moving back out (that one may still
/// read the compression's force: the two-phase law jumps at the maximum, between points).
fn restoring<'a>(p: &'a Points<'a>) -> impl Iterator<Item = (f32, f32, f32)> + 'a {
    p.iter().skip_while(|&(_, v, _)| v > 0.0).skip(1)
}

/// The restitution line `F = kr (X - 1) + b + c V` (scaled units; `kr x_p = kr - b`), the
/// two-phase fit's second branch and the [`set`]'s line.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Restitution {
    kr: f64,
    b: f64,
    c: f64,
}

/// The restitution line fitted to the restitution's points ([`restoring`]), once for the
/// two-phase fit and the set.
pub fn restitution(p: &Points<'_>) -> Option<Restitution> {
    if !p.usable() {
        return None;
    }
    let mut restitution = Sums::<9>::new();
    for (x, v, f) in restoring(p) {
        let u = x - 1.0;
        restitution.add([u * u, u, u * v, 1.0, v, v * v, u * f, f, v * f]);
    }
    let [uu, u, uv, n, sv, vv, uf, sf, vf] = restitution.get();
    let [kr, b, c] = solve([[uu, u, uv], [u, n, sv], [uv, sv, vv]], [uf, sf, vf])?;
    Some(Restitution { kr, b, c })
}

/// Largest RMS residual of the restitution line, relative to the peak force, for its set to
/// be reported ([`set`]): an elastic and a viscous part that fit the unloading to 1 % (a
/// Kelvin–Voigt or two-phase unloading fits to the noise; `k x (1 + c v)` and Hertz's
/// `x^1.5` do not, and their line's zero is no set).
pub const SET_RESIDUAL: f32 = 0.01;

/// The set the pad keeps once it has recovered, m: where the unloading's elastic part
/// `kr (x - x_s)` is zero, from the restitution line `F = kr (x - x_s) + c v` fitted to the
/// unloading (0 for a Kelvin–Voigt pad, whose viscous part holds the separation at
/// `x_sep = -c v_r / k > 0`; `x_p` for the two-phase law). `None` where the line does not
/// hold the unloading to [`SET_RESIDUAL`] (a Hertz or `x^n` unloading: the record cannot
/// tell the set) or no line fits (`line`: [`restitution`]'s).
pub fn set(p: &Points<'_>, line: Option<Restitution>) -> Option<f32> {
    let Restitution { kr, b, c } = line?;
    if !(kr > 0.0) {
        return None;
    }
    let (kr32, b32, c32) = (kr as f32, b as f32, c as f32);
    let mut s = Sums::<2>::new();
    for (x, v, f) in restoring(p) {
        let r = f - (kr32 * (x - 1.0) + b32 + c32 * v);
        s.add([r * r, 1.0]);
    }
    let [rss, n] = s.get();
    let rms = libm::sqrt(rss / n.max(1.0)) as f32;
    let x_s = ((kr - b) / kr * p.x_m as f64) as f32;
    // A set lies between the surface and the deepest point (a hair below 0 for noise).
    let inside = (-0.01 * p.x_m..=p.x_m).contains(&x_s);
    (rms <= SET_RESIDUAL && inside).then_some(x_s)
}

/// `F = k X^n + q X^n V` at one exponent over every `stride`-th point: `(k, q)` in scaled
/// units from the normal equations, and their right-hand sides `[Σ X^n F, Σ X^n V F]` (the
/// residual is [`rss`]'s).
fn nonlinear_at(p: &Points<'_>, xn: Power<'_>, stride: usize) -> Option<(f64, f64, [f64; 2])> {
    let exp = |n: f32| {
        move |((_, v, f), &l): ((f32, f32, f32), &f32)| (crate::numeric::exp::exp(n * l), v, f)
    };
    // The exponent's case and the stride chosen once, not at every point: a loop each.
    let [a11, a12, a22, b1, b2] = match (xn, stride) {
        (Power::One, 0 | 1) => normal_sums(p.iter()),
        (Power::One, s) => normal_sums(p.iter().step_by(s)),
        (Power::ThreeHalves, 0 | 1) => normal_sums(p.iter().map(|(x, v, f)| (pow15(x), v, f))),
        (Power::ThreeHalves, s) => {
            normal_sums(p.iter().step_by(s).map(|(x, v, f)| (pow15(x), v, f)))
        }
        // (`ln` holds a logarithm for every point: `nonlinear` makes sure of it.)
        (Power::Exp(n, ln), 0 | 1) => normal_sums(p.iter().zip(ln).map(exp(n))),
        // (Each slice stepped on its own: a pointer's step each, where stepping the zipped
        // points ran every point's closure.)
        (Power::Exp(n, ln), s) => normal_sums(
            (p.v.get(..p.len()).unwrap_or(&[]).iter().step_by(s))
                .zip(p.f.iter().step_by(s))
                .zip(ln.iter().step_by(s))
                .map(|((&v, &f), &l)| (crate::numeric::exp::exp(n * l), v, f)),
        ),
        (Power::Given(xn), 0 | 1) => normal_sums(p.iter().zip(xn).map(|((_, v, f), &a)| (a, v, f))),
        (Power::Given(xn), s) => normal_sums(
            (p.iter().zip(xn))
                .step_by(s)
                .map(|((_, v, f), &a)| (a, v, f)),
        ),
    };
    let det = a11 * a22 - a12 * a12;
    if !(det > 1e-300) {
        return None;
    }
    let k = (b1 * a22 - b2 * a12) / det;
    let q = (a11 * b2 - a12 * b1) / det;
    Some((k, q, [b1, b2]))
}

/// The residual sum of squares of [`nonlinear_at`]'s solution: `Σ F² - k Σ X^n F - q Σ X^n
/// V F`, `ff` the points' `Σ F²` (the same at every exponent, summed once by
/// [`force_squares`]).
fn rss(ff: f64, (k, q, [b1, b2]): (f64, f64, [f64; 2])) -> f64 {
    (ff - k * b1 - q * b2).max(0.0)
}

/// The normal equations' sums `Σ A², Σ A² V, Σ A² V², Σ A F, Σ A V F` over `(A, V, F)`,
/// `A = X^n`.
#[inline(always)]
fn normal_sums(points: impl Iterator<Item = (f32, f32, f32)>) -> [f64; 5] {
    let mut s = Sums::<5>::new();
    for (a, v, f) in points {
        let av = a * v;
        s.add([a * a, a * av, av * av, a * f, av * f]);
    }
    s.get()
}

/// `Σ F²` over every `stride`-th point.
fn force_squares(p: &Points<'_>, stride: usize) -> f64 {
    let mut s = Sums::<1>::new();
    for (_, _, f) in p.iter().step_by(stride.max(1)) {
        s.add([f * f]);
    }
    s.get()[0]
}

/// `X^n` at one exponent: `X` itself at 1, [`pow15`] at 1.5, else `exp(n ln X)` from the
/// points' logarithms (`ln 0 = -inf` gives 0; an f32 polynomial's exp, not libm's: most of
/// the exponent search's cost, `crate::numeric::exp`), or each point's, computed once.
#[derive(Clone, Copy)]
enum Power<'a> {
    One,
    ThreeHalves,
    Exp(f32, &'a [f32]),
    Given(&'a [f32]),
}

impl<'a> Power<'a> {
    fn new(n: f32, ln: &'a [f32]) -> Self {
        if n == 1.0 {
            Power::One
        } else if n == 1.5 {
            Power::ThreeHalves
        } else {
            Power::Exp(n, ln)
        }
    }

    /// `X^n` of point `i` (whose deformation is `x`).
    fn at(self, i: usize, x: f32) -> f32 {
        match self {
            Power::One => x,
            Power::ThreeHalves => pow15(x),
            Power::Exp(n, ln) => ln.get(i).map_or(0.0, |&l| crate::numeric::exp::exp(n * l)),
            Power::Given(xn) => xn.get(i).copied().unwrap_or(0.0),
        }
    }
}

/// Nonlinear `F = k x^n (1 + c v)`, the exponent fixed at `n`, or searched in [1, 2.5] when
/// `n` is `None` over at most [`SEARCH_POINTS`] of the points (`ln_x`, at least as long as
/// the points, is scratch for `ln X`).
// (Not inlined: each fit's frame stays out of the analysis task's.)
#[inline(never)]
pub fn nonlinear(p: &Points<'_>, n: Option<f32>, ln_x: &mut [f32]) -> Option<NonlinearFit> {
    nonlinear_searching(p, n, ln_x, SEARCH_POINTS)
}

/// [`nonlinear`], the exponent searched over at most `search` points.
fn nonlinear_searching(
    p: &Points<'_>,
    n: Option<f32>,
    ln_x: &mut [f32],
    search: usize,
) -> Option<NonlinearFit> {
    if !p.usable() {
        return None;
    }
    // ln x once per point, for the exponents x^n is taken as exp(n ln x).
    let needs_ln = n.is_none_or(|n| n != 1.0 && n != 1.5);
    if needs_ln {
        if ln_x.len() < p.len() {
            return None;
        }
        for (l, &x) in ln_x.iter_mut().zip(p.x) {
            // (A point a hair below zero, where an elastic contact lets go: x^n = 0.)
            *l = libm::logf(if x > 0.0 { x } else { 0.0 });
        }
    }
    let len = ln_x.len().min(p.len());
    let ln = &ln_x[..len];
    let n = match n {
        Some(n) => n,
        None => {
            let stride = p.len().div_ceil(search.max(1)).max(1);
            let ff = force_squares(p, stride);
            let (n, _, _) = brent_min(
                |n| {
                    nonlinear_at(p, Power::new(n as f32, ln), stride)
                        .map_or(f64::INFINITY, |s| rss(ff, s))
                },
                EXPONENT_RANGE.0,
                EXPONENT_RANGE.1,
                EXPONENT_TOL,
                EXPONENT_EVALS,
            );
            n as f32
        }
    };
    // `X^n` for the final solve and its residual: `exp(n ln X)` once a point, over the
    // logarithms (the search is done with them), where each pass took its own.
    let xn = match Power::new(n, ln) {
        Power::Exp(..) => {
            let xn = ln_x.get_mut(..len).unwrap_or(&mut []);
            for l in xn.iter_mut() {
                *l = crate::numeric::exp::exp(n * *l);
            }
            Power::Given(xn)
        }
        other => other,
    };
    let (k, q, _) = nonlinear_at(p, xn, 1)?;
    if !(k > 0.0) {
        return None;
    }
    let (k32, q32) = (k as f32, q as f32);
    let mut i = 0;
    let rms = residual(p, |x, v| {
        let a = xn.at(i, x);
        i += 1;
        a * (k32 + q32 * v)
    });
    let (xs, vs, fs) = (p.x_m as f64, p.v0 as f64, p.f_peak as f64);
    Some(NonlinearFit {
        k: (k * fs / libm::pow(xs, n as f64)) as f32,
        c_s_m: (q / (k * vs)) as f32,
        n,
        residual: rms,
    })
}

/// Hertz `F = K x^1.5`.
// (Not inlined: each fit's frame stays out of the analysis task's.)
#[inline(never)]
pub fn hertz(p: &Points<'_>) -> Option<HertzFit> {
    if !p.usable() {
        return None;
    }
    let mut s = Sums::<2>::new();
    for (x, _, f) in p.iter() {
        let x15 = pow15(x);
        s.add([f * x15, x15 * x15]);
    }
    let [sfx, sxx] = s.get();
    let k = sfx / sxx;
    if !(k > 0.0 && k.is_finite()) {
        return None;
    }
    let k32 = k as f32;
    let rms = residual(p, |x, _| k32 * pow15(x));
    Some(HertzFit {
        k: (k * p.f_peak as f64 / libm::pow(p.x_m as f64, 1.5)) as f32,
        residual: rms,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The exponent searched over every 4th of 2 000 points of a loop whose force has
    /// independent noise (±0.5 % of the peak at each point) is the one the search over all of
    /// them finds, within 5e-3 (measured: up to 2.7e-3), and its residual over every point
    /// within 1 % (measured: up to 0.54 %); the generating law within 1 %. (On `impact
    /// synth` records, whose noise is in the acceleration, the two exponents differ by up to
    /// 1.1e-3, where three noise seeds spread a fitted 1.5 over 1.476 to 1.505.)
    #[test]
    fn the_exponent_from_a_fraction_of_the_points_is_the_alls() {
        let len = 2000;
        for (n, seed) in [(1.0f32, 1u64), (1.3, 2), (1.5, 3), (2.2, 4)] {
            let mut noise = crate::testing::uniform(seed);
            // A loop: x up to 1 and back to 0 by another path, v from 1 to -0.6; F = x^n (1 + 0.5 v).
            let (mut x, mut v, mut f) = ([0.0f32; 2000], [0.0f32; 2000], [0.0f32; 2000]);
            for i in 0..len {
                let t = i as f32 / len as f32 * core::f32::consts::PI;
                x[i] = libm::sinf(t)
                    * if t > core::f32::consts::FRAC_PI_2 {
                        0.8 + 0.2 * libm::sinf(t)
                    } else {
                        1.0
                    };
                v[i] = libm::cosf(t)
                    * if t > core::f32::consts::FRAC_PI_2 {
                        0.6
                    } else {
                        1.0
                    };
                f[i] = libm::powf(x[i], n) * (1.0 + 0.5 * v[i]) + 0.01 * noise();
            }
            let p = Points {
                x: &x,
                v: &v,
                f: &f,
                x_m: 1.0,
                v0: 1.0,
                f_peak: 1.0,
            };
            let mut ln = [0.0f32; 2000];
            let all = nonlinear_searching(&p, None, &mut ln, len).unwrap();
            let part = nonlinear_searching(&p, None, &mut ln, 500).unwrap();
            assert!(
                (part.n - all.n).abs() < 5e-3,
                "{n}: {} vs {}",
                part.n,
                all.n
            );
            assert!(
                (part.residual / all.residual - 1.0).abs() < 1e-2,
                "{n}: {part:?} {all:?}"
            );
            assert!((all.n / n - 1.0).abs() < 0.01, "{n}: {}", all.n);
            assert_eq!(
                nonlinear(&p, None, &mut ln).map(|f| f.n.to_bits()),
                Some(part.n.to_bits())
            );
        }
    }
}
