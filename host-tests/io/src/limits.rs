//! The values the analysis accepts for a quantity: the range within which the core's f32
//! arithmetic holds it. One check for every option, scene file key and file property that
//! gives one, so that a value the core cannot hold is refused as what it is (out of range)
//! and by the name it was given, not by the core's f32 that it overflowed or underflowed to.

use std::fmt;

/// The accepted values of a quantity: from `low` to `high`, both included, in `unit`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Limits {
    pub low: f64,
    pub high: f64,
    /// The unit as messages write it (`kg`, `m/s²`, `Hz`; empty for a plain factor).
    pub unit: &'static str,
}

/// A positive quantity in `unit`: thirty decades either side of 1, so that it is a normal
/// f32 (1.2e-38 to 3.4e38) and so are the products and quotients of two of them.
pub const fn positive(unit: &'static str) -> Limits {
    Limits {
        low: 1e-30,
        high: 1e30,
        unit,
    }
}

/// A sample rate, Hz: positive, up to the core's 100 MHz
/// ([`impact_core::scene::MAX_RATE_HZ`]).
pub const RATE_HZ: Limits = Limits {
    high: impact_core::scene::MAX_RATE_HZ as f64,
    ..positive("Hz")
};

/// A level of the channel or its full scale, m/s² (the quantisation's gain is the full
/// scale over 32 000 counts: [`crate::quantise::gain_for`]).
pub const LEVEL_M_S2: Limits = positive("m/s²");

impl Limits {
    /// Whether `value` lies within (never for NaN).
    pub fn contains(&self, value: f64) -> bool {
        value >= self.low && value <= self.high
    }

    /// `value` if it lies within; else the error, `out of range (between LOW and HIGH
    /// UNIT)`.
    pub fn check(&self, value: f64) -> Result<f64, OutOfRange> {
        if self.contains(value) {
            Ok(value)
        } else {
            Err(OutOfRange {
                value,
                limits: *self,
            })
        }
    }

    /// [`Limits::check`] naming the value and where it came from (`what`: an option, a
    /// file's key): `--mass 1e300: out of range (between 1e-30 and 1e6 kg)`.
    pub fn check_named(&self, what: &str, value: f64) -> Result<f64, NamedOutOfRange> {
        self.check(value).map_err(|range| NamedOutOfRange {
            what: what.to_string(),
            range,
        })
    }

    /// The limits of the reciprocal (an interval's from a rate's), in `unit`.
    pub fn reciprocal(&self, unit: &'static str) -> Limits {
        Limits {
            low: 1.0 / self.high,
            high: 1.0 / self.low,
            unit,
        }
    }
}

/// A value outside its limits.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
#[error("out of range ({limits})")]
pub struct OutOfRange {
    pub value: f64,
    pub limits: Limits,
}

/// A value outside its limits, with the name it was given by (an option, a file's key).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{what} {}: {range}", number(.range.value))]
pub struct NamedOutOfRange {
    pub what: String,
    pub range: OutOfRange,
}

impl fmt::Display for Limits {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "between {} and {}", number(self.low), number(self.high))?;
        if !self.unit.is_empty() {
            write!(f, " {}", self.unit)?;
        }
        Ok(())
    }
}

/// Longest record (line) read, bytes: a file without line breaks (`/dev/zero`) or with an
/// unclosed quote is an error, not a memory blow-up.
pub const MAX_LINE_BYTES: usize = 1 << 20;

/// Largest magnitude a value may have: beyond it no sensor reading or time is meant (and the
/// f32 sample path would overflow).
pub const MAX_VALUE: f64 = 1e30;

/// Intervals per block of the drift check ([`crate::channel::Drift`]).
pub const DRIFT_BLOCK: u64 = 1024;
/// Largest difference of a block's mean interval from the first block's (1 %): a sample
/// clock is steady to parts per million; a time axis whose interval drifts further (each
/// step may stay well inside [`crate::channel::INTERVAL_RANGE`]) is no even grid, and
/// taking it for one puts the impacts at the wrong times with the wrong Δv.
pub const DRIFT_LIMIT: f64 = 0.01;

/// `x` with `digits` significant digits, without trailing zeros (`1000000`, `19986.9`, `20`).
pub fn sig(x: f64, digits: usize) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let decimals = (digits as i32 - 1 - x.abs().log10().floor() as i32).max(0) as usize;
    let s = format!("{x:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// A number as a message writes it, to 12 significant digits (`1e30`, not the
/// `9.999999999999999e29` that `1 / 1e-30` is): plain from 1e-4 to below 1e6, else with its
/// exponent (`1e6`, `1e300`, `2.5e-40`), never hundreds of digits.
pub fn number(value: f64) -> String {
    let value: f64 = format!("{value:.11e}").parse().unwrap_or(value);
    let a = value.abs();
    if a == 0.0 || !a.is_finite() || (1e-4..1e6).contains(&a) {
        format!("{value}")
    } else {
        format!("{value:e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_name_the_value_and_the_range() {
        let mass = Limits {
            high: 1e6,
            ..positive("kg")
        };
        assert_eq!(
            mass.check_named("--mass", 1e300).unwrap_err().to_string(),
            "--mass 1e300: out of range (between 1e-30 and 1e6 kg)"
        );
        assert_eq!(mass.check(0.06), Ok(0.06));
        assert!(mass.check(f64::NAN).is_err());
        assert!(mass.check(-1.0).is_err());
        assert_eq!(
            RATE_HZ.reciprocal("s").to_string(),
            "between 1e-8 and 1e30 s"
        );
        assert_eq!(number(0.002), "0.002");
        assert_eq!(number(1e-300), "1e-300");
        assert_eq!(number(1e6), "1e6");
        assert_eq!(number(f64::INFINITY), "inf");
    }
}
