//! An impact line's values within what the firmware and its stream can hold: signs and
//! ranges ([`check_report`]), times, lengths and deformations the report's own sample
//! positions allow ([`check_plausible`]).

use impact_core::board::CAPTURE_LEN;
use impact_core::report::COR_TOLERANCE;
use impact_core::ImpactReport;

/// An impact report's numbers within what the firmware can report (finite already: see
/// [`crate::firmware_link::fields::num`]).
pub(crate) fn check_report(r: &ImpactReport) -> Result<(), String> {
    fn out_of_range(field: &str, v: impl std::fmt::Display, range: &str) -> Result<(), String> {
        Err(format!("{field}={v}: out of range (must be {range})"))
    }
    let non_negative = |field: &str, v: f64, shown: &dyn std::fmt::Display| {
        if v < 0.0 {
            out_of_range(field, shown, ">= 0")
        } else {
            Ok(())
        }
    };
    non_negative("start_s", r.start_s, &r.start_s)?;
    non_negative("peak_time_s", r.peak_time_s, &r.peak_time_s)?;
    non_negative("duration_s", r.duration_s.into(), &r.duration_s)?;
    if let Some(w) = r.fwhm_s {
        non_negative("fwhm_s", w.into(), &w)?;
    }
    if r.end_sample < r.start_sample {
        return Err(format!(
            "end_sample={} before start_sample={}",
            r.end_sample, r.start_sample
        ));
    }
    if let Some(k) = &r.kinematics {
        non_negative("crush_time_s", k.crush_time_s.into(), &k.crush_time_s)?;
        non_negative(
            "max_deformation_m",
            k.max_deformation_m.into(),
            &k.max_deformation_m,
        )?;
        if k.impact_velocity_m_s <= 0.0 {
            return out_of_range("impact_velocity_m_s", k.impact_velocity_m_s, "> 0");
        }
        // The core flags a COR further outside [0, 1] `cor-out-of-range` and leaves it out.
        if !(-COR_TOLERANCE..=1.0 + COR_TOLERANCE).contains(&k.cor) {
            return out_of_range(
                "cor",
                k.cor,
                &format!("within [-{COR_TOLERANCE}, {}]", 1.0 + COR_TOLERANCE),
            );
        }
        let x = k.max_deformation_m;
        if !(-x..=x).contains(&k.permanent_deformation_m) {
            return out_of_range(
                "permanent_deformation_m",
                k.permanent_deformation_m,
                "within ± max_deformation_m",
            );
        }
    }
    let residuals = [
        ("two_phase_residual", r.fits.two_phase.map(|f| f.residual)),
        ("nonlinear_residual", r.fits.nonlinear.map(|f| f.residual)),
        ("hertz_residual", r.fits.hertz.map(|f| f.residual)),
    ];
    for (field, v) in residuals {
        if let Some(v) = v {
            non_negative(field, v.into(), &v)?;
        }
    }
    Ok(())
}

/// The largest deviation from the baseline the board's counts can hold, counts (an i16's
/// whole range): with the scene's gain, the largest acceleration in a report.
const MAX_DEVIATION_COUNTS: f64 = 65_535.0;

/// An impact's times and lengths within what its stream allows, at `rate_hz` samples per
/// second (`gain`: the scene's m/s² per count, if the log has a scene line). All follow from
/// the report's own sample positions:
///
/// * every time and duration (`start_s`, `peak_time_s`, `duration_s`, `crush_time_s`,
///   `fwhm_s`, `filtered_fwhm_s`, `flight_s`), s, lies in the stream up to the impact's end
///   (`end_sample`) and at most one capture after it ([`CAPTURE_LEN`] samples: a foot or a
///   filter's tail past the hold);
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
pub(crate) fn check_plausible(
    r: &ImpactReport,
    rate_hz: f64,
    gain: Option<f64>,
) -> Result<(), String> {
    let sample = 1.0 / rate_hz;
    let capture = CAPTURE_LEN as f64 / rate_hz;
    let stream = r.end_sample as f64 / rate_hz + capture;
    let at_most = |field: &str, v: f64, shown: &dyn Fn() -> String, limit: f64, why: &str| {
        if v <= limit * (1.0 + 1e-6) + sample {
            return Ok(());
        }
        let unit = if field.ends_with("_m") { "m" } else { "s" };
        Err(format!(
            "{field}={}: implausible (at most {}: {why})",
            shown(),
            crate::report::fmt::human(limit, unit)
        ))
    };
    let in_stream = "the stream up to the impact's end and one capture after it";
    let contact = "from first touch, start_s, to one capture after the impact's end";
    at_most(
        "start_s",
        r.start_s,
        &|| value(r.start_s),
        stream,
        in_stream,
    )?;
    let t = r.peak_time_s;
    at_most("peak_time_s", t, &|| value(t), stream, in_stream)?;
    let d = r.duration_s;
    at_most(
        "duration_s",
        d.into(),
        &|| value(d),
        stream - r.start_s,
        contact,
    )?;
    for (field, w) in [("fwhm_s", r.fwhm_s), ("filtered_fwhm_s", r.filtered_fwhm_s)] {
        if let Some(w) = w {
            at_most(field, w.into(), &|| value(w), capture, "one capture")?;
        }
    }
    if let Some(b) = &r.bounce {
        let f = b.flight_s;
        at_most("flight_s", f.into(), &|| value(f), stream, in_stream)?;
    }
    if let Some(k) = &r.kinematics {
        let c = k.crush_time_s;
        at_most(
            "crush_time_s",
            c.into(),
            &|| value(c),
            stream - r.start_s,
            contact,
        )?;
        if let Some(gain) = gain {
            // A sample more of travel: first touch may fall a fraction of one before the onset.
            let t = f64::from(c) + sample;
            let a = MAX_DEVIATION_COUNTS * gain.abs();
            let reach = f64::from(k.impact_velocity_m_s) * t + 0.5 * a * t * t;
            let x = k.max_deformation_m;
            at_most(
                "max_deformation_m",
                x.into(),
                &|| value(x),
                reach,
                "impact_velocity_m_s over crush_time_s under the largest acceleration the counts hold",
            )?;
        }
    }
    Ok(())
}

/// A field's value as a message shows it: as read (`0.1`, `86400`), or in exponent form when
/// huge or tiny (`1e30`).
fn value<T: Into<f64> + Copy + std::fmt::Display + std::fmt::LowerExp>(v: T) -> String {
    let x: f64 = v.into();
    if x != 0.0 && !(1e-4..1e6).contains(&x.abs()) {
        format!("{v:e}")
    } else {
        v.to_string()
    }
}
