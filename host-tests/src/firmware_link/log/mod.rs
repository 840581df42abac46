//! `impact log`: a decoded firmware log (the `scene`, `impact`, `heartbeat` and `summary`
//! lines of `docs/board.md`) read back, checked line by line, and turned into
//! `impact analyze`'s JSON and CSV.

mod seq;

use std::collections::HashMap;

use impact_core::report::{Bounce, Fits, Flags, HertzFit, NonlinearFit, Spectrum, TwoPhaseFit};
use impact_core::signal::spectrum::MAX_BANDS;
use impact_core::{Analysis, ImpactReport, Kinematics, Status};

use crate::firmware_link::fields::fields;
use crate::firmware_link::fields::flag;
use crate::firmware_link::fields::get;
use crate::firmware_link::fields::num;
use crate::firmware_link::fields::opt;
use crate::firmware_link::plausible::{check_plausible, check_report};
use seq::SeqSet;

/// What a firmware log says. A log can hold several runs of the board: one that resets starts
/// a new run with a new `scene` line, its impact indices, sample positions and times from 0
/// again. Every run's impacts are kept, run after run ([`Log::runs`] tells them apart).
#[derive(Clone, Debug, Default)]
pub struct Log {
    /// The `scene` line's fields, if the log has one (every run's scene is the same).
    pub scene: Option<HashMap<String, String>>,
    /// Every run's impacts, run after run, each run's in index order.
    pub impacts: Vec<ImpactReport>,
    /// Each impact's `report_latency_s` (real-time sources only).
    pub latencies: Vec<Option<f32>>,
    /// The last run's last `heartbeat` line's fields.
    pub heartbeat: Option<HashMap<String, String>>,
    /// The last run's `summary` line's fields (only at the end of a finite stream).
    pub summary: Option<HashMap<String, String>>,
    /// What looks wrong without being impossible (e.g. fewer impact lines than the last
    /// heartbeat counts), by line; and each restart of the board.
    pub warnings: Vec<String>,
    /// The captured windows the board sent (`wave` lines, scene `wave_every` > 0), run after
    /// run, each run's in index order.
    pub waveforms: Vec<crate::firmware_link::waves::Waveform>,
    /// Lines the board's logger dropped (each run's summary's, else its last heartbeat's
    /// `lines_dropped`, summed; 0 from firmware that did not count them).
    pub lines_dropped: u64,
    /// Data lines whose sequence numbers (`seq`) the log lacks, before the last one it has
    /// (each run numbers its lines from 0; summed).
    pub lines_missing: u64,
    /// The runs, in the order of the log (one for a log without a restart).
    pub runs: Vec<Run>,
}

/// One run of the board in a log: from its `scene` line (or the start of the log) to the
/// next `scene` line.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Run {
    /// Line of its `scene` line (0: the log starts within the run, without one).
    pub line: u64,
    /// Its impacts and their latencies: `Log::impacts[impacts]`, `Log::latencies[impacts]`.
    pub impacts: std::ops::Range<usize>,
    /// Its windows: `Log::waveforms[waveforms]`.
    pub waveforms: std::ops::Range<usize>,
    /// Samples its summary (or last heartbeat) counts (0 without either).
    pub samples: u64,
    /// Its summary's (or last heartbeat's) `samples_lost` and `analyses_skipped`.
    pub samples_lost: u64,
    pub analyses_skipped: u64,
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
        verdict: None,
    })
}

/// A `spec` line: the verdict of the impact with its `index`, or why there is none.
pub(crate) fn parse_verdict(
    m: &HashMap<String, String>,
) -> Result<
    (
        u32,
        Result<impact_core::spec::verdict::Verdict, impact_core::spec::verdict::Missing>,
    ),
    String,
> {
    use impact_core::spec::verdict::{Missing, Verdict};
    let index = num::<u32>(m, "index")?;
    if get(m, "pass")? == "none" {
        let missing = match get(m, "reason")? {
            "spec-window" => Missing::Window,
            "spec-resolution" => Missing::Resolution,
            "spec-overflow" => Missing::Overflow,
            other => return Err(format!("reason={other}: not a reason a verdict is missing")),
        };
        return Ok((index, Err(missing)));
    }
    Ok((
        index,
        Ok(Verdict {
            pass: flag(m, "pass")?,
            band_pass: flag(m, "band_pass")?,
            delta_v_pass: flag(m, "delta_v_pass")?,
            margin: num::<f32>(m, "margin")?,
            worst_s: num::<f64>(m, "worst_s")?,
            worst_m_s2: num::<f32>(m, "worst_m_s2")?,
            limit_m_s2: num::<f32>(m, "limit_m_s2")?,
            delta_v_m_s: num::<f32>(m, "delta_v_m_s")?,
            start_s: num::<f64>(m, "start_s")?,
        }),
    ))
}

/// An `srs` line: the spectra of the impact with its `index`.
pub(crate) fn parse_spectrum(m: &HashMap<String, String>) -> Result<(u32, Spectrum), String> {
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
/// field's range (times and lengths within what the stream allows: [`check_plausible`]),
/// impact indices unique and increasing within a run (unless its summary counts reports
/// printed out of order), heartbeat counters never going back within a run, and at the end
/// of a finite stream as many impact lines as the summary counts. A `scene` line after data
/// lines is a restart of the board: a new run, its indices, times and counters from 0 again
/// (a note in [`Log::warnings`]); a scene unlike the first is an error. Errors name the line.
///
/// Time and memory are linear in the log: what it keeps per impact is its report (and per
/// window the frames received); an impact is found by its index through a map.
#[derive(Default)]
pub struct LogReader {
    log: Log,
    /// The first `scene` line: its number and fields (every later run's must equal them).
    first_scene: Option<(u64, HashMap<String, String>)>,
    run: RunReader,
}

/// What the reader keeps of the run it reads.
#[derive(Default)]
struct RunReader {
    /// Line of the run's `scene` line (0: none).
    line: u64,
    /// Whether the run has a `scene` or data line (a `scene` line then starts a new run).
    started: bool,
    /// Where its impacts and windows start in the log's lists.
    first_impact: usize,
    first_wave: usize,
    /// Each impact's position in `Log::impacts` and its line, by index.
    impacts: HashMap<u32, (usize, u64)>,
    /// Each window's position in `Log::waveforms`, by index.
    waves: HashMap<u32, usize>,
    /// The first impact whose index did not increase: (line, index, previous index).
    reordered: Option<(u64, u32, u32)>,
    /// Line and counters (samples, impacts) of the last heartbeat, and its fields.
    last_heartbeat: Option<(u64, u64, u64)>,
    heartbeat: Option<HashMap<String, String>>,
    summary_line: u64,
    summary: Option<HashMap<String, String>>,
    /// The data lines' sequence numbers seen (`seq`).
    seqs: SeqSet,
    /// Samples per second (the scene's, or the first heartbeat's or summary's), and the
    /// scene's m/s² per count: what [`check_plausible`] needs.
    rate_hz: Option<f64>,
    gain: Option<f64>,
    /// Impacts read before the run's rate was known (line, position): checked when it is.
    unchecked: Vec<(u64, usize)>,
}

impl LogReader {
    /// Sets what a `what` line (`srs`, `spec`) adds to this run's impact `index` (`set` gives
    /// `None` if the impact has it already: a second such line).
    fn attach(
        &mut self,
        index: u32,
        what: &str,
        set: impl FnOnce(&mut ImpactReport) -> Option<()>,
    ) -> Result<(), String> {
        self.run
            .impacts
            .get(&index)
            .and_then(|&(k, _)| self.log.impacts.get_mut(k))
            .and_then(set)
            .ok_or_else(|| {
                format!(
                    "{what} index={index}: no impact line of that index before it, or a second {what} line"
                )
            })
    }

    /// Reads line `n` (1-based).
    pub fn line(&mut self, n: u64, line: &str) -> Result<(), String> {
        let at = |e: String| format!("line {n}: {e}");
        if let Some(m) = fields(line, "impact ") {
            let m = m.map_err(at)?;
            self.seen(&m).map_err(at)?;
            let r = parse_impact(&m).map_err(at)?;
            check_report(&r).map_err(|e| at(e.to_string()))?;
            let latency: Option<f32> = opt(&m, "report_latency_s").map_err(at)?;
            if let Some(l) = latency.filter(|&l| l < 0.0) {
                return Err(at(format!("report_latency_s={l}: not a time >= 0")));
            }
            let run = &mut self.run;
            if let Some(rate) = run.rate_hz {
                check_plausible(&r, rate, run.gain).map_err(|e| at(e.to_string()))?;
            } else {
                run.unchecked.push((n, self.log.impacts.len()));
            }
            if let Some(&(_, first)) = run.impacts.get(&r.index) {
                return Err(at(format!(
                    "impact index={} again (first on line {first}): two streams mixed, or a line repeated",
                    r.index
                )));
            }
            if let Some(prev) = self.log.impacts[run.first_impact..].last() {
                if r.index < prev.index && run.reordered.is_none() {
                    run.reordered = Some((n, r.index, prev.index));
                }
            }
            run.impacts.insert(r.index, (self.log.impacts.len(), n));
            self.log.impacts.push(r);
            self.log.latencies.push(latency);
        } else if let Some(m) = fields(line, "srs ") {
            let m = m.map_err(at)?;
            self.seen(&m).map_err(at)?;
            let (index, spectrum) = parse_spectrum(&m).map_err(at)?;
            self.attach(index, "srs", |r| {
                r.spectrum.is_none().then(|| r.spectrum = Some(spectrum))
            })
            .map_err(at)?;
        } else if let Some(m) = fields(line, "spec ") {
            let m = m.map_err(at)?;
            self.seen(&m).map_err(at)?;
            let (index, verdict) = parse_verdict(&m).map_err(at)?;
            self.attach(index, "spec", |r| {
                r.verdict.is_none().then(|| r.verdict = Some(verdict))
            })
            .map_err(at)?;
        } else if let Some(m) = fields(line, "wave_frame ") {
            let m = m.map_err(at)?;
            self.seen(&m).map_err(at)?;
            let (index, frame, counts) =
                crate::firmware_link::waves::parse_frame(line, &m).map_err(at)?;
            let w = self
                .run
                .waves
                .get(&index)
                .and_then(|&k| self.log.waveforms.get_mut(k))
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
            if self.run.waves.contains_key(&w.index) {
                return Err(at(format!(
                    "wave index={} again: two streams mixed, or a line repeated",
                    w.index
                )));
            }
            self.run.waves.insert(w.index, self.log.waveforms.len());
            self.log.waveforms.push(w);
        } else if let Some(m) = fields(line, "heartbeat ") {
            let m = m.map_err(at)?;
            self.seen(&m).map_err(at)?;
            let samples: u64 = num(&m, "samples").map_err(at)?;
            let impacts: u64 = num(&m, "impacts").map_err(at)?;
            let rate = rate(&m).map_err(at)?;
            if let Some((line, s0, i0)) = self.run.last_heartbeat {
                if samples < s0 || impacts < i0 {
                    return Err(at(format!(
                        "heartbeat samples={samples} impacts={impacts} after samples={s0} \
                         impacts={i0} (line {line}): counters never go back within a run"
                    )));
                }
            }
            self.run.last_heartbeat = Some((n, samples, impacts));
            self.run.heartbeat = Some(m);
            self.rate_known(rate)?;
        } else if let Some(m) = fields(line, "summary ") {
            let m = m.map_err(at)?;
            self.seen(&m).map_err(at)?;
            num::<u64>(&m, "samples").map_err(at)?;
            num::<u64>(&m, "impacts").map_err(at)?;
            let rate = rate(&m).map_err(at)?;
            self.run.summary_line = n;
            self.run.summary = Some(m);
            self.rate_known(rate)?;
        } else if let Some(m) = fields(line, "scene ") {
            let m = m.map_err(at)?;
            let rate = rate(&m).map_err(at)?;
            let gain: Option<f32> = match m.get("gain_m_s2_per_count") {
                Some(_) => Some(num(&m, "gain_m_s2_per_count").map_err(at)?),
                None => None,
            };
            match &self.first_scene {
                None => self.first_scene = Some((n, m.clone())),
                Some((first, scene)) => {
                    if let Some(e) = scene_difference(scene, &m) {
                        return Err(at(format!(
                            "a scene unlike line {first}'s ({e}): logs of two benches mixed; \
                             split the log before line {n}"
                        )));
                    }
                }
            }
            if self.run.started {
                self.end_run()?;
                self.run = RunReader {
                    first_impact: self.log.impacts.len(),
                    first_wave: self.log.waveforms.len(),
                    ..RunReader::default()
                };
                self.log.warnings.push(format!(
                    "line {n}: the board restarted (a new scene line): run {}'s impact indices, \
                     sample positions and times start from 0 again (\"run\" in the JSON, the \
                     CSV's run column)",
                    self.log.runs.len() + 1
                ));
            }
            self.run.line = n;
            self.run.started = true;
            self.run.gain = gain.map(f64::from);
            self.rate_known(rate)?;
            self.log.scene.get_or_insert(m);
        }
        Ok(())
    }

    /// A data line's sequence number (`seq`, absent from firmware that did not number them).
    fn seen(&mut self, m: &HashMap<String, String>) -> Result<(), String> {
        self.run.started = true;
        if m.contains_key("seq") {
            self.run.seqs.insert(num(m, "seq")?);
        }
        Ok(())
    }

    /// The run's sample rate, from its scene or its first heartbeat or summary: the impacts
    /// read before it are checked now.
    fn rate_known(&mut self, rate: f32) -> Result<(), String> {
        let run = &mut self.run;
        if run.rate_hz.is_some() {
            return Ok(());
        }
        run.rate_hz = Some(f64::from(rate));
        for (line, k) in std::mem::take(&mut run.unchecked) {
            check_plausible(&self.log.impacts[k], f64::from(rate), run.gain)
                .map_err(|e| format!("line {line}: {e}"))?;
        }
        Ok(())
    }

    /// The log, every run's reports in index order; checks each run's counts against its
    /// summary.
    pub fn finish(mut self) -> Result<Log, String> {
        self.end_run()?;
        Ok(self.log)
    }

    /// Closes the run read: its counts checked against its summary (or last heartbeat), its
    /// impacts and windows put in index order, its counters added to the log's.
    fn end_run(&mut self) -> Result<(), String> {
        let run = std::mem::take(&mut self.run);
        let log = &mut self.log;
        let printed = run.impacts.len() as u64;
        let state = run.summary.as_ref().or(run.heartbeat.as_ref());
        let counter = |key: &str| -> Result<u64, String> {
            match state {
                Some(m) if m.contains_key(key) => num::<u64>(m, key),
                _ => Ok(0),
            }
        };
        let lines_dropped = counter("lines_dropped")?;
        let lines_missing = run.seqs.missing();
        log.lines_dropped += lines_dropped;
        log.lines_missing += lines_missing;
        if lines_missing > 0 || lines_dropped > 0 {
            let first: Vec<String> = run
                .seqs
                .first_missing(5)
                .iter()
                .map(u32::to_string)
                .collect();
            log.warnings.push(format!(
                "the board dropped {lines_dropped} lines (its logger's count); {lines_missing} \
                 numbered lines are missing{}",
                if lines_missing > 0 {
                    format!(
                        " (seq {}{})",
                        first.join(", "),
                        if lines_missing > 5 { ", …" } else { "" }
                    )
                } else {
                    String::new()
                }
            ));
        }
        let lost = lines_dropped + lines_missing > 0;
        if let Some(m) = &run.summary {
            let at = |e: String| format!("line {}: {e}", run.summary_line);
            let counted: u64 = num(m, "impacts").map_err(at)?;
            let dropped: u64 = num(m, "reports_dropped").map_err(at)?;
            // Lines the board dropped (counted) explain missing impact lines.
            if printed + dropped != counted && !(lost && printed + dropped < counted) {
                return Err(at(format!(
                    "the summary counts {counted} impacts ({dropped} reports dropped), the log \
                     has {printed} impact lines: lines lost, or two streams mixed"
                )));
            }
            if let Some(index) = run
                .impacts
                .keys()
                .copied()
                .filter(|&i| u64::from(i) >= counted)
                .min()
            {
                return Err(at(format!(
                    "impact index={index} but the summary counts {counted} impacts"
                )));
            }
            if let Some((line, index, prev)) = run.reordered {
                if num::<u64>(m, "reports_out_of_order").map_err(at)? == 0 {
                    return Err(format!(
                        "line {line}: impact index={index} after index={prev}, and the \
                         summary counts no report out of order"
                    ));
                }
            }
        } else {
            if let Some((line, index, prev)) = run.reordered {
                return Err(format!(
                    "line {line}: impact index={index} after index={prev} (the firmware prints \
                     in index order; a reorder is counted only in a summary line)"
                ));
            }
            if let (Some((line, _, counted)), Some(m)) = (run.last_heartbeat, &run.heartbeat) {
                let dropped: u64 =
                    num(m, "reports_dropped").map_err(|e| format!("line {line}: {e}"))?;
                if printed + dropped < counted {
                    log.warnings.push(format!(
                        "line {line}: the heartbeat counts {counted} impacts ({dropped} reports \
                         dropped), the log has {printed} impact lines: a cut log, or lines lost \
                         on the link"
                    ));
                }
            }
        }
        let waves = &mut log.waveforms[run.first_wave..];
        waves.sort_by_key(|w| w.index);
        for w in waves.iter() {
            if w.missing_frames() > 0 {
                log.warnings.push(format!(
                    "impact {}: {} of {} waveform frames missing (the link dropped them)",
                    w.index,
                    w.missing_frames(),
                    w.frames
                ));
            }
        }
        if run.reordered.is_some() {
            let mut both: Vec<_> = log
                .impacts
                .drain(run.first_impact..)
                .zip(log.latencies.drain(run.first_impact..))
                .collect();
            both.sort_by_key(|(r, _)| r.index);
            for (r, l) in both {
                log.impacts.push(r);
                log.latencies.push(l);
            }
        }
        log.runs.push(Run {
            line: run.line,
            impacts: run.first_impact..log.impacts.len(),
            waveforms: run.first_wave..log.waveforms.len(),
            samples: counter("samples")?,
            samples_lost: counter("samples_lost")?,
            analyses_skipped: counter("analyses_skipped")?,
        });
        log.heartbeat = run.heartbeat;
        log.summary = run.summary;
        Ok(())
    }
}

/// The first field (in name order) in which two `scene` lines differ, as `key=new, not old`.
fn scene_difference(
    first: &HashMap<String, String>,
    new: &HashMap<String, String>,
) -> Option<String> {
    let mut keys: Vec<&String> = first.keys().chain(new.keys()).collect();
    keys.sort_unstable();
    keys.into_iter().find_map(|k| {
        let (a, b) = (first.get(k), new.get(k));
        (a != b).then(|| {
            let show = |v: Option<&String>| v.map_or("absent".to_string(), |v| format!("{k}={v}"));
            format!("{}, not {}", show(b), show(a))
        })
    })
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
