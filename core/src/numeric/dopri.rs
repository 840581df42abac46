//! Dormand–Prince 5(4) with Shampine's 4th-order dense output (the pair behind MATLAB's
//! `ode45`, scipy's `RK45` and Hairer's `DOPRI5`), for any autonomous system of up to `N`
//! states: the stages, the Kahan-compensated end state, the step controller and the dense
//! output, written once for the wall solver (`solve::adaptive`, 2 states) and the two-body
//! solver (`two_body::coupled`, the contact, the target and three energy integrals).
//!
//! Steps grow or shrink by the usual `SAFETY err^(-1/5)` rule within
//! `[MIN_FACTOR, MAX_FACTOR]`; the system measures the error its own way
//! ([`System::error_norm`]) and may cap the next step ([`System::max_step`]).

use crate::error::Error;
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

/// The controller's safety factor on the optimal step.
const SAFETY: f64 = 0.9;
/// Smallest and largest change of the step from one try to the next.
const MIN_FACTOR: f64 = 0.2;
const MAX_FACTOR: f64 = 5.0;
/// Rejections in a row before a step is given up.
const MAX_REJECTS: u32 = 64;

#[inline]
fn c<R: Real>(x: f64) -> R {
    R::from_f64(x)
}

/// An autonomous system `y' = f(y)` of `N` states (the first [`System::dim`] in use; the
/// others stay zero).
pub(crate) trait System<R: Real, const N: usize> {
    /// States in use.
    fn dim(&self) -> usize {
        N
    }
    /// `f(y)`.
    fn rhs(&self, y: &[R; N]) -> [R; N];
    /// The step's scaled error norm (the step is accepted at `<= 1`), from its stages `ks`,
    /// its length `h`, its start `y0` and its 5th-order end `y1`.
    fn error_norm(&self, h: R, ks: &[[R; N]; 7], y0: &[R; N], y1: &[R; N]) -> R;
    /// After a step to `y1` was accepted: the longest the next may be, if the system needs
    /// one (stability), else `None`.
    fn max_step(&self, _y1: &[R; N]) -> Option<R> {
        None
    }
}

/// An accepted step with `rcont1..rcont5` of Hairer's `CONTD5` for every state.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Dense<R, const N: usize> {
    /// Start time and length, s.
    pub t0: R,
    pub h: R,
    pub r: [[R; N]; 5],
}

impl<R: Real, const N: usize> Dense<R, N> {
    /// State `i` at fraction `th` of the step.
    #[inline]
    pub fn state(&self, i: usize, th: R) -> R {
        let th1 = R::ONE - th;
        let r = &self.r;
        r[0][i] + th * (r[1][i] + th1 * (r[2][i] + th * (r[3][i] + th1 * r[4][i])))
    }

    /// Every state at fraction `th` of the step.
    pub fn at(&self, th: R) -> [R; N] {
        let mut out = [R::ZERO; N];
        for (i, o) in out.iter_mut().enumerate() {
            *o = self.state(i, th);
        }
        out
    }
}

/// One try of a step of length `h` from `y0` (Kahan carry `carry`, derivative `k1 = f(y0)`):
/// the seven stages, the end state and its carry. 6 evaluations of `f`.
pub(crate) fn trial<R: Real, S: System<R, N>, const N: usize>(
    sys: &S,
    y0: &[R; N],
    carry: &[R; N],
    k1: &[R; N],
    h: R,
) -> ([[R; N]; 7], [R; N], [R; N]) {
    let dim = sys.dim().min(N);
    let stage = |coef: &[f64], ks: &[[R; N]]| -> [R; N] {
        let mut y = *y0;
        for (a, k) in coef.iter().zip(ks) {
            let a = c::<R>(*a) * h;
            for i in 0..dim {
                y[i] += a * k[i];
            }
        }
        y
    };
    let mut ks = [[R::ZERO; N]; 7];
    ks[0] = *k1;
    ks[1] = sys.rhs(&stage(&A2, &ks[..1]));
    ks[2] = sys.rhs(&stage(&A3, &ks[..2]));
    ks[3] = sys.rhs(&stage(&A4, &ks[..3]));
    ks[4] = sys.rhs(&stage(&A5, &ks[..4]));
    ks[5] = sys.rhs(&stage(&A6, &ks[..5]));
    let mut y1 = *y0;
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
    ks[6] = sys.rhs(&y1);
    (ks, y1, carry1)
}

/// An accepted step: its dense output, the end state, its carry and `f` there (FSAL).
pub(crate) struct Accepted<R, const N: usize> {
    pub dense: Dense<R, N>,
    pub y1: [R; N],
    pub carry1: [R; N],
    pub k_end: [R; N],
}

/// One accepted step from `y0` at time `t0`, trying `*h` first; leaves in `*h` the length to
/// try next. Counts the evaluations of `f` in `evals`. Fails when the step would shrink below
/// `h_min` or is rejected [`MAX_REJECTS`] times in a row.
#[allow(clippy::too_many_arguments)]
pub(crate) fn step<R: Real, S: System<R, N>, const N: usize>(
    sys: &S,
    t0: R,
    y0: &[R; N],
    carry: &[R; N],
    k1: &[R; N],
    h: &mut R,
    h_min: R,
    evals: &mut u32,
) -> Result<Accepted<R, N>, Error> {
    let dim = sys.dim().min(N);
    for _attempt in 0..MAX_REJECTS {
        let hh = *h;
        let (ks, y1, carry1) = trial(sys, y0, carry, k1, hh);
        *evals += 6;
        let norm = sys.error_norm(hh, &ks, y0, &y1);
        if !norm.is_finite() || !y1[..dim].iter().all(|x| x.is_finite()) {
            *h = hh * c(MIN_FACTOR);
        } else {
            let factor = if norm == R::ZERO {
                c(MAX_FACTOR)
            } else {
                (c::<R>(SAFETY) * norm.powf(c(-0.2)))
                    .max(c(MIN_FACTOR))
                    .min(c(MAX_FACTOR))
            };
            if norm <= R::ONE {
                let mut r = [[R::ZERO; N]; 5];
                for i in 0..dim {
                    let dy = y1[i] - y0[i];
                    let bspl = hh * k1[i] - dy;
                    r[0][i] = y0[i];
                    r[1][i] = dy;
                    r[2][i] = bspl;
                    r[3][i] = dy - hh * ks[6][i] - bspl;
                    let mut d = R::ZERO;
                    for (dj, k) in D.iter().zip(&ks) {
                        d += c::<R>(*dj) * k[i];
                    }
                    r[4][i] = hh * d;
                }
                *h = hh * factor;
                if let Some(cap) = sys.max_step(&y1) {
                    if cap > R::ZERO && cap.is_finite() {
                        *h = (*h).min(cap);
                    }
                }
                return Ok(Accepted {
                    dense: Dense { t0, h: hh, r },
                    y1,
                    carry1,
                    k_end: ks[6],
                });
            }
            *h = hh * factor.min(R::ONE);
        }
        if !(*h > h_min) {
            return Err(Error::Unresolved("adaptive step size underflow"));
        }
    }
    Err(Error::Unresolved(
        "adaptive step rejected 64 times in a row",
    ))
}

/// The first step to try: `0.05 rtol^(1/5)` of the contact's time scale; the smallest: 16 ulps
/// of it.
pub(crate) fn initial_steps<R: Real>(time_scale: R, rtol: R) -> (R, R) {
    (
        time_scale * c::<R>(0.05) * rtol.powf(c(0.2)),
        time_scale * R::EPSILON * c(16.0),
    )
}

/// Checks `rtol` (in `(0, 1)`) and raises it to at least `8 EPSILON` of the number type.
pub(crate) fn checked_rtol<R: Real>(rtol: R) -> Result<R, Error> {
    if !(rtol.is_finite() && rtol > R::ZERO && rtol < R::ONE) {
        return Err(Error::InvalidParameter {
            name: "rtol",
            reason: "must lie in (0, 1)",
        });
    }
    Ok(rtol.max(c::<R>(8.0) * R::EPSILON))
}
