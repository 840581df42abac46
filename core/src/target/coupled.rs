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
use crate::numeric::roots::{brent, golden_max};
use crate::real::Real;
use crate::solve::adaptive::{A2, A3, A4, A5, A6, B, D, E};
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

/// One accepted step: `rcont1..5` of Hairer's `CONTD5` for every state.
#[derive(Clone, Copy)]
struct Dense<R> {
    t0: R,
    h: R,
    r: [Vec<R>; 5],
}

impl<R: Real> Dense<R> {
    fn at(&self, th: R) -> Vec<R> {
        let th1 = R::ONE - th;
        let r = &self.r;
        let mut out = [R::ZERO; S];
        for (i, o) in out.iter_mut().enumerate() {
            *o = r[0][i] + th * (r[1][i] + th1 * (r[2][i] + th * (r[3][i] + th1 * r[4][i])));
        }
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

/// One Dormand–Prince step of length `h` from `s` (Kahan carry `carry`, derivative `k1`):
/// the seven stages, the new state and its carry.
#[allow(clippy::too_many_arguments)]
fn dopri<R: Real, L: ContactLaw<R>>(
    sys: &System<'_, R, L>,
    s: &Vec<R>,
    carry: &Vec<R>,
    k1: &Vec<R>,
    h: R,
    phase: Phase<R>,
    dim: usize,
) -> ([Vec<R>; 7], Vec<R>, Vec<R>) {
    let stage = |coef: &[f64], ks: &[Vec<R>]| -> Vec<R> {
        let mut y = *s;
        for (a, k) in coef.iter().zip(ks) {
            let a = c::<R>(*a) * h;
            for i in 0..dim {
                y[i] += a * k[i];
            }
        }
        y
    };
    let mut ks = [[R::ZERO; S]; 7];
    ks[0] = *k1;
    ks[1] = sys.rhs(&stage(&A2, &ks[..1]), phase);
    ks[2] = sys.rhs(&stage(&A3, &ks[..2]), phase);
    ks[3] = sys.rhs(&stage(&A4, &ks[..3]), phase);
    ks[4] = sys.rhs(&stage(&A5, &ks[..4]), phase);
    ks[5] = sys.rhs(&stage(&A6, &ks[..5]), phase);
    let mut y1 = *s;
    let mut carry1 = *carry;
    for i in 0..dim {
        let mut dy = R::ZERO;
        for (b, k) in B.iter().zip(&ks[..6]) {
            dy += c::<R>(*b) * h * k[i];
        }
        // Kahan-compensated state.
        let inc = dy - carry1[i];
        let sum = y1[i] + inc;
        carry1[i] = (sum - y1[i]) - inc;
        y1[i] = sum;
    }
    ks[6] = sys.rhs(&y1, phase);
    (ks, y1, carry1)
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
    if !(rtol.is_finite() && rtol > R::ZERO && rtol < R::ONE) {
        return Err(Error::InvalidParameter {
            name: "rtol",
            reason: "must lie in (0, 1)",
        });
    }
    let rtol = rtol.max(c::<R>(8.0) * R::EPSILON);
    let m1 = impact.mass_kg;
    let v0 = impact.v0_m_s;
    let n = target.n;
    let dim = n + 5;
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
    let h_min = scale_t * R::EPSILON * c(16.0);
    let mut h = scale_t * c::<R>(0.05) * rtol.powf(c(0.2));

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
    let show_step = |obs: &mut dyn FnMut(Sample<R>), seg: &Dense<R>, upto: R, ph: Phase<R>| {
        for k in 1..=SAMPLES_PER_STEP {
            let th = upto * R::from_u32(k) / R::from_u32(SAMPLES_PER_STEP);
            show(obs, seg.t0 + th * seg.h, &seg.at(th), ph);
        }
    };

    for _ in 0..1_000_000u32 {
        // One accepted step (Dormand–Prince, FSAL), as in `solve::adaptive`.
        let mut accepted = None;
        for _attempt in 0..64 {
            let (ks, y1, carry1) = dopri(&sys, &s, &carry, &k1, h, phase, dim);
            evals += 6;
            let mut err = [R::ZERO; S];
            for (e, k) in E.iter().zip(&ks) {
                for i in 0..dim {
                    err[i] += c::<R>(*e) * h * k[i];
                }
            }
            // Error on the deformation and its rate, the impactor, the contact point and the
            // energy integrals.
            let (ey, ew) = sys.outputs(&err);
            let (y0o, w0o) = sys.outputs(&s);
            let (y1o, w1o) = sys.outputs(&y1);
            let (x0, u0) = sys.impactor(&s);
            let (x1, u1) = sys.impactor(&y1);
            let tol = |a: R, b: R, floor: R| rtol * a.abs().max(b.abs()).max(floor);
            let terms = [
                err[0] / tol(s[0], y1[0], floor_x),
                err[1] / tol(s[1], y1[1], floor_v),
                (err[0] + ey) / tol(x0, x1, floor_x),
                (err[1] + ew) / tol(u0, u1, floor_v),
                ey / tol(y0o, y1o, floor_x),
                ew / tol(w0o, w1o, floor_v),
                err[2 + n] / tol(s[2 + n], y1[2 + n], floor_e),
                err[3 + n] / tol(s[3 + n], y1[3 + n], floor_e),
                err[4 + n] / tol(s[4 + n], y1[4 + n], floor_e),
            ];
            let mut sq = R::ZERO;
            for x in terms {
                sq += x * x;
            }
            let norm = (sq / c(9.0)).sqrt();
            let finite = y1[..dim].iter().all(|x| x.is_finite());
            if !norm.is_finite() || !finite {
                h *= c(0.2);
            } else {
                let factor = if norm == R::ZERO {
                    c(5.0)
                } else {
                    (c::<R>(0.9) * norm.powf(c(-0.2))).max(c(0.2)).min(c(5.0))
                };
                if norm <= R::ONE {
                    let mut r = [[R::ZERO; S]; 5];
                    for i in 0..dim {
                        let dy = y1[i] - s[i];
                        let bspl = h * k1[i] - dy;
                        r[0][i] = s[i];
                        r[1][i] = dy;
                        r[2][i] = bspl;
                        r[3][i] = dy - h * ks[6][i] - bspl;
                        let mut d = R::ZERO;
                        for (dj, k) in D.iter().zip(&ks) {
                            d += c::<R>(*dj) * k[i];
                        }
                        r[4][i] = h * d;
                    }
                    accepted = Some((Dense { t0: t.sum, h, r }, y1, carry1, ks[6]));
                    h *= factor;
                    // Inside the stability interval for the contact's own fastest mode.
                    let cap = c::<R>(STIFF_STEP) / sys.contact_rate(&y1, phase, floor_x, floor_v);
                    if cap > R::ZERO && cap.is_finite() {
                        h = h.min(cap);
                    }
                    break;
                }
                h *= factor.min(R::ONE);
            }
            if !(h > h_min) {
                return Err(Error::Unresolved("adaptive step size underflow"));
            }
        }
        let Some((seg, y1, carry1, k_end)) = accepted else {
            return Err(Error::Unresolved(
                "adaptive step rejected 64 times in a row",
            ));
        };
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
        let (_, f) = golden_max(force, lo, hi, 80);
        best.1 = best.1.max(f);
        peak = peak.max(best.1);

        // Maxima of the deformation: where its rate turns negative.
        let mut from = R::ZERO;
        if rate(R::ZERO) >= R::ZERO && rate(R::ONE) < R::ZERO {
            // Never skipped: if the interpolant's ends disagree with the test (rounding), the
            // chord.
            let th = brent(rate, R::ZERO, R::ONE, R::EPSILON * c(4.0), &mut evals)
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
            let th = brent(force, from, R::ONE, R::EPSILON * c(4.0), &mut evals)
                .unwrap_or_else(|| chord(force(from), force(R::ONE), from));
            // Land a step on the separation found on the interpolant: the state there has
            // the step's accuracy, not the interpolant's.
            let (_, ss, _) = dopri(&sys, &s, &carry, &k1, th * seg.h, phase, dim);
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
