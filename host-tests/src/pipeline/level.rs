//! Levels given for a channel, with or without a unit (`--trigger 5g`, `--range 16g`; a bare
//! number is in m/s²), on the command line and in a scene file.

use std::fmt;

use impact_io::units::Units;
use serde::{Deserialize, Deserializer};

/// A level of the channel (`--trigger`, `--edge`, `--range`): a number in m/s², or with a
/// unit (`5g`, `16 g`, `2kgn`, `490m/s2`, `200n` for a force channel).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Level {
    pub value: f64,
    pub units: Units,
}

impl Level {
    /// A level in m/s².
    pub const fn m_s2(value: f64) -> Self {
        Self {
            value,
            units: Units::MS2,
        }
    }

    /// The level in m/s² (a force over the mass).
    pub fn to_m_s2(self, mass_kg: Option<f64>) -> f64 {
        self.value * self.units.to_m_s2(mass_kg)
    }

    /// Parses `VALUE[UNIT]`: finite and > 0.
    pub fn parse(s: &str) -> Result<Level, LevelError> {
        let s = s.trim();
        let split = s
            .find(|c: char| c.is_alphabetic() && c != 'e' && c != 'E')
            .unwrap_or(s.len());
        let (number, unit) = s.split_at(split);
        let value: f64 = number.trim().parse().map_err(|_| LevelError::NotANumber {
            text: s.to_string(),
        })?;
        if !(value.is_finite() && value > 0.0) {
            return Err(LevelError::NotPositive);
        }
        let units = match unit.trim().to_lowercase().as_str() {
            "" | "m/s2" | "m/s²" | "m/s^2" | "ms2" | "m_s2" => Units::MS2,
            "g" => Units::G,
            "kgn" | "kg_n" => Units::Kgn,
            "n" => Units::N,
            other => {
                return Err(LevelError::Unit {
                    unit: other.to_string(),
                })
            }
        };
        Ok(Level { value, units })
    }
}

impl fmt::Display for Level {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let value = impact_io::limits::number(self.value);
        match self.units {
            Units::MS2 => write!(f, "{value} m/s²"),
            u => write!(f, "{value}{}", u.name()),
        }
    }
}

/// Why a level was refused (clap names the option and the value given; a scene file's
/// reader, the key).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum LevelError {
    /// The number part (`text`: the level as given, trimmed) is not a number.
    #[error("{text:?} is not a number with an optional unit (5, 5g, 49m/s2)")]
    NotANumber { text: String },
    #[error("must be finite and > 0")]
    NotPositive,
    /// A unit (lower-cased, as given) none of those a level takes.
    #[error("unit {unit:?}: one of m/s2 (the default), g, kgn, n")]
    Unit { unit: String },
}

impl std::str::FromStr for Level {
    type Err = LevelError;
    fn from_str(s: &str) -> Result<Self, LevelError> {
        Level::parse(s)
    }
}

/// A level in a scene file: a number (m/s²) or a string with a unit (`"16g"`). (Read through
/// `serde_json::Value`: a dependency turns on serde_json's `arbitrary_precision`, under which
/// an untagged enum cannot take a number.)
impl<'de> Deserialize<'de> for Level {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::Error;
        match serde_json::Value::deserialize(d)? {
            serde_json::Value::Number(n) => match n.as_f64() {
                Some(v) if v.is_finite() && v > 0.0 => Ok(Level::m_s2(v)),
                _ => Err(D::Error::custom(format!("{n}: must be finite and > 0"))),
            },
            serde_json::Value::String(s) => Level::parse(&s).map_err(D::Error::custom),
            other => Err(D::Error::custom(format!(
                "{other}: a level is a number (m/s²) or a string with its unit (\"16g\")"
            ))),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scene_files_give_levels_as_numbers_or_with_units() {
        let l: Level = serde_json::from_str("980.665").unwrap();
        assert_eq!(l, Level::m_s2(980.665));
        let l: Level = serde_json::from_str("\"16g\"").unwrap();
        assert_eq!(l.units, Units::G);
        assert!(serde_json::from_str::<Level>("-1").is_err());
        assert!(serde_json::from_str::<Level>("true").is_err());
    }

    #[test]
    fn levels_take_an_optional_unit() {
        assert_eq!(Level::parse("49"), Ok(Level::m_s2(49.0)));
        assert_eq!(Level::parse("1e3"), Ok(Level::m_s2(1000.0)));
        let g = Level::parse("5g").unwrap();
        assert!((g.to_m_s2(None) - 49.03325).abs() < 1e-9);
        assert_eq!(Level::parse("16 g").unwrap().units, Units::G);
        assert_eq!(Level::parse("2kgn").unwrap().units, Units::Kgn);
        assert_eq!(Level::parse("2.5E1m/s2"), Ok(Level::m_s2(25.0)));
        assert!((Level::parse("200n").unwrap().to_m_s2(Some(2.0)) - 100.0).abs() < 1e-12);
        assert!(Level::parse("5 furlongs").is_err());
        assert!(Level::parse("-5g").is_err());
        assert!(Level::parse("NaN").is_err());
        assert!(Level::parse("g").is_err());
    }
}
