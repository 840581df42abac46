//! Bounce trains: the approach speed of each bounce after the first, from the flight time
//! since the previous separation and from the previous rebound.
//!
//! A body dropped on a barrier bounces: between two contacts it flies up and falls back under
//! gravity (no drag; gravity along the sensor's axis, the flight vertical). It leaves the pad
//! at the previous contact's separation deformation `x_sep` and lands `h` higher, where the
//! pad's surface is by then, so after a flight `t` (from one separation to the next first
//! touch)
//!
//! ```text
//! v0_flight  = g t / 2 - h / t             (ballistic: up at g t / 2 + h / t, down at this)
//! v0_rebound = g t - v_r                   (the previous impact's measured rebound, up at
//!                                           v_r, down t later: wherever the pad then is)
//! ```
//!
//! are two measures of the same speed: the flight time needs only the stream's positions
//! (exact), `g` and the landing; the rebound `v_r` carries the previous approach speed's
//! error with the opposite sign, and needs no landing (a Kelvin–Voigt pad's bounce 7 at
//! 0.131 m/s: the plain `v_r` is 3.8 % high). Both are reported; the scene picks the one the
//! kinematics use. Where it picks the rebound (`--train rebound`), a chain: each bounce's
//! speed is the previous rebound brought down, so an error in it moves the next rebound the
//! other way by as much (`v_r = Δv - v0`) and the next speed back by as much again: the
//! chain keeps the first speed's error and adds each contact's Δv error, and a COR from it
//! moves by `(1 + 1/COR)` times the speed's share (at 20 kS/s a crushing pad's bounces drift
//! by 0.2 % of the speed each; the flight, the default, does not drift). (Landing the
//! rebound at the separation deformation instead, `sqrt(v_r² - 2 g h)`, would feed the
//! chain's error back through `h`, growing it by `1 + g T / v_r` a bounce; landing it where
//! it left gave each bounce `g x_sep / v_r` too fast, 3.4 % by a Kelvin–Voigt pad's bounce
//! 5 at 20 kS/s.)
//!
//! The landing height `h` (Stronge, *Impact Mechanics*, ch. 1: the pad's surface after
//! restitution) is one of two: `x_sep`, for a pad that recovers its shape between contacts
//! (elastic and viscoelastic: a Kelvin–Voigt pad leaves the body `c v / k` deep and springs
//! back behind it; a crushed pad reloading elastically), or 0, for one that keeps the dent
//! where the body left it (the two-phase law's first contact, whose separation lies at its
//! set). The pad recovering is taken, unless the previous rebound says otherwise clearly:
//! the two take-off speeds `g t / 2 + h / t` differ by more than [`LANDING_MARGIN`] of the
//! speed and the rebound is nearer the dent's (a crushed pad's first bounce: 9 % apart).
//! Nearer than that, the rebound cannot tell them (a Kelvin–Voigt pad's are 0.1–0.2 % apart
//! on every bounce, `x_sep / t ≈ c g / 2 k`, while the rebound carries the approach speed's
//! error), and a choice made by it would confirm itself bounce after bounce (a wrong dent
//! makes the next rebound low by the same `x_sep / t`). Without a rebound the pad recovers.
//! `h = x_sep` is taken only where it leaves a landing speed (`x_sep / t < g t / 2`) and the
//! rebound could have climbed it (`v_r² > 2 g x_sep`); the report's `landing_height_m`
//! gives the `h` used.
//!
//! A flight longer than the scene's longest (a new drop, the body picked up) ends the train:
//! the next impact is a first one, with the scene's [`crate::scene::Approach`]. After a
//! previous impact without a separation (settled, too long, a gap, the stream ended) there
//! is no flight to time: the next impact, if within a flight of it, has no speed but a light
//! gate's. After one without an approach speed (so without a rebound) or with a rebound the
//! flight could not have come back from (`g t <= v_r`), the bounce has its flight's measure
//! alone (under `--train rebound`, no speed, nor has the chain after it).
//!
//! Without a train the scene's approach speed (a drop's `v0` or height) is the first
//! impact's: an impact that follows a flight (its first touch within a train's longest
//! flight of the previous separation) came back at a speed nothing measured, so it has none
//! ([`crate::report::Flags::APPROACH_UNKNOWN`]), unless the scene says every impact comes at
//! it (`v0_every`, a rig that strikes again and again) or a light gate measured it.

use crate::report::summary::Summary;
use crate::report::{self, Bounce, Status, COR_TOLERANCE};
use crate::scene::{Scene, Train, TrainSpeed};

/// The previous rebound chooses a dented pad's landing only where the two take-off speeds
/// differ by more than this share of the speed: beyond any approach speed's error a lab
/// would give, so a choice does not hang on it (and, made, confirm itself).
pub const LANDING_MARGIN: f32 = 0.02;

/// An impact's approach, as the tracker decides it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Approached {
    /// The approach speed the kinematics use, m/s.
    pub v0_m_s: Option<f32>,
    /// The bounce, if the impact continues a train.
    pub bounce: Option<Bounce>,
    /// The impact follows a flight and the scene's speed was the first impact's: no speed.
    pub unknown: bool,
}

/// What the stream remembers of the previous impact between two impacts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Tracker {
    /// Stream position of the previous separation (fractional samples), if it had one (and
    /// the train goes on from it).
    separation: Option<f64>,
    /// Where the previous impact's contact ended, whatever its status (its separation, or
    /// the end of its window), stream position: a drop's later impacts follow a flight.
    last_end: Option<f64>,
    /// The previous impact's rebound speed, m/s, if known and in range.
    rebound_m_s: Option<f32>,
    /// The previous impact's separation deformation, m (0 if the online sums found none, or
    /// below its touch point).
    separation_deformation_m: f32,
    /// The previous impact's bounce number (0 for a train's first impact).
    number: u32,
}

impl Tracker {
    /// Before any impact.
    pub(crate) const fn new() -> Self {
        Self {
            separation: None,
            last_end: None,
            rebound_m_s: None,
            separation_deformation_m: 0.0,
            number: 0,
        }
    }

    /// The approach of an impact whose first touch is at stream position `touch`
    /// (fractional samples); `first` is the speed a first impact gets (the scene's approach,
    /// or a light gate's), `measured` whether a light gate measured it for this impact (then
    /// it holds after a flight too).
    pub(crate) fn approach(
        &self,
        scene: &Scene,
        touch: f64,
        first: Option<f32>,
        measured: bool,
    ) -> Approached {
        let plain = Approached {
            v0_m_s: first,
            bounce: None,
            unknown: false,
        };
        let fs = scene.calibration.sample_rate_hz as f64;
        let flight = |from: f64| ((touch - from) / fs) as f32;
        // Within the longest flight of the previous contact's end (or overlapping it): a
        // bounce, whose approach nothing measured unless a train does.
        let max = scene
            .train
            .map_or(Train::new().max_flight_s, |t| t.max_flight_s);
        let bounced = self.last_end.is_some_and(|e| flight(e) <= max);
        let unmeasured = |holds: bool| match first {
            Some(_) if bounced && !holds => Approached {
                v0_m_s: None,
                bounce: None,
                unknown: true,
            },
            _ => plain,
        };
        let Some(train) = scene.train else {
            // No train: the scene's speed was the drop's, unless every impact comes at it.
            return unmeasured(scene.v0_every || measured);
        };
        // A train goes on from a separation it could time; a bounce after one it could not
        // (a gap, a contact that settled) has no speed but a light gate's.
        let Some(flight_s) = self
            .separation
            .map(flight)
            .filter(|&f| f > 0.0 && f <= train.max_flight_s)
        else {
            return unmeasured(measured);
        };
        let g = scene.gravity_m_s2;
        let half = g * flight_s / 2.0;
        let h = self.landing_height_m(half, flight_s, g);
        // The rebound brought down by the flight's time: up at `v_r`, down `t` later at
        // `g t - v_r`, wherever the pad's surface then is.
        let v0_rebound_m_s = self
            .rebound_m_s
            .map(|v_r| g * flight_s - v_r)
            .filter(|v| v.is_finite() && *v > 0.0);
        let bounce = Bounce {
            number: self.number.saturating_add(1),
            flight_s,
            v0_flight_m_s: half - h / flight_s,
            v0_rebound_m_s,
            landing_height_m: h,
        };
        let v0 = match train.speed {
            TrainSpeed::Flight => Some(bounce.v0_flight_m_s),
            TrainSpeed::Rebound => bounce.v0_rebound_m_s,
        };
        Approached {
            v0_m_s: v0.filter(|v| v.is_finite() && *v > 0.0),
            bounce: Some(bounce),
            unknown: false,
        }
    }

    /// The landing height `h` after a flight of `flight_s` (`half`: `g t / 2`; `g`): the
    /// previous separation deformation (the pad recovered) unless the previous rebound is
    /// clearly the take-off speed of a pad that kept its dent (0), or the deformation leaves
    /// no landing speed (0).
    fn landing_height_m(&self, half: f32, flight_s: f32, g: f32) -> f32 {
        let x_sep = self.separation_deformation_m;
        let recovered = half + x_sep / flight_s;
        let lands = x_sep > 0.0
            && x_sep / flight_s < half
            && self.rebound_m_s.is_none_or(|v| v * v > 2.0 * g * x_sep);
        if !lands {
            return 0.0;
        }
        let dented = self.rebound_m_s.is_some_and(|v_r| {
            recovered - half > LANDING_MARGIN * half && (v_r - half).abs() < (v_r - recovered).abs()
        });
        if dented {
            0.0
        } else {
            x_sep
        }
    }

    /// Remembers the impact that just ended (its summary complete, `v0_m_s` included).
    pub(crate) fn ended(&mut self, s: &Summary, scene: &Scene) {
        let separation = match (s.status, s.separation_index) {
            // A full capture cut nothing the stream measured: the separation and Δv are
            // whole.
            (Status::Complete | Status::BufferFull, Some(i)) => {
                Some(i as f64 + s.separation_offset as f64)
            }
            _ => None,
        };
        // A clipped impact's Δv is a lower bound: no rebound from it.
        let rebound = match (s.v0_m_s, separation) {
            (Some(v0), Some(_)) if !s.clipped && scene.train.is_some() => report::rebound_m_s(
                &report::measured(s, scene),
                v0,
                scene.contact_gravity_m_s2(),
            )
            .filter(|r| {
                let cor = r / v0;
                cor.is_finite() && (0.0..=1.0 + COR_TOLERANCE).contains(&cor) && *r > 0.0
            }),
            _ => None,
        };
        // A contact that came back (not a level the signal settled at, as a release's jolt,
        // nor a stuck sensor or the stream's end): the next impact within a flight of it is
        // a bounce.
        let contact = matches!(
            s.status,
            Status::Complete | Status::BufferFull | Status::Gap
        );
        let last_end = s.separation_index.unwrap_or(s.end_index) as f64
            + if s.separation_index.is_some() {
                s.separation_offset as f64
            } else {
                0.0
            };
        // (The online sums' separation deformation: the analysis's comes later, and the next
        // impact's approach cannot wait for it.)
        let separation_deformation_m = match s.motion.get() {
            Ok(found) if found.x_sep.is_finite() && found.x_sep > 0.0 => found.x_sep as f32,
            _ => 0.0,
        };
        *self = Tracker {
            separation: separation.filter(|_| scene.train.is_some()),
            last_end: contact.then_some(last_end),
            rebound_m_s: rebound,
            separation_deformation_m,
            number: s.bounce.get().map_or(0, |b| b.number),
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::signal::Calibration;

    fn plain(v0: Option<f32>) -> Approached {
        Approached {
            v0_m_s: v0,
            bounce: None,
            unknown: false,
        }
    }

    fn scene() -> Scene {
        let mut s = Scene::new(
            Calibration {
                gain_m_s2_per_count: 0.5,
                sample_rate_hz: 100_000.0,
            },
            50.0,
        );
        s.train = Some(Train::new());
        s
    }

    #[test]
    fn the_first_impact_and_a_long_flight_take_the_scenes_speed() {
        let s = scene();
        let t = Tracker::new();
        assert_eq!(t.approach(&s, 1e4, Some(1.5), false), plain(Some(1.5)));
        let t = Tracker {
            separation: Some(0.0),
            last_end: Some(0.0),
            rebound_m_s: Some(1.0),
            separation_deformation_m: 0.0,
            number: 0,
        };
        // 2.5 s of flight: a new drop.
        assert_eq!(
            t.approach(&s, 250_000.0, Some(1.5), false),
            plain(Some(1.5))
        );
    }

    #[test]
    fn without_a_train_the_scenes_speed_is_the_first_impacts() {
        let mut s = scene();
        s.train = None;
        let t = Tracker {
            separation: None,
            last_end: Some(0.0),
            rebound_m_s: None,
            separation_deformation_m: 0.0,
            number: 0,
        };
        // 0.1 s after the previous contact: a bounce, at a speed nothing measured.
        let bounce = t.approach(&s, 10_000.0, Some(1.5), false);
        assert_eq!((bounce.v0_m_s, bounce.unknown), (None, true));
        // A light gate's reading, or a rig that says every impact comes at v0, holds.
        assert_eq!(t.approach(&s, 10_000.0, Some(1.5), true), plain(Some(1.5)));
        s.v0_every = true;
        assert_eq!(t.approach(&s, 10_000.0, Some(1.5), false), plain(Some(1.5)));
        s.v0_every = false;
        // Beyond a train's longest flight: a new drop. No speed given: nothing is unknown.
        assert_eq!(
            t.approach(&s, 250_000.0, Some(1.5), false),
            plain(Some(1.5))
        );
        assert_eq!(t.approach(&s, 10_000.0, None, false), plain(None));
        // The first impact of the stream takes it.
        assert_eq!(
            Tracker::new().approach(&s, 10_000.0, Some(1.5), false),
            plain(Some(1.5))
        );
    }

    #[test]
    fn a_train_that_could_not_time_a_flight_gives_a_bounce_no_speed() {
        let s = scene();
        // The previous contact ended (a gap in it: no separation to time from) 0.1 s ago.
        let t = Tracker {
            separation: None,
            last_end: Some(0.0),
            rebound_m_s: None,
            separation_deformation_m: 0.0,
            number: 0,
        };
        let a = t.approach(&s, 10_000.0, Some(1.5), false);
        assert_eq!((a.v0_m_s, a.unknown), (None, true));
        assert_eq!(t.approach(&s, 10_000.0, Some(1.5), true), plain(Some(1.5)));
        // A level the signal settled at (a release's jolt) is no contact: the drop's first
        // impact keeps the scene's speed.
        let mut t = Tracker::new();
        let mut settled = Summary::EMPTY;
        settled.status = Status::Settled;
        settled.end_index = 1000;
        t.ended(&settled, &s);
        assert_eq!(t.approach(&s, 10_000.0, Some(1.5), false), plain(Some(1.5)));
    }

    #[test]
    fn a_bounce_gets_both_speeds_and_the_scene_picks_one() {
        let mut s = scene();
        let t = Tracker {
            separation: Some(1000.0),
            last_end: Some(1000.0),
            rebound_m_s: Some(0.4),
            separation_deformation_m: 0.0,
            number: 2,
        };
        // 0.1 s of flight: g t / 2 = 0.4903 m/s.
        let a = t.approach(&s, 11_000.0, Some(1.5), false);
        let (v0, b) = (a.v0_m_s, a.bounce.unwrap());
        assert_eq!(b.number, 3);
        assert!((b.flight_s - 0.1).abs() < 1e-6);
        assert!((b.v0_flight_m_s - 0.490_332_5).abs() < 1e-5);
        assert_eq!(v0, Some(b.v0_flight_m_s));
        s.train = Some(Train {
            speed: TrainSpeed::Rebound,
            ..Train::new()
        });
        assert_eq!(s.train.unwrap().speed.name(), "rebound");
        // Up at 0.4 m/s, down 0.1 s later at g t - 0.4.
        let v0 = t.approach(&s, 11_000.0, Some(1.5), false).v0_m_s.unwrap();
        assert!((v0 - (0.980_665 - 0.4)).abs() < 1e-6, "{v0}");
        // A rebound the flight could not have come back from: no speed.
        let fast = Tracker {
            rebound_m_s: Some(1.0),
            ..t
        };
        assert_eq!(fast.approach(&s, 11_000.0, Some(1.5), false).v0_m_s, None);
        // No rebound to chain from: no speed, but the bounce is still reported.
        let t = Tracker {
            rebound_m_s: None,
            ..t
        };
        let a = t.approach(&s, 11_000.0, Some(1.5), false);
        assert_eq!(a.v0_m_s, None);
        assert!(a.bounce.is_some() && !a.unknown);
    }

    #[test]
    fn a_bounce_lands_where_the_pad_is_after_the_flight() {
        let s = scene();
        let g = s.gravity_m_s2;
        // 0.1 s of flight after a contact that left the body 2 mm deep.
        let t = Tracker {
            separation: Some(1000.0),
            last_end: Some(1000.0),
            rebound_m_s: None,
            separation_deformation_m: 2e-3,
            number: 1,
        };
        let half = g * 0.1 / 2.0;
        let speeds = |t: &Tracker| {
            let b = t.approach(&s, 11_000.0, Some(1.5), false).bounce.unwrap();
            (b.landing_height_m, b.v0_flight_m_s, b.v0_rebound_m_s)
        };
        // No rebound: the pad recovered, and the body lands 2 mm above where it left, slower.
        let (h, flight, rebound) = speeds(&t);
        assert_eq!((h, rebound), (2e-3, None));
        assert!((flight - (half - 0.02)).abs() < 1e-6, "{flight}");
        // A rebound at the take-off speed of a recovered pad: the same.
        let up = half + 2e-3 / 0.1;
        let (h, flight, rebound) = speeds(&Tracker {
            rebound_m_s: Some(up),
            ..t
        });
        assert_eq!(h, 2e-3);
        assert!((flight - (half - 0.02)).abs() < 1e-6, "{flight}");
        // The rebound's measure, brought down by the flight's time: the flight's speed.
        let landed = rebound.unwrap();
        assert!((landed - (g * 0.1 - up)).abs() < 1e-6);
        assert!(
            (landed - flight).abs() < 1e-4 * flight,
            "{landed} vs {flight}"
        );
        // A rebound at the take-off speed of a crushed pad, the two 4 % apart: it lands where
        // it left (the rebound's measure needs no landing).
        let (h, flight, rebound) = speeds(&Tracker {
            rebound_m_s: Some(half * 1.001),
            ..t
        });
        assert_eq!((h, flight), (0.0, half));
        assert!((rebound.unwrap() - half * 0.999).abs() < 1e-6);
        // 0.5 mm: the two 1 % apart, within what the rebound can tell: the pad recovered.
        let (h, _, _) = speeds(&Tracker {
            rebound_m_s: Some(half * 1.001),
            separation_deformation_m: 5e-4,
            ..t
        });
        assert_eq!(h, 5e-4);
        // A deformation no flight of 0.1 s rises from (it would land upwards), or one the
        // rebound could not have climbed: it lands where it left.
        let (h, flight, _) = speeds(&Tracker {
            separation_deformation_m: 0.06,
            ..t
        });
        assert_eq!((h, flight), (0.0, half));
        let (h, _, _) = speeds(&Tracker {
            rebound_m_s: Some(0.01),
            ..t
        });
        assert_eq!(h, 0.0);
        // A separation the sums did not find (0): nothing rises.
        let (h, flight, _) = speeds(&Tracker {
            rebound_m_s: Some(up),
            separation_deformation_m: 0.0,
            ..t
        });
        assert_eq!((h, flight), (0.0, half));
    }
}
