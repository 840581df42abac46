//! Hostile input: every case of the hostile-input issue, run as a user would run it, each
//! `impact` process under a 1 GiB address-space limit and a time limit. Asserted each time:
//! no panic, no hang, no allocation failure; the exit status; a one-line error naming the
//! option or the file and line, or a correct, flagged result; nothing non-finite written.
#![cfg(unix)]

use std::io::{BufRead, BufReader, Write};
use std::os::unix::process::ExitStatusExt;
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::time::Duration;

mod common;
use common::limited::{self, Run};
use common::{Scratch, SYNTH_T2 as T2};

/// Address space each `impact` process may map: far below what the cases used to take
/// (2.5–12 GB), far above what a bounded run needs.
const MEMORY_LIMIT_BYTES: u64 = 1 << 30;

/// Longest a case may run.
const TIME_LIMIT: Duration = Duration::from_secs(120);

/// Starts `impact ARGS` under [`MEMORY_LIMIT_BYTES`].
fn spawn(args: &[&str], stdin: Stdio) -> Child {
    limited::spawn(args, &[], stdin, MEMORY_LIMIT_BYTES)
}

/// Waits for `child` (killing it past [`TIME_LIMIT`]) and checks what any run must satisfy.
fn finish(child: Child, what: &str) -> Run {
    let run = limited::wait(child, what, TIME_LIMIT);
    assert!(
        run.code.is_some() || run.signal == Some(libc::SIGPIPE),
        "{what}: killed by signal {:?}: {}",
        run.signal,
        run.err
    );
    // Nothing non-finite in what is written (JSON has no inf; CSV and tables must not).
    let non_finite = run
        .out
        .split(|c: char| !c.is_ascii_alphanumeric())
        .any(|w| matches!(w.to_ascii_lowercase().as_str(), "inf" | "nan" | "infinity"));
    assert!(!non_finite, "{what}: non-finite output:\n{}", run.out);
    run
}

fn run(args: &[&str]) -> Run {
    finish(spawn(args, Stdio::null()), &args.join(" "))
}

fn run_with_stdin(args: &[&str], input: Vec<u8>) -> Run {
    let mut child = spawn(args, Stdio::piped());
    let mut stdin = child.stdin.take().unwrap();
    let writer = std::thread::spawn(move || {
        let _ = stdin.write_all(&input);
    });
    let r = finish(child, &args.join(" "));
    writer.join().unwrap();
    r
}

/// The run failed with one line that names `want`.
fn fails(args: &[&str], want: &str) -> String {
    let r = run(args);
    refused(&r, &args.join(" "), want);
    r.err
}

/// Refused: a one-line error (exit 1), or clap's usage error (exit 2), naming `want`.
fn refused(r: &Run, what: &str, want: &str) {
    common::assert_refused(r.code, &r.err, want, &format!("{what}\n{}", r.out));
}

fn ok(args: &[&str]) -> Run {
    let r = run(args);
    assert_eq!(r.code, Some(0), "{}: {}", args.join(" "), r.err);
    r
}

fn t2(extra: &[&str]) -> Vec<String> {
    T2.iter().chain(extra).map(|s| s.to_string()).collect()
}

fn strs(v: &[String]) -> Vec<&str> {
    v.iter().map(String::as_str).collect()
}

/// `base.csv`: one 55.6 g two-phase impact at 10 ms.
fn base() -> String {
    ok(&T2).out
}

fn json(text: &str) -> serde_json::Value {
    serde_json::from_str(text).unwrap_or_else(|e| panic!("{e}: {text}"))
}

#[test]
fn synth_refuses_what_it_cannot_render_naming_the_option() {
    for (extra, want) in [
        (&["--duration", "inf"][..], "--duration"),
        (&["--duration", "1e300"], "--duration x --rate"),
        (&["--duration", "NaN"], "--duration"),
        (&["--duration", "-1"], "--duration"),
        (&["--duration", "1e6"], "--duration x --rate"),
        (&["--rate", "1e12"], "--duration x --rate"),
        (&["--rate", "1e9"], "--duration x --rate"),
        (&["--bits", "16"], "--bits"),
        (&["--noise", "NaN"], "--noise"),
        (&["--noise", "-1"], "--noise"),
        (&["--offset", "NaN"], "--offset"),
        (&["--drift", "NaN"], "--drift"),
        (&["--drift", "inf"], "--drift"),
        (&["--full-scale", "NaN"], "--full-scale"),
        (&["--full-scale", "inf"], "--full-scale"),
        (&["--full-scale", "0"], "--full-scale"),
        (&["--full-scale", "-1"], "--full-scale"),
        (&["--touch", "inf"], "--touch"),
        (&["--touch", "NaN"], "--touch"),
        (&["--touch", "1e300"], "--touch"),
    ] {
        fails(&strs(&t2(extra)), want);
    }
}

#[test]
fn synth_memory_follows_the_recording_not_the_contact_time() {
    // Contacts of ~3e4 s, ~3e5 s and ~1e30 s rendered into 10 samples each: 10 rows, promptly
    // and in bounded memory.
    for law in [
        &["--mass", "1", "--stiffness", "1e-8"][..],
        &["--mass", "1", "--stiffness", "1e-10"],
        &["--mass", "1e30", "--stiffness", "1e-30"],
    ] {
        let mut args = vec!["synth", "--model", "linear", "--v0", "1"];
        args.extend(law);
        args.extend(["--duration", "0.01", "--rate", "1000", "--touch", "0.001"]);
        let r = ok(&args);
        assert_eq!(r.out.lines().count(), 11, "{args:?}: {}", r.out);
    }
}

#[test]
fn a_closed_output_pipe_ends_the_tool_quietly() {
    let scratch = Scratch::new();
    // `impact synth … | head -1`: the next write after the reader left gets SIGPIPE (the usual
    // status of a pipeline's writer), not a panic.
    let args = strs(&t2(&["--duration", "2"])).join(" ");
    let mut child = spawn(&strs(&t2(&["--duration", "2"])), Stdio::null());
    let mut first = String::new();
    let stdout = child.stdout.take().unwrap();
    BufReader::new(stdout).read_line(&mut first).unwrap();
    assert_eq!(first.trim(), "time_s,accel_g");
    let r = finish(child, &args);
    assert_eq!(r.signal, Some(libc::SIGPIPE), "{:?} {}", r.code, r.err);
    // `impact analyze big.csv --csv | head -1`: the same.
    let big = ok(&strs(&t2(&[
        "--impacts",
        "400",
        "--every",
        "0.02",
        "--duration",
        "8.1",
        "--rate",
        "50000",
    ])))
    .out;
    let f = scratch.file("big.csv", big.as_bytes());
    let mut child = spawn(&["analyze", f.to_str().unwrap(), "--csv"], Stdio::null());
    let mut first = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut first)
        .unwrap();
    assert!(first.starts_with("index,"), "{first}");
    let r = finish(child, "analyze big.csv --csv | head -1");
    assert!(
        r.signal == Some(libc::SIGPIPE) || r.code == Some(0),
        "{:?} {}",
        r.code,
        r.err
    );
}

#[test]
fn a_closed_error_pipe_ends_the_tool_quietly_too() {
    // `impact … 2>&1 | head -0`: the error message meets a closed pipe. The run ends by
    // SIGPIPE (or, if the write came first, by its status 1), never by a panic (101).
    for _ in 0..20 {
        let mut child = Command::new(env!("CARGO_BIN_EXE_impact"))
            .args(["analyze", "/nonexistent/impact.csv"])
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .expect("impact runs");
        drop(child.stderr.take());
        let status = child.wait().unwrap();
        assert!(
            status.signal() == Some(libc::SIGPIPE) || status.code() == Some(1),
            "{status:?}"
        );
    }
}

#[test]
fn endless_or_blocking_inputs_end_in_bounded_memory() {
    let scratch = Scratch::new();
    // No line break at all: an error after a bounded read.
    fails(&["analyze", "/dev/zero"], "/dev/zero:1: a line longer than");
    fails(&["log", "/dev/zero"], "/dev/zero:1: a line longer than");
    // A FIFO is opened once: the tool reads what the writer sends and ends when it closes.
    let fifo = scratch.join("stream.csv");
    let path = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
    // SAFETY: a valid NUL-terminated path.
    assert_eq!(unsafe { libc::mkfifo(path.as_ptr(), 0o600) }, 0);
    let csv = base();
    let child = spawn(
        &["analyze", fifo.to_str().unwrap(), "--json"],
        Stdio::null(),
    );
    std::fs::OpenOptions::new()
        .write(true)
        .open(&fifo)
        .unwrap()
        .write_all(csv.as_bytes())
        .unwrap();
    let r = finish(child, "analyze FIFO");
    assert_eq!(r.code, Some(0), "{}", r.err);
    assert_eq!(json(&r.out)["impacts"].as_array().unwrap().len(), 1);
    // Standard input (`-`) reads the same.
    let r = run_with_stdin(&["analyze", "-", "--json"], csv.into_bytes());
    assert_eq!(r.code, Some(0), "{}", r.err);
    assert_eq!(json(&r.out)["impacts"].as_array().unwrap().len(), 1);
    // An unclosed quote does not swallow the rest of the file into one field.
    let mut text = b"time_s,a_g\n0,1\n\"".to_vec();
    text.extend(b"0.001,2\n".repeat(200_000));
    let f = scratch.file("open-quote.csv", &text);
    fails(
        &["analyze", f.to_str().unwrap()],
        "open-quote.csv:3: a quote opened on this line is not closed",
    );
}

#[test]
fn the_exact_solvers_refuse_results_that_underflow() {
    for extra in [
        ["--mass", "8.419e-3", "--v0", "1e-160", "--precision", "f64"],
        ["--mass", "1e-45", "--v0", "1", "--precision", "f32"],
    ] {
        let mut args = vec![
            "simulate",
            "--model",
            "hertz",
            "--stiffness",
            "1e10",
            "--json",
        ];
        args.extend(extra);
        fails(&args, "underflowed");
    }
}

#[test]
fn values_no_sensor_gives_are_the_files_line() {
    let scratch = Scratch::new();
    let csv = base();
    for (v, line) in [
        ("1e38", 1002),
        ("1e39", 1002),
        ("1e308", 1002),
        ("NaN", 1002),
    ] {
        let text = csv.replacen(
            "\n0.002000000,",
            &format!("\n0.002000000,{v}\n0.002000001,"),
            1,
        );
        let f = scratch.file(&format!("value-{v}.csv"), text.as_bytes());
        let err = fails(
            &["analyze", f.to_str().unwrap(), "--csv"],
            &format!(":{line}:"),
        );
        assert!(
            !err.contains("--gain") && !err.contains("--trigger"),
            "{err}"
        );
    }
    // Leading NaN rows are data with a bad value, not header lines.
    let mut text = String::from("time_s,a_g\n");
    text.push_str(&"NaN,NaN\n".repeat(1000));
    text.push_str("0.001,1\n0.002,2\n");
    let f = scratch.file("nan-lead.csv", text.as_bytes());
    fails(
        &["analyze", f.to_str().unwrap()],
        "nan-lead.csv:2: value is NaN",
    );
}

#[test]
fn csv_layouts_are_read_right_or_refused_with_a_hint() {
    let scratch = Scratch::new();
    let csv = base();
    let f = scratch.file("plain.csv", csv.as_bytes());
    let reference = json(&ok(&["analyze", f.to_str().unwrap(), "--json"]).out)["impacts"].clone();
    let peak = reference[0]["peak_acceleration_m_s2"].as_f64().unwrap();
    assert!((peak - 546.0).abs() < 1.0, "{peak}");
    let same = |name: &str, text: String, extra: &[&str]| {
        let f = scratch.file(name, text.as_bytes());
        let mut args = vec!["analyze", f.to_str().unwrap(), "--json"];
        args.extend(extra);
        let r = ok(&args);
        assert_eq!(json(&r.out)["impacts"], reference, "{name}");
    };
    // A byte-order mark, quoted fields, semicolons, tabs, CRLF line ends.
    same("bom.csv", format!("\u{feff}{csv}"), &[]);
    let quoted: String = csv
        .lines()
        .map(|l| {
            l.split(',')
                .map(|f| format!("\"{f}\""))
                .collect::<Vec<_>>()
                .join(",")
                + "\n"
        })
        .collect();
    same("quoted.csv", quoted, &[]);
    same("semicolon.csv", csv.replace(',', ";"), &[]);
    same("tab.csv", csv.replace(',', "\t"), &["--delimiter", "tab"]);
    same("crlf.csv", csv.replace('\n', "\r\n"), &[]);
    // Decimal commas: read with the option, refused with a hint without it.
    let comma = csv.replace(',', ";").replace('.', ",");
    same(
        "comma.csv",
        comma.clone(),
        &["--decimal-comma", "--delimiter", ";"],
    );
    let f = scratch.file("comma.csv", comma.as_bytes());
    fails(
        &["analyze", f.to_str().unwrap()],
        "comma.csv:2: not a number: \"0,000000000\" (decimal commas? give --decimal-comma)",
    );
    fails(
        &[
            "analyze",
            f.to_str().unwrap(),
            "--decimal-comma",
            "--delimiter",
            ",",
        ],
        "--decimal-comma: the delimiter is ','",
    );
    // One column of decimal commas under a one-field header: a ragged row, not the integer
    // part analysed.
    let one: String = std::iter::once("accel_g\n".to_string())
        .chain(
            csv.lines()
                .skip(1)
                .map(|l| l.split(',').nth(1).unwrap().replace('.', ",") + "\n"),
        )
        .collect();
    let f = scratch.file("one-column.csv", one.as_bytes());
    fails(
        &["analyze", f.to_str().unwrap(), "--rate", "500000"],
        "one-column.csv:2: 2 fields, but the header (line 1) has 1",
    );
    let r = ok(&[
        "analyze",
        f.to_str().unwrap(),
        "--rate",
        "500000",
        "--decimal-comma",
        "--delimiter",
        ";",
        "--json",
    ]);
    let p = json(&r.out)["impacts"][0]["peak_acceleration_m_s2"]
        .as_f64()
        .unwrap();
    assert!((p - peak).abs() < 1e-3, "{p}");
    // Ragged rows against the header and against the first row.
    let f = scratch.file("ragged.csv", b"time_s,a_g\n0,1,2\n");
    fails(
        &["analyze", f.to_str().unwrap()],
        "ragged.csv:2: 3 fields, but the header",
    );
    let f = scratch.file("ragged2.csv", b"time_s,a_g\n0,1\n1e-6,2,3\n");
    fails(
        &["analyze", f.to_str().unwrap()],
        "ragged2.csv:3: 3 fields, expected 2",
    );
    fails(&["analyze", "x.csv", "--delimiter", "ab"], "--delimiter");
}

#[test]
fn options_are_checked_where_they_are_parsed_naming_themselves() {
    let scratch = Scratch::new();
    let csv = base();
    let f = scratch.file("options.csv", csv.as_bytes());
    let name = f.to_str().unwrap();
    for (extra, want) in [
        (&["--mass", "NaN"][..], "--mass"),
        (&["--mass", "-1"], "--mass"),
        (&["--mass", "3e38", "--v0", "1.3357"], "--mass"),
        (&["--v0", "inf"], "--v0"),
        (&["--drop-height", "0"], "--drop-height"),
        (&["--rate", "0"], "--rate"),
        (&["--trigger", "NaN"], "--trigger"),
        (&["--hold", "-1"], "--hold"),
        (&["--hold", "10"], "--hold"),
        (&["--rate", "1e8"], "lower the rate"),
        (&["--column", "0"], "time column"),
        (&["--column", "9"], "column 9"),
        (&["--plot", name], "input file"),
        (&["--plot", "/nonexistent-dir/x.svg"], "/nonexistent-dir"),
    ] {
        let mut args = vec!["analyze", name];
        args.extend(extra);
        let r = run(&args);
        refused(&r, &format!("{extra:?}"), want);
        assert!(r.out.is_empty(), "{extra:?}: printed before the error");
    }
    assert_eq!(
        std::fs::read_to_string(&f).unwrap(),
        csv,
        "--plot kept off the input"
    );
    // A scene file spells units as the command line does; a drop height given on the command
    // line replaces the scene's v0.
    let scene = scratch.file(
        "scene.json",
        br#"{"mass_kg": 0.06, "v0_m_s": 5.0, "units": "g"}"#,
    );
    let first = |extra: &[&str]| {
        let mut args = vec![
            "analyze",
            name,
            "--scene",
            scene.to_str().unwrap(),
            "--json",
        ];
        args.extend(extra);
        json(&ok(&args).out)["impacts"][0].clone()
    };
    // The scene's 5 m/s is more than this impact's Δv could stop: flagged, with reasons.
    let fast = first(&[]);
    assert!(fast["flags"].to_string().contains("no-stop"), "{fast}");
    assert_eq!(fast["null_reasons"]["cor"], "no-stop");
    let h = 1.3357f64 * 1.3357 / (2.0 * 9.80665);
    let v0 = first(&["--drop-height", &h.to_string()])["impact_velocity_m_s"]
        .as_f64()
        .unwrap();
    assert!((v0 - 1.3357).abs() < 1e-4, "{v0}");
    // A hold of 5 samples still holds the whole contact: the kinematics are the default
    // hold's (they need the contact, not the hold). An impact cut before the body has come
    // back (`--max-impact` shorter than the contact) has none, with the reason.
    let run = |extra: &[&str]| {
        let mut args = vec![
            "analyze", name, "--mass", "0.06", "--v0", "1.3357", "--json",
        ];
        args.extend_from_slice(extra);
        json(&ok(&args).out)["impacts"][0].clone()
    };
    let (short, whole) = (run(&["--hold", "1e-5"]), run(&[]));
    let cor = short["cor"].as_f64().unwrap_or_else(|| panic!("{short}"));
    assert!(
        (cor / whole["cor"].as_f64().unwrap() - 1.0).abs() < 1e-4,
        "{short}"
    );
    let cut = run(&["--max-impact", "0.002"]);
    assert!(
        cut["cor"].is_null() && cut["null_reasons"]["cor"] == "status-too-long",
        "{cut}"
    );
}

#[test]
fn impact_log_refuses_what_the_firmware_cannot_have_written_by_line() {
    let scratch = Scratch::new();
    // A real line from the emulated firmware's format (see docs/board.md).
    let (scene, line) = SAMPLE_LOG;
    let set = |field: &str, value: &str| {
        let (head, tail) = line.split_once(&format!(" {field}=")).unwrap();
        let rest = tail.split_once(' ').map_or("", |(_, r)| r);
        format!("{head} {field}={value} {rest}")
    };
    let log = |name: &str, text: String| scratch.file(name, text.as_bytes());
    let good = log("good.log", format!("{scene}\n{line}\n"));
    let r = ok(&["log", good.to_str().unwrap(), "--csv"]);
    assert_eq!(r.out.lines().count(), 2, "{}", r.out);
    for (name, text, want) in [
        (
            "rate.log",
            format!(
                "{}\n{line}\n",
                scene.replace("rate_hz=500000", "rate_hz=NaN")
            ),
            "rate.log: line 1: rate_hz=NaN",
        ),
        (
            "rate-neg.log",
            format!(
                "{}\n{line}\n",
                scene.replace("rate_hz=500000", "rate_hz=-5")
            ),
            "line 1: rate_hz=-5",
        ),
        (
            "zeros.log",
            format!("{scene}\n{line}\n{line}\n{line}\n"),
            "line 3: impact index=0 again (first on line 2)",
        ),
        (
            "order.log",
            format!("{scene}\n{}\n{line}\n", set("index", "5")),
            "line 3: impact index=0 after index=5",
        ),
        (
            "empty.log",
            "nothing to see\n".into(),
            "no scene, heartbeat or summary line",
        ),
    ] {
        let f = log(name, text);
        fails(&["log", f.to_str().unwrap()], want);
    }
    // A line whose own values no firmware writes is passed over and named (a line cut by the
    // link among them): the rest of the log is read.
    for (name, text, want) in [
        (
            "inf.log",
            format!("{scene}\n{}\n", set("peak_acceleration_m_s2", "inf")),
            "line 2: peak_acceleration_m_s2=inf: not finite",
        ),
        (
            "f32.log",
            format!("{scene}\n{}\n", set("peak_force_n", "1e39")),
            "line 2: peak_force_n=inf: not finite",
        ),
        (
            "cor.log",
            format!("{scene}\n{}\n", set("cor", "7.5")),
            "line 2: cor=7.5: out of range",
        ),
        (
            "xp.log",
            format!("{scene}\n{}\n", set("permanent_deformation_m", "-1")),
            "line 2: permanent_deformation_m=-1",
        ),
        (
            "garbage.log",
            format!("{scene}\n0.01 INFO  impact index=zero status=complete\n"),
            "line 2: missing field",
        ),
    ] {
        let f = log(name, text);
        let r = ok(&["log", f.to_str().unwrap()]);
        assert!(
            r.err.contains(want) && r.err.contains("(skipped)"),
            "{name}: {}",
            r.err
        );
        let j = json(&r.out);
        assert_eq!(j["impacts"].as_array().map(Vec::len), Some(0), "{name}");
        assert_eq!(j["skipped_lines"][0]["line"], 2, "{name}");
    }
    fails(&["log", good.to_str().unwrap(), "--t0", "NaN"], "--t0");
    // A heartbeat counting more impacts than the log has lines: said, by line.
    let beat = "heartbeat samples=500000 rate_hz=500000 impacts=7 reports_dropped=0";
    let f = log("beat.log", format!("{scene}\n{line}\n{beat}\n"));
    let r = ok(&["log", f.to_str().unwrap()]);
    assert!(
        r.err.contains("line 3: the heartbeat counts 7 impacts"),
        "{}",
        r.err
    );
    // Standard input.
    let r = run_with_stdin(&["log", "-", "--csv"], std::fs::read(&good).unwrap());
    assert_eq!(r.code, Some(0), "{}", r.err);
    assert_eq!(r.out.lines().count(), 2);
}

#[test]
fn binary_recordings_with_lying_headers_are_refused_in_bounded_memory() {
    let scratch = Scratch::new();
    let fixtures = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fixtures");
    // TDMS: the first object path claims 4 GiB (the reader would allocate it).
    let mut tdms = std::fs::read(fixtures.join("afrl-test1.tdms")).unwrap();
    tdms[32..36].copy_from_slice(&u32::MAX.to_le_bytes());
    let f = scratch.file("lying.tdms", &tdms);
    fails(
        &["analyze", f.to_str().unwrap()],
        "lying.tdms: TDMS: byte 36",
    );
    // (TDMS segments written interleaved, ToC bit 5, are read since #45: their sizes'
    // checks are in tests/hostile_readers.rs.)
    // TDMS: a value count beyond the file.
    let mut tdms = std::fs::read(fixtures.join("afrl-test1.tdms")).unwrap();
    tdms.truncate(2000);
    let f = scratch.file("short.tdms", &tdms);
    fails(&["analyze", f.to_str().unwrap()], "short.tdms");
    // WAV: a header announcing 2^31 frames of a file that holds a few.
    let mut wav = std::fs::read(fixtures.join("afrl-test1-int16.wav")).unwrap();
    wav.truncate(4000);
    let len = wav.len();
    wav[40..44].copy_from_slice(&(u32::MAX - 3).to_le_bytes());
    wav[4..8].copy_from_slice(&((len - 8) as u32).to_le_bytes());
    let f = scratch.file("lying.wav", &wav);
    fails(&["analyze", f.to_str().unwrap()], "lying.wav");
    // .npy: a shape of 2^40 rows.
    let mut npy = std::fs::read(fixtures.join("afrl-test1-int16.npy")).unwrap();
    let at = npy.windows(10).position(|w| w == b"(10000, 2)").unwrap();
    npy[at..at + 10].copy_from_slice(b"(99999, 2)");
    let f = scratch.file("lying.npy", &npy);
    fails(
        &["analyze", f.to_str().unwrap(), "--rate", "1e6"],
        "lying.npy",
    );
}

/// A recording that never settles to a baseline within the edge level (noise larger than
/// `--edge`) has no impact: `analyze` exits 0 with none and a note saying why, as the board
/// (`impact emulate`) does; an empty recording of any format is refused naming its file.
#[test]
fn quiet_or_unsettled_recordings_have_no_impacts_and_empty_ones_name_their_file() {
    let scratch = Scratch::new();
    // White noise of 20 m/s² RMS (a deterministic LCG) against --edge 5.5.
    let mut state = 12345u64;
    let mut noise = || {
        let mut s = 0.0;
        for _ in 0..12 {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            s += (state >> 11) as f64 / (1u64 << 53) as f64;
        }
        20.0 * (s - 6.0)
    };
    let mut csv = String::from("time_s,accel_m_s2\n");
    for k in 0..10_000 {
        csv += &format!("{},{:.4}\n", k as f64 / 1e4, noise());
    }
    let f = scratch.file("unsettled.csv", csv.as_bytes());
    let r = ok(&[
        "analyze",
        f.to_str().unwrap(),
        "--trigger",
        "27",
        "--edge",
        "5.5",
        "--json",
    ]);
    assert_eq!(json(&r.out)["impacts"].as_array().unwrap().len(), 0);
    assert!(
        r.err.contains("note: the signal never settled"),
        "{}",
        r.err
    );
    // Empty recordings: the file's name and what is missing.
    let wav = {
        let mut w = b"RIFF".to_vec();
        w.extend_from_slice(&36u32.to_le_bytes());
        w.extend_from_slice(b"WAVEfmt ");
        w.extend_from_slice(&16u32.to_le_bytes());
        w.extend_from_slice(&1u16.to_le_bytes()); // PCM
        w.extend_from_slice(&1u16.to_le_bytes()); // one channel
        w.extend_from_slice(&10_000u32.to_le_bytes());
        w.extend_from_slice(&20_000u32.to_le_bytes());
        w.extend_from_slice(&2u16.to_le_bytes());
        w.extend_from_slice(&16u16.to_le_bytes());
        w.extend_from_slice(b"data");
        w.extend_from_slice(&0u32.to_le_bytes());
        w
    };
    let f = scratch.file("empty.wav", &wav);
    fails(
        &["analyze", f.to_str().unwrap()],
        "empty.wav: channel 0: 0 samples; at least 2",
    );
    let f = scratch.file("empty.f32", b"");
    fails(
        &["analyze", f.to_str().unwrap(), "--rate", "1000"],
        "empty.f32: channel 0: 0 samples; at least 2",
    );
}

/// Secondary inputs are read up to a stated size: an endless one (`/dev/zero`) as a scene,
/// a target or an ELF is an error naming the limit at once (a scene grew to 24 GB). And a
/// negative `--t0` is a value, not an unknown option.
#[test]
fn endless_secondary_inputs_are_refused_naming_their_limit() {
    let scratch = Scratch::new();
    let csv = base();
    let f = scratch.file("secondary.csv", csv.as_bytes());
    let name = f.to_str().unwrap();
    fails(
        &["analyze", name, "--scene", "/dev/zero"],
        "/dev/zero: more than 1024 KiB, larger than any scene file",
    );
    fails(
        &[
            "simulate",
            "--model",
            "hertz",
            "--mass",
            "8.419e-3",
            "--v0",
            "2",
            "--radius",
            "6.35e-3",
            "--youngs",
            "200e9",
            "--poisson",
            "0.3",
            "--target",
            "/dev/zero",
        ],
        "--target /dev/zero: more than 1024 KiB, larger than any target file",
    );
    fails(
        &["log", "--elf", "/dev/zero", name],
        "/dev/zero: more than 262144 KiB, larger than any firmware ELF",
    );
    fails(
        &[
            "report",
            name,
            "--srs-required",
            "/dev/zero",
            "--html",
            &f.with_file_name("secondary-out.html").to_string_lossy(),
        ],
        "--srs-required /dev/zero: more than 1024 KiB, larger than any required SRS",
    );
    fails(
        &[
            "analyze",
            name,
            "--spec",
            "half-sine,50g,11ms,band-file=/dev/zero",
        ],
        "band-file=/dev/zero: more than 1024 KiB, larger than any band file",
    );
    // `synth --drop-every 1` would write a header and no sample.
    fails(&["synth", "--drop-every", "1"], "--drop-every");
    let (scene, line) = SAMPLE_LOG;
    let log = scratch.file("t0.log", format!("{scene}\n{line}\n").as_bytes());
    let r = ok(&["log", log.to_str().unwrap(), "--t0", "-0.5", "--json"]);
    let start = json(&r.out)["impacts"][0]["start_s"].as_f64().unwrap();
    assert!((start - (0.01 - 0.5)).abs() < 1e-9, "{start}");
}

/// A scene line and an impact line in the firmware's format (see docs/board.md).
const SAMPLE_LOG: (&str, &str) = (
    "scene rate_hz=500000 v0_m_s=1.3357 drop_height_m=none two_phase=false nonlinear=false fit_exponent=false hertz=false",
    "impact index=0 status=complete analysis=full clipped=false flags=0 start_sample=5000 end_sample=17000 start_s=0.01 peak_time_s=0.0100251 peak_acceleration_m_s2=4321.5 peak_force_n=259.29 delta_v_m_s=2.5 duration_s=0.0219 baseline_m_s2=0.2 fwhm_s=0.001 filtered_peak_acceleration_m_s2=none filtered_fwhm_s=none impact_velocity_m_s=1.3357 crush_time_s=0.0218 max_deformation_m=0.0186 rebound_velocity_m_s=1.16 cor=0.87 separation_deformation_m=0.0182 permanent_deformation_m=0.0182 absorbed_energy_j=none two_phase_kc_n_m=none two_phase_kr_n_m=none two_phase_c_n_s_m=none two_phase_permanent_deformation_m=none two_phase_residual=none nonlinear_k=none nonlinear_c_s_m=none nonlinear_exponent=none nonlinear_residual=none hertz_k=none hertz_residual=none report_latency_s=0.0123",
);
