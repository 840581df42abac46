//! The CFC filter (`--cfc`) against a filter run over the whole record, and a filter never
//! changing an unfiltered field: on every bundled recording and channel, every field of the
//! report but the filtered ones is the same with and without `--cfc`.

use std::path::PathBuf;

use impact_core::signal::cfc::{Biquad, Cfc};
use impact_host::pipeline::{self, AnalyzeArgs, Units};
use impact_host::report::AnalysisJson;
use impact_io::channel::ColumnRef;

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
            for class in [60, 180, 600, 1000] {
                let Ok(filtered) = analyze(&AnalyzeArgs {
                    cfc: Some(class),
                    ..args.clone()
                }) else {
                    // (A rate too low for the class is refused as a whole.)
                    continue;
                };
                assert_eq!(
                    unfiltered(&filtered),
                    unfiltered(&plain),
                    "{rel} column {column:?} CFC {class}"
                );
                compared += 1;
            }
        }
    }
    assert!(compared >= 40, "{compared}");
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
