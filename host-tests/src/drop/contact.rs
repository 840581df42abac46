//! One contact of a dropped body with gravity in it: `m z'' = m g - F(z, z')`, integrated by
//! classic RK4 at a fixed step of [`STEPS_PER_SCALE`] per the law's time scale, with every
//! event (the maximum depth, a reloading pad's return to its virgin line, separation) located
//! by bisection on an RK4 sub-step from the step's start and the integration restarted there,
//! and every sample taken by an RK4 sub-step to its exact time (no interpolation).
//!
//! Independent of the core's solvers on purpose: it is the oracle they are tested against,
//! and is itself checked against SciPy's DOP853 (`tests/drop_peer.rs`).

use super::pad::{Branch, Pad};

/// RK4 steps per [`impact_core::ContactLaw::time_scale`]: the global error is below 1e-9 of
/// every quantity for the laws the tests use (`tests/drop_peer.rs` holds it to 1e-6 against
/// SciPy).
pub const STEPS_PER_SCALE: f64 = 20_000.0;

/// Halvings of a step that locate an event: `2^-60` of a step.
const BISECTIONS: u32 = 60;

/// The body's state in a contact.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct State {
    /// Time since the record's start, s.
    pub t: f64,
    /// Depth below the virgin surface, m.
    pub z: f64,
    /// Velocity, m/s, positive downwards.
    pub v: f64,
}

/// What the body and the pad are, for the right-hand side.
#[derive(Clone, Copy)]
pub struct Body<'a> {
    pub pad: &'a Pad,
    pub mass_kg: f64,
    pub gravity_m_s2: f64,
}

impl Body<'_> {
    fn accel(&self, z: f64, v: f64, branch: Branch) -> f64 {
        self.gravity_m_s2 - self.pad.raw_force(z, v, branch) / self.mass_kg
    }

    /// One RK4 step of `h` from `s` on `branch`.
    fn step(&self, s: State, h: f64, branch: Branch) -> State {
        let a1 = self.accel(s.z, s.v, branch);
        let (z2, v2) = (s.z + 0.5 * h * s.v, s.v + 0.5 * h * a1);
        let a2 = self.accel(z2, v2, branch);
        let (z3, v3) = (s.z + 0.5 * h * v2, s.v + 0.5 * h * a2);
        let a3 = self.accel(z3, v3, branch);
        let (z4, v4) = (s.z + h * v3, s.v + h * a3);
        let a4 = self.accel(z4, v4, branch);
        State {
            t: s.t + h,
            z: s.z + h / 6.0 * (s.v + 2.0 * v2 + 2.0 * v3 + v4),
            v: s.v + h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4),
        }
    }

    /// The physical contact force, N.
    pub fn force(&self, s: State, branch: Branch) -> f64 {
        self.pad.raw_force(s.z, s.v, branch).max(0.0)
    }
}

/// The events a contact can meet, each an `f(state)` that turns `>= 0` at the event.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Event {
    /// The velocity reaches zero: the maximum depth.
    Max,
    /// A reloading pad passes its deepest point: back on the virgin line.
    Virgin,
    /// The force returns to zero after the maximum: separation.
    Separation,
}

impl Event {
    fn value(self, body: &Body<'_>, s: State, branch: Branch) -> f64 {
        match self {
            Event::Max => -s.v,
            Event::Virgin => match branch {
                Branch::Reloading { deepest_m } => s.z - deepest_m,
                _ => f64::NEG_INFINITY,
            },
            Event::Separation => -body.pad.raw_force(s.z, s.v, branch),
        }
    }
}

/// What one contact did, in absolute depth and record time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contact {
    /// The state at the maximum depth.
    pub max: Option<State>,
    /// Largest contact force, N.
    pub peak_force_n: f64,
    /// The state at separation; `None` if the body was still on the pad when the contact
    /// was cut (`until_s`) or came to rest on it.
    pub separation: Option<State>,
}

/// Integrates the contact that starts at `touch` on the pad's first branch until separation
/// or `until_s`, calling `sample(t, a)` with the specific force (`F/m`, m/s²) at each time of
/// `times` that falls in the contact (times are consumed in order; the first one not reached
/// is left for the caller). A contact longer than `max_scales` time scales has come to rest.
pub fn integrate(
    body: &Body<'_>,
    touch: State,
    until_s: f64,
    max_scales: f64,
    times: &mut std::iter::Peekable<impl Iterator<Item = f64>>,
    mut sample: impl FnMut(f64, f64),
) -> Contact {
    let impact = impact_core::Impact::new(body.mass_kg, touch.v.abs().max(1e-9));
    let scale = impact_core::ContactLaw::time_scale(body.pad.law(), &impact);
    let h = scale / STEPS_PER_SCALE;
    let stop = until_s.min(touch.t + max_scales * scale);
    let mut branch = body.pad.first_branch();
    let mut s = touch;
    let mut out = Contact {
        max: None,
        peak_force_n: body.force(s, branch),
        separation: None,
    };
    while s.t < stop {
        let h_here = h.min(stop - s.t);
        let next = body.step(s, h_here, branch);
        let events: &[Event] = if out.max.is_none() {
            &[Event::Virgin, Event::Max]
        } else {
            &[Event::Separation]
        };
        // The earliest event this step crosses, located by bisection.
        let mut first: Option<(f64, Event)> = None;
        for &e in events {
            if e.value(body, next, branch) >= 0.0 && e.value(body, s, branch) < 0.0 {
                let tau = locate(body, s, h_here, branch, e);
                if first.is_none_or(|(t, _)| tau < t) {
                    first = Some((tau, e));
                }
            }
        }
        let (end, event) = match first {
            Some((tau, e)) => (body.step(s, tau, branch), Some(e)),
            None => (next, None),
        };
        // The samples up to the step's (or the event's) end, each by its own sub-step.
        while let Some(&t) = times.peek() {
            if t > end.t {
                break;
            }
            if t >= s.t {
                let at = body.step(s, t - s.t, branch);
                sample(t, body.force(at, branch) / body.mass_kg);
            }
            times.next();
        }
        out.peak_force_n = out.peak_force_n.max(body.force(end, branch));
        s = end;
        match event {
            Some(Event::Max) => {
                out.max = Some(s);
                branch = body.pad.after_max(branch, s.z);
                out.peak_force_n = out.peak_force_n.max(body.force(s, branch));
                // A law whose restitution line starts at or below zero force lets go at once.
                if body.pad.raw_force(s.z, s.v, branch) <= 0.0 {
                    out.separation = Some(s);
                    return out;
                }
            }
            Some(Event::Virgin) => {
                branch = Branch::Loading;
                out.peak_force_n = out.peak_force_n.max(body.force(s, branch));
            }
            Some(Event::Separation) => {
                out.separation = Some(s);
                return out;
            }
            None => {}
        }
    }
    out
}

/// The time from `s` at which `event` turns non-negative within `(0, h]`.
fn locate(body: &Body<'_>, s: State, h: f64, branch: Branch, event: Event) -> f64 {
    let (mut lo, mut hi) = (0.0, h);
    for _ in 0..BISECTIONS {
        let mid = 0.5 * (lo + hi);
        if event.value(body, body.step(s, mid, branch), branch) >= 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    hi
}
