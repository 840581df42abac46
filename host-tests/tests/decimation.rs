//! A contact longer than the capture, kept whole at a coarser step (`core/src/capture.rs`):
//! what `impact analyze` measures on the decimated capture (its default is the board's
//! length) against the same recording analysed with a capture that holds every sample
//! (`--capture-samples 131072`).

mod common;
use common::{impact, impact_judged, Scratch};
use serde_json::Value;

/// The common soft train ([`common::soft_train_args`]): 4 contacts of 55–64 ms at 500 kS/s.
fn soft_train(scratch: &Scratch) -> String {
    let (code, csv, err) = impact(&common::soft_train_args("4", "0.8"));
    assert_eq!(code, 0, "{err}");
    scratch.text("soft-train.csv", &csv)
}

/// The impacts of `impact analyze FILE ARGS --json`.
fn impacts(file: &str, args: &[&str]) -> Vec<Value> {
    let mut all = vec!["analyze", file, "--json"];
    all.extend_from_slice(args);
    let (out, _) = impact_judged(&all);
    let v: Value = serde_json::from_str(&out).unwrap();
    v["impacts"].as_array().unwrap().clone()
}

fn num(v: &Value, field: &str) -> f64 {
    v[field]
        .as_f64()
        .unwrap_or_else(|| panic!("{field} not a number: {v}"))
}

fn within(what: &str, got: f64, want: f64, rel: f64) {
    assert!(
        (got - want).abs() <= rel * want.abs(),
        "{what}: {got} for {want} (more than {rel} relative)"
    );
}

const SCENE: [&str; 6] = ["--mass", "0.06", "--v0", "1.3357", "--train", "flight"];

#[test]
fn a_contact_longer_than_the_capture_keeps_every_field_that_resolves() {
    let scratch = Scratch::new();
    let file = soft_train(&scratch);
    let mut board = SCENE.to_vec();
    board.extend(["--srs", "--spec", "half-sine,10g,5ms"]);
    let mut whole = board.clone();
    whole.extend(["--capture-samples", "131072"]);
    let board = impacts(&file, &board);
    let whole = impacts(&file, &whole);
    assert_eq!(board.len(), 4);
    assert_eq!(whole.len(), 4);
    for (b, w) in board.iter().zip(&whole) {
        let i = &b["index"];
        assert!(num(w, "duration_s") > 0.0302, "{w}");
        // Whole at a coarser step, not cut.
        assert_eq!(b["status"], "complete", "{b}");
        let step = b["decimation"].as_u64().unwrap();
        assert!(step.is_power_of_two() && step >= 2, "{b}");
        assert!(b["flags"].as_array().unwrap().contains(&"decimated".into()));
        assert_eq!(w["decimation"], 1, "{w}");
        // The stream's fields and kinematics: every sample either way, the same bits.
        for field in [
            "start_s",
            "peak_acceleration_m_s2",
            "delta_v_m_s",
            "duration_s",
            "crush_time_s",
            "max_deformation_m",
            "cor",
        ] {
            assert_eq!(b[field], w[field], "impact {i}: {field}");
        }
        // The width on values of `step` samples: within 1 % (half of a mean's peak, which
        // averages the noise the single largest sample rides on, lies a little lower).
        within("fwhm_s", num(b, "fwhm_s"), num(w, "fwhm_s"), 1e-2);
        // The spectra at the coarser rate: the bands it reaches (up to its own limit, from
        // the same first band), each within 0.5 %.
        let (bs, ws) = (&b["shock_spectrum"], &w["shock_spectrum"]);
        assert_eq!(bs["first_hz"], ws["first_hz"]);
        let (bs, ws) = (
            bs["srs_m_s2"].as_array().unwrap(),
            ws["srs_m_s2"].as_array().unwrap(),
        );
        assert!(bs.len() >= 40 && bs.len() <= ws.len(), "{} bands", bs.len());
        for (x, y) in bs.iter().zip(ws) {
            within("srs", x.as_f64().unwrap(), y.as_f64().unwrap(), 5e-3);
        }
        // The verdict on the coarser values: the same, its margin and Δv within 1 %.
        let (bv, wv) = (&b["spec"], &w["spec"]);
        assert_eq!(bv["pass"], wv["pass"], "impact {i}: {bv} / {wv}");
        within("margin", num(bv, "margin"), num(wv, "margin"), 1e-2);
        within("Δv", num(bv, "delta_v_m_s"), num(wv, "delta_v_m_s"), 1e-2);
        // The fits on the coarser values' points: the law's parameters within 2 %.
        let (bf, wf) = (&b["fits"]["nonlinear"], &w["fits"]["nonlinear"]);
        for p in ["k", "c_s_m", "exponent"] {
            eprintln!("impact {i} {p}: {} vs {}", bf[p], wf[p]);
            within(p, num(bf, p), num(wf, p), 2e-2);
        }
        // The set, where the whole capture resolves it: within 1 % of the crush's deformation.
        let x_m = num(w, "max_deformation_m");
        match (
            b["permanent_deformation_m"].as_f64(),
            w["permanent_deformation_m"].as_f64(),
        ) {
            (Some(x), Some(y)) => assert!((x - y).abs() <= 0.01 * x_m, "set {x} vs {y}"),
            (None, None) => {}
            other => panic!("impact {i}: set {other:?}"),
        }
    }
}

#[test]
fn a_width_the_coarser_values_cannot_resolve_is_null_and_says_why() {
    // A 100 µs drop-tower pulse whose 100 ms specified window outgrows the capture many times:
    // the width would span a few values.
    let file = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/data/afrl-drop-tower/series1_test1_full_100ms.csv"
    );
    let (code, out, err) = impact(&[
        "analyze",
        file,
        "--spec",
        "half-sine,11000g,100ms",
        "--json",
    ]);
    assert!(code == 0 || code == 3, "{err}");
    let v: Value = serde_json::from_str(&out).unwrap();
    let r = &v["impacts"][0];
    assert!(r["decimation"].as_u64().unwrap() >= 4, "{r}");
    assert!(r["fwhm_s"].is_null(), "{r}");
    assert_eq!(r["null_reasons"]["fwhm_s"], "decimated-too-coarse");
    // The filtered width likewise: its half maximum lies inside (no flag says otherwise).
    let (code, out, err) = impact(&[
        "analyze",
        file,
        "--spec",
        "half-sine,11000g,100ms",
        "--cfc",
        "1000",
        "--json",
    ]);
    assert!(code == 0 || code == 3, "{err}");
    let v: Value = serde_json::from_str(&out).unwrap();
    let r = &v["impacts"][0];
    assert!(r["filtered_peak_acceleration_m_s2"].is_number(), "{r}");
    assert!(r["filtered_fwhm_s"].is_null(), "{r}");
    assert_eq!(r["null_reasons"]["filtered_fwhm_s"], "decimated-too-coarse");
    let flags = r["flags"].to_string();
    assert!(!flags.contains("half-maximum-outside"), "{flags}");
    // With every sample held, the width is there.
    let (_, out, _) = impact(&[
        "analyze",
        file,
        "--spec",
        "half-sine,11000g,100ms",
        "--json",
        "--capture-samples",
        "131072",
    ]);
    let v: Value = serde_json::from_str(&out).unwrap();
    assert!(v["impacts"][0]["fwhm_s"].is_number());
}

#[test]
fn a_filtered_half_maximum_outside_the_capture_says_so() {
    // A 2 ms, 100 g half-sine that settles at 70 g (a sensor knocked to a new level): neither
    // the raw nor the filtered signal comes back below half the peak.
    let scratch = Scratch::new();
    let mut csv = String::from("time_s,accel_g\n");
    let rate = 50_000.0;
    for i in 0..30_000 {
        let t = i as f64 / rate;
        let pulse = if (0.2..0.202).contains(&t) {
            100.0 * (std::f64::consts::PI * (t - 0.2) / 0.002).sin()
        } else {
            0.0
        };
        let level = if t >= 0.201 { 70.0 } else { 0.0 };
        let a = pulse.max(level) + 0.05 * (i as f64 * 1.3).sin();
        csv.push_str(&format!("{t:.6},{a:.4}\n"));
    }
    let file = scratch.text("step.csv", &csv);
    let r = &impacts(&file, &["--cfc", "1000"])[0];
    assert!(r["filtered_peak_acceleration_m_s2"].is_number(), "{r}");
    assert!(r["filtered_fwhm_s"].is_null(), "{r}");
    assert_eq!(r["null_reasons"]["filtered_fwhm_s"], "half-maximum-outside");
    let flags = r["flags"].to_string();
    assert!(
        flags.contains("\"filtered-half-maximum-outside\""),
        "{flags}"
    );
}

#[test]
fn the_emulator_runs_the_boards_capture_and_refuses_another() {
    let scratch = Scratch::new();
    let file = soft_train(&scratch);
    let (code, _, err) = impact(&["emulate", &file, "--capture-samples", "65536"]);
    assert_ne!(code, 0);
    assert!(
        err.contains("--capture-samples: the board's capture is 15104 samples"),
        "{err}"
    );
    // A length out of range is refused by the option.
    let (code, _, err) = impact(&["analyze", &file, "--capture-samples", "200000"]);
    assert_ne!(code, 0);
    assert!(err.contains("--capture-samples"), "{err}");
}
