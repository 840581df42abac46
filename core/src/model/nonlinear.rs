//! Nonlinear force `F = k x^n (1 + c v)` (seed 001, Eq. 7 with `n = 1`; `n = 3/2` is the
//! Hertz-based Hunt–Crossley law).

use super::closed_form as exact;
use super::{ContactLaw, Phase};
use super::{Impact, ImpactOutcome};
use crate::error::Error;
use crate::error::{non_negative, positive};
use crate::real::Real;

/// `k` in N/m^n, `c` in s/m, exponent `n >= 1`. Starting from `x = 0, v0 > 0` the factor
/// `1 + c v` stays positive, so the force vanishes only at `x = 0`: no permanent set.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Nonlinear<R> {
    pub k: R,
    pub c: R,
    pub n: R,
}

impl<R: Real> ContactLaw<R> for Nonlinear<R> {
    #[inline]
    fn raw_force(&self, x: R, v: R, _phase: Phase<R>) -> R {
        let spring = if self.n == R::ONE {
            self.k * x
        } else {
            self.k * x.signed_pow(self.n)
        };
        spring * (R::ONE + self.c * v)
    }
    fn admissible(&self, _x: R, v: R) -> bool {
        R::ONE + self.c * v > R::ZERO
    }
    fn velocity_dependent(&self) -> bool {
        self.c != R::ZERO
    }
    fn validate(&self) -> Result<(), Error> {
        positive(self.k, "stiffness")?;
        non_negative(self.c, "damping")?;
        if !(self.n.is_finite() && self.n >= R::ONE && self.n <= R::from_f64(4.0)) {
            return Err(Error::InvalidParameter {
                name: "exponent",
                reason: "must lie in [1, 4]",
            });
        }
        Ok(())
    }
    fn time_scale(&self, impact: &Impact<R>) -> R {
        exact::undamped_power_law_contact_time(self.k, self.n, impact)
    }
    fn max_rate(&self, impact: &Impact<R>) -> R {
        // Over the contact x <= the undamped x_m and 0 <= 1 + c v <= 1 + c v0.
        let m = impact.mass_kg;
        let x_m = exact::undamped_power_law_max(self.k, self.n, impact);
        let spring = self.k * x_m.powf(self.n - R::ONE);
        let factor = R::ONE + self.c * impact.v0_m_s;
        (self.n * spring * factor / m)
            .sqrt()
            .max(spring * x_m * self.c / m)
    }
    fn name(&self) -> &'static str {
        "nonlinear"
    }
    fn exact(&self, impact: &Impact<R>) -> Result<ImpactOutcome<R>, Error> {
        exact::nonlinear(self, impact)
    }
}
