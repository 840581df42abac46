//! The wall contact by adaptive Dormand–Prince 5(4) with dense output
//! ([`crate::numeric::dopri`]): the body's `(x, v)` as a 2-state system.
//!
//! Error per step is measured against `rtol * max(|y|, scale)` with `scale = v0 / 100` for the
//! velocity and `v0 * time_scale / 100` for the deformation. The stages are autonomous (the
//! force does not depend on time), so the nodes `c = (0, 1/5, 3/10, 4/5, 8/9, 1)` never
//! appear.

use super::events::{accel, run, Compensated, Observer, Segment, State, Stepper};
use super::{Error, Impact, ImpactOutcome};
use crate::model::{ContactLaw, Phase};
use crate::numeric::dopri::{self, Dense, System, E};
use crate::real::Real;

/// The wall contact as the 2-state system `(x, v)` under one phase, and how its error is
/// measured: against `rtol * max(|y|, scale)` per state, the RMS of the two.
struct Wall<'a, R, L> {
    law: &'a L,
    phase: Phase<R>,
    inv_m: R,
    rtol: R,
    scale_x: R,
    scale_v: R,
}

impl<R: Real, L: ContactLaw<R>> System<R, 2> for Wall<'_, R, L> {
    #[inline]
    fn rhs(&self, y: &[R; 2]) -> [R; 2] {
        [y[1], accel(self.law, self.phase, self.inv_m, y[0], y[1])]
    }

    fn error_norm(&self, h: R, ks: &[[R; 2]; 7], y0: &[R; 2], y1: &[R; 2]) -> R {
        // Scaled RMS error of the embedded 4th-order solution.
        let mut err = [R::ZERO; 2];
        for (e, k) in E.iter().zip(ks) {
            err[0] += R::from_f64(*e) * k[0];
            err[1] += R::from_f64(*e) * k[1];
        }
        let sx = self.rtol * y0[0].abs().max(y1[0].abs()).max(self.scale_x);
        let sv = self.rtol * y0[1].abs().max(y1[1].abs()).max(self.scale_v);
        let ex = h * err[0] / sx;
        let ev = h * err[1] / sv;
        (R::HALF * (ex * ex + ev * ev)).sqrt()
    }
}

/// An accepted step of the wall contact: its dense output for `(x, v)`.
impl<R: Real> Segment<R> for Dense<R, 2> {
    fn span(&self) -> (R, R) {
        (self.t0, self.h)
    }
    #[inline]
    fn at(&self, th: R) -> (R, R) {
        (self.state(0, th), self.state(1, th))
    }
    fn end(&self) -> State<R> {
        State {
            t: self.t0 + self.h,
            x: self.r[0][0] + self.r[1][0],
            v: self.r[0][1] + self.r[1][1],
        }
    }
}

struct Dopri<R> {
    rtol: R,
    scale_x: R,
    scale_v: R,
    inv_m: R,
    h: R,
    h_min: R,
    t: Compensated<R>,
    /// Position and velocity, and their Kahan carries across steps.
    y: [R; 2],
    carry: [R; 2],
    /// FSAL: derivative at the current state.
    k1: [R; 2],
    /// `(t, y, carry, k1)` before the last accepted step, for [`Stepper::retake`].
    before: (Compensated<R>, [R; 2], [R; 2], [R; 2]),
    evals: u32,
}

impl<R: Real> Dopri<R> {
    fn system<'a, L>(&self, law: &'a L, phase: Phase<R>) -> Wall<'a, R, L> {
        Wall {
            law,
            phase,
            inv_m: self.inv_m,
            rtol: self.rtol,
            scale_x: self.scale_x,
            scale_v: self.scale_v,
        }
    }
}

impl<R: Real> Stepper<R> for Dopri<R> {
    type Seg = Dense<R, 2>;

    fn start<L: ContactLaw<R>>(&mut self, law: &L, phase: Phase<R>, s: State<R>) {
        self.t = Compensated::new(s.t);
        self.y = [s.x, s.v];
        self.carry = [R::ZERO; 2];
        self.k1 = self.system(law, phase).rhs(&self.y);
        self.evals += 1;
    }

    fn step<L: ContactLaw<R>>(&mut self, law: &L, phase: Phase<R>) -> Result<Dense<R, 2>, Error> {
        self.before = (self.t, self.y, self.carry, self.k1);
        let sys = self.system(law, phase);
        let a = dopri::step(
            &sys,
            self.t.sum,
            &self.y,
            &self.carry,
            &self.k1,
            &mut self.h,
            self.h_min,
            &mut self.evals,
        )?;
        self.t.add(a.dense.h);
        self.y = a.y1;
        self.carry = a.carry1;
        self.k1 = a.k_end;
        Ok(a.dense)
    }

    fn retake(&mut self, h: R) {
        (self.t, self.y, self.carry, self.k1) = self.before;
        self.h = h;
    }

    fn evaluations(&self) -> u32 {
        self.evals
    }
}

/// Solves one impact with Dormand–Prince 5(4) at relative tolerance `rtol`
/// (clamped to at least `8 * EPSILON` of the number type).
pub fn solve<R: Real, L: ContactLaw<R>>(
    law: &L,
    impact: &Impact<R>,
    rtol: R,
) -> Result<ImpactOutcome<R>, Error> {
    solve_observed(law, impact, rtol, &mut ())
}

/// As [`solve`], showing every piece of the trajectory to `obs`.
pub fn solve_observed<R: Real, L: ContactLaw<R>>(
    law: &L,
    impact: &Impact<R>,
    rtol: R,
    obs: &mut impl Observer<R>,
) -> Result<ImpactOutcome<R>, Error> {
    let rtol = dopri::checked_rtol(rtol)?;
    let scale_t = law.time_scale(impact);
    if !(scale_t.is_finite() && scale_t > R::ZERO) {
        return Err(Error::Unresolved(
            "time scale is not a positive finite number",
        ));
    }
    let v0 = impact.v0_m_s;
    let (h, h_min) = dopri::initial_steps(scale_t, rtol);
    let mut stepper = Dopri {
        rtol,
        scale_x: v0 * scale_t * R::from_f64(1e-2),
        scale_v: v0 * R::from_f64(1e-2),
        inv_m: R::ONE / impact.mass_kg,
        h,
        h_min,
        t: Compensated::default(),
        y: [R::ZERO; 2],
        carry: [R::ZERO; 2],
        k1: [R::ZERO; 2],
        before: Default::default(),
        evals: 0,
    };
    run(law, impact, &mut stepper, 1_000_000, obs)
}
