//! `--spec SHAPE,PEAK,DURATION[,KEY=VALUE…]`: the specified shock pulse each impact is judged
//! against, with the tolerances of a standard (`standard=`) or the user's own. Every number of
//! every preset and its source: docs/standards.md.

use std::path::{Path, PathBuf};

use impact_core::consts::STANDARD_GRAVITY;
use impact_core::spec::{Shape, Spec};

use super::band_file::{self, BandFileError};

use crate::standards::STANDARDS;

/// A parsed `--spec`: the pulse with its tolerances, and the standard they start from
/// (`custom` once a tolerance is set by hand).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpecArg {
    pub spec: Spec,
    pub standard: &'static str,
    /// The user's band's file (`band-file=`): an input, which no output may overwrite.
    pub band_file: Option<&'static Path>,
    /// The peak and the duration as written with no unit (m/s² and s taken).
    pub bare: (bool, bool),
}

/// Why a `--spec` was refused (clap names the option and the value given). The texts held
/// are the parts as given.
#[derive(Debug, thiserror::Error)]
pub enum SpecError {
    #[error("SHAPE,PEAK,DURATION (half-sine,50g,11ms), then KEY=VALUE tolerances")]
    Form,
    #[error("peak {text:?}: not a number with an optional unit (50g, 490m/s2)")]
    PeakNotANumber { text: String },
    #[error("peak {text:?}: must be between 1e-30 and 1e30 m/s²")]
    PeakRange { text: String },
    #[error("duration {text:?}: not a number with an optional unit (11ms, 0.011)")]
    DurationNotANumber { text: String },
    #[error("duration {text:?}: must be between 1e-30 and 1e30 s")]
    DurationRange { text: String },
    /// A part after the duration without its `=`.
    #[error("{part:?}: KEY=VALUE (standard=, band=, dv=, …)")]
    NotKeyValue { part: String },
    #[error("standard={name}: one of {}", STANDARDS.map(|s| s.name).join(", "))]
    Standard { name: String },
    #[error("{key}={value}: not a number")]
    NotANumber { key: String, value: String },
    /// A key none of the tolerances (`trapezoid`: whether the shape takes `rise` and `fall`).
    #[error(
        "{key}: one of standard, band-file, band, outside, slack, dv, before, after, watch{}",
        if *.trapezoid { ", rise, fall" } else { " (rise, fall: a trapezoid's)" }
    )]
    Key { key: String, trapezoid: bool },
    #[error("shape {name:?}: one of half-sine, sawtooth (terminal-peak), trapezoid")]
    Shape { name: String },
    /// A shape the standard does not specify (MIL-STD-202H: half-sine and sawtooth only).
    #[error("{shape}: {title} specifies only {}; give another standard=", .shapes.join(" and "))]
    NotInStandard {
        shape: String,
        title: &'static str,
        shapes: &'static [&'static str],
    },
    /// The pulse or its tolerances refused by the core (a parameter named by the core's
    /// name: `spec-tolerance`).
    #[error(transparent)]
    Invalid(#[from] impact_core::Error),
    #[error(transparent)]
    BandFile(#[from] BandFileError),
    /// The pulse with the user's band refused by the core.
    #[error("band-file={}: {source}", .path.display())]
    BandInvalid {
        path: PathBuf,
        source: impact_core::Error,
    },
}

/// An acceleration with an optional unit: `50g`, `490.3m/s2` (m/s² without one).
fn acceleration(s: &str) -> Result<f32, SpecError> {
    let t = s.trim();
    let (num, scale) = if let Some(n) = t.strip_suffix('g') {
        (n, STANDARD_GRAVITY)
    } else {
        let n = ["m/s2", "m/s²", "m/s^2"]
            .iter()
            .find_map(|u| t.strip_suffix(u))
            .unwrap_or(t);
        (n, 1.0)
    };
    let v: f64 = num.trim().parse().map_err(|_| SpecError::PeakNotANumber {
        text: s.to_string(),
    })?;
    let v = v * scale;
    if !(v.is_finite() && (1e-30..=1e30).contains(&v)) {
        return Err(SpecError::PeakRange {
            text: s.to_string(),
        });
    }
    Ok(v as f32)
}

/// A duration with an optional unit: `11ms`, `500us`, `0.011` (s without one).
fn duration(s: &str) -> Result<f32, SpecError> {
    let t = s.trim();
    let (num, scale) = [("ms", 1e-3), ("us", 1e-6), ("µs", 1e-6), ("s", 1.0)]
        .iter()
        .find_map(|(u, k)| t.strip_suffix(u).map(|n| (n, *k)))
        .unwrap_or((t, 1.0));
    let v: f64 = num
        .trim()
        .parse()
        .map_err(|_| SpecError::DurationNotANumber {
            text: s.to_string(),
        })?;
    let v = v * scale;
    if !(v.is_finite() && (1e-30..=1e30).contains(&v)) {
        return Err(SpecError::DurationRange {
            text: s.to_string(),
        });
    }
    Ok(v as f32)
}

/// Parses `--spec`: `SHAPE,PEAK,DURATION` (`half-sine`, `sawtooth` or `trapezoid`; `50g`;
/// `11ms`), then `KEY=VALUE`s: `standard=` (the tolerances' source, [`STANDARDS`]), and any
/// tolerance by hand: `band`, `outside`, `slack`, `dv`, `before`, `after`, `watch` (fractions of
/// the peak or of the duration), a trapezoid's `rise` and `fall`; `band-file=` a user's band
/// (a CSV, [`band_file::read`]) instead of `band` and `slack`.
pub fn parse(s: &str) -> Result<SpecArg, SpecError> {
    let mut parts = s.split(',').map(str::trim);
    let shape_name = parts.next().unwrap_or_default();
    let (Some(peak), Some(dur)) = (parts.next(), parts.next()) else {
        return Err(SpecError::Form);
    };
    let peak_m_s2 = acceleration(peak)?;
    let duration_s = duration(dur)?;
    let mut pairs = Vec::new();
    for p in parts {
        let (k, v) = p.split_once('=').ok_or_else(|| SpecError::NotKeyValue {
            part: p.to_string(),
        })?;
        pairs.push((k.trim(), v.trim()));
    }
    let standard = match pairs.iter().find(|(k, _)| *k == "standard") {
        Some((_, name)) => {
            STANDARDS
                .iter()
                .find(|s| s.name == *name)
                .ok_or_else(|| SpecError::Standard {
                    name: name.to_string(),
                })?
        }
        None => &STANDARDS[0],
    };
    let mut t = standard.tolerance;
    let (mut rise, mut fall) = (standard.ramp, standard.ramp);
    let mut custom = false;
    let mut band_path = None;
    for (k, v) in pairs {
        if k == "standard" {
            continue;
        }
        if k == "band-file" {
            band_path = Some(v);
            continue;
        }
        let x: f32 = v
            .parse()
            .ok()
            .filter(|x: &f32| x.is_finite())
            .ok_or_else(|| SpecError::NotANumber {
                key: k.to_string(),
                value: v.to_string(),
            })?;
        let slot = match k {
            "band" => &mut t.band,
            "outside" => &mut t.outside,
            "slack" => &mut t.slack,
            "dv" => &mut t.delta_v,
            "before" => &mut t.before,
            "after" => &mut t.after,
            "watch" => &mut t.watch,
            "rise" if shape_name == "trapezoid" => &mut rise,
            "fall" if shape_name == "trapezoid" => &mut fall,
            _ => {
                return Err(SpecError::Key {
                    key: k.to_string(),
                    trapezoid: shape_name == "trapezoid",
                });
            }
        };
        *slot = x;
        custom |= !matches!(k, "rise" | "fall");
    }
    if !standard.shapes.contains(&shape_name)
        && ["half-sine", "sawtooth", "trapezoid"].contains(&shape_name)
    {
        return Err(SpecError::NotInStandard {
            shape: shape_name.to_string(),
            title: standard.title,
            shapes: standard.shapes,
        });
    }
    let shape = match shape_name {
        "half-sine" => Shape::HalfSine,
        "sawtooth" => Shape::Sawtooth,
        "trapezoid" => Shape::Trapezoid { rise, fall },
        other => {
            return Err(SpecError::Shape {
                name: other.to_string(),
            })
        }
    };
    let mut spec = Spec {
        shape,
        peak_m_s2,
        duration_s,
        tolerance: t,
        band: None,
    };
    spec.validate()?;
    let mut band_source = None;
    if let Some(path) = band_path {
        // The band is watched over its rows (`Spec::watched`); Δv keeps its window.
        spec.band = Some(band_file::read(Path::new(path), &spec)?);
        spec.validate().map_err(|source| SpecError::BandInvalid {
            path: PathBuf::from(path),
            source,
        })?;
        custom = true;
        band_source = Some(&*Box::leak(PathBuf::from(path).into_boxed_path()));
    }
    let no_unit = |t: &str| t.trim().parse::<f64>().is_ok();
    Ok(SpecArg {
        spec,
        standard: if custom { "custom" } else { standard.name },
        band_file: band_source,
        bare: (no_unit(peak), no_unit(dur)),
    })
}

/// How far apart two positive quantities are, as a factor (≥ 1).
fn factor(a: f64, b: f64) -> f64 {
    if a > 0.0 && b > 0.0 {
        (a / b).max(b / a)
    } else {
        f64::INFINITY
    }
}

/// A note when no impact was judged and the specified pulse is far from every measured one
/// (peak or duration more than 3× off, the nearest impact named): the likely slip named where
/// it fits a unit's factor (a bare peak is m/s², so 11000 meant as g is 9.8× low; a bare
/// duration is s, so 0.1 meant as ms is 1000× long).
pub fn far_from_every_pulse(
    arg: &SpecArg,
    reports: &[impact_core::ImpactReport],
) -> Option<String> {
    if reports.is_empty() || reports.iter().any(|r| matches!(r.verdict, Some(Ok(_)))) {
        return None;
    }
    let spec = &arg.spec;
    let (peak, dur) = (f64::from(spec.peak_m_s2), f64::from(spec.duration_s));
    // The duration a measured pulse shows: its FWHM over the spec shape's (the contact's
    // duration runs on through the ringing after a drop-tower pulse: 466 µs for a 100 µs
    // half-sine), else the contact's.
    let fraction = match spec.shape {
        impact_core::spec::Shape::HalfSine => 2.0 / 3.0,
        impact_core::spec::Shape::Sawtooth => 0.5,
        impact_core::spec::Shape::Trapezoid { rise, fall } => {
            (1.0 - f64::from(rise + fall) / 2.0).max(0.05)
        }
    };
    let nearest = reports
        .iter()
        .map(|r| {
            let p = f64::from(r.peak_acceleration_m_s2.abs());
            let (d, by) = r.fwhm_s.map_or((f64::from(r.duration_s), "contact"), |w| {
                (f64::from(w) / fraction, "FWHM")
            });
            (factor(p, peak).max(factor(d, dur)), p, d, by)
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))?;
    let (off, p, d, by) = nearest;
    if off <= 3.0 {
        return None;
    }
    let mut fixes = Vec::new();
    let g = STANDARD_GRAVITY;
    // Within a factor the unit's own (9.8, 1000) tells apart from no slip at all.
    if arg.bare.0 && (0.33..=3.0).contains(&(p / (peak * g))) {
        fixes.push(format!("a bare peak is m/s²: {}g?", shortest(peak)));
    }
    if arg.bare.1 {
        for (unit, k) in [("ms", 1e-3), ("us", 1e-6)] {
            if (0.2..=5.0).contains(&(d / (dur * k))) {
                fixes.push(format!("a bare duration is s: {}{unit}?", shortest(dur)));
            }
        }
    }
    let human = crate::report::fmt::human;
    Some(format!(
        "--spec: no impact judged, and the specified pulse ({}, {}) is far from every measured one (the nearest: peak {}, duration {} by its {by}){}",
        human(peak, "m/s²"),
        human(dur, "s"),
        human(p, "m/s²"),
        human(d, "s"),
        if fixes.is_empty() {
            String::new()
        } else {
            format!("; {}", fixes.join("; "))
        }
    ))
}

/// The shortest decimal of `v` (as the user might write it).
fn shortest(v: f64) -> String {
    format!("{}", v as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_spec_reads_with_units_and_a_standards_tolerances() {
        let a = parse("half-sine,50g,11ms").unwrap();
        assert_eq!(a.standard, "iec-60068-2-27");
        assert_eq!(a.spec.shape, Shape::HalfSine);
        assert!((a.spec.peak_m_s2 - 490.3325).abs() < 1e-3);
        assert!((a.spec.duration_s - 0.011).abs() < 1e-9);
        assert_eq!(a.spec.tolerance.delta_v, 0.15);
        let b = parse("sawtooth, 300m/s2, 0.006, standard=mil-std-810h").unwrap();
        assert_eq!(
            (b.standard, b.spec.tolerance.delta_v),
            ("mil-std-810h", 0.1)
        );
        let c = parse("trapezoid,100g,6ms,rise=0.2,fall=0.05,dv=0.2").unwrap();
        assert_eq!(c.standard, "custom");
        assert_eq!(
            c.spec.shape,
            Shape::Trapezoid {
                rise: 0.2,
                fall: 0.05
            }
        );
        for (bad, want) in [
            ("half-sine", "SHAPE,PEAK,DURATION"),
            ("square,50g,11ms", "shape \"square\""),
            ("half-sine,50q,11ms", "peak \"50q\""),
            ("half-sine,50g,-1ms", "duration \"-1ms\": must be"),
            ("half-sine,50g,11ms,standard=iso", "standard=iso: one of"),
            ("half-sine,50g,11ms,band=2", "spec-tolerance"),
            ("half-sine,50g,11ms,rise=0.1", "rise: one of"),
            ("half-sine,50g,11ms,dv", "KEY=VALUE"),
        ] {
            let e = parse(bad).unwrap_err().to_string();
            assert!(e.contains(want), "{bad}: {e}");
        }
        // The kinds, with what was given.
        let refused = |s: &str| parse(s).unwrap_err();
        assert!(matches!(refused("half-sine"), SpecError::Form));
        assert!(
            matches!(refused("square,50g,11ms"), SpecError::Shape { name } if name == "square")
        );
        assert!(
            matches!(refused("half-sine,50q,11ms"), SpecError::PeakNotANumber { text } if text == "50q")
        );
        assert!(matches!(
            refused("half-sine,50g,-1ms"),
            SpecError::DurationRange { .. }
        ));
        assert!(matches!(
            refused("half-sine,50g,11ms,band=2"),
            SpecError::Invalid(impact_core::Error::InvalidParameter { .. })
        ));
        assert!(matches!(
            refused("half-sine,50g,11ms,rise=0.1"),
            SpecError::Key {
                trapezoid: false,
                ..
            }
        ));
    }
}
