//! `impact analyze`'s JSON from a firmware log alone, impact by impact.

use impact_core::consts::STANDARD_GRAVITY;

use crate::firmware_link::fields::{flag, get, num};
use crate::firmware_link::log::{Log, Run};
use crate::report::{AnalysisJson, ImpactJson};

/// `impact analyze`'s JSON from a log alone (see [`LogJson`]).
pub fn log_json(log: &Log, t0: f64) -> Result<AnalysisJson, String> {
    let json = LogJson::new(log, t0)?;
    let mut a = json.head.clone();
    a.impacts = json.impacts().collect();
    Ok(a)
}

/// `impact analyze`'s JSON from a log alone: samples from each run's summary (or last
/// heartbeat), summed, the rate from the scene line (or a heartbeat), `v0_source` from the
/// scene line (a free fall measured on the host cannot be told from a plain `v0`). With more
/// than one run, each impact and window says its run (1 for the first). The impacts are made
/// one at a time from the log's reports ([`LogJson::impacts`]), as they are written.
pub struct LogJson<'a> {
    /// Everything but the impacts (`impacts` empty; `trains` from them).
    pub head: AnalysisJson,
    log: &'a Log,
    t0: f64,
    fits: impact_core::FitSet,
}

impl<'a> LogJson<'a> {
    pub fn new(log: &'a Log, t0: f64) -> Result<Self, String> {
        let state = log.summary.as_ref().or(log.heartbeat.as_ref());
        let rate = match (&log.scene, state) {
            (Some(m), _) => num::<f32>(m, "rate_hz")?,
            (None, Some(m)) => num::<f32>(m, "rate_hz")?,
            (None, None) => {
                return Err(
                    "the log has no scene, heartbeat or summary line: sample rate unknown".into(),
                )
            }
        };
        let (v0_m_s, v0_source) = match &log.scene {
            Some(m) if get(m, "drop_height_m")? != "none" => {
                let h = num::<f32>(m, "drop_height_m")?;
                (
                    Some((2.0 * STANDARD_GRAVITY * f64::from(h)).sqrt()),
                    Some("drop-height".to_string()),
                )
            }
            Some(m) if get(m, "v0_m_s")? != "none" => (
                Some(crate::report::fmt::shortest(num::<f32>(m, "v0_m_s")?)),
                Some("v0".to_string()),
            ),
            _ => (None, None),
        };
        // What the scene asked for (the scene line's flags), for the reasons of absent fits.
        let asked = |key: &str| -> Result<bool, String> {
            match &log.scene {
                Some(m) => flag(m, key),
                None => Ok(false),
            }
        };
        let fits = impact_core::FitSet {
            two_phase: asked("two_phase")?,
            nonlinear: asked("nonlinear")?,
            fit_exponent: asked("fit_exponent")?,
            nonlinear_exponent: 1.0,
            hertz: asked("hertz")?,
        };
        let train_speed = log
            .scene
            .as_ref()
            .and_then(|m| m.get("train"))
            .filter(|t| *t != "none")
            .cloned();
        let total = |f: fn(&Run) -> u64| log.runs.iter().map(f).sum::<u64>();
        // The run of each impact and window (1-based), with more than one run.
        let runs = log.runs.len() > 1;
        let run_of = |k: usize, range: fn(&Run) -> &std::ops::Range<usize>| {
            let r = log.runs.partition_point(|r| range(r).end <= k);
            runs.then_some(r as u32 + 1)
        };
        let a = AnalysisJson {
            column: None,
            units: None,
            lines_dropped: log.lines_dropped,
            lines_missing: log.lines_missing,
            v0_m_s,
            samples: total(|r| r.samples),
            train_speed,
            // The board's spec lines give each impact's verdict; the pulse is the scene's.
            spec: None,
            trains: Vec::new(),
            waveforms: (log.waveforms.iter().enumerate())
                .map(|(k, w)| {
                    let mut j = w.json();
                    j.run = run_of(k, |r| &r.waveforms);
                    j
                })
                .collect(),
            sample_rate_hz: rate as f64,
            v0_source,
            free_fall_s: None,
            samples_lost: total(|r| r.samples_lost),
            analyses_skipped: total(|r| r.analyses_skipped),
            resampled: false,
            spikes_removed: Vec::new(),
            clipping: None,
            impacts: Vec::new(),
        };
        let mut json = Self {
            head: a,
            log,
            t0,
            fits,
        };
        json.head.trains = crate::report::train::trains(json.impacts());
        Ok(json)
    }

    /// The impacts' JSON, in the log's order, made as they are taken.
    pub fn impacts(&self) -> impl Iterator<Item = ImpactJson> + Clone + '_ {
        let log = self.log;
        let runs = log.runs.len() > 1;
        (log.impacts.iter().zip(&log.latencies).enumerate()).map(move |(k, (r, latency))| {
            let mut j = crate::report::impact_json(r, self.t0, &self.fits);
            j.report_latency_s = latency.map(f64::from);
            j.run = runs.then(|| log.runs.partition_point(|run| run.impacts.end <= k) as u32 + 1);
            j
        })
    }
}
