//! Bounce trains on the host: the `--train` options, each bounce's two approach speeds and
//! CORs in the reports, and each train's COR against impact speed (constant, as a
//! Kelvin–Voigt contact gives, or falling with speed, as the nonlinear law does).

use clap::{Args, ValueEnum};
use impact_core::{Train, TrainSpeed};

use crate::parse::positive_f64;

/// Which measure of a bounce's approach speed the kinematics use.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum SpeedArg {
    /// `g t_flight / 2`, from the flight since the previous separation.
    Flight,
    /// The previous impact's rebound (`Δv - v0`).
    Rebound,
}

/// `--train` options (flattened into `analyze` and `emulate`).
#[derive(Args, Clone, Debug, Default)]
pub struct TrainArgs {
    /// Bounce trains: each bounce's v0 from its flight time or from the previous rebound.
    ///
    /// Bounce trains: each impact after the first of a drop takes its approach speed from the
    /// flight time since the previous separation (`flight`, vertical flight under gravity
    /// along the sensor's axis, no drag) or from the previous rebound (`rebound`); the first
    /// impact takes --v0, --drop-height or --free-fall. Both speeds are reported.
    #[arg(long, help_heading = "Analysis", value_enum)]
    pub train: Option<SpeedArg>,
    /// Gravity along the sensor's axis, m/s² [default: 9.80665].
    #[arg(long, help_heading = "Analysis", requires = "train", value_parser = positive_f64)]
    pub gravity: Option<f64>,
    /// A flight longer than this starts a new train (a new drop), s [default: 2].
    #[arg(long, help_heading = "Analysis", requires = "train", value_parser = positive_f64)]
    pub max_flight: Option<f64>,
}

impl TrainArgs {
    /// The scene's train settings, if asked for.
    pub fn train(&self) -> Option<Train> {
        let speed = match self.train? {
            SpeedArg::Flight => TrainSpeed::Flight,
            SpeedArg::Rebound => TrainSpeed::Rebound,
        };
        let d = Train::new();
        Some(Train {
            speed,
            gravity_m_s2: self.gravity.map_or(d.gravity_m_s2, |g| g as f32),
            max_flight_s: self.max_flight.map_or(d.max_flight_s, |t| t as f32),
        })
    }
}
