//! `impact analyze` from the command line: output formats and one-line errors on bad input.

mod common;
use common::{impact, Scratch};

fn afrl() -> String {
    concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/data/afrl-drop-tower/series1_test1_full_100ms.csv"
    )
    .to_string()
}

#[test]
fn json_csv_and_table_agree() {
    let f = afrl();
    let (code, out, err) = impact(&["analyze", &f, "--units", "kgn", "--json"]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["samples"], 100000);
    let imp = &v["impacts"][0];
    for key in [
        "peak_acceleration_m_s2",
        "peak_force_n",
        "delta_v_m_s",
        "duration_s",
        "start_s",
        "peak_time_s",
        "clipped",
        "impact_velocity_m_s",
        "crush_time_s",
        "max_deformation_m",
        "rebound_velocity_m_s",
        "cor",
        "separation_deformation_m",
        "permanent_deformation_m",
        "fits",
    ] {
        assert!(imp.get(key).is_some(), "missing {key}");
    }
    let (code, csv, _) = impact(&["analyze", &f, "--units", "kgn", "--csv"]);
    assert_eq!(code, 0);
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines.len(), 2);
    let header: Vec<&str> = lines[0].split(',').collect();
    let row: Vec<&str> = lines[1].split(',').collect();
    assert_eq!(header.len(), row.len());
    let col = header.iter().position(|h| *h == "delta_v_m_s").unwrap();
    // The CSV holds the report's f32 in the digits that give it back.
    assert_eq!(
        row[col].parse::<f32>().unwrap(),
        imp["delta_v_m_s"].as_f64().unwrap() as f32
    );
    let (code, table, _) = impact(&["analyze", &f, "--units", "kgn"]);
    assert_eq!(code, 0);
    assert!(table.contains("impact 0 [complete]"), "{table}");
}

#[test]
fn with_mass_and_v0_the_kinematics_and_fits_appear_and_a_plot_is_drawn() {
    let scratch = Scratch::new();
    let (code, csv, err) = impact(&[
        "synth",
        "--model",
        "nonlinear",
        "--stiffness",
        "309.416318071",
        "--damping",
        "1",
        "--mass",
        "0.06",
        "--v0",
        "1.3357",
    ]);
    assert_eq!(code, 0, "{err}");
    let f = scratch.file("bench.csv", &csv);
    let svg = f.with_extension("svg");
    // Its 50 ms contact outlasts the board's capture: held at every sample for the fits.
    let (code, out, err) = impact(&[
        "analyze",
        f.to_str().unwrap(),
        "--capture-samples",
        "131072",
        "--mass",
        "0.06",
        "--v0",
        "1.3357",
        "--json",
        "--plot",
        svg.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let i = &v["impacts"][0];
    assert!(
        (i["cor"].as_f64().unwrap() - 0.5186567982737768).abs() < 0.003,
        "{i}"
    );
    assert!(
        (i["fits"]["nonlinear"]["c_s_m"].as_f64().unwrap() - 1.0).abs() < 0.02,
        "{i}"
    );
    // The kinematics' assumption is said: a rigid, fixed barrier (none without v0).
    let said = |v: &serde_json::Value| {
        v["assumptions"].as_array().is_some_and(|a| {
            a.iter()
                .any(|s| s.as_str().unwrap().contains("rigid and fixed"))
        })
    };
    assert!(said(&v), "{}", v["assumptions"]);
    let (code, out, err) = impact(&["analyze", f.to_str().unwrap(), "--json"]);
    assert_eq!(code, 0, "{err}");
    assert!(!said(&serde_json::from_str(&out).unwrap()), "{out}");
    let (code, out, err) = impact(&[
        "analyze",
        f.to_str().unwrap(),
        "--mass",
        "0.06",
        "--v0",
        "1.3357",
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("a rigid, fixed barrier assumed"), "{out}");
    let drawn = std::fs::read_to_string(&svg).unwrap();
    assert!(drawn.contains("<svg") && drawn.contains("nonlinear fit"));
    // Every fit, the force–deformation loop; with --srs the spectra's panels.
    for text in ["Hertz fit", "two-phase fit", "force against deformation, N"] {
        assert!(drawn.contains(text), "{text} missing from the plot");
    }
    assert!(!drawn.contains("SRS (maximax)"));
    let (code, _, err) = impact(&[
        "analyze",
        f.to_str().unwrap(),
        "--mass",
        "0.06",
        "--v0",
        "1.3357",
        "--srs",
        "--plot",
        svg.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let drawn = std::fs::read_to_string(&svg).unwrap();
    assert!(drawn.contains("SRS (maximax)") && drawn.contains("pseudo-velocity"));
}

#[test]
fn malformed_input_is_one_line_naming_file_and_line() {
    let scratch = Scratch::new();
    let cases: [(&str, &str, &[&str], &str); 8] = [
        ("nan.csv", "time_s,a\n0,1\n1e-6,NaN\n", &[], ":3:"),
        ("text.csv", "time_s,a\n0,1\n1e-6,abc\n2e-6,1\n", &[], ":3:"),
        ("ragged.csv", "time_s,a\n0,1\n1e-6,2,3\n", &[], ":3:"),
        (
            "backwards.csv",
            "time_s,a\n0,1\n2e-6,2\n1e-6,3\n",
            &[],
            ":4:",
        ),
        ("repeat.csv", "time_s,a\n0,1\n1e-6,2\n1e-6,3\n", &[], ":4:"),
        ("empty.csv", "", &[], "no data rows"),
        ("header-only.csv", "time_s,a\n", &[], "no data rows"),
        ("one-line.csv", "time_s,a\n0,1\n", &[], "one sample"),
    ];
    for (name, text, extra, want) in cases {
        let f = scratch.file(name, text);
        let mut args = vec!["analyze", f.to_str().unwrap()];
        args.extend_from_slice(extra);
        let (code, _, err) = impact(&args);
        assert_ne!(code, 0, "{name}");
        assert_eq!(err.trim().lines().count(), 1, "{name}: {err}");
        assert!(err.contains(name) && err.contains(want), "{name}: {err}");
        assert!(!err.contains("panicked"));
    }
    let f = afrl();
    for (args, want) in [
        (vec!["analyze", &f, "--column", "nope"], "nope"),
        (vec!["analyze", &f, "--column", "9"], "9"),
        (vec!["analyze", &f, "--mass", "-1"], "--mass"),
        (vec!["analyze", &f, "--cfc", "100"], "--cfc"),
        (vec!["analyze", &f, "--rate", "0"], "rate"),
        (vec!["analyze", "/no/such/file.csv"], "/no/such/file.csv"),
    ] {
        let (code, _, err) = impact(&args);
        common::assert_refused(Some(code), &err, want, &format!("{args:?}"));
    }
}

/// A recording at 1 kHz: `n` rows of `time_s,a` with a half-sine pulse of 50 g at 0.1 s.
fn kilohertz(n: usize, time: impl Fn(usize) -> f64) -> String {
    let mut s = String::from("time_s,a_g\n");
    for i in 0..n {
        let t = i as f64 * 1e-3;
        let a = if (0.1..0.11).contains(&t) {
            50.0 * (std::f64::consts::PI * (t - 0.1) / 0.01).sin()
        } else {
            0.0
        } + 0.01 * ((i * 7919 % 5) as f64 - 2.0);
        s.push_str(&format!("{:.6},{a:.4}\n", time(i)));
    }
    s
}

#[test]
fn an_uneven_time_axis_is_an_error_naming_the_line_unless_resampled() {
    let scratch = Scratch::new();
    // A gap of 1000 s after row 300 (file line 302), and ten leading rows 10 ms apart.
    let gap = scratch.file(
        "gap.csv",
        kilohertz(600, |i| {
            i as f64 * 1e-3 + if i >= 300 { 1000.0 } else { 0.0 }
        }),
    );
    let (code, _, err) = impact(&["analyze", gap.to_str().unwrap()]);
    assert_ne!(code, 0);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(
        err.contains("gap.csv:302:") && err.contains("--resample"),
        "{err}"
    );
    // Resampling a 1000 s gap at 1 kHz would invent a million samples: refused.
    let (code, _, err) = impact(&["analyze", gap.to_str().unwrap(), "--resample"]);
    assert_ne!(code, 0);
    assert!(err.contains("cut the file"), "{err}");

    let lead = scratch.file(
        "lead.csv",
        kilohertz(600, |i| {
            if i < 10 {
                (i as f64 - 10.0) * 1e-2
            } else {
                (i - 10) as f64 * 1e-3
            }
        }),
    );
    let (code, _, err) = impact(&["analyze", lead.to_str().unwrap()]);
    assert_ne!(code, 0);
    assert!(err.contains("lead.csv:3:"), "{err}");
    // Resampled at the median interval: 1 kHz, the leading rows interpolated.
    let (code, out, err) = impact(&["analyze", lead.to_str().unwrap(), "--resample", "--json"]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["resampled"], true);
    assert!(
        (v["sample_rate_hz"].as_f64().unwrap() - 1000.0).abs() < 1e-6,
        "{v}"
    );
    // From -0.1 s to 0.589 s at 1 ms.
    assert!((689..=690).contains(&v["samples"].as_u64().unwrap()), "{v}");
    assert_eq!(v["impacts"].as_array().unwrap().len(), 1, "{v}");
}

#[test]
fn an_ambiguous_time_column_names_the_candidates_and_units_are_read_from_the_header() {
    let scratch = Scratch::new();
    let even = kilohertz(400, |i| i as f64 * 1e-3);
    let both: String = even
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if i == 0 {
                format!("timestamp_us,{l}\n")
            } else {
                let t: f64 = l.split(',').next().unwrap().parse().unwrap();
                format!("{},{l}\n", (t * 1e6).round())
            }
        })
        .collect();
    let f = scratch.file("two-times.csv", &both);
    let (code, _, err) = impact(&["analyze", f.to_str().unwrap()]);
    assert_ne!(code, 0);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(
        err.contains("\"timestamp_us\"") && err.contains("\"time_s\""),
        "{err}"
    );
    // Either column gives the same time base: microseconds are read as such.
    for t in ["timestamp_us", "time_s"] {
        let (code, out, err) = impact(&[
            "analyze",
            f.to_str().unwrap(),
            "--time-column",
            t,
            "--column",
            "a_g",
            "--json",
        ]);
        assert_eq!(code, 0, "{t}: {err}");
        let v: serde_json::Value = serde_json::from_str(&out).unwrap();
        assert!(
            (v["sample_rate_hz"].as_f64().unwrap() - 1000.0).abs() < 1e-6,
            "{t}: {v}"
        );
        let start = v["impacts"][0]["start_s"].as_f64().unwrap();
        assert!((0.099..0.102).contains(&start), "{t}: {start}");
    }
}

#[test]
fn a_free_fall_file_must_reach_the_impact() {
    let scratch = Scratch::new();
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/data/endaq-high-drop");
    let dc = std::fs::read_to_string(format!("{dir}/High-Drop_16g-DC_full.csv")).unwrap();
    // The DC channel cut at 4.6 s, 10 s before the impact (at rest, before the release).
    let short: String = dc
        .lines()
        .filter(|l| {
            l.split(',')
                .next()
                .unwrap()
                .parse::<f64>()
                .map_or(true, |t| t < 4.6)
        })
        .map(|l| format!("{l}\n"))
        .collect();
    let f = scratch.file("short-dc.csv", &short);
    let (code, _, err) = impact(&[
        "analyze",
        &format!("{dir}/High-Drop_2000g-PE_13.4-15.0s.csv"),
        "--column",
        "z_g",
        "--free-fall",
        f.to_str().unwrap(),
    ]);
    assert_ne!(code, 0);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(
        err.contains("ends at") && err.contains("before the impact"),
        "{err}"
    );
}
