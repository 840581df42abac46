//! `impact`: simulate impacts, benchmark the solvers (and, next, analyse recordings).

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use clap::{Parser, Subcommand};
use impact_host::cli::{analyze, emulate, log, progress};
use impact_host::firmware_link::memory;
use impact_host::{
    m4, pipeline, precision, realtime, simulate, soak, stability, synth, throughput, two_body_bench,
};

// The examples in the help are commands of docs/user-guide.md, run by its tests.
const ANALYZE_EXAMPLES: &str = "Examples:
  impact analyze host-tests/data/afrl-drop-tower/series1_test1_full_100ms.csv
  impact analyze seed.csv --mass 0.06 --v0 1.3357 --plot seed.svg
  impact analyze train.csv --mass 0.06 --v0 1.3357 --train flight
  impact analyze host-tests/data/endaq-high-drop/High-Drop_16g-DC_full.csv --axes x_g,y_g,z_g
  impact analyze host-tests/data/afrl-drop-tower/series1_test1_full_100ms.csv --srs --json";
const EMULATE_EXAMPLES: &str = "Examples:
  impact emulate host-tests/data/afrl-drop-tower/series1_test1_full_100ms.csv --realtime
  impact emulate seed.csv --mass 0.06 --v0 1.3357 --waveforms --log board.log";
const SIMULATE_EXAMPLES: &str = "Examples:
  impact simulate --model hertz --mass 8.419e-3 --v0 2 --radius 6.35e-3 --youngs 200e9 --poisson 0.3
  impact simulate --model kelvin-voigt --mass 0.06 --v0 1.3357 --stiffness 2e5 --damping 8 --target host-tests/examples/mount.json";
const SYNTH_EXAMPLES: &str = "Examples:
  impact synth --model two-phase --mass 0.06 --v0 1.3357 --max-deformation 0.0186 --kr 12376 --permanent 0.0182 --damping 2 -o seed.csv
  impact synth --model nonlinear --mass 0.06 --v0 1.3357 --stiffness 1e4 --damping 0.5 --bounces 8 --duration 1.5 -o train.csv";
const LOG_EXAMPLES: &str = "Examples:
  impact log board.log --csv
  impact log board.log --plot board.svg";

#[derive(Parser)]
#[command(
    name = "impact",
    version,
    allow_negative_numbers = true,
    about = "Live impact monitoring: models, solvers and recorded-signal analysis",
    after_help = "Start with `impact analyze FILE`; the user guide is docs/user-guide.md."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Solve one impact of a contact model.
    #[command(allow_negative_numbers = true, after_help = SIMULATE_EXAMPLES)]
    Simulate(Box<simulate::SimulateArgs>),
    /// Analyse a recorded signal: one report per impact.
    #[command(allow_negative_numbers = true, after_help = ANALYZE_EXAMPLES)]
    Analyze(Box<pipeline::AnalyzeArgs>),
    /// Analyse a recorded signal on the emulated firmware (QEMU): the same output as `analyze`.
    #[command(
        allow_negative_numbers = true,
        after_help = EMULATE_EXAMPLES,
        // The emulator replays a recording it has read whole: no one-pass reading.
        mut_arg("stream", |a| a.hide(true))
    )]
    Emulate(Box<emulate::EmulateArgs>),
    /// Turn the firmware's defmt log into JSON (default) or CSV, its waveforms into figures.
    #[command(after_help = LOG_EXAMPLES)]
    Log(log::LogArgs),
    /// Render a model impact as an accelerometer recording (CSV on stdout or --output, raw
    /// ADC codes with --raw).
    #[command(allow_negative_numbers = true, after_help = SYNTH_EXAMPLES)]
    Synth {
        #[command(flatten)]
        args: Box<synth::SynthArgs>,
        /// Write the CSV (time_s, accel_m_s2) to this file instead of standard output.
        #[arg(short = 'o', long, help_heading = "Output", value_name = "FILE.csv")]
        output: Option<PathBuf>,
        /// Also write the raw ADC codes as little-endian i16 to this file (`impact analyze
        /// FILE.i16 --rate ...` reads it).
        #[arg(long, help_heading = "Output", value_name = "FILE.i16")]
        raw: Option<PathBuf>,
    },
    /// Benchmarks.
    Bench {
        #[command(subcommand)]
        which: Bench,
    },
}

#[derive(Subcommand)]
enum Bench {
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

/// A closed output pipe (`impact … | head -1`) ends the tool quietly, as it does any Unix
/// filter, instead of panicking in `println!` (Rust ignores SIGPIPE by default).
#[cfg(unix)]
fn restore_sigpipe() {
    // SAFETY: sets the default disposition of one signal before any thread starts.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

fn main() -> ExitCode {
    #[cfg(unix)]
    restore_sigpipe();
    // clap's own message on a usage error (the accepted values, the usage line, a hint),
    // exit status 2; help and version on stdout, status 0.
    let cli = Cli::parse();
    // The docs' tests check that every documented command parses (tests/docs.rs).
    if std::env::var_os("IMPACT_PARSE_ONLY").is_some() {
        return ExitCode::SUCCESS;
    }
    let result = run(cli);
    progress::finish();
    // For benchmarks and tests: this process's own peak memory (VmHWM: the address space
    // since exec; wait4's ru_maxrss would include the parent's at the fork).
    if std::env::var_os("IMPACT_PEAK_MEMORY").is_some() {
        let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
        if let Some(line) = status.lines().find(|l| l.starts_with("VmHWM:")) {
            eprintln!("peak memory: {}", line.trim_start_matches("VmHWM:").trim());
        }
    }
    match result {
        Ok(()) => {
            for note in impact_host::take_notes() {
                eprintln!("note: {note}");
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(1)
        }
    }
}

fn run(cli: Cli) -> Result<(), String> {
    match cli.command {
        Command::Simulate(args) => {
            fn json<T: serde::Serialize>(v: &T) -> Result<String, String> {
                serde_json::to_string(v).map_err(|e| e.to_string())
            }
            match simulate::run_any(&args)? {
                simulate::Outcome::Wall(report) if args.json => println!("{}", json(&report)?),
                simulate::Outcome::Wall(report) => print!("{}", simulate::table(&report)),
                simulate::Outcome::Target(report) if args.json => println!("{}", json(&*report)?),
                simulate::Outcome::Target(report) => {
                    print!("{}", simulate::two_body::table(&report))
                }
            }
        }
        Command::Analyze(args) => analyze::run(&args)?,
        Command::Emulate(args) => emulate::emulate(&args)?,
        Command::Log(args) => log::log(&args)?,
        Command::Synth { args, output, raw } => {
            if let (Some(o), Some(r)) = (&output, &raw) {
                if o == r {
                    return Err(format!("--output and --raw are both {}", o.display()));
                }
            }
            let rec = synth::synth(&args)?;
            if let Some(path) = raw {
                let bytes: Vec<u8> = rec.samples.iter().flat_map(|c| c.to_le_bytes()).collect();
                std::fs::write(&path, bytes).map_err(|e| format!("{}: {e}", path.display()))?;
            }
            match output {
                Some(path) => {
                    let file = std::fs::File::create(&path)
                        .map_err(|e| format!("{}: {e}", path.display()))?;
                    let mut out = std::io::BufWriter::with_capacity(1 << 16, file);
                    synth::write_csv(&rec, &args, &mut out)
                        .and_then(|()| std::io::Write::flush(&mut out))
                        .map_err(|e| format!("{}: {e}", path.display()))?;
                }
                None => {
                    let stdout = std::io::stdout().lock();
                    synth::write_csv(
                        &rec,
                        &args,
                        &mut std::io::BufWriter::with_capacity(1 << 16, stdout),
                    )
                    .map_err(|e| format!("stdout: {e}"))?;
                }
            }
        }
        Command::Bench {
            which: Bench::Realtime(args),
        } => {
            let results = realtime::run(&args)?;
            if args.json {
                println!(
                    "{}",
                    serde_json::to_string_pretty(&results).map_err(|e| e.to_string())?
                );
            } else {
                print!("{}", realtime::table(&results));
            }
        }
        Command::Bench {
            which: Bench::M4(args),
        } => {
            let (report, profile) = m4::run(&args)?;
            if args.json {
                println!(
                    "{}",
                    serde_json::to_string_pretty(&report).map_err(|e| e.to_string())?
                );
            } else {
                print!("{}", m4::table(&report));
            }
            if !profile.is_empty() {
                eprint!("{profile}");
            }
            if let Some(path) = &args.check {
                let text = std::fs::read_to_string(path)
                    .map_err(|e| format!("{}: {e}", path.display()))?;
                let baseline: m4::M4Report =
                    serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))?;
                eprint!("{}", m4::check(&report, &baseline)?);
                eprintln!("M4 instruction counts within 10 % of {}", path.display());
            }
        }
        Command::Bench {
            which:
                Bench::Throughput {
                    samples,
                    impacts,
                    block,
                    csv_rows,
                    json,
                },
        } => {
            let exe = std::env::current_exe().map_err(|e| e.to_string())?;
            let r = throughput::throughput(samples, impacts, block, csv_rows, &exe)?;
            if json {
                println!(
                    "{}",
                    serde_json::to_string_pretty(&r).map_err(|e| e.to_string())?
                );
            } else {
                println!(
                    "pipeline: {} samples, {} impacts (all reported) in {:.3} s on one core: {:.3e} samples/s best of 3, {:.3e} median (target 1e9)",
                    r.samples, r.impacts_reported, r.seconds, r.samples_per_second, r.median_samples_per_second
                );
                let a = &r.analyze;
                println!(
                    "impact analyze: {} rows ({:.0} MB CSV), {} impacts in {:.2} s: {:.3e} rows/s, {:.0} MB/s, peak memory {:.0} MiB",
                    a.rows, a.bytes as f64 / 1e6, a.impacts_reported, a.seconds, a.rows_per_second, a.megabytes_per_second, a.peak_rss_mib
                );
                for f in &r.formats {
                    println!(
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
                    println!("  peers: none (python3 with pandas and numpy not found)");
                }
                for p in &r.peers {
                    println!(
                        "  peer {} on the {}: {:.2} s, {:.0} MB/s (reading only)",
                        p.tool, p.format, p.seconds, p.megabytes_per_second
                    );
                }
            }
        }
        Command::Bench {
            which: Bench::Stability { full, json },
        } => {
            let mut rows = stability::run(full);
            rows.extend(two_body_bench::stability(full));
            if json {
                println!(
                    "{}",
                    serde_json::to_string_pretty(&rows).map_err(|e| e.to_string())?
                );
            } else {
                print!("{}", stability::table(&rows));
            }
            let failures = stability::failures(&rows);
            if failures > 0 {
                return Err(format!(
                    "bench stability: {failures} results outside their stated bounds or not finite"
                ));
            }
        }
        Command::Bench {
            which:
                Bench::Soak {
                    samples,
                    spacing,
                    pulse,
                },
        } => {
            let r = soak::run(samples, spacing, pulse)?;
            println!(
                "{}",
                serde_json::to_string_pretty(&r).map_err(|e| e.to_string())?
            );
            if r.impacts_reported != r.impacts_inserted || r.mismatched != 0 || r.samples != samples
            {
                return Err(format!(
                    "soak: {} impacts inserted, {} reported, {} mismatched",
                    r.impacts_inserted, r.impacts_reported, r.mismatched
                ));
            }
        }
        Command::Bench {
            which: Bench::Memory { elf, map, json },
        } => {
            let (default_elf, default_map) = match (&elf, &map) {
                (Some(e), Some(m)) => (e.clone(), m.clone()),
                _ => memory::board_elf()?,
            };
            let b = memory::budget(
                elf.as_deref().unwrap_or(&default_elf),
                map.as_deref().unwrap_or(&default_map),
            )?;
            if json {
                println!(
                    "{}",
                    serde_json::to_string_pretty(&b).map_err(|e| e.to_string())?
                );
            } else {
                print!("{}", memory::table(&b));
            }
        }
        Command::Bench {
            which: Bench::Pipeline { block, json },
        } => {
            let c = throughput::measure(block)?;
            if json {
                println!(
                    "{}",
                    serde_json::to_string_pretty(&c).map_err(|e| e.to_string())?
                );
            } else {
                println!(
                    "streaming pipeline on this host, blocks of {} samples:",
                    c.block
                );
                println!(
                    "  idle                {:8.2} ns/sample ({:.3e} samples/s)",
                    c.idle_ns_per_sample, c.idle_samples_per_second
                );
                println!(
                    "  inside an impact    {:8.2} ns/sample (report included)",
                    c.impact_ns_per_sample
                );
                println!("  fits                {:8.1} µs/impact (8000 samples; two-phase, nonlinear with n, Hertz)", c.fits_us_per_impact);
            }
        }
        Command::Bench {
            which:
                Bench::Precision {
                    out,
                    budget_ms,
                    json,
                },
        } => {
            let mut points = precision::run(
                &precision::standard_cases(),
                Duration::from_millis(budget_ms),
            );
            points.extend(two_body_bench::precision(Duration::from_millis(budget_ms)));
            std::fs::create_dir_all(&out).map_err(|e| format!("{}: {e}", out.display()))?;
            let csv_path = out.join("work-precision.csv");
            std::fs::write(&csv_path, precision::csv(&points))
                .map_err(|e| format!("{}: {e}", csv_path.display()))?;
            let svg_path = out.join("work-precision.svg");
            precision::work_precision(&points, &svg_path)?;
            if json {
                println!(
                    "{}",
                    serde_json::to_string_pretty(&points).map_err(|e| e.to_string())?
                );
            } else {
                print!("{}", precision::table(&points));
                print!("{}", precision::summary(&points, 1e-9));
                println!("wrote {} and {}", csv_path.display(), svg_path.display());
            }
        }
    }
    Ok(())
}
