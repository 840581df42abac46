//! Adaptive Dormand–Prince 5(4) with Shampine's 4th-order dense output (the pair behind
//! MATLAB's `ode45`, scipy's `RK45` and Hairer's `DOPRI5`).
//!
//! Error per step is measured against `rtol * max(|y|, scale)` with `scale = v0` for the
//! velocity and `v0 * time_scale` for the deformation; steps grow or shrink by the usual
//! `0.9 err^(-1/5)` rule within `[0.2, 5]`. The stages are autonomous (the force does not
//! depend on time), so the nodes `c = (0, 1/5, 3/10, 4/5, 8/9, 1)` never appear.

use super::events::{accel, run, Compensated, Observer, Segment, State, Stepper};
use super::{Error, Impact, ImpactOutcome};
use crate::model::{ContactLaw, Phase};
use crate::real::Real;

pub(crate) const A2: [f64; 1] = [0.2];
pub(crate) const A3: [f64; 2] = [3.0 / 40.0, 9.0 / 40.0];
pub(crate) const A4: [f64; 3] = [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0];
pub(crate) const A5: [f64; 4] = [
    19372.0 / 6561.0,
    -25360.0 / 2187.0,
    64448.0 / 6561.0,
    -212.0 / 729.0,
];
pub(crate) const A6: [f64; 5] = [
    9017.0 / 3168.0,
    -355.0 / 33.0,
    46732.0 / 5247.0,
    49.0 / 176.0,
    -5103.0 / 18656.0,
];
/// 5th-order weights (also row 7 of the tableau: first same as last).
pub(crate) const B: [f64; 6] = [
    35.0 / 384.0,
    0.0,
    500.0 / 1113.0,
    125.0 / 192.0,
    -2187.0 / 6784.0,
    11.0 / 84.0,
];
/// Error weights `b - b*` for stages 1..7.
pub(crate) const E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];
/// Dense output weights (Shampine 1986, as in Hairer's `CONTD5`).
pub(crate) const D: [f64; 7] = [
    -12715105075.0 / 11282082432.0,
    0.0,
    87487479700.0 / 32700410799.0,
    -10690763975.0 / 1880347072.0,
    701980252875.0 / 199316789632.0,
    -1453857185.0 / 822651844.0,
    69997945.0 / 29380423.0,
];

/// An accepted step with Hairer's dense-output coefficients for `(x, v)`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct DenseStep<R> {
    t0: R,
    h: R,
    /// `rcont1..rcont5` of `CONTD5`, for x and v.
    r: [[R; 2]; 5],
}

impl<R: Real> Segment<R> for DenseStep<R> {
    fn span(&self) -> (R, R) {
        (self.t0, self.h)
    }
    #[inline]
    fn at(&self, th: R) -> (R, R) {
        let th1 = R::ONE - th;
        let r = &self.r;
        let comp =
            |i: usize| r[0][i] + th * (r[1][i] + th1 * (r[2][i] + th * (r[3][i] + th1 * r[4][i])));
        (comp(0), comp(1))
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
    /// Position and velocity, Kahan-compensated across steps.
    x: Compensated<R>,
    v: Compensated<R>,
    /// FSAL: derivative at the current state.
    k1: [R; 2],
    /// `(t, x, v, k1)` before the last accepted step, for [`Stepper::retake`].
    before: (Compensated<R>, Compensated<R>, Compensated<R>, [R; 2]),
    evals: u32,
}

#[inline]
fn c<R: Real>(x: f64) -> R {
    R::from_f64(x)
}

impl<R: Real> Stepper<R> for Dopri<R> {
    type Seg = DenseStep<R>;

    fn start<L: ContactLaw<R>>(&mut self, law: &L, phase: Phase<R>, s: State<R>) {
        self.t = Compensated::new(s.t);
        self.x = Compensated::new(s.x);
        self.v = Compensated::new(s.v);
        self.k1 = [s.v, accel(law, phase, self.inv_m, s.x, s.v)];
        self.evals += 1;
    }

    fn step<L: ContactLaw<R>>(&mut self, law: &L, phase: Phase<R>) -> Result<DenseStep<R>, Error> {
        let f = |x: R, v: R| [v, accel(law, phase, self.inv_m, x, v)];
        let y0 = [self.x.sum, self.v.sum];
        let k1 = self.k1;
        self.before = (self.t, self.x, self.v, self.k1);
        for _attempt in 0..64 {
            let h = self.h;
            let stage = |coef: &[f64], ks: &[[R; 2]]| -> [R; 2] {
                let mut y = y0;
                for (a, k) in coef.iter().zip(ks) {
                    let a = c::<R>(*a) * h;
                    y[0] += a * k[0];
                    y[1] += a * k[1];
                }
                y
            };
            let mut ks = [[R::ZERO; 2]; 7];
            ks[0] = k1;
            let y = stage(&A2, &ks[..1]);
            ks[1] = f(y[0], y[1]);
            let y = stage(&A3, &ks[..2]);
            ks[2] = f(y[0], y[1]);
            let y = stage(&A4, &ks[..3]);
            ks[3] = f(y[0], y[1]);
            let y = stage(&A5, &ks[..4]);
            ks[4] = f(y[0], y[1]);
            let y = stage(&A6, &ks[..5]);
            ks[5] = f(y[0], y[1]);
            // The step's increment, added with compensation.
            let mut dy = [R::ZERO; 2];
            for (b, k) in B.iter().zip(&ks[..6]) {
                let b = c::<R>(*b) * h;
                dy[0] += b * k[0];
                dy[1] += b * k[1];
            }
            let (mut x1, mut v1) = (self.x, self.v);
            x1.add(dy[0]);
            v1.add(dy[1]);
            let y1 = [x1.sum, v1.sum];
            ks[6] = f(y1[0], y1[1]);
            self.evals += 6;

            // Scaled RMS error of the embedded 4th-order solution.
            let mut err = [R::ZERO; 2];
            for (e, k) in E.iter().zip(&ks) {
                err[0] += c::<R>(*e) * k[0];
                err[1] += c::<R>(*e) * k[1];
            }
            let sx = self.rtol * y0[0].abs().max(y1[0].abs()).max(self.scale_x);
            let sv = self.rtol * y0[1].abs().max(y1[1].abs()).max(self.scale_v);
            let ex = h * err[0] / sx;
            let ev = h * err[1] / sv;
            let norm = (R::HALF * (ex * ex + ev * ev)).sqrt();
            if !norm.is_finite() || !y1[0].is_finite() || !y1[1].is_finite() {
                self.h = h * c(0.2);
            } else {
                let factor = if norm == R::ZERO {
                    c(5.0)
                } else {
                    (c::<R>(0.9) * norm.powf(c(-0.2))).max(c(0.2)).min(c(5.0))
                };
                if norm <= R::ONE {
                    // Accept; build the dense output.
                    let mut r = [[R::ZERO; 2]; 5];
                    for i in 0..2 {
                        let dy = y1[i] - y0[i];
                        let bspl = h * k1[i] - dy;
                        r[0][i] = y0[i];
                        r[1][i] = dy;
                        r[2][i] = bspl;
                        r[3][i] = dy - h * ks[6][i] - bspl;
                        let mut d = R::ZERO;
                        for (dj, k) in D.iter().zip(&ks) {
                            d += c::<R>(*dj) * k[i];
                        }
                        r[4][i] = h * d;
                    }
                    let seg = DenseStep {
                        t0: self.t.sum,
                        h,
                        r,
                    };
                    self.t.add(h);
                    self.x = x1;
                    self.v = v1;
                    self.k1 = ks[6];
                    self.h = h * factor;
                    return Ok(seg);
                }
                self.h = h * factor.min(R::ONE);
            }
            if !(self.h > self.h_min) {
                return Err(Error::Unresolved("adaptive step size underflow"));
            }
        }
        Err(Error::Unresolved(
            "adaptive step rejected 64 times in a row",
        ))
    }

    fn retake(&mut self, h: R) {
        (self.t, self.x, self.v, self.k1) = self.before;
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
    if !(rtol.is_finite() && rtol > R::ZERO && rtol < R::ONE) {
        return Err(Error::InvalidParameter {
            name: "rtol",
            reason: "must lie in (0, 1)",
        });
    }
    let rtol = rtol.max(c::<R>(8.0) * R::EPSILON);
    let scale_t = law.time_scale(impact);
    if !(scale_t.is_finite() && scale_t > R::ZERO) {
        return Err(Error::Unresolved(
            "time scale is not a positive finite number",
        ));
    }
    let v0 = impact.v0_m_s;
    let mut stepper = Dopri {
        rtol,
        scale_x: v0 * scale_t * c::<R>(1e-2),
        scale_v: v0 * c::<R>(1e-2),
        inv_m: R::ONE / impact.mass_kg,
        h: scale_t * c::<R>(0.05) * rtol.powf(c(0.2)),
        h_min: scale_t * R::EPSILON * c(16.0),
        t: Compensated::default(),
        x: Compensated::default(),
        v: Compensated::default(),
        k1: [R::ZERO; 2],
        before: Default::default(),
        evals: 0,
    };
    run(law, impact, &mut stepper, 1_000_000, obs)
}
