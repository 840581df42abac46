//! Text from a file reaches HTML and CSV only escaped or quoted, by construction:
//!
//! - every `html!` in the host crate takes a literal with no captured argument (a `{name}`
//!   inside the literal would be written unescaped), and only the macro calls the writer
//!   behind it;
//! - a hostile name (`<script>"'&` and a spreadsheet formula `=cmd|…`) in every place a user
//!   names something — the recording's file, its column, a band file, a required SRS, a
//!   board's session file — goes through every HTML output (`impact report`, the live view's
//!   `/report.html`) escaped, and through every CSV output (`analyze --csv` of one recording
//!   and of a series, `--axes`, `impact log --csv`, which is the live view's `/session.csv`) quoted
//!   and never as a formula.

use std::path::{Path, PathBuf};

use syn::visit::Visit;

mod common;
use common::{synth_t2, Scratch};

/// A name no page or spreadsheet may run.
const HOSTILE: &str = "=cmd|<script>\"'&";

// ---------------------------------------------------------------------------------------
// The static half: every html! call.

struct HtmlCalls<'a> {
    file: &'a Path,
    faults: Vec<String>,
    /// The `html!` calls visited (one nested in another macro is not: the test then fails).
    visited: usize,
}

impl<'ast> Visit<'ast> for HtmlCalls<'_> {
    fn visit_macro(&mut self, m: &'ast syn::Macro) {
        if m.path.is_ident("html") || m.path.segments.last().is_some_and(|s| s.ident == "html") {
            self.visited += 1;
            let parsed = m.parse_body_with(
                syn::punctuated::Punctuated::<syn::Expr, syn::Token![,]>::parse_terminated,
            );
            match parsed.as_ref().ok().and_then(|args| args.iter().nth(1)) {
                Some(syn::Expr::Lit(syn::ExprLit {
                    lit: syn::Lit::Str(s),
                    ..
                })) => {
                    let text = s.value().replace("{{", "");
                    if text
                        .split('{')
                        .skip(1)
                        .any(|rest| rest.starts_with(|c: char| c.is_alphabetic() || c == '_'))
                    {
                        self.faults.push(format!(
                            "{}: html! captures an argument inside its literal: {:?}",
                            self.file.display(),
                            s.value()
                        ));
                    }
                }
                _ => self.faults.push(format!(
                    "{}: html! without a literal as its second argument",
                    self.file.display()
                )),
            }
        }
        syn::visit::visit_macro(self, m);
    }
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

#[test]
fn every_html_call_takes_a_literal_and_captures_nothing() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let mut faults = Vec::new();
    let mut calls = 0;
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        if f.ends_with("html.rs") && f.parent() == Some(&src) {
            continue;
        }
        if text.contains("__write_markup") {
            faults.push(format!("{}: calls html's writer directly", f.display()));
        }
        // Only the plots' SVG writer takes plotters' SVG as markup.
        if text.contains("from_plotters(") && !f.ends_with("plot/mod.rs") {
            faults.push(format!("{}: takes a String as markup", f.display()));
        }
        let in_text = text.matches("html!(").count();
        calls += in_text;
        let ast = syn::parse_file(&text).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        let mut v = HtmlCalls {
            file: f,
            faults: Vec::new(),
            visited: 0,
        };
        v.visit_file(&ast);
        faults.extend(v.faults);
        if v.visited != in_text {
            faults.push(format!(
                "{}: {in_text} html! calls, {} checked (one inside another macro?)",
                f.display(),
                v.visited
            ));
        }
    }
    assert!(
        calls > 30,
        "only {calls} html! calls found: is the scan looking?"
    );
    assert!(faults.is_empty(), "{}", faults.join("\n"));
}

// ---------------------------------------------------------------------------------------
// The dynamic half: hostile names through every output.

/// An HTML page: the hostile text never raw, and (where `must_name`) there escaped.
fn assert_escaped_html(what: &str, page: &str, must_name: bool) {
    assert!(
        !page.contains("<script"),
        "{what}: a raw <script in the page"
    );
    assert!(!page.contains("\"'&\""), "{what}: the name unescaped");
    if must_name {
        assert!(
            page.contains("=cmd|&lt;script&gt;&quot;'&amp;"),
            "{what}: the name is not in the page escaped"
        );
    }
}

/// A CSV: read back by a CSV reader, no cell is a formula, and (where `must_name`) a cell
/// holds the hostile name (after the `'` that disarms it).
fn assert_quoted_csv(what: &str, text: &str, must_name: bool) {
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .from_reader(text.as_bytes());
    let mut named = false;
    for record in reader.records() {
        let record = record.unwrap_or_else(|e| panic!("{what}: not CSV: {e}\n{text}"));
        for cell in &record {
            assert!(
                !cell.starts_with(['=', '@', '+']),
                "{what}: a cell a spreadsheet runs: {cell:?}"
            );
            named |= cell.contains(&format!("'{HOSTILE}"));
        }
    }
    assert!(
        !must_name || named,
        "{what}: no cell names {HOSTILE:?}\n{text}"
    );
}

/// A recording named and columned hostilely: `time_s,<HOSTILE>x_g,<HOSTILE>y_g`.
fn hostile_recording(dir: &Scratch) -> String {
    let csv = synth_t2();
    let mut lines = csv.lines();
    lines.next();
    let quoted = HOSTILE.replace('"', "\"\"");
    let mut text = format!("time_s,\"{quoted}x_g\",\"{quoted}y_g\"\n");
    for l in lines {
        let v = l.split(',').nth(1).unwrap();
        text.push_str(&format!("{l},{v}\n"));
    }
    let name = format!("{HOSTILE}.csv");
    dir.file(&name, text);
    name
}

fn run_in(dir: &Path, args: &[&str]) -> (String, String) {
    let (code, stdout, stderr) = common::impact_in(dir, args);
    assert_eq!(code, 0, "impact {}: {stderr}", args.join(" "));
    (stdout, stderr)
}

#[test]
fn hostile_names_reach_every_html_and_csv_output_escaped_or_quoted() {
    let dir = Scratch::new();
    let rec = hostile_recording(&dir);
    let column = format!("{HOSTILE}x_g");
    // CSV: one recording (its column in the axes' header), and a series (file and channel).
    let (one, _) = run_in(
        dir.path(),
        &[
            "analyze",
            &rec,
            "--axes",
            &format!("{column},{HOSTILE}y_g"),
            "--csv",
        ],
    );
    assert_quoted_csv("analyze --axes --csv", &one, true);
    let (series, _) = run_in(
        dir.path(),
        &["analyze", &rec, &rec, "--column", &column, "--csv"],
    );
    assert_quoted_csv("series --csv", &series, true);
    // HTML: the report with a hostile band file and required SRS too.
    let band = format!("{HOSTILE}band.csv");
    std::fs::copy(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/bands/half-sine-50g-11ms.csv"),
        dir.join(&band),
    )
    .unwrap();
    let required = format!("{HOSTILE}srs.csv");
    dir.file(&required, "frequency_hz,acceleration_g\n10,1\n1000,100\n");
    run_in(
        dir.path(),
        &[
            "report",
            &rec,
            "--column",
            &column,
            "--srs-required",
            &required,
            "--html",
            "report.html",
        ],
    );
    let page = std::fs::read_to_string(dir.join("report.html")).unwrap();
    assert_escaped_html("report --srs-required", &page, true);
    assert!(
        page.matches("=cmd|&lt;script&gt;").count() >= 3,
        "file, column, SRS named"
    );
    let (_, err) = run_in(
        dir.path(),
        &[
            "report",
            &rec,
            "--column",
            &column,
            "--spec",
            &format!("half-sine,50g,11ms,band-file={band}"),
            "--html",
            "band.html",
        ],
    );
    let page = std::fs::read_to_string(dir.join("band.html")).unwrap();
    assert_escaped_html(&format!("report --spec band-file ({err})"), &page, true);
}

#[test]
fn a_hostile_session_name_reaches_the_log_exports_escaped_or_quoted() {
    let dir = Scratch::new();
    let log = format!("{HOSTILE}.log");
    dir.file(
        &log,
        format!(
            "{}\n{}\n",
            common::board_log::SCENE,
            common::board_log::impact_line(1, 0, None)
        ),
    );
    let (csv, _) = run_in(dir.path(), &["log", &log, "--csv"]);
    assert_quoted_csv("log --csv", &csv, false);
    // The live view's page report of that session file.
    let page = impact_host_report(dir.path(), &log);
    assert_escaped_html("watch's /report.html", &page, true);
}

/// The live view's `/report.html` of session file `log`, as its page serves it.
fn impact_host_report(dir: &Path, log: &str) -> String {
    impact_host::cli::html::log_report(&dir.join(log), None)
        .unwrap_or_else(|e| panic!("log report: {e}"))
}
