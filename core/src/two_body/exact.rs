//! Closed-form contacts with a target: the reduced-mass problem for a free body, and the
//! matrix exponential of the coupled linear system for affine laws on any linear target.

use super::matrix::{dot, Mat, Vector, DIM};
use super::{at_separation, reduced_mass, Target, TargetOutcome, MAX_STATES};
use crate::error::Error;
use crate::model::Impact;
use crate::model::{Affine, ContactLaw, Phase};
use crate::numeric::roots::brent;
use crate::real::Real;

/// Two free bodies: the relative motion is the wall problem of the reduced mass
/// `μ = m1 m2 / (m1 + m2)`, solved by the law's own exact solution; momentum gives each body's
/// velocity and the centre of mass each one's position.
pub(super) fn free_body<R: Real, L: ContactLaw<R>>(
    law: &L,
    impact: &Impact<R>,
    target: &Target<R>,
) -> Result<TargetOutcome<R>, Error> {
    let m1 = impact.mass_kg;
    let m2 = target.contact_mass_kg();
    let v0 = impact.v0_m_s;
    let mu = reduced_mass(m1, target);
    let rel = law.exact(&Impact::new(mu, v0))?;
    let v_rel = rel.rebound_velocity_m_s;
    let total = m1 + m2;
    // Momentum: m1 u1 + m2 w = m1 v0 with w - u1 = v_rel.
    let w = mu * (v0 + v_rel) / m2;
    let u1 = w - v_rel;
    let delta = rel.permanent_deformation_m;
    let y = m1 * v0 / total * rel.contact_time_s - m1 / total * delta;
    let mut z = [R::ZERO; MAX_STATES];
    z[0] = y;
    z[1] = w;
    let mut out = at_separation(
        impact,
        target,
        rel.contact_time_s,
        y + delta,
        u1,
        z,
        (rel.max_deformation_m, rel.crush_time_s),
        rel.peak_force_n,
        rel.rhs_evaluations,
    )?;
    let kinetic = R::HALF * m2 * w * w;
    out.target_work_j = Some(kinetic);
    out.target_dissipated_j = Some(R::ZERO);
    out.contact_work_j = Some(R::HALF * m1 * (v0 * v0 - u1 * u1) - kinetic);
    Ok(out)
}

/// The coupled system `q' = M q` for one affine phase, with `q = (x1, u1, z, 1)`.
struct Linear<R> {
    m: Mat<R>,
    /// Rows giving the force, the deformation and its rate from `q`.
    force: Vector<R>,
    deformation: Vector<R>,
    rate: Vector<R>,
    /// `dF/dt = force · M q`.
    force_rate: Vector<R>,
}

impl<R: Real> Linear<R> {
    fn new(law: Affine<R>, m1: R, target: &Target<R>) -> Self {
        let n = target.n;
        let dim = n + 3;
        let one = n + 2;
        let mut deformation = [R::ZERO; DIM];
        let mut rate = [R::ZERO; DIM];
        deformation[0] = R::ONE;
        rate[1] = R::ONE;
        for i in 0..n {
            deformation[2 + i] = -target.c[0][i];
            rate[2 + i] = -target.c[1][i];
        }
        let mut force = [R::ZERO; DIM];
        for j in 0..dim {
            force[j] = law.k * deformation[j] + law.c * rate[j];
        }
        force[one] = law.f0;
        let mut m = Mat::zero(dim);
        m.a[0][1] = R::ONE;
        for j in 0..dim {
            m.a[1][j] = -force[j] / m1;
        }
        for i in 0..n {
            for j in 0..n {
                m.a[2 + i][2 + j] = target.a[i][j];
            }
            for j in 0..dim {
                m.a[2 + i][j] += target.b[i] * force[j];
            }
        }
        let mut force_rate = [R::ZERO; DIM];
        for j in 0..dim {
            let mut s = R::ZERO;
            for k in 0..dim {
                s += force[k] * m.a[k][j];
            }
            force_rate[j] = s;
        }
        Self {
            m,
            force,
            deformation,
            rate,
            force_rate,
        }
    }

    fn dim(&self) -> usize {
        self.m.n
    }
}

/// Affine laws on a linear target: within each phase the coupled motion is `exp(M t) q0`. The
/// contact is scanned at a step well under the contact's and the target's time scales (one
/// matrix exponential per phase), and each event (maximum deformation, peak force,
/// separation) is the root of its linear function of `q` between two scan points, with
/// `exp(M τ)` evaluated at each trial `τ`.
pub(super) fn affine<R: Real, L: ContactLaw<R>>(
    law: &L,
    impact: &Impact<R>,
    target: &Target<R>,
) -> Result<TargetOutcome<R>, Error> {
    if R::EPSILON > R::from_f64(1e-10) {
        // Measured (`impact bench stability`): in f32 the exponential of a light or stiff,
        // damped mount over the contact loses its modes and moves events by percents.
        return Err(Error::InvalidParameter {
            name: "precision",
            reason: "the closed form on a target runs in f64 (in f32 use --solver adaptive)",
        });
    }
    let m1 = impact.mass_kg;
    let v0 = impact.v0_m_s;
    let n = target.n;
    let mu = reduced_mass(m1, target);
    let scale = law.time_scale(&Impact::new(mu, v0));
    let target_rate = target.rate();
    let quarter = if target_rate > R::ZERO {
        R::from_f64(0.25) / target_rate
    } else {
        scale
    };
    let h = (scale / R::from_f64(64.0))
        .min(quarter)
        .max(scale / R::from_f64(4096.0));
    if !(h > R::ZERO && h.is_finite()) {
        return Err(Error::Unresolved(
            "time scale is not a positive finite number",
        ));
    }
    let mut q = [R::ZERO; DIM];
    q[1] = v0;
    q[n + 2] = R::ONE;
    let mut t = R::ZERO;
    let mut phase = Phase::Compression;
    let mut first_max: Option<R> = None;
    let mut max = (R::ZERO, R::ZERO);
    let mut evals = 0u32;
    let tol = R::from_f64(4.0) * R::EPSILON * h;
    let mut peak = R::ZERO;
    'phases: loop {
        let Some(aff) = law.affine(phase) else {
            return Err(Error::Unresolved("law is not affine in this phase"));
        };
        let sys = Linear::new(aff, m1, target);
        let t_start = t;
        let dim = sys.dim();
        peak = peak.max(dot(&sys.force, &q, dim));
        // Scan points by one `exp(M h)`, re-anchored every 32 steps straight from the
        // phase's start (`exp(M k h) q_start`), so no rounding is carried over more than 32
        // products.
        let start = q;
        let Some(phi) = sys.m.exp(h) else {
            return Err(Error::Unresolved("matrix exponential overflowed"));
        };
        evals += 1;
        for k in 1..(1u32 << 20) {
            let q1 = if k % 32 == 0 {
                let Some(anchor) = sys.m.exp(R::from_u32(k) * h) else {
                    return Err(Error::Unresolved("matrix exponential overflowed"));
                };
                evals += 1;
                anchor.apply(&start)
            } else {
                phi.apply(&q)
            };
            let at = |tau: R| -> Vector<R> {
                match sys.m.exp(tau) {
                    Some(e) => e.apply(&q),
                    None => [R::MAX; DIM],
                }
            };
            // The event between the two scan points; if the trial exponentials disagree in sign
            // with the scan points (rounding, f32 on a stiff mount), the chord between them:
            // an event seen is never skipped.
            let root_of = |row: &Vector<R>, evals: &mut u32| -> R {
                brent(|tau| dot(row, &at(tau), dim), R::ZERO, h, tol, evals).unwrap_or_else(|| {
                    let (v0, v1) = (dot(row, &q, dim), dot(row, &q1, dim));
                    (h * v0 / (v0 - v1)).max(R::ZERO).min(h)
                })
            };
            // Peak force: a local maximum of F inside the step.
            let dq = dot(&sys.force_rate, &q, dim);
            let dq1 = dot(&sys.force_rate, &q1, dim);
            if dq > R::ZERO && dq1 <= R::ZERO {
                let tau = root_of(&sys.force_rate, &mut evals);
                peak = peak.max(dot(&sys.force, &at(tau), dim));
            }
            let rate0 = dot(&sys.rate, &q, dim);
            let rate1 = dot(&sys.rate, &q1, dim);
            if rate0 >= R::ZERO && rate1 < R::ZERO {
                // A maximum of the deformation.
                {
                    let tau = root_of(&sys.rate, &mut evals);
                    let qm = at(tau);
                    let d = dot(&sys.deformation, &qm, dim);
                    if d > max.0 {
                        max = (d, t + tau);
                    }
                    if first_max.is_none() {
                        first_max = Some(d);
                        phase = Phase::Restitution { x_max: d };
                        if law.switches_at_max() {
                            // Restart under the restitution law exactly at the maximum.
                            q = qm;
                            t += tau;
                            continue 'phases;
                        }
                    }
                }
            }
            if first_max.is_some() && dot(&sys.force, &q1, dim) <= R::ZERO {
                let tau = root_of(&sys.force, &mut evals);
                let qs = at(tau);
                let mut z = [R::ZERO; MAX_STATES];
                z[..n].copy_from_slice(&qs[2..2 + n]);
                let mut out =
                    at_separation(impact, target, t + tau, qs[0], qs[1], z, max, peak, evals)?;
                // Without a damper the target keeps what it was given.
                if target
                    .spring_mass
                    .is_some_and(|s| s.damping_n_s_m == R::ZERO)
                {
                    if let Some(e) = out.target_energy_j {
                        out.target_work_j = Some(e);
                        out.target_dissipated_j = Some(R::ZERO);
                        let u1 = qs[1];
                        out.contact_work_j = Some(R::HALF * m1 * (v0 * v0 - u1 * u1) - e);
                    }
                }
                return Ok(out);
            }
            peak = peak.max(dot(&sys.force, &q1, dim));
            if !q1[..dim].iter().all(|x| x.is_finite()) {
                return Err(Error::Unresolved("non-finite state"));
            }
            q = q1;
            t = t_start + R::from_u32(k) * h;
        }
        return Err(Error::Unresolved(
            "contact did not end within 2^20 scan steps",
        ));
    }
}
