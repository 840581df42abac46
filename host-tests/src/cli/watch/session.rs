//! `impact watch`'s session: the board's lines turned into the live view's events (JSON, the
//! protocol the page reads), keeping only what the view shows: the last impacts, the trend,
//! running statistics, the board's health. Memory does not grow with the session.

use std::collections::VecDeque;

use impact_core::consts::STANDARD_GRAVITY;
use impact_core::spec::Spec;
use impact_core::ImpactReport;
use serde_json::{json, Map, Value};

use crate::firmware_link::line::{
    self, Counter, FieldError, Fields, ImpactLine, LineError, LineKind, SpecLine, SrsLine, State,
    WaveFrameLine, WaveLine,
};
use crate::firmware_link::log;
use crate::firmware_link::plausible::Bounds;
use crate::firmware_link::waves::{WaveError, Waveform};
use crate::report::statistics::Running;

/// Impacts kept with their pulses (the newest; the page's "last impact" and its table start).
pub const LAST: usize = 50;
/// Trend points kept (the newest).
pub const TREND: usize = 2000;
/// Runs kept (the newest): a board that resets all day.
pub const RUNS: usize = 100;
/// How long an impact line waits for its `srs` and `spec` lines before it is shown, ms (they
/// follow it at once from the board's reporter; the wait covers a file followed in 50 ms
/// polls and a link's hiccups).
pub const HOLD_MS: u64 = 300;
/// The longest text kept of a line's error or a scene's value, bytes.
const MAX_TEXT: usize = 200;
/// A board is silent when its last heartbeat (one a second) is older than this, ms: within
/// two heartbeats.
pub const SILENT_MS: u64 = 2500;
/// Points a pulse is drawn with at most (min/max of 200 columns).
const PULSE_COLUMNS: usize = 200;

/// The metrics the trend and the statistics follow: name, label, read off an impact event.
const METRICS: [(&str, &str); 4] = [
    ("peak_g", "peak, g"),
    ("delta_v_m_s", "Δv, m/s"),
    ("duration_s", "duration, s"),
    ("cor", "COR"),
];

/// One impact on the trend (kept small: the session keeps [`TREND`] of them).
#[derive(Clone, Copy, Debug, serde::Serialize)]
struct TrendPoint {
    run: u32,
    index: u32,
    received_unix_ms: u64,
    peak_g: Option<f64>,
    delta_v_m_s: Option<f64>,
    duration_s: Option<f64>,
    cor: Option<f64>,
    pass: Option<bool>,
}

/// An impact line waiting for its `srs` and `spec` lines.
struct Pending {
    received_ms: u64,
    report: ImpactReport,
    latency_s: Option<f32>,
    /// The captured window the board sent before it, if it is this impact's.
    wave: Option<Waveform>,
}

/// What the session knows and shows.
pub struct Session {
    /// The pulse the impacts are drawn against: the board's (its scene line states it), else
    /// the one `--spec` gave.
    spec: Option<Spec>,
    /// The pulse `--spec` gave, if any, and the standard it named.
    given: Option<(Spec, &'static str)>,
    head: Map<String, Value>,
    run: u32,
    /// Whether the current run has had a data line (a `scene` line then is a restart).
    started: bool,
    rate_hz: Option<f64>,
    gain: Option<f64>,
    /// The scene's longest impact, s, and the run's rate from a heartbeat or summary (before
    /// a scene line, or without one): what an impact is checked against.
    max_impact_s: Option<f64>,
    state_rate_hz: Option<f64>,
    /// Gravity in the contacts, m/s² (the scene line's; none: horizontal).
    contact_gravity_m_s2: Option<f32>,
    /// The window being received (only the newest is kept).
    wave: Option<Waveform>,
    pending: Option<Pending>,
    impacts: VecDeque<Value>,
    trend: VecDeque<TrendPoint>,
    runs: VecDeque<Value>,
    stats: [Running; 4],
    /// Judged and passed, judged, not judged.
    passed: usize,
    judged: usize,
    not_judged: usize,
    health: Option<Value>,
    ended: Option<Value>,
    /// Lines read, and when the last one and the last heartbeat came (Unix ms).
    pub lines: u64,
    last_line_ms: Option<u64>,
    last_heartbeat_ms: Option<u64>,
    /// Lines that looked like the board's but could not be read, and the last one's error.
    pub bad_lines: u64,
    last_error: Option<String>,
}

impl Session {
    /// A session reading `source` into `session_file`, its impacts drawn against `spec` (and
    /// the standard `--spec` named) when given, until the board states its own.
    pub fn new(source: &str, session_file: &str, spec: Option<(Spec, &'static str)>) -> Self {
        let mut head = Map::new();
        head.insert(
            "tool".into(),
            json!(format!("impact {}", env!("CARGO_PKG_VERSION"))),
        );
        head.insert("source".into(), json!(source));
        head.insert("session_file".into(), json!(session_file));
        head.insert(
            "spec".into(),
            spec.as_ref().map_or(Value::Null, |(s, named)| {
                spec_head(s, &spec_text(s, Some(named)), "--spec", None)
            }),
        );
        Self {
            spec: spec.as_ref().map(|(s, _)| *s),
            given: spec,
            head,
            run: 1,
            started: false,
            rate_hz: None,
            gain: None,
            max_impact_s: None,
            state_rate_hz: None,
            contact_gravity_m_s2: None,
            wave: None,
            pending: None,
            impacts: VecDeque::new(),
            trend: VecDeque::new(),
            runs: VecDeque::new(),
            stats: Default::default(),
            passed: 0,
            judged: 0,
            not_judged: 0,
            health: None,
            ended: None,
            lines: 0,
            last_line_ms: None,
            last_heartbeat_ms: None,
            bad_lines: 0,
            last_error: None,
        }
    }

    /// The pulse the impacts are drawn against (the board's, else `--spec`'s).
    /// The pulse drawn and the standard named for it (`--spec`'s while it is drawn; a
    /// board's names none).
    pub fn spec(&self) -> Option<(Spec, Option<&'static str>)> {
        let named = self
            .given
            .filter(|(g, _)| Some(*g) == self.spec)
            .map(|(_, n)| n);
        self.spec.map(|s| (s, named))
    }

    /// Reads line `n` of the input, received at `now_ms` (Unix ms); returns the events it
    /// makes. A line that is not the board's is passed over; one that is but cannot be read
    /// is counted and reported as a `warning` event, and the session goes on.
    pub fn line(&mut self, n: u64, line: &str, now_ms: u64) -> Vec<Value> {
        self.lines += 1;
        self.last_line_ms = Some(now_ms);
        let mut events = Vec::new();
        if let Err(e) = self.read(line, now_ms, &mut events) {
            self.bad_lines += 1;
            let text = format!("line {n}: {}", cut(&e.to_string()));
            self.last_error = Some(text.clone());
            events.push(json!({"type": "warning", "text": text}));
        }
        events
    }

    fn read(
        &mut self,
        line: &str,
        now_ms: u64,
        events: &mut Vec<Value>,
    ) -> Result<(), SessionError> {
        let Some((kind, fields)) = line::find(line, &KINDS) else {
            return Ok(());
        };
        // An impact's `srs` and `spec` lines (and a window's frames) follow it; any other
        // data line shows the waiting impact first.
        if !matches!(kind, LineKind::Srs | LineKind::Spec | LineKind::WaveFrame) {
            self.show(events);
        }
        let fields = fields?;
        match kind {
            LineKind::Srs => self.read_srs(&fields),
            LineKind::Spec => self.read_spec(&fields, events),
            LineKind::WaveFrame => self.read_wave_frame(line, &fields),
            LineKind::Impact => self.read_impact(&fields, now_ms),
            LineKind::Wave => self.read_wave(&fields),
            LineKind::Heartbeat => self.read_heartbeat(fields, now_ms, events),
            LineKind::Summary => self.read_summary(fields, now_ms, events),
            LineKind::Scene => self.read_scene(fields, now_ms, events),
        }
    }

    /// An `srs` line: the waiting impact's spectra.
    fn read_srs(&mut self, f: &Fields) -> Result<(), SessionError> {
        let SrsLine { index, spectrum } = SrsLine::parse(f)?;
        match self.pending.as_mut().filter(|p| p.report.index == index) {
            Some(p) => p.report.spectrum = Some(spectrum),
            None => {
                return Err(SessionError::Late {
                    kind: LineKind::Srs,
                    index,
                })
            }
        }
        Ok(())
    }

    /// A `spec` line: the waiting impact's verdict, its last line (shown then).
    fn read_spec(&mut self, f: &Fields, events: &mut Vec<Value>) -> Result<(), SessionError> {
        let SpecLine { index, verdict } = SpecLine::parse(f)?;
        match self.pending.as_mut().filter(|p| p.report.index == index) {
            Some(p) => {
                p.report.verdict = Some(verdict);
                self.show(events);
            }
            None => {
                return Err(SessionError::Late {
                    kind: LineKind::Spec,
                    index,
                })
            }
        }
        Ok(())
    }

    /// A `wave_frame` line: a frame of the window being received (another's is passed over).
    fn read_wave_frame(&mut self, line: &str, f: &Fields) -> Result<(), SessionError> {
        let WaveFrameLine {
            index,
            frame,
            counts,
        } = WaveFrameLine::parse(line, f)?;
        if let Some(w) = self.wave.as_mut().filter(|w| w.index == index) {
            w.add_frame(frame, counts)?;
        }
        Ok(())
    }

    /// What an impact is checked against: the run's rate (the scene's, else a heartbeat's),
    /// the scene's gain and longest impact; `None` before any rate came.
    fn bounds(&self) -> Option<Bounds> {
        Some(Bounds {
            rate_hz: self.rate_hz.or(self.state_rate_hz)?,
            gain: self.gain,
            max_impact_s: self.max_impact_s,
        })
    }

    /// An `impact` line: it waits for its `srs` and `spec` lines. Only an impact `impact log`
    /// takes ([`log::accept`]) is shown and enters the statistics.
    fn read_impact(&mut self, f: &Fields, now_ms: u64) -> Result<(), SessionError> {
        let line = ImpactLine::parse(f)?;
        log::accept(&line, self.bounds().as_ref())?;
        let ImpactLine {
            report,
            report_latency_s: latency_s,
        } = line;
        let wave = self.wave.take().filter(|w| w.index == report.index);
        self.started = true;
        self.pending = Some(Pending {
            received_ms: now_ms,
            report,
            latency_s,
            wave,
        });
        Ok(())
    }

    /// A `wave` line: the window received next (only the newest is kept).
    fn read_wave(&mut self, f: &Fields) -> Result<(), SessionError> {
        self.started = true;
        // (A line declaring more values than a window holds is refused as it is parsed.)
        self.wave = Some(Waveform::new(WaveLine::parse(f)?));
        Ok(())
    }

    fn read_heartbeat(
        &mut self,
        f: Fields,
        now_ms: u64,
        events: &mut Vec<Value>,
    ) -> Result<(), SessionError> {
        self.started = true;
        self.last_heartbeat_ms = Some(now_ms);
        let state = State::new(f);
        let h = self.health(&state, now_ms)?;
        if self.state_rate_hz.is_none() {
            self.state_rate_hz = Some(f64::from(state.rate_hz()?));
        }
        self.health = Some(h.clone());
        events.push(tagged("health", h));
        Ok(())
    }

    fn read_summary(
        &mut self,
        f: Fields,
        now_ms: u64,
        events: &mut Vec<Value>,
    ) -> Result<(), SessionError> {
        let state = State::new(f);
        let h = self.health(&state, now_ms)?;
        self.health = Some(h.clone());
        events.push(tagged("health", h));
        let result = state.result()?;
        let end = json!({"result": result, "received_unix_ms": now_ms});
        self.ended = Some(end.clone());
        events.push(tagged("end", end));
        Ok(())
    }

    /// A scene: the board (re)started (as `impact log` counts runs: any scene line after the
    /// first line of the board's is a restart). Shown as the line gives it.
    fn read_scene(
        &mut self,
        f: Fields,
        now_ms: u64,
        events: &mut Vec<Value>,
    ) -> Result<(), SessionError> {
        let rate_hz = f64::from(line::rate(&f)?);
        if self.started {
            self.run += 1;
            self.wave = None;
            self.ended = None;
            self.state_rate_hz = None;
        }
        self.started = true;
        self.rate_hz = Some(rate_hz);
        self.gain = (f.readable::<f64>("gain_m_s2_per_count")).filter(|g| g.is_finite());
        self.max_impact_s =
            (f.readable::<f64>("max_impact_s")).filter(|x| x.is_finite() && *x > 0.0);
        // Gravity in the contacts (`none`: horizontal), for a bounce's COR.
        self.contact_gravity_m_s2 =
            (f.readable::<f32>("gravity_m_s2")).filter(|g| g.is_finite() && *g > 0.0);
        let scene: Map<String, Value> = f
            .iter()
            .take(64)
            .map(|(k, v)| (cut(k), cut(v)))
            .map(|(k, v)| {
                let value = v
                    .parse::<f64>()
                    .ok()
                    .filter(|x| x.is_finite())
                    .map_or_else(|| json!(v), |x| json!(x));
                (k, value)
            })
            .collect();
        self.board_spec(&f, events);
        let mut run = json!({"run": self.run, "received_unix_ms": now_ms, "scene": scene});
        if self.runs.back().is_some_and(|r| r["run"] == self.run) {
            // (A run the input's replacement began keeps saying so.)
            if let Some(r) = self.runs.pop_back().filter(|r| !r["replaced"].is_null()) {
                run["replaced"] = r["replaced"].clone();
            }
        }
        push_bounded(&mut self.runs, run.clone(), RUNS);
        events.push(tagged("run", run));
        Ok(())
    }

    /// The pulse the board judges, from its scene line: drawn from now on, and said (a
    /// `spec` event); a `--spec` unlike it is named in a warning the page keeps. A scene
    /// line without one (`spec=none`, or an older board's) leaves the pulse as it was.
    fn board_spec(&mut self, f: &Fields, events: &mut Vec<Value>) {
        let board = match line::spec_of(f) {
            Ok(Some(board)) => board,
            // A board that judges nothing (`spec=none`): `--spec`'s pulse again, if any.
            Ok(None) if f.get("spec") == Some("none") => {
                let was = self.spec;
                self.spec = self.given.map(|(g, _)| g);
                // Said only when the pulse drawn changes (a board that never judged says
                // nothing).
                if was == self.spec {
                    return;
                }
                let head = self.given.map_or(Value::Null, |(g, named)| {
                    spec_head(&g, &spec_text(&g, Some(named)), "--spec", None)
                });
                self.head.insert("spec".into(), head.clone());
                events.push(if head.is_null() {
                    json!({"type": "spec"})
                } else {
                    tagged("spec", head)
                });
                return;
            }
            // An older board's line, without the field: `--spec`'s stays.
            Ok(None) => return,
            Err(e) => {
                events.push(json!({"type": "warning", "text": cut(&e.to_string())}));
                return;
            }
        };
        let differs = self
            .given
            .filter(|(g, _)| !same_spec(g, &board))
            .map(|(g, named)| {
                format!(
                "--spec {} differs from the pulse the board judges ({}{}): the board's is drawn",
                spec_text(&g, Some(named)),
                spec_text(&board, None),
                first_difference(&g, &board)
            )
            });
        self.spec = Some(board);
        let head = spec_head(&board, &spec_text(&board, None), "board", differs);
        self.head.insert("spec".into(), head.clone());
        events.push(tagged("spec", head));
    }

    /// Shows the waiting impact if it has waited [`HOLD_MS`] by `now_ms`.
    pub fn flush(&mut self, now_ms: u64) -> Vec<Value> {
        let mut events = Vec::new();
        if self
            .pending
            .as_ref()
            .is_some_and(|p| now_ms >= p.received_ms + HOLD_MS)
        {
            self.show(&mut events);
        }
        events
    }

    /// Shows the waiting impact (if any): its event, the trend point, the statistics.
    fn show(&mut self, events: &mut Vec<Value>) {
        let Some(p) = self.pending.take() else {
            return;
        };
        let event = self.impact(&p);
        let number = |k: &str| event[k].as_f64();
        for (k, (name, _)) in METRICS.iter().enumerate() {
            if let Some(v) = number(name) {
                self.stats[k].add(v);
            }
        }
        let pass = event["verdict"]["pass"].as_bool();
        match &p.report.verdict {
            Some(Ok(v)) => {
                self.judged += 1;
                self.passed += usize::from(v.pass);
            }
            Some(Err(_)) => self.not_judged += 1,
            None => {}
        }
        let point = TrendPoint {
            run: self.run,
            index: p.report.index,
            received_unix_ms: p.received_ms,
            peak_g: number("peak_g"),
            delta_v_m_s: number("delta_v_m_s"),
            duration_s: number("duration_s"),
            cor: number("cor"),
            pass,
        };
        push_bounded(&mut self.trend, point, TREND);
        push_bounded(&mut self.impacts, event.clone(), LAST);
        events.push(tagged("impact", event));
        events.push(tagged("stats", self.stats()));
    }

    /// An impact's event: its numbers, verdict and pulse.
    fn impact(&self, p: &Pending) -> Value {
        let r = &p.report;
        let j = crate::report::impact_json(
            r,
            0.0,
            &impact_core::FitSet::default(),
            self.contact_gravity_m_s2,
            self.rate_hz.or(self.state_rate_hz),
        );
        let g = STANDARD_GRAVITY;
        let verdict = r.verdict.as_ref().map(|v| match v {
            Ok(v) => json!({
                "pass": v.pass, "reason": null, "band_pass": v.band_pass,
                "delta_v_pass": v.delta_v_pass, "margin": f64::from(v.margin),
                "margin_g": self.spec.map(|s| -f64::from(v.margin) * f64::from(s.peak_m_s2) / g),
                "worst_s": v.worst_s - r.start_s,
                "worst_g": f64::from(v.worst_m_s2) / g, "limit_g": f64::from(v.limit_m_s2) / g,
                "delta_v_m_s": f64::from(v.delta_v_m_s),
            }),
            Err(missing) => json!({"pass": null, "reason": missing.name()}),
        });
        json!({
            "run": self.run, "index": r.index, "received_unix_ms": p.received_ms,
            "start_s": j.start_s, "status": j.status, "analysis": j.analysis,
            "flags": j.flags, "clipped": j.clipped,
            "peak_g": j.peak_acceleration_m_s2 / g, "peak_m_s2": j.peak_acceleration_m_s2,
            "peak_force_n": j.peak_force_n, "delta_v_m_s": j.delta_v_m_s,
            "duration_s": j.duration_s, "cor": j.cor,
            "impact_velocity_m_s": j.impact_velocity_m_s,
            "rebound_velocity_m_s": j.rebound_velocity_m_s, "crush_time_s": j.crush_time_s,
            "max_deformation_m": j.max_deformation_m,
            "report_latency_s": p.latency_s.map(f64::from),
            "verdict": verdict,
            "pulse": self.pulse(p),
        })
    }

    /// The pulse drawn: the board's window when it sent one, else a half-sine sketch from
    /// the reported peak and duration; in g above the baseline (deceleration positive),
    /// against time from first touch; with the spec's nominal pulse and band where its
    /// verdict placed them.
    fn pulse(&self, p: &Pending) -> Value {
        let r = &p.report;
        let g = STANDARD_GRAVITY;
        let touch = r.start_s;
        let (from_s, to_s, placed) = crate::cli::pulse::window(self.spec.as_ref(), r);
        let sign = if r.peak_acceleration_m_s2 < 0.0 {
            -1.0
        } else {
            1.0
        };
        let peak_g = f64::from(r.peak_acceleration_m_s2.abs()) / g;
        let measured = match (&p.wave, self.rate_hz, self.gain) {
            (Some(w), Some(rate), Some(gain)) => {
                let every = f64::from(w.every);
                let base = f64::from(r.baseline_m_s2);
                let points: Vec<(f64, f64)> = (0..w.values())
                    .filter_map(|k| {
                        // The value is the mean of `every` samples: at their middle.
                        let t =
                            (w.first_sample as f64 + k as f64 * every + (every - 1.0) / 2.0) / rate;
                        let c = w.value(k)?;
                        ((from_s..=to_s).contains(&t))
                            .then(|| (t - touch, sign * (f64::from(c) * gain - base) / g))
                    })
                    .collect();
                (!points.is_empty())
                    .then(|| ("waveform", crate::plot::decimate(&points, PULSE_COLUMNS)))
            }
            _ => None,
        };
        let (source, points) = measured.unwrap_or_else(|| {
            let d = f64::from(r.duration_s);
            let mut pts = vec![(from_s - touch, 0.0)];
            pts.extend((0..=100).map(|k| {
                let u = f64::from(k) / 100.0;
                (u * d, peak_g * (std::f64::consts::PI * u).sin())
            }));
            pts.push((to_s - touch, 0.0));
            ("numbers", pts)
        });
        let band = placed.map(|(spec, start)| {
            let band = crate::cli::pulse::band(spec, start, from_s, to_s);
            let column = |f: &dyn Fn(&crate::cli::pulse::BandPoint) -> f64| -> Vec<f64> {
                band.iter().map(f).collect()
            };
            json!({
                "t_s": column(&|b| b.0 - touch),
                "nominal_g": column(&|b| b.3 / g),
                "lower_g": column(&|b| b.1 / g),
                "upper_g": column(&|b| b.2 / g),
            })
        });
        json!({
            "source": source,
            "t_s": points.iter().map(|q| q.0).collect::<Vec<_>>(),
            "g": points.iter().map(|q| q.1).collect::<Vec<_>>(),
            "band": band,
        })
    }

    /// The board's health from a heartbeat's (or the summary's) counters.
    fn health(&self, s: &State, now_ms: u64) -> Result<Value, SessionError> {
        let n = |c: Counter| s.counter(c);
        let samples = n(Counter::Samples)?;
        let rate_hz = f64::from(s.rate_hz()?);
        let shown = |c: Counter| s.readable(c);
        Ok(json!({
            "run": self.run, "received_unix_ms": now_ms,
            "board_time_s": samples as f64 / rate_hz, "samples": samples,
            "samples_lost": n(Counter::SamplesLost)?, "gaps": shown(Counter::Gaps),
            "lines_dropped": shown(Counter::LinesDropped),
            "analyses_skipped": shown(Counter::AnalysesSkipped),
            "reports_dropped": shown(Counter::ReportsDropped),
            "stack_peak_bytes": shown(Counter::StackPeakBytes),
            "stack_size_bytes": shown(Counter::StackSizeBytes),
            "busy_share": s.busy_share(), "impacts": n(Counter::Impacts)?,
        }))
    }

    /// The statistics so far (the series statistics' definitions, kept running).
    fn stats(&self) -> Value {
        let metrics: Vec<Value> = METRICS
            .iter()
            .zip(&self.stats)
            .map(|((name, label), running)| match running.statistic(name) {
                Some(s) => json!({
                    "name": name, "label": label, "n": s.n, "mean": s.mean, "sd": s.sd,
                    "cv": s.cv, "min": s.min, "max": s.max,
                }),
                None => json!({"name": name, "label": label, "n": 0}),
            })
            .collect();
        let asked = self.judged + self.not_judged > 0;
        json!({
            "metrics": metrics,
            "pass_rate": asked.then(|| json!({
                "passed": self.passed, "judged": self.judged, "not_judged": self.not_judged,
            })),
        })
    }

    /// Everything the page shows, for a page that (re)connects.
    pub fn snapshot(&self, now_ms: u64) -> Value {
        let mut s = self.head.clone();
        s.insert("type".into(), json!("snapshot"));
        s.insert("runs".into(), json!(self.runs));
        s.insert("impacts".into(), json!(self.impacts));
        s.insert("trend".into(), json!(self.trend));
        s.insert("stats".into(), self.stats());
        s.insert("health".into(), json!(self.health));
        s.insert("ended".into(), json!(self.ended));
        s.insert("now_unix_ms".into(), json!(now_ms));
        Value::Object(s)
    }

    /// How long since the last heartbeat, ms (`None` before the first, and once the stream
    /// ended).
    pub fn silent_for(&self, now_ms: u64) -> Option<u64> {
        if self.ended.is_some() {
            return None;
        }
        self.last_heartbeat_ms.map(|t| now_ms.saturating_sub(t))
    }

    /// The clock event: when the last line and the last heartbeat came.
    pub fn tick(&self, now_ms: u64, dropped_events: u64) -> Value {
        json!({
            "type": "tick", "now_unix_ms": now_ms, "last_line_unix_ms": self.last_line_ms,
            "last_heartbeat_unix_ms": self.last_heartbeat_ms, "lines": self.lines,
            "dropped_events": dropped_events, "bad_lines": self.bad_lines,
            "last_error": self.last_error,
        })
    }

    /// The followed file was replaced (`why` says how: a new file at its path, or rewritten
    /// in place): what follows is a new run, read from the new file's first line, never mixed
    /// with the old one's (the waiting impact shown first). Said in a `warning` and in the
    /// run's `replaced` (the terminal's line, the page's notice).
    pub fn input_replaced(&mut self, why: &str, now_ms: u64) -> Vec<Value> {
        let mut events = Vec::new();
        self.show(&mut events);
        self.run += 1;
        self.started = false;
        self.wave = None;
        self.ended = None;
        (
            self.rate_hz,
            self.gain,
            self.max_impact_s,
            self.state_rate_hz,
        ) = (None, None, None, None);
        self.contact_gravity_m_s2 = None;
        let text = format!("{why}: run {} from its first line", self.run);
        let run =
            json!({"run": self.run, "received_unix_ms": now_ms, "scene": {}, "replaced": text});
        push_bounded(&mut self.runs, run.clone(), RUNS);
        events.push(tagged("run", run));
        events
    }

    /// The input ended (a closed pipe, the end of a file not followed): an `end` event
    /// unless the board's summary said so already.
    pub fn input_ended(&mut self, now_ms: u64) -> Vec<Value> {
        let mut events = Vec::new();
        self.show(&mut events);
        if self.ended.is_none() {
            let end = json!({"result": "input-closed", "received_unix_ms": now_ms});
            self.ended = Some(end.clone());
            events.push(tagged("end", end));
        }
        events
    }
}

/// The order the session tries a line's kinds in: the lines that follow an impact first.
const KINDS: [LineKind; 8] = [
    LineKind::Srs,
    LineKind::Spec,
    LineKind::WaveFrame,
    LineKind::Impact,
    LineKind::Wave,
    LineKind::Heartbeat,
    LineKind::Summary,
    LineKind::Scene,
];

/// Why a line of the board's could not be read into the session (shown as a `warning`
/// event, `line N: what`; the session goes on).
#[derive(Debug, thiserror::Error)]
pub enum SessionError {
    #[error(transparent)]
    Field(#[from] FieldError),
    #[error(transparent)]
    Line(#[from] LineError),
    #[error(transparent)]
    Wave(#[from] WaveError),
    /// An `srs` or `spec` line whose impact was shown already (or never came).
    #[error(
        "{kind} index={index}: after its impact was shown (or without its impact line): not \
         on the page; the session file has it (impact log reads it)"
    )]
    Late { kind: LineKind, index: u32 },
    /// An impact `impact log` refuses (a value its stream cannot hold).
    #[error(transparent)]
    Refused(#[from] log::LogErrorKind),
}

/// `text`, at most [`MAX_TEXT`] bytes of it (cut at a character's boundary, marked).
fn cut(text: &str) -> String {
    if text.len() <= MAX_TEXT {
        return text.to_string();
    }
    let mut end = MAX_TEXT;
    while !text.is_char_boundary(end) {
        end -= 1;
    }
    format!("{}…", &text[..end])
}

/// The pulse as the page names it: shape, peak in g, duration in ms, the standard (or
/// `custom`), a user's band's rows.
pub fn spec_text(spec: &Spec, named: Option<&str>) -> String {
    let (_, standard) = crate::report::spec::standard_of(spec, named);
    format!(
        "{} {} g {} ms, {}",
        spec.shape.name(),
        crate::report::fmt::sig(f64::from(spec.peak_m_s2) / STANDARD_GRAVITY, 4),
        crate::report::fmt::sig(f64::from(spec.duration_s) * 1e3, 4),
        crate::standards::title(&standard),
    ) + &spec.band.map_or(String::new(), |rows| {
        format!(", the user's band ({} rows)", rows.len())
    })
}

/// Whether two specs are the same pulse and tolerances, each number within 1e-6 of the other
/// (a board's static `50.0 * g` and the host's parse of `50g` may differ in the last bit).
fn same_spec(a: &Spec, b: &Spec) -> bool {
    use impact_core::spec::Shape;
    let near = |x: f32, y: f32| (x - y).abs() <= 1e-6 * x.abs().max(y.abs()).max(f32::MIN_POSITIVE);
    let shapes = match (a.shape, b.shape) {
        (Shape::Trapezoid { rise: r1, fall: f1 }, Shape::Trapezoid { rise: r2, fall: f2 }) => {
            near(r1, r2) && near(f1, f2)
        }
        (x, y) => x == y,
    };
    let (t, u) = (a.tolerance, b.tolerance);
    let bands = match (a.band, b.band) {
        (None, None) => true,
        (Some(p), Some(q)) => {
            p.len() == q.len()
                && p.iter().zip(q).all(|(x, y)| {
                    near(x.u, y.u) && near(x.lower, y.lower) && near(x.upper, y.upper)
                })
        }
        _ => false,
    };
    shapes
        && bands
        && [
            (a.peak_m_s2, b.peak_m_s2),
            (a.duration_s, b.duration_s),
            (t.band, u.band),
            (t.outside, u.outside),
            (t.slack, u.slack),
            (t.delta_v, u.delta_v),
            (t.before, u.before),
            (t.after, u.after),
            (t.watch, u.watch),
        ]
        .iter()
        .all(|&(x, y)| near(x, y))
}

/// Where two specs differ, as `; its dv 0.1, not 0.3` (the first field that does), for a
/// warning whose two texts may read alike.
fn first_difference(given: &Spec, board: &Spec) -> String {
    let (g, b) = (given.tolerance, board.tolerance);
    let fields = [
        ("peak_m_s2", given.peak_m_s2, board.peak_m_s2),
        ("duration_s", given.duration_s, board.duration_s),
        ("band", g.band, b.band),
        ("outside", g.outside, b.outside),
        ("slack", g.slack, b.slack),
        ("dv", g.delta_v, b.delta_v),
        ("before", g.before, b.before),
        ("after", g.after, b.after),
        ("watch", g.watch, b.watch),
    ];
    match fields.iter().find(|(_, x, y)| x != y) {
        Some((name, x, y)) => format!("; its {name} {y}, not {x}"),
        None if given.shape != board.shape => "; its shape".to_string(),
        None => "; its band's rows".to_string(),
    }
}

/// The session head's `spec`: the pulse drawn, where it came from (`board`: its scene line;
/// `--spec`) and, when `--spec` differs from the board's, the warning that says so.
fn spec_head(spec: &Spec, text: &str, from: &str, differs: Option<String>) -> Value {
    json!({
        "text": text,
        "shape": spec.shape.name(),
        "peak_g": f64::from(spec.peak_m_s2) / STANDARD_GRAVITY,
        "duration_s": f64::from(spec.duration_s),
        "nominal_delta_v_m_s": f64::from(spec.delta_v_m_s()),
        "delta_v_tolerance": f64::from(spec.tolerance.delta_v),
        "from": from,
        "differs": differs,
    })
}

/// `value` (an object) with its event `type` first.
fn tagged(kind: &str, value: Value) -> Value {
    let mut m = Map::new();
    m.insert("type".into(), json!(kind));
    if let Value::Object(o) = value {
        m.extend(o);
    }
    Value::Object(m)
}

fn push_bounded<T>(q: &mut VecDeque<T>, v: T, cap: usize) {
    if q.len() == cap {
        q.pop_front();
    }
    q.push_back(v);
}

#[cfg(test)]
mod tests {
    use super::*;

    const SCENE: &str = "0.001409 INFO scene rate_hz=500000.0 gain_m_s2_per_count=0.004467775 mass_kg=0.06 v0_m_s=1.3357 drop_height_m=none trigger_m_s2=6.816018 edge_m_s2=1.3632036 hold_s=0.002 max_impact_s=1.0 settle_s=0.05 clip_low=-32768 clip_high=32767 cfc=none trigger_cfc=none two_phase=true nonlinear=true fit_exponent=true exponent=1.0 hertz=true train=none gravity_m_s2=none max_flight_s=none srs=false wave_every=0";
    const HEARTBEAT: &str = "1.002161 INFO heartbeat seq=198 samples=500224 rate_hz=500000.0 blocks=1954 busy_permille=115 overruns=0 blocks_lost=0 blocks_missing=0 samples_lost=3 gaps=1 source_errors=0 impacts=7 incomplete=7 analyses_skipped=0 level_changes=0 reports_dropped=0 heartbeats_dropped=0 lines_dropped=0 armed=true in_impact=false stack_peak_bytes=12784 stack_size_bytes=24576";

    /// Impact `index`'s line (the emulated board's, its index and place changed).
    fn impact(index: u32) -> String {
        let start = 5180 + 100_000 * u64::from(index);
        format!("0.131031 INFO impact seq={} index={index} status=complete analysis=full clipped=false flags=0 start_sample={start} end_sample={} start_s={} peak_time_s={} peak_acceleration_m_s2=136.32632 peak_force_n=8.17958 delta_v_m_s=2.255874 duration_s=0.034259174 baseline_m_s2=6.6424823 fwhm_s=0.016056484 filtered_peak_acceleration_m_s2=none filtered_fwhm_s=none impact_velocity_m_s=none crush_time_s=none max_deformation_m=none rebound_velocity_m_s=none cor=none separation_deformation_m=none permanent_deformation_m=none absorbed_energy_j=none two_phase_kc_n_m=none two_phase_kr_n_m=none two_phase_c_n_s_m=none two_phase_permanent_deformation_m=none two_phase_residual=none nonlinear_k=none nonlinear_c_s_m=none nonlinear_exponent=none nonlinear_residual=none hertz_k=none hertz_residual=none bounce_number=none flight_s=none v0_flight_m_s=none v0_rebound_m_s=none landing_height_m=none report_latency_s=0.084117",
            2 * index, start + 17_540, start as f64 / 5e5, (start + 5692) as f64 / 5e5)
    }

    fn spec(index: u32, pass: bool) -> String {
        format!("0.131106 INFO spec seq={} index={index} pass={pass} band_pass={pass} delta_v_pass=true margin=-0.1 worst_s=0.01983 worst_m_s2=131.63962 limit_m_s2=140.0 delta_v_m_s=2.25 start_s=0.0101", 2 * index + 1)
    }

    fn kinds(events: &[Value]) -> Vec<&str> {
        events.iter().map(|e| e["type"].as_str().unwrap()).collect()
    }

    #[test]
    fn an_impact_is_shown_with_its_verdict_or_after_waiting_for_it() {
        let mut s = Session::new("board.log", "s.log", None);
        assert_eq!(kinds(&s.line(1, SCENE, 0)), ["run"]);
        // Its spec line is its last: shown then, with the verdict.
        assert!(s.line(2, &impact(0), 10).is_empty());
        let shown = s.line(3, &spec(0, true), 12);
        assert_eq!(kinds(&shown), ["impact", "stats"]);
        let e = &shown[0];
        assert_eq!((e["run"].as_u64(), e["index"].as_u64()), (Some(1), Some(0)));
        assert!((e["peak_g"].as_f64().unwrap() - 136.32632 / STANDARD_GRAVITY).abs() < 1e-5);
        assert_eq!(e["verdict"]["pass"], true);
        assert_eq!(e["cor"], Value::Null);
        // No window sent: the pulse is a sketch, and says so.
        assert_eq!(e["pulse"]["source"], "numbers");
        assert_eq!(e["received_unix_ms"], 10);
        // Without a spec line: shown once it waited HOLD_MS, or at the next data line.
        assert!(s.line(4, &impact(1), 100).is_empty());
        assert!(s.flush(100 + HOLD_MS - 1).is_empty());
        assert_eq!(kinds(&s.flush(100 + HOLD_MS)), ["impact", "stats"]);
        s.line(5, &impact(2), 300);
        assert_eq!(
            kinds(&s.line(6, HEARTBEAT, 301)),
            ["impact", "stats", "health"]
        );
        let snap = s.snapshot(400);
        assert_eq!(snap["impacts"].as_array().unwrap().len(), 3);
        assert_eq!(snap["stats"]["metrics"][0]["n"], 3);
        assert_eq!(snap["stats"]["pass_rate"]["judged"], 1);
        assert_eq!(snap["health"]["samples_lost"], 3);
        assert_eq!(s.silent_for(2901), Some(2600));
    }

    #[test]
    fn a_restart_starts_a_run_and_a_bad_line_is_a_warning() {
        let mut s = Session::new("board.log", "s.log", None);
        s.line(1, SCENE, 0);
        s.line(2, &impact(0), 1);
        // A cut line: the impact before it is shown, the line counted and said.
        let bad = s.line(3, "INFO impact seq=9 index=1 status=complete", 2);
        assert_eq!(kinds(&bad), ["impact", "stats", "warning"]);
        assert!(bad[2]["text"].as_str().unwrap().starts_with("line 3: "));
        assert_eq!(s.bad_lines, 1);
        let restart = s.line(4, SCENE, 3);
        assert_eq!(kinds(&restart), ["run"]);
        assert_eq!(restart[0]["run"], 2);
        s.line(5, &impact(0), 4);
        let end = s.input_ended(5);
        assert_eq!(kinds(&end), ["impact", "stats", "end"]);
        assert_eq!(
            (end[0]["run"].as_u64(), end[2]["result"].as_str()),
            (Some(2), Some("input-closed"))
        );
        // Prose that merely starts like a data line is not the board's.
        assert!(s.line(6, "impact of the day: none", 6).is_empty());
        assert_eq!(s.bad_lines, 1);
    }

    #[test]
    fn a_long_session_keeps_what_it_shows_only() {
        let mut s = Session::new("board.log", "s.log", None);
        s.line(1, SCENE, 0);
        for k in 0..3000 {
            s.line(2 + u64::from(k), &impact(k), u64::from(k));
        }
        s.input_ended(5000);
        let snap = s.snapshot(5000);
        assert_eq!(snap["impacts"].as_array().unwrap().len(), LAST);
        assert_eq!(snap["trend"].as_array().unwrap().len(), TREND);
        assert_eq!(snap["trend"][TREND - 1]["index"], 2999);
        assert_eq!(snap["stats"]["metrics"][0]["n"], 3000);
    }
}
