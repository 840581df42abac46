//! Linear spring `F = k x`: the cheap stand-in for Hertz (seed 000, section 3.2.1).

use super::closed_form as exact;
use super::{Affine, ContactLaw, Hertz, Phase};
use super::{Impact, ImpactOutcome};
use crate::error::positive;
use crate::error::Error;
use crate::real::Real;

/// Linear contact spring, `k` in N/m.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Linear<R> {
    pub k: R,
}

impl<R: Real> Linear<R> {
    /// The spring that gives the same maximum deformation as `hertz` for this impact:
    /// `k = m v0^2 / x_m^2`.
    pub fn matching_max_deformation(hertz: &Hertz<R>, impact: &Impact<R>) -> Result<Self, Error> {
        let x_m = hertz.exact(impact)?.max_deformation_m;
        let k = impact.mass_kg * impact.v0_m_s * impact.v0_m_s / (x_m * x_m);
        let law = Self { k };
        law.validate()?;
        Ok(law)
    }

    /// Elastic energy stored at deformation `x`, J: `k x^2 / 2`.
    pub fn energy(&self, x: R) -> R {
        R::HALF * self.k * x * x
    }
}

impl<R: Real> ContactLaw<R> for Linear<R> {
    #[inline]
    fn raw_force(&self, x: R, _v: R, _phase: Phase<R>) -> R {
        self.k * x
    }
    fn velocity_dependent(&self) -> bool {
        false
    }
    fn affine(&self, _phase: Phase<R>) -> Option<Affine<R>> {
        Some(Affine {
            k: self.k,
            c: R::ZERO,
            f0: R::ZERO,
        })
    }
    fn validate(&self) -> Result<(), Error> {
        positive(self.k, "stiffness")
    }
    fn time_scale(&self, impact: &Impact<R>) -> R {
        R::PI * (impact.mass_kg / self.k).sqrt()
    }
    fn max_rate(&self, impact: &Impact<R>) -> R {
        (self.k / impact.mass_kg).sqrt()
    }
    fn name(&self) -> &'static str {
        "linear"
    }
    fn exact(&self, impact: &Impact<R>) -> Result<ImpactOutcome<R>, Error> {
        exact::linear_spring(self.k, impact)
    }
}
