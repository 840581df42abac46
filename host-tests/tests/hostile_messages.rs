//! Hostile input, round three: messages that were false or named the wrong option. Each
//! refusal names what was given (the option, the scene file's key, the file's property or
//! line) and what is accepted; a value that would have been lost silently is refused.

use std::path::PathBuf;
use std::process::{Command, Stdio};

mod common;
use common::{assert_refused, impact, Scratch};

/// Read whole (`IMPACT_READ_WHOLE`, as `--axes` or `--resample` read a recording) where the
/// arguments hold this word, in passes elsewhere.
const WHOLE: &str = "(read whole)";

/// `impact ARGS` is refused with a message holding every one of `want` and none of `not`:
/// the message.
fn refused(args: &[&str], want: &[&str], not: &[&str]) -> String {
    let whole = args.contains(&WHOLE);
    let args: Vec<&str> = args.iter().copied().filter(|a| *a != WHOLE).collect();
    let args = args.as_slice();
    let (code, out, err) = if whole {
        let out = Command::new(env!("CARGO_BIN_EXE_impact"))
            .args(args)
            .env("IMPACT_READ_WHOLE", "1")
            .output()
            .expect("runs");
        (
            out.status.code().unwrap_or(-1),
            String::from_utf8_lossy(&out.stdout).into_owned(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    } else {
        impact(args)
    };
    let what = format!("impact {}\n{out}", args.join(" "));
    assert_refused(Some(code), &err, want[0], &what);
    for w in want {
        assert!(err.contains(w), "{what}: wanted {w:?} in {err}");
    }
    for n in not {
        assert!(!err.contains(n), "{what}: {n:?} in {err}");
    }
    err
}

/// `impact analyze - ARGS` with `file` on standard input: (exit code, stderr).
fn analyze_stdin(file: &PathBuf, args: &[&str]) -> (i32, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_impact"))
        .args(["analyze", "-"])
        .args(args)
        .stdin(Stdio::from(std::fs::File::open(file).unwrap()))
        .output()
        .expect("runs");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// The hostile-input issue's `T2` recording (one 55.6 g impact), as a file in the test's own
/// scratch folder (the tests run in parallel: one file rewritten while another test read it
/// made that one flaky).
fn t2(scratch: &Scratch) -> PathBuf {
    scratch.file("t2.csv", common::synth_t2())
}

#[test]
fn values_the_core_cannot_hold_are_out_of_range_not_infinite() {
    let scratch = Scratch::new();
    // Finite and > 0, but beyond the f32 the core takes: each option names its limits.
    let t2 = t2(&scratch);
    let t2 = t2.to_str().unwrap();
    for (args, option, limits) in [
        (
            &["--mass", "1e300"][..],
            "--mass",
            "between 1e-30 and 1e6 kg",
        ),
        (&["--mass", "1e-300"], "--mass", "between 1e-30 and 1e6 kg"),
        (&["--rate", "1e-300"], "--rate", "between 1e-30 and 1e8 Hz"),
        (
            &["--train", "flight", "--gravity", "1e300"],
            "--gravity",
            "between 1e-30 and 1e30 m/s²",
        ),
        (
            &["--train", "flight", "--max-flight", "1e-300"],
            "--max-flight",
            "between 1e-30 and 1e30 s",
        ),
        (&["--hold", "1e-300"], "--hold", "between 1e-30 and 1e30 s"),
        (&["--v0", "1e300"], "--v0", "between 1e-30 and 1e30 m/s"),
        (
            &["--trigger", "1e300"],
            "--trigger 1e300 m/s²",
            "between 1e-30 and 1e30 m/s²",
        ),
        (
            &["--trigger", "1e30g"],
            "--trigger 1e30g (9.807e30 m/s²)",
            "between 1e-30 and 1e30 m/s²",
        ),
        (
            &["--srs", "--srs-low", "1e-300"],
            "--srs-low",
            "between 1e-30 and 1e30 Hz",
        ),
        (
            &["--range", "1e300"],
            "--range 1e300 m/s²",
            "between 1e-30 and 1e30 m/s²",
        ),
        (
            &["--range", "1e-300"],
            "--range 1e-300 m/s²",
            "between 1e-30 and 1e30 m/s²",
        ),
        // Dropped the impact silently: every reading under one count.
        (&["--gain", "1e-40"], "--gain", "between 1e-30 and 1e30"),
    ] {
        let mut all = vec!["analyze", t2];
        all.extend_from_slice(args);
        let err = refused(
            &all,
            &[option, &format!("out of range ({limits}")],
            &["finite", "--gain:", "--clip", "--srs:"],
        );
        assert!(!err.contains("1000000000"), "{err}");
    }
    // The lowest band below the rate's reach names --srs-low, not --srs.
    refused(
        &["analyze", t2, "--srs", "--srs-low", "1e-20"],
        &["--srs-low: no band between it and rate / 8"],
        &["--srs:"],
    );
    // A highest band below the first band at or above the lowest names --srs-high; a
    // spectrum's setting without the spectra names itself and the fix.
    refused(
        &[
            "analyze",
            t2,
            "--srs",
            "--srs-low",
            "100",
            "--srs-high",
            "105",
        ],
        &["--srs-high: below the first band at or above the lowest band"],
        &["--srs:", "--srs-low:"],
    );
    for option in ["--srs-high", "--srs-low", "--srs-damping", "--srs-bands"] {
        let value = if option == "--srs-bands" { "12" } else { "0.1" };
        refused(
            &["analyze", t2, option, value],
            &[&format!(
                "{option}: a shock spectrum's setting without the spectra: add --srs"
            )],
            &[],
        );
    }
    // A recording of zeros with a range of 1e-300 named an option that does not exist.
    let zeros: String = std::iter::once("time_s,accel_g\n".to_string())
        .chain((0..2000).map(|i| format!("{:.6},0\n", i as f64 * 2e-6)))
        .collect();
    let zeros = scratch.file("zeros.csv", zeros.as_bytes());
    refused(
        &["analyze", zeros.to_str().unwrap(), "--range", "1e-300"],
        &["--range 1e-300 m/s²: out of range"],
        &["--clip"],
    );
}

#[test]
fn readings_too_small_or_large_for_the_counts_are_refused_not_lost() {
    let scratch = Scratch::new();
    // Readings of 1e-5 g times --gain 1e-30 are below the smallest full scale: every count
    // would be 0 and the impact lost.
    let tiny: String = std::iter::once("time_s,accel_g\n".to_string())
        .chain((0..2000).map(|i| {
            let v = if (1000..1010).contains(&i) { 1e-5 } else { 0.0 };
            format!("{:.6},{v}\n", i as f64 * 1e-5)
        }))
        .collect();
    let tiny = scratch.file("tiny.csv", tiny.as_bytes());
    let t2 = t2(&scratch);
    for (file, gain) in [(&tiny, "1e-30"), (&t2, "1e30")] {
        refused(
            &["analyze", file.to_str().unwrap(), "--gain", gain],
            &[
                "the recording reaches",
                "out of range (between 1e-30 and 1e30 m/s²)",
                "--gain",
            ],
            &["--gain: must be finite"],
        );
    }
}

#[test]
fn scene_files_are_named_with_their_keys() {
    let scratch = Scratch::new();
    let t2 = t2(&scratch);
    let t2 = t2.to_str().unwrap();
    for (name, json, want) in [
        (
            "hold.json",
            r#"{"hold": 1e-300}"#,
            "hold.json: hold 1e-300: out of range (between 1e-30 and 1e30 s)",
        ),
        (
            "max_impact.json",
            r#"{"max_impact": 1e-9}"#,
            "max_impact.json: max_impact 1e-9: shorter than the hold (at least the default --hold, 0.002 s)",
        ),
        (
            "mass.json",
            r#"{"mass": 1e300}"#,
            "mass.json: mass 1e300: out of range (between 1e-30 and 1e6 kg)",
        ),
        (
            "trigger.json",
            r#"{"trigger": "1e30g"}"#,
            "trigger.json: trigger 1e30g (9.807e30 m/s²): out of range",
        ),
        (
            "edge.json",
            r#"{"edge": "100g", "trigger": "5g"}"#,
            "edge.json: edge 100g (980.7 m/s²): not below the trigger level (below the scene file's trigger 5g, 49.03 m/s²)",
        ),
        (
            "cfc.json",
            r#"{"cfc": 7}"#,
            "cfc.json: cfc: 7 is not one of 60, 180, 600, 1000",
        ),
        (
            "exponent.json",
            r#"{"fits": {"exponent": 7}}"#,
            "exponent.json: fits.exponent 7: out of range (between 1 and 4)",
        ),
    ] {
        let scene = scratch.file(name, json.as_bytes());
        refused(
            &["analyze", t2, "--scene", scene.to_str().unwrap()],
            &[want],
            // (Not blamed on an option.)
            &["error: --"],
        );
    }
    // On the command line the same checks name the options.
    refused(
        &["analyze", t2, "--hold", "5"],
        &["--hold 5: longer than the longest impact (at most the default --max-impact, 1 s)"],
        &[],
    );
    refused(
        &["analyze", t2, "--hold", "0.5", "--settle", "0.1"],
        &["--settle 0.1: shorter than the hold (at least --hold 0.5)"],
        &[],
    );
}

#[test]
fn a_rate_from_a_file_names_the_file_and_its_property() {
    let scratch = Scratch::new();
    let fixtures = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fixtures");
    let mut tdms = std::fs::read(fixtures.join("afrl-test1.tdms")).unwrap();
    // Every wf_increment (a double after its name and type code) 1e300 s.
    let mut at = 0;
    while let Some(p) = tdms[at..].windows(12).position(|w| w == b"wf_increment") {
        let value = at + p + 12 + 4;
        tdms[value..value + 8].copy_from_slice(&1e300f64.to_le_bytes());
        at = value + 8;
    }
    assert!(at > 0, "the fixture has a wf_increment");
    let tdms = scratch.file("increment.tdms", &tdms);
    let tdms = tdms.to_str().unwrap();
    for extra in [
        &[][..],
        &[WHOLE],
        &["--stream", "--range", "16000g", "--trigger", "5g"],
    ] {
        let mut args = vec!["analyze", tdms];
        args.extend_from_slice(extra);
        refused(
            &args,
            &["increment.tdms: afrl/bottom_kgn: wf_increment 1e300: out of range (between 1e-8 and 1e30 s)"],
            &["--rate"],
        );
    }
    // A time column at 1 GS/s (nanoseconds named seconds).
    let fast: String = std::iter::once("time_s,accel_g\n".to_string())
        .chain((0..2000).map(|i| format!("{:.12},0\n", i as f64 * 1e-9)))
        .collect();
    let fast = scratch.file("fast.csv", fast.as_bytes());
    refused(
        &["analyze", fast.to_str().unwrap()],
        &["fast.csv: the time column \"time_s\" gives 1e9 S/s: out of range (between 1e-30 and 1e8 Hz)"],
        &["--rate:"],
    );
}

#[test]
fn a_raw_file_without_a_rate_asks_for_rate_not_stream() {
    let scratch = Scratch::new();
    let zeros = vec![0u8; 4096];
    for name in ["codes.i16", "values.f32"] {
        let raw = scratch.file(name, &zeros);
        let raw = raw.to_str().unwrap();
        for extra in [
            &[][..],
            &[WHOLE],
            &["--stream", "--range", "16g", "--trigger", "5g"],
        ] {
            let mut args = vec!["analyze", raw];
            args.extend_from_slice(extra);
            refused(
                &args,
                &[&format!("{name}: a raw file holds no time: give --rate")],
                &["--stream:"],
            );
        }
        refused(
            &["analyze", raw, "--time-column", "0"],
            &[&format!(
                "{name}: a raw file takes --rate, --raw-channels and --column only"
            )],
            &["--stream:"],
        );
    }
}

/// A CSV of `rows` rows of a 500 kS/s time column and zeros, with `line` (1-based, the header
/// is line 1) changed by `change`, then `after` more rows.
fn csv_with(rows: usize, change: impl Fn(String) -> String, after: usize) -> Vec<u8> {
    let mut text = String::from("time_s,accel_g\n");
    for i in 0..rows + after {
        let row = format!("{:.6},0\n", i as f64 * 2e-6);
        text.push_str(&if i == rows { change(row) } else { row });
    }
    text.into_bytes()
}

#[test]
fn an_unclosed_quote_is_reported_where_it_was_opened() {
    let scratch = Scratch::new();
    // Past the sequential reader's head (the parallel one stops at the quote and hands over)
    // and within it; the quoted text runs past the longest line, or to the end of the file.
    for (rows, after, want) in [
        (100_000, 120_000, "not closed within 1048576 bytes"),
        (100, 120_000, "not closed within 1048576 bytes"),
        (100_000, 1000, "never closed"),
    ] {
        let line = rows + 2;
        let csv = scratch.file(
            &format!("quote-{rows}-{after}.csv"),
            csv_with(rows, |row| format!("\"{row}"), after),
        );
        let want = format!(":{line}: a quote opened on this line is {want}");
        refused(&["analyze", csv.to_str().unwrap()], &[&want], &[]);
        refused(&["analyze", csv.to_str().unwrap(), WHOLE], &[&want], &[]);
        let (code, err) = analyze_stdin(&csv, &[]);
        assert_refused(Some(code), &err, &format!("stdin{want}"), "stdin");
    }
}

#[test]
fn a_byte_order_mark_after_the_first_line_is_refused_on_every_line() {
    let scratch = Scratch::new();
    for rows in [100, 100_000] {
        let line = rows + 2;
        let csv = scratch.file(
            &format!("bom-{rows}.csv"),
            csv_with(rows, |row| format!("\u{feff}{row}"), 2000),
        );
        let want = format!(":{line}: not a number: \"\\u{{feff}}");
        for extra in [&[][..], &[WHOLE]] {
            let mut args = vec!["analyze", csv.to_str().unwrap()];
            args.extend_from_slice(extra);
            refused(&args, &[&want, "a byte-order mark"], &[]);
        }
        let (code, err) = analyze_stdin(&csv, &[]);
        assert_refused(Some(code), &err, &format!("stdin{want}"), "stdin");
    }
}

/// The enDAQ recording's bytes with `patch` (offset, new bytes) applied, as a file.
fn ide_patched(scratch: &Scratch, name: &str, at: usize, bytes: &[u8]) -> PathBuf {
    ide_patches(scratch, name, &[(at, bytes)])
}

/// The enDAQ recording's bytes with each (offset, new bytes) applied, as a file.
fn ide_patches(scratch: &Scratch, name: &str, patches: &[(usize, &[u8])]) -> PathBuf {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let mut ide = std::fs::read(root.join("data/endaq-high-drop/High-Drop.IDE")).unwrap();
    // The CalibrationList's polynomial 35 (subchannel 32.2's): CalID at 427, its first
    // coefficient's 8 bytes at 437; checked so that a changed file fails here, not later.
    assert_eq!(&ide[427..431], &[0x4B, 0x03, 0x81, 35]);
    assert_eq!(&ide[434..437], &[0x4B, 0x08, 0x88]);
    // Polynomial 32 (channel 32's own): its first coefficient's 8 bytes at 85.
    assert_eq!(&ide[75..79], &[0x4B, 0x03, 0x81, 32]);
    assert_eq!(&ide[82..85], &[0x4B, 0x08, 0x88]);
    for &(at, bytes) in patches {
        ide[at..at + bytes.len()].copy_from_slice(bytes);
    }
    let path = scratch.path().join(name);
    std::fs::write(&path, ide).unwrap();
    path
}

/// A calibration coefficient that is NaN names the calibration and that the file's is damaged
/// (it said "give a smaller --gain", which none was given); a subchannel whose calibration id
/// is not in the file is read raw as idelib reads it, and a note says so (it was silent).
#[test]
fn an_ide_calibration_that_is_nan_or_missing_is_named() {
    let scratch = Scratch::new();
    let nan = ide_patched(&scratch, "nan.ide", 437, &f64::NAN.to_be_bytes());
    let nan = nan.to_str().unwrap();
    refused(
        &["analyze", nan, "--column", "32.2"],
        &[
            "calibration 35 holds a coefficient that is not a finite number",
            nan,
        ],
        &["--gain"],
    );
    // The subchannel read whole (--axes) meets it too.
    refused(
        &["analyze", nan, "--axes", "32.0,32.1,32.2"],
        &["calibration 35 holds a coefficient that is not a finite number"],
        &["--gain"],
    );
    // Finite coefficients whose product overflows (the channel's 1e300 times the
    // subchannel's 1e300): the same error, not values of infinity.
    let big = 1e300f64.to_be_bytes();
    let product = ide_patches(&scratch, "product.ide", &[(85, &big), (437, &big)]);
    let product = product.to_str().unwrap();
    refused(
        &["analyze", product, "--column", "32.2"],
        &["calibration 35 holds a coefficient that is not a finite number"],
        &["--gain"],
    );
    let missing = ide_patched(&scratch, "missing.ide", 430, &[99]);
    let (code, _, err) = impact(&["analyze", missing.to_str().unwrap(), "--column", "32.2"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("32.2 Z (16g) [g]: its calibration 35 is not in the file's calibration list")
            && err.contains("may be uncalibrated"),
        "{err}"
    );
    // Its neighbour keeps its own calibration: no note.
    let (code, _, err) = impact(&["analyze", missing.to_str().unwrap(), "--column", "32.1"]);
    assert_eq!(code, 0, "{err}");
    assert!(!err.contains("calibration list"), "{err}");
}
