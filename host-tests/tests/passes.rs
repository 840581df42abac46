//! `impact analyze` on a regular file or standard input reads it in passes (a survey of the
//! whole recording, a second one if glitches were removed, then the analysis) in memory that
//! does not grow with its length; a CSV's or standard input's values are kept from the first
//! pass in a temporary file. The reports equal the whole-file path's (`IMPACT_READ_WHOLE`, as
//! `--axes` or `--resample` read it) for every format, with glitches, flat tops and the levels
//! learned from the recording.

use std::io::Write;
use std::path::PathBuf;
use std::process::{Command, Stdio};

mod common;
use common::{impact_ok, Scratch};

fn fixture(name: &str) -> String {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures")
        .join(name)
        .to_string_lossy()
        .into_owned()
}

/// `impact ARGS` read whole (`IMPACT_READ_WHOLE`): (exit code, stdout, stderr).
fn whole(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_impact"))
        .args(args)
        .env("IMPACT_READ_WHOLE", "1")
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// `impact analyze FILE ARGS --json` read in passes, and read whole.
fn passes_and_whole(file: &str, args: &[&str]) -> (String, String) {
    let mut v = vec!["analyze", file, "--json"];
    v.extend_from_slice(args);
    let (code, out, err) = whole(&v);
    assert_eq!(code, 0, "{v:?}: {err}");
    (impact_ok(&v).0, out)
}

/// `impact analyze - ARGS --json` with `bytes` on standard input.
fn from_stdin(bytes: Vec<u8>, args: &[&str]) -> String {
    let mut child = Command::new(env!("CARGO_BIN_EXE_impact"))
        .args(["analyze", "-", "--json"])
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let writer = std::thread::spawn(move || stdin.write_all(&bytes).unwrap());
    let out = child.wait_with_output().unwrap();
    writer.join().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

#[test]
fn every_format_gives_the_whole_files_reports_in_passes() {
    let cases: [(String, Vec<&str>); 8] = [
        (
            fixture("afrl-test1-int16.wav"),
            vec!["--column", "1", "--gain", "0.001"],
        ),
        (fixture("afrl-test1-float32.wav"), vec![]),
        (
            fixture("afrl-test1-int16.npy"),
            vec!["--rate", "1e6", "--column", "0", "--gain", "0.001"],
        ),
        (
            fixture("afrl-test1-float32-fortran.npy"),
            vec!["--rate", "1e6", "--column", "1"],
        ),
        (
            fixture("afrl-test1-2ch.i16"),
            vec!["--rate", "1e6", "--raw-channels", "2", "--column", "1"],
        ),
        (fixture("afrl-test1.f32"), vec!["--rate", "1e6"]),
        (
            fixture("afrl-test1.tdms"),
            vec!["--column", "afrl/bottom_kgn"],
        ),
        (
            PathBuf::from(env!("CARGO_MANIFEST_DIR"))
                .join("data/afrl-drop-tower/series1_test1_full_100ms.csv")
                .to_string_lossy()
                .into_owned(),
            vec!["--units", "kgn"],
        ),
    ];
    for (file, args) in &cases {
        let (passes, whole) = passes_and_whole(file, args);
        assert_eq!(passes, whole, "{file}");
        let v: serde_json::Value = serde_json::from_str(&passes).unwrap();
        assert!(!v["impacts"].as_array().unwrap().is_empty(), "{file}: {v}");
    }
}

/// Three 2 ms half-sine impacts of 50 g at 100 kS/s (200 000 rows: past the head, the
/// parallel reader's) on ±1 count (0.01 g) of noise, in g,
/// with glitches of one and two samples far above them and, if `clip_g` is given, the
/// impacts' tops clipped flat there.
fn glitched_csv(clip_g: Option<f64>) -> String {
    let mut out = String::from("time_s,accel_g\n");
    for k in 0..200_000u32 {
        let t = f64::from(k) * 1e-5;
        let noise = f64::from((k.wrapping_mul(2_654_435_761) >> 30) as i32 - 1) * 0.01;
        let mut v = noise;
        for at in [0.1, 0.4, 1.5] {
            if (at..at + 0.002).contains(&t) {
                v += 50.0 * (std::f64::consts::PI * (t - at) / 0.002).sin();
            }
        }
        if let Some(c) = clip_g {
            v = v.min(c);
        }
        let v = match k {
            20_000 => 4000.0,
            130_000 => -3000.0,
            130_001 => -2500.0,
            _ => (v * 100.0).round() / 100.0,
        };
        out.push_str(&format!("{t:.5},{v}\n"));
    }
    out
}

#[test]
fn glitches_flat_tops_and_learned_levels_give_the_whole_files_reports_in_passes() {
    let scratch = Scratch::new();
    for clip in [None, Some(30.0)] {
        let csv = glitched_csv(clip);
        let file = scratch.text(&format!("glitched-{}.csv", clip.is_some()), &csv);
        for args in [
            vec!["--mass", "0.06", "--v0", "1.3357"],
            vec!["--mass", "0.06", "--keep-spikes"],
            vec![
                "--mass", "0.06", "--v0", "1", "--srs", "--cfc", "1000", "--train", "flight",
            ],
            vec![],
            vec!["--range", "200g", "--trigger", "5"],
        ] {
            let (passes, whole) = passes_and_whole(&file, &args);
            assert_eq!(passes, whole, "clip {clip:?}, {args:?}");
            assert_eq!(
                from_stdin(csv.clone().into_bytes(), &args),
                whole,
                "stdin, clip {clip:?}, {args:?}"
            );
            let v: serde_json::Value = serde_json::from_str(&passes).unwrap();
            let spikes = v["spikes_removed"].as_array().map_or(0, Vec::len);
            let keep = args.contains(&"--keep-spikes");
            assert_eq!(spikes, if keep { 0 } else { 2 }, "{args:?}: {v}");
            // (A kept glitch is the recording's maximum: no flat top there.)
            if clip.is_some() && !keep && !args.contains(&"--range") {
                assert_eq!(v["clipping"]["from"], "flat-top", "{args:?}: {v}");
            }
        }
    }
}

/// A hand-over from the parallel reader to the row-by-row one right after the head (every
/// field quoted) reads on to the end.
#[test]
fn quoted_rows_past_the_head_are_all_read() {
    let scratch = Scratch::new();
    let mut csv = String::from("time_s,accel_g\n");
    for k in 0..100_000u32 {
        let v = if (50_000..50_200).contains(&k) {
            40.0 * (std::f64::consts::PI * f64::from(k - 50_000) / 200.0).sin()
        } else {
            f64::from(k % 3) * 0.01
        };
        csv.push_str(&format!("\"{:.5}\",\"{v:.4}\"\n", f64::from(k) * 1e-5));
    }
    let file = scratch.text("quoted.csv", &csv);
    let (passes, whole) = passes_and_whole(&file, &[]);
    assert_eq!(passes, whole);
    assert_eq!(from_stdin(csv.into_bytes(), &[]), whole);
    let v: serde_json::Value = serde_json::from_str(&passes).unwrap();
    assert_eq!(v["samples"], 100_000);
    assert_eq!(v["impacts"].as_array().unwrap().len(), 1, "{v}");
}

#[test]
fn a_file_too_long_to_hold_whole_is_analysed_in_passes_in_bounded_memory() {
    let scratch = Scratch::new();
    // 2^26 samples of raw i16 (128 MB; read whole, some 2.7 GB): one 2 ms impact every
    // 2^21 samples on ±1 count of noise, and one glitch far above them all.
    const PERIOD: usize = 1 << 21;
    const PERIODS: usize = 32;
    let pattern = common::impact_period(PERIOD, 0);
    let file = scratch.join_str("long.i16");
    {
        let mut f = std::io::BufWriter::new(std::fs::File::create(&file).unwrap());
        for p in 0..PERIODS {
            let mut chunk = pattern.clone();
            if p == 7 {
                chunk[200..202].copy_from_slice(&30000i16.to_le_bytes());
            }
            f.write_all(&chunk).unwrap();
        }
    }
    let out = Command::new(env!("CARGO_BIN_EXE_impact"))
        .args([
            "analyze", &file, "--rate", "500000", "--gain", "0.390625", "--units", "m/s2", "--json",
        ])
        // The child's own peak memory (VmHWM) on stderr.
        .env("IMPACT_PEAK_MEMORY", "1")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["impacts"].as_array().unwrap().len(), PERIODS, "{err}");
    assert_eq!(
        v["spikes_removed"][0]["sample"],
        7 * PERIOD + 100,
        "{}",
        v["spikes_removed"]
    );
    assert_eq!(v["spikes_removed"].as_array().unwrap().len(), 1);
    let peak_mib = common::peak_memory_mib(&err);
    eprintln!("2^26 samples in passes, peak memory {peak_mib:.1} MiB");
    assert!(peak_mib < 64.0, "peak memory {peak_mib:.1} MiB");
    // The same samples on standard input (read once, the values kept in a temporary file
    // for the later passes): the same reports, in bounded memory.
    let piped = Command::new(env!("CARGO_BIN_EXE_impact"))
        .args([
            "analyze",
            "-",
            "--raw-type",
            "i16",
            "--rate",
            "500000",
            "--gain",
            "0.390625",
            "--units",
            "m/s2",
            "--json",
        ])
        .env("IMPACT_PEAK_MEMORY", "1")
        .env("TMPDIR", env!("CARGO_TARGET_TMPDIR"))
        .stdin(std::fs::File::open(&file).unwrap())
        .output()
        .unwrap();
    let _ = std::fs::remove_file(&file);
    let err = String::from_utf8_lossy(&piped.stderr);
    assert!(piped.status.success(), "{err}");
    assert_eq!(piped.stdout, out.stdout);
    let peak_mib = common::peak_memory_mib(&err);
    eprintln!("2^26 samples from standard input, peak memory {peak_mib:.1} MiB");
    assert!(peak_mib < 64.0, "peak memory {peak_mib:.1} MiB");
}

/// Without a temporary directory to keep the first pass's values in, or room there, a CSV
/// file is read again for the later passes (the same reports, and a note), and standard
/// input, which cannot be, is a one-line error that names the directory.
#[test]
fn without_a_temporary_file_a_file_is_read_again_and_stdin_is_refused() {
    let scratch = Scratch::new();
    let csv = glitched_csv(None);
    let file = scratch.text("no-spool.csv", &csv);
    let missing = scratch.join_str("no-such-directory");
    let run = |tmpdir: &str, input: &str| {
        Command::new(env!("CARGO_BIN_EXE_impact"))
            .args(["analyze", input, "--json", "--mass", "0.06"])
            .env("TMPDIR", tmpdir)
            .stdin(std::fs::File::open(&file).unwrap())
            .output()
            .unwrap()
    };
    let spooled = run(env!("CARGO_TARGET_TMPDIR"), &file);
    let again = run(&missing, &file);
    assert!(spooled.status.success() && again.status.success());
    assert_eq!(again.stdout, spooled.stdout);
    assert_eq!(run(env!("CARGO_TARGET_TMPDIR"), "-").stdout, spooled.stdout);
    let refused = run(&missing, "-");
    let err = String::from_utf8_lossy(&refused.stderr);
    assert!(!refused.status.success());
    assert!(
        err.starts_with("error: stdin: ") && err.contains(&missing),
        "{err}"
    );
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    // A spool that cannot grow past 64 KiB (a full disk): the file is read again, standard
    // input refused.
    let capped = |input: &str| {
        use std::os::unix::process::CommandExt;
        let mut command = Command::new(env!("CARGO_BIN_EXE_impact"));
        command
            .args(["analyze", input, "--json", "--mass", "0.06"])
            .env("TMPDIR", env!("CARGO_TARGET_TMPDIR"))
            .stdin(std::fs::File::open(&file).unwrap());
        // SAFETY: only async-signal-safe calls between fork and exec.
        unsafe {
            command.pre_exec(|| {
                libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
                let limit = libc::rlimit {
                    rlim_cur: 1 << 16,
                    rlim_max: 1 << 16,
                };
                libc::setrlimit(libc::RLIMIT_FSIZE, &limit);
                Ok(())
            });
        }
        command.output().unwrap()
    };
    assert!(csv.len() > 8 << 16, "the spool outgrows the cap");
    let again = capped(&file);
    let err = String::from_utf8_lossy(&again.stderr);
    assert!(again.status.success(), "{err}");
    assert_eq!(again.stdout, spooled.stdout);
    assert!(err.contains("is read again"), "{err}");
    let refused = capped("-");
    let err = String::from_utf8_lossy(&refused.stderr);
    assert!(!refused.status.success());
    assert!(err.starts_with("error: stdin: the spool in "), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
}

/// A CSV's time errors read the same in passes (from the file and from standard input), whole
/// and `--stream`: a value that is not a number first, then time going back, then an uneven
/// interval (the first of each), every interval against the first intervals' median.
#[test]
fn time_axis_errors_read_the_same_on_every_path() {
    let scratch = Scratch::new();
    let csv = |rows: usize, time: &dyn Fn(usize) -> f64, bad: Option<usize>| {
        let mut s = String::from("time_s,accel_g\n");
        for k in 0..rows {
            let v = if Some(k) == bad {
                "x".to_string()
            } else {
                format!("{:.2}", (k % 3) as f64 * 0.01)
            };
            s.push_str(&format!("{:.7},{v}\n", time(k)));
        }
        s
    };
    // 65 536 intervals of 10 µs, then 16 µs: uneven against the first intervals' median (the
    // median of all of them would pass it).
    let drift = |k: usize| {
        if k <= 65_536 {
            k as f64 * 1e-5
        } else {
            0.65536 + (k - 65_536) as f64 * 1.6e-5
        }
    };
    let back = |k: usize| {
        let t = k as f64 * 1e-5;
        match k {
            100_000 => t + 1.0, // a gap: uneven
            150_000 => t - 0.5, // back in time
            _ if k > 100_000 => t + 1.0,
            _ => t,
        }
    };
    let even = |k: usize| k as f64 * 1e-5;
    // Time going back in the first rows (no rate to be had from them), a text value late.
    let early = |k: usize| if k == 0 { 70_000.0 } else { k as f64 };
    let stuck = |_: usize| 0.0;
    let cases: [(&str, String, &str); 6] = [
        (
            "drift",
            csv(200_000, &drift, None),
            ":65539: uneven time axis",
        ),
        ("back", csv(200_000, &back, None), ":150002: time"),
        ("text", csv(200_000, &back, Some(180_000)), ":180002:"),
        ("text-even", csv(100_000, &even, Some(90_000)), ":90002:"),
        ("early", csv(70_000, &early, Some(69_000)), ":69002:"),
        (
            "stuck",
            csv(70_000, &stuck, None),
            ":3: time 0 s does not increase",
        ),
    ];
    for (name, text, want) in cases {
        let file = scratch.text(&format!("{name}.csv"), &text);
        let passes = common::impact(&["analyze", &file]);
        let whole = whole(&["analyze", &file]);
        let stream = common::impact(&[
            "analyze",
            &file,
            "--stream",
            "--range",
            "10g",
            "--trigger",
            "1",
        ]);
        let out = Command::new(env!("CARGO_BIN_EXE_impact"))
            .args(["analyze", "-"])
            .stdin(std::fs::File::open(&file).unwrap())
            .output()
            .unwrap();
        let stdin = String::from_utf8_lossy(&out.stderr).replace("stdin", &file);
        assert!(
            passes.0 != 0 && passes.2.contains(want),
            "{name}: {}",
            passes.2
        );
        assert_eq!(passes.2.trim().lines().count(), 1, "{name}: {}", passes.2);
        assert_eq!(whole.2, passes.2, "{name}: whole");
        assert_eq!(stdin, passes.2, "{name}: stdin");
        if name == "early" {
            // A stream needs the rate after its first rows: it stops at the time going back.
            assert!(
                stream.2.contains(":3: time 1 s does not increase"),
                "{}",
                stream.2
            );
        } else {
            assert_eq!(stream.2, passes.2, "{name}: --stream");
        }
    }
    // With --rate the time column gives only the first time (its drift is not checked).
    let file = scratch.join_str("drift-rate.csv");
    let text = csv(200_000, &drift, None);
    std::fs::write(&file, &text).unwrap();
    let rate = ["--rate", "100000", "--time-column", "time_s"];
    let passes = impact_ok(&[&["analyze", &file, "--json"][..], &rate].concat()).0;
    assert_eq!(passes, from_stdin(text.into_bytes(), &rate));
}
