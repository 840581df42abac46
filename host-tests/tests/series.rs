//! A test series (`impact analyze FILE… --channels LIST`): the five AFRL repeats in one call
//! give the reports of five single analyses and the textbook statistics of their metrics;
//! folders and patterns expand to their recordings; a recording that fails is named, the
//! others still reported, the exit status 1.

use std::path::Path;

mod common;
use common::{impact, impact_ok, Scratch};

fn data(rel: &str) -> String {
    format!("{}/data/{rel}", env!("CARGO_MANIFEST_DIR"))
}

fn json(text: &str) -> serde_json::Value {
    serde_json::from_str(text).unwrap_or_else(|e| panic!("{e}: {text}"))
}

/// The five repeats of AFRL's bottom accelerometer (columns 1 to 5 of `accel_5.csv`, kg_n).
#[test]
fn the_five_afrl_repeats_are_five_analyses_and_their_statistics() {
    let file = data("afrl-drop-tower/accel_5.csv");
    let (out, _) = impact_ok(&[
        "analyze",
        &file,
        "--channels",
        "1,2,3,4,5",
        "--units",
        "kgn",
        "--json",
    ]);
    let series = json(&out);
    assert_eq!(series["recordings"], 5);
    assert_eq!(series["failed"], 0);
    let entries = series["entries"].as_array().unwrap();
    let mut peaks = Vec::new();
    let mut delta_vs = Vec::new();
    for (k, e) in entries.iter().enumerate() {
        let column = (k + 1).to_string();
        assert_eq!(e["channel"], column.as_str());
        assert_eq!(e["file"], file.as_str());
        // Each entry is the single analysis of its channel, field for field.
        let (single, _) = impact_ok(&[
            "analyze", &file, "--column", &column, "--units", "kgn", "--json",
        ]);
        let single = json(&single);
        assert_eq!(e["impacts"], single["impacts"], "channel {column}");
        assert_eq!(e["samples"], single["samples"]);
        let i = &single["impacts"][0];
        peaks.push(i["peak_acceleration_m_s2"].as_f64().unwrap());
        delta_vs.push(i["delta_v_m_s"].as_f64().unwrap());
    }
    // Every repeat ends while its pulse rings (`stream-ended`): none is compared, the
    // statistics say so (their arithmetic: `report::statistics`'s unit tests, and
    // `statistics_leave_out_clipped_and_cut_pulses_and_count_them` below).
    assert_eq!(series["statistics"], serde_json::json!([]), "{series}");
    assert_eq!(
        series["statistics_left_out"],
        serde_json::json!({"incomplete": 5, "clipped": 0, "later_bounces": 0})
    );

    // The table: a row per impact and the statistics.
    let (table, _) = impact_ok(&[
        "analyze",
        &file,
        "--channels",
        "1,2,3,4,5",
        "--units",
        "kgn",
    ]);
    assert!(
        table.starts_with("series: 5 recordings, 5 impacts\n"),
        "{table}"
    );
    assert!(
        table.contains("statistics over the 0 comparable impacts (complete, unclipped, each drop's first); left out: 5 incomplete"),
        "{table}"
    );

    // The CSV: file and channel first, the peak in g last, engineering digits.
    let (csv, _) = impact_ok(&[
        "analyze",
        &file,
        "--channels",
        "1,2,3,4,5",
        "--units",
        "kgn",
        "--csv",
    ]);
    let mut rows = csv.lines().map(|l| l.split(',').collect::<Vec<_>>());
    let header = rows.next().unwrap();
    assert_eq!(&header[..3], ["file", "channel", "index"]);
    assert_eq!(*header.last().unwrap(), "peak_acceleration_g");
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let rows: Vec<Vec<&str>> = rows.collect();
    assert_eq!(rows.len(), 5);
    for (k, r) in rows.iter().enumerate() {
        assert_eq!(r.len(), header.len());
        assert_eq!(r[1], (k + 1).to_string());
        let peak: f32 = r[col("peak_acceleration_m_s2")].parse().unwrap();
        assert_eq!(f64::from(peak), peaks[k], "the f32 read back exactly");
        assert!(
            r[col("peak_acceleration_m_s2")].len() <= 10,
            "{}",
            r[col("peak_acceleration_m_s2")]
        );
        let g: f64 = r[col("peak_acceleration_g")].parse().unwrap();
        assert!((g * 9.80665 / peaks[k] - 1.0).abs() < 1e-6);
    }
}

/// A folder gives its recordings by name (other files and hidden ones left out); a quoted
/// pattern its matches; a failing recording is named and the others still reported.
#[test]
fn folders_and_patterns_expand_and_a_failure_is_named() {
    let folder = Scratch::new();
    let d = folder.path();
    let seed = common::synth_t2();
    for name in ["b.csv", "a.csv"] {
        std::fs::write(d.join(name), &seed).unwrap();
    }
    std::fs::write(d.join("notes.txt"), "not a recording").unwrap();
    std::fs::write(d.join(".hidden.csv"), "not one either").unwrap();
    let s = |p: &Path| p.to_string_lossy().into_owned();
    let files = |out: &str| -> Vec<String> {
        json(out)["entries"]
            .as_array()
            .unwrap()
            .iter()
            .map(|e| {
                e["file"]
                    .as_str()
                    .unwrap()
                    .rsplit('/')
                    .next()
                    .unwrap()
                    .to_string()
            })
            .collect()
    };
    let kin = ["--mass", "0.06", "--v0", "1.3357", "--json"];
    let mut args = vec!["analyze".to_string(), s(d)];
    args.extend(kin.iter().map(|a| a.to_string()));
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let (out, _) = impact_ok(&args);
    assert_eq!(files(&out), ["a.csv", "b.csv"]);
    let pattern = s(&d.join("?.csv"));
    let mut args = vec!["analyze", &pattern];
    args.extend(kin);
    let (out, _) = impact_ok(&args);
    assert_eq!(files(&out), ["a.csv", "b.csv"]);
    let series = json(&out);
    let cor = series["statistics"]
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["metric"] == "cor")
        .unwrap()
        .clone();
    assert_eq!(cor["n"], 2);
    assert_eq!(cor["sd"], 0.0, "the same recording twice");

    // One bad recording among good ones: reported, named, exit 1.
    let bad = d.join("bad.csv");
    std::fs::write(&bad, "time_s,accel_g\n").unwrap();
    let a = s(&d.join("a.csv"));
    let bad = s(&bad);
    let mut args = vec!["analyze", &a, &bad];
    args.extend(kin);
    let (code, out, err) = impact(&args);
    assert_eq!(code, 1, "{err}");
    let series = json(&out);
    assert_eq!(
        (series["recordings"].as_u64(), series["failed"].as_u64()),
        (Some(2), Some(1))
    );
    assert_eq!(series["entries"][0]["impacts"].as_array().unwrap().len(), 1);
    assert!(
        series["entries"][1]["error"]
            .as_str()
            .unwrap()
            .contains("no data rows"),
        "{out}"
    );
    assert!(
        err.contains(&format!("1 of 2 recordings failed: {bad}: ")),
        "{err}"
    );

    // Nothing to analyse, standard input, a figure of many: refused before any work.
    let nothing = Scratch::new();
    let empty = nothing.path();
    for (args, want) in [
        (
            vec!["analyze".to_string(), s(empty)],
            "a folder with no recordings",
        ),
        (
            vec!["analyze".into(), s(&empty.join("*.csv"))],
            "no file matches",
        ),
        (
            vec!["analyze".into(), a.clone(), "-".into()],
            "standard input (-) can be one recording only",
        ),
        (
            vec![
                "analyze".into(),
                a.clone(),
                a.clone(),
                "--plot".into(),
                s(&d.join("x.svg")),
            ],
            "--plot draws one recording",
        ),
    ] {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let (code, _, err) = impact(&args);
        common::assert_refused(Some(code), &err, want, &args.join(" "));
    }
    assert!(!d.join("x.svg").exists());
}

/// A quoted `**` pattern over folders with links to a parent (a loop) and to a sibling: each
/// recording is one entry, each folder entered once (a loop gave one file 41 entries, counted
/// as 41 drops, and two loops made the walk exponential).
#[test]
fn a_pattern_through_linked_folders_counts_each_recording_once() {
    let scratch = Scratch::new();
    let lp = scratch.path().join("lp");
    std::fs::create_dir_all(lp.join("day1/run")).unwrap();
    std::fs::create_dir_all(lp.join("day2")).unwrap();
    let seed = common::synth_t2();
    std::fs::write(lp.join("day1/run/a.csv"), &seed).unwrap();
    std::fs::write(lp.join("day2/b.csv"), &seed).unwrap();
    for (link, to) in [
        ("day1/run/up", "../.."),
        ("day1/run/up2", ".."),
        ("day2/back", "../day1"),
        ("day2/again", "."),
    ] {
        std::os::unix::fs::symlink(to, lp.join(link)).unwrap();
    }
    let pattern = format!("{}/**/*.csv", lp.display());
    let (out, _) = impact_ok(&[
        "analyze", &pattern, "--mass", "0.06", "--v0", "1.3357", "--json",
    ]);
    let series = json(&out);
    let files: Vec<&str> = series["entries"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["file"].as_str().unwrap())
        .collect();
    let want = [
        lp.join("day1/run/a.csv").display().to_string(),
        lp.join("day2/b.csv").display().to_string(),
    ];
    assert_eq!(files, want, "{out}");
    assert_eq!(series["recordings"], 2, "{out}");
}

/// The statistics compare like with like: a clipped pulse (peak and Δv lower bounds) and one
/// the recording cuts (`stream-ended`) are left out and counted by why, in the JSON, the
/// table and the report; the two complete ones are the statistics' n.
#[test]
fn statistics_leave_out_clipped_and_cut_pulses_and_count_them() {
    let scratch = Scratch::new();
    // A 5 ms half-sine of `peak` g at 10 kS/s from 0.2 s, over `len` s, tops held at `rail`.
    let pulse = |name: &str, peak: f64, rail: f64, len: f64| {
        let mut text = String::from("time_s,accel_g\n");
        for k in 0..(len * 1e4) as usize {
            let t = k as f64 / 1e4;
            let tt = t - 0.2;
            let a = if (0.0..0.005).contains(&tt) {
                peak * (std::f64::consts::PI * tt / 0.005).sin()
            } else {
                0.0
            };
            text.push_str(&format!("{t:.4},{:.4}\n", a.min(rail)));
        }
        scratch.file(name, text)
    };
    let files = [
        pulse("a.csv", 50.0, f64::INFINITY, 0.5),
        pulse("b.csv", 52.0, f64::INFINITY, 0.5),
        pulse("clipped.csv", 80.0, 60.0, 0.5),
        // Ends 1 ms after the pulse: cut before its hold.
        pulse("cut.csv", 51.0, f64::INFINITY, 0.206),
    ];
    let mut args = vec!["analyze"];
    args.extend(files.iter().map(|f| f.to_str().unwrap()));
    let (table, _) = impact_ok(&args);
    assert!(
        table.contains(
            "statistics over the 2 comparable impacts (complete, unclipped, each drop's first); left out: 1 incomplete, 1 clipped"
        ),
        "{table}"
    );
    args.push("--json");
    let (json, _) = impact_ok(&args);
    let j: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(
        j["statistics_left_out"],
        serde_json::json!({"incomplete": 1, "clipped": 1, "later_bounces": 0})
    );
    let peak = j["statistics"]
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["metric"] == "peak_acceleration_g")
        .unwrap();
    assert_eq!(peak["n"], 2, "{peak}");
    assert!(
        (peak["mean"].as_f64().unwrap() - 51.0).abs() < 0.01,
        "{peak}"
    );
}

/// A series of drops that bounce: the statistics compare each drop's first impact, and the
/// later bounces bounce by bounce (bounce 1 of every drop, bounce 2, …), never averaged
/// together (their peaks fall from bounce to bounce).
#[test]
fn bounces_are_compared_bounce_by_bounce() {
    let scratch = Scratch::new();
    let mut files = Vec::new();
    for (name, v0) in [("a.csv", "1.3357"), ("b.csv", "1.30")] {
        let path = scratch.join(name);
        impact_ok(&[
            "synth",
            "--model",
            "nonlinear",
            "--mass",
            "0.06",
            "--v0",
            v0,
            "--stiffness",
            "1e4",
            "--damping",
            "0.5",
            "--bounces",
            "4",
            "--duration",
            "1.5",
            "-o",
            path.to_str().unwrap(),
        ]);
        files.push(path.to_str().unwrap().to_string());
    }
    let mut args = vec!["analyze"];
    args.extend(files.iter().map(String::as_str));
    args.extend(["--mass", "0.06", "--v0", "1.3357", "--train", "flight"]);
    let (table, _) = impact_ok(&args);
    args.push("--json");
    let (out, _) = impact_ok(&args);
    let j: serde_json::Value = serde_json::from_str(&out).unwrap();
    let n_of = |stats: &serde_json::Value, metric: &str| {
        stats
            .as_array()
            .unwrap()
            .iter()
            .find(|s| s["metric"] == metric)
            .unwrap()["n"]
            .as_u64()
            .unwrap()
    };
    // The drops' first impacts.
    assert_eq!(
        n_of(&j["statistics"], "peak_acceleration_m_s2"),
        2,
        "{}",
        j["statistics"]
    );
    let groups = j["bounce_statistics"].as_array().unwrap();
    assert!(groups.len() >= 3, "{groups:?}");
    let mut last_peak = f64::INFINITY;
    for (k, g) in groups.iter().enumerate() {
        assert_eq!(g["bounce_number"], k as u64 + 1);
        assert_eq!(n_of(&g["statistics"], "peak_acceleration_m_s2"), 2, "{g}");
        let mean = g["statistics"]
            .as_array()
            .unwrap()
            .iter()
            .find(|s| s["metric"] == "peak_acceleration_m_s2")
            .unwrap()["mean"]
            .as_f64()
            .unwrap();
        assert!(
            mean < last_peak,
            "bounce {}: {mean} after {last_peak}",
            k + 1
        );
        last_peak = mean;
    }
    assert!(
        table.contains("statistics of bounce 1 (each drop's, complete and unclipped)"),
        "{table}"
    );
    assert!(
        table.contains("later bounces of a drop (compared bounce by bounce below)"),
        "{table}"
    );
}

/// A 50 kS/s recording in g of a 6 ms half-sine of `peak` g at 50 ms (and 1 mg of ripple).
fn half_sine_file(scratch: &Scratch, name: &str, peak: f64) -> String {
    let mut csv = String::from("time_s,accel_g\n");
    for k in 0..10_000u32 {
        let t = f64::from(k) / 50_000.0 - 0.05;
        let p = if (0.0..0.006).contains(&t) {
            peak * (std::f64::consts::PI * t / 0.006).sin()
        } else {
            0.0
        };
        csv.push_str(&format!(
            "{:.6},{:.5}\n",
            t + 0.05,
            p + 0.001 * f64::from(k % 7)
        ));
    }
    scratch.text(name, &csv)
}

/// `--direction`: a series' recordings grouped by shock direction, from the file name (its
/// pattern's group), the channel, or the report's `--meta direction=`; each direction's
/// verdicts and statistics; a recording with none named in a note and grouped last.
#[test]
fn a_series_is_judged_and_compared_direction_by_direction() {
    let scratch = Scratch::new();
    let files = [
        half_sine_file(&scratch, "shock_+Z_1.csv", 50.0),
        half_sine_file(&scratch, "shock_-Z_1.csv", 65.0),
        half_sine_file(&scratch, "shock_+Z_2.csv", 52.0),
        half_sine_file(&scratch, "other.csv", 50.0),
    ];
    let mut args: Vec<&str> = vec!["analyze"];
    args.extend(files.iter().map(String::as_str));
    args.extend([
        "--spec",
        "half-sine,50g,6ms",
        "--direction",
        "name:_([+-][XYZ])_",
    ]);
    let (code, out, err) = impact(&[args.as_slice(), &["--json"]].concat());
    assert_eq!(code, 3, "-Z's 65 g fails: {err}");
    assert!(
        err.contains("other.csv: no direction (--direction name:_([+-][XYZ])_)"),
        "{err}"
    );
    let s = json(&out);
    let groups = s["direction_statistics"].as_array().unwrap();
    let summary: Vec<(serde_json::Value, u64, u64, u64)> = groups
        .iter()
        .map(|g| {
            (
                g["direction"].clone(),
                g["recordings"].as_u64().unwrap(),
                g["spec"]["judged"].as_u64().unwrap(),
                g["spec"]["passed"].as_u64().unwrap(),
            )
        })
        .collect();
    assert_eq!(
        summary,
        [
            ("+Z".into(), 2, 2, 2),
            ("-Z".into(), 1, 1, 0),
            (serde_json::Value::Null, 1, 1, 1)
        ]
    );
    let peak = |g: &serde_json::Value| {
        g["statistics"]
            .as_array()
            .unwrap()
            .iter()
            .find(|m| m["metric"] == "peak_acceleration_g")
            .unwrap()["mean"]
            .as_f64()
            .unwrap()
    };
    assert!((peak(&groups[0]) - 51.0).abs() < 0.05, "{}", groups[0]);
    assert_eq!(s["entries"][1]["direction"], "-Z");
    assert!(s["entries"][3].get("direction").is_none());
    // The table's section and the CSV's column.
    let (_, table, _) = impact(&args);
    assert!(
        table.contains("direction +Z: 2 recordings, 2 impacts; spec: 2 of 2 judged impacts pass"),
        "{table}"
    );
    let (_, csv, _) = impact(&[args.as_slice(), &["--csv"]].concat());
    let mut lines = csv.lines();
    assert!(lines
        .next()
        .unwrap()
        .starts_with("file,channel,direction,index,"));
    assert!(lines.next().unwrap().contains(",'+Z,"), "{csv}");
    // The channel as the direction: a series over channels.
    let (out, _) = impact_ok(&[
        "analyze",
        &data("afrl-drop-tower/accel_5.csv"),
        "--channels",
        "1,2",
        "--units",
        "kgn",
        "--direction",
        "channel",
        "--json",
    ]);
    let s = json(&out);
    let d: Vec<&str> = s["direction_statistics"]
        .as_array()
        .unwrap()
        .iter()
        .map(|g| g["direction"].as_str().unwrap())
        .collect();
    assert_eq!(d, ["1", "2"]);
    // The report: a fixed direction from its title block, and the page's section.
    let html = scratch.join_str("r.html");
    let (code, _, err) = impact(&[
        "report",
        &files[0],
        &files[2],
        "--spec",
        "half-sine,50g,6ms",
        "--meta",
        "direction=+Z",
        "--html",
        &html,
    ]);
    assert_eq!(code, 0, "{err}");
    let page = std::fs::read_to_string(&html).unwrap();
    assert!(page.contains("<h2>By direction</h2>"), "{page}");
    assert!(page.contains("impact 0 (direction +Z)"));
    // A pattern that is none is a usage error.
    let (code, _, err) = impact(&["analyze", &files[0], "--direction", "name:("]);
    assert_eq!(code, 2, "{err}");
}
