//! Linear Kelvin–Voigt spring-damper `F = k x + c v` (seed 001, Eq. 2).

use super::closed_form as exact;
use super::{Affine, ContactLaw, Phase};
use super::{Impact, ImpactOutcome};
use crate::error::Error;
use crate::error::{non_negative, positive};
use crate::real::Real;

/// Spring `k` (N/m) in parallel with a damper `c` (N s/m). Separation is where the force (not
/// the deformation) returns to zero, so a deformation is left at separation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KelvinVoigt<R> {
    pub k: R,
    pub c: R,
}

impl<R: Real> ContactLaw<R> for KelvinVoigt<R> {
    #[inline]
    fn raw_force(&self, x: R, v: R, _phase: Phase<R>) -> R {
        self.k * x + self.c * v
    }
    fn velocity_dependent(&self) -> bool {
        self.c != R::ZERO
    }
    fn affine(&self, _phase: Phase<R>) -> Option<Affine<R>> {
        Some(Affine {
            k: self.k,
            c: self.c,
            f0: R::ZERO,
        })
    }
    fn validate(&self) -> Result<(), Error> {
        positive(self.k, "stiffness")?;
        non_negative(self.c, "damping")
    }
    fn time_scale(&self, impact: &Impact<R>) -> R {
        damped_time_scale(self.k, self.c, impact.mass_kg)
    }
    fn max_rate(&self, impact: &Impact<R>) -> R {
        let m = impact.mass_kg;
        (self.k / m).sqrt().max(self.c / m)
    }
    fn name(&self) -> &'static str {
        "kelvin-voigt"
    }
    fn exact(&self, impact: &Impact<R>) -> Result<ImpactOutcome<R>, Error> {
        exact::kelvin_voigt(self.k, self.c, impact)
    }
}

/// Half-period of the undamped oscillator, shortened to `2 m / c` under strong damping, s.
pub(crate) fn damped_time_scale<R: Real>(k: R, c: R, m: R) -> R {
    let elastic = R::PI * (m / k).sqrt();
    if c > R::ZERO {
        elastic.min(R::from_f64(4.0) * m / c)
    } else {
        elastic
    }
}
