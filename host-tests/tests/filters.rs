//! The CFC filter (`--cfc`) against a filter run over the whole record, and a filter never
//! changing an unfiltered field: on every bundled recording and channel, every field of the
//! report but the filtered ones is the same with and without `--cfc` or `--lowpass`. The
//! low-pass from the command line: its filtered peak, its name in every output, its refusals.

use std::path::PathBuf;

use impact_core::signal::cfc::{Biquad, Cfc};
use impact_host::parse::LowpassArg;
use impact_host::pipeline::{self, AnalyzeArgs, Units};
use impact_host::report::AnalysisJson;
use impact_io::channel::ColumnRef;

mod common;
use common::{impact, impact_ok, Scratch};

fn data(rel: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("data")
        .join(rel)
}

fn analyze(args: &AnalyzeArgs) -> Result<AnalysisJson, pipeline::PipelineError> {
    let setup = pipeline::setup(args, impact_io::progress::Progress::none())?;
    let reports = pipeline::run(&setup.prepared.counts, &setup.scene, setup.capture_len)?;
    Ok(pipeline::to_json(&setup, &reports))
}

/// The report as JSON without the fields a filter may set (and the flags and null reasons
/// that say whether it could).
fn unfiltered(a: &AnalysisJson) -> serde_json::Value {
    let mut v = serde_json::to_value(a).unwrap();
    // The low-pass's setting, which says what the filtered fields are.
    v.as_object_mut().unwrap().remove("lowpass");
    for i in v["impacts"].as_array_mut().unwrap() {
        let i = i.as_object_mut().unwrap();
        for k in [
            "filtered_peak_acceleration_m_s2",
            "filtered_fwhm_s",
            "flags",
            "null_reasons",
            // With a CFC the fits take the filtered force (documented).
            "fits",
        ] {
            i.remove(k);
        }
    }
    v
}

#[test]
fn a_filter_never_changes_an_unfiltered_field_on_any_recording() {
    // Before the filter's padding was taken beyond the impact's window, --cfc lengthened the
    // hold: 8 bounces became 6 on the enDAQ DC channel, 2 pulses 1 on its piezo channel, and
    // the water entry's Δv moved by 40 %.
    let cases: Vec<(&str, Vec<Option<usize>>)> = vec![
        (
            "afrl-drop-tower/series1_test1_full_100ms.csv",
            vec![Some(1), Some(2)],
        ),
        (
            "endaq-high-drop/High-Drop_16g-DC_full.csv",
            vec![Some(1), Some(2), Some(3)],
        ),
        (
            "endaq-high-drop/High-Drop_2000g-PE_13.4-15.0s.csv",
            vec![Some(1), Some(2)],
        ),
        (
            "impack-water-entry/4mps_sphere_1_100g-PR_9.9-10.6s.csv",
            vec![Some(1), Some(2), Some(3)],
        ),
        (
            "impack-water-entry/4mps_sphere_1_40g-DC_9.9-10.6s.csv",
            vec![Some(1), Some(2), Some(3)],
        ),
        ("pyfrf-impact-hammer/measurement_1.csv", vec![Some(1)]),
    ];
    let mut compared = 0;
    for (rel, columns) in cases {
        for column in columns {
            let args = AnalyzeArgs {
                column: column.map(ColumnRef::Index),
                ..AnalyzeArgs {
                    file: data(rel),
                    ..Default::default()
                }
            };
            let plain = analyze(&args).unwrap();
            let cfc = [60, 180, 600, 1000].map(|class| AnalyzeArgs {
                cfc: Some(class),
                ..args.clone()
            });
            // The low-pass takes the same padding route: at orders whose padding is shorter
            // and longer than a CFC's.
            let lowpass =
                [(2, 1000.0), (4, 300.0), (8, 5000.0)].map(|(order, cutoff_hz)| AnalyzeArgs {
                    lowpass: Some(LowpassArg { order, cutoff_hz }),
                    ..args.clone()
                });
            for filter in cfc.iter().chain(&lowpass) {
                let Ok(filtered) = analyze(filter) else {
                    // (A rate too low for the class or cut-off is refused as a whole.)
                    continue;
                };
                assert_eq!(
                    unfiltered(&filtered),
                    unfiltered(&plain),
                    "{rel} column {column:?} CFC {:?} low-pass {:?}",
                    filter.cfc,
                    filter.lowpass
                );
                compared += 1;
            }
        }
    }
    assert!(compared >= 70, "{compared}");
}

/// The J211 filter run over the whole of `a` (f64, forward then backward, at rest on the
/// first sample): the peak and its full width at half maximum, s.
fn whole_record(a: &[f64], class: Cfc, rate_hz: f64) -> (f64, f64) {
    let mut y = a.to_vec();
    Biquad::cfc(class, rate_hz).unwrap().phaseless(&mut y);
    let i = (0..y.len())
        .max_by(|&p, &q| y[p].abs().total_cmp(&y[q].abs()))
        .unwrap();
    let half = y[i].abs() / 2.0;
    let cross = |j: usize, k: usize| {
        let (a, b) = (y[j].abs(), y[k].abs());
        j as f64 + (half - a) / (b - a) * (k as f64 - j as f64)
    };
    let l = (0..i).rev().find(|&j| y[j].abs() < half).unwrap();
    let r = (i + 1..y.len()).find(|&j| y[j].abs() < half).unwrap();
    (y[i], (cross(r, r - 1) - cross(l, l + 1)) / rate_hz)
}

#[test]
fn cfc_60_on_the_1_ms_s_afrl_record_is_the_whole_records_filter() {
    // 9.88 ms of quiet record before the pulse, SAE J211's padding for CFC 60 is 10 ms: the
    // capture reaches back to the record's first sample, where the filter starts at rest as
    // one run over the whole record does. Every class agrees with that run.
    let args = AnalyzeArgs {
        file: data("afrl-drop-tower/series1_test1_full_100ms.csv"),
        units: Some(Units::Kgn),
        column: Some(ColumnRef::Index(1)),
        // CFC 60's 10 ms of padding at 1 MS/s: more than the board's capture holds before
        // the pulse.
        capture_samples: Some(131_072),
        ..Default::default()
    };
    let plain = analyze(&args).unwrap();
    let rate = plain.sample_rate_hz;
    let base = plain.impacts[0].baseline_m_s2;
    let text = std::fs::read_to_string(&args.file).unwrap();
    let a: Vec<f64> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(1).unwrap().trim().parse::<f64>().unwrap() * 9806.65 - base)
        .collect();
    for class in [60, 180, 600, 1000] {
        let cfc = Cfc::from_class(class).unwrap();
        let (peak, width) = whole_record(&a, cfc, rate);
        let r = analyze(&AnalyzeArgs {
            cfc: Some(class),
            ..args.clone()
        })
        .unwrap();
        let i = &r.impacts[0];
        let got = i
            .filtered_peak_acceleration_m_s2
            .unwrap_or_else(|| panic!("CFC {class}: {:?}", i.null_reasons));
        // The host quantises the record to i16 counts (0.02 % of the peak's scale).
        assert!(
            (got / peak - 1.0).abs() < 1e-3,
            "CFC {class}: {got} vs {peak}"
        );
        let w = i.filtered_fwhm_s.unwrap();
        assert!(
            (w / width - 1.0).abs() < 2e-3,
            "CFC {class}: {w} vs {width}"
        );
    }
}

/// `impact analyze` on the AFRL record's bottom channel with `extra`: (table, JSON).
fn afrl_cli(extra: &[&str]) -> (String, serde_json::Value) {
    let f = data("afrl-drop-tower/series1_test1_full_100ms.csv");
    let mut args = vec!["analyze", f.to_str().unwrap(), "--units", "kgn"];
    args.extend(extra);
    let (table, _) = impact_ok(&args);
    args.push("--json");
    let (json, _) = impact_ok(&args);
    (table, serde_json::from_str(&json).unwrap())
}

#[test]
fn the_lowpass_changes_the_filtered_peak_and_is_named_in_every_output() {
    let filtered =
        |v: &serde_json::Value| v["impacts"][0]["filtered_peak_acceleration_m_s2"].as_f64();
    let (plain_table, plain) = afrl_cli(&[]);
    let (cfc_table, cfc) = afrl_cli(&["--cfc", "1000"]);
    let (lp_table, lp) = afrl_cli(&["--lowpass", "2,1kHz"]);
    let (_, lp4) = afrl_cli(&["--lowpass", "4,1000"]);
    // Raw 10 925 g; CFC 1000 3 118 g; a 2-pole 1 kHz low-pass (no J211 corner correction)
    // half that; 4 poles less again.
    assert_eq!(filtered(&plain), None);
    let (cfc_peak, lp_peak, lp4_peak) = (
        filtered(&cfc).unwrap(),
        filtered(&lp).unwrap(),
        filtered(&lp4).unwrap(),
    );
    assert!((cfc_peak - 30_580.0).abs() < 5.0, "{cfc_peak}");
    assert!((lp_peak - 15_731.0).abs() < 5.0, "{lp_peak}");
    assert!((lp4_peak - 14_744.0).abs() < 5.0, "{lp4_peak}");
    // Named: the JSON's setting (absent without it), the table's line.
    assert_eq!(
        lp["lowpass"],
        serde_json::json!({"order": 2, "cutoff_hz": 1000.0, "padding_samples": 1000})
    );
    assert_eq!(lp4["lowpass"]["order"], 4);
    assert_eq!(lp4["lowpass"]["padding_samples"], 1848);
    assert!(plain.get("lowpass").is_none() && cfc.get("lowpass").is_none());
    assert!(
        lp_table
            .contains("    low-pass-filtered (order 2, 1000 Hz): peak 15731 m/s² (1604 g), FWHM "),
        "{lp_table}"
    );
    assert!(!lp_table.contains("CFC"), "{lp_table}");
    assert!(
        cfc_table.contains("    CFC-filtered: peak 30580 m/s² (3118 g)"),
        "{cfc_table}"
    );
    assert!(!plain_table.contains("filtered"), "{plain_table}");
    // The raw fields are the same.
    for k in ["peak_acceleration_m_s2", "fwhm_s", "delta_v_m_s"] {
        assert_eq!(lp["impacts"][0][k], plain["impacts"][0][k], "{k}");
    }
    // Too little signal around the contact for an 8-pole 20 Hz filter (padding 181 ms of a
    // 100 ms record): said on the table's line, with the flag's reason.
    let (table, v) = afrl_cli(&["--lowpass", "8,20"]);
    assert_eq!(filtered(&v), None);
    assert!(
        table.contains("    low-pass-filtered (order 8, 20 Hz): unknown (cfc-window)"),
        "{table}"
    );
}

#[test]
fn the_lowpass_is_drawn_and_named_in_the_figure_and_the_report() {
    let scratch = Scratch::new();
    let d = scratch.path();
    let f = data("afrl-drop-tower/accel_5.csv");
    let svg = d.join("lowpass.svg");
    impact_ok(&[
        "analyze",
        f.to_str().unwrap(),
        "--column",
        "1",
        "--lowpass",
        "4,2kHz",
        "--plot",
        svg.to_str().unwrap(),
    ]);
    let drawn = std::fs::read_to_string(&svg).unwrap();
    for want in [
        "raw signal above its baseline, m/s²; Butterworth low-pass order 4, 2000 Hz (phaseless) over the deceleration",
        ">\nraw\n</text>",
        ">\nlow-pass\n</text>",
    ] {
        assert!(drawn.contains(want), "{want} missing from the figure");
    }
    let html = d.join("lowpass.html");
    impact_ok(&[
        "report",
        f.to_str().unwrap(),
        "--channels",
        "1,2",
        "--units",
        "kgn",
        "--lowpass",
        "4,2kHz",
        "--html",
        html.to_str().unwrap(),
    ]);
    let page = std::fs::read_to_string(&html).unwrap();
    assert!(
        page.contains(
            "<dt>filter</dt><dd>Butterworth low-pass order 4, 2000 Hz (phaseless, SciPy's \
             sosfiltfilt) on the captured windows</dd>"
        ),
        "the provenance"
    );
    assert_eq!(
        page.matches("g low-pass order 4, 2000 Hz</text>").count(),
        2,
        "the titles"
    );
    assert_eq!(
        page.matches(">low-pass order 4, 2000 Hz</text>").count(),
        2,
        "the legends"
    );
}

#[test]
fn a_bad_lowpass_is_refused_with_the_fix() {
    let f = data("afrl-drop-tower/series1_test1_full_100ms.csv");
    let f = f.to_str().unwrap();
    for (cmd, setting, want) in [
        ("analyze", "4", "expected ORDER,CUTOFF: an order of 1 to 8 and a cut-off in Hz (`4,1000` or `4,1kHz`)"),
        ("analyze", "0,1000", "order `0`: the order must be a whole number from 1 to 8"),
        ("analyze", "9,1kHz", "order `9`: the order must be a whole number from 1 to 8"),
        ("report", "2.5,1kHz", "order `2.5`: the order must be a whole number from 1 to 8"),
        ("analyze", "4,fast", "cut-off `fast`: not a number; give Hz as a number or with a unit: `1000`, `1000Hz`, `1kHz`, `0.5MHz`"),
        ("analyze", "4,-1kHz", "cut-off `-1kHz`: out of range"),
        ("emulate", "4,0", "cut-off `0`: out of range"),
        // Against the recording's rate (1 MS/s).
        ("analyze", "4,500kHz", "--lowpass: cut-off 500000 Hz is not below the Nyquist frequency, 500000 Hz (half the recording's 1000000 S/s): choose a cut-off below it"),
        ("emulate", "2,0.6MHz", "--lowpass: cut-off 600000 Hz is not below the Nyquist frequency, 500000 Hz"),
        ("analyze", "4,5Hz", "--lowpass: cut-off 5 Hz is below 10 Hz, the recording's 1000000 S/s over 100 000 (the filter's gain at 0 Hz drifts below it): choose a cut-off of at least 10 Hz"),
    ] {
        let mut args = vec![cmd, f, "--units", "kgn", "--lowpass", setting];
        let html = std::env::temp_dir().join("never-written.html");
        let html = html.to_str().unwrap();
        if cmd == "report" {
            args.extend(["--html", html]);
        }
        let (code, out, err) = impact(&args);
        assert_ne!(code, 0, "{cmd} --lowpass {setting}: {out}");
        assert!(err.contains(want), "{cmd} --lowpass {setting}: {err}");
    }
    // One filter: a CFC or a low-pass.
    let (code, _, err) = impact(&["analyze", f, "--cfc", "1000", "--lowpass", "4,1kHz"]);
    assert_ne!(code, 0);
    assert!(
        err.contains("cannot be used with") && err.contains("--lowpass <ORDER,CUTOFF>"),
        "{err}"
    );
    // The limits are the core's: 1e-5 of the rate and below Nyquist pass.
    let (code, _, err) = impact(&["analyze", f, "--units", "kgn", "--lowpass", "1,10Hz"]);
    assert_eq!(code, 0, "{err}");
    let (code, _, err) = impact(&["analyze", f, "--units", "kgn", "--lowpass", "8,499999"]);
    assert_eq!(code, 0, "{err}");
}
