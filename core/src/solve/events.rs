//! The contact driver shared by the time-stepping solvers: steps from first touch, locates
//! the maximum deformation, the peak force and separation on each step's interpolant.

use super::{Error, Impact, ImpactOutcome};
use crate::model::{ContactLaw, Phase};
use crate::numeric::roots::{brent, golden_max};
use crate::real::Real;

/// Position and velocity at a time, s / m / m/s.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct State<R> {
    pub t: R,
    pub x: R,
    pub v: R,
}

/// One accepted step with its continuous extension.
pub(crate) trait Segment<R: Real>: Copy {
    /// Start time and length, s.
    fn span(&self) -> (R, R);
    /// `(x, v)` at fraction `theta` in [0, 1] of the step.
    fn at(&self, theta: R) -> (R, R);
    /// State at the end of the step.
    fn end(&self) -> State<R>;
}

/// A time-stepping method: advances the contact by one accepted step.
pub(crate) trait Stepper<R: Real> {
    type Seg: Segment<R>;
    /// Starts (or restarts, after a change of force law) at `state`.
    fn start<L: ContactLaw<R>>(&mut self, law: &L, phase: Phase<R>, state: State<R>);
    /// One accepted step from the current state.
    fn step<L: ContactLaw<R>>(&mut self, law: &L, phase: Phase<R>) -> Result<Self::Seg, Error>;
    /// Takes back the last step and makes the next one `h` long (an adaptive method may still
    /// shorten it): used to land a step on separation instead of stepping across it.
    fn retake(&mut self, h: R);
    /// Right-hand-side evaluations so far.
    fn evaluations(&self) -> u32;
}

/// Acceleration of the body, m/s²: `-F/m` with the smooth force law.
#[inline]
pub(crate) fn accel<R: Real, L: ContactLaw<R>>(
    law: &L,
    phase: Phase<R>,
    inv_m: R,
    x: R,
    v: R,
) -> R {
    -law.raw_force(x, v, phase) * inv_m
}

/// Sees every accepted piece of the trajectory, in time order (used to sample it).
pub trait Observer<R: Real> {
    /// The trajectory on `[t_a, t_b]` (s) is `at(t) -> (x, v)` under `phase`.
    fn piece(&mut self, t_a: R, t_b: R, at: &dyn Fn(R) -> (R, R), phase: Phase<R>);
}

/// Observes nothing.
impl<R: Real> Observer<R> for () {
    #[inline]
    fn piece(&mut self, _: R, _: R, _: &dyn Fn(R) -> (R, R), _: Phase<R>) {}
}

fn show<R: Real, S: Segment<R>>(obs: &mut impl Observer<R>, seg: &S, a: R, b: R, phase: Phase<R>) {
    let (t0, h) = seg.span();
    let at = |t: R| seg.at((t - t0) / h);
    obs.piece(t0 + a * h, t0 + b * h, &at, phase);
}

/// Part of a segment, `[a, b]` in step fractions, under one phase.
#[derive(Clone, Copy)]
struct Piece<S, R> {
    seg: S,
    a: R,
    b: R,
    phase: Phase<R>,
}

/// Remembers the largest sampled force and the pieces on either side of it, then maximises
/// the interpolated force over those pieces.
struct PeakTrack<S, R> {
    best: R,
    before: Option<Piece<S, R>>,
    after: Option<Piece<S, R>>,
    last: Option<Piece<S, R>>,
    want_after: bool,
}

impl<S: Segment<R>, R: Real> PeakTrack<S, R> {
    fn new(f0: R) -> Self {
        Self {
            best: f0,
            before: None,
            after: None,
            last: None,
            want_after: true,
        }
    }

    fn add<L: ContactLaw<R>>(&mut self, law: &L, piece: Piece<S, R>) {
        let force = |theta: R| {
            let (x, v) = piece.seg.at(theta);
            law.raw_force(x, v, piece.phase)
        };
        let f_start = force(piece.a);
        let f_end = force(piece.b);
        if self.want_after {
            self.after = Some(piece);
            self.want_after = false;
        }
        if f_start > self.best {
            self.best = f_start;
            self.before = self.last;
            self.after = Some(piece);
        }
        if f_end > self.best {
            self.best = f_end;
            self.before = Some(piece);
            self.after = None;
            self.want_after = true;
        }
        self.last = Some(piece);
    }

    fn refine<L: ContactLaw<R>>(&self, law: &L) -> R {
        let mut best = self.best;
        for piece in [self.before, self.after].into_iter().flatten() {
            let (_, f) = golden_max(
                |theta: R| {
                    let (x, v) = piece.seg.at(theta);
                    law.raw_force(x, v, piece.phase)
                },
                piece.a,
                piece.b,
                GOLDEN_ITERATIONS,
            );
            best = best.max(f);
        }
        best
    }
}

/// Golden-section iterations refining the peak force on a piece: the bracket shrinks to
/// 0.618^52 ≈ 1e-11 of a step, far below what changes an interior maximum; a maximum at a
/// piece end is the sampled value itself.
const GOLDEN_ITERATIONS: u32 = 52;

/// A separation found before this fraction of a step makes the step be taken again.
const LAND_BEFORE: f64 = 0.99;
/// How far past the located separation the retaken step ends (fraction of its length).
const LAND_OVERSHOOT: f64 = 1.002;
/// At most this many retakes per contact.
const MAX_LANDINGS: u32 = 4;

/// One more piece of the contact: to the peak-force search and to the observer.
fn record<R: Real, L: ContactLaw<R>, S: Segment<R>>(
    peak: &mut PeakTrack<S, R>,
    obs: &mut impl Observer<R>,
    law: &L,
    piece: Piece<S, R>,
) {
    show(obs, &piece.seg, piece.a, piece.b, piece.phase);
    peak.add(law, piece);
}

/// Runs one contact with `stepper` until separation (at most `max_steps` accepted steps).
pub(crate) fn run<R: Real, L: ContactLaw<R>, S: Stepper<R>>(
    law: &L,
    impact: &Impact<R>,
    stepper: &mut S,
    max_steps: u32,
    obs: &mut impl Observer<R>,
) -> Result<ImpactOutcome<R>, Error> {
    let v0 = impact.v0_m_s;
    let mut phase = Phase::Compression;
    stepper.start(
        law,
        phase,
        State {
            t: R::ZERO,
            x: R::ZERO,
            v: v0,
        },
    );
    let mut peak: PeakTrack<S::Seg, R> = PeakTrack::new(law.raw_force(R::ZERO, v0, phase));
    let mut crush: Option<(R, R)> = None; // (t_m, x_m)
    let mut evals = 0u32;
    let tol = R::ZERO;
    let mut landings = 0u32;

    for _ in 0..max_steps {
        let seg = stepper.step(law, phase)?;
        let end = seg.end();
        if !(end.x.is_finite() && end.v.is_finite() && end.t.is_finite()) {
            return Err(Error::Unresolved(
                "state became non-finite (step too large for the stiffness)",
            ));
        }
        let (t0, h) = seg.span();
        let mut from = R::ZERO;

        if crush.is_none() && end.v <= R::ZERO {
            // Maximum deformation: v = 0 on the interpolant.
            let theta = brent(|th: R| seg.at(th).1, R::ZERO, R::ONE, tol, &mut evals)
                .ok_or(Error::Unresolved("maximum deformation not bracketed"))?;
            let (x_m, _) = seg.at(theta);
            let t_m = t0 + theta * h;
            crush = Some((t_m, x_m));
            record(
                &mut peak,
                obs,
                law,
                Piece {
                    seg,
                    a: R::ZERO,
                    b: theta,
                    phase,
                },
            );
            phase = Phase::Restitution { x_max: x_m };
            if law.switches_at_max() {
                stepper.start(
                    law,
                    phase,
                    State {
                        t: t_m,
                        x: x_m,
                        v: R::ZERO,
                    },
                );
                continue;
            }
            from = theta;
        }

        if let (Some((t_m, x_m)), Phase::Restitution { .. }) = (crush, phase) {
            let force = |th: R| {
                let (x, v) = seg.at(th);
                law.raw_force(x, v, phase)
            };
            if force(R::ONE) <= R::ZERO {
                // Separation: the force returns to zero on this step.
                let theta = if force(from) <= R::ZERO {
                    from
                } else {
                    brent(force, from, R::ONE, tol, &mut evals)
                        .ok_or(Error::Unresolved("separation not bracketed"))?
                };
                // A step that reaches far past separation integrated the force law's
                // extension beyond it: take it again, ending just after separation.
                if from == R::ZERO && theta < R::from_f64(LAND_BEFORE) && landings < MAX_LANDINGS {
                    landings += 1;
                    stepper.retake(theta * h * R::from_f64(LAND_OVERSHOOT));
                    continue;
                }
                record(
                    &mut peak,
                    obs,
                    law,
                    Piece {
                        seg,
                        a: from,
                        b: theta,
                        phase,
                    },
                );
                let (x_s, v_s) = seg.at(theta);
                if !law.admissible(x_s, v_s) {
                    return Err(Error::Unresolved(
                        "the steps left the law's reachable states (too few for the damping)",
                    ));
                }
                let rebound = (-v_s).max(R::ZERO);
                return Ok(ImpactOutcome {
                    max_deformation_m: x_m,
                    crush_time_s: t_m,
                    contact_time_s: t0 + theta * h,
                    rebound_velocity_m_s: rebound,
                    cor: rebound / v0,
                    peak_force_n: peak.refine(law),
                    permanent_deformation_m: x_s.max(R::ZERO),
                    rhs_evaluations: stepper.evaluations(),
                });
            }
        }
        record(
            &mut peak,
            obs,
            law,
            Piece {
                seg,
                a: from,
                b: R::ONE,
                phase,
            },
        );
    }
    Err(Error::Unresolved("no separation within the step budget"))
}

/// Kahan-compensated accumulator: long runs of small increments keep full precision.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Compensated<R> {
    pub sum: R,
    carry: R,
}

impl<R: Real> Compensated<R> {
    pub fn new(sum: R) -> Self {
        Self {
            sum,
            carry: R::ZERO,
        }
    }
    #[inline]
    pub fn add(&mut self, increment: R) {
        let y = increment - self.carry;
        let t = self.sum + y;
        self.carry = (t - self.sum) - y;
        self.sum = t;
    }
}
