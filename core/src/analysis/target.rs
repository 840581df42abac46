//! The contact's kinematics against a target that moves (seed 000, section 3.2: a mass on a
//! spring and damper to ground, or any linear target in state-space form), from the
//! impactor's own measured force.
//!
//! The sensor rides on the impactor (mass `m1`), so its reading is the contact force over
//! `m1`: the force `F` on the target is known at every sample. The target is linear, so its
//! contact point's displacement `y` and velocity `w` follow from `F` alone: each sample's
//! force held over its interval (the midpoint rule the sums already use,
//! [`crate::report::motion`]) moves the target's state `z` exactly by
//!
//! ```text
//! z_{k+1} = Φ z_k + Γ F_k,   [Φ Γ; 0 1] = exp([A B; 0 0] dt)   (zero-order hold)
//! ```
//!
//! (a spring–mass's `z = (y, w)`; a state space's contact point `y = Cx z`, `w = Cv z`,
//! [`crate::two_body::step`])
//! and the contact's kinematics are the impactor's less the target's (Stronge, *Impact
//! Mechanics*, ch. 1): the deformation `δ = x1 - y`, its rate `u1 - w`; the crush where that
//! rate reaches zero; Newton's COR `(w - u1) / v0` at separation; the energy the contact
//! absorbed, the impactor's loss less the work `∫ F w dt` the force did on the target.
//! Without a target the barrier is the rigid wall the rest of the crate assumes.
//!
//! The target is at rest at first touch (its state at the integration's first half sample:
//! first touch lies within a sample of it, and the force before touch is the foot's, a few
//! counts); each impact of a record assumes it again, which the report says. The force is
//! the body's mass times the reading above the baseline, gravity included (in a vertical
//! contact the body's deceleration is the reading less `g`, the force on the target the
//! reading). Per sample the pass costs a dozen f32 operations and an integer conversion
//! against a spring–mass, about `n² + 4n` more against a state space of `n` states (no f64
//! on the Cortex-M4's path).
//!
//! Against a target the body's own verdicts (its velocity never reaching zero, its rebound
//! over `v0` out of range) say nothing about the contact: a light target leaves the body
//! moving on. The kinematics come from this pass alone; a jump at touch is not placed from
//! the compression's law (that would move the body's motion alone): where how far touch may
//! lie matters, the crush time and deformations are null ([`touch_placed`]); nor is a force
//! that steps at the crush split (`report::motion::Step`), within a sample's share of the
//! crush at the rates tested (`tests/mounted.rs`).

use super::motion::{to_f32, PointsOut};
use crate::report::motion::{touch_placed, Frame, MIN_CRUSH_SAMPLES};
use crate::report::{rebound_m_s, Flags, ImpactReport, Kinematics, COR_TOLERANCE};
use crate::scene::Scene;
use crate::signal::baseline::Deviation;
use crate::two_body::step::{Step, Stepper};
use crate::two_body::SceneTarget;

// The scene's validation bounds the target's motion over the longest pass, 2^17 samples
// (`Scene::validate`: scene cannot import the analysis).
const _: () = assert!(super::motion::MAX_SAMPLES == 1 << 17);

/// The contact's motion relative to the target, in the frame's terms.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Relative {
    /// Where the deformation's rate first reached zero, samples from the integration's
    /// first sample (as [`crate::report::motion::Found::crush`]).
    pub crush: f64,
    /// The deformation `x1 - y` there, m.
    pub x_max: f64,
    /// The deformation at the separation, m.
    pub x_sep: f64,
    /// The body's own displacement at the separation, m (gravity's work on it).
    pub x1_sep: f64,
    /// The target's contact point's velocity at the separation, m/s (in the impact
    /// direction).
    pub w_sep: f64,
    /// The work the contact force did on the target up to the separation, J.
    pub target_work_j: f64,
}

/// Why the pass gave no relative motion.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Missing {
    /// The deformation's rate never reached zero before the separation.
    NoStop,
    /// The samples end before the separation, or the target's step or state is not finite.
    NotHeld,
}

/// What one state of the pass holds: the deformation, the target's displacement and
/// velocity, and the work done on it.
#[derive(Clone, Copy)]
struct State {
    x: f32,
    y: f32,
    w: f32,
    work: f32,
}

/// The deviations the pass takes from each raw sample: the body's deceleration's (`motion`,
/// less gravity in a vertical contact) for its sums, and the reading's (`force`, the
/// baseline alone) for the force on the target.
#[derive(Clone, Copy, Debug)]
pub struct Deviations {
    pub motion: Deviation,
    pub force: Deviation,
}

/// The sums over `samples` (the raw samples from the frame's first) with the target driven
/// by `m1` times the reading: the relative crush and separation. The fit points, where
/// given, are written in the relative frame (the deformation and its rate, in units of
/// `v0`, after sample `every i`).
pub fn relative<T: Step>(
    samples: &[i16],
    dev: Deviations,
    frame: &Frame,
    target: &T,
    mass_kg: f32,
    mut points: Option<PointsOut<'_>>,
) -> Result<Relative, Missing> {
    let sc = &frame.scale;
    let last = (frame.sep_floor as usize).saturating_add(1);
    let samples = samples.get(..last).ok_or(Missing::NotHeld)?;
    let (v0, kv, dt) = (sc.v0 as f32, sc.kv as f32, sc.dt as f32);
    // Newtons per unit of `d'`: one sample's velocity change `kv d` over its interval.
    let f_per = mass_kg * kv / dt;
    let half_kv_dt = kv * dt / 2.0;
    let x_lead = sc.x_lead as f32;
    let (mut c, mut q) = (0i64, 0i64);
    let mut z = T::REST;
    // The contact point's displacement and velocity.
    let mut yw = (0.0f32, 0.0f32);
    let mut work = 0.0f32;
    let mut prev = (v0, x_lead);
    let mut crush = None;
    let start = State {
        x: x_lead,
        y: 0.0,
        w: 0.0,
        work: 0.0,
    };
    let mut at_sep = [(frame.sep_floor == 0).then_some(start), None];
    for (j, &raw) in samples.iter().enumerate() {
        let d = dev.motion.of(raw);
        c += i64::from(d);
        q += c;
        let f = dev.force.of(raw) as f32 * f_per;
        z = target.step(z, f);
        let next = target.at(&z);
        work += f * (next.0 - yw.0);
        yw = next;
        // The state after `k` samples, at time `k - ½`.
        let k = j + 1;
        let t = q.wrapping_mul(2).wrapping_sub(c);
        let u = v0 - kv * to_f32(c) - yw.1;
        let x = x_lead + k as f32 * v0 * dt - half_kv_dt * to_f32(t) - yw.0;
        if crush.is_none() && u <= 0.0 {
            // Linear in the interval: the zero `f` of the way in, the area before it.
            let f = prev.0 / (prev.0 - u);
            crush = Some((
                j as f64 + f as f64 - 0.5,
                (prev.1 + dt * f * prev.0 / 2.0) as f64,
            ));
        }
        prev = (u, x);
        if let Some(p) = points.as_mut() {
            let every = p.every.max(1);
            if j % every == 0 {
                let i = j / every;
                if let (Some(px), Some(pv)) = (p.x.get_mut(i), p.v.get_mut(i)) {
                    // (As the body's pass writes its own: the deformation not below zero.)
                    *px = x.max(0.0);
                    *pv = u / v0;
                }
            }
        }
        let here = State {
            x,
            y: yw.0,
            w: yw.1,
            work,
        };
        if k + 1 == last {
            at_sep[0] = Some(here);
        } else if k == last {
            at_sep[1] = Some(here);
        }
    }
    // (A state that overflowed never stops: not held, not "no stop".)
    let [Some(s0), Some(s1)] = at_sep else {
        return Err(Missing::NotHeld);
    };
    if !(yw.0.is_finite() && yw.1.is_finite() && work.is_finite()) {
        return Err(Missing::NotHeld);
    }
    let (crush, x_max) = crush.ok_or(Missing::NoStop)?;
    let frac = frame.frac as f32;
    let lerp = |a: f32, b: f32| (a + frac * (b - a)) as f64;
    let rel = Relative {
        crush,
        x_max,
        x_sep: lerp(s0.x, s1.x),
        x1_sep: lerp(s0.x + s0.y, s1.x + s1.y),
        w_sep: lerp(s0.w, s1.w),
        target_work_j: lerp(s0.work, s1.work),
    };
    let finite = [
        rel.crush,
        rel.x_max,
        rel.x_sep,
        rel.x1_sep,
        rel.w_sep,
        rel.target_work_j,
    ]
    .iter()
    .all(|v| v.is_finite());
    finite.then_some(rel).ok_or(Missing::NotHeld)
}

/// The body's own verdicts on its kinematics, which against a target say nothing of the
/// contact's.
const BODY_ONLY: Flags = Flags(
    Flags::NO_STOP.0
        | Flags::COR_OUT_OF_RANGE.0
        | Flags::UNDERSAMPLED.0
        | Flags::KINEMATICS_NOT_HELD.0,
);

/// `r`'s kinematics as the contact's against `target` (the body's from the sums are
/// replaced, their flags with them), from the pass over `samples` (the raw samples from the
/// frame's first); the fit points, where given, in the contact's frame. The deformation at
/// the crush (m: what the fit points are scaled by), or `None` with the flag that says why
/// (no fits then).
/// Not inlined: its frame stays out of the fits'.
#[inline(never)]
#[allow(clippy::too_many_arguments)]
pub fn contact(
    r: &mut ImpactReport,
    scene: &Scene,
    frame: &Frame,
    samples: &[i16],
    dev: Deviations,
    target: &SceneTarget,
    mass_kg: f32,
    points: Option<PointsOut<'_>>,
) -> Option<f64> {
    r.flags.remove(BODY_ONLY);
    r.kinematics = None;
    let rel = match Stepper::new(target, frame.scale.dt) {
        Some(Stepper::SpringMass(d)) => relative(samples, dev, frame, &d, mass_kg, points),
        Some(Stepper::General(g)) => relative(samples, dev, frame, &g, mass_kg, points),
        None => Err(Missing::NotHeld),
    };
    match rel {
        Ok(rel) => {
            kinematics(r, scene, frame, &rel);
            r.kinematics
                .and_then(|k| k.max_deformation_m)
                .map(|_| rel.x_max)
        }
        Err(Missing::NoStop) => {
            r.flags.insert(Flags::NO_STOP);
            None
        }
        Err(Missing::NotHeld) => {
            r.flags.insert(Flags::KINEMATICS_NOT_HELD);
            None
        }
    }
}

/// `r`'s kinematics from the contact's relative motion: Newton's COR `(v' + w) / v0` (the
/// body's rebound `v'` from Δv, as without a target), the crush time and the deformations
/// relative to the target, the energy the contact absorbed (the body's loss, with gravity's
/// work on it in a vertical contact, less the work done on the target). The COR's range,
/// the compression's samples ([`MIN_CRUSH_SAMPLES`]) and how far first touch may lie
/// ([`touch_placed`]) are checked as without a target. (A jump at touch is not placed from
/// the compression's law here, `analysis::jump` being the body's: first touch lies anywhere
/// in its interval, up to half a sample from its middle, as far as the onset from a line's
/// zero; measured +7 % on `x_m` on a Kelvin–Voigt pad at 20 kS/s, 0.7 % at 100 kS/s.)
pub fn kinematics(r: &mut ImpactReport, scene: &Scene, frame: &Frame, rel: &Relative) {
    let v0 = frame.scale.v0 as f32;
    let gravity = scene.contact_gravity_m_s2();
    let Some(rebound) = rebound_m_s(r, v0, gravity) else {
        return;
    };
    let cor = (rebound + rel.w_sep as f32) / v0;
    if !(cor.is_finite() && (-COR_TOLERANCE..=1.0 + COR_TOLERANCE).contains(&cor)) {
        r.flags.insert(Flags::COR_OUT_OF_RANGE);
        return;
    }
    let crush_s = (rel.crush - frame.touch) * frame.scale.dt;
    let resolved = crush_s * scene.calibration.sample_rate_hz as f64 >= MIN_CRUSH_SAMPLES
        && touch_placed(frame.touch_reach, frame, rel.x_max);
    if !resolved {
        r.flags.insert(Flags::UNDERSAMPLED);
    }
    let held = |v: f64| resolved.then_some(v as f32);
    let absorbed = scene.mass_kg.map(|m| {
        0.5 * m * (v0 * v0 - rebound * rebound) + gravity.map_or(0.0, |g| m * g * rel.x1_sep as f32)
            - rel.target_work_j as f32
    });
    if absorbed.is_some_and(|e| !e.is_finite()) {
        r.flags.remove(Flags::UNDERSAMPLED);
        r.flags.insert(Flags::KINEMATICS_NOT_HELD);
        return;
    }
    r.kinematics = Some(Kinematics {
        impact_velocity_m_s: v0,
        crush_time_s: held(crush_s),
        max_deformation_m: held(rel.x_max),
        rebound_velocity_m_s: rebound,
        cor,
        separation_deformation_m: held(rel.x_sep),
        permanent_deformation_m: None,
        absorbed_energy_j: absorbed,
    });
}
