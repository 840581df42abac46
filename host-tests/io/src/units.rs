//! Units of a recorded channel: what a header names (`bottom_kgn`, `x_g`, `table_m_s2`,
//! `force_n`) and what `--units` states.

use impact_core::consts::STANDARD_GRAVITY;

use crate::channel::words;
use crate::error::{Opt, OptionNames};

/// Units of a recorded channel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum, serde::Deserialize))]
/// Scene files use the command line's spellings (`g`, `m/s2`, `kgn`, `n`).
pub enum Units {
    /// Standard gravities (9.80665 m/s²).
    #[cfg_attr(feature = "cli", serde(rename = "g", alias = "G"))]
    G,
    /// m/s².
    #[cfg_attr(feature = "cli", value(name = "m/s2"))]
    #[cfg_attr(feature = "cli", serde(rename = "m/s2", alias = "MS2", alias = "ms2"))]
    MS2,
    /// Kilo-g (1000 g), as in the AFRL drop-tower data.
    #[cfg_attr(feature = "cli", serde(rename = "kgn", alias = "Kgn"))]
    Kgn,
    /// Force in N (divided by the mass, or by 1 kg if none is given).
    #[cfg_attr(feature = "cli", serde(rename = "n", alias = "N"))]
    N,
}

impl Units {
    /// m/s² per unit (per N: one over the mass, 1 kg if none is given).
    pub fn to_m_s2(self, mass_kg: Option<f64>) -> f64 {
        match self {
            Units::G => STANDARD_GRAVITY,
            Units::MS2 => 1.0,
            Units::Kgn => 1000.0 * STANDARD_GRAVITY,
            Units::N => 1.0 / mass_kg.unwrap_or(1.0),
        }
    }

    /// The unit's name as `--units` spells it.
    pub fn name(self) -> &'static str {
        match self {
            Units::G => "g",
            Units::MS2 => "m/s2",
            Units::Kgn => "kgn",
            Units::N => "n",
        }
    }

    /// The unit a column header names in a word after its first (`x_g`, `bottom_kgn`,
    /// `table_m_s2`, `accel [m/s²]`, `force_n`, `Force (N)`); `None` if it names none.
    pub fn of_header(header: &str) -> Option<Units> {
        let h = header.to_lowercase();
        let w: Vec<&str> = words(&h).skip(1).collect();
        // m/s², m/s^2, m_s2, ms2, mps2 (as two words or one).
        let m_s2 = w
            .windows(2)
            .any(|p| p[0] == "m" && matches!(p[1], "s2" | "s²" | "s" | "sec2"))
            || w.iter().any(|x| matches!(*x, "ms2" | "mps2" | "ms²"));
        if m_s2 {
            return Some(Units::MS2);
        }
        if w.windows(2).any(|p| p[0] == "kg" && p[1] == "n") {
            return Some(Units::Kgn);
        }
        w.iter().rev().find_map(|x| match *x {
            "g" | "gs" | "gee" => Some(Units::G),
            "kgn" | "kgs" => Some(Units::Kgn),
            "n" | "newton" | "newtons" => Some(Units::N),
            _ => None,
        })
    }

    /// The channel's units: the ones stated (`--units` or the scene file), else the ones its
    /// header names, else g; an error naming both if they disagree.
    pub fn resolve(stated: Option<Units>, column: &str) -> Result<Units, UnitsConflict> {
        match (stated, Units::of_header(column)) {
            (Some(s), Some(h)) if s != h => Err(UnitsConflict {
                stated: s,
                header: column.to_string(),
                named: h,
            }),
            (Some(s), _) => Ok(s),
            (None, Some(h)) => Ok(h),
            (None, None) => Ok(Units::G),
        }
    }
}

/// Units stated that the channel's header contradicts.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub struct UnitsConflict {
    pub stated: Units,
    /// The header, and the units it names.
    pub header: String,
    pub named: Units,
}

impl UnitsConflict {
    /// The message, naming the stated units' setting as `n` does.
    pub fn display_with(&self, n: OptionNames) -> impl std::fmt::Display + '_ {
        struct D<'a>(&'a UnitsConflict, OptionNames);
        impl std::fmt::Display for D<'_> {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                let (e, units) = (self.0, (self.1)(Opt::Units));
                write!(
                    f,
                    "{units} {} contradicts the column's header {:?}, which names {}: drop {units} or choose another column",
                    e.stated.name(),
                    e.header,
                    e.named.name()
                )
            }
        }
        D(self, n)
    }
}

impl std::fmt::Display for UnitsConflict {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.display_with(Opt::field).fmt(f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn headers_name_their_units() {
        for (h, u) in [
            ("x_g", Some(Units::G)),
            ("bottom_kgn", Some(Units::Kgn)),
            ("table_m_s2", Some(Units::MS2)),
            ("accel [m/s²]", Some(Units::MS2)),
            ("accel_mps2", Some(Units::MS2)),
            ("force_n", Some(Units::N)),
            ("Force (N)", Some(Units::N)),
            ("top_kg_n", Some(Units::Kgn)),
            ("response", None),
            ("g", None),
            ("test1", None),
            ("column 2", None),
        ] {
            assert_eq!(Units::of_header(h), u, "{h}");
        }
    }

    #[test]
    fn stated_units_must_agree_with_the_header() {
        assert_eq!(Units::resolve(None, "bottom_kgn"), Ok(Units::Kgn));
        assert_eq!(
            Units::resolve(Some(Units::Kgn), "bottom_kgn"),
            Ok(Units::Kgn)
        );
        assert_eq!(Units::resolve(None, "test1"), Ok(Units::G));
        assert_eq!(Units::resolve(Some(Units::MS2), "test1"), Ok(Units::MS2));
        let e = Units::resolve(Some(Units::G), "table_m_s2")
            .unwrap_err()
            .to_string();
        assert!(e.contains("`units` g") && e.contains("m/s2"), "{e}");
    }
}
