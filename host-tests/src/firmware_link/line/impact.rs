//! The `impact` line: every field of the core's report in its order (`report::FIELDS`, then
//! `BOUNCE_FIELDS`), kinematics and fits flattened, then the report's latency (the
//! reporter's `log_impact`).

use impact_core::report::{Bounce, Fits, Flags, HertzFit, NonlinearFit, TwoPhaseFit};
use impact_core::{Analysis, ImpactReport, Kinematics, Status};

use super::{Fields, LineError};
use crate::firmware_link::plausible::check_report;

/// An `impact` line: the core's report (floats parsed at their own width, so the firmware's
/// shortest round-trip decimals give back its exact bits; its numbers within what the
/// firmware can report, [`check_report`]) and when the board printed it.
#[derive(Clone, Debug, PartialEq)]
pub struct ImpactLine {
    pub report: ImpactReport,
    /// From the end of the impact's hold to the line, s (real-time sources only).
    pub report_latency_s: Option<f32>,
}

impl ImpactLine {
    pub fn parse(f: &Fields) -> Result<Self, LineError> {
        let report = report(f)?;
        check_report(&report)?;
        Ok(Self {
            report,
            report_latency_s: f.opt("report_latency_s")?,
        })
    }
}

/// Fields older firmware did not write, each read as what that firmware meant: `decimation`
/// (it held every sample, or cut the capture).
const ADDED: [&str; 1] = ["decimation"];

/// The report's fields. Every field of the contract is looked for first, in its order: the
/// first missing one is the error (but for [`ADDED`]).
fn report(f: &Fields) -> Result<ImpactReport, LineError> {
    for field in impact_core::report::FIELDS {
        if !ADDED.contains(&field) {
            f.text(field)?;
        }
    }
    let status = f.text("status")?;
    let status = Status::ALL
        .into_iter()
        .find(|s| s.name() == status)
        .ok_or_else(|| LineError::Status {
            text: status.to_string(),
        })?;
    let analysis = f.text("analysis")?;
    let analysis = [Analysis::Full, Analysis::Skipped]
        .into_iter()
        .find(|a| a.name() == analysis)
        .ok_or_else(|| LineError::Analysis {
            text: analysis.to_string(),
        })?;
    let kinematics = kinematics(f)?;
    let fits = fits(f)?;
    let bounce = bounce(f)?;
    Ok(ImpactReport {
        index: f.num("index")?,
        status,
        analysis,
        clipped: f.flag("clipped")?,
        flags: Flags(f.num("flags")?),
        start_sample: f.num("start_sample")?,
        end_sample: f.num("end_sample")?,
        start_s: f.num("start_s")?,
        peak_time_s: f.num("peak_time_s")?,
        peak_acceleration_m_s2: f.num("peak_acceleration_m_s2")?,
        peak_force_n: f.opt("peak_force_n")?,
        delta_v_m_s: f.opt("delta_v_m_s")?,
        duration_s: f.num("duration_s")?,
        baseline_m_s2: f.num("baseline_m_s2")?,
        fwhm_s: f.opt("fwhm_s")?,
        filtered_peak_acceleration_m_s2: f.opt("filtered_peak_acceleration_m_s2")?,
        filtered_fwhm_s: f.opt("filtered_fwhm_s")?,
        // (Firmware before the decimating capture wrote none: it held every sample.)
        decimation: f.given("decimation")?.unwrap_or(1),
        kinematics,
        fits,
        bounce,
        spectrum: None,
        verdict: None,
    })
}

/// The kinematics, if the line has an impact velocity.
fn kinematics(f: &Fields) -> Result<Option<Kinematics>, LineError> {
    let Some(v0) = f.opt::<f32>("impact_velocity_m_s")? else {
        return Ok(None);
    };
    Ok(Some(Kinematics {
        impact_velocity_m_s: v0,
        crush_time_s: f.opt("crush_time_s")?,
        max_deformation_m: f.opt("max_deformation_m")?,
        rebound_velocity_m_s: f.num("rebound_velocity_m_s")?,
        cor: f.num("cor")?,
        separation_deformation_m: f.opt("separation_deformation_m")?,
        permanent_deformation_m: f.opt("permanent_deformation_m")?,
        absorbed_energy_j: f.opt("absorbed_energy_j")?,
    }))
}

/// Each fit whose first parameter the line has.
fn fits(f: &Fields) -> Result<Fits, LineError> {
    let two_phase = match f.opt::<f32>("two_phase_kc_n_m")? {
        None => None,
        Some(kc) => Some(TwoPhaseFit {
            kc_n_m: kc,
            kr_n_m: f.num("two_phase_kr_n_m")?,
            c_n_s_m: f.num("two_phase_c_n_s_m")?,
            permanent_m: f.num("two_phase_permanent_deformation_m")?,
            residual: f.num("two_phase_residual")?,
        }),
    };
    let nonlinear = match f.opt::<f32>("nonlinear_k")? {
        None => None,
        Some(k) => Some(NonlinearFit {
            k,
            c_s_m: f.num("nonlinear_c_s_m")?,
            n: f.num("nonlinear_exponent")?,
            residual: f.num("nonlinear_residual")?,
        }),
    };
    let hertz = match f.opt::<f32>("hertz_k")? {
        None => None,
        Some(k) => Some(HertzFit {
            k,
            residual: f.num("hertz_residual")?,
        }),
    };
    Ok(Fits {
        two_phase,
        nonlinear,
        hertz,
    })
}

/// The bounce of a train, if the line numbers one (firmware before bounce trains wrote no
/// bounce fields: absent means none).
fn bounce(f: &Fields) -> Result<Option<Bounce>, LineError> {
    let number = if f.contains("bounce_number") {
        f.opt::<u32>("bounce_number")?
    } else {
        None
    };
    let Some(number) = number else {
        return Ok(None);
    };
    Ok(Some(Bounce {
        number,
        flight_s: f.num("flight_s")?,
        v0_flight_m_s: f.num("v0_flight_m_s")?,
        v0_rebound_m_s: f.opt("v0_rebound_m_s")?,
        // (Firmware before the landing height took every flight to land where it left.)
        landing_height_m: if f.contains("landing_height_m") {
            f.num("landing_height_m")?
        } else {
            0.0
        },
    }))
}
