//! The command line follows its ecosystem's conventions and reads what a test engineer means:
//! clap's own errors with the accepted values; one name per concept (the earlier spellings
//! kept as hidden aliases); levels with their unit; units read from the header and checked
//! against `--units`; a time column without a unit checked for plausibility; `--plot` writes
//! SVG or refuses; the channel taken, and what the tool derives, said where the user looks.

mod common;

use common::{impact, impact_ok, Scratch};

fn afrl() -> String {
    concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/data/afrl-drop-tower/series1_test1_full_100ms.csv"
    )
    .to_string()
}

/// A recording at 10 kHz: a half-sine of `peak` at 0.1 s, in a CSV with `header`.
fn pulse_csv(scratch: &Scratch, name: &str, header: &str, peak: f64, dt: f64) -> String {
    let mut s = format!("{header}\n");
    for k in 0..4000 {
        let t = k as f64 * 1e-4;
        let v = if (0.1..0.104).contains(&t) {
            peak * (std::f64::consts::PI * (t - 0.1) / 0.004).sin()
        } else {
            0.001 * ((k * 7919) % 13) as f64
        };
        s.push_str(&format!("{:.7},{v}\n", k as f64 * dt));
    }
    scratch.text(name, &s)
}

fn json(args: &[&str]) -> serde_json::Value {
    let mut all = args.to_vec();
    all.push("--json");
    serde_json::from_str(&impact_ok(&all).0).unwrap()
}

#[test]
fn a_usage_error_is_claps_message_with_the_accepted_values() {
    let (code, _, err) = impact(&["analyze", &afrl(), "--units", "G"]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.starts_with("error: invalid value 'G' for '--units <UNITS>'")
            && err.contains("[possible values: g, m/s2, kgn, n]")
            && err.contains("--help"),
        "{err}"
    );
}

#[test]
fn earlier_spellings_still_work_but_are_not_offered() {
    let scratch = Scratch::new();
    let out = scratch.join_str("alias.csv");
    let out = out.as_str();
    let new = impact_ok(&[
        "synth",
        "--model",
        "linear",
        "--mass",
        "0.06",
        "--v0",
        "1",
        "--stiffness",
        "1e4",
        "--impacts",
        "2",
        "--every",
        "0.03",
        "--duration",
        "0.08",
    ])
    .0;
    let old = impact_ok(&[
        "synth",
        "--law",
        "linear",
        "--mass",
        "0.06",
        "--v0",
        "1",
        "--stiffness",
        "1e4",
        "--repeat",
        "2",
        "--every",
        "0.03",
        "--duration",
        "0.08",
    ])
    .0;
    assert_eq!(new, old);
    impact_ok(&[
        "synth",
        "--model",
        "linear",
        "-m",
        "0.06",
        "--v0",
        "1",
        "--stiffness",
        "1e4",
        "-o",
        out,
    ]);
    assert!(std::fs::read_to_string(out)
        .unwrap()
        .starts_with("time_s,accel_g\n"));
    for (sub, hidden) in [
        ("synth", "--law"),
        ("synth", "--repeat"),
        ("emulate", "--raw"),
    ] {
        let help = impact_ok(&[sub, "--help"]).0;
        assert!(
            !help.contains(&format!("{hidden} ")),
            "{sub} --help offers {hidden}"
        );
    }
    // emulate refuses --stream: it is not offered.
    assert!(!impact_ok(&["emulate", "--help"]).0.contains("--stream"));
    // Every subcommand's help is in sections, with examples.
    for sub in ["analyze", "emulate", "simulate", "synth", "log"] {
        let help = impact_ok(&[sub, "--help"]).0;
        assert!(help.contains("Examples:\n  impact "), "{sub}");
        assert!(help.contains("\nOutput:\n"), "{sub}: no Output section");
    }
}

#[test]
fn levels_take_their_unit_and_a_bare_number_is_m_s2() {
    let f = afrl();
    let g = json(&["analyze", &f, "--trigger", "500g", "--edge", "100g"]);
    let si = json(&["analyze", &f, "--trigger", "4903.325", "--edge", "980.665"]);
    assert_eq!(g, si);
    // A range in the wrong unit: the recording reaches far more than twice it.
    let (code, _, err) = impact(&["analyze", &f, "--range", "16"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("--range") && err.contains("16g"), "{err}");
    assert!(json(&["analyze", &f, "--range", "16kgn"])["clipping"]["from"] == "range");
}

#[test]
fn the_scene_file_uses_the_options_names_and_reads_the_earlier_ones() {
    let f = afrl();
    let scratch = Scratch::new();
    let new = scratch.file(
        "new.json",
        r#"{"trigger": "500g", "edge": 980.665, "hold": 0.003}"#,
    );
    let old = scratch.file(
        "old.json",
        r#"{"trigger_m_s2": 4903.325, "edge_m_s2": 980.665, "hold_s": 0.003}"#,
    );
    let a = json(&["analyze", &f, "--scene", new.to_str().unwrap()]);
    let b = json(&["analyze", &f, "--scene", old.to_str().unwrap()]);
    assert_eq!(a, b);
    let c = json(&[
        "analyze",
        &f,
        "--trigger",
        "500g",
        "--edge",
        "100g",
        "--hold",
        "0.003",
    ]);
    assert_eq!(a, c);
}

#[test]
fn units_come_from_the_header_and_must_agree_with_units_given() {
    let scratch = Scratch::new();
    // The same pulse written in m/s² under a header that says so, and in g under a bare one.
    let si = pulse_csv(&scratch, "si.csv", "time_s,table_m_s2", 490.3325, 1e-4);
    let g = pulse_csv(&scratch, "g.csv", "time_s,table", 50.0, 1e-4);
    let a = json(&["analyze", &si]);
    let b = json(&["analyze", &g]);
    let peak = |v: &serde_json::Value| v["impacts"][0]["peak_acceleration_m_s2"].as_f64().unwrap();
    assert!((peak(&a) - peak(&b)).abs() < 1e-3 * peak(&b), "{a} {b}");
    assert!((peak(&a) - 490.3).abs() < 5.0, "{a}");
    assert_eq!(json(&["analyze", &si, "--units", "m/s2"]), a);
    let (code, _, err) = impact(&["analyze", &si, "--units", "g"]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("--units g") && err.contains("table_m_s2"),
        "{err}"
    );
    // kg_n from the AFRL header: --units kgn changes nothing.
    assert_eq!(
        json(&["analyze", &afrl()]),
        json(&["analyze", &afrl(), "--units", "kgn"])
    );
    let (code, _, err) = impact(&["analyze", &afrl(), "--units", "g"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("bottom_kgn") && err.contains("kgn"), "{err}");
}

#[test]
fn a_time_column_without_a_unit_that_implies_a_crawl_is_refused_with_the_fix() {
    let scratch = Scratch::new();
    // Written in ms (0.1 ms apart) under a bare `time`: 10 S/s if read in seconds.
    let ms = pulse_csv(&scratch, "ms.csv", "time,accel_g", 50.0, 0.1);
    for extra in [
        &[][..],
        &["--stream", "--range", "100g", "--trigger", "5g"][..],
    ] {
        let mut args = vec!["analyze", &ms];
        args.extend_from_slice(extra);
        let (code, _, err) = impact(&args);
        assert_eq!(code, 1, "{extra:?}: {err}");
        assert!(
            err.contains("\"time\" names no unit") && err.contains("--time-unit ms"),
            "{err}"
        );
    }
    let fixed = json(&["analyze", &ms, "--time-unit", "ms"]);
    assert_eq!(fixed["sample_rate_hz"].as_f64().unwrap().round(), 10000.0);
    let named = pulse_csv(&scratch, "named.csv", "time_ms,accel_g", 50.0, 0.1);
    assert_eq!(json(&["analyze", &named]), fixed);
}

#[test]
fn plot_writes_svg_or_png_or_refuses() {
    // (A PNG's contents: tests/figures.rs.)
    let scratch = Scratch::new();
    let pdf = scratch.join_str("x.pdf");
    let pdf = pdf.as_str();
    for args in [
        vec!["analyze", &afrl(), "--plot", pdf],
        vec![
            "simulate",
            "--model",
            "linear",
            "--mass",
            "1",
            "--v0",
            "1",
            "--stiffness",
            "1e6",
            "--plot",
            pdf,
        ],
    ] {
        let (code, _, err) = impact(&args);
        assert_eq!(code, 1, "{args:?}: {err}");
        assert!(
            err.contains("SVG or PNG") && err.contains(".svg or .png"),
            "{err}"
        );
        assert!(!std::path::Path::new(pdf).exists(), "{pdf} was written");
    }
}

#[test]
fn the_channel_taken_and_what_is_derived_are_said() {
    // Several channels and no --column: a note names the one taken (after the results).
    let dc = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/data/endaq-high-drop/High-Drop_16g-DC_full.csv"
    );
    let (out, err) = impact_ok(&["analyze", dc]);
    assert!(out.starts_with("x_g in g: 9780 samples"), "{out}");
    assert!(
        err.contains("note: analysing x_g of 3 channels (x_g, y_g, z_g): choose one with --column"),
        "{err}"
    );
    let (_, err) = impact_ok(&["analyze", dc, "--column", "z_g"]);
    assert!(!err.contains("note:"), "{err}");
    // An error stays one line: no note before it.
    let (code, _, err) = impact(&["analyze", dc, "--hold", "100"]);
    assert_eq!(code, 1);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    // The approach speed a free fall gives is printed, not only the fall's time.
    let pe = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/data/endaq-high-drop/High-Drop_2000g-PE_13.4-15.0s.csv"
    );
    let (out, _) = impact_ok(&["analyze", pe, "--column", "z_g", "--free-fall", dc]);
    assert!(
        out.lines()
            .next()
            .unwrap()
            .contains("v0 9.835 m/s from 1.003 s of free fall"),
        "{out}"
    );
    let v = json(&["analyze", pe, "--column", "z_g", "--free-fall", dc]);
    assert!((v["v0_m_s"].as_f64().unwrap() - 9.835).abs() < 1e-3, "{v}");
    // A setting is echoed in its own precision.
    let v = json(&["analyze", &afrl(), "--srs"]);
    assert_eq!(v["impacts"][0]["shock_spectrum"]["damping"], 0.05);
}
