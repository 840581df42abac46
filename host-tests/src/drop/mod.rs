//! A physical drop, the tests' oracle: what an accelerometer on a body records when the body is
//! held at rest, released, falls under gravity, strikes a pad and bounces on it.
//!
//! An accelerometer measures specific force along its axis (here up, the pad's push
//! positive): `+g` at rest on the holder, 0 in free fall, `F/m` in a contact. The body's
//! acceleration into the pad is `g - F/m`: gravity acts in every contact, so the pulse's
//! area is `v0 + v_r + g t_c`, not `v0 + v_r`. The record starts at rest (or already moving),
//! and each flight is ballistic from the depth where the body left to the pad's recovered
//! surface ([`pad`]: the virgin surface for every law but the two-phase one, whose set stays).
//!
//! Independent of the core's analysis and solvers: its own integrator ([`contact`]), checked
//! against a stored SciPy peer (`tests/drop_peer.rs`). Gravity 0 is a horizontal strike.
//!
//! Definitions, each as an experimental mechanician measures it against high-speed video
//! (Stronge, *Impact Mechanics*, ch. 1–2; Goldsmith, *Impact*, ch. 4):
//! - approach `v0`: the speed at first touch; rebound `v_r`: the speed at separation, where
//!   the contact force returns to zero; COR `v_r / v0` (kinematic, Newton's);
//! - deformations are the body's displacement since first touch: `x_m` at the maximum, the
//!   separation deformation where it left, the set where the pad's surface is once it has
//!   recovered (0 for an elastic or Kelvin–Voigt pad; `x_p` for a virgin two-phase pad);
//! - absorbed energy `m v0²/2 - m v_r²/2 + m g x_sep`: gravity's work in the contact counts.

pub mod contact;
pub mod mounted;
pub mod pad;

use contact::{Body, State};
use impact_core::{ContactLaw, Error, Model};
pub use pad::Pad;

/// How the record begins.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Start {
    /// Held at rest on a support for `rest_s` (the accelerometer reads `+g`), released, and
    /// falling `height_m` to the pad.
    Rest { rest_s: f64, height_m: f64 },
    /// Already in free flight at the record's start, touching the pad at `touch_s` at
    /// `v0_m_s` (a horizontal strike when gravity is 0).
    Moving { touch_s: f64, v0_m_s: f64 },
}

/// A drop (or a strike): the body, the pad, gravity, and how many contacts to model.
#[derive(Clone, Copy, Debug)]
pub struct Drop {
    pub law: Model<f64>,
    pub mass_kg: f64,
    /// Gravity along the sensor's axis, m/s² (0: a horizontal strike, no flights).
    pub gravity_m_s2: f64,
    pub start: Start,
    /// Contacts modelled at most; the record ends at the landing after the last.
    pub max_contacts: u32,
    /// The train ends after a rebound slower than this, m/s (at the next landing).
    pub min_rebound_m_s: f64,
}

/// A contact that lasts longer than this many of the law's time scales has come to rest.
const REST_SCALES: f64 = 200.0;

/// What is true about one contact. Times are from the record's start; deformations are the
/// body's displacement since first touch, m.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactTruth {
    pub touch_s: f64,
    /// Speed at first touch, m/s.
    pub approach_m_s: f64,
    /// Depth of the pad's surface at first touch, below the virgin surface, m.
    pub surface_m: f64,
    /// From first touch to the maximum deformation, s (`None`: the record ended first).
    pub crush_time_s: Option<f64>,
    pub max_deformation_m: Option<f64>,
    /// Largest contact force, N (within the record).
    pub peak_force_n: f64,
    pub separation: Option<Separation>,
}

/// A contact's end.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Separation {
    /// From first touch to separation, s.
    pub contact_time_s: f64,
    /// Speed at separation, m/s (upwards, positive).
    pub rebound_m_s: f64,
    pub cor: f64,
    /// Displacement since first touch at separation, m.
    pub deformation_m: f64,
    /// The pad's recovered surface below the touch point, m (the permanent set).
    pub set_m: f64,
    /// `m v0²/2 - m v_r²/2 + m g x_sep`, J.
    pub absorbed_energy_j: f64,
    /// The area of the specific force over the contact, m/s: `v0 + v_r + g t_c`.
    pub delta_v_m_s: f64,
}

/// Why the record ends where it does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum End {
    /// The duration asked for.
    Duration,
    /// At the landing after the last contact modelled (`max_contacts` or `min_rebound_m_s`).
    Contacts,
    /// At a separation after which the pad could not recover before the body landed again
    /// (or the body could not rise above it): the next contact would start on a moving pad.
    PadNotRecovered,
    /// The body came to rest on the pad.
    Rests,
}

/// A rendered drop: the specific force at each sample time, m/s², and the truth.
#[derive(Clone, Debug)]
pub struct Rendered {
    /// Specific force along the axis at `k / rate_hz`, m/s².
    pub accel_m_s2: Vec<f64>,
    pub contacts: Vec<ContactTruth>,
    pub end: End,
}

impl Drop {
    /// Checks the parameters; names the offending one.
    pub fn validate(&self) -> Result<(), Error> {
        self.law.validate()?;
        let bad = |name, reason| Err(Error::InvalidParameter { name, reason });
        if !(self.mass_kg.is_finite() && self.mass_kg > 0.0) {
            return bad("mass", "must be finite and > 0");
        }
        if !(self.gravity_m_s2.is_finite() && self.gravity_m_s2 >= 0.0) {
            return bad("gravity", "must be finite and >= 0");
        }
        if !(self.min_rebound_m_s.is_finite() && self.min_rebound_m_s > 0.0) {
            return bad("min-rebound", "must be finite and > 0");
        }
        match self.start {
            Start::Rest { rest_s, height_m } => {
                if self.gravity_m_s2 == 0.0 {
                    return bad("gravity", "must be > 0 for a drop from rest");
                }
                if !(rest_s.is_finite() && rest_s >= 0.0) {
                    return bad("rest", "must be finite and >= 0");
                }
                if !(height_m.is_finite() && height_m > 0.0) {
                    return bad("drop-height", "must be finite and > 0");
                }
            }
            Start::Moving { touch_s, v0_m_s } => {
                if !(touch_s.is_finite() && touch_s >= 0.0) {
                    return bad("touch", "must be finite and >= 0");
                }
                if !(v0_m_s.is_finite() && v0_m_s > 0.0) {
                    return bad("v0", "must be finite and > 0");
                }
            }
        }
        Ok(())
    }

    /// The first touch: its time and speed.
    fn first_touch(&self) -> (f64, f64) {
        match self.start {
            Start::Rest { rest_s, height_m } => {
                let g = self.gravity_m_s2;
                (
                    rest_s + (2.0 * height_m / g).sqrt(),
                    (2.0 * g * height_m).sqrt(),
                )
            }
            Start::Moving { touch_s, v0_m_s } => (touch_s, v0_m_s),
        }
    }

    /// Renders `n` samples at `rate_hz` (sample `k` at `k / rate_hz`), fewer if the record
    /// ends first ([`End`]).
    pub fn render(&self, rate_hz: f64, n: usize) -> Result<Rendered, Error> {
        self.validate()?;
        if !(rate_hz.is_finite() && rate_hz > 0.0) {
            return Err(Error::InvalidParameter {
                name: "rate",
                reason: "must be finite and > 0",
            });
        }
        let g = self.gravity_m_s2;
        let mut out = Rendered {
            accel_m_s2: Vec::with_capacity(n),
            contacts: Vec::new(),
            end: End::Duration,
        };
        let mut times = (0..n).map(|k| k as f64 / rate_hz).peekable();
        let record_end = n as f64 / rate_hz;
        // Held, then free until the first touch.
        let release = match self.start {
            Start::Rest { rest_s, .. } => rest_s,
            Start::Moving { .. } => 0.0,
        };
        fill(&mut times, &mut out.accel_m_s2, release, g);
        let (t_touch, v_touch) = self.first_touch();
        fill(&mut times, &mut out.accel_m_s2, t_touch, 0.0);
        let mut pad = Pad::new(self.law);
        let mut touch = State {
            t: t_touch,
            z: 0.0,
            v: v_touch,
        };
        while touch.t < record_end {
            let body = Body {
                pad: &pad,
                mass_kg: self.mass_kg,
                gravity_m_s2: g,
            };
            let accel = &mut out.accel_m_s2;
            let c =
                contact::integrate(&body, touch, record_end, REST_SCALES, &mut times, |_, a| {
                    accel.push(a)
                });
            let mut truth = ContactTruth {
                touch_s: touch.t,
                approach_m_s: touch.v,
                surface_m: touch.z,
                crush_time_s: c.max.map(|m| m.t - touch.t),
                max_deformation_m: c.max.map(|m| m.z - touch.z),
                peak_force_n: c.peak_force_n,
                separation: None,
            };
            if let Some(m) = c.max {
                pad.remember(m.z);
            }
            let (Some(sep), Some(max)) = (c.separation, c.max) else {
                out.contacts.push(truth);
                if times.peek().is_some() {
                    // Cut before the record's end: the body rests on the pad.
                    out.end = End::Rests;
                }
                break;
            };
            let rebound = -sep.v;
            let surface = pad.surface_m();
            truth.separation = Some(Separation {
                contact_time_s: sep.t - touch.t,
                rebound_m_s: rebound,
                cor: rebound / touch.v,
                deformation_m: sep.z - touch.z,
                set_m: surface - touch.z,
                absorbed_energy_j: 0.5 * self.mass_kg * (touch.v * touch.v - rebound * rebound)
                    + self.mass_kg * g * (sep.z - touch.z),
                delta_v_m_s: touch.v + rebound + g * (sep.t - touch.t),
            });
            out.contacts.push(truth);
            // Ballistic from the separation depth to the recovered surface.
            let rise = rebound * rebound - 2.0 * g * (sep.z - surface);
            if g == 0.0 {
                fill(&mut times, &mut out.accel_m_s2, f64::INFINITY, 0.0);
                break;
            }
            if rise < 0.0 {
                out.end = End::PadNotRecovered;
                break;
            }
            let landing = rise.sqrt();
            let flight = (rebound + landing) / g;
            let last =
                out.contacts.len() as u32 >= self.max_contacts || rebound < self.min_rebound_m_s;
            if !last && pad.recovery_s(sep.z, max.z - touch.z) > flight {
                out.end = End::PadNotRecovered;
                break;
            }
            fill(&mut times, &mut out.accel_m_s2, sep.t + flight, 0.0);
            if last {
                out.end = End::Contacts;
                break;
            }
            touch = State {
                t: sep.t + flight,
                z: surface,
                v: landing,
            };
        }
        Ok(out)
    }
}

/// Pushes `value` for every sample time before `until_s`.
fn fill(
    times: &mut std::iter::Peekable<impl Iterator<Item = f64>>,
    out: &mut Vec<f64>,
    until_s: f64,
    value: f64,
) {
    while times.next_if(|&t| t < until_s).is_some() {
        out.push(value);
    }
}
