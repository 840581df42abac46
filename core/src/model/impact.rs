//! One impact's problem (the body's approach) and its answer (what the contact did), the
//! same for every law and every solver.

use crate::error::{positive, Error};
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
