//! One impact from first touch to separation: the report and the solvers that produce it.
//!
//! Every solver returns the same [`ImpactOutcome`]. `exact` uses closed forms and the energy
//! relation; `fixed` runs semi-implicit Euler, velocity Verlet or classic RK4 at a fixed step;
//! `adaptive` runs Dormand–Prince 5(4) with dense output. Events (maximum deformation, peak
//! force, separation) are located on each method's interpolant, never snapped to a step.

pub mod adaptive;
pub mod bounce;
pub(crate) mod events;
pub mod exact;
pub mod fixed;
pub mod quad;
pub mod roots;
pub mod trajectory;

use crate::model::{positive, ContactLaw};
use crate::real::Real;

/// The approach of a body to a barrier.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Impact<R> {
    /// Mass of the impacting body, kg.
    pub mass_kg: R,
    /// Approach speed at first touch, m/s (> 0).
    pub v0_m_s: R,
}

impl<R: Real> Impact<R> {
    pub fn new(mass_kg: R, v0_m_s: R) -> Self {
        Self { mass_kg, v0_m_s }
    }

    /// Checks mass and speed.
    pub fn validate(&self) -> Result<(), Error> {
        positive(self.mass_kg, "mass")?;
        positive(self.v0_m_s, "v0")
    }
}

/// What one impact did. All fields SI.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ImpactOutcome<R> {
    /// Largest deformation `x_m`, m.
    pub max_deformation_m: R,
    /// Time from first touch to `x_m` (crush time `t_m`), s.
    pub crush_time_s: R,
    /// Time from first touch to separation `t_c`, s.
    pub contact_time_s: R,
    /// Speed at separation `v'` (positive), m/s.
    pub rebound_velocity_m_s: R,
    /// Coefficient of restitution `v'/v0`.
    pub cor: R,
    /// Largest contact force, N.
    pub peak_force_n: R,
    /// Deformation left at separation `x_p`, m.
    pub permanent_deformation_m: R,
    /// Right-hand-side (force law) evaluations the solver spent: its cost in work units.
    pub rhs_evaluations: u32,
}

/// Why an impact could not be solved.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Error {
    /// A parameter is outside its domain. `name` is the parameter as the `impact` tool spells
    /// it (`"mass"`, `"v0"`, `"kc"`, ...).
    InvalidParameter {
        name: &'static str,
        reason: &'static str,
    },
    /// The solver could not resolve the contact within its budget (too few steps for the
    /// stiffness or damping, step size underflow, non-finite state). No result is better than a
    /// wrong one.
    Unresolved(&'static str),
}

impl core::fmt::Display for Error {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Error::InvalidParameter { name, reason } => write!(f, "--{name}: {reason}"),
            Error::Unresolved(why) => write!(f, "contact not resolved: {why}"),
        }
    }
}

/// The solvers the crate offers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// Closed forms / energy relation and quadrature.
    Exact,
    /// Semi-implicit (symplectic) Euler, first order.
    Euler,
    /// Velocity Verlet, second order.
    Verlet,
    /// Classic fourth-order Runge–Kutta.
    Rk4,
    /// Dormand–Prince 5(4), adaptive, with dense output.
    Adaptive,
}

impl Method {
    pub fn name(self) -> &'static str {
        match self {
            Method::Exact => "exact",
            Method::Euler => "euler",
            Method::Verlet => "verlet",
            Method::Rk4 => "rk4",
            Method::Adaptive => "adaptive",
        }
    }
}

/// How to solve: the method plus its accuracy knob.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings<R> {
    pub method: Method,
    /// Fixed-step methods: steps per [`ContactLaw::time_scale`].
    pub steps: u32,
    /// Adaptive method: relative tolerance (absolute tolerance is scaled from it).
    pub rtol: R,
}

impl<R: Real> Settings<R> {
    pub fn exact() -> Self {
        Self {
            method: Method::Exact,
            steps: 0,
            rtol: R::ZERO,
        }
    }
    pub fn fixed(method: Method, steps: u32) -> Self {
        Self {
            method,
            steps,
            rtol: R::ZERO,
        }
    }
    pub fn adaptive(rtol: R) -> Self {
        Self {
            method: Method::Adaptive,
            steps: 0,
            rtol,
        }
    }
}

/// Solves one impact of `law` with the chosen settings.
pub fn solve<R: Real, L: ContactLaw<R>>(
    law: &L,
    impact: &Impact<R>,
    settings: &Settings<R>,
) -> Result<ImpactOutcome<R>, Error> {
    impact.validate()?;
    law.validate()?;
    match settings.method {
        Method::Exact => law.exact(impact),
        Method::Euler | Method::Verlet | Method::Rk4 => {
            fixed::solve(law, impact, settings.method, settings.steps)
        }
        Method::Adaptive => adaptive::solve(law, impact, settings.rtol),
    }
}
