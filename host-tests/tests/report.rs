//! `impact report … --html FILE`: the five AFRL repeats with a specification in one
//! self-contained page (no network, no script), checked as written and in a real headless
//! browser (Chromium from the distribution's packages: `scripts/setup.sh` installs it; with
//! `IMPACT_REQUIRE_BROWSER` set a missing browser is an error, not a skip): the page loads,
//! every figure is there, and its screenshot is a full, non-blank image. A required SRS: each
//! impact's SRS judged against it and drawn over it.

use std::path::Path;
use std::process::Command;

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
    // One figure per impact, each with the measured trace and the band.
    assert_eq!(page.matches("<svg").count(), 5);
    assert_eq!(page.matches("nominal, tolerance band").count(), 5);
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
    let required = d.join(format!("{name}.csv"));
    std::fs::write(&required, csv).unwrap();
    let html = d.join(format!("{name}.html"));
    let (code, _, err) = impact(&[
        "report",
        &afrl(),
        "--channels",
        "1,2",
        "--units",
        "kgn",
        "--srs-required",
        required.to_str().unwrap(),
        "--html",
        html.to_str().unwrap(),
    ]);
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
