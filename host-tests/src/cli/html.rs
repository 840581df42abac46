//! `impact report … --html FILE`: one self-contained HTML file (no network, no script) a test
//! engineer can hand in: the settings and provenance, the series table and statistics, and
//! every impact's pulse drawn with the nominal pulse and its tolerance band when a
//! specification is given.

use std::path::PathBuf;

use impact_core::consts::STANDARD_GRAVITY;

use super::analyze::AnalyzeCommand;
use super::pulse::MAX_FIGURES;
use super::series::{self, EntryJson};
use super::srs_required::{self, RequiredSrs};
use crate::html;
use crate::html::Html;
use crate::report::fmt::human;

/// `impact report`'s command line: the analysis's (one or more recordings), and the file.
#[derive(clap::Args, Clone, Debug)]
pub struct ReportArgs {
    #[command(flatten)]
    pub analyze: AnalyzeCommand,
    /// The report: one self-contained HTML file (its figures inline).
    #[arg(long, value_name = "FILE.html", help_heading = "Output")]
    pub html: PathBuf,
    /// A required SRS each impact's SRS is judged against (implies --srs).
    ///
    /// A required SRS: a CSV with the columns frequency_hz and acceleration_m_s2 (or
    /// acceleration_g), straight between its breakpoints on log–log axes. Each impact's SRS is
    /// drawn over it with MIL-STD-810H Method 516.8's tolerance (−1.5 dB, +3 dB) dashed, and
    /// the table says whether it lies within at every natural frequency both have. Implies
    /// --srs.
    #[arg(long, value_name = "FILE.csv", help_heading = "Output")]
    pub srs_required: Option<PathBuf>,
}

/// Why `impact report` failed.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    #[error("--plot, --json, --csv: `impact analyze` writes those; the report is --html")]
    NotAReport,
    #[error(transparent)]
    Series(#[from] series::SeriesError),
    #[error(transparent)]
    Output(#[from] crate::output::OutputError),
    #[error(transparent)]
    RequiredSrs(#[from] srs_required::RequiredSrsError),
    /// Some of the recordings failed (the page names each).
    #[error("{failed} of {recordings} recordings failed (each named in the report)")]
    Failed { failed: usize, recordings: usize },
}

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
}

/// Runs `impact report`; returns the verdicts (the exit status says whether one failed).
pub fn run(args: &ReportArgs) -> Result<crate::report::spec::Judged, ReportError> {
    let cmd = &args.analyze;
    let a = &cmd.args;
    if a.plot.is_some() || a.json || a.csv {
        return Err(ReportError::NotAReport);
    }
    let mut files = vec![a.file.clone()];
    files.extend(cmd.more.iter().cloned());
    let entries = series::entries(&files, &cmd.channels, a.column.as_ref())?;
    let mut inputs = crate::output::Inputs::new();
    for e in &entries {
        inputs = inputs.with(&e.file);
    }
    let inputs = inputs
        .with_some(a.scene.as_deref())
        .with_some(a.free_fall.as_deref().map(crate::pipeline::free_fall::file))
        .with_some(args.srs_required.as_deref())
        .with_some(a.spec.and_then(|s| s.band_file));
    crate::output::check("--html", &args.html, &inputs, Some("html"))?;
    let required = args
        .srs_required
        .as_deref()
        .map(RequiredSrs::read)
        .transpose()?;
    // A required SRS needs the measured one.
    let mut a = a.clone();
    a.spectrum.srs |= required.is_some();
    let results = series::analyze_drawn(&a, &entries);
    // The windows' filter as the command line and the scene file set it (the first
    // recording's scene; every recording takes the same options).
    let filter = results
        .iter()
        .filter_map(|e| e.analysis.as_ref())
        .find_map(|a| a.lowpass.as_ref())
        .map(|l| {
            format!(
                "Butterworth {} (phaseless, SciPy's sosfiltfilt) on the captured windows",
                l.name()
            )
        })
        .or_else(|| {
            a.cfc
                .map(|c| format!("CFC {c} (SAE J211) on the captured windows"))
        });
    let page = page(filter.as_deref(), &results, required.as_ref());
    crate::output::write(&args.html, page.as_str().as_bytes())?;
    for e in &results {
        for n in &e.notes {
            crate::errln!("note: {}", series::failure(e, n));
        }
    }
    crate::errln!("wrote {}", args.html.display());
    let failed = results.iter().filter(|e| e.error.is_some()).count();
    if failed > 0 {
        return Err(ReportError::Failed {
            failed,
            recordings: results.len(),
        });
    }
    Ok(crate::report::spec::Judged::impacts(
        results
            .iter()
            .filter_map(|e| e.analysis.as_ref())
            .flat_map(|a| &a.impacts),
    ))
}

const STYLE: &str = "body{font-family:system-ui,sans-serif;margin:2em;color:#222;max-width:1100px}\
h1{font-size:1.5em}h2{font-size:1.2em;margin-top:2em;border-bottom:1px solid #ccc}\
table{border-collapse:collapse;font-size:.85em;margin:.5em 0}\
td,th{border:1px solid #ccc;padding:.2em .5em;text-align:right}th{background:#f3f3f3}\
td.l,th.l{text-align:left}.pass{color:#080;font-weight:bold}.fail{color:#b00;font-weight:bold}\
.figure{display:inline-block;margin:.5em;vertical-align:top}dl{display:grid;grid-template-columns:max-content auto;gap:.2em 1em}\
dt{font-weight:bold}";

/// The page: `results` analysed with the windows' filter `filter` (its description), against
/// `required`.
fn page(filter: Option<&str>, results: &[EntryJson], required: Option<&RequiredSrs>) -> Html {
    let json = series::to_json(results);
    let mut h = Html::new();
    h.raw("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>Impact report</title><style>")
        .raw(STYLE)
        .raw("</style></head><body>\n");
    html!(
        h,
        "<h1>Impact report: {} recording{}, {} impact{}</h1>\n",
        json.recordings,
        if json.recordings == 1 { "" } else { "s" },
        json.impacts,
        if json.impacts == 1 { "" } else { "s" },
    );
    provenance(&mut h, filter, results, required);
    impacts_table(&mut h, results, required);
    for e in results {
        if let Some(err) = &e.error {
            html!(
                h,
                "<p class=\"fail\">FAILED {}</p>\n",
                series::failure(e, err.of_recording())
            );
        }
    }
    if let Some(r) = &json.spec {
        html!(
            h,
            "<p><b>Specification:</b> {} of {} judged impacts pass{}{}.</p>\n",
            r.passed,
            r.judged,
            r.pass_rate
                .map_or(String::new(), |p| format!(" ({:.1} %)", 100.0 * p)),
            if r.not_judged > 0 {
                format!("; {} not judged", r.not_judged)
            } else {
                String::new()
            }
        );
    }
    if let Some(text) = json.statistics_left_out.text(json.impacts) {
        html!(h, "<p>{}.</p>\n", text);
    }
    if !json.statistics.is_empty() {
        h.raw("<h2>Statistics across the series</h2><p>sd: sample standard deviation; CV: sd / |mean|.</p>");
        statistics_table(&mut h, &json.statistics);
    }
    for g in &json.bounce_statistics {
        html!(
            h,
            "<h3>Bounce {} of each drop</h3><p>Complete and unclipped.</p>",
            g.bounce_number
        );
        statistics_table(&mut h, &g.statistics);
    }
    // The pulses.
    h.raw("<h2>Pulses</h2>\n");
    let drawn: usize = results.iter().map(|e| e.figures.len()).sum();
    let total = json.impacts;
    if drawn < total {
        html!(
            h,
            "<p>The first {} of {} impacts are drawn (at most {}); the table has them all.</p>\n",
            drawn,
            total,
            MAX_FIGURES
        );
    }
    for e in results {
        for f in &e.figures {
            html!(h, "<div class=\"figure\">{}</div>\n", f);
        }
    }
    if let Some(r) = required {
        spectra(&mut h, results, r);
    }
    h.raw("</body></html>\n");
    h
}

/// The settings and provenance: the tool, the command, each recording, the filter, the
/// required SRS and the specification.
fn provenance(
    h: &mut Html,
    filter: Option<&str>,
    results: &[EntryJson],
    required: Option<&RequiredSrs>,
) {
    h.raw("<h2>Settings and provenance</h2><dl>");
    let mut dd = |k: &str, v: &str| html!(h, "<dt>{}</dt><dd>{}</dd>", k, v);
    dd("tool", &format!("impact {}", env!("CARGO_PKG_VERSION")));
    dd("command", &std::env::args().collect::<Vec<_>>().join(" "));
    for e in results {
        let size =
            std::fs::metadata(&e.file).map_or(String::new(), |m| format!(", {} bytes", m.len()));
        let rate = e.analysis.as_ref().map_or(String::new(), |a| {
            format!(
                ", {} samples at {} S/s",
                a.samples,
                crate::report::fmt::sig(a.sample_rate_hz, 6)
            )
        });
        dd(
            "recording",
            &format!("{} [{}]{size}{rate}", e.file, e.channel),
        );
        // What the tool assumed of this recording, where the customer reads its provenance.
        for assumed in e.analysis.iter().flat_map(|a| &a.assumptions) {
            dd("assumed", assumed);
        }
        // A board's log: the lines passed over (the first 20, and how many more).
        let skipped: Vec<_> = e.analysis.iter().flat_map(|a| &a.skipped_lines).collect();
        for s in skipped.iter().take(20) {
            dd(
                "skipped",
                &format!("line {}: {} (skipped)", s.line, s.reason),
            );
        }
        if skipped.len() > 20 {
            dd("skipped", &format!("and {} more lines", skipped.len() - 20));
        }
    }
    dd("filter", filter.unwrap_or("none (raw signal)"));
    if let Some(r) = required {
        let (first, last) = (r.points()[0].0, r.points()[r.points().len() - 1].0);
        let (low, high) = crate::standards::SRS_TOLERANCE_DB;
        dd(
            "required SRS",
            &format!(
                "{}: {} breakpoints, {} to {}; tolerance {low:+} dB, {high:+} dB ({})",
                r.file,
                r.points().len(),
                human(first, "Hz").trim_end(),
                human(last, "Hz").trim_end(),
                crate::standards::SRS_TOLERANCE_SOURCE,
            ),
        );
    }
    if let Some(s) = results
        .iter()
        .find_map(|e| e.analysis.as_ref()?.spec.clone())
    {
        dd(
            "specification",
            crate::report::spec::table_head(&s)
                .trim_end()
                .trim_start_matches("spec: "),
        );
        if let Some(rows) = &s.band_table {
            let rows: Vec<String> = rows
                .iter()
                .map(|r| {
                    format!(
                        "{}D: {}…{}",
                        r.time_over_duration, r.lower_over_peak, r.upper_over_peak
                    )
                })
                .collect();
            dd(
                "user's band",
                &format!(
                    "{} rows (time from the nominal start: lower…upper limit, × the peak): {}",
                    rows.len(),
                    rows.join("; ")
                ),
            );
        }
        for x in &s.sources {
            dd(
                &format!("source of {}", x.tolerance),
                &format!("{} ({})", x.source, x.confidence),
            );
        }
        if let (Some(o), Some(from)) = (s.delta_v_tolerance_other, s.delta_v_tolerance_other_source)
        {
            dd(
                "Δv, other reading",
                &format!(
                    "±{:.0} %: {from}; each verdict says whether Δv passes under it",
                    100.0 * o
                ),
            );
        }
    }
    h.raw("</dl>\n");
}

/// A statistics table: a row per metric.
fn statistics_table(h: &mut Html, statistics: &[crate::report::statistics::Statistic]) {
    h.raw("<table><tr><th class=\"l\">metric</th><th>n</th><th>mean</th><th>sd</th><th>CV</th><th>min</th><th>max</th></tr>\n");
    for st in statistics {
        let [metric, n, mean, sd, cv, min, max] = st.cells("—");
        html!(
            h,
            "<tr><td class=\"l\">{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>\n",
            metric,
            n,
            mean,
            sd,
            cv,
            min,
            max
        );
    }
    h.raw("</table>\n");
}

/// The series table: a row per impact, with the required SRS's column when there is one.
fn impacts_table(h: &mut Html, results: &[EntryJson], required: Option<&RequiredSrs>) {
    h.raw("<h2>Impacts</h2><table><tr><th class=\"l\">file</th><th class=\"l\">channel</th><th>#</th><th>start</th><th>peak (g)</th><th>peak (m/s²)</th><th>Δv</th><th>duration</th><th>FWHM</th><th>COR</th><th class=\"l\">status</th><th class=\"l\">verdict</th>");
    if required.is_some() {
        h.raw("<th class=\"l\">SRS within −1.5/+3 dB of required</th>");
    }
    h.raw("</tr>\n");
    for (e, i) in series::impacts(results) {
        let o = |v: Option<f64>, u: &str| {
            v.map_or("—".into(), |v| human(v, u).trim_end().to_string())
        };
        let mut verdict = Html::new();
        match &i.spec {
            Some(Some(v)) if v.pass => {
                verdict.raw("<span class=\"pass\">PASS</span>");
            }
            Some(Some(v)) => {
                // Which part failed: the band (by its worst excursion) or Δv (by its offset
                // from the nominal, and the standard's other reading when it has one).
                let spec = e.analysis.as_ref().and_then(|a| a.spec.as_ref());
                let mut why = Vec::new();
                if !v.band_pass {
                    why.push(format!("band {:+.1} % of the peak", 100.0 * v.margin));
                }
                if !v.delta_v_pass {
                    let off = spec.map_or(String::new(), |s| {
                        format!(
                            " {:+.1} % of nominal",
                            100.0 * (v.delta_v_m_s / s.nominal_delta_v_m_s - 1.0)
                        )
                    });
                    let other = match crate::report::spec::delta_v_pass_other(v, spec) {
                        Some(true) => ", within the other reading's tolerance",
                        _ => "",
                    };
                    why.push(format!("Δv{off}{other}"));
                }
                html!(
                    verdict,
                    "<span class=\"fail\">FAIL</span> ({})",
                    why.join("; ")
                )
            }
            Some(None) => html!(
                verdict,
                "not judged ({})",
                crate::report::spec::not_judged(
                    i.null_reasons.get("spec").map_or("", String::as_str)
                )
            ),
            None => {
                verdict.raw("—");
            }
        }
        html!(
            h,
            "<tr><td class=\"l\">{}</td><td class=\"l\">{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td class=\"l\">{}</td><td class=\"l\">{}</td>",
            e.file,
            e.channel,
            i.index,
            human(i.start_s, "s"),
            human(i.peak_acceleration_m_s2 / STANDARD_GRAVITY, "g").trim_end_matches(" g"),
            human(i.peak_acceleration_m_s2, "m/s²").trim_end_matches(" m/s²"),
            o(i.delta_v_m_s, "m/s"),
            human(i.duration_s, "s"),
            o(i.fwhm_s, "s"),
            o(i.cor, ""),
            status_cell(i),
            verdict,
        );
        if let Some(r) = required {
            match &i.shock_spectrum {
                Some(sp) => {
                    let c = srs_required::compare(r, &sp.frequency_hz, &sp.srs_m_s2);
                    let class = match c {
                        Some(c) if c.within => " pass",
                        Some(_) => " fail",
                        None => "",
                    };
                    html!(
                        h,
                        "<td class=\"l{}\">{}</td>",
                        class,
                        srs_required::cell(c.as_ref())
                    );
                }
                None => {
                    h.raw("<td class=\"l\">no SRS (see its status)</td>");
                }
            }
        }
        h.raw("</tr>\n");
    }
    h.raw("</table>\n");
}

/// The section of each impact's SRS drawn over the required one (at most [`MAX_FIGURES`]).
fn spectra(h: &mut Html, results: &[EntryJson], required: &RequiredSrs) {
    h.raw("<h2>Shock response spectra against the required SRS</h2>\n");
    let (low, high) = crate::standards::SRS_TOLERANCE_DB;
    html!(
        h,
        "<p>Each impact's SRS (maximax absolute acceleration) over the required SRS of {}, its tolerance ({:+} dB, {:+} dB, {}) dashed.</p>\n",
        required.file,
        low,
        high,
        crate::standards::SRS_TOLERANCE_SOURCE
    );
    let mut drawn = 0;
    for (e, i) in series::impacts(results) {
        let Some(sp) = &i.shock_spectrum else {
            continue;
        };
        if drawn == MAX_FIGURES {
            html!(
                h,
                "<p>The first {} spectra are drawn; the table judges them all.</p>\n",
                MAX_FIGURES
            );
            break;
        }
        let name = std::path::Path::new(&e.file)
            .file_name()
            .map_or_else(|| e.file.clone(), |n| n.to_string_lossy().into_owned());
        let title = format!(
            "{name} [{}] impact {}: SRS, m/s² (left), g (right)",
            e.channel, i.index
        );
        match srs_required::svg(&title, &sp.frequency_hz, &sp.srs_m_s2, required) {
            Ok(svg) => {
                html!(h, "<div class=\"figure\">{}</div>\n", svg);
                drawn += 1;
            }
            Err(err) => {
                html!(
                    h,
                    "<p class=\"fail\">{}: not drawn: {}</p>\n",
                    title,
                    err.to_string()
                );
            }
        }
    }
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
    Ok(page(None, std::slice::from_ref(&entry), None).into_string())
}

/// An impact's status cell: its status and flags, a decimated capture's with its step.
fn status_cell(i: &crate::report::ImpactJson) -> String {
    let flags = i.flags.iter().map(|f| match f.as_str() {
        "decimated" => format!("decimated ×{}", i.decimation),
        f => f.to_string(),
    });
    std::iter::once(i.status.clone())
        .chain(flags)
        .collect::<Vec<_>>()
        .join(" ")
}
