//! `impact log`: a decoded firmware log (the lines of docs/board.md, read by
//! [`crate::firmware_link::line`]) read back, checked line by line, and turned into `impact
//! analyze`'s JSON and CSV.

mod error;
mod run;
mod seq;

pub use error::{LogError, LogErrorKind};

use std::collections::HashMap;

use impact_core::ImpactReport;

use crate::firmware_link::line::{
    self, Fields, HeartbeatLine, ImpactLine, LineKind, SceneLine, SpecLine, SrsLine, SummaryLine,
    WaveFrameLine, WaveLine,
};
use crate::firmware_link::plausible::{check_plausible, Bounds};
use crate::firmware_link::waves::Waveform;
use error::At;
use seq::SeqSet;

/// What a firmware log says. A log can hold several runs of the board: one that resets starts
/// a new run with a new `scene` line, its impact indices, sample positions and times from 0
/// again. Every run's impacts are kept, run after run ([`Log::runs`] tells them apart).
#[derive(Clone, Debug, Default)]
pub struct Log {
    /// The `scene` line, if the log has one (every run's scene is the same).
    pub scene: Option<SceneLine>,
    /// Every run's impacts, run after run, each run's in index order.
    pub impacts: Vec<ImpactReport>,
    /// Each impact's `report_latency_s` (real-time sources only).
    pub latencies: Vec<Option<f32>>,
    /// The last run's last `heartbeat` line.
    pub heartbeat: Option<HeartbeatLine>,
    /// The last run's `summary` line (only at the end of a finite stream).
    pub summary: Option<SummaryLine>,
    /// What looks wrong without being impossible (e.g. fewer impact lines than the last
    /// heartbeat counts), by line; and each restart of the board.
    pub warnings: Vec<String>,
    /// The captured windows the board sent (`wave` lines, scene `wave_every` > 0), run after
    /// run, each run's in index order.
    pub waveforms: Vec<Waveform>,
    /// Lines the board's logger dropped (each run's summary's, else its last heartbeat's
    /// `lines_dropped`, summed; 0 from firmware that did not count them).
    pub lines_dropped: u64,
    /// Data lines whose sequence numbers (`seq`) the log lacks, before the last one it has
    /// (each run numbers its lines from 0; summed).
    pub lines_missing: u64,
    /// The runs, in the order of the log (one for a log without a restart).
    pub runs: Vec<Run>,
    /// Lines passed over (a reader made by [`LogReader::skipping`]): each line's number and
    /// why, in line order.
    pub skipped: Vec<Skipped>,
}

/// A line passed over: its number and what is wrong with it, shown `line N: what (skipped)`.
#[derive(Clone, Debug, PartialEq)]
pub struct Skipped {
    pub line: u64,
    pub kind: LogErrorKind,
    /// The kind of line it is, when its name says it.
    pub of: Option<LineKind>,
}

impl Skipped {
    /// Why, for an output (JSON, CSV, a report): the error's text with a non-finite value it
    /// quotes from the line (`inf`, `NaN`) said in words, so no output holds one.
    pub fn reason(&self) -> String {
        let text = self.kind.to_string();
        let mut out = String::with_capacity(text.len());
        let mut word = String::new();
        let flush = |word: &mut String, out: &mut String| {
            out.push_str(match word.to_ascii_lowercase().as_str() {
                "inf" | "infinity" => "an infinite value",
                "nan" => "not-a-number",
                _ => word,
            });
            word.clear();
        };
        for c in text.chars() {
            if c.is_ascii_alphanumeric() {
                word.push(c);
            } else {
                flush(&mut word, &mut out);
                out.push(c);
            }
        }
        flush(&mut word, &mut out);
        out
    }

    /// `line N: why (skipped)`, for an output ([`Skipped::reason`]).
    pub fn note(&self) -> String {
        format!("line {}: {} (skipped)", self.line, self.reason())
    }
}

impl std::fmt::Display for Skipped {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "line {}: {} (skipped)", self.line, self.kind)
    }
}

/// Whether an impact line is one `impact log` takes: its latency a time >= 0 and, once its
/// run's rate is known (`bounds`), its times, lengths and sample span within what its stream
/// allows ([`check_plausible`]; its signs and ranges were checked as it was parsed). The live
/// view's statistics take only the impacts this accepts.
pub fn accept(line: &ImpactLine, bounds: Option<&Bounds>) -> Result<(), LogErrorKind> {
    if let Some(value) = line.report_latency_s.filter(|&l| l < 0.0) {
        return Err(LogErrorKind::NegativeLatency { value });
    }
    if let Some(b) = bounds {
        check_plausible(&line.report, b)?;
    }
    Ok(())
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

/// Parses a decoded firmware log (any other lines are ignored), checking what it reads (see
/// [`LogReader`]).
pub fn parse_log(text: &str) -> Result<Log, LogError> {
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
    /// Whether a line whose own text is wrong ([`LogErrorKind::is_the_lines`]) is passed
    /// over and noted ([`Log::skipped`]) instead of ending the reading.
    skip: bool,
    /// Line of the first `scene` line (`Log::scene`: every later run's must equal it).
    first_scene: u64,
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
    /// The last heartbeat and its line.
    heartbeat: Option<(u64, HeartbeatLine)>,
    /// The summary and its line.
    summary: Option<(u64, SummaryLine)>,
    /// The data lines' sequence numbers seen (`seq`).
    seqs: SeqSet,
    /// Samples per second (the scene's, or the first heartbeat's or summary's), and the
    /// scene's m/s² per count: what [`check_plausible`] needs.
    rate_hz: Option<f64>,
    gain: Option<f64>,
    /// The scene's longest impact, s.
    max_impact_s: Option<f64>,
    /// Impacts read before the run's rate was known (line, position): checked when it is.
    unchecked: Vec<(u64, usize)>,
}

impl LogReader {
    /// A reader that passes over a line whose own text is wrong (a line cut by the link, a
    /// value no board gives), noting it in [`Log::skipped`]; what only several lines show
    /// (two streams mixed, counters going back) still ends the reading.
    pub fn skipping() -> Self {
        Self {
            skip: true,
            ..Self::default()
        }
    }

    /// Reads line `n` (1-based).
    pub fn line(&mut self, n: u64, text: &str) -> Result<(), LogError> {
        match self.read(n, text) {
            Err(e) if self.skip && e.line == Some(n) && e.kind.is_the_lines() => {
                self.log.skipped.push(Skipped {
                    line: n,
                    kind: e.kind,
                    of: line::find(text, &LineKind::ALL).map(|(k, _)| k),
                });
                Ok(())
            }
            r => r,
        }
    }

    fn read(&mut self, n: u64, text: &str) -> Result<(), LogError> {
        let Some((kind, fields)) = line::find(text, &LineKind::ALL) else {
            return Ok(());
        };
        let fields = fields.at(n)?;
        // A data line's sequence number (`seq`, absent from firmware that did not number
        // them), counted once the line is read: a line passed over is a line missing.
        let seq = if kind.is_data() {
            fields.given::<u32>("seq").at(n)?
        } else {
            None
        };
        self.read_kind(n, kind, text, fields)?;
        if kind.is_data() {
            self.run.started = true;
            if let Some(seq) = seq {
                self.run.seqs.insert(seq);
            }
        }
        Ok(())
    }

    fn read_kind(
        &mut self,
        n: u64,
        kind: LineKind,
        text: &str,
        fields: Fields,
    ) -> Result<(), LogError> {
        match kind {
            LineKind::Impact => self.impact(n, &fields),
            LineKind::Srs => self.srs(n, &fields),
            LineKind::Spec => self.spec(n, &fields),
            LineKind::WaveFrame => self.wave_frame(n, text, &fields),
            LineKind::Wave => self.wave(n, &fields),
            LineKind::Heartbeat => self.heartbeat(n, fields),
            LineKind::Summary => self.summary(n, fields),
            LineKind::Scene => self.scene(n, fields),
        }
    }

    /// The log, every run's reports in index order; checks each run's counts against its
    /// summary.
    pub fn finish(mut self) -> Result<Log, LogError> {
        self.end_run()?;
        self.log.skipped.sort_by_key(|s| s.line);
        Ok(self.log)
    }

    fn impact(&mut self, n: u64, f: &Fields) -> Result<(), LogError> {
        let line = ImpactLine::parse(f).at(n)?;
        let bounds = self.run.bounds();
        accept(&line, bounds.as_ref()).at(n)?;
        let ImpactLine {
            report: r,
            report_latency_s: latency,
        } = line;
        let run = &mut self.run;
        if let Some(&(_, first)) = run.impacts.get(&r.index) {
            let index = r.index;
            return Err(LogError::at(n, LogErrorKind::ImpactAgain { index, first }));
        }
        if let Some(prev) = self.log.impacts[run.first_impact..].last() {
            if r.index < prev.index && run.reordered.is_none() {
                run.reordered = Some((n, r.index, prev.index));
            }
        }
        if bounds.is_none() {
            run.unchecked.push((n, self.log.impacts.len()));
        }
        run.impacts.insert(r.index, (self.log.impacts.len(), n));
        self.log.impacts.push(r);
        self.log.latencies.push(latency);
        Ok(())
    }

    fn srs(&mut self, n: u64, f: &Fields) -> Result<(), LogError> {
        let SrsLine { index, spectrum } = SrsLine::parse(f).at(n)?;
        self.attach(index, LineKind::Srs, |r| {
            r.spectrum.is_none().then(|| r.spectrum = Some(spectrum))
        })
        .at(n)
    }

    fn spec(&mut self, n: u64, f: &Fields) -> Result<(), LogError> {
        let SpecLine { index, verdict } = SpecLine::parse(f).at(n)?;
        self.attach(index, LineKind::Spec, |r| {
            r.verdict.is_none().then(|| r.verdict = Some(verdict))
        })
        .at(n)
    }

    /// Sets what a `kind` line (`srs`, `spec`) adds to this run's impact `index` (`set` gives
    /// `None` if the impact has it already: a second such line).
    fn attach(
        &mut self,
        index: u32,
        kind: LineKind,
        set: impl FnOnce(&mut ImpactReport) -> Option<()>,
    ) -> Result<(), LogErrorKind> {
        self.run
            .impacts
            .get(&index)
            .and_then(|&(k, _)| self.log.impacts.get_mut(k))
            .and_then(set)
            .ok_or(LogErrorKind::NoImpactFor { kind, index })
    }

    fn wave_frame(&mut self, n: u64, text: &str, f: &Fields) -> Result<(), LogError> {
        let WaveFrameLine {
            index,
            frame,
            counts,
        } = WaveFrameLine::parse(text, f).at(n)?;
        let w = self
            .run
            .waves
            .get(&index)
            .and_then(|&k| self.log.waveforms.get_mut(k))
            .ok_or(LogErrorKind::NoWaveFor { index })
            .at(n)?;
        w.add_frame(frame, counts).at(n)
    }

    fn wave(&mut self, n: u64, f: &Fields) -> Result<(), LogError> {
        let w = Waveform::new(WaveLine::parse(f).at(n)?);
        if self.run.waves.contains_key(&w.index) {
            let index = w.index;
            return Err(LogError::at(n, LogErrorKind::WaveAgain { index }));
        }
        self.run.waves.insert(w.index, self.log.waveforms.len());
        self.log.waveforms.push(w);
        Ok(())
    }

    fn heartbeat(&mut self, n: u64, fields: Fields) -> Result<(), LogError> {
        let h = HeartbeatLine::parse(fields).at(n)?;
        if let Some((line, before)) = &self.run.heartbeat {
            if h.samples < before.samples || h.impacts < before.impacts {
                let back = LogErrorKind::CountersBack {
                    samples: h.samples,
                    impacts: h.impacts,
                    samples_before: before.samples,
                    impacts_before: before.impacts,
                    line: *line,
                };
                return Err(LogError::at(n, back));
            }
        }
        let rate = h.rate_hz;
        self.run.heartbeat = Some((n, h));
        self.rate_known(rate)
    }

    fn summary(&mut self, n: u64, fields: Fields) -> Result<(), LogError> {
        let s = SummaryLine::parse(fields).at(n)?;
        let rate = s.rate_hz;
        self.run.summary = Some((n, s));
        self.rate_known(rate)
    }

    /// A scene: the first one kept, a later one equal to it (a restart of the board after
    /// data lines: a new run).
    fn scene(&mut self, n: u64, fields: Fields) -> Result<(), LogError> {
        let scene = SceneLine::parse(fields).at(n)?;
        if let Some(difference) = self.log.scene.as_ref().and_then(|s| s.difference(&scene)) {
            let unlike = LogErrorKind::SceneUnlike {
                first: self.first_scene,
                difference,
                line: n,
            };
            return Err(LogError::at(n, unlike));
        }
        if self.run.started {
            self.restart(n)?;
        }
        self.run.line = n;
        self.run.started = true;
        self.run.gain = scene.gain_m_s2_per_count.map(f64::from);
        self.run.max_impact_s = scene.max_impact_s();
        let rate = scene.rate_hz;
        if self.log.scene.is_none() {
            self.first_scene = n;
            self.log.scene = Some(scene);
        }
        self.rate_known(rate)
    }

    /// The board restarted on line `n`: the run read ends, a new one starts.
    fn restart(&mut self, n: u64) -> Result<(), LogError> {
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
        Ok(())
    }

    /// The run's sample rate, from its scene or its first heartbeat or summary: the impacts
    /// read before it are checked now.
    fn rate_known(&mut self, rate: f32) -> Result<(), LogError> {
        let run = &mut self.run;
        if run.rate_hz.is_some() {
            return Ok(());
        }
        run.rate_hz = Some(f64::from(rate));
        let Some(bounds) = run.bounds() else {
            return Ok(());
        };
        let mut refused = Vec::new();
        for (line, k) in std::mem::take(&mut run.unchecked) {
            if let Err(e) = check_plausible(&self.log.impacts[k], &bounds) {
                if !self.skip {
                    return Err(LogError::at(line, e));
                }
                refused.push((line, k, e));
            }
        }
        // Passed over now: out of the log, the later impacts' positions one less.
        for (line, k, e) in refused.into_iter().rev() {
            self.log.impacts.remove(k);
            self.log.latencies.remove(k);
            run.impacts.retain(|_, (at, _)| *at != k);
            for (at, _) in run.impacts.values_mut() {
                if *at > k {
                    *at -= 1;
                }
            }
            self.log.skipped.push(Skipped {
                line,
                kind: e.into(),
                of: Some(LineKind::Impact),
            });
        }
        Ok(())
    }
}

impl RunReader {
    /// What the run's impacts are checked against, once its rate is known.
    fn bounds(&self) -> Option<Bounds> {
        Some(Bounds {
            rate_hz: self.rate_hz?,
            gain: self.gain,
            max_impact_s: self.max_impact_s,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::firmware_link::line::FieldError;
    use impact_core::Status;

    const LINE: &str = "0.013931 INFO  impact index=0 status=complete analysis=full clipped=false flags=0 start_sample=5000 end_sample=17000 start_s=0.01 peak_time_s=0.0100251 peak_acceleration_m_s2=4321.5 peak_force_n=259.29 delta_v_m_s=2.5 duration_s=0.0219 baseline_m_s2=0.2 fwhm_s=0.001 filtered_peak_acceleration_m_s2=none filtered_fwhm_s=none impact_velocity_m_s=1.3357 crush_time_s=0.0218 max_deformation_m=0.0186 rebound_velocity_m_s=1.16 cor=0.87 separation_deformation_m=0.0182 permanent_deformation_m=0.0182 absorbed_energy_j=none two_phase_kc_n_m=none two_phase_kr_n_m=none two_phase_c_n_s_m=none two_phase_permanent_deformation_m=none two_phase_residual=none nonlinear_k=1e6 nonlinear_c_s_m=0.5 nonlinear_exponent=1.2 nonlinear_residual=0.01 hertz_k=none hertz_residual=none report_latency_s=0.0123";

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
        let missing = FieldError::Missing { field: "fwhm_s" };
        assert_eq!(e, LogError::at(1, missing));
        assert_eq!(e.to_string(), "line 1: missing field fwhm_s");
        // A bad number names the field and the text.
        let e = parse_log(&with("flags", "x1")).unwrap_err();
        let bad = FieldError::NotANumber {
            field: "flags",
            text: "x1".into(),
        };
        assert_eq!(e, LogError::at(1, bad));
        assert_eq!(e.to_string(), "line 1: flags=x1: not a number");
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
            let e = parse_log(&text).unwrap_err().to_string();
            assert!(
                e.starts_with("line 2: ") && e.contains(says),
                "{field}={value}: {e}"
            );
        }
        let scene = "scene rate_hz=NaN\n";
        assert!(parse_log(scene)
            .unwrap_err()
            .to_string()
            .contains("line 1: rate_hz=NaN"));
        let beat = "heartbeat samples=5 impacts=0 rate_hz=-5 reports_dropped=0\n";
        assert!(parse_log(beat)
            .unwrap_err()
            .to_string()
            .contains("rate_hz=-5"));
    }

    #[test]
    fn indices_must_be_unique_and_increasing() {
        let zero = with("index", "0");
        let e = parse_log(&format!("{zero}\n{zero}\n{zero}\n"))
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("line 2: impact index=0 again (first on line 1)"),
            "{e}"
        );
        let five = with("index", "5");
        let e = parse_log(&format!("{five}\n{zero}\n"))
            .unwrap_err()
            .to_string();
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
        let e = parse_log(&format!("{lines}{summary}\n"))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("line 4: the summary counts 7 impacts"), "{e}");
        // Counters never go back.
        let back = "heartbeat samples=4 impacts=7 rate_hz=1000 reports_dropped=0";
        let e = parse_log(&format!("{beat}\n{back}\n"))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("line 2: heartbeat samples=4"), "{e}");
    }
}
