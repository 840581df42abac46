//! `impact analyze --stream`: a CSV or raw recording analysed as it is read. The same reports
//! as the whole-file path given the same levels; a stream too long to load (over 24 GiB as
//! the whole-file path holds it) through standard input, in memory that does not grow.

use std::io::Write;
use std::process::{Command, Stdio};

mod common;
use common::{impact_ok as impact, Scratch};

/// The seed bench's ADC codes (offset binary, 12 bits over ±800 m/s², so the full scale is
/// 4096 codes, 1600 m/s²) at 500 kS/s.
const LEVELS: [&str; 16] = [
    "--rate",
    "500000",
    "--gain",
    "0.390625",
    "--units",
    "m/s2",
    "--range",
    "1600",
    "--trigger",
    "10",
    "--edge",
    "2",
    "--mass",
    "0.06",
    "--v0",
    "1.3357",
];

/// The same levels for the seed bench's CSV, in g (the file's unit): ±163 g is the ADC's
/// ±1600 m/s².
const SEED_CSV_LEVELS: [&str; 10] = [
    "--range",
    "163g",
    "--trigger",
    "10",
    "--edge",
    "2",
    "--mass",
    "0.06",
    "--v0",
    "1.3357",
];

#[test]
fn a_raw_stream_gives_the_whole_files_reports() {
    let scratch = Scratch::new();
    let raw = scratch.join_str("seed.i16");
    let args: Vec<&str> = ["synth", "--raw", &raw]
        .into_iter()
        .chain(impact_host::synth::SEED_BENCH_ARGS)
        .collect();
    impact(&args);
    let with = |head: &[&str], tail: &[&str]| -> Vec<String> {
        head.iter()
            .chain(&LEVELS)
            .chain(tail)
            .map(|s| s.to_string())
            .collect()
    };
    let run = |v: Vec<String>| impact(&v.iter().map(String::as_str).collect::<Vec<_>>()).0;
    // The whole-file path screens spikes with the whole recording's noise: not here.
    let whole = run(with(&["analyze", &raw], &["--json", "--keep-spikes"]));
    let streamed = run(with(&["analyze", &raw], &["--json", "--stream"]));
    assert_eq!(streamed, whole);
    let v: serde_json::Value = serde_json::from_str(&whole).unwrap();
    assert!(v["impacts"][0]["cor"].is_number(), "{v}");

    // Through standard input, read in whatever pieces the pipe gives.
    let mut child = Command::new(env!("CARGO_BIN_EXE_impact"))
        .args(with(
            &["analyze", "-"],
            &["--json", "--stream", "--raw-type", "i16"],
        ))
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let bytes = std::fs::read(&raw).unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let writer = std::thread::spawn(move || {
        for piece in bytes.chunks(777) {
            stdin.write_all(piece).unwrap();
        }
    });
    let out = child.wait_with_output().unwrap();
    writer.join().unwrap();
    assert!(out.status.success());
    assert_eq!(String::from_utf8(out.stdout).unwrap(), whole);

    // What needs the whole recording is refused, a cut frame named.
    let (code, _, err) = common::impact(&["analyze", &raw, "--stream", "--rate", "500000"]);
    assert!(code != 0 && err.contains("--range"), "{err}");
    let (code, _, err) = common::impact(
        &with(
            &["analyze", &raw],
            &["--stream", "--plot", &scratch.join_str("x.svg")],
        )
        .iter()
        .map(String::as_str)
        .collect::<Vec<_>>(),
    );
    assert!(
        code != 0 && err.contains("--plot needs the whole recording"),
        "{err}"
    );
    let odd = scratch.join_str("odd.i16");
    std::fs::write(&odd, &std::fs::read(&raw).unwrap()[..1001]).unwrap();
    let (code, _, err) = common::impact(
        &with(&["analyze", &odd], &["--stream"])
            .iter()
            .map(String::as_str)
            .collect::<Vec<_>>(),
    );
    assert!(
        code != 0 && err.contains("the last frame starts at byte 1000"),
        "{err}"
    );
}

#[test]
fn a_csv_stream_gives_the_whole_files_reports() {
    let scratch = Scratch::new();
    let (csv, _) = impact(
        &["synth"]
            .into_iter()
            .chain(impact_host::synth::SEED_BENCH_ARGS)
            .collect::<Vec<_>>(),
    );
    let file = scratch.text("seed.csv", &csv);
    let levels = SEED_CSV_LEVELS;
    let args = |head: &[&str], tail: &[&str]| -> Vec<String> {
        head.iter()
            .chain(&levels)
            .chain(tail)
            .map(|s| s.to_string())
            .collect()
    };
    let run = |v: Vec<String>| impact(&v.iter().map(String::as_str).collect::<Vec<_>>()).0;
    let whole = run(args(&["analyze", &file], &["--json", "--keep-spikes"]));
    assert_eq!(
        run(args(&["analyze", &file], &["--json", "--stream"])),
        whole
    );
    let mut child = Command::new(env!("CARGO_BIN_EXE_impact"))
        .args(args(&["analyze", "-"], &["--json", "--stream"]))
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let bytes = csv.into_bytes();
    let writer = std::thread::spawn(move || {
        for piece in bytes.chunks(1013) {
            stdin.write_all(piece).unwrap();
        }
    });
    let out = child.wait_with_output().unwrap();
    writer.join().unwrap();
    assert!(out.status.success());
    assert_eq!(String::from_utf8(out.stdout).unwrap(), whole);

    // A gap in the time column is an error at its line, as in the whole-file path.
    let mut lines: Vec<&str> = std::str::from_utf8(&std::fs::read(&file).unwrap())
        .unwrap()
        .lines()
        .map(|l| l.to_owned().leak() as &str)
        .collect();
    lines.remove(30_000);
    let gap = scratch.text("gap.csv", &lines.join("\n"));
    let (code, _, err) = common::impact(
        &args(&["analyze", &gap], &["--stream"])
            .iter()
            .map(String::as_str)
            .collect::<Vec<_>>(),
    );
    assert!(
        code != 0 && err.contains(":30001: uneven") && err.contains("uneven time axis"),
        "{err}"
    );
}

#[test]
fn a_wav_stream_gives_the_whole_files_reports() {
    let scratch = Scratch::new();
    let wav = concat!(env!("CARGO_MANIFEST_DIR"), "/fixtures/afrl-test1-int16.wav");
    let levels = [
        "--gain",
        "0.001",
        "--units",
        "kgn",
        "--range",
        "32.767kgn",
        "--trigger",
        "20000",
        "--json",
    ];
    fn args<'a>(wav: &'a str, levels: &[&'a str], tail: &[&'a str]) -> Vec<&'a str> {
        ["analyze", wav]
            .iter()
            .chain(levels)
            .chain(tail)
            .copied()
            .collect()
    }
    let (whole, _) = impact(&args(wav, &levels, &["--keep-spikes"]));
    let (streamed, _) = impact(&args(wav, &levels, &["--stream"]));
    assert_eq!(streamed, whole);
    assert!(whole.contains("peak_acceleration_m_s2"), "{whole}");
    // Cut in the middle of the data: an error naming the frame, as the whole-file reader's.
    let cut = scratch.join_str("cut.wav");
    let bytes = std::fs::read(wav).unwrap();
    std::fs::write(&cut, &bytes[..bytes.len() / 2 + 1]).unwrap();
    let args: Vec<&str> = ["analyze", &cut, "--stream"]
        .iter()
        .chain(&levels)
        .copied()
        .collect();
    let (code, _, err) = common::impact(&args);
    assert!(code != 0 && err.contains("WAV: frame"), "{err}");
}

#[test]
fn npy_streams_give_the_whole_files_reports_in_either_order() {
    let scratch = Scratch::new();
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/fixtures/");
    for (file, gain, range) in [
        ("afrl-test1-int16.npy", "0.001", "40kgn"),
        ("afrl-test1-float32-fortran.npy", "1", "40000kgn"),
    ] {
        let path = format!("{dir}{file}");
        for column in ["0", "1"] {
            let args = |tail: &str| -> Vec<String> {
                [
                    "analyze",
                    &path,
                    "--rate",
                    "1000000",
                    "--column",
                    column,
                    "--units",
                    "kgn",
                    "--gain",
                    gain,
                    "--range",
                    range,
                    "--trigger",
                    "20000",
                    "--json",
                    tail,
                ]
                .iter()
                .map(|s| s.to_string())
                .collect()
            };
            let run = |v: Vec<String>| impact(&v.iter().map(String::as_str).collect::<Vec<_>>()).0;
            let whole = run(args("--keep-spikes"));
            assert_eq!(run(args("--stream")), whole, "{file} column {column}");
            assert!(whole.contains("peak_time_s"), "{file}: no impact");
        }
    }
    // A file cut short: an error naming where its data ends.
    let bytes = std::fs::read(format!("{dir}afrl-test1-int16.npy")).unwrap();
    let cut = scratch.join_str("cut.npy");
    std::fs::write(&cut, &bytes[..bytes.len() - 1000]).unwrap();
    let (code, _, err) = common::impact(&[
        "analyze",
        &cut,
        "--rate",
        "1000000",
        "--range",
        "40000g",
        "--trigger",
        "20000",
        "--stream",
    ]);
    assert!(code != 0 && err.contains("npy"), "{err}");
}

/// 2^30 samples (2 GiB of i16; 36 minutes at 500 kS/s; over 24 GiB as the whole-file path
/// would hold them) generated as they are written into `impact analyze -`'s standard input:
/// every impact reported, in under 64 MiB.
#[test]
fn a_stream_longer_than_memory_is_analysed_in_bounded_memory() {
    const PERIOD: usize = 1 << 22; // 8.4 s at 500 kS/s, one impact each
    const PERIODS: usize = 256;
    // Mid-scale with ±1 count of noise, a 2 ms half-sine of 1000 counts (390 m/s²).
    let pattern = common::impact_period(PERIOD, 2048);
    let mut child = Command::new(env!("CARGO_BIN_EXE_impact"))
        .args(["analyze", "-", "--stream", "--raw-type", "i16", "--csv"])
        .args(&LEVELS[..12])
        // The child's own peak memory (VmHWM) on stderr.
        .env("IMPACT_PEAK_MEMORY", "1")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let writer = std::thread::spawn(move || {
        for _ in 0..PERIODS {
            stdin.write_all(&pattern).unwrap();
        }
    });
    let out = child.wait_with_output().unwrap();
    writer.join().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    let csv = String::from_utf8(out.stdout).unwrap();
    let rows = csv.lines().skip(1).filter(|l| !l.is_empty()).count();
    assert_eq!(rows, PERIODS, "one report per inserted impact");
    let peak_mib = common::peak_memory_mib(&err);
    eprintln!("2^30 samples streamed, {rows} impacts, peak memory {peak_mib:.1} MiB");
    assert!(peak_mib < 64.0, "peak memory {peak_mib:.1} MiB");
}

/// Past its head (65 536 rows) a CSV file's plain rows are parsed in parallel; quoted fields,
/// blank lines, `\r\n` and spaces hand over to the sequential reader for a while, and errors
/// read as in one pass: the same reports as the whole-file path, the same messages and lines.
#[test]
fn a_long_csv_file_gives_the_same_reports_and_errors_through_the_parallel_reader() {
    let scratch = Scratch::new();
    let (csv, _) = impact(
        &["synth"]
            .into_iter()
            .chain(impact_host::synth::SEED_BENCH_ARGS)
            .chain(["--touch", "0.3", "--duration", "0.6"])
            .collect::<Vec<_>>(),
    );
    let lines: Vec<String> = csv.lines().map(str::to_owned).collect();
    assert!(lines.len() > 290_000, "{}", lines.len());
    let levels = SEED_CSV_LEVELS;
    let run = |file: &str, tail: &[&str]| {
        let v: Vec<&str> = ["analyze", file]
            .into_iter()
            .chain(levels)
            .chain(tail.iter().copied())
            .collect();
        common::impact(&v)
    };
    let write = |name: &str, lines: &[String]| scratch.text(name, &(lines.join("\n") + "\n"));
    // Through a pipe on standard input (which cannot be read twice: the readers hand it
    // over on a tape).
    let run_stdin = |file: &str, tail: &[&str]| {
        let mut child = Command::new(env!("CARGO_BIN_EXE_impact"))
            .args(["analyze", "-"])
            .args(levels)
            .args(tail)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let bytes = std::fs::read(file).unwrap();
        let mut stdin = child.stdin.take().unwrap();
        // (The child may stop reading at an error: a broken pipe is no failure here.)
        let writer = std::thread::spawn(move || {
            let _ = stdin.write_all(&bytes);
        });
        let out = child.wait_with_output().unwrap();
        writer.join().unwrap();
        (
            out.status.code().unwrap_or(-1),
            String::from_utf8_lossy(&out.stdout).into_owned(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    };
    let plain = write("long.csv", &lines);
    // The whole-file path (`--plot` holds the recording).
    let svg = scratch.join_str("long.svg");
    let whole = run(&plain, &["--json", "--keep-spikes", "--plot", &svg]);
    assert_eq!(whole.0, 0, "{}", whole.2);
    assert_eq!(run_stdin(&plain, &["--json", "--keep-spikes"]).1, whole.1);
    let v: serde_json::Value = serde_json::from_str(&whole.1).unwrap();
    assert!(v["impacts"][0]["cor"].is_number(), "{v}");
    assert_eq!(run(&plain, &["--json", "--keep-spikes"]).1, whole.1);
    assert_eq!(run(&plain, &["--json", "--stream"]).1, whole.1);

    // Quoted fields, a blank line, `\r\n` and spaces past the head.
    let mut odd = lines.clone();
    for (at, how) in [
        (100_000, 0),
        (100_001, 1),
        (150_000, 2),
        (150_100, 3),
        (200_000, 0),
    ] {
        let (t, a) = odd[at].split_once(',').unwrap();
        odd[at] = match how {
            0 => format!("\"{t}\",\"{a}\""),
            1 => format!("{t},{a}\r"),
            2 => format!(" {t} , {a}"),
            _ => format!("{t},{a}\n"),
        };
    }
    let odd = write("odd.csv", &odd);
    assert_eq!(run_stdin(&odd, &["--json", "--keep-spikes"]).1, whole.1);
    assert_eq!(run_stdin(&odd, &["--json", "--stream"]).1, whole.1);
    assert_eq!(run(&odd, &["--json", "--keep-spikes"]).1, whole.1);
    assert_eq!(run(&odd, &["--json", "--stream"]).1, whole.1);
    // The whole-file path from the pipe draws the same figure.
    let piped_svg = scratch.join_str("long-piped.svg");
    let piped = run_stdin(&odd, &["--json", "--keep-spikes", "--plot", &piped_svg]);
    assert_eq!(piped.1, whole.1, "{}", piped.2);
    // (Titled with what was read: `-` or the file's name.)
    assert_eq!(
        common::untitled(&std::fs::read_to_string(&piped_svg).unwrap()).1,
        common::untitled(&std::fs::read_to_string(&svg).unwrap()).1
    );

    // A text field and a gap, far past the head: the whole-file reader's message and line.
    let mut text = lines.clone();
    text[250_000] = text[250_000].replace(',', ",x");
    let text = write("text.csv", &text);
    let (code, _, err) = run(&text, &["--stream"]);
    let (_, _, passes_err) = run(&text, &[]);
    assert!(code != 0 && err.contains(":250001: not a number"), "{err}");
    assert_eq!(err, passes_err);
    let (_, _, stdin_err) = run_stdin(&text, &[]);
    assert_eq!(stdin_err, err.replace(&text, "stdin"));
    let (_, _, whole_err) = run(&text, &["--plot", &svg]);
    assert_eq!(whole_err, err);
    // A line longer than the readers take, far past the head (the sequential reader takes
    // over there): the same message at its line, from the file and through the pipe.
    let mut long = lines.clone();
    long[250_000].push_str(&" ".repeat(2 << 20));
    let long = write("long-line.csv", &long);
    let (code, _, err) = run(&long, &[]);
    assert!(code != 0 && err.contains(":250001: "), "{err}");
    assert_eq!(run_stdin(&long, &[]).2, err.replace(&long, "stdin"));
    // A byte-order mark shifts every byte the readers hand over at by three.
    let mut marked = lines.clone();
    marked[0].insert(0, '\u{feff}');
    let marked = write("bom-long.csv", &marked);
    assert_eq!(run_stdin(&marked, &["--json", "--keep-spikes"]).1, whole.1);
    let mut gap = lines.clone();
    gap.remove(240_000);
    let gap = write("gap-long.csv", &gap);
    let (code, _, err) = run(&gap, &["--stream"]);
    assert!(
        code != 0 && err.contains(":240001: uneven") && err.contains("uneven time axis"),
        "{err}"
    );
    let (code, _, stdin_err) = run_stdin(&gap, &["--stream"]);
    assert_eq!((code, stdin_err), (1, err.replace(&gap, "stdin")));
}

/// A TDMS channel read a range at a time: the whole file's reports, either channel type;
/// a file cut short is one line naming it.
#[test]
fn tdms_streams_give_the_whole_files_reports() {
    let scratch = Scratch::new();
    let tdms = concat!(env!("CARGO_MANIFEST_DIR"), "/fixtures/afrl-test1.tdms");
    for (column, gain, range) in [
        ("afrl/bottom_kgn", "1", "40000kgn"),
        ("top_codes", "0.001", "40kgn"),
    ] {
        let args = |tail: &'static str| -> Vec<&str> {
            [
                "analyze",
                tdms,
                "--column",
                column,
                "--gain",
                gain,
                "--units",
                "kgn",
                "--range",
                range,
                "--trigger",
                "20000",
                "--json",
                tail,
            ]
            .to_vec()
        };
        let (whole, _) = impact(&args("--keep-spikes"));
        assert_eq!(impact(&args("--stream")).0, whole, "{column}");
        assert!(whole.contains("peak_time_s"), "{column}: no impact");
    }
    let bytes = std::fs::read(tdms).unwrap();
    let cut = scratch.join_str("cut.tdms");
    std::fs::write(&cut, &bytes[..bytes.len() / 3]).unwrap();
    let (code, _, err) = common::impact(&[
        "analyze",
        &cut,
        "--stream",
        "--range",
        "40000g",
        "--trigger",
        "20000",
    ]);
    assert!(
        code != 0 && err.contains("cut.tdms") && err.trim().lines().count() == 1,
        "{err}"
    );
}
