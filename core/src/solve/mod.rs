//! One impact from first touch to separation: the report and the solvers that produce it.
//!
//! Every solver returns the same [`ImpactOutcome`]. `exact` uses closed forms and the energy
//! relation; `fixed` runs semi-implicit Euler, velocity Verlet or classic RK4 at a fixed step;
//! `adaptive` runs Dormand–Prince 5(4) with dense output. Events (maximum deformation, peak
//! force, separation) are located on each method's interpolant, never snapped to a step.

pub mod adaptive;
pub mod bounce;
pub(crate) mod events;
pub mod fixed;
pub mod trajectory;

pub use crate::error::Error;
use crate::model::ContactLaw;
pub use crate::model::{Impact, ImpactOutcome};
use crate::real::Real;

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
