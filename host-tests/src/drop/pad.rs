//! The pad a dropped body strikes: the contact law in absolute depth, the branch the law is on,
//! and what the pad keeps between contacts.
//!
//! Depth `z` is measured downwards from the pad's original (virgin) surface, m; the body's
//! velocity `v = dz/dt` is positive downwards. Every law but the two-phase one recovers its
//! shape between contacts (the elastic and viscous ones relax to the virgin surface, in
//! [`Pad::recovery_s`]), so each contact starts at `z = 0`. The two-phase pad keeps its set:
//! its surface stays at `x_p` after a contact, and the next contact reloads along the
//! restitution line `kr (z - x_p) + c v` until it passes the deepest point ever reached, where
//! it is on the virgin compression line `kc z` again (elastic–plastic reloading).

use impact_core::model::{ContactLaw, Model, Phase};

/// Which part of the law a contact is on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Branch {
    /// Moving in, on the virgin loading line (or the law's single curve).
    Loading,
    /// Moving in along the restitution line of an earlier contact whose deepest point was
    /// `deepest_m` (two-phase only); back on [`Branch::Loading`] past it.
    Reloading { deepest_m: f64 },
    /// After the maximum depth `deepest_m` of this contact (or of an earlier one, deeper).
    Unloading { deepest_m: f64 },
}

/// A pad under a body: its law, and the deepest point and set it keeps.
#[derive(Clone, Copy, Debug)]
pub struct Pad {
    law: Model<f64>,
    /// Deepest point ever reached, m (0 for a virgin pad).
    deepest_m: f64,
}

impl Pad {
    pub fn new(law: Model<f64>) -> Self {
        Self {
            law,
            deepest_m: 0.0,
        }
    }

    pub fn law(&self) -> &Model<f64> {
        &self.law
    }

    /// The depth of the pad's surface once it has recovered after a contact, m: the set of a
    /// two-phase pad, 0 for every other law.
    pub fn surface_m(&self) -> f64 {
        match self.law {
            Model::TwoPhase(p) if self.deepest_m > 0.0 => p.permanent_set(self.deepest_m),
            _ => 0.0,
        }
    }

    /// The branch a new contact starts on.
    pub fn first_branch(&self) -> Branch {
        match self.law {
            Model::TwoPhase(_) if self.deepest_m > 0.0 => Branch::Reloading {
                deepest_m: self.deepest_m,
            },
            _ => Branch::Loading,
        }
    }

    /// The contact force at depth `z` and velocity `v` on `branch`, N, extended smoothly past
    /// separation (negative there: the physical force is `max(0, raw)`).
    pub fn raw_force(&self, z: f64, v: f64, branch: Branch) -> f64 {
        let phase = match branch {
            Branch::Loading => Phase::Compression,
            Branch::Reloading { deepest_m } | Branch::Unloading { deepest_m } => {
                Phase::Restitution { x_max: deepest_m }
            }
        };
        self.law.raw_force(z, v, phase)
    }

    /// The branch after the maximum depth `z_max` of a contact on `branch`.
    pub fn after_max(&self, branch: Branch, z_max: f64) -> Branch {
        match branch {
            Branch::Loading => Branch::Unloading { deepest_m: z_max },
            Branch::Reloading { deepest_m } | Branch::Unloading { deepest_m } => {
                Branch::Unloading { deepest_m }
            }
        }
    }

    /// Records a contact whose maximum depth was `z_max`.
    pub fn remember(&mut self, z_max: f64) {
        self.deepest_m = self.deepest_m.max(z_max);
    }

    /// Time the pad takes, once the body has left at depth `z_sep`, to come within `1e-9` of
    /// the largest deformation `x_m` from its recovered surface, s: 0 for the elastic laws;
    /// the exponential relaxation `(c/k) ln(...)` of a Kelvin–Voigt element (of the
    /// restitution line for the two-phase law); `c (z_sep - 0)` for `k x (1 + c v)`, whose
    /// massless element relaxes at `1/c` m/s.
    pub fn recovery_s(&self, z_sep: f64, x_m: f64) -> f64 {
        let tol = 1e-9 * x_m.max(f64::MIN_POSITIVE);
        let exponential = |k: f64, c: f64, gap: f64| {
            if c == 0.0 || gap <= tol {
                0.0
            } else {
                c / k * (gap / tol).ln()
            }
        };
        match self.law {
            Model::KelvinVoigt(kv) => exponential(kv.k, kv.c, z_sep),
            Model::TwoPhase(p) => exponential(p.kr, p.c, (z_sep - self.surface_m()).abs()),
            Model::Nonlinear(n) => n.c * z_sep.max(0.0),
            Model::Linear(_) | Model::Hertz(_) => 0.0,
        }
    }
}
