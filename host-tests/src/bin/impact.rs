//! `impact`: simulate impacts, analyse recordings, run the firmware emulated, read its logs,
//! benchmark. This file parses the command line and hands each subcommand to its module in
//! `impact_host::cli`; the exit status and the notes are set here.

use std::process::ExitCode;

use impact_host::report::spec::{Judged, EXIT_FAILED_VERDICT};

use clap::{Parser, Subcommand};
use impact_host::cli::{self, progress};
use impact_host::simulate;

// The examples in the help are commands of docs/user-guide.md, run by its tests.
const ANALYZE_EXAMPLES: &str = "Examples:
  impact analyze host-tests/data/afrl-drop-tower/series1_test1_full_100ms.csv
  impact analyze seed.csv --mass 0.06 --v0 1.3357 --plot seed.svg
  impact analyze train.csv --mass 0.06 --v0 1.3357 --train flight
  impact analyze host-tests/data/endaq-high-drop/High-Drop_16g-DC_full.csv --axes x_g,y_g,z_g
  impact analyze host-tests/data/afrl-drop-tower/series1_test1_full_100ms.csv --srs --json
  impact analyze host-tests/data/afrl-drop-tower/accel_5.csv --channels 1,2,3,4,5 --units kgn";
const EMULATE_EXAMPLES: &str = "Examples:
  impact emulate host-tests/data/afrl-drop-tower/series1_test1_full_100ms.csv --realtime
  impact emulate seed.csv --mass 0.06 --v0 1.3357 --waveforms --log board.log";
const SIMULATE_EXAMPLES: &str = "Examples:
  impact simulate --model hertz --mass 8.419e-3 --v0 2 --radius 6.35e-3 --youngs 200e9 --poisson 0.3
  impact simulate --model kelvin-voigt --mass 0.06 --v0 1.3357 --stiffness 2e5 --damping 8 --target host-tests/examples/mount.json";
const SYNTH_EXAMPLES: &str = "Examples:
  impact synth --model two-phase --mass 0.06 --v0 1.3357 --max-deformation 0.0186 --kr 12376 --permanent 0.0182 --damping 2 -o seed.csv
  impact synth --model nonlinear --mass 0.06 --v0 1.3357 --stiffness 1e4 --damping 0.5 --bounces 8 --duration 1.5 -o train.csv";
const REPORT_EXAMPLES: &str = "Examples:
  impact report host-tests/data/afrl-drop-tower/accel_5.csv --channels 1,2,3,4,5 --units kgn --spec half-sine,11000g,0.1ms --html afrl.html";
const WATCH_EXAMPLES: &str = "Examples:
  impact emulate seed.csv --mass 0.06 --v0 1.3357 --realtime --waveforms 8 --log day.log
  impact watch --replay day.log
  impact watch board.log --spec half-sine,100g,3ms
  impact watch board.log --terminal --once";
const SELFTEST_EXAMPLES: &str = "Examples:
  impact selftest
  impact selftest --wire-gain 0.9";
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
    Analyze(Box<cli::analyze::AnalyzeCommand>),
    /// Analyse a recorded signal on the emulated firmware (QEMU): the same output as `analyze`.
    #[command(
        allow_negative_numbers = true,
        after_help = EMULATE_EXAMPLES,
        // The emulator replays a recording it has read whole: no one-pass reading.
        mut_arg("stream", |a| a.hide(true))
    )]
    Emulate(Box<cli::emulate::EmulateArgs>),
    /// Analyse recordings into one self-contained HTML report (settings, the series' table and
    /// statistics, every pulse drawn with the specification's band).
    #[command(
        allow_negative_numbers = true,
        after_help = REPORT_EXAMPLES,
        // The report is the output: analyze's own outputs are refused here.
        mut_arg("json", |a| a.hide(true)),
        mut_arg("csv", |a| a.hide(true)),
        mut_arg("plot", |a| a.hide(true))
    )]
    Report(Box<cli::html::ReportArgs>),
    /// Turn the firmware's defmt log into JSON (default) or CSV, its waveforms into figures.
    #[command(after_help = LOG_EXAMPLES)]
    Log(cli::log::LogArgs),
    /// Watch the board live: its log as it arrives (a pipe, a growing file) shown on a local
    /// web page (or in the terminal), every line kept in a session file.
    #[command(after_help = WATCH_EXAMPLES)]
    Watch(Box<cli::watch::WatchArgs>),
    /// The board's bring-up self-test (`--features selftest`) on the emulated board: the
    /// DAC's half-sine replayed through the monitor and judged as the board judges it
    /// (peak, FWHM, sample rate; PASS, or FAIL with exit status 3).
    #[command(after_help = SELFTEST_EXAMPLES)]
    Selftest(cli::selftest::SelftestArgs),
    /// Render a model impact as an accelerometer recording (CSV on stdout or --output, raw
    /// ADC codes with --raw).
    #[command(allow_negative_numbers = true, after_help = SYNTH_EXAMPLES)]
    Synth(cli::synth::SynthCommand),
    /// Benchmarks.
    Bench {
        #[command(subcommand)]
        which: cli::bench::Bench,
    },
}

fn main() -> ExitCode {
    // Ctrl-C and its kin remove temporary files and end QEMU; a closed output pipe
    // (`impact … | head -1`) ends the tool quietly; a file-size limit is an error.
    impact_host::interrupt::install();
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
            impact_host::errln!("peak memory: {}", line.trim_start_matches("VmHWM:").trim());
        }
    }
    match result {
        Ok(judged) => {
            for note in impact_host::take_notes() {
                impact_host::errln!("note: {note}");
            }
            if judged.failed > 0 {
                impact_host::errln!(
                    "FAIL: {} of {} judged impact{} failed the specification (exit status {EXIT_FAILED_VERDICT})",
                    judged.failed,
                    judged.judged,
                    if judged.judged == 1 { "" } else { "s" }
                );
                ExitCode::from(EXIT_FAILED_VERDICT)
            } else {
                ExitCode::SUCCESS
            }
        }
        Err(e) => {
            impact_host::errln!("error: {e}");
            ExitCode::from(1)
        }
    }
}

/// What ended a command: its own error, printed `error: …` with exit status 1 (each
/// command's error says what it refused or what failed in the words the user sees).
#[derive(Debug, thiserror::Error)]
enum Error {
    #[error(transparent)]
    Simulate(#[from] simulate::SimulateError),
    #[error(transparent)]
    Analyze(#[from] cli::analyze::AnalyzeError),
    #[error(transparent)]
    Emulate(#[from] cli::emulate::EmulateError),
    #[error(transparent)]
    Log(#[from] cli::log::LogCommandError),
    #[error(transparent)]
    Report(#[from] cli::html::ReportError),
    #[error(transparent)]
    Watch(#[from] cli::watch::WatchError),
    #[error(transparent)]
    Synth(#[from] impact_host::synth::SynthError),
    #[error(transparent)]
    Selftest(#[from] cli::selftest::SelftestError),
    /// (Boxed: the benchmarks' errors are the largest, and the rarest.)
    #[error(transparent)]
    Bench(Box<impact_host::bench::BenchError>),
}

/// Runs the command; the verdicts of the commands that judge impacts against a spec
/// (`analyze`, `report`, `emulate`, `log`) or pulses against the played one (`selftest`),
/// none for the others.
fn run(cli: Cli) -> Result<Judged, Error> {
    let none = Judged::default();
    match cli.command {
        Command::Simulate(args) => Ok(cli::simulate::run(&args).map(|()| none)?),
        Command::Analyze(args) => Ok(cli::analyze::run(&args)?),
        Command::Emulate(args) => Ok(cli::emulate::emulate(&args)?),
        Command::Log(args) => Ok(cli::log::log(&args)?),
        Command::Report(args) => Ok(cli::html::run(&args)?),
        Command::Watch(args) => Ok(cli::watch::run(&args).map(|()| none)?),
        Command::Selftest(args) => Ok(cli::selftest::run(&args)?),
        Command::Synth(command) => Ok(cli::synth::run(command).map(|()| none)?),
        Command::Bench { which } => cli::bench::run(which)
            .map(|()| none)
            .map_err(|e| Error::Bench(Box::new(e))),
    }
}
