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

/// A frequency (the lowest or highest spectrum band), Hz.
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

/// `--srs-low` and `--srs-high`, Hz ([`FREQUENCY_HZ`]).
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

/// `--lowpass ORDER,CUTOFF`: a Butterworth low-pass's order and cut-off, Hz.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LowpassArg {
    pub order: u8,
    pub cutoff_hz: f64,
}

/// Why `--lowpass` was refused (clap names the option and the value given); each says the
/// fix. Its cut-off against the recording's rate is checked with the rate
/// (`pipeline::PipelineError::LowpassCutoff`).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum LowpassArgError {
    #[error(
        "expected ORDER,CUTOFF: an order of 1 to 8 and a cut-off in Hz (`4,1000` or `4,1kHz`)"
    )]
    Shape,
    #[error(
        "order `{0}`: the order must be a whole number from 1 to 8 (each pass rolls off at 6 dB \
         per octave per order; 2 or 4 are usual): `4,1000`"
    )]
    Order(String),
    #[error(
        "cut-off `{given}`: {why}; give Hz as a number or with a unit: `1000`, `1000Hz`, \
         `1kHz`, `0.5MHz`"
    )]
    Cutoff { given: String, why: NumberError },
}

/// `--lowpass`: ORDER (1 to 8) and CUTOFF (Hz, a bare number or with `Hz`, `kHz`, `MHz`).
pub fn lowpass(s: &str) -> Result<LowpassArg, LowpassArgError> {
    use impact_core::signal::lowpass::{MAX_ORDER, MIN_ORDER};
    let (order, cutoff) = s.split_once(',').ok_or(LowpassArgError::Shape)?;
    let order_ok = order
        .trim()
        .parse::<u8>()
        .ok()
        .filter(|o| (MIN_ORDER..=MAX_ORDER).contains(o));
    let Some(order) = order_ok else {
        return Err(LowpassArgError::Order(order.trim().to_string()));
    };
    let given = cutoff.trim();
    let lower = given.to_ascii_lowercase();
    let (number, scale) = [("mhz", 1e6), ("khz", 1e3), ("hz", 1.0)]
        .into_iter()
        .find_map(|(unit, scale)| lower.strip_suffix(unit).map(|n| (n, scale)))
        .unwrap_or((lower.as_str(), 1.0));
    let cutoff_hz = within(number, &FREQUENCY_HZ)
        .and_then(|v| Ok(FREQUENCY_HZ.check(v * scale)?))
        .map_err(|why| LowpassArgError::Cutoff {
            given: given.to_string(),
            why,
        })?;
    Ok(LowpassArg { order, cutoff_hz })
}

#[cfg(test)]
mod lowpass_tests {
    use super::*;

    #[test]
    fn takes_an_order_and_a_cutoff_with_or_without_a_unit() {
        let lp = |order, cutoff_hz| Ok(LowpassArg { order, cutoff_hz });
        assert_eq!(lowpass("4,1000"), lp(4, 1000.0));
        assert_eq!(lowpass("4,1kHz"), lp(4, 1000.0));
        assert_eq!(lowpass("2, 1.5 kHz"), lp(2, 1500.0));
        assert_eq!(lowpass("1,250Hz"), lp(1, 250.0));
        assert_eq!(lowpass("8,0.1MHz"), lp(8, 100_000.0));
        assert_eq!(lowpass("3,2khz"), lp(3, 2000.0));
    }

    #[test]
    fn refuses_a_bad_order_or_cutoff_with_the_fix() {
        assert_eq!(lowpass("4"), Err(LowpassArgError::Shape));
        for bad in ["0", "9", "-1", "2.5", "four", ""] {
            assert_eq!(
                lowpass(&format!("{bad},1000")),
                Err(LowpassArgError::Order(bad.to_string())),
                "{bad}"
            );
        }
        for bad in ["0", "-5", "1 kg", "fast", "nan", "inf", "kHz", "1e40"] {
            let e = lowpass(&format!("4,{bad}")).unwrap_err();
            assert!(matches!(e, LowpassArgError::Cutoff { .. }), "{bad}: {e:?}");
            assert!(e.to_string().contains("`1kHz`"), "{e}");
        }
        assert!(lowpass("9,1000")
            .unwrap_err()
            .to_string()
            .contains("1 to 8"));
    }
}
