//! Any contact law on a linear target by Dormand–Prince 5(4) with dense output: the contact's
//! deformation and its rate, the target's states and three energy integrals in one system,
//! events on the interpolant.
//!
//! The impactor is carried relative to the contact point (`δ = x1 - y`, `δ' = u1 - w`), not
//! by its own position and velocity: the law, the maximum and separation are functions of
//! `δ` and `δ'`, and on a light target that moves along with the impactor they are small
//! differences of large `x1 - y`, `u1 - w` (Kelvin–Voigt on a 1000× lighter sprung target:
//! `δ'` near the maximum is 1e-5 of `v0`). As states they keep their own precision and the
//! step control sees their error; `x1 = δ + y`, `u1 = δ' + w` are sums, formed where needed.

use super::{at_separation, reduced_mass, Target, TargetOutcome, MAX_STATES};
use crate::error::Error;
use crate::model::Impact;
use crate::model::{ContactLaw, Phase};
use crate::numeric::dopri::{self, Dense, E};
use crate::numeric::roots::{brent, golden_max};
use crate::real::Real;
use crate::solve::events::Compensated;

/// States: `δ, δ'`, the target's `z`, then `∫ F δ' dt`, `∫ F w dt`, `∫ c2 w² dt`.
const S: usize = MAX_STATES + 5;
type Vec<R> = [R; S];

#[inline]
fn c<R: Real>(x: f64) -> R {
    R::from_f64(x)
}

struct System<'a, R, L> {
    law: &'a L,
    target: &'a Target<R>,
    inv_m1: R,
    /// `1 / μ`, the reduced mass of impactor and contact point.
    inv_mu: R,
    /// The target's damper (spring–mass), for its dissipation integral.
    c2: R,
    n: usize,
}

impl<R: Real, L: ContactLaw<R>> System<'_, R, L> {
    fn outputs(&self, s: &Vec<R>) -> (R, R) {
        let mut y = R::ZERO;
        let mut w = R::ZERO;
        for i in 0..self.n {
            y += self.target.c[0][i] * s[2 + i];
            w += self.target.c[1][i] * s[2 + i];
        }
        (y, w)
    }
    /// The impactor's position and velocity, `x1 = δ + y`, `u1 = δ' + w`.
    fn impactor(&self, s: &Vec<R>) -> (R, R) {
        let (y, w) = self.outputs(s);
        (s[0] + y, s[1] + w)
    }
    /// Deformation, its rate and the smooth force.
    fn contact(&self, s: &Vec<R>, phase: Phase<R>) -> (R, R, R) {
        (s[0], s[1], self.law.raw_force(s[0], s[1], phase))
    }
    /// The contact's fastest rate at `s`, 1/s: the larger root `|λ|` of
    /// `μ λ² + c λ + k = 0`, the law linearised there (`k = |∂F/∂δ|`, `c = |∂F/∂δ'|`, by
    /// forward differences) on the reduced mass `μ`. NaN if the law is not finite nearby.
    fn contact_rate(&self, s: &Vec<R>, phase: Phase<R>, floor_x: R, floor_v: R) -> R {
        let (d, r) = (s[0], s[1]);
        let f = self.law.raw_force(d, r, phase);
        let root = R::EPSILON.sqrt();
        let ed = root * d.abs().max(floor_x);
        let er = root * r.abs().max(floor_v);
        let k = ((self.law.raw_force(d + ed, r, phase) - f) / ed).abs() * self.inv_mu;
        let c = ((self.law.raw_force(d, r + er, phase) - f) / er).abs() * self.inv_mu;
        let half = R::HALF * c;
        let disc = half * half - k;
        if disc > R::ZERO {
            // Overdamped: the fast real root.
            half + disc.sqrt()
        } else {
            // A damped oscillation: its modulus.
            k.sqrt()
        }
    }
    fn rhs(&self, s: &Vec<R>, phase: Phase<R>) -> Vec<R> {
        let n = self.n;
        let (_, w) = self.outputs(s);
        let r = s[1];
        let f = self.law.raw_force(s[0], r, phase);
        let mut out = [R::ZERO; S];
        out[0] = r;
        // δ'' = u1' - w' = -F / m1 - Cv z'.
        let mut w_dot = R::ZERO;
        for i in 0..n {
            let mut z = self.target.b[i] * f;
            for j in 0..n {
                z += self.target.a[i][j] * s[2 + j];
            }
            out[2 + i] = z;
            w_dot += self.target.c[1][i] * z;
        }
        out[1] = -f * self.inv_m1 - w_dot;
        out[2 + n] = f * r;
        out[3 + n] = f * w;
        out[4 + n] = self.c2 * w * w;
        out
    }
}

/// One point of a contact's trajectory, SI, impact direction positive.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sample<R> {
    pub t_s: R,
    pub impactor_m: R,
    pub impactor_m_s: R,
    pub target_m: R,
    pub target_m_s: R,
    /// The contact force (never negative), N.
    pub force_n: R,
}

/// Largest `h |λ|` for the contact's fastest mode `λ` ([`System::contact_rate`]).
///
/// On a light target the impactor may carry the target along on the contact (a stiff, heavily
/// damped spring on the reduced mass) for thousands of the contact's time scales; the step is
/// then held by stability, not accuracy. Left to the error control it sits at the edge of
/// Dormand–Prince's stability interval on the negative axis (`h |λ| ≈ 3.3`, where the
/// amplification `R(-3.3) ≈ +1`): the fast mode is no longer damped and keeps an error as
/// large as the tolerance allows, in `δ'`, whose root is the maximum deformation (Kelvin–Voigt
/// on a 1000× lighter target on a soft damped mount: crush time off by 7.8e-4 at rtol 1e-6).
/// At `h |λ| <= 2.8`, `|R| <= 0.4`: the fast mode dies out within a few steps (1e-12 there,
/// for ~15% more steps).
const STIFF_STEP: f64 = 2.8;

/// The events' rules, which differ from the wall solver's (`solve::events`) and are kept
/// as they are (changing them changes every two-body result in its last digits): the peak
/// force is refined by this many golden-section steps within a quarter step of the best of
/// five samples (`events`: 52 steps between the sampled neighbours);
const PEAK_ITERATIONS: u32 = 80;
/// the maximum deformation and separation are Brent roots to this many `EPSILON` of a step
/// (`events`: 0, to the last bit), and a root the interpolant's ends fail to bracket (by
/// rounding) falls back to the chord instead of failing; separation is always landed on by a
/// fresh step from the step's start (`events`: a bounded retake of the adaptive step).
const ROOT_TOLERANCE_EPS: f64 = 4.0;

/// Samples per accepted step handed to an observer.
const SAMPLES_PER_STEP: u32 = 8;

/// Where the chord from `(from, a)` to `(1, b)` crosses zero, within `[from, 1]`.
fn chord<R: Real>(a: R, b: R, from: R) -> R {
    let th = from + (R::ONE - from) * a / (a - b);
    if th.is_finite() {
        th.max(from).min(R::ONE)
    } else {
        R::ONE
    }
}

/// The coupled system under one phase, and how its error is measured: the deformation and
/// its rate, the impactor, the contact point and the energy integrals, each against
/// `rtol * max(|y|, floor)`, their RMS; the next step is held inside the stability interval
/// of the contact's fastest mode ([`STIFF_STEP`]).
struct Phased<'s, 'a, R, L> {
    sys: &'s System<'a, R, L>,
    phase: Phase<R>,
    rtol: R,
    floor_x: R,
    floor_v: R,
    floor_e: R,
}

impl<R: Real, L: ContactLaw<R>> dopri::System<R, S> for Phased<'_, '_, R, L> {
    fn dim(&self) -> usize {
        self.sys.n + 5
    }

    fn rhs(&self, y: &Vec<R>) -> Vec<R> {
        self.sys.rhs(y, self.phase)
    }

    fn error_norm(&self, h: R, ks: &[Vec<R>; 7], s: &Vec<R>, y1: &Vec<R>) -> R {
        let (sys, n, dim) = (self.sys, self.sys.n, self.dim());
        let mut err = [R::ZERO; S];
        for (e, k) in E.iter().zip(ks) {
            for i in 0..dim {
                err[i] += c::<R>(*e) * h * k[i];
            }
        }
        let (ey, ew) = sys.outputs(&err);
        let (y0o, w0o) = sys.outputs(s);
        let (y1o, w1o) = sys.outputs(y1);
        let (x0, u0) = sys.impactor(s);
        let (x1, u1) = sys.impactor(y1);
        let tol = |a: R, b: R, floor: R| self.rtol * a.abs().max(b.abs()).max(floor);
        let (fx, fv, fe) = (self.floor_x, self.floor_v, self.floor_e);
        let terms = [
            err[0] / tol(s[0], y1[0], fx),
            err[1] / tol(s[1], y1[1], fv),
            (err[0] + ey) / tol(x0, x1, fx),
            (err[1] + ew) / tol(u0, u1, fv),
            ey / tol(y0o, y1o, fx),
            ew / tol(w0o, w1o, fv),
            err[2 + n] / tol(s[2 + n], y1[2 + n], fe),
            err[3 + n] / tol(s[3 + n], y1[3 + n], fe),
            err[4 + n] / tol(s[4 + n], y1[4 + n], fe),
        ];
        let mut sq = R::ZERO;
        for x in terms {
            sq += x * x;
        }
        (sq / c(9.0)).sqrt()
    }

    fn max_step(&self, y1: &Vec<R>) -> Option<R> {
        let rate = self
            .sys
            .contact_rate(y1, self.phase, self.floor_x, self.floor_v);
        Some(c::<R>(STIFF_STEP) / rate)
    }
}

/// Solves the contact at relative tolerance `rtol` (at least `8 * EPSILON`).
pub(super) fn solve<R: Real, L: ContactLaw<R>>(
    law: &L,
    impact: &Impact<R>,
    target: &Target<R>,
    rtol: R,
) -> Result<TargetOutcome<R>, Error> {
    solve_observed(law, impact, target, rtol, &mut |_| {})
}

/// As [`solve`], handing `obs` eight points of every accepted step's interpolant, in time
/// order, from first touch to separation.
pub(super) fn solve_observed<R: Real, L: ContactLaw<R>>(
    law: &L,
    impact: &Impact<R>,
    target: &Target<R>,
    rtol: R,
    obs: &mut dyn FnMut(Sample<R>),
) -> Result<TargetOutcome<R>, Error> {
    let rtol = dopri::checked_rtol(rtol)?;
    let m1 = impact.mass_kg;
    let v0 = impact.v0_m_s;
    let n = target.n;
    let scale_t = law.time_scale(&Impact::new(reduced_mass(m1, target), v0));
    if !(scale_t.is_finite() && scale_t > R::ZERO) {
        return Err(Error::Unresolved(
            "time scale is not a positive finite number",
        ));
    }
    let sys = System {
        law,
        target,
        inv_m1: R::ONE / m1,
        inv_mu: R::ONE / reduced_mass(m1, target),
        c2: target
            .spring_mass
            .map(|s| s.damping_n_s_m)
            .unwrap_or(R::ZERO),
        n,
    };
    let floor_x = v0 * scale_t * c::<R>(1e-2);
    let floor_v = v0 * c::<R>(1e-2);
    let floor_e = R::HALF * m1 * v0 * v0 * c::<R>(1e-2);
    let (mut h, h_min) = dopri::initial_steps(scale_t, rtol);

    // At first touch: no deformation, closing at `v0`, the target at rest.
    let mut s: Vec<R> = [R::ZERO; S];
    s[1] = v0;
    let mut carry: Vec<R> = [R::ZERO; S];
    // Kahan-compensated: a stiff contact takes ~1e5 steps of one length, and in f32 each
    // `t + h` would round the same way.
    let mut t = Compensated::new(R::ZERO);
    let mut phase = Phase::Compression;
    let mut k1 = sys.rhs(&s, phase);
    let mut evals = 1u32;
    let mut first_max = false;
    let mut max = (R::ZERO, R::ZERO);
    let mut peak = sys.contact(&s, phase).2;
    let show = |obs: &mut dyn FnMut(Sample<R>), t: R, st: &Vec<R>, ph: Phase<R>| {
        let (y, w) = sys.outputs(st);
        let (x1, u1) = sys.impactor(st);
        obs(Sample {
            t_s: t,
            impactor_m: x1,
            impactor_m_s: u1,
            target_m: y,
            target_m_s: w,
            force_n: sys.contact(st, ph).2.max(R::ZERO),
        });
    };
    show(obs, R::ZERO, &s, phase);
    let show_step = |obs: &mut dyn FnMut(Sample<R>), seg: &Dense<R, S>, upto: R, ph: Phase<R>| {
        for k in 1..=SAMPLES_PER_STEP {
            let th = upto * R::from_u32(k) / R::from_u32(SAMPLES_PER_STEP);
            show(obs, seg.t0 + th * seg.h, &seg.at(th), ph);
        }
    };

    for _ in 0..1_000_000u32 {
        // One accepted step (Dormand–Prince, FSAL).
        let phased = Phased {
            sys: &sys,
            phase,
            rtol,
            floor_x,
            floor_v,
            floor_e,
        };
        let dopri::Accepted {
            dense: seg,
            y1,
            carry1,
            k_end,
        } = dopri::step(&phased, t.sum, &s, &carry, &k1, &mut h, h_min, &mut evals)?;
        let contact_at = |th: R, ph: Phase<R>| sys.contact(&seg.at(th), ph);
        let force = |th: R| contact_at(th, phase).2;
        let rate = |th: R| contact_at(th, phase).1;

        // Peak force: the largest of five samples, refined around it if it is inside.
        let mut best = (R::ZERO, force(R::ZERO));
        for k in 1..=4u32 {
            let th = R::from_u32(k) * c(0.25);
            let f = force(th);
            evals += 1;
            if f > best.1 {
                best = (th, f);
            }
        }
        // The force is unimodal near its peak: refine around the best sample (at an end of
        // the step too, where the peak may lie just inside).
        let lo = (best.0 - c(0.25)).max(R::ZERO);
        let hi = (best.0 + c(0.25)).min(R::ONE);
        let (_, f) = golden_max(force, lo, hi, PEAK_ITERATIONS);
        best.1 = best.1.max(f);
        peak = peak.max(best.1);

        // Maxima of the deformation: where its rate turns negative.
        let mut from = R::ZERO;
        if rate(R::ZERO) >= R::ZERO && rate(R::ONE) < R::ZERO {
            // Never skipped: if the interpolant's ends disagree with the test (rounding), the
            // chord.
            let th = brent(
                rate,
                R::ZERO,
                R::ONE,
                R::EPSILON * c(ROOT_TOLERANCE_EPS),
                &mut evals,
            )
            .unwrap_or_else(|| chord(rate(R::ZERO), rate(R::ONE), R::ZERO));
            {
                let sm = seg.at(th);
                let (d, _, _) = sys.contact(&sm, phase);
                if d > max.0 {
                    max = (d, seg.t0 + th * seg.h);
                }
                if !first_max {
                    first_max = true;
                    phase = Phase::Restitution { x_max: d };
                    if law.switches_at_max() {
                        // Restart under the restitution law exactly at the maximum.
                        show_step(obs, &seg, th, Phase::Compression);
                        s = sm;
                        carry = [R::ZERO; S];
                        t.add(th * seg.h);
                        k1 = sys.rhs(&s, phase);
                        evals += 1;
                        peak = peak.max(sys.contact(&s, phase).2);
                        continue;
                    }
                    from = th;
                }
            }
        }
        // Separation: the force returns to zero after the maximum.
        let force = |th: R| contact_at(th, phase).2;
        if first_max && force(R::ONE) <= R::ZERO {
            let th = brent(
                force,
                from,
                R::ONE,
                R::EPSILON * c(ROOT_TOLERANCE_EPS),
                &mut evals,
            )
            .unwrap_or_else(|| chord(force(from), force(R::ONE), from));
            // Land a step on the separation found on the interpolant: the state there has
            // the step's accuracy, not the interpolant's.
            // Under the phase now in force (restitution, once the maximum is passed).
            let phased = Phased { phase, ..phased };
            let (_, ss, _) = dopri::trial(&phased, &s, &carry, &k1, th * seg.h);
            evals += 6;
            show_step(obs, &seg, th, phase);
            let mut z = [R::ZERO; MAX_STATES];
            z[..n].copy_from_slice(&ss[2..2 + n]);
            let (x1, u1) = sys.impactor(&ss);
            let mut out = at_separation(
                impact,
                target,
                seg.t0 + th * seg.h,
                x1,
                u1,
                z,
                max,
                peak,
                evals,
            )?;
            // From the states themselves, not as differences of the sums just formed.
            out.permanent_deformation_m = ss[0].max(R::ZERO);
            out.cor = R::ZERO - ss[1] / v0;
            out.contact_work_j = Some(ss[2 + n]);
            out.target_work_j = Some(ss[3 + n]);
            out.target_dissipated_j = target.spring_mass.map(|_| ss[4 + n]);
            return Ok(out);
        }
        let (d1, r1, _) = sys.contact(&y1, phase);
        if !law.admissible(d1, r1) {
            return Err(Error::Unresolved(
                "the step left the law's admissible states",
            ));
        }
        show_step(obs, &seg, R::ONE, phase);
        s = y1;
        carry = carry1;
        k1 = k_end;
        t.add(seg.h);
    }
    Err(Error::Unresolved("contact did not end within 10^6 steps"))
}
