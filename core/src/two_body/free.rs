//! After separation: the target rings on by itself and the impactor coasts; do they meet again?

use super::{Target, TargetOutcome, MAX_STATES};
use crate::error::Error;
use crate::numeric::roots::brent;
use crate::real::Real;

/// The target's free response after separation and the check of the single-hit assumption.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FreeResponse<R> {
    /// When (from first touch) the coasting impactor first meets the target again, s: the
    /// deformation climbs back to what it was at separation (the surfaces touch where they
    /// parted). `None`: no recontact up to `checked_until_s`.
    pub recontact_s: Option<R>,
    /// Recontact was looked for from separation up to this time (from first touch), s.
    pub checked_until_s: R,
    /// The contact point's largest excursion from its rest position after separation, m
    /// (sampled at 40 points per period: within 0.3 %); 0 for a free body, which drifts.
    pub ring_amplitude_m: R,
    /// Ring-down frequency, Hz: the damped natural frequency of a spring–mass, otherwise from
    /// the turning points of the contact point over the horizon; `None` if it does not
    /// oscillate (a free body, an over-damped mount, fewer than three turning points).
    pub ring_frequency_hz: Option<R>,
}

/// Samples per shortest period when scanning the free response.
const PER_PERIOD: f64 = 40.0;
/// Most scan steps.
const MAX_STEPS: u32 = 400_000;

/// The time after separation up to which recontact is possible or worth looking for, s, and
/// for a state-space target the time after which the scan may stop early (two periods of its
/// slowest mode, and at least 100 contact times: once the impactor has recontacted, or has
/// coasted a full swing beyond the lowest point the target reached).
fn horizon<R: Real>(target: &Target<R>, out: &TargetOutcome<R>) -> (R, Option<R>) {
    let tc = out.contact_time_s;
    let base = R::from_f64(20.0) * tc;
    let u1 = -out.rebound_velocity_m_s;
    let Some(s) = target.spring_mass else {
        // The slowest mode sets the time scale, as a spring–mass's period does; a singular
        // A (a free body in state-space form) has none.
        return match target.a_mat().slowest_rate() {
            Some(rate) => {
                let period = R::TWO * R::PI / rate;
                let settle = (R::TWO * period).max(R::from_f64(100.0) * tc);
                (base.max(R::from_f64(1000.0) * period), Some(settle))
            }
            None => (R::from_f64(100.0) * tc, None),
        };
    };
    if s.stiffness_n_m > R::ZERO {
        let period = R::TWO * R::PI * (s.mass_kg / s.stiffness_n_m).sqrt();
        let long = R::from_f64(1000.0) * period;
        if u1 < R::ZERO {
            // The contact point never leaves |y| <= amplitude bound from its energy.
            let energy = out.target_energy_j.unwrap_or(R::ZERO);
            let bound = (R::TWO * energy / s.stiffness_n_m).sqrt();
            let gap = out.impactor_displacement_m - out.permanent_deformation_m + bound;
            (base.max(R::TWO * period).max((gap / -u1).min(long)), None)
        } else {
            (base.max(long), None)
        }
    } else if s.damping_n_s_m > R::ZERO {
        // A damped free body stops `m2 w / c2` further on.
        let tau = s.mass_kg / s.damping_n_s_m;
        let rest = out.target_displacement_m + out.target_velocity_m_s * tau;
        let gap = rest - (out.impactor_displacement_m - out.permanent_deformation_m);
        let closing = if u1 > R::ZERO {
            gap.max(R::ZERO) / u1
        } else {
            R::ZERO
        };
        (base.max(R::from_f64(10.0) * tau + R::TWO * closing), None)
    } else {
        (base, None)
    }
}

/// The target's free response after `out` and whether the impactor meets it again.
pub fn after<R: Real>(
    target: &Target<R>,
    out: &TargetOutcome<R>,
) -> Result<FreeResponse<R>, Error> {
    let n = target.n;
    let a = target.a_mat();
    let (span, settle) = horizon(target, out);
    let tc = out.contact_time_s;
    let mut h = tc / R::from_f64(PER_PERIOD);
    let rate = a.norm_inf();
    if rate > R::ZERO {
        h = h.min(R::TWO * R::PI / rate / R::from_f64(PER_PERIOD));
    }
    // A scan that may stop early keeps its resolution and stops at MAX_STEPS at the latest
    // (`checked_until_s` says where); one that runs to its horizon spreads MAX_STEPS over it.
    if settle.is_none() {
        h = h.max(span / R::from_u32(MAX_STEPS));
    }
    if !(h > R::ZERO && h.is_finite() && span.is_finite()) {
        return Err(Error::Unresolved("free response time scale is not finite"));
    }
    let Some(phi) = a.exp(h) else {
        return Err(Error::Unresolved("matrix exponential overflowed"));
    };
    let mut z = [R::ZERO; super::matrix::DIM];
    z[..n].copy_from_slice(&out.target_state[..n]);
    let x1 = out.impactor_displacement_m;
    let u1 = -out.rebound_velocity_m_s;
    let set = out.permanent_deformation_m;
    let outputs = |z: &[R; super::matrix::DIM]| {
        let mut zz = [R::ZERO; MAX_STATES];
        zz[..n].copy_from_slice(&z[..n]);
        target.outputs(&zz)
    };
    // Gap function: positive once the surfaces overlap again.
    let gap = |tau: R, z: &[R; super::matrix::DIM]| x1 + u1 * tau - outputs(z).0 - set;
    let slack = R::from_f64(64.0) * R::EPSILON * out.max_deformation_m;
    let steps = (span / h).to_f64().min(MAX_STEPS as f64) as u32;
    let mut recontact = None;
    let mut turning: (u32, R, R) = (0, R::ZERO, R::ZERO);
    let (_, mut w_prev) = outputs(&z);
    let mut g_prev = R::ZERO;
    let mut evals = 0u32;
    let mut ys = (R::MAX, -R::MAX);
    let mut scanned = steps;
    for k in 1..=steps {
        let tau = R::from_u32(k) * h;
        let z1 = phi.apply(&z);
        let (y, w) = outputs(&z1);
        if !(y.is_finite() && w.is_finite()) {
            return Err(Error::Unresolved("free response is not finite"));
        }
        let g = gap(tau, &z1);
        if recontact.is_none() && k > 1 && g_prev <= slack && g > slack {
            let z0 = z;
            let root = brent(
                |s: R| match a.exp(s) {
                    Some(e) => gap(tau - h + s, &e.apply(&z0)) - slack,
                    None => R::MAX,
                },
                R::ZERO,
                h,
                R::from_f64(4.0) * R::EPSILON * h,
                &mut evals,
            );
            recontact = Some(tc + root.map_or(tau, |s| tau - h + s));
        }
        if (w_prev > R::ZERO) != (w > R::ZERO) {
            turning = match turning.0 {
                0 => (1, tau, tau),
                c => (c + 1, turning.1, tau),
            };
        }
        ys = (ys.0.min(y), ys.1.max(y));
        w_prev = w;
        g_prev = g;
        z = z1;
        if settle.is_some_and(|t| tau >= t)
            && (recontact.is_some() || x1 + u1 * tau - set < ys.0 - (ys.1 - ys.0))
        {
            scanned = k;
            break;
        }
    }
    let frequency = match target.spring_mass {
        Some(s) if s.stiffness_n_m > R::ZERO => {
            let wn = (s.stiffness_n_m / s.mass_kg).sqrt();
            let zeta = s.damping_n_s_m / (R::TWO * (s.stiffness_n_m * s.mass_kg).sqrt());
            (zeta < R::ONE).then(|| wn * (R::ONE - zeta * zeta).sqrt() / (R::TWO * R::PI))
        }
        Some(_) => None,
        None => (turning.0 >= 3 && turning.2 > turning.1)
            .then(|| R::from_u32(turning.0 - 1) / (R::TWO * (turning.2 - turning.1))),
    };
    let amplitude = match target.spring_mass {
        // A free body drifts; it does not ring.
        Some(s) if s.stiffness_n_m == R::ZERO => R::ZERO,
        _ => {
            ys.1.abs()
                .max(ys.0.abs())
                .max(out.target_displacement_m.abs())
        }
    };
    Ok(FreeResponse {
        recontact_s: recontact,
        checked_until_s: tc + R::from_u32(scanned) * h,
        ring_amplitude_m: amplitude,
        ring_frequency_hz: frequency,
    })
}

/// The contact point's displacement and velocity `tau` seconds after separation (the target
/// ringing freely from its state at separation).
pub fn target_at<R: Real>(target: &Target<R>, out: &TargetOutcome<R>, tau: R) -> Option<(R, R)> {
    let n = target.n;
    let e = target.a_mat().exp(tau)?;
    let mut z = [R::ZERO; super::matrix::DIM];
    z[..n].copy_from_slice(&out.target_state[..n]);
    let z1 = e.apply(&z);
    let mut zz = [R::ZERO; MAX_STATES];
    zz[..n].copy_from_slice(&z1[..n]);
    Some(target.outputs(&zz))
}
