//! Value parsers the options share, and the limits of the quantities they give
//! ([`impact_io::limits`]): the same limits check an option, a scene file's key and a file's
//! property.

use impact_io::limits::{positive, Limits};
pub use impact_io::limits::{LEVEL_M_S2, RATE_HZ};

/// The body's mass, kg: up to the core's heaviest impactor
/// ([`impact_core::scene::MAX_MASS_KG`]).
pub const MASS_KG: Limits = Limits {
    high: impact_core::scene::MAX_MASS_KG as f64,
    ..positive("kg")
};

/// A time (hold, settle, longest impact, longest flight), s.
pub const SECONDS: Limits = positive("s");

/// An approach speed, m/s.
pub const SPEED_M_S: Limits = positive("m/s");

/// A drop height, m.
pub const HEIGHT_M: Limits = positive("m");

/// Gravity along the sensor's axis, m/s².
pub const GRAVITY_M_S2: Limits = positive("m/s²");

/// A frequency (the lowest spectrum band), Hz.
pub const FREQUENCY_HZ: Limits = positive("Hz");

/// The factor the channel's values are multiplied by first (`--gain`).
pub const GAIN: Limits = positive("");

/// The nonlinear model's exponent when it is not fitted (the core's `[1, 4]`).
pub const EXPONENT: Limits = Limits {
    low: 1.0,
    high: 4.0,
    unit: "",
};

/// Why an option's number was refused (clap names the option and the value given).
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum NumberError {
    #[error("not a number")]
    NotANumber,
    #[error(transparent)]
    OutOfRange(#[from] impact_io::limits::OutOfRange),
    #[error("must be finite and > 0")]
    NotPositive,
}

/// A command-line number within `limits`.
fn within(s: &str, limits: &Limits) -> Result<f64, NumberError> {
    match s.trim().parse::<f64>() {
        Ok(v) => Ok(limits.check(v)?),
        Err(_) => Err(NumberError::NotANumber),
    }
}

/// `--rate`, Hz ([`RATE_HZ`]).
pub fn rate_hz(s: &str) -> Result<f64, NumberError> {
    within(s, &RATE_HZ)
}

/// `--mass`, kg ([`MASS_KG`]).
pub fn mass_kg(s: &str) -> Result<f64, NumberError> {
    within(s, &MASS_KG)
}

/// `--hold`, `--settle`, `--max-impact`, `--max-flight`, s ([`SECONDS`]).
pub fn seconds(s: &str) -> Result<f64, NumberError> {
    within(s, &SECONDS)
}

/// `--v0`, m/s ([`SPEED_M_S`]).
pub fn speed_m_s(s: &str) -> Result<f64, NumberError> {
    within(s, &SPEED_M_S)
}

/// `--drop-height`, m ([`HEIGHT_M`]).
pub fn height_m(s: &str) -> Result<f64, NumberError> {
    within(s, &HEIGHT_M)
}

/// `--gravity`, m/s² ([`GRAVITY_M_S2`]).
pub fn gravity_m_s2(s: &str) -> Result<f64, NumberError> {
    within(s, &GRAVITY_M_S2)
}

/// `--srs-low`, Hz ([`FREQUENCY_HZ`]).
pub fn frequency_hz(s: &str) -> Result<f64, NumberError> {
    within(s, &FREQUENCY_HZ)
}

/// `--gain` ([`GAIN`]).
pub fn gain(s: &str) -> Result<f64, NumberError> {
    within(s, &GAIN)
}

/// A command-line number that must be finite and > 0 (a count or a factor the core does not
/// take as f32; quantities have their limits above).
pub fn positive_f64(s: &str) -> Result<f64, NumberError> {
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        Ok(_) => Err(NumberError::NotPositive),
        Err(_) => Err(NumberError::NotANumber),
    }
}
