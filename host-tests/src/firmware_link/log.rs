//! `impact log`: a decoded firmware log (the `scene`, `impact`, `heartbeat` and `summary`
//! lines of `docs/board.md`) read back, checked line by line, and turned into
//! `impact analyze`'s JSON and CSV.

use std::collections::HashMap;

use impact_core::consts::STANDARD_GRAVITY;
use impact_core::report::COR_TOLERANCE;
use impact_core::report::{Bounce, Fits, Flags, HertzFit, NonlinearFit, Spectrum, TwoPhaseFit};
use impact_core::signal::spectrum::MAX_BANDS;
use impact_core::{Analysis, ImpactReport, Kinematics, Status};

use crate::firmware_link::fields::fields;
use crate::firmware_link::fields::flag;
use crate::firmware_link::fields::get;
use crate::firmware_link::fields::num;
use crate::firmware_link::fields::opt;
use crate::report::AnalysisJson;

/// What a firmware log says.
#[derive(Clone, Debug, Default)]
pub struct Log {
    /// The `scene` line's fields, if the log has one.
    pub scene: Option<HashMap<String, String>>,
    pub impacts: Vec<ImpactReport>,
    /// Each impact's `report_latency_s` (real-time sources only).
    pub latencies: Vec<Option<f32>>,
    /// The last `heartbeat` line's fields.
    pub heartbeat: Option<HashMap<String, String>>,
    /// The `summary` line's fields (only at the end of a finite stream).
    pub summary: Option<HashMap<String, String>>,
    /// What looks wrong without being impossible (e.g. fewer impact lines than the last
    /// heartbeat counts), by line.
    pub warnings: Vec<String>,
    /// The captured windows the board sent (`wave` lines, scene `wave_every` > 0).
    pub waveforms: Vec<crate::firmware_link::waves::Waveform>,
    /// Lines the board's logger dropped (the summary's, else the last heartbeat's
    /// `lines_dropped`; 0 from firmware that did not count them).
    pub lines_dropped: u64,
    /// Data lines whose sequence numbers (`seq`) the log lacks, before the last one it has.
    pub lines_missing: u64,
}

/// An `impact` line's fields as the core's report (floats parsed at their own width, so the
/// firmware's shortest round-trip decimals give back its exact bits).
pub fn parse_impact(m: &HashMap<String, String>) -> Result<ImpactReport, String> {
    // Every field of the contract first, in its order (`report::FIELDS`): the first missing
    // one is the error.
    for key in impact_core::report::FIELDS {
        get(m, key)?;
    }
    let status = get(m, "status")?;
    let status = Status::ALL
        .into_iter()
        .find(|s| s.name() == status)
        .ok_or_else(|| format!("status={status}: unknown status"))?;
    let analysis = get(m, "analysis")?;
    let analysis = [Analysis::Full, Analysis::Skipped]
        .into_iter()
        .find(|a| a.name() == analysis)
        .ok_or_else(|| format!("analysis={analysis}: not full or skipped"))?;
    let kinematics = match opt::<f32>(m, "impact_velocity_m_s")? {
        None => None,
        Some(v0) => Some(Kinematics {
            impact_velocity_m_s: v0,
            crush_time_s: num(m, "crush_time_s")?,
            max_deformation_m: num(m, "max_deformation_m")?,
            rebound_velocity_m_s: num(m, "rebound_velocity_m_s")?,
            cor: num(m, "cor")?,
            permanent_deformation_m: num(m, "permanent_deformation_m")?,
            absorbed_energy_j: opt(m, "absorbed_energy_j")?,
        }),
    };
    let two_phase = match opt::<f32>(m, "two_phase_kc_n_m")? {
        None => None,
        Some(kc) => Some(TwoPhaseFit {
            kc_n_m: kc,
            kr_n_m: num(m, "two_phase_kr_n_m")?,
            c_n_s_m: num(m, "two_phase_c_n_s_m")?,
            permanent_m: num(m, "two_phase_permanent_deformation_m")?,
            residual: num(m, "two_phase_residual")?,
        }),
    };
    let nonlinear = match opt::<f32>(m, "nonlinear_k")? {
        None => None,
        Some(k) => Some(NonlinearFit {
            k,
            c_s_m: num(m, "nonlinear_c_s_m")?,
            n: num(m, "nonlinear_exponent")?,
            residual: num(m, "nonlinear_residual")?,
        }),
    };
    let hertz = match opt::<f32>(m, "hertz_k")? {
        None => None,
        Some(k) => Some(HertzFit {
            k,
            residual: num(m, "hertz_residual")?,
        }),
    };
    // Firmware before bounce trains wrote no bounce fields: absent means none.
    let bounce = match m
        .contains_key("bounce_number")
        .then(|| opt::<u32>(m, "bounce_number"))
        .transpose()?
        .flatten()
    {
        None => None,
        Some(number) => Some(Bounce {
            number,
            flight_s: num(m, "flight_s")?,
            v0_flight_m_s: num(m, "v0_flight_m_s")?,
            v0_rebound_m_s: opt(m, "v0_rebound_m_s")?,
        }),
    };
    Ok(ImpactReport {
        index: num(m, "index")?,
        status,
        analysis,
        clipped: flag(m, "clipped")?,
        flags: Flags(num(m, "flags")?),
        start_sample: num(m, "start_sample")?,
        end_sample: num(m, "end_sample")?,
        start_s: num(m, "start_s")?,
        peak_time_s: num(m, "peak_time_s")?,
        peak_acceleration_m_s2: num(m, "peak_acceleration_m_s2")?,
        peak_force_n: opt(m, "peak_force_n")?,
        delta_v_m_s: opt(m, "delta_v_m_s")?,
        duration_s: num(m, "duration_s")?,
        baseline_m_s2: num(m, "baseline_m_s2")?,
        fwhm_s: opt(m, "fwhm_s")?,
        filtered_peak_acceleration_m_s2: opt(m, "filtered_peak_acceleration_m_s2")?,
        filtered_fwhm_s: opt(m, "filtered_fwhm_s")?,
        kinematics,
        fits: Fits {
            two_phase,
            nonlinear,
            hertz,
        },
        bounce,
        spectrum: None,
    })
}

/// An `srs` line: the spectra of the impact with its `index`.
fn parse_spectrum(m: &HashMap<String, String>) -> Result<(u32, Spectrum), String> {
    let list = |key: &str| -> Result<Vec<f32>, String> {
        get(m, key)?
            .split(',')
            .map(|v| match v.parse::<f32>() {
                Ok(x) if x.is_finite() && x >= 0.0 => Ok(x),
                _ => Err(format!("{key}: {v} is not a finite value >= 0")),
            })
            .collect()
    };
    let bands: u8 = num(m, "bands")?;
    let (srs, pvss) = (list("srs_m_s2")?, list("pvss_m_s")?);
    let n = usize::from(bands);
    if n == 0 || n > MAX_BANDS || srs.len() != n || pvss.len() != n {
        return Err(format!(
            "bands={bands} with {} SRS and {} PVSS values",
            srs.len(),
            pvss.len()
        ));
    }
    let mut s = Spectrum {
        bands,
        first_hz: num(m, "first_hz")?,
        bands_per_octave: num(m, "bands_per_octave")?,
        damping: num(m, "damping")?,
        srs_m_s2: [0.0; MAX_BANDS],
        pvss_m_s: [0.0; MAX_BANDS],
        half_sine: match (
            opt::<f32>(m, "half_sine_amplitude_m_s2")?,
            opt::<f32>(m, "half_sine_duration_s")?,
        ) {
            (Some(a), Some(d)) => Some((a, d)),
            _ => None,
        },
        from_sample: num(m, "from_sample")?,
        to_sample: num(m, "to_sample")?,
    };
    s.srs_m_s2[..n].copy_from_slice(&srs);
    s.pvss_m_s[..n].copy_from_slice(&pvss);
    Ok((num(m, "index")?, s))
}

/// Parses a decoded firmware log (any other lines are ignored), checking what it reads (see
/// [`LogReader`]).
pub fn parse_log(text: &str) -> Result<Log, String> {
    let mut reader = LogReader::default();
    for (n, line) in text.lines().enumerate() {
        reader.line(n as u64 + 1, line)?;
    }
    reader.finish()
}

/// A firmware log read line by line, checked as it goes: every number finite and within its
/// field's range, impact indices unique and increasing (unless the summary counts reports
/// printed out of order), heartbeat counters never going back, and at the end of a finite
/// stream as many impact lines as the summary counts. Errors name the line.
#[derive(Default)]
pub struct LogReader {
    log: Log,
    /// Line of each impact report, in the order read.
    impact_lines: Vec<u64>,
    /// The first impact whose index did not increase: (line, index, previous index).
    reordered: Option<(u64, u32, u32)>,
    /// Line and counters (samples, impacts) of the last heartbeat.
    last_heartbeat: Option<(u64, u64, u64)>,
    summary_line: u64,
    /// The data lines' sequence numbers seen (`seq`).
    seqs: Vec<u32>,
}

impl LogReader {
    /// Reads line `n` (1-based).
    pub fn line(&mut self, n: u64, line: &str) -> Result<(), String> {
        let at = |e: String| format!("line {n}: {e}");
        if let Some(m) = fields(line, "impact ") {
            let m = m.map_err(at)?;
            self.seen(&m).map_err(at)?;
            let r = parse_impact(&m).map_err(at)?;
            check_report(&r).map_err(at)?;
            let latency: Option<f32> = opt(&m, "report_latency_s").map_err(at)?;
            if let Some(l) = latency.filter(|&l| l < 0.0) {
                return Err(at(format!("report_latency_s={l}: not a time >= 0")));
            }
            if let Some(k) = self.log.impacts.iter().position(|p| p.index == r.index) {
                return Err(at(format!(
                    "impact index={} again (first on line {}): two streams mixed, or a line repeated",
                    r.index, self.impact_lines[k]
                )));
            }
            if let Some(prev) = self.log.impacts.last() {
                if r.index < prev.index && self.reordered.is_none() {
                    self.reordered = Some((n, r.index, prev.index));
                }
            }
            self.log.impacts.push(r);
            self.log.latencies.push(latency);
            self.impact_lines.push(n);
        } else if let Some(m) = fields(line, "srs ") {
            let m = m.map_err(at)?;
            self.seen(&m).map_err(at)?;
            let (index, spectrum) = parse_spectrum(&m).map_err(at)?;
            match self.log.impacts.iter_mut().rev().find(|r| r.index == index) {
                Some(r) if r.spectrum.is_none() => r.spectrum = Some(spectrum),
                _ => {
                    return Err(at(format!(
                        "srs index={index}: no impact line of that index before it, or a second srs line"
                    )))
                }
            }
        } else if let Some(m) = fields(line, "wave_frame ") {
            let m = m.map_err(at)?;
            self.seen(&m).map_err(at)?;
            let (index, frame, counts) =
                crate::firmware_link::waves::parse_frame(line, &m).map_err(at)?;
            let w = self
                .log
                .waveforms
                .iter_mut()
                .rev()
                .find(|w| w.index == index)
                .ok_or_else(|| {
                    at(format!(
                        "wave_frame index={index}: no wave line of that index before it"
                    ))
                })?;
            w.add_frame(frame, counts).map_err(at)?;
        } else if let Some(m) = fields(line, "wave ") {
            let m = m.map_err(at)?;
            self.seen(&m).map_err(at)?;
            let w = crate::firmware_link::waves::Waveform::from_header(&m).map_err(at)?;
            if self.log.waveforms.iter().any(|p| p.index == w.index) {
                return Err(at(format!(
                    "wave index={} again: two streams mixed, or a line repeated",
                    w.index
                )));
            }
            self.log.waveforms.push(w);
        } else if let Some(m) = fields(line, "heartbeat ") {
            let m = m.map_err(at)?;
            self.seen(&m).map_err(at)?;
            let samples: u64 = num(&m, "samples").map_err(at)?;
            let impacts: u64 = num(&m, "impacts").map_err(at)?;
            rate(&m).map_err(at)?;
            if let Some((line, s0, i0)) = self.last_heartbeat {
                if samples < s0 || impacts < i0 {
                    return Err(at(format!(
                        "heartbeat samples={samples} impacts={impacts} after samples={s0} \
                         impacts={i0} (line {line}): counters never go back within a stream"
                    )));
                }
            }
            self.last_heartbeat = Some((n, samples, impacts));
            self.log.heartbeat = Some(m);
        } else if let Some(m) = fields(line, "summary ") {
            let m = m.map_err(at)?;
            self.seen(&m).map_err(at)?;
            num::<u64>(&m, "samples").map_err(at)?;
            num::<u64>(&m, "impacts").map_err(at)?;
            rate(&m).map_err(at)?;
            self.summary_line = n;
            self.log.summary = Some(m);
        } else if let Some(m) = fields(line, "scene ") {
            let m = m.map_err(at)?;
            rate(&m).map_err(at)?;
            // A restart (a new scene) starts a new stream.
            *self = LogReader::default();
            self.log.scene = Some(m);
        }
        Ok(())
    }

    /// A data line's sequence number (`seq`, absent from firmware that did not number them).
    fn seen(&mut self, m: &HashMap<String, String>) -> Result<(), String> {
        if m.contains_key("seq") {
            self.seqs.push(num(m, "seq")?);
        }
        Ok(())
    }

    /// The log, its reports in index order; checks the counts against the summary.
    pub fn finish(mut self) -> Result<Log, String> {
        let printed = self.log.impacts.len() as u64;
        let state = self.log.summary.as_ref().or(self.log.heartbeat.as_ref());
        self.log.lines_dropped = match state {
            Some(m) if m.contains_key("lines_dropped") => num(m, "lines_dropped")?,
            _ => 0,
        };
        self.seqs.sort_unstable();
        self.seqs.dedup();
        if let Some(&last) = self.seqs.last() {
            self.log.lines_missing = u64::from(last) + 1 - self.seqs.len() as u64;
        }
        if self.log.lines_missing > 0 || self.log.lines_dropped > 0 {
            let first: Vec<String> = (0..)
                .filter(|s| self.seqs.binary_search(s).is_err())
                .take(5)
                .map(|s: u32| s.to_string())
                .collect();
            self.log.warnings.push(format!(
                "the board dropped {} lines (its logger's count); {} numbered lines are missing{}",
                self.log.lines_dropped,
                self.log.lines_missing,
                if self.log.lines_missing > 0 {
                    format!(
                        " (seq {}{})",
                        first.join(", "),
                        if self.log.lines_missing > 5 {
                            ", …"
                        } else {
                            ""
                        }
                    )
                } else {
                    String::new()
                }
            ));
        }
        let lost = self.log.lines_dropped + self.log.lines_missing > 0;
        if let Some(m) = &self.log.summary {
            let at = |e: String| format!("line {}: {e}", self.summary_line);
            let counted: u64 = num(m, "impacts").map_err(at)?;
            let dropped: u64 = num(m, "reports_dropped").map_err(at)?;
            // Lines the board dropped (counted) explain missing impact lines.
            if printed + dropped != counted && !(lost && printed + dropped < counted) {
                return Err(at(format!(
                    "the summary counts {counted} impacts ({dropped} reports dropped), the log \
                     has {printed} impact lines: lines lost, or two streams mixed"
                )));
            }
            if let Some(r) = self
                .log
                .impacts
                .iter()
                .find(|r| u64::from(r.index) >= counted)
            {
                return Err(at(format!(
                    "impact index={} but the summary counts {counted} impacts",
                    r.index
                )));
            }
            if let Some((line, index, prev)) = self.reordered {
                if num::<u64>(m, "reports_out_of_order").map_err(at)? == 0 {
                    return Err(format!(
                        "line {line}: impact index={index} after index={prev}, and the \
                         summary counts no report out of order"
                    ));
                }
            }
        } else {
            if let Some((line, index, prev)) = self.reordered {
                return Err(format!(
                    "line {line}: impact index={index} after index={prev} (the firmware prints \
                     in index order; a reorder is counted only in a summary line)"
                ));
            }
            if let (Some((line, _, counted)), Some(m)) = (self.last_heartbeat, &self.log.heartbeat)
            {
                let dropped: u64 =
                    num(m, "reports_dropped").map_err(|e| format!("line {line}: {e}"))?;
                if printed + dropped < counted {
                    self.log.warnings.push(format!(
                        "line {line}: the heartbeat counts {counted} impacts ({dropped} reports \
                         dropped), the log has {printed} impact lines: a cut log, or lines lost \
                         on the link"
                    ));
                }
            }
        }
        for w in &self.log.waveforms {
            if w.missing_frames() > 0 {
                self.log.warnings.push(format!(
                    "impact {}: {} of {} waveform frames missing (the link dropped them)",
                    w.index,
                    w.missing_frames(),
                    w.frames
                ));
            }
        }
        self.log.waveforms.sort_by_key(|w| w.index);
        let mut both: Vec<_> = self
            .log
            .impacts
            .drain(..)
            .zip(self.log.latencies.drain(..))
            .collect();
        both.sort_by_key(|(r, _)| r.index);
        (self.log.impacts, self.log.latencies) = both.into_iter().unzip();
        Ok(self.log)
    }
}

/// A line's `rate_hz`: finite and > 0.
pub(crate) fn rate(m: &HashMap<String, String>) -> Result<f32, String> {
    let r: f32 = num(m, "rate_hz")?;
    if r.is_finite() && r > 0.0 {
        Ok(r)
    } else {
        Err(format!("rate_hz={r}: not a finite rate > 0"))
    }
}

/// An impact report's numbers within what the firmware can report (finite already: see
/// [`Number`]).
fn check_report(r: &ImpactReport) -> Result<(), String> {
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

/// `impact analyze`'s JSON from a log alone: samples from the summary (or the last
/// heartbeat), the rate from the scene line (or a heartbeat), `v0_source` from the scene line
/// (a free fall measured on the host cannot be told from a plain `v0`).
pub fn log_json(log: &Log, t0: f64) -> Result<AnalysisJson, String> {
    let state = log.summary.as_ref().or(log.heartbeat.as_ref());
    let samples = match state {
        Some(m) => num::<u64>(m, "samples")?,
        None => 0,
    };
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
    let counter = |key: &str| -> Result<u64, String> {
        match state {
            Some(m) if m.contains_key(key) => num::<u64>(m, key),
            _ => Ok(0),
        }
    };
    let train_speed = log
        .scene
        .as_ref()
        .and_then(|m| m.get("train"))
        .filter(|t| *t != "none")
        .cloned();
    let mut a = AnalysisJson {
        column: None,
        units: None,
        lines_dropped: log.lines_dropped,
        lines_missing: log.lines_missing,
        v0_m_s,
        samples,
        train_speed,
        trains: Vec::new(),
        waveforms: log.waveforms.iter().map(|w| w.json()).collect(),
        sample_rate_hz: rate as f64,
        v0_source,
        free_fall_s: None,
        samples_lost: counter("samples_lost")?,
        analyses_skipped: counter("analyses_skipped")?,
        resampled: false,
        spikes_removed: Vec::new(),
        clipping: None,
        impacts: log
            .impacts
            .iter()
            .zip(&log.latencies)
            .map(|(r, latency)| {
                let mut j = crate::report::impact_json(r, t0, &fits);
                j.report_latency_s = latency.map(f64::from);
                j
            })
            .collect(),
    };
    a.trains = crate::report::train::trains(&a.impacts);
    Ok(a)
}

#[cfg(test)]
mod tests {
    use super::*;

    const LINE: &str = "0.013931 INFO  impact index=0 status=complete analysis=full clipped=false flags=0 start_sample=5000 end_sample=17000 start_s=0.01 peak_time_s=0.0100251 peak_acceleration_m_s2=4321.5 peak_force_n=259.29 delta_v_m_s=2.5 duration_s=0.0219 baseline_m_s2=0.2 fwhm_s=0.001 filtered_peak_acceleration_m_s2=none filtered_fwhm_s=none impact_velocity_m_s=1.3357 crush_time_s=0.0218 max_deformation_m=0.0186 rebound_velocity_m_s=1.16 cor=0.87 permanent_deformation_m=0.0182 absorbed_energy_j=none two_phase_kc_n_m=none two_phase_kr_n_m=none two_phase_c_n_s_m=none two_phase_permanent_deformation_m=none two_phase_residual=none nonlinear_k=1e6 nonlinear_c_s_m=0.5 nonlinear_exponent=1.2 nonlinear_residual=0.01 hertz_k=none hertz_residual=none report_latency_s=0.0123";

    #[test]
    fn parses_an_impact_line() {
        let log = parse_log(&format!(
            "noise\n{LINE}\n└─ impact_firmware::tasks::reporter @ src/tasks/reporter.rs:150\n"
        ))
        .unwrap();
        let r = log.impacts[0];
        assert_eq!(
            (r.index, r.status, r.start_sample),
            (0, Status::Complete, 5000)
        );
        assert_eq!(r.peak_acceleration_m_s2, 4321.5f32);
        assert_eq!(r.kinematics.unwrap().absorbed_energy_j, None);
        assert_eq!(r.fits.nonlinear.unwrap().n, 1.2f32);
        assert!(r.fits.two_phase.is_none() && r.fits.hertz.is_none());
        assert_eq!(log.latencies, [Some(0.0123f32)]);
    }

    #[test]
    fn a_missing_field_is_an_error_naming_it() {
        let line = LINE.replace(" fwhm_s=0.001", "");
        let e = parse_log(&line).unwrap_err();
        assert!(e.contains("line 1") && e.contains("fwhm_s"), "{e}");
    }

    #[test]
    fn prose_starting_with_a_marker_word_is_not_a_line() {
        let log = parse_log("INFO  impact-firmware 0.1.0 up\nWARN summary of nothing").unwrap();
        assert!(log.impacts.is_empty() && log.summary.is_none());
    }

    fn with(field: &str, value: &str) -> String {
        let (head, tail) = LINE.split_once(&format!(" {field}=")).unwrap();
        let rest = tail.split_once(' ').map_or("", |(_, r)| r);
        format!("{head} {field}={value} {rest}")
    }

    #[test]
    fn impossible_numbers_are_refused_by_line() {
        for (field, value, says) in [
            ("peak_acceleration_m_s2", "inf", "not finite"),
            ("peak_acceleration_m_s2", "1e39", "not finite"),
            ("duration_s", "NaN", "not finite"),
            ("cor", "7.5", "cor=7.5: out of range"),
            (
                "permanent_deformation_m",
                "-1",
                "permanent_deformation_m=-1: out of range",
            ),
            ("fwhm_s", "-0.001", "fwhm_s=-0.001: out of range"),
            ("report_latency_s", "-1", "report_latency_s=-1"),
        ] {
            let text = format!("noise\n{}\n", with(field, value));
            let e = parse_log(&text).unwrap_err();
            assert!(
                e.starts_with("line 2: ") && e.contains(says),
                "{field}={value}: {e}"
            );
        }
        let scene = "scene rate_hz=NaN\n";
        assert!(parse_log(scene)
            .unwrap_err()
            .contains("line 1: rate_hz=NaN"));
        let beat = "heartbeat samples=5 impacts=0 rate_hz=-5 reports_dropped=0\n";
        assert!(parse_log(beat).unwrap_err().contains("rate_hz=-5"));
    }

    #[test]
    fn indices_must_be_unique_and_increasing() {
        let zero = with("index", "0");
        let e = parse_log(&format!("{zero}\n{zero}\n{zero}\n")).unwrap_err();
        assert!(
            e.starts_with("line 2: impact index=0 again (first on line 1)"),
            "{e}"
        );
        let five = with("index", "5");
        let e = parse_log(&format!("{five}\n{zero}\n")).unwrap_err();
        assert!(e.starts_with("line 2: impact index=0 after index=5"), "{e}");
        // The firmware's summary can own up to a reorder.
        let summary = |out_of_order: u32| {
            format!(
                "summary samples=9 impacts=6 rate_hz=1000 reports_dropped=4 \
                 reports_out_of_order={out_of_order}"
            )
        };
        let log = parse_log(&format!("{five}\n{zero}\n{}\n", summary(1))).unwrap();
        assert_eq!(
            log.impacts.iter().map(|r| r.index).collect::<Vec<_>>(),
            [0, 5]
        );
        assert!(parse_log(&format!("{five}\n{zero}\n{}\n", summary(0))).is_err());
    }

    #[test]
    fn counts_are_checked_against_the_heartbeat_and_summary() {
        let lines: String = (0..3)
            .map(|i| with("index", &i.to_string()) + "\n")
            .collect();
        // A heartbeat counting more impacts than were printed: a warning naming its line.
        let beat = "heartbeat samples=5 impacts=7 rate_hz=1000 reports_dropped=0";
        let log = parse_log(&format!("{lines}{beat}\n")).unwrap();
        assert_eq!(log.warnings.len(), 1);
        assert!(log.warnings[0].starts_with("line 4: the heartbeat counts 7 impacts"));
        // The end of a stream: the summary's count must match.
        let summary =
            "summary samples=9 impacts=7 rate_hz=1000 reports_dropped=0 reports_out_of_order=0";
        let e = parse_log(&format!("{lines}{summary}\n")).unwrap_err();
        assert!(e.starts_with("line 4: the summary counts 7 impacts"), "{e}");
        // Counters never go back.
        let back = "heartbeat samples=4 impacts=7 rate_hz=1000 reports_dropped=0";
        let e = parse_log(&format!("{beat}\n{back}\n")).unwrap_err();
        assert!(e.starts_with("line 2: heartbeat samples=4"), "{e}");
    }
}
