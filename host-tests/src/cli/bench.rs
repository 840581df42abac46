//! `impact bench …`: the benchmarks' options and their printed output (the measuring is in
//! [`crate::bench`]).

use std::path::PathBuf;
use std::time::Duration;

use clap::Subcommand;

use crate::bench::{m4, precision, realtime, soak, stability, throughput, two_body, BenchError};
use crate::firmware_link::memory;

#[derive(Subcommand)]
pub enum Bench {
    /// Numerical stability sweep: where each solver is trustworthy.
    Stability {
        /// The full grid (slower) instead of the CI one.
        #[arg(long)]
        full: bool,
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
    /// A long stream with many impacts through the pipeline: every one must be reported.
    Soak {
        /// Samples in the stream.
        #[arg(long, default_value_t = 1_000_000_000)]
        samples: u64,
        /// Samples between two impacts.
        #[arg(long, default_value_t = 100_000)]
        spacing: u64,
        /// Samples per impact pulse.
        #[arg(long, default_value_t = 500)]
        pulse: u64,
    },
    /// Cost on the Cortex-M4F (QEMU, exact instruction counts): per sample, per impact, per
    /// solve and fit, and the maths back-ends.
    M4(m4::M4Args),
    /// The firmware in real-time emulation on trains of impacts: report latency, and the
    /// highest impact rate with nothing lost and every impact analysed, with and without fits.
    Realtime(realtime::RealtimeArgs),
    /// Host throughput: the pipeline over a long in-memory stream with many impacts (one
    /// core), and `impact analyze` end to end on a large CSV with its peak memory.
    Throughput {
        /// Samples in the stream.
        #[arg(long, default_value_t = 100_000_000)]
        samples: usize,
        /// Impacts in the stream.
        #[arg(long, default_value_t = 2000)]
        impacts: usize,
        /// Samples per block.
        #[arg(long, default_value_t = 256)]
        block: usize,
        /// Rows of the CSV given to `impact analyze`.
        #[arg(long, default_value_t = 20_000_000)]
        csv_rows: usize,
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
    /// Host cost of the streaming pipeline per sample (idle, in impact) and per report.
    Pipeline {
        /// Samples per block (the firmware hands over DMA halves of 256).
        #[arg(long, default_value_t = 256)]
        block: usize,
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
    /// The firmware's memory budget from its ELF: flash, stack, statics, CCM RAM.
    Memory {
        /// The firmware ELF [default: the board's, built with `cargo fw`].
        #[arg(long)]
        elf: Option<PathBuf>,
        /// Its memory map [default: firmware/stm32/board-memory.x].
        #[arg(long)]
        map: Option<PathBuf>,
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
    /// Time per impact against error for every model, solver and setting (CSV + SVG).
    Precision {
        /// Directory for work-precision.csv and work-precision.svg.
        #[arg(long, default_value = "target/bench")]
        out: PathBuf,
        /// Minimum timing per point, ms.
        #[arg(long, default_value_t = 20)]
        budget_ms: u64,
        /// Print the points as JSON instead of a table.
        #[arg(long)]
        json: bool,
    },
}

/// Runs one benchmark and prints its results.
pub fn run(which: Bench) -> Result<(), BenchError> {
    match which {
        Bench::Realtime(args) => {
            let results = realtime::run(&args)?;
            if args.json {
                crate::outln!("{}", serde_json::to_string_pretty(&results)?);
            } else {
                crate::out!("{}", realtime::table(&results));
            }
        }
        Bench::M4(args) => {
            let (report, profile) = m4::run(&args)?;
            if args.json {
                crate::outln!("{}", serde_json::to_string_pretty(&report)?);
            } else {
                crate::out!("{}", m4::table(&report));
            }
            if !profile.is_empty() {
                crate::err!("{profile}");
            }
            if let Some(path) = &args.check {
                let text = std::fs::read_to_string(path).map_err(|source| BenchError::File {
                    path: path.clone(),
                    source,
                })?;
                let baseline: m4::M4Report =
                    serde_json::from_str(&text).map_err(|source| BenchError::Baseline {
                        path: path.clone(),
                        source,
                    })?;
                crate::err!("{}", m4::check(&report, &baseline)?);
                crate::errln!("M4 instruction counts within 10 % of {}", path.display());
            }
        }
        Bench::Throughput {
            samples,
            impacts,
            block,
            csv_rows,
            json,
        } => {
            let exe = std::env::current_exe().map_err(BenchError::Io)?;
            let r = throughput::throughput(samples, impacts, block, csv_rows, &exe)?;
            if json {
                crate::outln!("{}", serde_json::to_string_pretty(&r)?);
            } else {
                crate::outln!(
                    "pipeline: {} samples, {} impacts (all reported) in {:.3} s on one core: {:.3e} samples/s best of 3, {:.3e} median (target 1e9)",
                    r.samples, r.impacts_reported, r.seconds, r.samples_per_second, r.median_samples_per_second
                );
                let a = &r.analyze;
                crate::outln!(
                    "impact analyze: {} rows ({:.0} MB CSV), {} impacts in {:.2} s: {:.3e} rows/s, {:.0} MB/s, peak memory {:.0} MiB",
                    a.rows, a.bytes as f64 / 1e6, a.impacts_reported, a.seconds, a.rows_per_second, a.megabytes_per_second, a.peak_rss_mib
                );
                for f in &r.formats {
                    crate::outln!(
                        "  {:<3} {:<6} {:>5.0} MB in {:>5.2} s: {:>5.0} MB/s, {:.3e} samples/s, peak memory {:>4.0} MiB",
                        f.format,
                        f.path,
                        f.bytes as f64 / 1e6,
                        f.seconds,
                        f.megabytes_per_second,
                        f.samples_per_second,
                        f.peak_rss_mib
                    );
                }
                if r.peers.is_empty() {
                    crate::outln!("  peers: none (python3 with pandas and numpy not found)");
                }
                for p in &r.peers {
                    crate::outln!(
                        "  peer {} on the {}: {:.2} s, {:.0} MB/s (reading only)",
                        p.tool,
                        p.format,
                        p.seconds,
                        p.megabytes_per_second
                    );
                }
            }
        }
        Bench::Stability { full, json } => {
            let mut rows = stability::run(full);
            rows.extend(two_body::stability(full));
            if json {
                crate::outln!("{}", serde_json::to_string_pretty(&rows)?);
            } else {
                crate::out!("{}", stability::table(&rows));
            }
            let failures = stability::failures(&rows);
            if failures > 0 {
                return Err(BenchError::Stability { failures });
            }
        }
        Bench::Soak {
            samples,
            spacing,
            pulse,
        } => {
            let r = soak::run(samples, spacing, pulse)?;
            crate::outln!("{}", serde_json::to_string_pretty(&r)?);
            if r.impacts_reported != r.impacts_inserted || r.mismatched != 0 || r.samples != samples
            {
                return Err(BenchError::Soak {
                    inserted: r.impacts_inserted,
                    reported: r.impacts_reported,
                    mismatched: r.mismatched,
                });
            }
        }
        Bench::Memory { elf, map, json } => {
            let (default_elf, default_map) = match (&elf, &map) {
                (Some(e), Some(m)) => (e.clone(), m.clone()),
                _ => memory::board_elf()?,
            };
            let b = memory::budget(
                elf.as_deref().unwrap_or(&default_elf),
                map.as_deref().unwrap_or(&default_map),
            )?;
            if json {
                crate::outln!("{}", serde_json::to_string_pretty(&b)?);
            } else {
                crate::out!("{}", memory::table(&b));
            }
        }
        Bench::Pipeline { block, json } => {
            let c = throughput::measure(block)?;
            if json {
                crate::outln!("{}", serde_json::to_string_pretty(&c)?);
            } else {
                crate::outln!(
                    "streaming pipeline on this host, blocks of {} samples:",
                    c.block
                );
                crate::outln!(
                    "  idle                {:8.2} ns/sample ({:.3e} samples/s)",
                    c.idle_ns_per_sample,
                    c.idle_samples_per_second
                );
                crate::outln!(
                    "  inside an impact    {:8.2} ns/sample (report included)",
                    c.impact_ns_per_sample
                );
                crate::outln!("  fits                {:8.1} µs/impact (8000 samples; two-phase, nonlinear with n, Hertz)", c.fits_us_per_impact);
            }
        }
        Bench::Precision {
            out,
            budget_ms,
            json,
        } => {
            let mut points = precision::run(
                &precision::standard_cases(),
                Duration::from_millis(budget_ms),
            );
            points.extend(two_body::precision(Duration::from_millis(budget_ms)));
            std::fs::create_dir_all(&out).map_err(|source| BenchError::File {
                path: out.clone(),
                source,
            })?;
            let csv_path = out.join("work-precision.csv");
            std::fs::write(&csv_path, precision::csv(&points)).map_err(|source| {
                BenchError::File {
                    path: csv_path.clone(),
                    source,
                }
            })?;
            let svg_path = out.join("work-precision.svg");
            precision::work_precision(&points, &svg_path)?;
            if json {
                crate::outln!("{}", serde_json::to_string_pretty(&points)?);
            } else {
                crate::out!("{}", precision::table(&points));
                crate::out!("{}", precision::summary(&points, 1e-9));
                crate::outln!("wrote {} and {}", csv_path.display(), svg_path.display());
            }
        }
    }
    Ok(())
}
