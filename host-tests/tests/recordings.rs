//! Every bundled recording through `impact analyze` (the core pipeline), with what is known
//! about it (see ../shared/signals/README.md).

use std::path::PathBuf;

use impact_host::analyze::{self, AnalysisJson, AnalyzeArgs, Units};
use impact_host::recording::ColumnRef;

fn signals() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/signals")
}

fn analyze(args: AnalyzeArgs) -> AnalysisJson {
    let setup = analyze::setup(&args, None).unwrap_or_else(|e| panic!("{e}"));
    let reports = analyze::run(&setup.prepared.counts, &setup.scene).unwrap();
    analyze::to_json(&setup, &reports)
}

fn file(rel: &str) -> AnalyzeArgs {
    AnalyzeArgs {
        file: signals().join(rel),
        ..Default::default()
    }
}

const G: f64 = 9.80665;

#[test]
fn afrl_test1_full_record_gives_exactly_one_impact() {
    let a = analyze(AnalyzeArgs {
        units: Some(Units::Kgn),
        ..file("afrl-drop-tower/series1_test1_full_100ms.csv")
    });
    assert_eq!(a.samples, 100_000);
    assert!((a.sample_rate_hz - 1e6).abs() < 1.0);
    assert_eq!(a.impacts.len(), 1, "{:#?}", a.impacts);
    let i = &a.impacts[0];
    assert_eq!(i.status, "complete");
    assert!(!i.clipped);
    // Source: ~150 µs wide pulse, 11-13 kg_n.
    let peak_kgn = i.peak_acceleration_m_s2 / (1000.0 * G);
    assert!((10.5..13.5).contains(&peak_kgn), "{peak_kgn}");
    assert!((100e-6..400e-6).contains(&i.duration_s), "{}", i.duration_s);
    let fwhm = i.fwhm_s.expect("FWHM");
    assert!((40e-6..100e-6).contains(&fwhm), "{fwhm}");
    let dv = i.delta_v_m_s.expect("Δv");
    assert!((5.0..8.0).contains(&dv), "{dv}");
    // The table hit the mass ~9.9 ms into the record.
    assert!((0.0095..0.0102).contains(&i.start_s), "{}", i.start_s);
}

#[test]
fn afrl_five_repeats_are_consistent() {
    // accel_5: the bottom fixture, the clean body-to-barrier pulse; accel_6: the top fixture
    // (the package's own response, looser).
    for (f, dv_spread) in [
        ("afrl-drop-tower/accel_5.csv", 0.05),
        ("afrl-drop-tower/accel_6.csv", 0.10),
    ] {
        let mut peaks = Vec::new();
        let mut widths = Vec::new();
        let mut dvs = Vec::new();
        for c in 1..=5 {
            let a = analyze(AnalyzeArgs {
                units: Some(Units::Kgn),
                rate: Some(1e6),
                column: Some(ColumnRef::Index(c)),
                ..file(f)
            });
            assert_eq!(a.impacts.len(), 1, "{f} test {c}: {:#?}", a.impacts);
            let i = &a.impacts[0];
            peaks.push(i.peak_acceleration_m_s2 / (1000.0 * G));
            widths.push(i.fwhm_s.expect("FWHM"));
            dvs.push(i.delta_v_m_s.expect("Δv"));
        }
        let spread = |v: &[f64]| {
            let mean = v.iter().sum::<f64>() / v.len() as f64;
            let max_dev = v.iter().map(|x| (x / mean - 1.0).abs()).fold(0.0, f64::max);
            (mean, max_dev)
        };
        let (peak, dp) = spread(&peaks);
        let (width, dw) = spread(&widths);
        let (dv, ddv) = spread(&dvs);
        println!(
            "{f}: peak {peak:.2} kg_n ±{:.1} %, FWHM {:.1} µs ±{:.1} %, Δv {dv:.3} m/s ±{:.1} %",
            dp * 100.0,
            width * 1e6,
            dw * 100.0,
            ddv * 100.0
        );
        assert!((10.0..13.5).contains(&peak) && dp < 0.10, "{peaks:?}");
        assert!(dw < 0.15, "{widths:?}");
        assert!(ddv < dv_spread, "{dvs:?}");
    }
}

#[test]
fn endaq_drop_free_fall_gives_the_impact_speed() {
    let dc = signals().join("endaq-high-drop/High-Drop_16g-DC_full.csv");
    let a = analyze(AnalyzeArgs {
        column: Some(ColumnRef::Name("z_g".into())),
        free_fall: Some(dc.display().to_string()),
        ..file("endaq-high-drop/High-Drop_2000g-PE_13.4-15.0s.csv")
    });
    assert_eq!(a.v0_source.as_deref(), Some("free-fall"));
    let t_ff = a.free_fall_s.unwrap();
    // Released near 13.62 s, hits near 14.63 s: about one second of free fall.
    assert!((0.98..1.03).contains(&t_ff), "{t_ff}");
    let i = &a.impacts[0];
    assert!((14.60..14.65).contains(&i.start_s), "{}", i.start_s);
    assert_eq!(a.impacts.len(), 1, "{:#?}", a.impacts);
    // The piezo channel is AC-coupled: after the pulse it undoes its Δv. That is said, and
    // no Δv or COR is given (it was a COR of -0.92 before the flag).
    assert_eq!(i.flags, ["ac-coupled"]);
    assert!(i.delta_v_m_s.is_none() && i.cor.is_none(), "{i:#?}");
    assert_eq!(i.null_reasons["cor"], "ac-coupled");
}

/// Reports in time order, each one's contact before the next one's (and its window too).
fn ordered_and_disjoint(a: &AnalysisJson) {
    for (r, next) in a.impacts.iter().zip(a.impacts.iter().skip(1)) {
        assert!(r.start_s + r.duration_s <= next.start_s, "{r:#?} {next:#?}");
        assert!(r.end_sample <= next.start_sample, "{r:#?} {next:#?}");
    }
}

#[test]
fn water_entry_gives_the_slam_first_and_ordered_disjoint_pulses() {
    // The 100 g channel at 20 kS/s: the slam at 10.18 s, then pulses tens of ms apart with
    // the signal back at its level between them (each its own report).
    let a = analyze(AnalyzeArgs {
        column: Some(ColumnRef::Name("y_g".into())),
        ..file("impack-water-entry/4mps_sphere_1_100g-PR_9.9-10.6s.csv")
    });
    let i = &a.impacts[0];
    assert!(
        (60.0..66.0).contains(&(i.peak_acceleration_m_s2 / G)),
        "{}",
        i.peak_acceleration_m_s2 / G
    );
    assert!((10.18..10.19).contains(&i.start_s), "{}", i.start_s);
    ordered_and_disjoint(&a);
    // The 40 g DC channel at 2 kS/s sees the slam in one sample at the same time, and no
    // report starts before it (its slow drift before the entry is no impact).
    let dc = analyze(AnalyzeArgs {
        column: Some(ColumnRef::Name("y_g".into())),
        ..file("impack-water-entry/4mps_sphere_1_40g-DC_9.9-10.6s.csv")
    });
    assert!(
        (dc.impacts[0].peak_time_s - i.peak_time_s).abs() < 1e-3,
        "{dc:#?}"
    );
    ordered_and_disjoint(&dc);
}

#[test]
fn hammer_strikes_give_one_pulse_each() {
    for n in 1..=5 {
        let a = analyze(AnalyzeArgs {
            column: Some(ColumnRef::Name("force_n".into())),
            units: Some(Units::N),
            ..file(&format!("pyfrf-impact-hammer/measurement_{n}.csv"))
        });
        assert_eq!(a.impacts.len(), 1, "measurement {n}: {:#?}", a.impacts);
        let i = &a.impacts[0];
        assert_eq!(i.status, "complete");
        // A 6-7 sample force pulse at 25.6 kHz.
        assert!(
            (100e-6..500e-6).contains(&i.duration_s),
            "{n}: {}",
            i.duration_s
        );
        assert!(
            (50.0..100.0).contains(&i.peak_acceleration_m_s2),
            "{n}: {}",
            i.peak_acceleration_m_s2
        );
    }
}
