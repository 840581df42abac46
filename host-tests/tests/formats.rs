//! Recordings in other formats than CSV give the same reports as their CSV twins: the WAV
//! and `.npy` fixtures of `scripts/make_format_fixtures.py` (CPython's `wave`, scipy, numpy),
//! against CSV files made here from the same rows of the bundled AFRL record; malformed
//! files are one-line errors naming the file (and the frame).

mod common;

use std::path::PathBuf;

use common::{assert_refused_file, impact, impact_ok, Scratch};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Rows 5000..25000 of AFRL test 1 (the WAV fixtures' source): (bottom, top) in kg_n.
fn source_rows() -> Vec<(f64, f64)> {
    rows(5000, 20_000)
}

/// `count` rows of AFRL test 1 from `first`: (bottom, top) in kg_n.
fn rows(first: usize, count: usize) -> Vec<(f64, f64)> {
    let text =
        std::fs::read_to_string(root().join("data/afrl-drop-tower/series1_test1_full_100ms.csv"))
            .unwrap();
    text.lines()
        .skip(1 + first)
        .take(count)
        .map(|l| {
            let mut f = l.split(',').skip(1).map(|v| v.parse::<f64>().unwrap());
            (f.next().unwrap(), f.next().unwrap())
        })
        .collect()
}

/// A CSV of `values` at 1 MS/s from t = 0.
fn twin(scratch: &Scratch, name: &str, values: impl Iterator<Item = String>) -> PathBuf {
    let mut text = String::from("time_s,value\n");
    for (k, v) in values.enumerate() {
        text.push_str(&format!("{:.6},{v}\n", k as f64 * 1e-6));
    }
    scratch.file(name, text)
}

fn json(file: &std::path::Path, extra: &[&str]) -> String {
    let mut args = vec![
        "analyze",
        file.to_str().unwrap(),
        "--units",
        "kgn",
        "--json",
    ];
    args.extend_from_slice(extra);
    impact_ok(&args).0
}

#[test]
fn integer_wav_channels_give_their_csv_twins_reports() {
    let scratch = Scratch::new();
    let wav = root().join("fixtures/afrl-test1-int16.wav");
    let rows = source_rows();
    // The codes the fixture holds: round half to even of kg_n × 1000 (Python's round).
    let code = |v: f64| ((v * 1000.0).round_ties_even() as i64).to_string();
    for (channel, pick) in [(0, 0usize), (1, 1)] {
        let csv = twin(
            &scratch,
            &format!("int16-{channel}.csv"),
            rows.iter().map(|r| code(if pick == 0 { r.0 } else { r.1 })),
        );
        let ch = channel.to_string();
        let from_wav = json(&wav, &["--column", &ch, "--gain", "0.001"]);
        let from_csv = json(&csv, &["--gain", "0.001"]);
        assert_eq!(from_wav, from_csv, "channel {channel}");
        let v: serde_json::Value = serde_json::from_str(&from_wav).unwrap();
        assert_eq!(v["samples"], 20_000);
        assert!(!v["impacts"].as_array().unwrap().is_empty());
    }
}

#[test]
fn float_wav_gives_its_csv_twins_report() {
    let scratch = Scratch::new();
    let wav = root().join("fixtures/afrl-test1-float32.wav");
    // The fixture's float32 values exactly (as f64 decimals that give them back).
    let csv = twin(
        &scratch,
        "float32.csv",
        source_rows()
            .iter()
            .map(|r| format!("{}", r.0 as f32 as f64)),
    );
    assert_eq!(json(&wav, &[]), json(&csv, &[]));
}

#[test]
fn malformed_wav_files_are_one_line_errors_naming_file_and_frame() {
    let good = std::fs::read(root().join("fixtures/afrl-test1-int16.wav")).unwrap();
    let scratch = Scratch::new();
    // Cut in the middle of the data: the header announces more frames than the file holds.
    let cut = scratch.file("cut.wav", &good[..good.len() / 2 + 1]);
    let garbage = scratch.file("garbage.wav", b"RIFF\x10\x00\x00\x00WAVEjunkjunkjunk");
    let wav = root().join("fixtures/afrl-test1-int16.wav");
    for (file, extra, want) in [
        (&cut, vec![], "frame"),
        (&garbage, vec![], "WAV"),
        (&wav, vec!["--column", "2"], "--column 2"),
        (&wav, vec!["--column", "z_g"], "--column z_g"),
        (&wav, vec!["--rate", "1000"], "own rate"),
    ] {
        let mut args = vec!["analyze", file.to_str().unwrap()];
        args.extend(extra.iter().copied());
        let (code, _, err) = impact(&args);
        assert_refused_file(Some(code), &err, want, file, &format!("{args:?}"));
    }
}

#[test]
fn npy_arrays_in_either_order_give_their_csv_twins_reports() {
    let scratch = Scratch::new();
    let rows = rows(8000, 10_000);
    let code = |v: f64| ((v * 1000.0).round_ties_even() as i64).to_string();
    let ints = root().join("fixtures/afrl-test1-int16.npy");
    let floats = root().join("fixtures/afrl-test1-float32-fortran.npy");
    for column in [0usize, 1] {
        let pick = |r: &(f64, f64)| if column == 0 { r.0 } else { r.1 };
        let c = column.to_string();
        let csv = twin(
            &scratch,
            &format!("npy-int16-{column}.csv"),
            rows.iter().map(|r| code(pick(r))),
        );
        assert_eq!(
            json(&ints, &["--rate", "1e6", "--column", &c, "--gain", "0.001"]),
            json(&csv, &["--gain", "0.001"]),
            "int16 column {column}"
        );
        let csv = twin(
            &scratch,
            &format!("npy-f32-{column}.csv"),
            rows.iter().map(|r| format!("{}", pick(r) as f32 as f64)),
        );
        assert_eq!(
            json(&floats, &["--rate", "1e6", "--column", &c]),
            json(&csv, &[]),
            "float32 (Fortran order) column {column}"
        );
    }
}

#[test]
fn malformed_npy_files_are_one_line_errors_naming_the_file() {
    let good = std::fs::read(root().join("fixtures/afrl-test1-int16.npy")).unwrap();
    let scratch = Scratch::new();
    let cut = scratch.file("cut.npy", &good[..good.len() / 2]);
    let garbage = scratch.file("garbage.npy", b"\x93NUMPY\x01\x00junk");
    let npy = root().join("fixtures/afrl-test1-int16.npy");
    for (file, extra, want) in [
        (&cut, vec!["--rate", "1e6"], "npy"),
        (&garbage, vec!["--rate", "1e6"], "npy"),
        (&npy, vec![], "--rate"),
        (&npy, vec!["--rate", "1e6", "--column", "2"], "--column 2"),
    ] {
        let mut args = vec!["analyze", file.to_str().unwrap()];
        args.extend(extra.iter().copied());
        let (code, _, err) = impact(&args);
        assert_refused_file(Some(code), &err, want, file, &format!("{args:?}"));
    }
}

#[test]
fn raw_files_give_their_csv_twins_reports() {
    let scratch = Scratch::new();
    let rows = rows(8000, 10_000);
    let code = |v: f64| ((v * 1000.0).round_ties_even() as i64).to_string();
    let ints = root().join("fixtures/afrl-test1-2ch.i16");
    for column in [0usize, 1] {
        let pick = |r: &(f64, f64)| if column == 0 { r.0 } else { r.1 };
        let c = column.to_string();
        let csv = twin(
            &scratch,
            &format!("raw-i16-{column}.csv"),
            rows.iter().map(|r| code(pick(r))),
        );
        assert_eq!(
            json(
                &ints,
                &[
                    "--rate",
                    "1e6",
                    "--raw-channels",
                    "2",
                    "--column",
                    &c,
                    "--gain",
                    "0.001"
                ]
            ),
            json(&csv, &["--gain", "0.001"]),
            "i16 column {column}"
        );
    }
    let csv = twin(
        &scratch,
        "raw-f32.csv",
        rows.iter().map(|r| format!("{}", r.0 as f32 as f64)),
    );
    assert_eq!(
        json(&root().join("fixtures/afrl-test1.f32"), &["--rate", "1e6"]),
        json(&csv, &[])
    );
    // A file that is not whole frames names the byte where the last one starts.
    let good = std::fs::read(&ints).unwrap();
    let cut = scratch.file("cut.i16", &good[..good.len() - 3]);
    let (code, _, err) = impact(&[
        "analyze",
        cut.to_str().unwrap(),
        "--rate",
        "1e6",
        "--raw-channels",
        "2",
    ]);
    assert_ne!(code, 0);
    assert!(
        err.contains("cut.i16") && err.contains("byte 39996"),
        "{err}"
    );
    let (code, _, err) = impact(&["analyze", ints.to_str().unwrap()]);
    assert_ne!(code, 0);
    assert!(err.contains("--rate"), "{err}");
}

#[test]
fn tdms_channels_give_their_csv_twins_reports() {
    let scratch = Scratch::new();
    let rows = rows(8000, 10_000);
    let tdms = root().join("fixtures/afrl-test1.tdms");
    // float64 kg_n at the wf_increment's rate, by its full name.
    let csv = twin(
        &scratch,
        "tdms-bottom.csv",
        rows.iter().map(|r| format!("{}", r.0)),
    );
    assert_eq!(
        json(&tdms, &["--column", "afrl/bottom_kgn"]),
        json(&csv, &[])
    );
    // int16 codes, by the channel's own name.
    let code = |v: f64| ((v * 1000.0).round_ties_even() as i64).to_string();
    let csv = twin(&scratch, "tdms-top.csv", rows.iter().map(|r| code(r.1)));
    assert_eq!(
        json(&tdms, &["--column", "top_codes", "--gain", "0.001"]),
        json(&csv, &["--gain", "0.001"])
    );
    // A missing channel lists the file's; a file cut short is one line naming the file.
    let (code, _, err) = impact(&["analyze", tdms.to_str().unwrap(), "--column", "z"]);
    assert_ne!(code, 0);
    assert!(err.contains("afrl/bottom_kgn, afrl/top_codes"), "{err}");
    let good = std::fs::read(&tdms).unwrap();
    let cut = scratch.file("cut.tdms", &good[..good.len() / 3]);
    let (code, _, err) = impact(&["analyze", cut.to_str().unwrap()]);
    assert_ne!(code, 0);
    assert!(
        err.contains("cut.tdms") && err.trim().lines().count() == 1,
        "{err}"
    );
}

/// A TDMS channel whose name names no unit takes NI's `unit_string` property as its header's
/// unit: `g` and `m/s^2` give the kg_n channel's impacts with nothing assumed (read whole and
/// streamed); one without the property is read as g and the assumption said.
#[test]
fn a_tdms_channels_unit_string_is_its_unit() {
    let units = root().join("fixtures/afrl-test1-units.tdms");
    let file = units.to_str().unwrap();
    let reference = impacts_of(&[
        root().join("fixtures/afrl-test1.tdms").to_str().unwrap(),
        "--column",
        "afrl/bottom_kgn",
        "--units",
        "kgn",
    ]);
    let near = |a: &[(f64, f64, f64, bool)], b: &[(f64, f64, f64, bool)]| {
        a.len() == b.len()
            && a.iter().zip(b).all(|(x, y)| {
                (x.0 - y.0).abs() < 1e-9
                    && (x.1 / y.1 - 1.0).abs() < 1e-6
                    && (x.2 - y.2).abs() <= 1e-6 * y.2.abs().max(1.0)
                    && x.3 == y.3
            })
    };
    for (column, head) in [
        ("afrl/bottom", "afrl/bottom (g) in g: "),
        ("afrl/bottom_si", "afrl/bottom_si (m/s^2) in m/s2: "),
    ] {
        let got = impacts_of(&[file, "--column", column]);
        assert!(near(&got, &reference), "{column}: {got:?} vs {reference:?}");
        let (out, err) = impact_ok(&["analyze", file, "--column", column]);
        assert!(out.starts_with(head), "{out}");
        assert!(!err.contains("names no unit"), "{err}");
        let (out, _) = impact_ok(&["analyze", file, "--column", column, "--json"]);
        let j: serde_json::Value = serde_json::from_str(&out).unwrap();
        assert!(j.get("assumptions").is_none(), "{column}: {out}");
        // Streamed, the same units.
        let (out, err) = impact_ok(&[
            "analyze",
            file,
            "--column",
            column,
            "--stream",
            "--range",
            "20000g",
            "--trigger",
            "500g",
        ]);
        assert!(out.starts_with(head), "{column} streamed: {out}");
        assert!(!err.contains("names no unit"), "{err}");
    }
    let (_, err) = impact_ok(&["analyze", file, "--column", "afrl/bare"]);
    assert!(
        err.contains("\"afrl/bare\" names no unit: its values read as g"),
        "{err}"
    );
}

/// The impacts of `impact analyze ARGS --json`: (start, peak, Δv or 0, clipped) each.
fn impacts_of(args: &[&str]) -> Vec<(f64, f64, f64, bool)> {
    let mut all = vec!["analyze"];
    all.extend_from_slice(args);
    all.push("--json");
    let (out, _) = impact_ok(&all);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    v["impacts"]
        .as_array()
        .unwrap()
        .iter()
        .map(|i| {
            (
                i["start_s"].as_f64().unwrap(),
                i["peak_acceleration_m_s2"].as_f64().unwrap(),
                i["delta_v_m_s"].as_f64().unwrap_or(0.0),
                i["clipped"].as_bool().unwrap(),
            )
        })
        .collect()
}

/// An enDAQ `.ide` recording read directly gives the reports of its CSV exports (idelib's,
/// rounded to 5 decimals for the 16 g channel, 4 for the 2000 g one, times to 1 µs): the 16 g
/// DC z axis (seven bounces, the first three clipped), its three axes together (the same and
/// a hit the y axis carries), and the
/// 2000 g piezo's z axis around the impact (the CSV is a 13.4–15.0 s excerpt, so its levels
/// come from less of the recording: the impact, not the numbers, is compared there).
#[test]
fn an_ide_recording_gives_its_csv_exports_reports() {
    let data = root().join("data/endaq-high-drop");
    let ide = data.join("High-Drop.IDE");
    let ide = ide.to_str().unwrap();
    let dc = data.join("High-Drop_16g-DC_full.csv");
    let dc = dc.to_str().unwrap();
    for (from_ide, from_csv, reports) in [
        (
            vec![ide, "--column", "32.2"],
            vec![dc, "--column", "z_g"],
            7,
        ),
        (
            vec![ide, "--axes", "32.0,32.1,32.2"],
            vec![dc, "--axes", "x_g,y_g,z_g"],
            8,
        ),
    ] {
        let (a, b) = (impacts_of(&from_ide), impacts_of(&from_csv));
        assert_eq!(a.len(), reports, "{from_ide:?}: {a:?}");
        assert_eq!(a.len(), b.len(), "{from_ide:?}");
        for (x, y) in a.iter().zip(&b) {
            // (Within 1 % of the 2.56 ms sample interval: the CSV's rounding moves a level
            // measured before a bounce, and with it the extrapolated first touch, by as much.)
            assert!(
                (x.0 - y.0).abs() < 2.6e-5,
                "{from_ide:?}: start {x:?} {y:?}"
            );
            assert!(
                (x.1 - y.1).abs() < 1e-4 * y.1.abs(),
                "{from_ide:?}: peak {x:?} {y:?}"
            );
            assert!(
                (x.2 - y.2).abs() < 1e-4 * y.2.abs().max(1e-3),
                "{from_ide:?}: Δv {x:?} {y:?}"
            );
            assert_eq!(x.3, y.3, "{from_ide:?}: clipped {x:?} {y:?}");
        }
    }
    // The piezo's z axis: the impact at 14.625 s, its peak to 0.1 %.
    let pe = data.join("High-Drop_2000g-PE_13.4-15.0s.csv");
    let whole = impacts_of(&[ide, "--column", "Z (2000g)"]);
    let excerpt = impacts_of(&[pe.to_str().unwrap(), "--column", "z_g"]);
    let hit = |list: &[(f64, f64, f64, bool)]| {
        *list
            .iter()
            .find(|i| (14.62..14.63).contains(&i.0))
            .unwrap_or_else(|| panic!("no impact at 14.625 s: {list:?}"))
    };
    let (w, e) = (hit(&whole), hit(&excerpt));
    assert!((w.0 - e.0).abs() < 1e-4, "{w:?} {e:?}");
    assert!((w.1 - e.1).abs() < 1e-3 * e.1, "{w:?} {e:?}");
}

/// What no reader takes is named as such, and a subchannel that is no acceleration or force
/// is refused naming its units.
#[test]
fn unsupported_files_and_channels_are_named() {
    let scratch = Scratch::new();
    for (name, bytes, want) in [
        ("sheet.xlsx", b"PK\x03\x04rest".to_vec(), "spreadsheet"),
        ("old.xls", vec![0xD0, 0xCF, 0x11, 0xE0, 1, 2], "Excel 97"),
        (
            "data.mat",
            b"MATLAB 5.0 MAT-file, Platform".to_vec(),
            "MATLAB",
        ),
        ("data.h5", b"\x89HDF\r\n\x1a\n".to_vec(), "HDF5"),
        ("blob.bin", vec![1, 0, 2, 0, 3], "binary"),
    ] {
        let path = scratch.file(name, bytes);
        let (code, _, err) = impact(&["analyze", path.to_str().unwrap()]);
        assert_eq!(code, 1, "{name}: {err}");
        assert!(
            err.contains("unsupported format") && err.contains(want),
            "{name}: {err}"
        );
    }
    let ide = root().join("data/endaq-high-drop/High-Drop.IDE");
    let (code, _, err) = impact(&["analyze", ide.to_str().unwrap(), "--column", "36.1"]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("°C") && err.contains("not an acceleration"),
        "{err}"
    );
}

/// A time column whose interval grows smoothly by 45 % (every step a hair longer than the
/// last, far inside the 0.5–1.5× window) is no steady sample clock: taken as an even grid it
/// put the impact 20 ms late with Δv 5 % low, and the whole-file path, the passes and a
/// stream disagreed. All three refuse it at the same line; `--resample` gives the file's own
/// times' answer.
#[test]
fn a_drifting_time_axis_is_refused_alike_everywhere_or_resampled() {
    let scratch = Scratch::new();
    let n = 8000usize;
    let (v0, e, width, touch) = (2.0f64, 0.6, 0.002, 0.3);
    let dv = v0 * (1.0 + e);
    let peak = dv * std::f64::consts::PI / (2.0 * width);
    let mut t = 0.0f64;
    let mut text = String::from("time_s,accel_m_s2\n");
    for k in 0..n {
        let a = if (touch..touch + width).contains(&t) {
            peak * (std::f64::consts::PI * (t - touch) / width).sin()
        } else {
            0.0
        };
        // A deterministic ±0.5 m/s² dither keeps a noise floor.
        let dither = 0.5 * (((k * 7919) % 13) as f64 / 6.0 - 1.0);
        text.push_str(&format!("{t:.9},{:.4}\n", a + dither));
        t += 50e-6 * (1.0 + 0.45 * k as f64 / (n - 2) as f64);
    }
    let path = scratch.file("drifting-time.csv", text);
    let file = path.to_str().unwrap();
    let mut errors = Vec::new();
    // In passes, read whole (as `--axes` reads it), and as a stream.
    for (extra, whole) in [
        (&["--v0", "2"][..], false),
        (&["--v0", "2"][..], true),
        (
            &[
                "--v0",
                "2",
                "--stream",
                "--range",
                "4000",
                "--trigger",
                "200",
            ][..],
            false,
        ),
    ] {
        let mut args = vec!["analyze", file];
        args.extend_from_slice(extra);
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_impact"))
            .args(&args)
            .env(
                if whole {
                    "IMPACT_READ_WHOLE"
                } else {
                    "IMPACT_UNSET"
                },
                "1",
            )
            .output()
            .unwrap();
        let (code, out, err) = (
            out.status.code().unwrap_or(-1),
            String::from_utf8_lossy(&out.stdout).into_owned(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        );
        assert_eq!(code, 1, "{extra:?}: {out}");
        assert!(err.contains("the time axis drifts"), "{extra:?}: {err}");
        errors.push(err);
    }
    assert!(errors.iter().all(|e| *e == errors[0]), "{errors:?}");
    assert!(
        errors[0].contains("drifting-time.csv:2050:"),
        "{}",
        errors[0]
    );
    // Past the head the plain rows are parsed in parallel: a steady clock for 150 000 rows,
    // then one that slows by 5 % over the next 50 000, is refused at the same line everywhere
    // (and the parallel reader's rows are checked as the sequential reader's).
    let mut text = String::from("time_s,accel_m_s2\n");
    let mut t = 0.0f64;
    for k in 0..200_000usize {
        let dither = 0.5 * (((k * 7919) % 13) as f64 / 6.0 - 1.0);
        text.push_str(&format!("{t:.9},{dither:.4}\n"));
        let slow = k.saturating_sub(150_000) as f64 / 50_000.0;
        t += 2e-6 * (1.0 + 0.05 * slow);
    }
    let long = scratch.file("drifting-long.csv", text);
    let long = long.to_str().unwrap();
    let mut errors = Vec::new();
    for extra in [
        &[][..],
        &["--stream", "--range", "100", "--trigger", "10"][..],
    ] {
        let mut args = vec!["analyze", long];
        args.extend_from_slice(extra);
        let (code, out, err) = impact(&args);
        assert_eq!(code, 1, "{extra:?}: {out}");
        assert!(err.contains("the time axis drifts"), "{extra:?}: {err}");
        errors.push(err);
    }
    assert_eq!(errors[0], errors[1]);
    let line: u64 = errors[0]
        .split(':')
        .nth(2)
        .and_then(|l| l.trim().parse().ok())
        .unwrap_or_else(|| panic!("{}", errors[0]));
    // 1 % slower on average over a block of 1024 intervals: about 10 000 rows in.
    assert!((155_000..170_000).contains(&line), "{}", errors[0]);
    let (out, _) = impact_ok(&["analyze", file, "--v0", "2", "--resample", "--json"]);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let i = &v["impacts"][0];
    let start = i["start_s"].as_f64().unwrap();
    assert!((start - touch).abs() < 1e-4, "{start}");
    let got = i["delta_v_m_s"].as_f64().unwrap();
    assert!((got / dv - 1.0).abs() < 0.005, "Δv {got} vs {dv}");
    let cor = i["cor"].as_f64().unwrap();
    assert!((cor - e).abs() < 0.005, "COR {cor} vs {e}");
}

/// A plot never draws what the report refuses: the enDAQ piezo channel's impact has no Δv
/// (`ac-coupled`), so its figure has no velocity, deformation or force loop (it drew a
/// velocity change of -13 m/s), only the deceleration, whose title says why.
#[test]
fn a_plot_draws_no_velocity_the_report_refuses() {
    let pe = root().join("data/endaq-high-drop/High-Drop_2000g-PE_13.4-15.0s.csv");
    let scratch = Scratch::new();
    let svg = scratch.join("piezo.svg");
    let (_, err) = impact_ok(&[
        "analyze",
        pe.to_str().unwrap(),
        "--column",
        "z_g",
        "--plot",
        svg.to_str().unwrap(),
    ]);
    let text = std::fs::read_to_string(&svg).unwrap_or_else(|e| panic!("{e}: {err}"));
    assert!(
        text.contains("Δv unknown: no velocity or deformation"),
        "{err}"
    );
    assert!(!text.contains("velocity change from touch"));
    assert!(!text.contains("deformation, mm") && !text.contains("velocity, m/s"));
}
