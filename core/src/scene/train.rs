//! A scene's bounce-train settings: which measure of a bounce's approach speed the
//! kinematics use, the longest flight (gravity is the scene's) ([`crate::stream::train`] follows a train).

/// Which measure of a bounce's approach speed the kinematics use.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum TrainSpeed {
    /// `g t / 2 - h / t` from the flight `t` since the previous separation and the landing
    /// height `h` (`stream/train.rs`): each bounce measured afresh (the default).
    Flight,
    /// The previous impact's rebound `v_r` (`Δv - v0 - g t_c`) brought down by the flight
    /// `t`, `g t - v_r` (vertical flight, no landing height needed): a chain, each bounce
    /// keeping the previous one's speed error and adding its contact's Δv error.
    Rebound,
}

impl TrainSpeed {
    /// The name options and reports use (`flight`, `rebound`).
    pub fn name(self) -> &'static str {
        match self {
            TrainSpeed::Flight => "flight",
            TrainSpeed::Rebound => "rebound",
        }
    }
}

/// A scene's bounce-train settings. SI units.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Train {
    /// The approach speed the kinematics use for bounces after the first.
    pub speed: TrainSpeed,
    /// A flight longer than this starts a new train, s (default 2 s: a 4.9 m bounce).
    pub max_flight_s: f32,
}

impl Train {
    /// Flights up to 2 s, the kinematics on the flight time.
    pub const fn new() -> Self {
        Self {
            speed: TrainSpeed::Flight,
            max_flight_s: 2.0,
        }
    }
}

impl Default for Train {
    fn default() -> Self {
        Self::new()
    }
}
