//! `impact report … --html FILE`: the five AFRL repeats with a specification in one
//! self-contained page (no network, no script), checked as written and in a real headless
//! browser (Chromium from the distribution's packages: `scripts/setup.sh` installs it; with
//! `IMPACT_REQUIRE_BROWSER` set a missing browser is an error, not a skip): the page loads,
//! every figure is there, and its screenshot is a full, non-blank image. A required SRS: each
//! impact's SRS judged against it and drawn over it. A deliverable to sign: the verdict's
//! banner first, each failing pulse named with the criterion it failed and where; the title
//! block (`--meta`, `--meta-file`, an `.IDE`'s recorder and sensor, the time and the tool's
//! commit); every input's SHA-256; a hostile `--meta` escaped.

use std::path::Path;
use std::process::Command;

use sha2::{Digest, Sha256};

mod common;
use common::browser::chromium;
use common::{impact, impact_judged, impact_ok, Scratch};

fn afrl() -> String {
    format!(
        "{}/data/afrl-drop-tower/accel_5.csv",
        env!("CARGO_MANIFEST_DIR")
    )
}

/// The report of the five repeats, judged as 11 000 g, 100 µs half-sines.
fn write_report(html: &Path) -> String {
    // Every pulse fails: exit status 3.
    let (_, err) = impact_judged(&[
        "report",
        &afrl(),
        "--channels",
        "1,2,3,4,5",
        "--units",
        "kgn",
        "--spec",
        "half-sine,11000g,0.1ms",
        "--html",
        html.to_str().unwrap(),
    ]);
    assert!(err.contains("wrote "), "{err}");
    std::fs::read_to_string(html).unwrap()
}

#[test]
fn the_report_is_one_self_contained_page_with_every_pulse() {
    let scratch = Scratch::new();
    let html_path = scratch.join("afrl.html");
    let page = write_report(&html_path);
    assert!(page.starts_with("<!DOCTYPE html>"));
    // Self-contained: nothing fetched, nothing run.
    for outside in ["<script", "<link", " src=", "url(", "@import"] {
        assert!(!page.contains(outside), "{outside} in the page");
    }
    // The settings and provenance, the table, the statistics and the verdicts.
    for want in [
        "Impact report: 5 recordings, 5 impacts",
        &format!("impact {}", env!("CARGO_PKG_VERSION")),
        "IEC 60068-2-27:2008 tolerances",
        // The repeats all end while their pulse rings: none is compared, and the page says so.
        "statistics over the 0 comparable impacts",
        "left out: 5 incomplete",
        "judged impacts pass",
    ] {
        assert!(page.contains(want), "{want} missing");
    }
    // One figure per impact, each with the measured trace and the band, its time told from
    // the nominal pulse's start (as the verdict's "after the nominal start"), placed on the
    // recording's clock where the verdict placed it.
    assert_eq!(page.matches("<svg").count(), 5);
    assert_eq!(page.matches("nominal, tolerance band").count(), 5);
    assert_eq!(
        page.matches("time from the nominal pulse's start, t = ")
            .count(),
        5
    );
    // The impacts' table names each file within the folder it gives once (the full path is
    // in the inputs' table).
    assert!(page.contains("<tr><td class=\"l\">accel_5.csv</td>"));
    assert!(page.contains(&format!(
        "Files in {}",
        Path::new(&afrl()).parent().unwrap().display()
    )));
    // The numbers in the table are the series' own.
    let (json, _) = impact_judged(&[
        "analyze",
        &afrl(),
        "--channels",
        "1,2,3,4,5",
        "--units",
        "kgn",
        "--spec",
        "half-sine,11000g,0.1ms",
        "--json",
    ]);
    let j: serde_json::Value = serde_json::from_str(&json).unwrap();
    let start = j["entries"][0]["impacts"][0]["spec"]["nominal_start_s"]
        .as_f64()
        .unwrap();
    assert!(
        page.contains(&format!(
            "time from the nominal pulse's start, t = {start:.6} s"
        )),
        "{start}"
    );
    assert_eq!(
        page.matches("class=\"fail\">FAIL").count() + page.matches("class=\"pass\">PASS").count(),
        5
    );
    let passed = j["spec"]["passed"].as_u64().unwrap();
    assert!(page.contains(&format!("{passed} of 5 judged impacts pass")));
    // The report never writes over an input.
    let (code, _, err) = impact(&["report", &afrl(), "--channels", "1,2", "--html", &afrl()]);
    common::assert_refused(
        Some(code),
        &err,
        "would be overwritten",
        "--html onto an input",
    );
}

/// Channel `channel`'s SRS (Hz, m/s²) as `impact analyze --srs --json` gives it.
fn measured_srs(channel: &str) -> Vec<(f64, f64)> {
    let (json, _) = impact_ok(&[
        "analyze",
        &afrl(),
        "--column",
        channel,
        "--units",
        "kgn",
        "--srs",
        "--json",
    ]);
    let j: serde_json::Value = serde_json::from_str(&json).unwrap();
    let sp = &j["impacts"][0]["shock_spectrum"];
    let values = |k: &str| -> Vec<f64> {
        sp[k]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect()
    };
    values("frequency_hz")
        .into_iter()
        .zip(values("srs_m_s2"))
        .collect()
}

/// The report of channels 1 and 2 against the required SRS in `csv`: the page, or the error.
fn report_against(d: &Path, name: &str, csv: &str) -> Result<String, String> {
    report_against_with(d, name, csv, &[])
}

/// [`report_against`] with the options `extra` too.
fn report_against_with(d: &Path, name: &str, csv: &str, extra: &[&str]) -> Result<String, String> {
    let required = d.join(format!("{name}.csv"));
    std::fs::write(&required, csv).unwrap();
    let html = d.join(format!("{name}.html"));
    let afrl = afrl();
    let mut args = vec![
        "report",
        &afrl,
        "--channels",
        "1,2",
        "--units",
        "kgn",
        "--srs-required",
        required.to_str().unwrap(),
        "--html",
        html.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let (code, _, err) = impact(&args);
    if code == 0 {
        Ok(std::fs::read_to_string(&html).unwrap())
    } else {
        Err(err)
    }
}

#[test]
fn a_required_srs_judges_and_draws_each_impact_s_srs() {
    let scratch = Scratch::new();
    let d = scratch.path();
    // Channel 1's own SRS lowered by 2 dB, in m/s² and in g: its SRS lies 2 dB above it at
    // every natural frequency (within −1.5/+3 dB); lowered by 4 dB, 4 dB above (beyond +3).
    let srs = measured_srs("1");
    let required = |db: f64, g: bool| {
        let k = 10f64.powf(-db / 20.0) / if g { 9.80665 } else { 1.0 };
        let unit = if g {
            "acceleration_g"
        } else {
            "acceleration_m_s2"
        };
        let rows: String = srs
            .iter()
            .map(|(f, a)| format!("{f},{}\n", a * k))
            .collect();
        format!("frequency_hz,{unit}\n{rows}")
    };
    for g in [false, true] {
        let page = report_against(d, "within", &required(2.0, g)).unwrap();
        // No --srs given: the required SRS implies it.
        assert!(page.contains("SRS within −1.5/+3 dB of required</th>"));
        assert!(page.contains("MIL-STD-810H Method 516.8"));
        let cells: Vec<&str> = page
            .match_indices("worst at ")
            .map(|(k, _)| &page[k - 8..k + 40])
            .collect();
        assert_eq!(cells.len(), 2, "{cells:?}");
        assert!(
            cells[0].contains("yes, worst at") && cells[0].contains(", +2.00 dB<"),
            "{cells:?}"
        );
        // Two pulses, two spectra over the required one with its limits dashed.
        assert_eq!(page.matches("<svg").count(), 4);
        assert_eq!(page.matches("−1.5 dB\n</text>").count(), 2);
        assert!(page.contains("impact 0: SRS, m/s² (left), g (right)"));
    }
    let page = report_against(d, "beyond", &required(4.0, false)).unwrap();
    assert!(page.contains("class=\"l fail\">no, worst at "), "the cell");
    assert!(page.contains(", +4.00 dB</td>"));
    // Bands stopped at 10 kHz (--srs-high; --srs implied by the requirement, not given)
    // against a requirement to 114 kHz (channel 1's own SRS): within where compared, said to
    // be for that part only, and no pass.
    let page = report_against_with(
        d,
        "within-10k",
        &required(2.0, false),
        &["--srs-high", "10000"],
    )
    .unwrap();
    let want =
        " dB; compared from 11.05 Hz to 8980 Hz only, required from 11.05 Hz to 1.140e5 Hz</td>";
    assert!(page.contains(want), "{want}");
    assert!(page.contains("<td class=\"l\">yes, worst at "));
    assert!(!page.contains("class=\"l pass\""));
    // Breakpoints outside the spectrum's band: nothing to compare.
    let page = report_against(d, "elsewhere", "frequency_hz,acceleration_g\n1,10\n5,10\n").unwrap();
    assert_eq!(
        page.matches("not compared (no natural frequency in both)")
            .count(),
        2
    );
    // Saved by Excel as "CSV UTF-8" (a byte-order mark first): read as without it.
    let page = report_against(
        d,
        "bom",
        "\u{feff}frequency_hz,acceleration_g\n1,10\n5,10\n",
    )
    .unwrap();
    assert_eq!(
        page.matches("not compared (no natural frequency in both)")
            .count(),
        2
    );
    // A file that is no required SRS is refused, naming what is wrong.
    for (csv, want) in [
        (
            "f,a\n1,2\n",
            "needs the columns frequency_hz and acceleration_m_s2",
        ),
        (
            "frequency_hz,acceleration_g\n100,1\n50,1\n",
            "line 3: frequency_hz 50 does not increase",
        ),
        (
            "frequency_hz,acceleration_g\n100,1\n200,-1\n",
            "line 3: acceleration_g \"-1\" is not a positive number",
        ),
        (
            "frequency_hz,acceleration_g\n100,1\n",
            "at least two breakpoints",
        ),
        // 1e308 g is a finite number that overflows in m/s²: it was compared in "NaN dB".
        (
            "frequency_hz,acceleration_g\n100,1e308\n200,1\n",
            "line 2: acceleration_g \"1e308\" is too large to be an acceleration",
        ),
        // CRLF and a comment between rows: lines counted as an editor counts them.
        (
            "# spec 7\r\nfrequency_hz,acceleration_g\r\n100,1\r\n# x\r\n50,1\r\n",
            "line 5: frequency_hz 50 does not increase",
        ),
    ] {
        let err = report_against(d, "bad", csv).unwrap_err();
        assert!(
            err.contains("--srs-required") && err.contains(want),
            "{err}"
        );
    }
    // The report never writes over it.
    let required = d.join("kept.csv");
    std::fs::write(&required, required_text()).unwrap();
    let (code, _, err) = impact(&[
        "report",
        &afrl(),
        "--channels",
        "1",
        "--srs-required",
        required.to_str().unwrap(),
        "--html",
        required.to_str().unwrap(),
    ]);
    common::assert_refused(Some(code), &err, "would be overwritten", "--html onto it");
    assert_eq!(std::fs::read_to_string(&required).unwrap(), required_text());
}

/// A required SRS (+6 dB/octave to 2 kHz, flat to 50 kHz).
fn required_text() -> &'static str {
    "frequency_hz,acceleration_g\n100,400\n2000,8000\n50000,8000\n"
}

#[test]
fn the_report_loads_in_a_headless_browser_with_every_figure() {
    let Some(browser) = chromium() else { return };
    let scratch = Scratch::new();
    let d = scratch.path();
    let html = d.join("browser.html");
    write_report(&html);
    let url = format!("file://{}", html.display());
    let headless = |extra: &[&str]| {
        let out = Command::new(browser)
            .args([
                "--headless",
                "--no-sandbox",
                "--disable-gpu",
                "--hide-scrollbars",
                "--enable-logging=stderr",
                "--v=0",
                &format!("--user-data-dir={}", d.join("profile").display()),
            ])
            .args(extra)
            .arg(&url)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        out
    };
    // The page as the browser built it: every figure an SVG element in the document.
    let dom = headless(&["--dump-dom"]);
    let dom_text = String::from_utf8_lossy(&dom.stdout);
    assert_eq!(dom_text.matches("<svg").count(), 5, "{dom_text}");
    assert!(dom_text.contains("statistics over the 0 comparable impacts"));
    assert!(
        dom_text.contains("<b>FAIL</b>: 0 of 5 pulses pass"),
        "the banner"
    );
    let log = String::from_utf8_lossy(&dom.stderr);
    assert!(
        !log.contains("Uncaught") && !log.contains(":CONSOLE("),
        "the page logged errors: {log}"
    );
    // Its screenshot: a PNG of the window's size, not blank (a blank page compresses to a
    // few kB).
    let png = d.join("browser.png");
    headless(&[
        "--window-size=1200,2400",
        &format!("--screenshot={}", png.display()),
    ]);
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    let be = |k: usize| u32::from_be_bytes(bytes[k..k + 4].try_into().unwrap());
    assert_eq!((be(16), be(20)), (1200, 2400), "IHDR width and height");
    assert!(
        bytes.len() > 100_000,
        "{} bytes: a blank page?",
        bytes.len()
    );
}

/// Runs `impact ARGS` with `SOURCE_DATE_EPOCH` set to `epoch`: (exit code, stdout, stderr).
fn impact_at(epoch: &str, args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_impact"))
        .env("SOURCE_DATE_EPOCH", epoch)
        .args(args)
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn ide() -> String {
    format!(
        "{}/data/endaq-high-drop/High-Drop.IDE",
        env!("CARGO_MANIFEST_DIR")
    )
}

/// A row of the title block.
fn title_row(label: &str, value: &str) -> String {
    format!("<tr><th class=\"l\">{label}</th><td class=\"l\">{value}</td></tr>")
}

#[test]
fn the_title_block_holds_the_lab_s_lines_and_the_recording_s_own() {
    let scratch = Scratch::new();
    let meta = scratch.text(
        "meta.txt",
        "# drop 7\ntest-id = T-0042\ndut: bracket, rev B\ncalibration-due = 2027-01-31\n",
    );
    let html = scratch.join_str("ide.html");
    let (code, _, err) = impact_at(
        "1764385620",
        &[
            "report",
            &ide(),
            "--column",
            "8.1",
            "--meta-file",
            &meta,
            "--meta",
            "operator=A. Smith",
            "--meta",
            "test-id=T-0043",
            "--meta",
            "shaker=LDS V8",
            "--html",
            &html,
        ],
    );
    assert_eq!(code, 0, "{err}");
    let page = std::fs::read_to_string(&html).unwrap();
    // The lab's lines with their labels, in the order given: the file's, then --meta's (one
    // that the file also gives takes its place with the command line's value); an unknown key
    // as it is.
    let rows = [
        title_row("Test ID", "T-0043"),
        title_row("Device under test", "bracket, rev B"),
        title_row("Calibration due", "2027-01-31"),
        title_row("Operator", "A. Smith"),
        title_row("shaker", "LDS V8"),
        title_row(
            "Report written",
            "2025-11-29T03:07:00Z (UTC, from SOURCE_DATE_EPOCH)",
        ),
    ];
    let at: Vec<usize> = rows
        .iter()
        .map(|r| {
            page.find(r.as_str())
                .unwrap_or_else(|| panic!("{r} missing"))
        })
        .collect();
    assert!(at.windows(2).all(|w| w[0] < w[1]), "the order: {at:?}");
    assert!(!page.contains("T-0042"), "the file's test-id replaced");
    // The tool's version and the commit it was built from (a copy without git: unknown).
    let tool = format!(
        "<th class=\"l\">Tool</th><td class=\"l\">impact {}, git commit ",
        env!("CARGO_PKG_VERSION")
    );
    let k = page.find(&tool).expect("the tool's row") + tool.len();
    let commit = &page[k..page[k..].find('<').unwrap() + k];
    // A build from changed sources says so after its commit.
    let commit = commit
        .strip_suffix(" with changes not committed (a development build: not for a signed report)")
        .unwrap_or(commit);
    assert!(
        commit == "unknown"
            || (commit.len() == 40 && commit.bytes().all(|b| b.is_ascii_hexdigit())),
        "{commit}"
    );
    // The recording's own account: the recorder, the analysed subchannel's sensor, the
    // factory calibration (as enDAQ's idelib reads them from the file).
    for want in [
        "Slam Stick X (2000g+DC), part number LOG-0002-02kG-DC, serial 6468, firmware 1.20.1",
        "832M1 PE Accelerometer, serial 5663-033 (subchannel 8.1 Z (2000g))",
        "calibrated 2019-01-29, calibration no. 4953, no expiry recorded",
    ] {
        assert!(page.contains(want), "{want} missing");
    }
    // The block comes after the verdict's banner and before the series.
    let banner = page.find("id=\"verdict\"").unwrap();
    assert!(banner < at[0] && at[0] < page.find("<h2>Impacts</h2>").unwrap());
    // A SOURCE_DATE_EPOCH that is no time, a meta line without a value's separator: refused.
    let (code, _, err) = impact_at("tomorrow", &["report", &ide(), "--html", &html]);
    common::assert_refused(
        Some(code),
        &err,
        "SOURCE_DATE_EPOCH=\"tomorrow\"",
        "a bad epoch",
    );
    let bad = scratch.text("bad.txt", "test-id = 1\njust words\n");
    let (code, _, err) = impact(&["report", &ide(), "--meta-file", &bad, "--html", &html]);
    common::assert_refused(
        Some(code),
        &err,
        "bad.txt: line 2: no `=` or `:` between a key and its value",
        "a bad meta file",
    );
    let (code, _, err) = impact(&["report", &ide(), "--meta", "operator", "--html", &html]);
    assert_eq!(code, 2, "a usage error: {err}");
    assert!(err.contains("no `=` between a key and its value"), "{err}");
}

/// `bytes`' SHA-256 in lower-case hex.
fn sha256(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

#[test]
fn every_input_is_listed_with_its_size_and_sha_256() {
    let scratch = Scratch::new();
    let required = scratch.text("required.csv", required_text());
    let meta = scratch.text("meta.txt", "test-id: T-7\n");
    let html = scratch.join_str("hashes.html");
    let (code, _, err) = impact(&[
        "report",
        &afrl(),
        "--channels",
        "1,2",
        "--units",
        "kgn",
        "--srs-required",
        &required,
        "--meta-file",
        &meta,
        "--html",
        &html,
    ]);
    assert_eq!(code, 0, "{err}");
    let page = std::fs::read_to_string(&html).unwrap();
    // Each file once (the recording is analysed twice), with its role, size and hash.
    for (role, path) in [
        ("recording", afrl()),
        ("required SRS", required.clone()),
        ("meta file", meta.clone()),
    ] {
        let bytes = std::fs::read(&path).unwrap();
        let row = format!(
            "<tr><td class=\"l\">{role}</td><td class=\"l\">{path}</td><td>{}</td><td class=\"l hash\">{}</td></tr>",
            bytes.len(),
            sha256(&bytes)
        );
        assert_eq!(page.matches(&row).count(), 1, "{row}");
    }
    assert_eq!(page.matches("<td class=\"l hash\">").count(), 3);
}

#[test]
fn the_verdict_comes_first_and_names_each_failing_pulse_with_what_it_failed_and_where() {
    let scratch = Scratch::new();
    let page = write_report(&scratch.join("afrl.html"));
    // The banner first: before the title block, the verdicts, the settings and the table.
    let banner = page
        .find("<div class=\"banner banner-fail\" id=\"verdict\"><p class=\"headline\"><b>FAIL</b>: 0 of 5 pulses pass</p>")
        .expect("the banner");
    for later in [
        "<table class=\"title\">",
        "<h2>Verdicts</h2>",
        "<h2>Settings and provenance</h2>",
        "<h2>Impacts</h2>",
        "<h2>Pulses</h2>",
    ] {
        assert!(
            banner < page.find(later).unwrap(),
            "{later} before the banner"
        );
    }
    assert!(page[..banner].matches("<table").count() == 0);
    // Each pulse named, with the criterion its verdict failed and where, as the JSON has it.
    let (json, _) = impact_judged(&[
        "analyze",
        &afrl(),
        "--channels",
        "1,2,3,4,5",
        "--units",
        "kgn",
        "--spec",
        "half-sine,11000g,0.1ms",
        "--json",
    ]);
    let j: serde_json::Value = serde_json::from_str(&json).unwrap();
    let recordings = j["entries"].as_array().unwrap();
    assert_eq!(recordings.len(), 5);
    for (k, r) in recordings.iter().enumerate() {
        let v = &r["impacts"][0]["spec"];
        assert_eq!(v["pass"], false);
        let limit = v["worst_limit"].as_str().unwrap();
        let words = match limit {
            "upper" => "above the band's upper limit",
            "lower" => "below the band's lower limit",
            other => panic!("worst_limit {other}"),
        };
        // The worst sample beyond its limit: above the upper one, below the lower one.
        let (worst, lim) = (
            v["worst_m_s2"].as_f64().unwrap(),
            v["limit_m_s2"].as_f64().unwrap(),
        );
        assert_eq!(worst > lim, limit == "upper", "{v}");
        // On the recording's clock to the microsecond.
        let at = format!("at t = {:.6} s", v["worst_time_s"].as_f64().unwrap());
        let named = format!(
            "<li><a href=\"#pulse-{k}\">accel_5.csv [{}] impact 0</a>: {words}: ",
            k + 1
        );
        let li = page
            .find(&named)
            .unwrap_or_else(|| panic!("{named} missing"));
        let line = &page[li..li + page[li..].find("</li>").unwrap()];
        assert!(line.contains(&at), "{line}: {at}");
        // Its row in the verdicts' table, which the banner links to.
        assert!(page.contains(&format!("<tr id=\"pulse-{k}\"><td class=\"l\">accel_5.csv [{}] impact 0</td><td class=\"l fail\">FAIL</td>", k + 1)));
    }
    // The judged Δv against the nominal one, each pulse's worst point circled in its figure.
    let nominal = j["entries"][0]["spec"]["nominal_delta_v_m_s"]
        .as_f64()
        .unwrap();
    assert!(
        page.contains(&format!("<td>{nominal:.3}</td>")),
        "nominal Δv {nominal}"
    );
    assert_eq!(page.matches("<circle class=\"worst\"").count(), 5);
    assert_eq!(page.matches(">worst point: fails</text>").count(), 5);
}

#[test]
fn a_pulse_failing_its_delta_v_is_named_so_with_its_window() {
    let scratch = Scratch::new();
    let html = scratch.join_str("dv.html");
    // AFRL's pulse as an 11 000 g, 100 µs half-sine with Δv within ±2 %: its Δv is 5 % high.
    let (_, err) = impact_judged(&[
        "report",
        &format!(
            "{}/data/afrl-drop-tower/series1_test1_full_100ms.csv",
            env!("CARGO_MANIFEST_DIR")
        ),
        "--column",
        "bottom_kgn",
        "--spec",
        "half-sine,11000g,0.1ms,dv=0.02",
        "--html",
        &html,
    ]);
    assert!(err.contains("1 of 1 judged impact failed"), "{err}");
    let page = std::fs::read_to_string(&html).unwrap();
    let li = page.find("<li><a href=\"#pulse-0\">").expect("named");
    let line = &page[li..li + page[li..].find("</li>").unwrap()];
    assert!(line.contains("below the band's lower limit: "), "{line}");
    assert!(
        line.contains("; Δv outside its tolerance: 7.240 m/s is +5.4 % of the nominal 6.867 m/s (tolerance ±2 %), integrated from t = "),
        "{line}"
    );
}

#[test]
fn a_hostile_meta_value_reaches_the_page_escaped() {
    let scratch = Scratch::new();
    let meta = scratch.text("meta.txt", "lab = <img onerror=\"x\">&amp;\n");
    let html = scratch.join_str("hostile.html");
    let (code, _, err) = impact(&[
        "report",
        &ide(),
        "--meta",
        "operator=<script>alert(\"x\")</script>",
        "--meta",
        "<b>key</b>=v",
        "--meta-file",
        &meta,
        "--html",
        &html,
    ]);
    assert_eq!(code, 0, "{err}");
    let page = std::fs::read_to_string(&html).unwrap();
    for raw in ["<script", "<img", "<b>key"] {
        assert!(!page.contains(raw), "{raw} unescaped");
    }
    for escaped in [
        title_row(
            "Operator",
            "&lt;script&gt;alert(&quot;x&quot;)&lt;/script&gt;",
        ),
        title_row("&lt;b&gt;key&lt;/b&gt;", "v"),
        title_row("Laboratory", "&lt;img onerror=&quot;x&quot;&gt;&amp;amp;"),
    ] {
        assert!(page.contains(&escaped), "{escaped} missing");
    }
}

/// What a quality manager could be misled by is refused or said: a recording of the series
/// with no pulse makes the verdict INCOMPLETE and is named; a contact that had not ended has
/// a duration that is a lower bound (no error made of it); a meta file that is no regular
/// file, a key that would pose as the tool's own row, two spellings of one key, and a
/// bidi override are refused; a recording read through a pipe is not given the hash of
/// whatever the pipe holds later.
#[cfg(unix)]
#[test]
fn what_would_mislead_a_signed_report_is_refused_or_said() {
    let scratch = Scratch::new();
    let accel_5 = format!(
        "{}/data/afrl-drop-tower/accel_5.csv",
        env!("CARGO_MANIFEST_DIR")
    );
    let quiet = scratch.join("quiet.csv");
    let rows: String = (0..2000)
        .map(|k| format!("{:.6},0.0\n", k as f64 * 1e-6))
        .collect();
    std::fs::write(&quiet, format!("time_s,accel\n{rows}")).unwrap();
    let html = scratch.join("q.html");
    let (code, _, err) = common::impact(&[
        "report",
        &accel_5,
        quiet.to_str().unwrap(),
        "--column",
        "1",
        "--units",
        "kgn",
        "--spec",
        "half-sine,11000g,0.1ms,band=0.9,outside=0.9",
        "--html",
        html.to_str().unwrap(),
    ]);
    assert!(code == 0 || code == 3, "{err}");
    let page = std::fs::read_to_string(&html).unwrap();
    assert!(
        page.contains("<b>INCOMPLETE</b>"),
        "a recording without a pulse"
    );
    assert!(page.contains("1 recording without a pulse"));
    assert!(page.contains("quiet.csv [") && page.contains("no pulse found, nothing judged"));
    // accel_5's contact runs to the end of its capture: a lower bound, no error.
    assert!(
        page.contains("<td>≥ 410.9 µs</td><td>— (stream-ended)</td>"),
        "duration"
    );
    let refused = |args: &[&str], want: &str| {
        let mut all = vec!["report", &accel_5, "--units", "kgn", "--html"];
        let out = scratch.join("r.html");
        all.push(out.to_str().unwrap());
        all.extend(args);
        let (code, _, err) = common::impact(&all);
        assert_ne!(code, 0, "{args:?}");
        assert!(err.contains(want), "{args:?}: {err}");
    };
    refused(
        &["--meta", "Report written=2001-01-01"],
        "the tool's own row",
    );
    refused(
        &["--meta", "test-id=1", "--meta", "TEST_ID=2"],
        "given twice",
    );
    let bidi = scratch.join("bidi.txt");
    std::fs::write(&bidi, "operator = A\u{202e}B\n").unwrap();
    refused(
        &["--meta-file", bidi.to_str().unwrap()],
        "a control character in the value",
    );
    refused(&["--meta-file", "/dev/zero"], "not a regular file");
    // A recording through a pipe: listed without a hash, and why.
    let piped = scratch.join("p.html");
    let status = std::process::Command::new("bash")
        .arg("-c")
        .arg(format!(
            "{} report <(cat {accel_5}) --column 1 --units kgn --html {}",
            env!("CARGO_BIN_EXE_impact"),
            piped.display()
        ))
        .status()
        .unwrap();
    assert!(status.success());
    let page = std::fs::read_to_string(&piped).unwrap();
    assert!(page.contains("not a regular file: read once as it streamed, so not hashed"));
    assert!(!page.contains("e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855"));
    // A file named in bytes that are not UTF-8, and an argument with a space: the command
    // row quotes it as a shell would take it back; no panic.
    use std::os::unix::ffi::OsStrExt;
    let odd = scratch
        .join("x")
        .with_file_name(std::ffi::OsStr::from_bytes(b"\xff.csv"));
    std::fs::copy(&accel_5, &odd).unwrap();
    let out = scratch.join("odd.html");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_impact"))
        .arg("report")
        .arg(&odd)
        .args([
            "--column",
            "1",
            "--units",
            "kgn",
            "--meta",
            "operator=A. Smith",
            "--html",
        ])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{o:?}");
    let page = std::fs::read_to_string(&out).unwrap();
    assert!(
        page.contains("\u{fffd}.csv&#39;") || page.contains("\u{fffd}.csv'"),
        "the file's name"
    );
    assert!(
        page.contains("--meta &#39;operator=A. Smith&#39;")
            || page.contains("--meta 'operator=A. Smith'")
    );
}

/// `impact report --srs` (no required SRS): each impact's SRS drawn in its own section, one
/// figure per impact with a spectrum; without `--srs`, no such section.
#[test]
fn srs_alone_draws_each_impacts_spectrum() {
    let scratch = Scratch::new();
    let file = format!(
        "{}/data/endaq-high-drop/High-Drop_2000g-PE_13.4-15.0s.csv",
        env!("CARGO_MANIFEST_DIR")
    );
    let run = |extra: &[&str], name: &str| {
        let out = scratch.join(name);
        let mut args = vec!["report", &file, "--html", out.to_str().unwrap()];
        args.extend(extra);
        let (code, _, err) = common::impact(&args);
        assert_eq!(code, 0, "{err}");
        std::fs::read_to_string(out).unwrap()
    };
    let json = common::impact_ok(&["analyze", &file, "--srs", "--json"]).0;
    let j: serde_json::Value = serde_json::from_str(&json).unwrap();
    let with = j["impacts"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|i| !i["shock_spectrum"].is_null())
        .count();
    assert!(with > 0);
    let page = run(&["--srs"], "srs.html");
    assert!(page.contains("<h2>Shock response spectra</h2>"));
    assert_eq!(page.matches(": SRS, m/s² (left), g (right)").count(), with);
    let page = run(&[], "plain.html");
    assert!(!page.contains("Shock response spectra"));
}

/// A recording whose clock starts at 100 s: the pulse figure's origin is said on that clock,
/// as the verdict's `nominal_start_s` is.
#[test]
fn the_pulse_figure_says_its_origin_on_the_recording_s_clock() {
    let scratch = Scratch::new();
    let mut csv = String::from("time_s,accel_g\n");
    for k in 0..10_000u32 {
        let t = f64::from(k) / 50_000.0 - 0.05;
        let p = if (0.0..0.006).contains(&t) {
            50.0 * (std::f64::consts::PI * t / 0.006).sin()
        } else {
            0.0
        };
        csv.push_str(&format!(
            "{:.6},{:.5}\n",
            100.0 + t + 0.05,
            p + 0.001 * f64::from(k % 7)
        ));
    }
    let file = scratch.text("late.csv", &csv);
    let html = scratch.join_str("late.html");
    let (code, _, err) = impact(&[
        "report",
        &file,
        "--spec",
        "half-sine,50g,6ms",
        "--html",
        &html,
    ]);
    assert_eq!(code, 0, "{err}");
    let (json, _) = impact_judged(&["analyze", &file, "--spec", "half-sine,50g,6ms", "--json"]);
    let j: serde_json::Value = serde_json::from_str(&json).unwrap();
    let start = j["impacts"][0]["spec"]["nominal_start_s"].as_f64().unwrap();
    assert!(start > 100.0, "{start}");
    let page = std::fs::read_to_string(&html).unwrap();
    assert!(
        page.contains(&format!(
            "time from the nominal pulse's start, t = {start:.6} s on the recording's clock"
        )),
        "{start}"
    );
}
