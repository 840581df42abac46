//! Two-phase Kelvin–Voigt (seed 001, Eq. 5): undamped compression with `kc`, damped
//! restitution with `kr` and `c` around a permanent set `x_p`.

use super::closed_form as exact;
use super::kelvin_voigt::damped_time_scale;
use super::{Affine, ContactLaw, Phase};
use super::{Impact, ImpactOutcome};
use crate::error::Error;
use crate::error::{non_negative, positive};
use crate::real::Real;

/// `F = kc x` while compressing; `F = kr (x - x_p) + c v` after the maximum deformation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TwoPhase<R> {
    /// Compression stiffness, N/m.
    pub kc: R,
    /// Restitution stiffness, N/m.
    pub kr: R,
    /// Restitution damping, N s/m.
    pub c: R,
    /// Permanent set, m. `None`: from force continuity at `x_m`, `x_p = x_m (1 - kc/kr)`.
    pub permanent_m: Option<R>,
}

impl<R: Real> TwoPhase<R> {
    /// The permanent set the restitution phase oscillates around, given the maximum
    /// deformation `x_max` (m).
    #[inline]
    pub fn permanent_set(&self, x_max: R) -> R {
        match self.permanent_m {
            Some(x_p) => x_p,
            None => x_max * (R::ONE - self.kc / self.kr),
        }
    }

    /// The seed-001 bench model from measured `x_m` and `v0`: `kc = m (v0 / x_m)^2`.
    pub fn compression_stiffness_for(impact: &Impact<R>, x_max: R) -> R {
        let r = impact.v0_m_s / x_max;
        impact.mass_kg * r * r
    }
}

impl<R: Real> ContactLaw<R> for TwoPhase<R> {
    #[inline]
    fn raw_force(&self, x: R, v: R, phase: Phase<R>) -> R {
        match phase {
            Phase::Compression => self.kc * x,
            Phase::Restitution { x_max } => self.kr * (x - self.permanent_set(x_max)) + self.c * v,
        }
    }
    fn switches_at_max(&self) -> bool {
        true
    }
    fn affine(&self, phase: Phase<R>) -> Option<Affine<R>> {
        Some(match phase {
            Phase::Compression => Affine {
                k: self.kc,
                c: R::ZERO,
                f0: R::ZERO,
            },
            Phase::Restitution { x_max } => Affine {
                k: self.kr,
                c: self.c,
                f0: -self.kr * self.permanent_set(x_max),
            },
        })
    }
    fn velocity_dependent(&self) -> bool {
        self.c != R::ZERO
    }
    fn validate(&self) -> Result<(), Error> {
        positive(self.kc, "kc")?;
        positive(self.kr, "kr")?;
        non_negative(self.c, "damping")?;
        match self.permanent_m {
            Some(x_p) => non_negative(x_p, "permanent"),
            None if self.kr < self.kc => Err(Error::InvalidParameter {
                name: "kr",
                reason: "must be >= kc when the permanent set comes from force continuity",
            }),
            None => Ok(()),
        }
    }
    fn time_scale(&self, impact: &Impact<R>) -> R {
        let m = impact.mass_kg;
        R::HALF * (R::PI * (m / self.kc).sqrt() + damped_time_scale(self.kr, self.c, m))
    }
    fn max_rate(&self, impact: &Impact<R>) -> R {
        let m = impact.mass_kg;
        (self.kc.max(self.kr) / m).sqrt().max(self.c / m)
    }
    fn name(&self) -> &'static str {
        "two-phase"
    }
    fn exact(&self, impact: &Impact<R>) -> Result<ImpactOutcome<R>, Error> {
        exact::two_phase(self, impact)
    }
}
