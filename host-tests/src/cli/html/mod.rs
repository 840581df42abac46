//! `impact report … --html FILE`: one self-contained HTML file (no network, no script) a test
//! engineer can hand in and a quality manager sign: the verdict first (a banner, then each
//! pulse against the nominal one: `verdict`), the title block (the lab's `--meta`, an `.IDE`
//! recording's recorder and sensor, when and by what the report was written: `title`), the
//! series table and statistics, every impact's pulse drawn with the nominal pulse, its
//! tolerance band and the worst point when a specification is given, and last the settings
//! and every input with its SHA-256 (`provenance`).

pub mod board;
mod directions;
pub mod pdf;
pub mod provenance;
pub mod title;
pub mod verdict;

pub use board::{log_report, LogReportError};

use std::path::PathBuf;

use impact_core::consts::STANDARD_GRAVITY;

use super::analyze::AnalyzeCommand;
use super::pulse::MAX_FIGURES;
use super::series::{self, EntryJson};
use super::srs_required::{self, RequiredSrs};
use crate::html;
use crate::html::Html;
use crate::report::fmt::human;
use crate::report::spec::Criterion;

/// `impact report`'s command line: the analysis's (one or more recordings), and the file.
#[derive(clap::Args, Clone, Debug)]
pub struct ReportArgs {
    #[command(flatten)]
    pub analyze: AnalyzeCommand,
    /// The report: one self-contained HTML file (its figures inline).
    #[arg(
        long,
        value_name = "FILE.html",
        help_heading = "Output",
        required_unless_present = "pdf"
    )]
    pub html: Option<PathBuf>,
    /// The report as a paginated PDF (printed by a headless Chromium: no figure, table row or
    /// title block cut across pages).
    #[arg(long, value_name = "FILE.pdf", help_heading = "Output")]
    pub pdf: Option<PathBuf>,
    /// The PDF's paper.
    #[arg(
        long,
        value_enum,
        default_value_t,
        requires = "pdf",
        help_heading = "Output"
    )]
    pub paper: pdf::Paper,
    /// A required SRS each impact's SRS is judged against (implies --srs).
    ///
    /// A required SRS: a CSV with the columns frequency_hz and acceleration_m_s2 (or
    /// acceleration_g), straight between its breakpoints on log–log axes. Each impact's SRS is
    /// drawn over it with MIL-STD-810H Method 516.8's tolerance (−1.5 dB, +3 dB) dashed, and
    /// the table says whether it lies within at every natural frequency both have, and which
    /// part of the required range that was if the bands stop short of it (--srs-high,
    /// --srs-low, the rate / 8). Implies --srs.
    #[arg(long, value_name = "FILE.csv", help_heading = "Output")]
    pub srs_required: Option<PathBuf>,
    #[command(flatten)]
    pub meta: title::MetaArgs,
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
    #[error(transparent)]
    Meta(#[from] title::MetaError),
    #[error(transparent)]
    Provenance(#[from] provenance::ProvenanceError),
    #[error(transparent)]
    Pdf(#[from] pdf::PdfError),
    /// Some of the recordings failed (the page names each).
    #[error("{failed} of {recordings} recordings failed (each named in the report)")]
    Failed { failed: usize, recordings: usize },
}

/// What the page says before the series: the title block's lines, what each `.IDE`
/// recording says of itself, when the report was written, and the inputs digested.
pub struct Front {
    pub meta: Vec<(String, String)>,
    pub recorded: Vec<title::Recorded>,
    pub written: provenance::Written,
    pub inputs: Vec<provenance::Input>,
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
    let mut entries = series::entries(&files, &cmd.channels, a.column.as_ref())?;
    let target = crate::pipeline::options::target_file(a);
    let mut inputs = crate::output::Inputs::new();
    for e in &entries {
        inputs = inputs.with(&e.file);
    }
    let inputs = inputs
        .with_some(a.scene.as_deref())
        .with_some(a.free_fall.as_deref().map(crate::pipeline::free_fall::file))
        .with_some(args.srs_required.as_deref())
        .with_some(a.spec.and_then(|s| s.band_file))
        .with_some(target.as_deref())
        .with_some(args.meta.meta_file.as_deref());
    if let Some(html) = &args.html {
        crate::output::check("--html", html, &inputs, Some("html"))?;
    }
    if let Some(out) = &args.pdf {
        crate::output::check("--pdf", out, &inputs, Some("pdf"))?;
    }
    let written = provenance::Written::now()?;
    let meta = title::read_meta(&args.meta)?;
    // A direction by --direction, else one for the whole report by --meta direction=.
    let direction = cmd.direction.clone().or_else(|| {
        meta.iter()
            .find(|(k, _)| title::label(k) == title::label("direction"))
            .map(|(_, v)| super::direction::Direction::Fixed(v.clone()))
    });
    if let Some(d) = &direction {
        series::with_directions(&mut entries, d);
    }
    let required = args
        .srs_required
        .as_deref()
        .map(RequiredSrs::read)
        .transpose()?;
    // A required SRS needs the measured one.
    let mut a = a.clone();
    a.spectrum.srs |= required.is_some();
    let results = series::analyze_drawn(&a, &entries);
    // Every input, each once, in the order given: the recordings, then the files the options
    // name.
    use provenance::Role;
    let files: Vec<(Role, PathBuf)> = (entries.iter().map(|e| (Role::Recording, e.file.clone())))
        .chain(a.scene.clone().map(|p| (Role::Scene, p)))
        .chain(
            (a.free_fall.as_deref().map(crate::pipeline::free_fall::file))
                .map(|p| (Role::FreeFall, p.to_path_buf())),
        )
        .chain(
            a.spec
                .and_then(|s| s.band_file)
                .map(|p| (Role::Band, p.to_path_buf())),
        )
        .chain(target.clone().map(|p| (Role::Target, p)))
        .chain(args.srs_required.clone().map(|p| (Role::RequiredSrs, p)))
        .chain(args.meta.meta_file.clone().map(|p| (Role::Meta, p)))
        .collect();
    // Each `.IDE` recording's own account, once a file.
    let mut recorded: Vec<title::Recorded> = Vec::new();
    for e in &entries {
        if let Some(r) = title::recorded(&e.file, e.column.as_ref(), &a.axes) {
            if !recorded.contains(&r) {
                recorded.push(r);
            }
        }
    }
    let front = Front {
        meta,
        recorded,
        written,
        inputs: provenance::inputs(&files),
    };
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
    let page = page(filter.as_deref(), &results, required.as_ref(), &front);
    if let Some(html) = &args.html {
        crate::output::write(html, page.as_str().as_bytes())?;
    }
    if let Some(out) = &args.pdf {
        pdf::print(page.as_str(), args.paper, out)?;
    }
    for e in &results {
        for n in &e.notes {
            crate::errln!("note: {}", series::failure(e, n));
        }
    }
    for out in args.html.iter().chain(&args.pdf) {
        crate::errln!("wrote {}", out.display());
    }
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
dt{font-weight:bold}\
.banner{border:2px solid #999;border-radius:4px;padding:.5em 1em;margin:1em 0;background:#f3f3f3}\
.banner .headline{font-size:1.3em;margin:.2em 0}.banner ul{margin:.3em 0}\
.banner-pass{border-color:#080;background:#eaf6ea}.banner-pass b{color:#080}\
.banner-fail{border-color:#b00;background:#fcebea}.banner-fail b{color:#b00}\
.banner-incomplete{border-color:#b80;background:#fff7e0}.banner-incomplete b{color:#960}\
table.title{font-size:.95em;min-width:40em}table.title th{width:13em}th.sub{background:#e6ecf5}\
.hash{font-family:monospace;font-size:.95em}table.verdicts td{vertical-align:top;white-space:nowrap}\
table.verdicts td.l{white-space:normal}";

/// The page: `results` analysed with the windows' filter `filter` (its description), against `required`, with
/// `front`'s title block and inputs: the verdict first, then who and what, the verdicts of each
/// pulse, the series, the pulses; the settings and the inputs last.
fn page(
    filter: Option<&str>,
    results: &[EntryJson],
    required: Option<&RequiredSrs>,
    front: &Front,
) -> Html {
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
        json.summary.impacts,
        if json.summary.impacts == 1 { "" } else { "s" },
    );
    verdict::banner(&mut h, results);
    title::title_block(&mut h, &front.meta, &front.recorded, front.written);
    verdict::verdicts_table(&mut h, results);
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
    if let Some(r) = &json.summary.spec {
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
    if let Some(text) = json.summary.statistics_left_out.text(json.summary.impacts) {
        html!(h, "<p>{}.</p>\n", text);
    }
    if !json.summary.statistics.is_empty() {
        h.raw("<h2>Statistics across the series</h2><p>sd: sample standard deviation; CV: sd / |mean|.</p>");
        statistics_table(&mut h, &json.summary.statistics);
    }
    for g in &json.summary.bounce_statistics {
        html!(
            h,
            "<h3>Bounce {} of each drop</h3><p>Complete and unclipped.</p>",
            g.bounce_number
        );
        statistics_table(&mut h, &g.statistics);
    }
    directions::by_direction(&mut h, &json.direction_statistics);
    // The pulses.
    h.raw("<h2>Pulses</h2>\n");
    let drawn: usize = results.iter().map(|e| e.figures.len()).sum();
    let total = json.summary.impacts;
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
    // The spectra: with --srs each impact's, over the required one with --srs-required.
    if required.is_some() || series::impacts(results).any(|(_, i)| i.shock_spectrum.is_some()) {
        spectra(&mut h, results, required);
    }
    // The appendix: how the report was made, and from what.
    provenance::settings(&mut h, filter, results, required);
    provenance::inputs_table(&mut h, &front.inputs);
    h.raw("</body></html>\n");
    h
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
    let files: Vec<&str> = series::impacts(results)
        .map(|(e, _)| e.file.as_str())
        .collect();
    let (folder, short) = verdict::short_files(&files);
    for ((e, i), file) in series::impacts(results).zip(&short) {
        let o = |v: Option<f64>, u: &str| {
            v.map_or("—".into(), |v| human(v, u).trim_end().to_string())
        };
        let mut verdict = Html::new();
        match &i.spec {
            Some(Some(v)) if v.pass => {
                verdict.raw("<span class=\"pass\">PASS</span>");
            }
            Some(Some(v)) => {
                // Which part failed: the band (its limit, by its worst excursion) or Δv (by
                // its offset from the nominal, and the standard's other reading when it has
                // one).
                let spec = e.analysis.as_ref().and_then(|a| a.spec.as_ref());
                let mut why = Vec::new();
                for c in v.failed() {
                    let text = match c {
                        Criterion::BandUpper | Criterion::BandLower => {
                            format!("{} by {:+.1} % of the peak", c.words(), 100.0 * v.margin)
                        }
                        Criterion::DeltaV => {
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
                            format!("Δv{off}{other}")
                        }
                        Criterion::Transverse => format!(
                            "transverse: {}",
                            v.transverse
                                .as_ref()
                                .map_or(String::new(), |t| t.worst_words())
                        ),
                    };
                    why.push(text);
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
            file,
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
                    html!(
                        h,
                        "<td class=\"l{}\">{}</td>",
                        srs_required::class(c.as_ref()),
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
    if !folder.is_empty() {
        html!(
            h,
            "<p class=\"note\">Files in {} (each input's full path and SHA-256: Inputs, at the end).</p>\n",
            folder
        );
    }
}

/// The section of each impact's SRS, drawn over the required one when there is one (at most
/// [`MAX_FIGURES`]).
fn spectra(h: &mut Html, results: &[EntryJson], required: Option<&RequiredSrs>) {
    match required {
        Some(required) => {
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
        }
        None => {
            h.raw("<h2>Shock response spectra</h2>\n");
            h.raw("<p>Each impact's SRS (maximax absolute acceleration of the oscillators, their damping and bands as the settings give them).</p>\n");
        }
    }
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
