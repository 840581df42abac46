//! The impactor on a target with its own dynamics (seed 000, section 3.2): a point mass with
//! any contact law of the crate, pressed into a linear target.
//!
//! Assumptions (the seed's): the contact spring is undeformed at first touch and the target at
//! rest in equilibrium; the contact only pushes, so the two interact while the law's force is
//! positive and the impactor is removed from the system at separation; the target keeps
//! ringing afterwards. Whether the coasting impactor and the ringing target meet again (the
//! seed assumes a single hit) is checked by [`free::after`].
//!
//! Conventions: the impactor's position `x1` and the contact point's displacement `y` are
//! positive in the impact direction, from their positions at first touch; the deformation is
//! `δ = x1 - y` and its rate `δ' = u1 - w`. The contact force `F = law(δ, δ')` pushes the
//! impactor back (`m1 u1' = -F`) and the target on (`z' = A z + B F`, `y = Cx z`,
//! `w = Cv z`).

// Matrix and state-vector code reads best with the indices of the formulas.
#![allow(clippy::needless_range_loop)]

mod coupled;
mod exact;
pub mod free;
pub mod matrix;
pub mod step;

pub use coupled::Sample;

use crate::error::positive;
use crate::error::Error;
use crate::model::ContactLaw;
use crate::model::Impact;
use crate::real::Real;
use crate::solve::{Method, Settings};
use matrix::{dot, Mat, Vector, DIM};

/// Most states a target may have.
pub const MAX_STATES: usize = 6;

/// A point mass on a spring and damper to ground: the contact point is the mass.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpringMass<R> {
    /// Target mass `m2`, kg (> 0).
    pub mass_kg: R,
    /// Spring to ground `k2`, N/m (>= 0; 0 is a free body).
    pub stiffness_n_m: R,
    /// Damper to ground `c2`, N s/m (>= 0).
    pub damping_n_s_m: R,
}

/// A linear target in state-space form: `z' = A z + B F`, contact point displacement
/// `y = Cx z` (m) and velocity `w = Cv z` (m/s), at rest (`z = 0`) at first touch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Target<R> {
    /// Number of states, 1..=[`MAX_STATES`].
    pub n: usize,
    pub a: [[R; MAX_STATES]; MAX_STATES],
    pub b: [R; MAX_STATES],
    /// Rows: displacement `Cx`, velocity `Cv`.
    pub c: [[R; MAX_STATES]; 2],
    /// Set when the target was built from a spring–mass (its energy and dissipation are then
    /// defined; a general state space has no mass matrix to define them).
    pub spring_mass: Option<SpringMass<R>>,
}

/// The target a scene's analysis pushes ([`crate::scene::Scene::target`]): a spring–mass by
/// value, or a state space by reference (its 240 bytes on the board kept once, in a `static`,
/// not in every copy of the scene).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SceneTarget {
    SpringMass(SpringMass<f32>),
    StateSpace(&'static Target<f32>),
}

impl SceneTarget {
    /// The spring–mass, if the target is one.
    pub fn spring_mass(&self) -> Option<SpringMass<f32>> {
        match self {
            Self::SpringMass(s) => Some(*s),
            Self::StateSpace(_) => None,
        }
    }

    /// The state space, if the target is one.
    pub fn state_space(&self) -> Option<&'static Target<f32>> {
        match self {
            Self::SpringMass(_) => None,
            Self::StateSpace(t) => Some(t),
        }
    }
}

fn invalid(name: &'static str, reason: &'static str) -> Error {
    Error::InvalidParameter { name, reason }
}

impl<R: Real> Target<R> {
    /// `m2 y'' = F - k2 y - c2 y'`: states `(y, w)`.
    pub fn spring_mass(mass_kg: R, stiffness_n_m: R, damping_n_s_m: R) -> Result<Self, Error> {
        positive(mass_kg, "target-mass")?;
        if !(stiffness_n_m.is_finite() && stiffness_n_m >= R::ZERO) {
            return Err(invalid("target-stiffness", "must be finite and >= 0"));
        }
        if !(damping_n_s_m.is_finite() && damping_n_s_m >= R::ZERO) {
            return Err(invalid("target-damping", "must be finite and >= 0"));
        }
        let t = Self::of_spring_mass(SpringMass {
            mass_kg,
            stiffness_n_m,
            damping_n_s_m,
        });
        t.validate()?;
        Ok(t)
    }

    /// The matrices of the spring–mass `s`, unchecked (a scene's target as its keys set it:
    /// [`crate::scene::Scene::validate`] checks its parameters, and the analysis steps it by
    /// them, [`step::Stepper`]).
    pub fn of_spring_mass(s: SpringMass<R>) -> Self {
        let mut t = Self {
            n: 2,
            a: [[R::ZERO; MAX_STATES]; MAX_STATES],
            b: [R::ZERO; MAX_STATES],
            c: [[R::ZERO; MAX_STATES]; 2],
            spring_mass: Some(s),
        };
        t.a[0][1] = R::ONE;
        t.a[1][0] = -s.stiffness_n_m / s.mass_kg;
        t.a[1][1] = -s.damping_n_s_m / s.mass_kg;
        t.b[1] = R::ONE / s.mass_kg;
        t.c[0][0] = R::ONE;
        t.c[1][1] = R::ONE;
        t
    }

    /// A general linear target; `d` is the direct feed-through of the force to the
    /// displacement and velocity outputs and must be zero (a contact point that moves with the
    /// force itself would make the contact an algebraic loop).
    pub fn state_space(
        n: usize,
        a: [[R; MAX_STATES]; MAX_STATES],
        b: [R; MAX_STATES],
        c: [[R; MAX_STATES]; 2],
        d: [R; 2],
    ) -> Result<Self, Error> {
        if n == 0 || n > MAX_STATES {
            return Err(invalid("target", "must have 1 to 6 states"));
        }
        if d.iter().any(|x| *x != R::ZERO) {
            return Err(invalid(
                "target",
                "D must be zero: a contact point that moves with the force itself is an algebraic loop",
            ));
        }
        let t = Self {
            n,
            a,
            b,
            c,
            spring_mass: None,
        };
        t.validate()?;
        Ok(t)
    }

    /// `n` states (at most [`MAX_STATES`]), every entry zero, not a spring–mass: to be filled
    /// through [`Target::entries_mut`] (and checked by [`Target::validate`]).
    pub fn unset(n: usize) -> Self {
        Self {
            n: n.min(MAX_STATES),
            a: [[R::ZERO; MAX_STATES]; MAX_STATES],
            b: [R::ZERO; MAX_STATES],
            c: [[R::ZERO; MAX_STATES]; 2],
            spring_mass: None,
        }
    }

    /// The entries in the order of the board's `target_space` list (its scene key and its
    /// scene line): `A` row by row, `B`, `C` (the displacement's row, then the velocity's);
    /// `n² + 3n` of them.
    pub fn entries(&self) -> impl Iterator<Item = &R> {
        let n = self.n.min(MAX_STATES);
        (self.a.iter().take(n).flat_map(move |r| r.iter().take(n)))
            .chain(self.b.iter().take(n))
            .chain(self.c.iter().flat_map(move |r| r.iter().take(n)))
    }

    /// [`Target::entries`], to write.
    pub fn entries_mut(&mut self) -> impl Iterator<Item = &mut R> {
        let n = self.n.min(MAX_STATES);
        (self
            .a
            .iter_mut()
            .take(n)
            .flat_map(move |r| r.iter_mut().take(n)))
        .chain(self.b.iter_mut().take(n))
        .chain(self.c.iter_mut().flat_map(move |r| r.iter_mut().take(n)))
    }

    /// The target's own matrix `A` as a [`Mat`].
    /// (Every method reads at most [`MAX_STATES`] states, whatever `n` holds: none can fail
    /// on an index, as the board's build requires.)
    pub fn a_mat(&self) -> Mat<R> {
        let n = self.n.min(MAX_STATES);
        let mut m = Mat::zero(n);
        for (out, row) in m.a.iter_mut().zip(&self.a).take(n) {
            for (o, a) in out.iter_mut().zip(row).take(n) {
                *o = *a;
            }
        }
        m
    }

    fn row(&self, r: usize) -> Vector<R> {
        let mut v = [R::ZERO; DIM];
        if let Some(c) = self.c.get(r) {
            for (o, c) in v.iter_mut().zip(c).take(self.n) {
                *o = *c;
            }
        }
        v
    }

    fn b_vec(&self) -> Vector<R> {
        let mut v = [R::ZERO; DIM];
        for (o, b) in v.iter_mut().zip(&self.b).take(self.n) {
            *o = *b;
        }
        v
    }

    /// Contact point displacement (m) and velocity (m/s) of state `z`.
    pub fn outputs(&self, z: &[R; MAX_STATES]) -> (R, R) {
        let mut y = R::ZERO;
        let mut w = R::ZERO;
        for ((cx, cv), z) in self.c[0].iter().zip(&self.c[1]).zip(z).take(self.n) {
            y += *cx * *z;
            w += *cv * *z;
        }
        (y, w)
    }

    /// `1 / (Cv B)`: the mass the contact point shows to an impulse, kg.
    pub fn contact_mass_kg(&self) -> R {
        R::ONE / dot(&self.row(1), &self.b_vec(), self.n)
    }

    /// Checks that the target can be pushed: finite entries, velocity the derivative of the
    /// displacement (`Cv = Cx A`, `Cx B = 0`), a positive mass at the contact point
    /// (`Cv B > 0`), and no state growing exponentially on its own.
    pub fn validate(&self) -> Result<(), Error> {
        let n = self.n;
        if n == 0 || n > MAX_STATES {
            return Err(invalid("target", "must have 1 to 6 states"));
        }
        let finite = (0..n).all(|i| {
            self.b[i].is_finite()
                && self.c[0][i].is_finite()
                && self.c[1][i].is_finite()
                && (0..n).all(|j| self.a[i][j].is_finite())
        });
        if !finite {
            return Err(invalid("target", "every entry of A, B, C must be finite"));
        }
        let a = self.a_mat();
        let cx = self.row(0);
        let cv = self.row(1);
        let b = self.b_vec();
        // Cx A, compared with Cv relative to the size of the terms.
        let tol = R::from_f64(1e3) * R::EPSILON;
        for j in 0..n {
            let mut s = R::ZERO;
            let mut size = cv[j].abs();
            for i in 0..n {
                s += cx[i] * a.a[i][j];
                size += (cx[i] * a.a[i][j]).abs();
            }
            if !((s - cv[j]).abs() <= tol * size) {
                return Err(invalid(
                    "target",
                    "the velocity output must be the derivative of the displacement output (Cv = Cx A)",
                ));
            }
        }
        let cxb = dot(&cx, &b, n);
        let mut size = R::ZERO;
        for i in 0..n {
            size += (cx[i] * b[i]).abs();
        }
        if !(cxb.abs() <= tol * size) {
            return Err(invalid(
                "target",
                "the displacement must not jump under a force (Cx B = 0)",
            ));
        }
        let inv_m = dot(&cv, &b, n);
        if !(inv_m > R::ZERO && (R::ONE / inv_m).is_finite()) {
            return Err(invalid(
                "target",
                "the contact point must have a positive finite mass (Cv B > 0)",
            ));
        }
        // In f64 whatever `R`: 48 squarings in f32 round an undamped mode's unit modulus up
        // and would call it growing.
        let mut a64 = Mat::<f64>::zero(n);
        for i in 0..n {
            for j in 0..n {
                a64.a[i][j] = a.a[i][j].to_f64();
            }
        }
        if grows(&a64, n) {
            return Err(invalid(
                "target",
                "A is unstable: a state grows exponentially without any force",
            ));
        }
        Ok(())
    }

    /// The undamped natural frequency (rad/s) that bounds how fast the target moves by
    /// itself: `|A|`.
    fn rate(&self) -> R {
        self.a_mat().norm_inf()
    }

    /// True for a spring–mass with neither spring nor damper: the two-body problem.
    pub fn is_free_body(&self) -> bool {
        self.spring_mass
            .is_some_and(|s| s.stiffness_n_m == R::ZERO && s.damping_n_s_m == R::ZERO)
    }
}

/// True if `exp(A t)` outgrows every polynomial of the target's order `n` as `t` doubles up
/// to `2^48 / |A|` (marginal modes, a free body's drift, grow at most like `t^(n-1)`).
fn grows(a: &Mat<f64>, n: usize) -> bool {
    let norm = a.norm_inf();
    if norm == 0.0 {
        return false;
    }
    let mut t = 1.0 / norm;
    let Some(mut phi) = a.exp(t) else {
        return true;
    };
    for _ in 0..48 {
        phi = phi.mul(&phi);
        t *= 2.0;
        let tn = t * norm;
        let mut bound = 1e3;
        for _ in 0..n {
            bound *= 1.0 + tn;
        }
        let size = phi.norm_inf();
        if !size.is_finite() || size > bound {
            return true;
        }
    }
    false
}

/// What one contact with a target did. All fields SI; times from first touch.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TargetOutcome<R> {
    /// Largest deformation `δ = x1 - y`, m.
    pub max_deformation_m: R,
    /// Time of the largest deformation, s.
    pub crush_time_s: R,
    /// Time from first touch to separation, s.
    pub contact_time_s: R,
    /// Largest contact force, N.
    pub peak_force_n: R,
    /// Deformation left at separation, m.
    pub permanent_deformation_m: R,
    /// The impactor's speed away from the target at separation, m/s (negative if it still
    /// moves on into the target's direction).
    pub rebound_velocity_m_s: R,
    /// The impactor's displacement at separation, m (impact direction positive).
    pub impactor_displacement_m: R,
    /// The contact point's displacement and velocity at separation (impact direction).
    pub target_displacement_m: R,
    pub target_velocity_m_s: R,
    /// Relative separation speed over approach speed, `(w - u1) / v0`.
    pub cor: R,
    /// The target's state at separation (for its free response).
    pub target_state: [R; MAX_STATES],
    /// The target's kinetic plus spring energy at separation, J (spring–mass targets).
    pub target_energy_j: Option<R>,
    /// Work the contact force did on the target, `∫ F w dt`, J.
    pub target_work_j: Option<R>,
    /// Work the impactor lost into the contact law, `∫ F δ' dt`, J (dissipated plus left
    /// stored at separation).
    pub contact_work_j: Option<R>,
    /// Energy the target's damper took, `∫ c2 w² dt`, J (spring–mass targets).
    pub target_dissipated_j: Option<R>,
    /// Right-hand-side (force law) evaluations or matrix exponentials spent.
    pub rhs_evaluations: u32,
}

/// Solves one contact of `law` on `target`: the reduced-mass problem for a free body (any
/// law, with the law's own exact solution), the matrix exponential for affine laws (linear,
/// Kelvin–Voigt, two-phase) on any linear target, Dormand–Prince 5(4) with events on its
/// dense output otherwise. Fixed-step methods are not offered for targets.
pub fn solve<R: Real, L: ContactLaw<R>>(
    law: &L,
    impact: &Impact<R>,
    target: &Target<R>,
    settings: &Settings<R>,
) -> Result<TargetOutcome<R>, Error> {
    impact.validate()?;
    law.validate()?;
    target.validate()?;
    match settings.method {
        Method::Exact if target.is_free_body() => exact::free_body(law, impact, target),
        Method::Exact if law.affine(crate::model::Phase::Compression).is_some() => {
            exact::affine(law, impact, target)
        }
        Method::Exact => Err(invalid(
            "solver",
            "no closed form for this law on a target with its own dynamics: use adaptive",
        )),
        Method::Adaptive => coupled::solve(law, impact, target, settings.rtol),
        Method::Euler | Method::Verlet | Method::Rk4 => Err(invalid(
            "solver",
            "a target is solved exact or adaptive, not at a fixed step",
        )),
    }
}

/// The contact's trajectory for plots: Dormand–Prince at `rtol` (whatever solver gave the
/// figures), `obs` sees eight points per step from first touch to separation.
pub fn trajectory<R: Real, L: ContactLaw<R>>(
    law: &L,
    impact: &Impact<R>,
    target: &Target<R>,
    rtol: R,
    obs: &mut dyn FnMut(Sample<R>),
) -> Result<TargetOutcome<R>, Error> {
    impact.validate()?;
    law.validate()?;
    target.validate()?;
    coupled::solve_observed(law, impact, target, rtol, obs)
}

/// The reduced mass of the impactor and the contact point, kg.
pub(crate) fn reduced_mass<R: Real>(m1: R, target: &Target<R>) -> R {
    let m2 = target.contact_mass_kg();
    m1 * m2 / (m1 + m2)
}

/// Finishes an outcome from the state at separation (shared by the solvers).
#[allow(clippy::too_many_arguments)]
pub(crate) fn at_separation<R: Real>(
    impact: &Impact<R>,
    target: &Target<R>,
    t: R,
    x1: R,
    u1: R,
    z: [R; MAX_STATES],
    max: (R, R),
    peak_force_n: R,
    evals: u32,
) -> Result<TargetOutcome<R>, Error> {
    let (y, w) = target.outputs(&z);
    let v0 = impact.v0_m_s;
    let energy = target
        .spring_mass
        .map(|s| R::HALF * (s.mass_kg * w * w + s.stiffness_n_m * y * y));
    let out = TargetOutcome {
        max_deformation_m: max.0,
        crush_time_s: max.1,
        contact_time_s: t,
        peak_force_n,
        permanent_deformation_m: (x1 - y).max(R::ZERO),
        rebound_velocity_m_s: R::ZERO - u1,
        impactor_displacement_m: x1,
        target_displacement_m: y,
        target_velocity_m_s: w,
        cor: (w - u1) / v0,
        target_state: z,
        target_energy_j: energy,
        target_work_j: None,
        contact_work_j: None,
        target_dissipated_j: None,
        rhs_evaluations: evals,
    };
    let finite = [
        out.max_deformation_m,
        out.crush_time_s,
        out.contact_time_s,
        out.peak_force_n,
        out.rebound_velocity_m_s,
        out.target_displacement_m,
        out.target_velocity_m_s,
        out.cor,
        out.impactor_displacement_m,
    ]
    .iter()
    .all(|x| x.is_finite());
    if !finite || !(t > R::ZERO) || !(max.0 > R::ZERO) {
        return Err(Error::Unresolved(
            "the contact underflowed or overflowed the number type",
        ));
    }
    Ok(out)
}
