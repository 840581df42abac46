//! `impact analyze`'s JSON from a firmware log alone, impact by impact.

use impact_core::consts::STANDARD_GRAVITY;

use crate::firmware_link::line::{FieldError, LineTarget, SceneLine};
use crate::firmware_link::log::{Log, LogError, LogErrorKind, Run};
use crate::report::{AnalysisJson, ImpactJson};

/// `impact analyze`'s JSON from a log alone (see [`LogJson`]).
pub fn log_json(log: &Log, t0: f64) -> Result<AnalysisJson, LogError> {
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
    /// Gravity in the contacts, m/s² (the scene line's `gravity_m_s2`; none: horizontal).
    gravity: Option<f32>,
    /// The stream's rate, S/s (the scene line's, else the board's state's).
    rate_hz: f64,
}

impl<'a> LogJson<'a> {
    pub fn new(log: &'a Log, t0: f64) -> Result<Self, LogError> {
        let state_rate =
            (log.summary.as_ref().map(|s| s.rate_hz)).or(log.heartbeat.as_ref().map(|h| h.rate_hz));
        let rate = match (&log.scene, state_rate) {
            (Some(scene), _) => scene.rate_hz,
            (None, Some(rate)) => rate,
            (None, None) => return Err(LogError::whole(LogErrorKind::NoRate)),
        };
        let scene = log.scene.as_ref();
        // Gravity in the contacts, read once (none: horizontal).
        let gravity = scene
            .map(SceneLine::contact_gravity_m_s2)
            .transpose()
            .map_err(LogError::whole)?
            .flatten();
        let (v0_m_s, v0_source) = approach(scene, gravity).map_err(LogError::whole)?;
        let fits = asked(scene).map_err(LogError::whole)?;
        let target = (scene.map(SceneLine::target).transpose())
            .map_err(LogError::whole)?
            .flatten();
        let train_speed = scene.and_then(SceneLine::train).map(str::to_string);
        // The pulse the board judged, as its scene line states it.
        // (One this tool cannot read, a newer board's shape say, is said and left out.)
        let spec = match scene.map(SceneLine::spec).transpose() {
            Ok(spec) => spec.flatten(),
            Err(e) => {
                impact_io::note(&format!("the scene line's pulse is left out: {e}"));
                None
            }
        };
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
            assumptions: Vec::new(),
            units_assumed: false,
            time_unit_assumed: false,
            samples: total(|r| r.samples),
            train_speed,
            // The board's spec lines give each impact's verdict; the pulse is the scene's.
            spec: spec
                .as_ref()
                .map(|s| crate::report::spec::spec_json(s, None)),
            // The low-pass the board filtered with, as its scene line states it.
            lowpass: scene
                .and_then(SceneLine::lowpass)
                .map(|l| crate::report::filter::LowpassJson::of(&l, rate)),
            target: target.map(|t| match t {
                LineTarget::SpringMass(s) => crate::report::TargetJson::of_spring_mass(&s),
                LineTarget::StateSpace(t) => crate::report::TargetJson::of_state_space(&t),
            }),
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
            contact_gravity_m_s2: gravity.map(crate::report::fmt::shortest),
            free_fall_s: None,
            samples_lost: total(|r| r.samples_lost),
            analyses_skipped: total(|r| r.analyses_skipped),
            resampled: false,
            spikes_removed: Vec::new(),
            clipping: None,
            impacts: Vec::new(),
            drifts: Vec::new(),
            skipped_lines: (log.skipped.iter())
                .map(|s| crate::report::SkippedLineJson {
                    line: s.line,
                    reason: s.reason(),
                })
                .collect(),
        };
        let mut json = Self {
            head: a,
            log,
            t0,
            fits,
            gravity,
            rate_hz: f64::from(rate),
        };
        json.head.trains = crate::report::train::trains(json.impacts());
        json.head.assume_rigid_barrier();
        // The events that are drift, not impacts (as `impact analyze` separates them).
        json.head.drifts = json
            .events()
            .filter(crate::report::is_drift)
            .map(|i| crate::report::DriftJson::of(&i))
            .collect();
        Ok(json)
    }

    /// The impacts' JSON, in the log's order, made as they are taken (the events that are
    /// drift left out: the head's `drifts`).
    pub fn impacts(&self) -> impl Iterator<Item = ImpactJson> + Clone + '_ {
        self.events().filter(|i| !crate::report::is_drift(i))
    }

    /// Every event's JSON, in the log's order, made as they are taken.
    fn events(&self) -> impl Iterator<Item = ImpactJson> + Clone + '_ {
        let log = self.log;
        let runs = log.runs.len() > 1;
        (log.impacts.iter().zip(&log.latencies).enumerate()).map(move |(k, (r, latency))| {
            let mut j = crate::report::impact_json(
                r,
                self.t0,
                &self.fits,
                self.gravity,
                Some(self.rate_hz),
            );
            j.report_latency_s = latency.map(f64::from);
            j.run = runs.then(|| log.runs.partition_point(|run| run.impacts.end <= k) as u32 + 1);
            j
        })
    }
}

/// The approach speed the scene gives, m/s, and where it comes from (`drop-height`, `v0`);
/// `gravity` is the scene line's gravity in the contacts.
fn approach(
    scene: Option<&SceneLine>,
    gravity: Option<f32>,
) -> Result<(Option<f64>, Option<String>), FieldError> {
    let Some(scene) = scene else {
        return Ok((None, None));
    };
    if let Some(h) = scene.drop_height_m()? {
        // A drop is vertical: the scene line gives its gravity (an older board's, none).
        let g = gravity.map_or(STANDARD_GRAVITY, crate::report::fmt::shortest);
        let v0 = (2.0 * g * f64::from(h)).sqrt();
        return Ok((Some(v0), Some("drop-height".to_string())));
    }
    Ok(match scene.v0_m_s()? {
        Some(v0) => (
            Some(crate::report::fmt::shortest(v0)),
            Some("v0".to_string()),
        ),
        None => (None, None),
    })
}

/// The fits the scene asked for (the scene line's flags; none without one), for the reasons
/// of absent fits.
fn asked(scene: Option<&SceneLine>) -> Result<impact_core::FitSet, FieldError> {
    let asked = |flag: fn(&SceneLine) -> Result<bool, FieldError>| scene.map_or(Ok(false), flag);
    Ok(impact_core::FitSet {
        two_phase: asked(SceneLine::two_phase)?,
        nonlinear: asked(SceneLine::nonlinear)?,
        fit_exponent: asked(SceneLine::fit_exponent)?,
        nonlinear_exponent: 1.0,
        hertz: asked(SceneLine::hertz)?,
    })
}
