//! Cost of the core on the Cortex-M4F: runs the `m4-bench` firmware under QEMU (`impact bench m4`).
//!
//! Two runs of the same ELF (`firmware/src/bin/m4_bench.rs`):
//!
//! * **trace**: `qemu-system-arm -singlestep -d exec,nochain` logs every executed instruction;
//!   the instructions between the firmware's `bench_begin` and `bench_end` marks are counted
//!   exactly, per 256-sample `push_block` call, and weighed by the Cortex-M4's cycle timings
//!   ([`cycles`]) for the estimated cycle count;
//! * **count**: `-icount shift=0` (one virtual nanosecond per instruction) and SysTick, for the
//!   regions too long to trace: per-impact fits, f32 solves, maths back-ends. Resolution: one
//!   SysTick tick, 40 instructions (calibrated on a loop of known length each run).

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use impact_core::model::{Hertz, KelvinVoigt, Linear, Nonlinear, TwoPhase};
use impact_core::spec::MAX_BAND_POINTS;
use impact_core::{solve, Impact, ImpactOutcome, Method, Model, Settings};
use serde::{Deserialize, Serialize};

use crate::testkit::cases::{self, Case};
use crate::testkit::compare;

pub mod cycles;
pub mod disasm;
pub mod maths;
pub mod report;
pub mod trace;

use disasm::disassemble;
use maths::{host_math, math_error, maths};
pub use report::{check, table};
use trace::{profile_text, run_qemu, Region, TraceState};

/// Why the M4 benchmark could not run, or its firmware's output is not what it reads.
#[derive(Debug, thiserror::Error)]
pub enum M4Error {
    #[error(transparent)]
    Qemu(#[from] crate::firmware_link::qemu::QemuError),
    /// The seed recording's options (clap's own error).
    #[error(transparent)]
    Args(#[from] clap::Error),
    #[error(transparent)]
    Synth(#[from] crate::synth::SynthError),
    /// A file the runs read or write.
    #[error("{}: {source}", .path.display())]
    File {
        path: PathBuf,
        source: std::io::Error,
    },
    /// A jobs file could not be written.
    #[error(transparent)]
    Jobs(std::io::Error),
    #[error("{}: semihosting cannot pass a path with spaces or commas", .path.display())]
    Unpassable { path: PathBuf },
    /// A tool (`qemu-system-arm`, `mkfifo`) could not be run.
    #[error("{tool}: {source}")]
    Tool {
        tool: &'static str,
        source: std::io::Error,
    },
    #[error("mkfifo {} failed", .fifo.display())]
    Mkfifo { fifo: PathBuf },
    #[error("reading the trace: {0}")]
    Trace(std::io::Error),
    /// The bench firmware failed: its status and what it printed (stdout, then QEMU's
    /// stderr), the only account of why.
    #[error("the M4 bench failed ({status}):\n{output}")]
    Failed {
        status: std::process::ExitStatus,
        output: String,
    },
    /// The firmware's self-test failed: its output, the only account of what.
    #[error("the M4 self-test did not pass:\n{output}")]
    SelfTest { output: String },
    #[error("arm-none-eabi-objdump: {0} (run scripts/setup.sh)")]
    Objdump(std::io::Error),
    #[error("arm-none-eabi-objdump -d {} failed", .elf.display())]
    ObjdumpFailed { elf: PathBuf },
    #[error("{}: no `{name}` symbol", .elf.display())]
    NoSymbol { elf: PathBuf, name: &'static str },
    #[error("trace: {regions} regions for {blocks} blocks")]
    Regions { regions: usize, blocks: usize },
    #[error("trace run: no stream line")]
    NoStreamLine,
    #[error("count run: no `{prefix}` line")]
    NoCountLine { prefix: String },
    #[error("M4 bench output: no `{key}`")]
    NoField { key: &'static str },
    #[error("the seed recording gave {reports} reports, not 1")]
    Reports { reports: u32 },
    #[error("trace: unexpected block kinds {kinds}")]
    Kinds { kinds: String },
    /// A case's exact solve on the host (the core's words).
    #[error("{case}: {source}")]
    Case {
        case: &'static str,
        source: impact_core::Error,
    },
    #[error("no host maths function")]
    NoHostMath,
    #[error("the {fit} fit gave no result on the seed impact")]
    NoFit { fit: &'static str },
}

/// CPU clock of the STM32F407 board, Hz.
pub const BOARD_CLOCK_HZ: f64 = 168e6;
/// The seed experiment's sample rate, S/s.
pub const SEED_RATE_HZ: f64 = 500e3;
/// The STM32F4 ADC's top rate (12 bits, 2.4 MS/s with one ADC), S/s.
pub const ADC_TOP_RATE_HZ: f64 = 2.4e6;
/// Targets of the issue: instructions per sample, idle and inside an impact (#44: the whole
/// in-impact path, the online sums and the physics issues' work included, at most 40, which
/// `--check` holds; the idle path's is printed).
pub const IDLE_TARGET: f64 = 10.0;
pub const IMPACT_TARGET: f64 = 40.0;
/// Per-impact targets (issue "analysis 20x cheaper"), instructions: the report without fits,
/// the three fits with the exponent fixed together, the nonlinear fit with the exponent
/// searched, and the board's whole analysis (report and its scene's fits).
pub const REPORT_TARGET: u64 = 400_000;
pub const THREE_FITS_TARGET: u64 = 2_000_000;
pub const EXPONENT_FIT_TARGET: u64 = 3_000_000;
pub const ANALYSIS_TARGET: u64 = 5_000_000;
/// The shock spectra of one impact at 1/6 octave (issue: spectra per impact on the board).
pub const SPECTRUM_TARGET: u64 = 5_000_000;
/// The scene keys of the spectra the bench measures (SRS and PVSS, 5 %, 1/6 octave from
/// 10 Hz: 75 bands at 500 kS/s).
const SPECTRUM_KEYS: &str = "two_phase=0 nonlinear=0 hertz=0 srs=1";
/// The same spectra up to 10 kHz, MIL-STD-810's SRS range (`--srs-high 10000`: 59 bands).
const SPECTRUM_10K_KEYS: &str = "two_phase=0 nonlinear=0 hertz=0 srs=1 srs_high=10000";
/// The verdict of one impact against a specified pulse (`--spec`, issue: "a compact verdict
/// on the board, its cost measured").
pub const SPEC_TARGET: u64 = 1_000_000;
/// The scene keys of the verdict the bench measures: a 3 ms half-sine of the seed impact's
/// peak with IEC 60068-2-27's tolerances (at 500 kS/s its watched window, 1.5k samples
/// each side of the pulse, fits the board's capture; the seed's 25 ms contact fails it).
const SPEC_KEYS: &str = "two_phase=0 nonlinear=0 hertz=0 spec=half-sine spec_peak=96.9 spec_duration=0.003 spec_band=0.2 spec_outside=0.2 spec_slack=0.1 spec_dv=0.15 spec_before=0.4 spec_after=0.1 spec_watch=1.1";
/// The same verdict with a user's band ([`impact_core::spec::Spec::band`]) of the most rows a
/// band holds ([`MAX_BAND_POINTS`], 64): the half-sine ± 0.2 over D and A, tabulated from
/// 0.4 D before the pulse to 0.5 D after it.
fn spec_band_keys() -> String {
    let n = MAX_BAND_POINTS;
    let rows: Vec<String> = (0..n)
        .map(|i| {
            let u = -0.4 + 1.9 * i as f64 / (n - 1) as f64;
            let nominal = if (0.0..=1.0).contains(&u) {
                (std::f64::consts::PI * u).sin()
            } else {
                0.0
            };
            format!(
                "{u:.5}:{:.5}:{:.5}",
                (nominal - 0.2).max(-0.2),
                nominal + 0.2
            )
        })
        .collect();
    format!("spec_rows={}", rows.join(";"))
}
/// Accuracy the board's solves must reach (relative, every report field).
pub const BOARD_ACCURACY: f64 = 1e-4;

/// What `impact bench m4` measured.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct M4Report {
    /// Samples per `push_block` call (the firmware's DMA half-buffer).
    pub block: usize,
    /// Idle path: instructions per sample, everything in `push_block` included.
    pub idle_instructions_per_sample: f64,
    /// Inside an impact (capture, sums, end detection): instructions per sample.
    pub impact_instructions_per_sample: f64,
    /// Estimated Cortex-M4 cycles per sample, idle and in impact.
    pub idle_cycles_per_sample: f64,
    pub impact_cycles_per_sample: f64,
    /// The worse of the two.
    pub estimated_cycles_per_sample: f64,
    /// CPU left for everything else at 500 kS/s and at the ADC's top rate (1 - used/budget).
    pub headroom_at_500k: f64,
    pub headroom_at_adc_top_rate: f64,
    /// Per impact: the trigger (walk back to the onset, pre-trigger replay) and the report
    /// (metrics and kinematics, no fit), instructions.
    pub trigger_instructions: u64,
    pub report_instructions: u64,
    /// Samples in the measured impact's window.
    pub impact_samples: u64,
    /// Per-impact fits on the M4 (the captured impact above), instructions: each one alone
    /// (the fit points it shares with the others included), and together.
    pub fits: Vec<FitCost>,
    /// The board's whole analysis of the impact: the report and its scene's fits (all three,
    /// the exponent fitted), instructions.
    #[serde(default)]
    pub analysis_instructions: u64,
    /// The shock spectra of the impact (SRS, PVSS, half-sine at 1/6 octave), instructions.
    #[serde(default)]
    pub spectrum_instructions: u64,
    /// The same spectra up to 10 kHz ([`SPECTRUM_10K_KEYS`]), instructions.
    #[serde(default)]
    pub spectrum_10khz_instructions: u64,
    /// The verdict of the impact against a specified pulse ([`SPEC_KEYS`]), instructions.
    #[serde(default)]
    pub spec_instructions: u64,
    /// The same verdict with a user's band of 64 rows instead of the standard's, instructions.
    #[serde(default)]
    pub spec_band_instructions: u64,
    /// One impact of each model with each solver in f32 at [`BOARD_ACCURACY`].
    pub solves: Vec<SolveCost>,
    /// Maths back-ends: cost per call on the M4 and error against f64.
    pub maths: Vec<MathCost>,
    /// Instructions per SysTick tick in the count run (40 expected).
    pub instructions_per_tick: f64,
    /// The whole emulator firmware (sampler, channel, monitor, reporter, executor, SysTick
    /// time driver), per idle sample: the difference between two idle recordings of 2^17
    /// and 2^18 samples. Its sampler replays a host file through semihosting, which the
    /// board's DMA does without the CPU.
    #[serde(default)]
    pub firmware_idle_instructions_per_sample: f64,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FitCost {
    pub fit: String,
    pub instructions: u64,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SolveCost {
    pub case: String,
    pub method: String,
    /// Steps per time scale (fixed steps) or relative tolerance (adaptive); 0 for exact.
    pub setting: f64,
    /// Largest relative error of the f32 outcome over the report fields.
    pub error: f64,
    pub instructions: u64,
    /// The M4's outcome has the same bits as the host's f32 solve.
    pub same_bits_as_host: bool,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct MathCost {
    pub op: String,
    pub backend: String,
    pub instructions_per_call: f64,
    /// Largest relative error against f64 `libm` over the input range, and in ulp-free terms.
    pub max_relative_error: f64,
}

/// Options of `impact bench m4`.
#[derive(clap::Args, Clone, Debug)]
pub struct M4Args {
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
    /// Compare with a stored baseline (JSON from `--json`); fail if an instruction count
    /// grew by more than 10 %.
    #[arg(long)]
    pub check: Option<PathBuf>,
    /// The bench ELF (default: build it).
    #[arg(long)]
    pub elf: Option<PathBuf>,
    /// Also print where the instructions go (functions, per path).
    #[arg(long)]
    pub profile: bool,
}

/// `key=value` fields of an output line.
fn fields(line: &str) -> HashMap<&str, &str> {
    line.split_whitespace()
        .filter_map(|w| w.split_once('='))
        .collect()
}

fn number<T: std::str::FromStr>(m: &HashMap<&str, &str>, key: &'static str) -> Result<T, M4Error> {
    m.get(key)
        .and_then(|v| v.parse().ok())
        .ok_or(M4Error::NoField { key })
}

/// The seed bench impact (seed 001: 60 g at 1.3357 m/s, two-phase), 40 ms after the start of
/// a 120 ms recording at 500 kS/s, 12-bit ADC codes.
pub fn seed_recording() -> Result<Vec<i16>, M4Error> {
    use clap::Parser;
    #[derive(Parser)]
    struct Wrap {
        #[command(flatten)]
        synth: crate::synth::SynthArgs,
    }
    let args = ["synth"]
        .into_iter()
        .chain(crate::synth::SEED_BENCH_ARGS)
        .chain(["--touch", "0.04", "--duration", "0.12"]);
    let args = Wrap::try_parse_from(args)?;
    Ok(crate::synth::synth(&args.synth)?.samples)
}

/// The board's scene with the fits switched by `fits` (`key=value` overrides of
/// `scene::BENCH` in the firmware).
fn scene_line(fits: &str) -> String {
    format!("scene {fits}")
}

const NO_FITS: &str = "two_phase=0 nonlinear=0 hertz=0";
/// The name of the variant that is the board's scene (all three fits, the exponent fitted).
const BOARD_FITS: &str = "the board's: all three, n fitted";
const FIT_VARIANTS: [(&str, &str); 6] = [
    ("two-phase", "two_phase=1 nonlinear=0 hertz=0"),
    (
        "nonlinear (n = 1 fixed)",
        "two_phase=0 nonlinear=1 fit_exponent=0 hertz=0",
    ),
    (
        "nonlinear (n fitted)",
        "two_phase=0 nonlinear=1 fit_exponent=1 hertz=0",
    ),
    ("hertz", "two_phase=0 nonlinear=0 hertz=1"),
    (
        "two-phase + nonlinear (n fixed) + hertz",
        "two_phase=1 nonlinear=1 fit_exponent=0 hertz=1",
    ),
    (BOARD_FITS, "two_phase=1 nonlinear=1 fit_exponent=1 hertz=1"),
];

/// The f32 model of a case and its parameters as the bench's `solve` job writes them.
fn f32_model(model: &Model<f64>) -> (Model<f32>, String) {
    let e = |v: f64| format!("{:e}", v as f32);
    match *model {
        Model::Hertz(h) => (
            Model::Hertz(Hertz { k: h.k as f32 }),
            format!("hertz {} 0 0 none", e(h.k)),
        ),
        Model::Linear(l) => (
            Model::Linear(Linear { k: l.k as f32 }),
            format!("linear {} 0 0 none", e(l.k)),
        ),
        Model::KelvinVoigt(k) => (
            Model::KelvinVoigt(KelvinVoigt {
                k: k.k as f32,
                c: k.c as f32,
            }),
            format!("kelvin-voigt {} {} 0 none", e(k.k), e(k.c)),
        ),
        Model::TwoPhase(t) => (
            Model::TwoPhase(TwoPhase {
                kc: t.kc as f32,
                kr: t.kr as f32,
                c: t.c as f32,
                permanent_m: t.permanent_m.map(|p| p as f32),
            }),
            format!(
                "two-phase {} {} {} {}",
                e(t.kc),
                e(t.kr),
                e(t.c),
                t.permanent_m.map_or("none".into(), e)
            ),
        ),
        Model::Nonlinear(n) => (
            Model::Nonlinear(Nonlinear {
                k: n.k as f32,
                c: n.c as f32,
                n: n.n as f32,
            }),
            format!("nonlinear {} {} {} none", e(n.k), e(n.c), e(n.n)),
        ),
    }
}

/// A setting of one solver that reaches [`BOARD_ACCURACY`] in f32 on the host, the cheapest
/// on a ladder; `None` if none does.
fn board_setting(
    model: &Model<f32>,
    impact: &Impact<f32>,
    exact: &ImpactOutcome<f64>,
    method: Method,
) -> Option<(Settings<f32>, ImpactOutcome<f32>, f64)> {
    let error = |s: &Settings<f32>| {
        solve(model, impact, s).ok().map(|o| {
            let e = compare::max_relative_error(&compare::widen(&o), exact).0;
            (o, e)
        })
    };
    let ladder: Vec<Settings<f32>> = match method {
        Method::Exact => vec![Settings::exact()],
        Method::Adaptive => (4..=14)
            .map(|k| Settings::adaptive(10f32.powf(-(k as f32) / 2.0)))
            .collect(),
        m => (0..=40)
            .map(|k| Settings::fixed(m, (8.0 * 2f64.powf(k as f64 / 2.0)).round() as u32))
            .collect(),
    };
    ladder.into_iter().find_map(|s| {
        let (o, e) = error(&s)?;
        (e <= BOARD_ACCURACY).then_some((s, o, e))
    })
}

fn bits(o: &ImpactOutcome<f32>) -> String {
    [
        o.max_deformation_m,
        o.crush_time_s,
        o.contact_time_s,
        o.rebound_velocity_m_s,
        o.peak_force_n,
        o.permanent_deformation_m,
    ]
    .iter()
    .map(|v| format!("{:08x}", v.to_bits()))
    .collect::<Vec<_>>()
    .join(",")
}

/// Builds the bench ELF with cargo (a no-op when up to date).
fn build() -> Result<PathBuf, M4Error> {
    Ok(crate::firmware_link::qemu::build_firmware_bin(
        "m4-bench",
        Some("m4-bench"),
    )?)
}

/// Runs the whole benchmark (about a minute: the trace run dominates).
pub fn run(args: &M4Args) -> Result<(M4Report, String), M4Error> {
    crate::firmware_link::qemu::tools_available()?;
    let elf = match &args.elf {
        Some(e) => e.clone(),
        None => build()?,
    };
    let code = disassemble(&elf)?;
    let files = BenchFiles::new();
    let samples = seed_recording()?;
    let bytes: Vec<u8> = samples.iter().flat_map(|c| c.to_le_bytes()).collect();
    std::fs::write(&files.raw, bytes).map_err(file(&files.raw))?;
    let streaming = trace_run(&elf, &code, &files, args.profile)?;
    let counted = count_run(&elf, &files)?;
    let firmware = crate::firmware_link::qemu::build_firmware()?;
    let firmware_idle = firmware_idle_marginal(&firmware)?;
    let s = &streaming;
    let worst = s.idle_cps.max(s.impact_cps);
    let report = M4Report {
        block: s.block,
        idle_instructions_per_sample: s.idle_ips,
        impact_instructions_per_sample: s.impact_ips,
        idle_cycles_per_sample: s.idle_cps,
        impact_cycles_per_sample: s.impact_cps,
        estimated_cycles_per_sample: worst,
        headroom_at_500k: 1.0 - worst / (BOARD_CLOCK_HZ / SEED_RATE_HZ),
        headroom_at_adc_top_rate: 1.0 - worst / (BOARD_CLOCK_HZ / ADC_TOP_RATE_HZ),
        trigger_instructions: s.trigger_instructions,
        report_instructions: s.report_instructions,
        impact_samples: s.impact_samples,
        analysis_instructions: s.report_instructions
            + counted
                .fits
                .iter()
                .find(|f| f.fit == BOARD_FITS)
                .map_or(0, |f| f.instructions),
        spectrum_instructions: counted.spectrum_instructions,
        spectrum_10khz_instructions: counted.spectrum_10khz_instructions,
        spec_instructions: counted.spec_instructions,
        spec_band_instructions: counted.spec_band_instructions,
        fits: counted.fits,
        solves: counted.solves,
        maths: counted.maths,
        instructions_per_tick: counted.instructions_per_tick,
        firmware_idle_instructions_per_sample: firmware_idle,
    };
    let prof = if args.profile {
        profile_text(&s.kinds, &s.profile)
    } else {
        String::new()
    };
    Ok((report, prof))
}

/// The bench's temporary files (the seed recording's counts, the two runs' job lists),
/// removed when dropped or on an interrupt.
struct BenchFiles {
    raw: PathBuf,
    trace_jobs: PathBuf,
    count_jobs: PathBuf,
    _guards: [crate::interrupt::FileGuard; 3],
}

impl BenchFiles {
    fn new() -> Self {
        let dir = std::env::temp_dir();
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.subsec_nanos());
        let stem = format!("impact-m4-{}-{nanos}", std::process::id());
        let raw = dir.join(format!("{stem}.i16"));
        let trace_jobs = dir.join(format!("{stem}-trace.txt"));
        let count_jobs = dir.join(format!("{stem}-count.txt"));
        let _guards = [&raw, &trace_jobs, &count_jobs].map(|p| crate::interrupt::temporary(p));
        Self {
            raw,
            trace_jobs,
            count_jobs,
            _guards,
        }
    }
}

impl Drop for BenchFiles {
    fn drop(&mut self) {
        for f in [&self.raw, &self.trace_jobs, &self.count_jobs] {
            let _ = std::fs::remove_file(f);
        }
    }
}

/// What the trace run measured of the streaming path: per sample idle and in an impact
/// (instructions and estimated cycles), the trigger's and the report's own cost, the block
/// size, the impact's samples; each block's kind and (with `--profile`) its per-function
/// profile.
struct Streaming {
    block: usize,
    idle_ips: f64,
    impact_ips: f64,
    idle_cps: f64,
    impact_cps: f64,
    trigger_instructions: u64,
    report_instructions: u64,
    impact_samples: u64,
    kinds: String,
    profile: Vec<HashMap<String, u64>>,
}

/// The trace run: every block's instructions counted exactly, then averaged by the block's
/// kind (idle, trigger, in the impact, end).
fn trace_run(
    elf: &Path,
    code: &disasm::Code,
    files: &BenchFiles,
    profiling: bool,
) -> Result<Streaming, M4Error> {
    std::fs::write(
        &files.trace_jobs,
        format!("selftest\n{}\nstream pipeline\n", scene_line(NO_FITS)),
    )
    .map_err(M4Error::Jobs)?;
    // Per-block regions.
    let mut regions: Vec<Region> = Vec::new();
    let mut profile: Vec<HashMap<String, u64>> = Vec::new();
    let mut state = TraceState::default();
    let mut on_line = |line: &str| state.line(line, code, &mut regions, &mut profile, profiling);
    let out = run_qemu(
        elf,
        &[
            "trace".into(),
            path_arg(&files.raw)?,
            path_arg(&files.trace_jobs)?,
        ],
        Some(&mut on_line),
        false,
    )?;
    if !out.lines().any(|l| l == "selftest ok") {
        return Err(M4Error::SelfTest { output: out });
    }
    let kinds: String = out
        .lines()
        .filter_map(|l| l.strip_prefix("kinds "))
        .collect();
    if kinds.len() != regions.len() {
        return Err(M4Error::Regions {
            regions: regions.len(),
            blocks: kinds.len(),
        });
    }
    let stream = out
        .lines()
        .find(|l| l.starts_with("stream "))
        .map(fields)
        .ok_or(M4Error::NoStreamLine)?;
    let n_samples: usize = number(&stream, "samples")?;
    let block: usize = number(&stream, "block")?;
    let reports: u32 = number(&stream, "reports")?;
    if reports != 1 {
        return Err(M4Error::Reports { reports });
    }
    let mut per_kind: HashMap<char, (Region, usize, u64)> = HashMap::new();
    for (k, (kind, r)) in kinds.chars().zip(&regions).enumerate() {
        let len = block.min(n_samples.saturating_sub(k * block)) as u64;
        let e = per_kind.entry(kind).or_default();
        e.0.instructions += r.instructions;
        e.0.cycles += r.cycles;
        e.1 += 1;
        e.2 += len;
    }
    let get = |k: char| per_kind.get(&k).copied().unwrap_or_default();
    let (idle, _, idle_n) = get('i');
    let (active, _, active_n) = get('a');
    let (trigger, _, trigger_n) = get('t');
    let (end, _, end_n) = get('e');
    if idle_n == 0 || active_n == 0 || trigger_n == 0 || end_n == 0 {
        return Err(M4Error::Kinds { kinds });
    }
    let per = |r: Region, n: u64| r.instructions as f64 / n as f64;
    let per_c = |r: Region, n: u64| r.cycles as f64 / n as f64;
    let impact_ips = per(active, active_n);
    // The trigger and end blocks: their samples at the in-impact rate, the rest per impact.
    let own = |r: Region, n: u64| (r.instructions as f64 - impact_ips * n as f64).max(0.0) as u64;
    Ok(Streaming {
        block,
        idle_ips: per(idle, idle_n),
        impact_ips,
        idle_cps: per_c(idle, idle_n),
        impact_cps: per_c(active, active_n),
        trigger_instructions: own(trigger, trigger_n),
        report_instructions: own(end, end_n),
        impact_samples: trigger_n + active_n + end_n,
        kinds,
        profile,
    })
}

/// What the count run measured: each fit variant's, the spectra's and the verdicts' cost per
/// impact, the f32 solves and the maths back-ends, and SysTick's instructions per tick.
struct Counted {
    fits: Vec<FitCost>,
    spectrum_instructions: u64,
    spectrum_10khz_instructions: u64,
    spec_instructions: u64,
    spec_band_instructions: u64,
    solves: Vec<SolveCost>,
    maths: Vec<MathCost>,
    instructions_per_tick: f64,
}

/// A solve the count run times: its label in the jobs, the case, the method, its setting,
/// the host's error and the host's result bits.
type SolveJob = (String, &'static str, Method, f64, f64, String);

/// A maths back-end the count run times: the operation, the back-end and its host error.
type MathJob = (&'static str, &'static str, f64);

/// The count run's jobs: the stream with each fit variant, the spectra and the verdicts; the
/// f32 solves of every case and method the board would use; each maths back-end.
fn count_jobs() -> Result<(String, Vec<SolveJob>, Vec<MathJob>), M4Error> {
    let mut jobs = String::new();
    jobs.push_str(&format!("{}\nstream no-fit\n", scene_line(NO_FITS)));
    for (i, (_, keys)) in FIT_VARIANTS.iter().enumerate() {
        jobs.push_str(&format!("{}\nstream fit{i}\n", scene_line(keys)));
    }
    jobs.push_str(&format!("{}\nstream srs\n", scene_line(SPECTRUM_KEYS)));
    jobs.push_str(&format!(
        "{}\nstream srs-10k\n",
        scene_line(SPECTRUM_10K_KEYS)
    ));
    jobs.push_str(&format!("{}\nstream spec\n", scene_line(SPEC_KEYS)));
    jobs.push_str(&format!(
        "{}\nstream spec-band\n",
        scene_line(&format!("{SPEC_KEYS} {}", spec_band_keys()))
    ));
    let mut solve_rows = Vec::new();
    for case in solve_cases() {
        let exact = solve(&case.model, &case.impact, &Settings::exact()).map_err(|source| {
            M4Error::Case {
                case: case.name,
                source,
            }
        })?;
        let (model, params) = f32_model(&case.model);
        let impact = Impact::new(case.impact.mass_kg as f32, case.impact.v0_m_s as f32);
        for method in [
            Method::Exact,
            Method::Euler,
            Method::Verlet,
            Method::Rk4,
            Method::Adaptive,
        ] {
            let Some((s, o, e)) = board_setting(&model, &impact, &exact, method) else {
                continue;
            };
            let knob = match method {
                Method::Exact => "0".to_string(),
                Method::Adaptive => format!("{:e}", s.rtol),
                _ => s.steps.to_string(),
            };
            let label = format!("s{}", solve_rows.len());
            // Repeated so that SysTick's 40-instruction resolution stays below 0.1 %
            // (Euler's solves are millions of instructions already).
            let reps = if method == Method::Euler { 1 } else { 64 };
            jobs.push_str(&format!(
                "solve {label} {reps} {} {knob} {:e} {:e} {params}\n",
                method.name(),
                impact.mass_kg,
                impact.v0_m_s
            ));
            let setting = match method {
                Method::Exact => 0.0,
                Method::Adaptive => s.rtol as f64,
                _ => s.steps as f64,
            };
            solve_rows.push((label, case.name, method, setting, e, bits(&o)));
        }
    }
    let mut math_rows = Vec::new();
    jobs.push_str("math none libm 0 1\n");
    for (op, reference, range, backends) in maths() {
        for b in backends {
            jobs.push_str(&format!("math {op} {b} {:e} {:e}\n", range.0, range.1));
            let f = host_math(op, b).ok_or(M4Error::NoHostMath)?;
            math_rows.push((op, *b, math_error(f, reference, range)));
        }
    }
    Ok((jobs, solve_rows, math_rows))
}

/// The count run ([`count_jobs`] under `-icount`, timed by SysTick, calibrated each run).
fn count_run(elf: &Path, files: &BenchFiles) -> Result<Counted, M4Error> {
    let (jobs, solve_rows, math_rows) = count_jobs()?;
    std::fs::write(&files.count_jobs, jobs).map_err(M4Error::Jobs)?;
    let out = run_qemu(
        elf,
        &[
            "count".into(),
            path_arg(&files.raw)?,
            path_arg(&files.count_jobs)?,
        ],
        None,
        true,
    )?;
    let lines: Vec<&str> = out.lines().collect();
    let find = |prefix: &str| {
        lines
            .iter()
            .find(|l| l.starts_with(prefix))
            .map(|l| fields(l))
            .ok_or_else(|| M4Error::NoCountLine {
                prefix: prefix.to_string(),
            })
    };
    let cal = find("calibrate ")?;
    let ipt = number::<f64>(&cal, "instructions")? / number::<f64>(&cal, "ticks")?;
    let ticks_total = |label: &str| -> Result<f64, M4Error> {
        number::<f64>(&find(&format!("ticks {label} "))?, "total")
    };
    let base = ticks_total("no-fit")?;
    let over_base = |label: &str| -> Result<u64, M4Error> {
        Ok(((ticks_total(label)? - base) * ipt).max(0.0) as u64)
    };
    let mut fits = Vec::new();
    for (i, (name, _)) in FIT_VARIANTS.iter().enumerate() {
        let s = find(&format!("stream fit{i} "))?;
        let got: String = number(&s, "fits")?;
        if !got.contains('1') {
            return Err(M4Error::NoFit { fit: name });
        }
        fits.push(FitCost {
            fit: name.to_string(),
            instructions: over_base(&format!("fit{i}"))?,
        });
    }
    let mut solves = Vec::new();
    for (label, case, method, setting, error, host_bits) in solve_rows {
        let s = find(&format!("solve {label} "))?;
        let ok: u32 = number(&s, "ok")?;
        let m4_bits = s.get("bits").copied().unwrap_or("");
        solves.push(SolveCost {
            case: case.to_string(),
            method: method.name().to_string(),
            setting,
            error,
            instructions: (number::<f64>(&s, "ticks")? * ipt / number::<f64>(&s, "reps")?).round()
                as u64,
            same_bits_as_host: ok == 1 && m4_bits == host_bits,
        });
    }
    let loop_ticks = number::<f64>(&find("math none libm ")?, "ticks")?;
    let mut maths = Vec::new();
    for (op, b, err) in math_rows {
        let m = find(&format!("math {op} {b} "))?;
        let calls: f64 = number(&m, "calls")?;
        let ticks: f64 = number(&m, "ticks")?;
        maths.push(MathCost {
            op: op.to_string(),
            backend: b.to_string(),
            instructions_per_call: ((ticks - loop_ticks) * ipt / calls).max(0.0),
            max_relative_error: err,
        });
    }
    Ok(Counted {
        fits,
        spectrum_instructions: over_base("srs")?,
        spectrum_10khz_instructions: over_base("srs-10k")?,
        spec_instructions: over_base("spec")?,
        spec_band_instructions: over_base("spec-band")?,
        solves,
        maths,
        instructions_per_tick: ipt,
    })
}

/// Instructions the whole emulator firmware executes per idle sample (see
/// [`M4Report::firmware_idle_instructions_per_sample`]).
fn firmware_idle_marginal(firmware: &Path) -> Result<f64, M4Error> {
    let dir = std::env::temp_dir();
    let mut totals = Vec::new();
    for n in [1usize << 17, 1 << 18] {
        let counts = crate::bench::throughput::impact_stream(n, 0);
        let raw = dir.join(format!("impact-m4-idle-{}-{n}.i16", std::process::id()));
        let _raw = crate::interrupt::temporary(&raw);
        let bytes: Vec<u8> = counts.iter().flat_map(|c| c.to_le_bytes()).collect();
        std::fs::write(&raw, bytes).map_err(file(&raw))?;
        let mut lines = 0u64;
        let mut count = |_: &str| lines += 1;
        // icount: SysTick (the time driver) then ticks with the instructions, not the wall
        // clock, so the count is deterministic.
        let result = run_qemu(
            firmware,
            &[path_arg(&raw)?, "lossless".into()],
            Some(&mut count),
            true,
        );
        let _ = std::fs::remove_file(&raw);
        result?;
        totals.push((n, lines));
    }
    let (n1, i1) = totals[0];
    let (n2, i2) = totals[1];
    Ok(i2.saturating_sub(i1) as f64 / (n2 - n1) as f64)
}

/// The cases solved on the M4: one per model (the standard set's first of each).
fn solve_cases() -> Vec<Case> {
    let mut seen = Vec::new();
    cases::standard()
        .into_iter()
        .filter(|c| {
            let kind = std::mem::discriminant(&c.model);
            if seen.contains(&kind) {
                false
            } else {
                seen.push(kind);
                true
            }
        })
        .collect()
}

fn path_arg(p: &Path) -> Result<String, M4Error> {
    let s = p.to_string_lossy().into_owned();
    if s.contains([' ', ',']) {
        return Err(M4Error::Unpassable {
            path: p.to_path_buf(),
        });
    }
    Ok(s)
}

/// An I/O error of the file at `path`.
fn file(path: &Path) -> impl FnOnce(std::io::Error) -> M4Error + '_ {
    move |source| M4Error::File {
        path: path.to_path_buf(),
        source,
    }
}
