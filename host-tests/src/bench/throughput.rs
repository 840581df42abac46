//! Host cost of the streaming pipeline: nanoseconds per sample while idle and inside impacts.

use std::time::Instant;

use impact_core::{Calibration, FitSet, ImpactReport, Monitor, Scene};
use serde::Serialize;

use super::BenchError;

/// Measured costs.
#[derive(Clone, Debug, Serialize)]
pub struct PipelineCost {
    /// Block size used (the firmware's DMA half).
    pub block: usize,
    /// Idle path, ns per sample.
    pub idle_ns_per_sample: f64,
    /// Inside an impact, ns per sample, everything included (capture, running sums, end
    /// detection, and the end-of-impact report spread over the impact's samples).
    pub impact_ns_per_sample: f64,
    /// The two-phase, nonlinear (n fitted) and Hertz fits, µs per 8000-sample impact.
    pub fits_us_per_impact: f64,
    /// Samples per second on one core, idle stream.
    pub idle_samples_per_second: f64,
}

type M = Monitor<4096, 16384>;

fn scene(fits: bool) -> Scene {
    let mut s = Scene::new(
        Calibration {
            gain_m_s2_per_count: 0.39,
            sample_rate_hz: 500_000.0,
        },
        10.0,
    );
    s.edge_m_s2 = 2.0;
    s.hold_s = 1e-3;
    s.mass_kg = Some(0.06);
    // Δv of the test pulse is ~0.4 m/s: v0 = 0.2 m/s gives a crush and a rebound.
    s.approach = impact_core::Approach::Speed { v0_m_s: 0.2 };
    // Every pulse of the stream is a strike at that speed.
    s.v0_every = true;
    s.fits = if fits { FitSet::all() } else { FitSet::none() };
    s
}

/// Runs the measurements (a few seconds).
pub fn measure(block: usize) -> Result<PipelineCost, BenchError> {
    super::on_big_stack(move || measure_inner(block))
}

fn measure_inner(block: usize) -> Result<PipelineCost, BenchError> {
    let block = block.max(1);
    // Idle: 2^24 samples of ±1-count noise around 2065.
    let idle: Vec<i16> = (0..1u32 << 24)
        .map(|k| 2065 + ((k.wrapping_mul(2_654_435_761) >> 30) as i16 - 1))
        .collect();
    let mut m = M::new(scene(false))?;
    let mut count = 0u32;
    let t = Instant::now();
    for b in idle.chunks(block) {
        m.push_block(std::hint::black_box(b), &mut |_r: &ImpactReport| count += 1);
    }
    let idle_s = t.elapsed().as_secs_f64();
    if count != 0 {
        return Err(BenchError::NoiseTriggered { count });
    }
    let idle_ns = idle_s * 1e9 / idle.len() as f64;

    // Impacts: 200 half-sine pulses of 8000 samples (100 counts peak), 2000 quiet samples apart.
    let pulse: Vec<i16> = (0..8000)
        .map(|k| 2065 + (100.0 * (std::f64::consts::PI * k as f64 / 8000.0).sin()) as i16)
        .collect();
    let mut stream: Vec<i16> = vec![2065; 8192];
    for _ in 0..200 {
        stream.extend(&pulse);
        stream.extend(std::iter::repeat_n(2065i16, 2000));
    }
    let run = |fits: bool| -> Result<(f64, u32), BenchError> {
        let mut m = M::new(scene(fits))?;
        let mut n = 0u32;
        let t = Instant::now();
        for b in stream.chunks(block) {
            m.push_block(std::hint::black_box(b), &mut |_r: &ImpactReport| n += 1);
        }
        Ok((t.elapsed().as_secs_f64(), n))
    };
    let (plain_s, n) = run(false)?;
    let (fits_s, n2) = run(true)?;
    if n != 200 || n2 != 200 {
        return Err(BenchError::Impacts200 { plain: n, fits: n2 });
    }
    // In-impact samples: the pulses plus the hold; the rest is idle at idle cost.
    let in_impact = 200.0 * (8000.0 + 500.0);
    let idle_part = (stream.len() as f64 - in_impact) * idle_ns * 1e-9;
    let c = (plain_s - idle_part) / in_impact;
    let fits = ((fits_s - plain_s) / 200.0).max(0.0);
    Ok(PipelineCost {
        block,
        idle_ns_per_sample: idle_ns,
        impact_ns_per_sample: c * 1e9,
        fits_us_per_impact: fits * 1e6,
        idle_samples_per_second: 1e9 / idle_ns,
    })
}

/// `impact bench throughput`: the pipeline over a long in-memory stream, and `impact analyze`
/// end to end on a large CSV.
#[derive(Clone, Debug, Serialize)]
pub struct Throughput {
    /// Samples streamed (in memory, blocks of `block`).
    pub samples: u64,
    pub block: usize,
    pub impacts_inserted: u64,
    pub impacts_reported: u64,
    /// Wall time of the pipeline over the stream, s (one core, best of three runs).
    pub seconds: f64,
    pub samples_per_second: f64,
    /// The median of the three runs.
    pub median_samples_per_second: f64,
    /// `impact analyze` on a CSV of the stream's first samples, parsing included.
    pub analyze: AnalyzeThroughput,
    /// The same samples per format and path (passes, `--stream`, standard input).
    pub formats: Vec<FormatThroughput>,
    /// Peers reading the same files in the same run (absent when not installed).
    pub peers: Vec<PeerThroughput>,
}

#[derive(Clone, Debug, Serialize)]
pub struct AnalyzeThroughput {
    pub rows: u64,
    pub bytes: u64,
    pub impacts_reported: u64,
    pub seconds: f64,
    pub rows_per_second: f64,
    pub megabytes_per_second: f64,
    /// Peak resident memory of the `impact analyze` process, MiB.
    pub peak_rss_mib: f64,
}

/// A quiet stream (±1 count of noise around mid-scale) with `impacts` half-sine pulses of 500
/// samples and 150 counts (about 60 m/s² at the board's gain), evenly spaced.
pub fn impact_stream(samples: usize, impacts: usize) -> Vec<i16> {
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut v: Vec<i16> = (0..samples)
        .map(|_| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            2048 + (state >> 62) as i16 - 1
        })
        .collect();
    let spacing = samples / impacts.max(1);
    for i in 0..impacts {
        let at = i * spacing + spacing / 2;
        for k in 0..500 {
            if let Some(x) = v.get_mut(at + k) {
                *x += (150.0 * (std::f64::consts::PI * k as f64 / 500.0).sin()) as i16;
            }
        }
    }
    v
}

fn stream_scene() -> Scene {
    let mut s = Scene::new(
        Calibration {
            gain_m_s2_per_count: 1600.0 / 4096.0,
            sample_rate_hz: 500_000.0,
        },
        10.0,
    );
    s.edge_m_s2 = 2.0;
    s.hold_s = 2e-3;
    s.mass_kg = Some(0.06);
    s.approach = impact_core::Approach::Speed { v0_m_s: 0.1 };
    s.v0_every = true;
    s.fits = FitSet::none();
    s
}

/// Runs the stream through the pipeline, then `analyze_exe analyze` on the first
/// `csv_rows` samples written as CSV.
pub fn throughput(
    samples: usize,
    impacts: usize,
    block: usize,
    csv_rows: usize,
    analyze_exe: &std::path::Path,
) -> Result<Throughput, BenchError> {
    let block = block.max(1);
    let stream = impact_stream(samples, impacts);
    // Best of three runs (a fresh monitor each), the usual way to quote a throughput on a
    // machine shared with other work; the median is kept beside it.
    let mut runs = Vec::new();
    for _ in 0..3 {
        runs.push(super::on_big_stack({
            let stream = stream.clone();
            move || -> Result<(f64, u64), BenchError> {
                let mut m = M::new(stream_scene())?;
                let mut n = 0u64;
                let t = Instant::now();
                for b in stream.chunks(block) {
                    m.push_block(std::hint::black_box(b), &mut |_r: &ImpactReport| n += 1);
                }
                m.finish(&mut |_r: &ImpactReport| n += 1);
                Ok((t.elapsed().as_secs_f64(), n))
            }
        })?);
    }
    runs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (seconds, reported) = runs[0];
    let median_seconds = runs[1].0;
    if let Some(r) = runs.iter().find(|r| r.1 != reported) {
        return Err(BenchError::RunsDisagree {
            first: reported,
            other: r.1,
        });
    }
    if reported != impacts as u64 {
        return Err(BenchError::Lost {
            inserted: impacts,
            reported,
        });
    }
    let (analyze, formats, peers) = analyze_files(
        &stream[..csv_rows.min(stream.len())],
        &stream,
        impacts,
        samples,
        analyze_exe,
    )?;
    Ok(Throughput {
        samples: samples as u64,
        block,
        impacts_inserted: impacts as u64,
        impacts_reported: reported,
        seconds,
        samples_per_second: samples as f64 / seconds,
        median_samples_per_second: samples as f64 / median_seconds,
        analyze,
        formats,
        peers,
    })
}

/// `impact analyze` on one file: its form, how fast, in how much memory.
#[derive(Clone, Debug, Serialize)]
pub struct FormatThroughput {
    /// `csv` or `i16`.
    pub format: String,
    /// How `impact analyze` read it: `passes` (a regular file, the default), `stream`
    /// (`--stream`, levels given) or `stdin` (in passes from standard input: parsed by one
    /// thread, the values kept in a temporary file for the later passes).
    pub path: String,
    pub bytes: u64,
    pub seconds: f64,
    pub megabytes_per_second: f64,
    pub samples_per_second: f64,
    /// Peak resident memory of the `impact analyze` process, MiB.
    pub peak_rss_mib: f64,
}

/// A peer reading the same file in the same run: pandas' `read_csv` (C engine) on the CSV,
/// numpy's `fromfile` on the raw file (reading only, no analysis).
#[derive(Clone, Debug, Serialize)]
pub struct PeerThroughput {
    pub tool: String,
    pub format: String,
    pub seconds: f64,
    pub megabytes_per_second: f64,
}

/// Runs `exe ARGS` to the end: its stdout, wall time and peak resident memory, MiB (the
/// child's own VmHWM, which it prints with IMPACT_PEAK_MEMORY set: wait4's ru_maxrss counts
/// this process's memory at the fork too).
fn run_child(
    exe: &std::path::Path,
    args: &[&str],
    stdin: Option<&std::path::Path>,
) -> Result<(String, f64, f64), BenchError> {
    let input = match stdin {
        Some(p) => std::fs::File::open(p).map_err(super::file(p))?.into(),
        None => std::process::Stdio::null(),
    };
    let t = Instant::now();
    let child = std::process::Command::new(exe)
        .env("IMPACT_PEAK_MEMORY", "1")
        .args(args)
        .stdin(input)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .map_err(super::file(exe))?;
    let _child = crate::interrupt::child(child.id());
    let out = child.wait_with_output().map_err(BenchError::Io)?;
    let seconds = t.elapsed().as_secs_f64();
    let stderr = String::from_utf8_lossy(&out.stderr);
    if !out.status.success() {
        return Err(BenchError::ChildFailed {
            exe: exe.to_path_buf(),
            args: args.join(" "),
            stderr: stderr.trim().to_string(),
        });
    }
    let kib: f64 = stderr
        .lines()
        .find_map(|l| l.strip_prefix("peak memory: "))
        .and_then(|v| v.trim_end_matches("kB").trim().parse().ok())
        .ok_or(BenchError::NoPeakMemory)?;
    Ok((
        String::from_utf8_lossy(&out.stdout).into_owned(),
        seconds,
        kib / 1024.0,
    ))
}

/// A peer's own timing of reading `path`, from the Python one-liner `code` (printing the
/// seconds), or `None` when Python or the library is missing (CI has no network).
fn peer(code: &str, path: &std::path::Path) -> Option<f64> {
    let out = std::process::Command::new("python3")
        .args(["-c", code])
        .arg(path)
        .output()
        .ok()?;
    if !out.status.success() {
        return None;
    }
    String::from_utf8_lossy(&out.stdout).trim().parse().ok()
}

/// `impact analyze` on `counts` written as CSV (in passes from the file and from standard
/// input, and `--stream`) and on the `long`
/// stream as raw i16 (`--stream`; long enough that starting the process does not count),
/// and the peers reading the same files.
fn analyze_files(
    counts: &[i16],
    long: &[i16],
    impacts: usize,
    samples: usize,
    exe: &std::path::Path,
) -> Result<
    (
        AnalyzeThroughput,
        Vec<FormatThroughput>,
        Vec<PeerThroughput>,
    ),
    BenchError,
> {
    use std::io::Write;
    let dir = std::env::temp_dir();
    let csv = dir.join(format!("impact-throughput-{}.csv", std::process::id()));
    let raw = dir.join(format!("impact-throughput-{}.i16", std::process::id()));
    let _temporaries = [&csv, &raw].map(|p| crate::interrupt::temporary(p));
    let result = (|| {
        let file = std::fs::File::create(&csv).map_err(super::file(&csv))?;
        let mut w = std::io::BufWriter::with_capacity(1 << 20, file);
        let gain_g = 1600.0 / 4096.0 / impact_core::consts::STANDARD_GRAVITY;
        writeln!(w, "time_s,accel_g").map_err(BenchError::Io)?;
        for (k, &c) in counts.iter().enumerate() {
            writeln!(
                w,
                "{:.7},{:.5}",
                k as f64 * 2e-6,
                (c as f64 - 2048.0) * gain_g
            )
            .map_err(BenchError::Io)?;
        }
        w.flush().map_err(BenchError::Io)?;
        drop(w);
        let bytes: Vec<u8> = long.iter().flat_map(|c| c.to_le_bytes()).collect();
        std::fs::write(&raw, bytes).map_err(super::file(&raw))?;
        let size = |p: &std::path::Path| std::fs::metadata(p).map(|m| m.len()).unwrap_or(0);
        let check = |out: &str, rows: usize| -> Result<u64, BenchError> {
            let expected = (impacts as u64 * rows as u64) / samples.max(1) as u64;
            let v: serde_json::Value =
                serde_json::from_str(out).map_err(BenchError::AnalyzeJson)?;
            let reported = v["impacts"].as_array().map_or(0, |a| a.len()) as u64;
            if reported.abs_diff(expected) > 1 {
                return Err(BenchError::Reported { reported, expected });
            }
            Ok(reported)
        };
        let (csv_s, raw_s) = (csv.to_string_lossy(), raw.to_string_lossy());
        // The stream's levels: the ADC's full scale (±2048 codes) and a 20 m/s² trigger.
        let range_g = format!("{}", 2048.0 * gain_g);
        let gain = format!("{gain_g}");
        let csv_args = ["analyze", &*csv_s, "--json"];
        let raw_args = [
            "analyze", &*raw_s, "--json", "--rate", "500000", "--gain", &*gain,
        ];
        let stream_csv = ["--stream", "--range", &*range_g, "--trigger", "20"];
        let stream_raw = ["--stream", "--range", "4096", "--trigger", "20"];
        let runs: [(&str, &str, Vec<&str>, Option<&std::path::Path>); 5] = [
            ("csv", "passes", csv_args.to_vec(), None),
            ("csv", "stream", [&csv_args[..], &stream_csv].concat(), None),
            ("csv", "stdin", vec!["analyze", "-", "--json"], Some(&csv)),
            ("i16", "passes", raw_args.to_vec(), None),
            ("i16", "stream", [&raw_args[..], &stream_raw].concat(), None),
        ];
        let mut default = None;
        let mut formats = Vec::new();
        for (format, path, args, stdin) in runs {
            let (out, seconds, peak) = run_child(exe, &args, stdin)?;
            let rows = if format == "csv" {
                counts.len()
            } else {
                long.len()
            };
            let reported = check(&out, rows)?;
            let bytes = if format == "csv" {
                size(&csv)
            } else {
                size(&raw)
            };
            if format == "csv" && path == "passes" {
                default = Some(AnalyzeThroughput {
                    rows: counts.len() as u64,
                    bytes,
                    impacts_reported: reported,
                    seconds,
                    rows_per_second: counts.len() as f64 / seconds,
                    megabytes_per_second: bytes as f64 / 1e6 / seconds,
                    peak_rss_mib: peak,
                });
            }
            formats.push(FormatThroughput {
                format: format.into(),
                path: path.into(),
                bytes,
                seconds,
                megabytes_per_second: bytes as f64 / 1e6 / seconds,
                samples_per_second: rows as f64 / seconds,
                peak_rss_mib: peak,
            });
        }
        let mut peers = Vec::new();
        let pandas = "import sys,time,pandas; t=time.perf_counter(); pandas.read_csv(sys.argv[1], engine='c'); print(time.perf_counter()-t)";
        let numpy = "import sys,time,numpy; t=time.perf_counter(); numpy.fromfile(sys.argv[1], dtype='<i2'); print(time.perf_counter()-t)";
        for (tool, format, code, path) in [
            ("pandas read_csv (C engine)", "csv", pandas, &csv),
            ("numpy fromfile", "i16", numpy, &raw),
        ] {
            if let Some(seconds) = peer(code, path) {
                peers.push(PeerThroughput {
                    tool: tool.into(),
                    format: format.into(),
                    seconds,
                    megabytes_per_second: size(path) as f64 / 1e6 / seconds,
                });
            }
        }
        let default = default.ok_or(BenchError::NoDefaultRun)?;
        Ok((default, formats, peers))
    })();
    let _ = std::fs::remove_file(&csv);
    let _ = std::fs::remove_file(&raw);
    result
}
