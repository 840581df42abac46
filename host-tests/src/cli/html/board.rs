//! The report of a board's log (`impact watch`'s session file, exported from its page): the
//! same page as `impact report`'s, from the log's impacts and the windows the board sent.

use super::super::pulse::MAX_FIGURES;
use super::super::series::EntryJson;
use super::{page, provenance, Front};

/// Why a board's log could not be reported ([`log_report`]).
#[derive(Debug, thiserror::Error)]
pub enum LogReportError {
    /// The log not read ([`crate::cli::log::read_log`]'s error; boxed, it is large).
    #[error(transparent)]
    ReadLog(Box<crate::cli::log::LogCommandError>),
    #[error(transparent)]
    Log(#[from] crate::firmware_link::log::LogError),
    /// The log's scene line without a field the figures need.
    #[error(transparent)]
    Field(#[from] crate::firmware_link::line::FieldError),
    #[error(transparent)]
    Provenance(#[from] provenance::ProvenanceError),
}

/// The report of a board's log (`impact watch`'s session file, exported from its page): the
/// log's impacts as `impact log` reads them, each pulse drawn from the window the board sent
/// (its run's), with `spec`'s band where its verdict placed it.
pub fn log_report(
    path: &std::path::Path,
    spec: Option<(impact_core::spec::Spec, Option<&str>)>,
) -> Result<String, LogReportError> {
    let name = path.display().to_string();
    let log = crate::cli::log::read_log(path).map_err(|e| LogReportError::ReadLog(Box::new(e)))?;
    let mut analysis = crate::firmware_link::log_json::log_json(&log, 0.0)?;
    // The pulse given (and the standard it named), else the one the board's scene line
    // states (log_json's).
    let board = log.scene.as_ref().and_then(|s| s.spec().ok()).flatten();
    let (spec, named) = match spec {
        Some((s, named)) => (Some(s), named),
        None => (board, None),
    };
    if let Some(s) = &spec {
        analysis.spec = Some(crate::report::spec::spec_json(s, named));
    }
    let spec = spec.as_ref();
    let mut figures = Vec::new();
    if let Some(scene) = &log.scene {
        let rate = f64::from(scene.rate_hz);
        let gain = f64::from(scene.gain()?);
        let mass = scene.mass_kg()?;
        for (k, run) in log.runs.iter().enumerate() {
            let waves = &log.waveforms[run.waveforms.clone()];
            for r in &log.impacts[run.impacts.clone()] {
                let Some(wave) = waves.iter().find(|w| w.index == r.index) else {
                    continue;
                };
                if figures.len() == MAX_FIGURES {
                    continue;
                }
                // (The board's windows hold no filter padding: no CFC trace.)
                let signal = crate::plot::Signal {
                    title: String::new(),
                    filter: None,
                    rate_hz: rate,
                    mass_kg: mass.map(f64::from),
                    force_kg: None,
                    t0_s: 0.0,
                    accel_m_s2: Box::new(move |i| wave.at_sample(i).map(|c| f64::from(c) * gain)),
                };
                let held =
                    wave.first_sample..wave.first_sample.saturating_add(u64::from(wave.samples));
                let title = if log.runs.len() > 1 {
                    format!("run {} impact {}", k + 1, r.index)
                } else {
                    format!("impact {}", r.index)
                };
                figures.push(crate::cli::pulse::pulse_svg(
                    &signal,
                    spec,
                    r,
                    title,
                    Some(held),
                ));
            }
        }
    }
    let entry = EntryJson {
        file: name,
        channel: "the board".into(),
        direction: None,
        error: None,
        notes: (log.warnings.iter().cloned())
            .chain(
                log.skipped
                    .iter()
                    .map(crate::firmware_link::log::Skipped::note),
            )
            .collect(),
        analysis: Some(analysis),
        figures,
    };
    let front = Front {
        meta: Vec::new(),
        recorded: Vec::new(),
        written: provenance::Written::now()?,
        inputs: provenance::inputs(&[(provenance::Role::Session, path.to_path_buf())]),
    };
    Ok(page(None, std::slice::from_ref(&entry), None, &front).into_string())
}
