//! Bracketed scalar root finding (Brent's method): never leaves its bracket, never panics.

use crate::real::Real;

/// A root of `f` in `[a, b]`, where `f(a)` and `f(b)` differ in sign (or one is zero).
///
/// Returns `None` if the bracket is invalid or a value is not finite. Converges to
/// `tol` absolute in the root plus a few ulps; `evals` counts calls of `f`.
pub fn brent<R: Real>(mut f: impl FnMut(R) -> R, a: R, b: R, tol: R, evals: &mut u32) -> Option<R> {
    let (mut a, mut b) = (a, b);
    let mut fa = f(a);
    let mut fb = f(b);
    *evals += 2;
    if !(fa.is_finite() && fb.is_finite()) {
        return None;
    }
    if fa == R::ZERO {
        return Some(a);
    }
    if fb == R::ZERO {
        return Some(b);
    }
    if (fa > R::ZERO) == (fb > R::ZERO) {
        return None;
    }
    let mut c = a;
    let mut fc = fa;
    let mut d = b - a;
    let mut e = d;
    for _ in 0..200 {
        if (fb > R::ZERO) == (fc > R::ZERO) {
            c = a;
            fc = fa;
            d = b - a;
            e = d;
        }
        if fc.abs() < fb.abs() {
            a = b;
            b = c;
            c = a;
            fa = fb;
            fb = fc;
            fc = fa;
        }
        let tol1 = R::TWO * R::EPSILON * b.abs() + R::HALF * tol;
        let xm = R::HALF * (c - b);
        if xm.abs() <= tol1 || fb == R::ZERO {
            return Some(b);
        }
        if e.abs() >= tol1 && fa.abs() > fb.abs() {
            // Inverse quadratic interpolation or secant.
            let s = fb / fa;
            let (mut p, mut q);
            if a == c {
                p = R::TWO * xm * s;
                q = R::ONE - s;
            } else {
                let qq = fa / fc;
                let r = fb / fc;
                p = s * (R::TWO * xm * qq * (qq - r) - (b - a) * (r - R::ONE));
                q = (qq - R::ONE) * (r - R::ONE) * (s - R::ONE);
            }
            if p > R::ZERO {
                q = -q;
            }
            p = p.abs();
            let min1 = R::from_f64(3.0) * xm * q - (tol1 * q).abs();
            let min2 = (e * q).abs();
            if R::TWO * p < min1.min(min2) {
                e = d;
                d = p / q;
            } else {
                d = xm;
                e = d;
            }
        } else {
            d = xm;
            e = d;
        }
        a = b;
        fa = fb;
        if d.abs() > tol1 {
            b += d;
        } else if xm > R::ZERO {
            b += tol1;
        } else {
            b -= tol1;
        }
        fb = f(b);
        *evals += 1;
        if !fb.is_finite() {
            return None;
        }
    }
    Some(b)
}

/// The maximum of a unimodal `f` on `[a, b]` by golden-section search: `(t, f(t))`.
pub fn golden_max<R: Real>(mut f: impl FnMut(R) -> R, a: R, b: R, iterations: u32) -> (R, R) {
    let g = R::from_f64(0.618_033_988_749_894_8);
    let (mut a, mut b) = (a, b);
    let mut x1 = b - g * (b - a);
    let mut x2 = a + g * (b - a);
    let mut f1 = f(x1);
    let mut f2 = f(x2);
    for _ in 0..iterations {
        if f1 < f2 {
            a = x1;
            x1 = x2;
            f1 = f2;
            x2 = a + g * (b - a);
            f2 = f(x2);
        } else {
            b = x2;
            x2 = x1;
            f2 = f1;
            x1 = b - g * (b - a);
            f1 = f(x1);
        }
        if !(b - a > R::EPSILON * (a.abs() + b.abs())) {
            break;
        }
    }
    if f1 >= f2 {
        (x1, f1)
    } else {
        (x2, f2)
    }
}

/// The minimum of `f` on `[a, b]` by Brent's method (parabolic steps through the three best
/// points, golden-section steps when they misbehave), to within `tol` of its abscissa:
/// `(t, f(t))` and the number of evaluations. Unimodal `f` converge superlinearly, typically in
/// a handful of evaluations where golden section alone needs one per 0.618 of the bracket.
/// At most `max_evals` evaluations; a NaN value counts as +∞.
pub fn brent_min(
    mut f: impl FnMut(f64) -> f64,
    a: f64,
    b: f64,
    tol: f64,
    max_evals: u32,
) -> (f64, f64, u32) {
    const CGOLD: f64 = 0.381_966_011_250_105_1;
    let mut eval = |x: f64| {
        let y = f(x);
        if y.is_nan() {
            f64::INFINITY
        } else {
            y
        }
    };
    let (mut a, mut b) = (a.min(b), a.max(b));
    let mut x = a + CGOLD * (b - a);
    let (mut w, mut v) = (x, x);
    let mut fx = eval(x);
    let (mut fw, mut fv) = (fx, fx);
    let mut evals = 1u32;
    let (mut d, mut e) = (0.0f64, 0.0f64);
    while evals < max_evals {
        let m = 0.5 * (a + b);
        let tol1 = tol + 1e-10 * libm::fabs(x);
        let tol2 = 2.0 * tol1;
        if libm::fabs(x - m) <= tol2 - 0.5 * (b - a) {
            break;
        }
        let mut golden = true;
        if libm::fabs(e) > tol1 {
            // Parabola through x, w, v.
            let r = (x - w) * (fx - fv);
            let mut q = (x - v) * (fx - fw);
            let mut p = (x - v) * q - (x - w) * r;
            q = 2.0 * (q - r);
            if q > 0.0 {
                p = -p;
            }
            q = libm::fabs(q);
            let e_prev = e;
            e = d;
            if libm::fabs(p) < libm::fabs(0.5 * q * e_prev) && p > q * (a - x) && p < q * (b - x) {
                d = p / q;
                let u = x + d;
                if u - a < tol2 || b - u < tol2 {
                    d = if x < m { tol1 } else { -tol1 };
                }
                golden = false;
            }
        }
        if golden {
            e = if x < m { b - x } else { a - x };
            d = CGOLD * e;
        }
        let u = if libm::fabs(d) >= tol1 {
            x + d
        } else if d > 0.0 {
            x + tol1
        } else {
            x - tol1
        };
        let fu = eval(u);
        evals += 1;
        if fu <= fx {
            if u < x {
                b = x;
            } else {
                a = x;
            }
            (v, fv, w, fw, x, fx) = (w, fw, x, fx, u, fu);
        } else {
            if u < x {
                a = u;
            } else {
                b = u;
            }
            if fu <= fw || w == x {
                (v, fv, w, fw) = (w, fw, u, fu);
            } else if fu <= fv || v == x || v == w {
                (v, fv) = (u, fu);
            }
        }
    }
    (x, fx, evals)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn brent_finds_cube_root_of_two() {
        let mut n = 0;
        let r = brent(|x: f64| x * x * x - 2.0, 0.0, 2.0, 0.0, &mut n).unwrap();
        assert!((r - 2f64.cbrt()).abs() < 4.0 * f64::EPSILON);
        assert!(n < 30, "{n} evaluations");
    }

    #[test]
    fn brent_rejects_a_bad_bracket_and_nan() {
        let mut n = 0;
        assert!(brent(|x: f64| x * x + 1.0, -1.0, 1.0, 0.0, &mut n).is_none());
        assert!(brent(|_x: f64| f64::NAN, -1.0, 1.0, 0.0, &mut n).is_none());
    }

    #[test]
    fn brent_min_finds_a_smooth_minimum_in_few_evaluations() {
        // A residual-like curve with its minimum at 1.37 on [1, 2.5].
        let f = |n: f64| 0.01 + (n - 1.37) * (n - 1.37) * (1.0 + 0.5 * (n - 1.37));
        let (t, v, evals) = brent_min(f, 1.0, 2.5, 1e-4, 40);
        assert!((t - 1.37).abs() < 3e-4, "{t}");
        assert!((v - 0.01).abs() < 1e-7);
        assert!(evals <= 12, "{evals} evaluations");
        // At an end of the bracket, and through NaN.
        let (t, _, _) = brent_min(|n: f64| n, 1.0, 2.5, 1e-4, 60);
        assert!(t - 1.0 < 1e-3, "{t}");
        let (t, _, _) = brent_min(
            |n: f64| if n > 2.0 { f64::NAN } else { -n },
            1.0,
            2.5,
            1e-4,
            60,
        );
        assert!((t - 2.0).abs() < 1e-3, "{t}");
    }

    #[test]
    fn golden_finds_the_top_of_a_parabola() {
        let (t, v) = golden_max(|x: f64| 3.0 - (x - 0.3) * (x - 0.3), 0.0, 1.0, 100);
        assert!((t - 0.3).abs() < 1e-7);
        assert_eq!(v, 3.0 - (t - 0.3) * (t - 0.3));
    }
}
