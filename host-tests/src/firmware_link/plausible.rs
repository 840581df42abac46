//! An impact line's values within what the firmware and its stream can hold: signs and
//! ranges ([`check_report`]), times, lengths and deformations the report's own sample
//! positions allow ([`check_plausible`]).

use impact_core::board::CAPTURE_LEN;
use impact_core::report::COR_TOLERANCE;
use impact_core::ImpactReport;

/// A report's number that no firmware or stream gives.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum Implausible {
    /// Beyond what the firmware can report.
    #[error("{field}={value}: out of range (must be {range})")]
    OutOfRange {
        field: &'static str,
        value: Value,
        range: Range,
    },
    #[error("end_sample={end} before start_sample={start}")]
    EndBeforeStart { start: u64, end: u64 },
    /// The crush time, `x_m` and the deformation at separation are absent together, and
    /// exactly where the flags say `undersampled`.
    #[error(
        "crush_time_s, max_deformation_m and separation_deformation_m: none where flags has \
         no undersampled bit, or a value (or a permanent_deformation_m) where it has (a garbled \
         line)"
    )]
    Undersampled,
    /// A capture's step is a power of two up to the coarsest the core decimates to.
    #[error("decimation={value}: not a power of two from 1 to {max}")]
    Decimation { value: u32, max: u32 },
    /// An impact longer, in samples, than the scene lets the core follow one.
    #[error(
        "end_sample={end}: {} samples after start_sample={start}, and the scene's \
         max_impact_s={max_impact_s} ends an impact after {limit} (a cut or garbled line)",
        .end - .start
    )]
    Span {
        start: u64,
        end: u64,
        max_impact_s: f64,
        limit: u64,
    },
    /// Beyond what the impact's stream allows (`limit`: s, or m for a `_m` field).
    #[error(
        "{field}={}: implausible (at most {}: {why})",
        .value.shown(),
        crate::report::fmt::human(*.limit, if .field.ends_with("_m") { "m" } else { "s" })
    )]
    Beyond {
        field: &'static str,
        value: Value,
        limit: f64,
        why: &'static str,
    },
}

/// A field's value at its width.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Value {
    F32(f32),
    F64(f64),
}

impl From<f32> for Value {
    fn from(v: f32) -> Self {
        Value::F32(v)
    }
}

impl From<f64> for Value {
    fn from(v: f64) -> Self {
        Value::F64(v)
    }
}

impl Value {
    fn f64(self) -> f64 {
        match self {
            Value::F32(v) => v.into(),
            Value::F64(v) => v,
        }
    }

    /// As read (`0.1`, `86400`), or in exponent form when huge or tiny (`1e30`).
    fn shown(self) -> String {
        let x = self.f64();
        let exponent = x != 0.0 && !(1e-4..1e6).contains(&x.abs());
        match (self, exponent) {
            (Value::F32(v), true) => format!("{v:e}"),
            (Value::F64(v), true) => format!("{v:e}"),
            (Value::F32(v), false) => v.to_string(),
            (Value::F64(v), false) => v.to_string(),
        }
    }
}

/// As read.
impl std::fmt::Display for Value {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Value::F32(v) => v.fmt(f),
            Value::F64(v) => v.fmt(f),
        }
    }
}

/// The range a report's field must lie in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Range {
    NonNegative,
    Positive,
    /// A COR within [`COR_TOLERANCE`] of [0, 1].
    Cor,
    /// Within ± the maximum deformation.
    WithinMaxDeformation,
}

impl std::fmt::Display for Range {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Range::NonNegative => f.write_str(">= 0"),
            Range::Positive => f.write_str("> 0"),
            Range::Cor => write!(f, "within [-{COR_TOLERANCE}, {}]", 1.0 + COR_TOLERANCE),
            Range::WithinMaxDeformation => f.write_str("within ± max_deformation_m"),
        }
    }
}

/// An impact report's numbers within what the firmware can report (finite already: see
/// [`crate::firmware_link::line::Number`]).
pub(crate) fn check_report(r: &ImpactReport) -> Result<(), Implausible> {
    let out_of_range = |field, value: Value, range| {
        Err(Implausible::OutOfRange {
            field,
            value,
            range,
        })
    };
    let non_negative = |field, value: Value| {
        if value.f64() < 0.0 {
            out_of_range(field, value, Range::NonNegative)
        } else {
            Ok(())
        }
    };
    non_negative("start_s", r.start_s.into())?;
    non_negative("peak_time_s", r.peak_time_s.into())?;
    non_negative("duration_s", r.duration_s.into())?;
    if let Some(w) = r.fwhm_s {
        non_negative("fwhm_s", w.into())?;
    }
    if r.end_sample < r.start_sample {
        return Err(Implausible::EndBeforeStart {
            start: r.start_sample,
            end: r.end_sample,
        });
    }
    if let Some(b) = &r.bounce {
        non_negative("flight_s", b.flight_s.into())?;
        // (The core takes no landing below where the body left.)
        non_negative("landing_height_m", b.landing_height_m.into())?;
    }
    if let Some(k) = &r.kinematics {
        let undersampled = r.flags.contains(impact_core::report::Flags::UNDERSAMPLED);
        let absent = [
            k.crush_time_s,
            k.max_deformation_m,
            k.separation_deformation_m,
        ]
        .map(|v| v.is_none());
        // (Nor a set where the compression was too short for `x_m`.)
        let set = undersampled && k.permanent_deformation_m.is_some();
        if set || absent.iter().any(|&a| a != undersampled) {
            return Err(Implausible::Undersampled);
        }
        for (field, value) in [
            ("crush_time_s", k.crush_time_s),
            ("max_deformation_m", k.max_deformation_m),
        ] {
            if let Some(v) = value {
                non_negative(field, v.into())?;
            }
        }
        if k.impact_velocity_m_s <= 0.0 {
            let v = k.impact_velocity_m_s.into();
            return out_of_range("impact_velocity_m_s", v, Range::Positive);
        }
        // The core flags a COR further outside [0, 1] `cor-out-of-range` and leaves it out.
        if !(-COR_TOLERANCE..=1.0 + COR_TOLERANCE).contains(&k.cor) {
            return out_of_range("cor", k.cor.into(), Range::Cor);
        }
        // (An undersampled compression has no deformations to compare.)
        let x = k.max_deformation_m.unwrap_or(f32::INFINITY);
        for (field, value) in [
            ("separation_deformation_m", k.separation_deformation_m),
            ("permanent_deformation_m", k.permanent_deformation_m),
        ] {
            if let Some(v) = value.filter(|v| !(-x..=x).contains(v)) {
                return out_of_range(field, v.into(), Range::WithinMaxDeformation);
            }
        }
    }
    let residuals = [
        ("two_phase_residual", r.fits.two_phase.map(|f| f.residual)),
        ("nonlinear_residual", r.fits.nonlinear.map(|f| f.residual)),
        ("hertz_residual", r.fits.hertz.map(|f| f.residual)),
    ];
    for (field, v) in residuals {
        if let Some(v) = v {
            non_negative(field, v.into())?;
        }
    }
    Ok(())
}

/// The largest deviation from the baseline the board's counts can hold, counts (an i16's
/// whole range): with the scene's gain, the largest acceleration in a report.
const MAX_DEVIATION_COUNTS: f64 = 65_535.0;

/// What a run's lines tell an impact's values are checked against: its rate (the scene's,
/// else a heartbeat's or the summary's), and the scene's gain and longest impact when a scene
/// line came.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    pub rate_hz: f64,
    /// The scene's m/s² per count.
    pub gain: Option<f64>,
    /// The scene's `max_impact_s`: the core ends an impact that long (`too-long`).
    pub max_impact_s: Option<f64>,
}

/// An impact's times and lengths within what its stream allows, at `rate_hz` samples per
/// second (`gain`: the scene's m/s² per count, if the log has a scene line). All follow from
/// the report's own sample positions:
///
/// * with the scene's `max_impact_s`, the impact spans (`end_sample - start_sample`) at most
///   that long at the rate, and a capture more (the core ends an impact there; the slack
///   covers a gap inside it): so no reader loops over more samples than a stream holds;
///
/// * every time and duration (`start_s`, `peak_time_s`, `duration_s`, `crush_time_s`,
///   `fwhm_s`, `filtered_fwhm_s`, `flight_s`), s, lies in the stream up to the impact's end
///   (`end_sample`) and at most one capture after it ([`CAPTURE_LEN`] values of
///   `decimation` samples each: a foot or a filter's tail past the hold);
/// * the contact (`duration_s`, `crush_time_s`, from first touch at `start_s`) ends there
///   too, and a width measured in the capture (`fwhm_s`, `filtered_fwhm_s`) is at most one
///   capture;
/// * `max_deformation_m`, m, is at most what the body covers over its crush time `T` from the
///   impact speed `v0` under the largest acceleration the counts can hold (`a`:
///   [`MAX_DEVIATION_COUNTS`] × gain): `v0 T + a T² / 2` (`permanent_deformation_m` is
///   within ± it: [`check_report`]).
///
/// Fit parameters are not bounded (a poor fit may give any finite value). A slack of a sample
/// and 1e-6 relative covers the f32 fields' rounding.
pub(crate) fn check_plausible(r: &ImpactReport, bounds: &Bounds) -> Result<(), Implausible> {
    let Bounds {
        rate_hz,
        gain,
        max_impact_s,
    } = *bounds;
    if let Some(max_impact_s) = max_impact_s {
        let limit = (max_impact_s * rate_hz).ceil() + CAPTURE_LEN as f64;
        let limit = if limit < u64::MAX as f64 {
            limit as u64
        } else {
            u64::MAX
        };
        if r.end_sample.saturating_sub(r.start_sample) > limit {
            return Err(Implausible::Span {
                start: r.start_sample,
                end: r.end_sample,
                max_impact_s,
                limit,
            });
        }
    }
    let sample = 1.0 / rate_hz;
    let max = 1u32 << impact_core::capture::MAX_DECIMATION_LOG2;
    if !r.decimation.is_power_of_two() || r.decimation > max {
        return Err(Implausible::Decimation {
            value: r.decimation,
            max,
        });
    }
    let capture = CAPTURE_LEN as f64 * f64::from(r.decimation) / rate_hz;
    let stream = r.end_sample as f64 / rate_hz + capture;
    let at_most = |field, value: Value, limit: f64, why| {
        if value.f64() <= limit * (1.0 + 1e-6) + sample {
            return Ok(());
        }
        Err(Implausible::Beyond {
            field,
            value,
            limit,
            why,
        })
    };
    let in_stream = "the stream up to the impact's end and one capture after it";
    let contact = "from first touch, start_s, to one capture after the impact's end";
    at_most("start_s", r.start_s.into(), stream, in_stream)?;
    at_most("peak_time_s", r.peak_time_s.into(), stream, in_stream)?;
    let d = r.duration_s.into();
    at_most("duration_s", d, stream - r.start_s, contact)?;
    for (field, w) in [("fwhm_s", r.fwhm_s), ("filtered_fwhm_s", r.filtered_fwhm_s)] {
        if let Some(w) = w {
            at_most(field, w.into(), capture, "one capture")?;
        }
    }
    if let Some(b) = &r.bounce {
        at_most("flight_s", b.flight_s.into(), stream, in_stream)?;
    }
    if let Some((k, c)) = r
        .kinematics
        .as_ref()
        .and_then(|k| Some((k, k.crush_time_s?)))
    {
        at_most("crush_time_s", c.into(), stream - r.start_s, contact)?;
        if let (Some(gain), Some(x_m)) = (gain, k.max_deformation_m) {
            // A sample more of travel: first touch may fall a fraction of one before the onset.
            let t = f64::from(c) + sample;
            let a = MAX_DEVIATION_COUNTS * gain.abs();
            let reach = f64::from(k.impact_velocity_m_s) * t + 0.5 * a * t * t;
            at_most(
                "max_deformation_m",
                x_m.into(),
                reach,
                "impact_velocity_m_s over crush_time_s under the largest acceleration the counts hold",
            )?;
        }
    }
    Ok(())
}
