//! Hostile input, round four (#45), TDMS: every chunk of a TDMS segment and
//! interleaved segments read as npTDMS reads them (its numbers stored beside the files, made by
//! `scripts/make_tdms_chunk_fixtures.py`); every size a TDMS segment gives checked against the
//! bytes there. Each `impact` process runs under a 1 GiB address-space limit and a time
//! limit: no panic, no allocation failure, no hang; a one-line error naming the file.
#![cfg(unix)]

use std::path::{Path, PathBuf};
use std::process::{Child, Stdio};
use std::time::Duration;

mod common;
use common::limited::{self, Run};
use common::Scratch;

use impact_io::{ColumnRef, ReadOptions};

/// Address space each `impact` process may map.
const MEMORY_LIMIT_BYTES: u64 = 1 << 30;

/// Longest a case may run.
const TIME_LIMIT: Duration = Duration::from_secs(60);

fn fixtures() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fixtures")
}

/// Starts `impact ARGS` under [`MEMORY_LIMIT_BYTES`], with `env` set.
fn spawn(args: &[&str], env: &[(&str, &str)], stdin: Stdio) -> Child {
    limited::spawn(args, env, stdin, MEMORY_LIMIT_BYTES)
}

/// Waits for `child` (killed past [`TIME_LIMIT`]): no panic, no allocation failure, no
/// signal.
fn finish(child: Child, what: &str) -> Run {
    let run = limited::wait(child, what, TIME_LIMIT);
    assert!(
        run.code.is_some(),
        "{what}: killed by a signal: {}",
        run.err
    );
    run
}

fn run(args: &[&str], env: &[(&str, &str)]) -> Run {
    finish(spawn(args, env, Stdio::null()), &args.join(" "))
}

/// The run failed (exit 1) with one line naming the file `name` and `want`.
fn fails(args: &[&str], env: &[(&str, &str)], name: &str, want: &str) {
    let r = run(args, env);
    let what = args.join(" ");
    assert_eq!(r.code, Some(1), "{what}: {}", r.err);
    let line = r.err.trim();
    assert_eq!(line.lines().count(), 1, "{what}: {line}");
    assert!(
        line.contains(name) && line.contains(want),
        "{what}: wanted {name:?} and {want:?} in: {line}"
    );
}

/// npTDMS's read of one channel of a fixture (`peer.csv`).
struct Peer {
    file: String,
    channel: String,
    count: usize,
    sum: f64,
    /// (index, value): the first, the last and the seams of chunks and segments.
    at: Vec<(usize, f64)>,
}

fn peers() -> Vec<Peer> {
    let text = std::fs::read_to_string(fixtures().join("tdms-chunks/peer.csv")).unwrap();
    text.lines()
        .skip(1)
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            let count: usize = f[2].parse().unwrap();
            let mut at = vec![
                (0, f[4].parse().unwrap()),
                (count - 1, f[5].parse().unwrap()),
            ];
            for (k, i) in [2499, 2500, 7499, 7500].into_iter().enumerate() {
                if let Ok(v) = f[6 + k].parse() {
                    at.push((i, v));
                }
            }
            Peer {
                file: f[0].into(),
                channel: f[1].into(),
                count,
                sum: f[3].parse().unwrap(),
                at,
            }
        })
        .collect()
}

fn options(channel: &str) -> ReadOptions {
    ReadOptions {
        column: Some(ColumnRef::Name(channel.into())),
        // (`counter` and `row` have no wf_increment.)
        rate_hz: (!channel.ends_with("top_codes")).then_some(1000.0),
        ..ReadOptions::default()
    }
}

/// A segment of several chunks (its raw data size a multiple of the chunk size, as NI's
/// writers leave it) and interleaved segments (ToC bit 5) are read whole, read at once and a
/// range at a time, as npTDMS reads them: the count, the sum, the first and last values and
/// those at the seams of chunks and segments. (The multi-chunk file's `top_codes` was read to
/// its first chunk only, 2 500 of 10 000 values; the interleaved file was refused.)
#[test]
fn tdms_chunks_and_interleaved_segments_read_as_nptdms_reads_them() {
    let peers = peers();
    assert_eq!(peers.len(), 4, "peer.csv: two channels of two files");
    for p in &peers {
        let path = fixtures().join("tdms-chunks").join(&p.file);
        let what = format!("{} {}", p.file, p.channel);
        let whole = impact_io::read_recording(&path, &options(&p.channel))
            .unwrap_or_else(|e| panic!("{what}: {e}"));
        // A range at a time, in reads that end inside chunks.
        let mut source = impact_io::open_source(&path, &options(&p.channel)).unwrap();
        let mut streamed = Vec::new();
        loop {
            let before = streamed.len();
            source.next_values(777, &mut streamed).unwrap();
            if streamed.len() == before {
                break;
            }
        }
        for values in [&whole.values, &streamed] {
            assert_eq!(values.len(), p.count, "{what}: count");
            assert_eq!(values.iter().sum::<f64>(), p.sum, "{what}: sum");
            for &(i, v) in &p.at {
                assert_eq!(values[i], v, "{what}: value {i}");
            }
        }
    }
}

/// The same codes in one chunk (afrl-test1.tdms), in four chunks over two segments and
/// interleaved give the same report, whole and streamed (the multi-chunk file gave none:
/// its impact lies past the first chunk).
#[test]
fn tdms_chunks_give_the_one_chunk_files_impacts() {
    let one = fixtures().join("afrl-test1.tdms");
    let args = |file: &Path, stream: bool| {
        let mut a: Vec<String> = [
            "analyze",
            file.to_str().unwrap(),
            "--column",
            "afrl/top_codes",
            "--gain",
            "0.001",
            "--units",
            "kgn",
            "--range",
            "40kgn",
            "--trigger",
            "20000",
            "--json",
        ]
        .map(String::from)
        .to_vec();
        if stream {
            a.push("--stream".into());
        }
        a
    };
    let json = |file: &Path, stream: bool| {
        let a = args(file, stream);
        let r = run(&a.iter().map(String::as_str).collect::<Vec<_>>(), &[]);
        assert_eq!(r.code, Some(0), "{a:?}: {}", r.err);
        r.out
    };
    let reference = json(&one, false);
    assert!(
        reference.contains("peak_time_s"),
        "the fixture has an impact"
    );
    for name in ["multi-chunk.tdms", "interleaved.tdms"] {
        let file = fixtures().join("tdms-chunks").join(name);
        for stream in [false, true] {
            assert_eq!(json(&file, stream), reference, "{name}, stream {stream}");
        }
    }
}

/// Where `needle` starts in `bytes`.
fn find(bytes: &[u8], needle: &[u8]) -> usize {
    bytes
        .windows(needle.len())
        .position(|w| w == needle)
        .expect("in the fixture")
}

/// Every size a TDMS segment gives that the bytes there do not bear out is a one-line error
/// naming the file and the byte, in bounded memory and time: a value count that makes the
/// chunk larger than the data, or overflows, or leaves part of a chunk; a next-segment offset
/// past the file's end; metadata past the file or the segment; a string length past the
/// metadata; interleaved channels of different counts.
#[test]
fn tdms_sizes_that_lie_are_refused() {
    let scratch = Scratch::new();
    let multi = std::fs::read(fixtures().join("tdms-chunks/multi-chunk.tdms")).unwrap();
    let interleaved = std::fs::read(fixtures().join("tdms-chunks/interleaved.tdms")).unwrap();
    let path = b"/'afrl'/'top_codes'";
    // The value count of top_codes's raw data index: after the path, the index's length,
    // type and dimension.
    let count_at = find(&multi, path) + path.len() + 12;
    let counter = b"/'afrl'/'counter'";
    let counter_count_at = find(&multi, counter) + counter.len() + 12;
    let row = b"/'afrl'/'row'";
    let row_count_at = find(&interleaved, row) + row.len() + 12;
    let path_len_at = find(&multi, path) - 4;
    let set_u64 = |bytes: &[u8], at: usize, v: u64| {
        let mut b = bytes.to_vec();
        b[at..at + 8].copy_from_slice(&v.to_le_bytes());
        b
    };
    let set_u32 = |bytes: &[u8], at: usize, v: u32| {
        let mut b = bytes.to_vec();
        b[at..at + 4].copy_from_slice(&v.to_le_bytes());
        b
    };
    let next = u64::from_le_bytes(multi[12..20].try_into().unwrap());
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        (
            "count-2e18.tdms",
            set_u64(&multi, count_at, 1 << 62),
            "byte 0: ",
        ),
        (
            "count-overflow.tdms",
            set_u64(&multi, count_at, u64::MAX / 2 + 1),
            "more than any file holds",
        ),
        (
            "count-plus-one.tdms",
            set_u64(&multi, counter_count_at, 26),
            "no whole number of its",
        ),
        (
            "next-past-end.tdms",
            set_u64(&multi, 12, next + 1_000_000),
            "the file is cut short",
        ),
        (
            "metadata-past-end.tdms",
            set_u64(&multi, 20, u64::MAX - 100),
            "runs past the file",
        ),
        (
            "metadata-past-segment.tdms",
            set_u64(&multi, 20, next + 1),
            "beyond the segment's",
        ),
        (
            "path-4gib.tdms",
            set_u32(&multi, path_len_at, 0xFFFF_FFF0),
            "bytes announced",
        ),
        (
            "interleaved-counts.tdms",
            set_u64(&interleaved, row_count_at, 2499),
            "interleaved channels",
        ),
    ];
    for (name, bytes, want) in cases {
        let file = scratch.file(name, &bytes);
        let file = file.to_str().unwrap();
        for stream in [false, true] {
            let mut args = vec!["analyze", file, "--column", "afrl/top_codes"];
            if stream {
                args.push("--stream");
            }
            fails(&args, &[], name, want);
            fails(&args, &[], name, "TDMS: byte ");
        }
    }
    // The reader itself refuses them, in the same words (no process limits here).
    let file = scratch.file("lib.tdms", set_u64(&multi, count_at, 1 << 62));
    let e = impact_io::read_recording(&file, &options("afrl/top_codes")).unwrap_err();
    assert!(e.to_string().contains("no whole number of its"), "{e}");
}
