//! `impact report … --html FILE`: the five AFRL repeats with a specification in one
//! self-contained page (no network, no script), checked as written and in a real headless
//! browser (Chromium from the distribution's packages: `scripts/setup.sh` installs it; with
//! `IMPACT_REQUIRE_BROWSER` set a missing browser is an error, not a skip): the page loads,
//! every figure is there, and its screenshot is a full, non-blank image.

use std::path::{Path, PathBuf};
use std::process::Command;

mod common;
use common::browser::chromium;
use common::{impact, impact_ok};

fn dir() -> PathBuf {
    let d =
        PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("report-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn afrl() -> String {
    format!(
        "{}/data/afrl-drop-tower/accel_5.csv",
        env!("CARGO_MANIFEST_DIR")
    )
}

/// The report of the five repeats, judged as 11 000 g, 100 µs half-sines.
fn write_report(html: &Path) -> String {
    let (_, err) = impact_ok(&[
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
    let html_path = dir().join("afrl.html");
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
        "Statistics across the series",
        "delta_v_m_s",
        "judged impacts pass",
    ] {
        assert!(page.contains(want), "{want} missing");
    }
    // One figure per impact, each with the measured trace and the band.
    assert_eq!(page.matches("<svg").count(), 5);
    assert_eq!(page.matches("nominal, tolerance band").count(), 5);
    // The numbers in the table are the series' own.
    let (json, _) = impact_ok(&[
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

#[test]
fn the_report_loads_in_a_headless_browser_with_every_figure() {
    let Some(browser) = chromium() else { return };
    let d = dir();
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
    assert!(dom_text.contains("Statistics across the series"));
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
