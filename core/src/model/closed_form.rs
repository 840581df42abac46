//! Exact and semi-analytic outcomes: closed forms for linear phases, the energy relation plus
//! tanh-sinh quadrature for power-law and nonlinear forces (see `docs/oracles.md`).
//!
//! Every formula here is written so that it stays accurate at the ends of its range: damping
//! ratios near critical, vanishing or huge damping, and the inverse-power endpoint of the
//! time integrals.

use super::{Impact, ImpactOutcome, Nonlinear, TwoPhase};
use crate::error::Error;
use crate::numeric::quad::tanh_sinh;
use crate::numeric::roots::brent;
use crate::real::{pow, Real};

fn finite<R: Real>(o: ImpactOutcome<R>) -> Result<ImpactOutcome<R>, Error> {
    let fields = [
        o.max_deformation_m,
        o.crush_time_s,
        o.contact_time_s,
        o.rebound_velocity_m_s,
        o.cor,
        o.peak_force_n,
        o.permanent_deformation_m,
    ];
    if !fields.iter().all(|f| f.is_finite()) {
        return Err(Error::Unresolved(
            "result not finite: parameters outside the range of the number type",
        ));
    }
    // A contact always takes time, deforms and pushes: zeros here are underflow (v0² below
    // the smallest number), not an answer.
    if !(o.max_deformation_m > R::ZERO
        && o.crush_time_s > R::ZERO
        && o.contact_time_s > R::ZERO
        && o.peak_force_n > R::ZERO)
    {
        return Err(Error::Unresolved(
            "result underflowed: parameters outside the range of the number type",
        ));
    }
    Ok(o)
}

/// `I(n) = ∫0^1 du / sqrt(1 - u^(n+1)) = sqrt(pi) Γ(1 + 1/(n+1)) / Γ(1/2 + 1/(n+1))`:
/// the undamped power-law crush time is `t_m = I(n) x_m / v0` (`I(3/2) = 1.4716375921…`).
pub fn contact_integral<R: Real>(n: R) -> R {
    let a = R::ONE / (n + R::ONE);
    R::PI.sqrt() * (R::ONE + a).tgamma() / (R::HALF + a).tgamma()
}

/// Maximum deformation of the undamped law `F = k x^n`, m: `x_m^(n+1) = (n+1) m v0^2 / (2 k)`.
pub fn undamped_power_law_max<R: Real>(k: R, n: R, impact: &Impact<R>) -> R {
    let v0 = impact.v0_m_s;
    let n1 = n + R::ONE;
    (n1 * impact.mass_kg * v0 * v0 / (R::TWO * k)).powf(R::ONE / n1)
}

/// Contact time of the undamped law `F = k x^n`, s.
pub fn undamped_power_law_contact_time<R: Real>(k: R, n: R, impact: &Impact<R>) -> R {
    R::TWO * contact_integral(n) * undamped_power_law_max(k, n, impact) / impact.v0_m_s
}

/// Elastic power law `F = k x^n` (Hertz: `n = 3/2`; linear spring: `n = 1`).
pub fn elastic_power_law<R: Real>(
    k: R,
    n: R,
    impact: &Impact<R>,
) -> Result<ImpactOutcome<R>, Error> {
    let v0 = impact.v0_m_s;
    let x_m = undamped_power_law_max(k, n, impact);
    let t_m = contact_integral(n) * x_m / v0;
    finite(ImpactOutcome {
        max_deformation_m: x_m,
        crush_time_s: t_m,
        contact_time_s: R::TWO * t_m,
        rebound_velocity_m_s: v0,
        cor: R::ONE,
        peak_force_n: k * pow(x_m, n),
        permanent_deformation_m: R::ZERO,
        rhs_evaluations: 0,
    })
}

/// Linear spring `F = k x`: `x_m = v0/w`, `t_c = pi/w`, `F_peak = v0 sqrt(k m)`.
pub fn linear_spring<R: Real>(k: R, impact: &Impact<R>) -> Result<ImpactOutcome<R>, Error> {
    let m = impact.mass_kg;
    let v0 = impact.v0_m_s;
    let w = (k / m).sqrt();
    finite(ImpactOutcome {
        max_deformation_m: v0 / w,
        crush_time_s: R::HALF * R::PI / w,
        contact_time_s: R::PI / w,
        rebound_velocity_m_s: v0,
        cor: R::ONE,
        peak_force_n: v0 * (k * m).sqrt(),
        permanent_deformation_m: R::ZERO,
        rhs_evaluations: 0,
    })
}

/// `g(zeta) = acos(zeta) / sqrt(1 - zeta^2)` for `zeta < 1`, `acosh(zeta) / sqrt(zeta^2 - 1)`
/// above, `1` at critical damping: `g / w` is the time from rest (or from zero force) of a
/// damped oscillator to its next force zero. Written through `asin(s)/s` and `asinh(s)/s`,
/// so it is accurate through `zeta = 1`.
pub fn damped_quarter<R: Real>(zeta: R) -> R {
    let one = R::ONE;
    let s = (R::HALF * (one - zeta).abs()).sqrt();
    let ratio = if s == R::ZERO {
        one
    } else if zeta < one {
        s.asin() / s
    } else {
        s.asinh() / s
    };
    R::TWO * ratio / (R::TWO * (one + zeta)).sqrt()
}

/// Linear Kelvin–Voigt `F = k x + c v`, separation where the force returns to zero (so a
/// deformation `x(t_c) > 0` is left). Under-, critically and over-damped alike:
/// `t_m = g/w`, `t_c = 2 t_m`, `x_m = v0/w e^(-zeta g)`, `COR = e^(-2 zeta g)`,
/// `x(t_c) = 2 zeta x_m COR / e^(-zeta g)`.
pub fn kelvin_voigt<R: Real>(k: R, c: R, impact: &Impact<R>) -> Result<ImpactOutcome<R>, Error> {
    let m = impact.mass_kg;
    let v0 = impact.v0_m_s;
    let w = (k / m).sqrt();
    let zeta = c / (R::TWO * (k * m).sqrt());
    let g = damped_quarter(zeta);
    let decay = (-zeta * g).exp(); // e^(-zeta w t_m)
    let cor = decay * decay;
    // Peak force: at t = 0 (c v0) for zeta >= 1/2, else at wd t* = 3 acos(zeta) - pi.
    let peak = if zeta < R::HALF {
        let root = (R::ONE - zeta * zeta).sqrt();
        let theta = zeta.acos();
        m * v0 * w * (-zeta * (R::from_f64(3.0) * theta - R::PI) / root).exp()
    } else {
        c * v0
    };
    finite(ImpactOutcome {
        max_deformation_m: v0 / w * decay,
        crush_time_s: g / w,
        contact_time_s: R::TWO * g / w,
        rebound_velocity_m_s: v0 * cor,
        cor,
        peak_force_n: peak,
        permanent_deformation_m: R::TWO * zeta * v0 / w * cor,
        rhs_evaluations: 0,
    })
}

/// Two-phase Kelvin–Voigt (seed 001, Eq. 5): undamped compression with `kc`, then
/// `m y'' + c y' + kr y = 0` for `y = x - x_p`, from rest at `y0 = x_m - x_p`, until the force
/// `kr y + c y'` returns to zero after `t_r = g/w_r`, with `v' = y0 w_r e^(-zeta g)` and
/// `x(t_c) = x_p + 2 zeta y0 e^(-zeta g)`. If `x_p >= x_m` the body stops dead at `x_m`.
pub fn two_phase<R: Real>(
    law: &TwoPhase<R>,
    impact: &Impact<R>,
) -> Result<ImpactOutcome<R>, Error> {
    let m = impact.mass_kg;
    let v0 = impact.v0_m_s;
    let wc = (law.kc / m).sqrt();
    let x_m = v0 / wc;
    let t_m = R::HALF * R::PI / wc;
    let compression_peak = v0 * (m * law.kc).sqrt();
    let x_p = law.permanent_set(x_m);
    let y0 = x_m - x_p;
    if !(y0 > R::ZERO) {
        return finite(ImpactOutcome {
            max_deformation_m: x_m,
            crush_time_s: t_m,
            contact_time_s: t_m,
            rebound_velocity_m_s: R::ZERO,
            cor: R::ZERO,
            peak_force_n: compression_peak,
            permanent_deformation_m: x_m,
            rhs_evaluations: 0,
        });
    }
    let wr = (law.kr / m).sqrt();
    let zeta = law.c / (R::TWO * (law.kr * m).sqrt());
    let g = damped_quarter(zeta);
    let decay = (-zeta * g).exp();
    let rebound = y0 * wr * decay;
    finite(ImpactOutcome {
        max_deformation_m: x_m,
        crush_time_s: t_m,
        contact_time_s: t_m + g / wr,
        rebound_velocity_m_s: rebound,
        cor: rebound / v0,
        peak_force_n: compression_peak.max(law.kr * y0),
        permanent_deformation_m: x_p + R::TWO * zeta * y0 * decay,
        rhs_evaluations: 0,
    })
}

/// `psi(r) = 2 (-ln(1 - r) - r) / r^2 = sum_i 2 r^i / (i + 2)`, for `r < 1`.
fn psi<R: Real>(r: R) -> R {
    if r.abs() < R::from_f64(0.1) {
        let mut acc = R::ZERO;
        let mut i = 15u32;
        loop {
            acc = acc * r + R::TWO / R::from_u32(i + 2);
            if i == 0 {
                break;
            }
            i -= 1;
        }
        acc
    } else {
        R::TWO * (-(-r).ln_1p() - r) / (r * r)
    }
}

/// One phase of the nonlinear contact in the velocity variable, measured from the phase's
/// end where `x = 0`: `e` is the speed change from that end (`e = v0 - v` in compression,
/// `e = v + v'` in restitution). The energy relation there reads
/// `k x^(n+1) / (n+1) = m e S(e)` with `S` smooth and positive (no cancellation at `e -> 0`).
#[derive(Clone, Copy)]
struct Branch<R> {
    /// Speed at the `x = 0` end, m/s (`v0` or `v'`).
    speed: R,
    /// `1 + c v` at that end (`1 + c v0` or `1 - c v'`).
    w: R,
    /// `+1` in compression (v decreases from the end), `-1` in restitution.
    sigma: R,
}

impl<R: Real> Branch<R> {
    #[inline]
    fn s(&self, c: R, e: R) -> R {
        let r = self.sigma * c * e / self.w;
        (self.speed - e * psi(r) / (R::TWO * self.w)) / self.w
    }
}

/// Nonlinear `F = k x^n (1 + c v)`: COR from the exit condition (it depends on `p = c v0`
/// alone), `x_m` and the peak force from the energy relation, `t_m` and `t_c` by tanh-sinh
/// quadrature after the substitution `e = E t^(n+1)` that removes the inverse-power endpoint.
pub fn nonlinear<R: Real>(
    law: &Nonlinear<R>,
    impact: &Impact<R>,
) -> Result<ImpactOutcome<R>, Error> {
    let (k, c, n) = (law.k, law.c, law.n);
    if c == R::ZERO {
        return elastic_power_law(k, n, impact);
    }
    let m = impact.mass_kg;
    let v0 = impact.v0_m_s;
    let n1 = n + R::ONE;
    let a = n1 * m / k; // x^(n+1) = a e S(e)
    let p = c * v0;
    let w0 = R::ONE + p;
    let qtol = R::from_f64(64.0) * R::EPSILON;
    let accept = R::EPSILON.sqrt() * R::from_f64(0.01);
    let mut evals = 0u32;
    let unresolved =
        Error::Unresolved("nonlinear exit state not found (damping c v0 out of range)");

    let comp = Branch {
        speed: v0,
        w: w0,
        sigma: R::ONE,
    };
    // Maximum deformation: e = v0.
    let x_m = (a * v0 * comp.s(c, v0)).powf(R::ONE / n1);

    // A phase duration: ∫ m de / (k x^n (1 + c v)) with e = E t^(n+1).
    let phase_time = |b: Branch<R>, evals: &mut u32| -> Result<R, Error> {
        let e_end = b.speed;
        let q = tanh_sinh(
            |t: R| {
                let tn = pow(t, n);
                let e = e_end * tn * t;
                let s = b.s(c, e);
                let one_cv = b.w - b.sigma * c * e;
                n1 * e_end * m / (k * pow(a * e_end * s, n / n1) * one_cv)
            },
            qtol,
        )
        .ok_or(Error::Unresolved("quadrature met a non-finite integrand"))?;
        *evals += q.evaluations;
        if q.error > accept * q.value.abs() {
            return Err(Error::Unresolved("quadrature did not converge"));
        }
        Ok(q.value)
    };
    let t_m = phase_time(comp, &mut evals)?;

    // Exit speed and restitution time.
    let (rebound, t_r) = if p < R::ONE {
        // d = v0 + v' solves d psi(c d / w0) = 2 w0 v0 on [v0, 2 v0].
        let d = brent(
            |d: R| d * psi(c * d / w0) - R::TWO * w0 * v0,
            v0,
            R::TWO * v0,
            R::ZERO,
            &mut evals,
        )
        .ok_or(unresolved)?;
        let rebound = d - v0;
        let rest = Branch {
            speed: rebound,
            w: R::ONE - c * rebound,
            sigma: -R::ONE,
        };
        (rebound, phase_time(rest, &mut evals)?)
    } else {
        // u = ln(1 - c v') solves u - e^u = ln(w0) - w0 on [L, L + 1] (Lambert W, log form).
        let l = w0.ln() - w0;
        let u =
            brent(|u: R| u - u.exp() - l, l, l + R::ONE, R::ZERO, &mut evals).ok_or(unresolved)?;
        let w_e = u.exp();
        let rebound = (R::ONE - w_e) / c;
        // Restitution in s = ln(1 + c v), delta = s - u from 0 (exit) to -u (x_m):
        // k x^(n+1)/(n+1) = m/c^2 (delta - w_e expm1(delta)), dt = m ds / (c k x^n).
        let span = -u;
        let q = tanh_sinh(
            |t: R| {
                let tn = pow(t, n);
                let delta = span * tn * t;
                // w_e (e^delta - 1) / delta, without overflow when w_e underflows.
                let rise = if delta == R::ZERO {
                    w_e
                } else if delta < R::ONE {
                    w_e * delta.exp_m1() / delta
                } else {
                    ((u + delta).exp() - w_e) / delta
                };
                let qd = R::ONE - rise;
                n1 * span * m / (c * k * pow(a * span * qd / (c * c), n / n1))
            },
            qtol,
        )
        .ok_or(Error::Unresolved("quadrature met a non-finite integrand"))?;
        evals += q.evaluations;
        if q.error > accept * q.value.abs() {
            return Err(Error::Unresolved("quadrature did not converge"));
        }
        (rebound, q.value)
    };

    // Peak force in compression where (n+1) c e S(e) = n (v0 - e).
    let e_pk = brent(
        |e: R| n1 * c * e * comp.s(c, e) - n * (v0 - e),
        R::ZERO,
        v0,
        R::ZERO,
        &mut evals,
    )
    .ok_or(unresolved)?;
    let x_pk = (a * e_pk * comp.s(c, e_pk)).powf(R::ONE / n1);
    let peak = k * pow(x_pk, n) * (R::ONE + c * (v0 - e_pk));

    finite(ImpactOutcome {
        max_deformation_m: x_m,
        crush_time_s: t_m,
        contact_time_s: t_m + t_r,
        rebound_velocity_m_s: rebound,
        cor: rebound / v0,
        peak_force_n: peak,
        permanent_deformation_m: R::ZERO,
        rhs_evaluations: evals,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn contact_integral_matches_the_oracle() {
        let i = contact_integral(1.5f64);
        // libm's tgamma is good to a few ulps.
        assert!((i - 1.471_637_592_162_352_3).abs() < 2e-15, "{i}");
        let half_pi = contact_integral(1.0f64);
        assert!(
            (half_pi - core::f64::consts::FRAC_PI_2).abs() < 4e-15,
            "{half_pi}"
        );
    }

    #[test]
    fn damped_quarter_is_continuous_through_critical() {
        let below = damped_quarter(1.0f64 - 1e-9);
        let at = damped_quarter(1.0f64);
        let above = damped_quarter(1.0f64 + 1e-9);
        assert_eq!(at, 1.0);
        assert!((below - 1.0 - 1e-9 / 3.0).abs() < 1e-15, "{below}");
        assert!((above - 1.0 + 1e-9 / 3.0).abs() < 1e-15, "{above}");
        assert!((damped_quarter(0.0f64) - core::f64::consts::FRAC_PI_2).abs() < 1e-15);
    }

    #[test]
    fn psi_series_and_closed_form_agree_at_the_switch() {
        let r = 0.1f64;
        let closed = 2.0 * (-(-r).ln_1p() - r) / (r * r);
        let below = psi(r - 1e-12);
        assert!((closed - below).abs() < 1e-12, "{closed} {below}");
    }
}
