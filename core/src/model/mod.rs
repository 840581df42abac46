//! Contact laws: the force a barrier exerts on the impacting body as a function of deformation.
//!
//! Conventions (shared with the whole crate): `x` is the deformation (overlap) in m, positive in
//! compression; `v = dx/dt` in m/s, positive while the body moves into the barrier. An impact
//! starts at `x = 0, v = v0 > 0`. A barrier cannot pull: the physical force is
//! `max(0, raw_force)`, and separation is the first instant after the maximum deformation at
//! which the force returns to zero. Solvers integrate the smooth `raw_force` and stop at
//! separation, so the clamp never acts inside a contact.

pub mod closed_form;
mod hertz;
mod impact;
mod kelvin_voigt;
mod linear;
mod nonlinear;
mod two_phase;

pub use hertz::{Body, Hertz};
pub use impact::{Impact, ImpactOutcome};
pub use kelvin_voigt::KelvinVoigt;
pub use linear::Linear;
pub use nonlinear::Nonlinear;
pub use two_phase::TwoPhase;

use crate::error::Error;
use crate::real::Real;

/// Which side of the maximum deformation the contact is on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Phase<R> {
    /// From first touch to the maximum deformation (`v >= 0`).
    Compression,
    /// After the maximum deformation `x_max` (m) was reached.
    Restitution { x_max: R },
}

/// A force affine in deformation and rate: `F = k x + c v + f0` (N/m, N s/m, N).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Affine<R> {
    pub k: R,
    pub c: R,
    pub f0: R,
}

/// A force law between an impacting body and a barrier.
pub trait ContactLaw<R: Real> {
    /// Contact force in N at deformation `x` (m) and rate `v` (m/s), extended smoothly past
    /// separation (it may be negative there; the physical force is `max(0, raw)`).
    fn raw_force(&self, x: R, v: R, phase: Phase<R>) -> R;

    /// Physical contact force in N: never negative (a barrier cannot pull).
    #[inline]
    fn force(&self, x: R, v: R, phase: Phase<R>) -> R {
        self.raw_force(x, v, phase).max(R::ZERO)
    }

    /// True if the law changes at the maximum deformation (two-phase models): solvers then
    /// restart the integration exactly there.
    fn switches_at_max(&self) -> bool {
        false
    }

    /// False for states the exact motion can never reach (the nonlinear law's `1 + c v <= 0`):
    /// a time-stepper that lands there has not resolved the contact.
    fn admissible(&self, _x: R, _v: R) -> bool {
        true
    }

    /// False if the force depends on `x` alone (integrators can then skip work).
    fn velocity_dependent(&self) -> bool {
        true
    }

    /// The force as `k x + c v + f0` within `phase`, for laws that are affine there (linear,
    /// Kelvin–Voigt, two-phase): linear targets then have a closed-form solution.
    fn affine(&self, _phase: Phase<R>) -> Option<Affine<R>> {
        None
    }

    /// Checks the parameters; names the offending one.
    fn validate(&self) -> Result<(), Error>;

    /// A duration in s over which the contact happens (the undamped contact time, shortened by
    /// strong damping): fixed-step solvers size their step from it.
    fn time_scale(&self, impact: &Impact<R>) -> R;

    /// An upper bound on the fastest rate of the linearised contact, 1/s: the larger of the
    /// stiffness frequency `sqrt(dF/dx / m)` and the damping rate `(dF/dv) / m` over the
    /// contact. A fixed step `h` resolves the contact only if `h * max_rate` is small.
    fn max_rate(&self, impact: &Impact<R>) -> R;

    /// Short name used in reports (`"hertz"`, `"two-phase"`, ...).
    fn name(&self) -> &'static str;

    /// The exact or semi-analytic outcome of one impact (closed forms, energy relation plus
    /// quadrature).
    fn exact(&self, impact: &Impact<R>) -> Result<ImpactOutcome<R>, Error>;
}

/// Any of the contact laws, chosen at run time (host tools, scene files). Firmware that knows
/// its law at compile time uses the concrete type instead, so the others are not linked in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Model<R> {
    Hertz(Hertz<R>),
    Linear(Linear<R>),
    KelvinVoigt(KelvinVoigt<R>),
    TwoPhase(TwoPhase<R>),
    Nonlinear(Nonlinear<R>),
}

macro_rules! each_model {
    ($self:ident, $m:ident => $e:expr) => {
        match $self {
            Model::Hertz($m) => $e,
            Model::Linear($m) => $e,
            Model::KelvinVoigt($m) => $e,
            Model::TwoPhase($m) => $e,
            Model::Nonlinear($m) => $e,
        }
    };
}

impl<R: Real> ContactLaw<R> for Model<R> {
    #[inline]
    fn raw_force(&self, x: R, v: R, phase: Phase<R>) -> R {
        each_model!(self, m => m.raw_force(x, v, phase))
    }
    fn switches_at_max(&self) -> bool {
        each_model!(self, m => m.switches_at_max())
    }
    fn velocity_dependent(&self) -> bool {
        each_model!(self, m => m.velocity_dependent())
    }
    fn admissible(&self, x: R, v: R) -> bool {
        each_model!(self, m => m.admissible(x, v))
    }
    fn affine(&self, phase: Phase<R>) -> Option<Affine<R>> {
        each_model!(self, m => m.affine(phase))
    }
    fn validate(&self) -> Result<(), Error> {
        each_model!(self, m => m.validate())
    }
    fn time_scale(&self, impact: &Impact<R>) -> R {
        each_model!(self, m => m.time_scale(impact))
    }
    fn max_rate(&self, impact: &Impact<R>) -> R {
        each_model!(self, m => m.max_rate(impact))
    }
    fn name(&self) -> &'static str {
        each_model!(self, m => m.name())
    }
    fn exact(&self, impact: &Impact<R>) -> Result<ImpactOutcome<R>, Error> {
        each_model!(self, m => m.exact(impact))
    }
}
