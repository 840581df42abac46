//! Hertz contact of two elastic spheres, `F = K x^(3/2)` (seed 000, Eq. 44–46).

use super::closed_form as exact;
use super::{ContactLaw, Phase};
use super::{Impact, ImpactOutcome};
use crate::error::positive;
use crate::error::Error;
use crate::real::Real;

/// One elastic body at the contact. An infinite radius is a flat wall; an infinite Young's
/// modulus is a rigid body.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Body<R> {
    /// Radius of curvature at the contact, m (`R::MAX` or infinity: flat).
    pub radius_m: R,
    /// Young's modulus, Pa (`R::MAX` or infinity: rigid).
    pub youngs_pa: R,
    /// Poisson's ratio, in (-1, 0.5].
    pub poisson: R,
}

impl<R: Real> Body<R> {
    /// A rigid flat wall.
    pub fn rigid_wall() -> Self {
        Self {
            radius_m: R::from_f64(f64::INFINITY),
            youngs_pa: R::from_f64(f64::INFINITY),
            poisson: R::ZERO,
        }
    }
}

/// Hertz contact law `F = K x^(3/2)`, `K` in N/m^1.5.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hertz<R> {
    pub k: R,
}

impl<R: Real> Hertz<R> {
    /// `K = 4/3 sqrt(R1 R2 / (R1 + R2)) E*`, `1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2`.
    ///
    /// Errors name the offending parameter with the `impact` tool's spelling (`radius`,
    /// `youngs2`, ...).
    pub fn from_bodies(b1: &Body<R>, b2: &Body<R>) -> Result<Self, Error> {
        let names = [
            ("radius", "youngs", "poisson"),
            ("radius2", "youngs2", "poisson2"),
        ];
        let mut inv_radius = R::ZERO;
        let mut inv_modulus = R::ZERO;
        for (b, (rn, en, pn)) in [b1, b2].into_iter().zip(names) {
            if b.radius_m.is_nan() || b.radius_m <= R::ZERO {
                return Err(Error::InvalidParameter {
                    name: rn,
                    reason: "must be > 0 (infinite: flat)",
                });
            }
            if b.youngs_pa.is_nan() || b.youngs_pa <= R::ZERO {
                return Err(Error::InvalidParameter {
                    name: en,
                    reason: "must be > 0 (infinite: rigid)",
                });
            }
            if !b.poisson.is_finite() || b.poisson <= -R::ONE || b.poisson > R::HALF {
                return Err(Error::InvalidParameter {
                    name: pn,
                    reason: "must lie in (-1, 0.5]",
                });
            }
            if b.radius_m.is_finite() {
                inv_radius += R::ONE / b.radius_m;
            }
            if b.youngs_pa.is_finite() {
                inv_modulus += (R::ONE - b.poisson * b.poisson) / b.youngs_pa;
            }
        }
        if inv_radius <= R::ZERO {
            return Err(Error::InvalidParameter {
                name: "radius",
                reason: "two flat bodies have no Hertz contact",
            });
        }
        if inv_modulus <= R::ZERO {
            return Err(Error::InvalidParameter {
                name: "youngs",
                reason: "two rigid bodies have no Hertz contact",
            });
        }
        let k = R::from_f64(4.0 / 3.0) * (R::ONE / inv_radius).sqrt() / inv_modulus;
        Ok(Self { k })
    }

    /// Elastic energy stored at deformation `x`, J: `U = 2/5 K x^(5/2)`.
    pub fn energy(&self, x: R) -> R {
        R::from_f64(0.4) * self.k * x.max(R::ZERO).powf(R::from_f64(2.5))
    }

    /// The same law as a [`super::Nonlinear`] force with `n = 3/2` and no damping.
    pub fn as_power_law(&self) -> super::Nonlinear<R> {
        super::Nonlinear {
            k: self.k,
            c: R::ZERO,
            n: R::from_f64(1.5),
        }
    }
}

impl<R: Real> ContactLaw<R> for Hertz<R> {
    #[inline]
    fn raw_force(&self, x: R, _v: R, _phase: Phase<R>) -> R {
        self.k * x * x.abs().sqrt()
    }
    fn velocity_dependent(&self) -> bool {
        false
    }
    fn validate(&self) -> Result<(), Error> {
        positive(self.k, "stiffness")
    }
    fn time_scale(&self, impact: &Impact<R>) -> R {
        self.as_power_law().time_scale(impact)
    }
    fn max_rate(&self, impact: &Impact<R>) -> R {
        self.as_power_law().max_rate(impact)
    }
    fn name(&self) -> &'static str {
        "hertz"
    }
    fn exact(&self, impact: &Impact<R>) -> Result<ImpactOutcome<R>, Error> {
        exact::elastic_power_law(self.k, R::from_f64(1.5), impact)
    }
}
