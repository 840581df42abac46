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
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use impact_core::model::{Hertz, KelvinVoigt, Linear, Nonlinear, TwoPhase};
use impact_core::{solve, Impact, ImpactOutcome, Method, Model, Settings};
use serde::{Deserialize, Serialize};

use crate::testkit::cases::{self, Case};
use crate::testkit::compare;

/// CPU clock of the STM32F407 board, Hz.
pub const BOARD_CLOCK_HZ: f64 = 168e6;
/// The seed experiment's sample rate, S/s.
pub const SEED_RATE_HZ: f64 = 500e3;
/// The STM32F4 ADC's top rate (12 bits, 2.4 MS/s with one ADC), S/s.
pub const ADC_TOP_RATE_HZ: f64 = 2.4e6;
/// Targets of the issue: instructions per sample, idle and inside an impact.
pub const IDLE_TARGET: f64 = 10.0;
pub const IMPACT_TARGET: f64 = 60.0;
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
/// 10 Hz: 76 bands at 500 kS/s).
const SPECTRUM_KEYS: &str = "two_phase=0 nonlinear=0 hertz=0 srs=1";
/// Accuracy the board's solves must reach (relative, every report field).
pub const BOARD_ACCURACY: f64 = 1e-4;
/// Pipeline refill after a taken branch, cycles (the M4 TRM gives 1 to 3).
const REFILL: u32 = 2;

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

/// One decoded instruction.
#[derive(Clone, Debug)]
struct Insn {
    size: u32,
    mnemonic: String,
    operands: String,
}

/// The ELF's code: instruction per address and the marks' address ranges.
struct Code {
    insns: HashMap<u32, Insn>,
    begin: (u32, u32),
    end: (u32, u32),
}

fn disassemble(elf: &Path) -> Result<Code, String> {
    let out = Command::new("arm-none-eabi-objdump")
        .arg("-d")
        .arg(elf)
        .output()
        .map_err(|e| format!("arm-none-eabi-objdump: {e} (run scripts/setup.sh)"))?;
    if !out.status.success() {
        return Err(format!("arm-none-eabi-objdump -d {} failed", elf.display()));
    }
    let text = String::from_utf8_lossy(&out.stdout);
    let mut insns = HashMap::new();
    // The function being read, and each function's address range.
    let mut current: Option<String> = None;
    let mut ranges: HashMap<String, (u32, u32)> = HashMap::new();
    for line in text.lines() {
        // Function header: `00000458 <impact_core_vsqrt_f32>:`
        if let Some(name) = line
            .strip_suffix(">:")
            .and_then(|l| l.split_once(" <"))
            .and_then(|(a, n)| u32::from_str_radix(a.trim(), 16).ok().map(|a| (n, a)))
        {
            ranges.insert(name.0.to_string(), (name.1, name.1));
            current = Some(name.0.to_string());
            continue;
        }
        // Instruction: `     458:\teeb1 0ac0 \tvsqrt.f32\ts0, s0`
        let mut fields = line.split('\t');
        let (Some(addr), Some(raw), Some(mnemonic)) = (fields.next(), fields.next(), fields.next())
        else {
            continue;
        };
        let Some(addr) = addr
            .trim()
            .strip_suffix(':')
            .and_then(|a| u32::from_str_radix(a, 16).ok())
        else {
            continue;
        };
        let size = raw.split_whitespace().map(|h| h.len() as u32 / 2).sum();
        let operands = fields.next().unwrap_or("").to_string();
        insns.insert(
            addr,
            Insn {
                size,
                mnemonic: mnemonic.trim().to_string(),
                operands,
            },
        );
        if let Some(n) = &current {
            if let Some(r) = ranges.get_mut(n) {
                r.1 = addr + size;
            }
        }
    }
    let range = |name: &str| {
        ranges
            .get(name)
            .copied()
            .ok_or_else(|| format!("{}: no `{name}` symbol", elf.display()))
    };
    Ok(Code {
        begin: range("bench_begin")?,
        end: range("bench_end")?,
        insns,
    })
}

/// Registers in a `{r4, r5-r7, lr}` list (a D register counts as two words).
fn register_count(operands: &str) -> u32 {
    let Some(list) = operands
        .split_once('{')
        .and_then(|(_, r)| r.split_once('}'))
        .map(|(l, _)| l)
    else {
        return 1;
    };
    list.split(',')
        .map(|r| {
            let r = r.trim();
            let words = if r.starts_with('d') { 2 } else { 1 };
            let n = match r.split_once('-') {
                Some((a, b)) => {
                    let num = |s: &str| {
                        s.trim()
                            .trim_start_matches(|c: char| c.is_ascii_alphabetic())
                            .parse::<u32>()
                            .unwrap_or(0)
                    };
                    num(b).saturating_sub(num(a)) + 1
                }
                None => 1,
            };
            n * words
        })
        .sum()
}

const CONDITIONS: [&str; 14] = [
    "eq", "ne", "cs", "hs", "cc", "lo", "mi", "pl", "vs", "vc", "hi", "ls", "ge", "lt",
];
const MORE_CONDITIONS: [&str; 3] = ["gt", "le", "al"];

fn is_condition(s: &str) -> bool {
    CONDITIONS.contains(&s) || MORE_CONDITIONS.contains(&s)
}

/// Estimated Cortex-M4 cycles of one executed instruction (Cortex-M4 TRM, tables 3-1 and 7-1;
/// zero-wait-state memory, as behind the STM32F4's ART accelerator): `taken` says whether
/// the next executed instruction is not the next in memory, `after_load` whether the
/// previous one was a single load (which the next load or store pipelines with).
fn cycles(insn: &Insn, taken: bool, after_load: bool) -> u32 {
    let full = insn.mnemonic.as_str();
    let base = full.split('.').next().unwrap_or(full);
    let ops = insn.operands.as_str();
    let writes_pc = ops.split(',').next().is_some_and(|d| d.trim() == "pc");
    let branch_like = matches!(base, "b" | "bl" | "blx" | "bx" | "cbz" | "cbnz")
        || (base.len() == 3 && base.starts_with('b') && is_condition(&base[1..]));
    if branch_like {
        return if taken { 1 + REFILL } else { 1 };
    }
    if matches!(base, "tbb" | "tbh") {
        return 2 + 1 + REFILL;
    }
    let n = register_count(ops);
    let single_load =
        base.starts_with("ldr") && !base.starts_with("ldrd") && !base.starts_with("ldrex");
    match base {
        _ if base.starts_with("pop") || base.starts_with("ldm") => {
            1 + n + if ops.contains("pc") { REFILL } else { 0 }
        }
        _ if base.starts_with("push") || base.starts_with("stm") => 1 + n,
        "vpush" | "vpop" | "vldmia" | "vldmdb" | "vstmia" | "vstmdb" | "vldm" | "vstm" => 1 + n,
        _ if base.starts_with("ldrd") || base.starts_with("strd") => 3,
        _ if single_load && writes_pc => 2 + REFILL,
        _ if single_load => {
            if after_load {
                1
            } else {
                2
            }
        }
        _ if base.starts_with("str") => {
            // Register offset: two cycles; immediate offset: one (the write buffer).
            let register_offset = ops.split_once('[').is_some_and(|(_, a)| {
                a.split(',')
                    .nth(1)
                    .is_some_and(|o| o.trim().starts_with('r'))
            });
            if register_offset {
                2
            } else {
                1
            }
        }
        "vldr" | "vstr" => {
            if ops.trim_start().starts_with('d') {
                3
            } else {
                2
            }
        }
        "sdiv" | "udiv" => 12,
        "mla" | "mls" => 2,
        "vmla" | "vmls" | "vnmla" | "vnmls" | "vfma" | "vfms" | "vfnma" | "vfnms" => 3,
        "vdiv" | "vsqrt" => 14,
        "vmov" if ops.matches(',').count() >= 2 => 2,
        _ if writes_pc => 1 + REFILL,
        _ => 1,
    }
}

/// Counts of one measured region.
#[derive(Clone, Copy, Debug, Default)]
struct Region {
    instructions: u64,
    cycles: u64,
}

/// Runs `qemu-system-arm` on the bench ELF; returns its standard output. With `trace`, every
/// executed instruction is logged into a FIFO read by `on_line`.
fn run_qemu(
    elf: &Path,
    args: &[String],
    trace: Option<&mut dyn FnMut(&str)>,
    icount: bool,
) -> Result<String, String> {
    let dir = std::env::temp_dir().join(format!("impact-m4-{}", std::process::id()));
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let mut cmd = Command::new("qemu-system-arm");
    cmd.args([
        "-machine",
        "mps2-an386",
        "-cpu",
        "cortex-m4",
        "-nographic",
        "-monitor",
        "none",
        "-serial",
        "null",
    ]);
    let mut config = String::from("enable=on,target=native,arg=firmware");
    for a in args {
        config.push_str(",arg=");
        config.push_str(a);
    }
    cmd.args(["-semihosting-config", &config]);
    cmd.arg("-kernel").arg(elf);
    cmd.stdout(Stdio::piped()).stderr(Stdio::piped());
    if icount {
        cmd.args(["-icount", "shift=0"]);
    }
    let fifo = dir.join("trace.fifo");
    let result = match trace {
        None => cmd.output().map_err(|e| format!("qemu-system-arm: {e}")),
        Some(on_line) => {
            let _ = std::fs::remove_file(&fifo);
            let status = Command::new("mkfifo")
                .arg(&fifo)
                .status()
                .map_err(|e| format!("mkfifo: {e}"))?;
            if !status.success() {
                return Err(format!("mkfifo {} failed", fifo.display()));
            }
            cmd.args(["-singlestep", "-d", "exec,nochain", "-D"])
                .arg(&fifo);
            let child = cmd.spawn().map_err(|e| format!("qemu-system-arm: {e}"))?;
            // QEMU opens the log when it starts; the FIFO blocks until then.
            let file =
                std::fs::File::open(&fifo).map_err(|e| format!("{}: {e}", fifo.display()))?;
            let mut reader = BufReader::with_capacity(1 << 20, file);
            let mut line = String::new();
            loop {
                line.clear();
                match reader.read_line(&mut line) {
                    Ok(0) => break,
                    Ok(_) => on_line(&line),
                    Err(e) => return Err(format!("reading the trace: {e}")),
                }
            }
            child
                .wait_with_output()
                .map_err(|e| format!("qemu-system-arm: {e}"))
        }
    };
    let _ = std::fs::remove_file(&fifo);
    let _ = std::fs::remove_dir(&dir);
    let out = result?;
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    if !out.status.success() || stdout.lines().any(|l| l.starts_with("error")) {
        return Err(format!(
            "the M4 bench failed ({}):\n{}{}",
            out.status,
            stdout,
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    Ok(stdout)
}

/// `key=value` fields of an output line.
fn fields(line: &str) -> HashMap<&str, &str> {
    line.split_whitespace()
        .filter_map(|w| w.split_once('='))
        .collect()
}

fn number<T: std::str::FromStr>(m: &HashMap<&str, &str>, key: &str) -> Result<T, String> {
    m.get(key)
        .and_then(|v| v.parse().ok())
        .ok_or_else(|| format!("M4 bench output: no `{key}`"))
}

/// The seed bench impact (seed 001: 60 g at 1.3357 m/s, two-phase), 40 ms after the start of
/// a 120 ms recording at 500 kS/s, 12-bit ADC codes.
pub fn seed_recording() -> Result<Vec<i16>, String> {
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
    let args = Wrap::try_parse_from(args).map_err(|e| e.to_string())?;
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

/// A maths function compared: name, f64 reference, input range, the back-ends that offer it.
type MathCase = (
    &'static str,
    fn(f64) -> f64,
    (f32, f32),
    &'static [&'static str],
);

/// The maths functions the models use, compared across back-ends.
fn maths() -> Vec<MathCase> {
    vec![
        (
            "sqrt",
            f64::sqrt,
            (1e-4, 1e3),
            &["libm", "micromath", "vsqrt"],
        ),
        ("exp", f64::exp, (-10.0, 10.0), &["libm", "micromath"]),
        ("ln", f64::ln, (1e-4, 1e3), &["libm", "micromath"]),
        (
            "pow1.5",
            |x| x.powf(1.5),
            (1e-4, 1e3),
            &["libm", "micromath", "vsqrt"],
        ),
        ("sin", f64::sin, (-3.0, 3.0), &["libm", "micromath"]),
        ("cos", f64::cos, (-3.0, 3.0), &["libm", "micromath"]),
        ("asin", f64::asin, (-0.999, 0.999), &["libm", "micromath"]),
        ("acos", f64::acos, (-0.999, 0.999), &["libm", "micromath"]),
    ]
}

/// The host's copy of a back-end function (the same code as on the M4: f32 arithmetic is
/// IEEE on both).
fn host_math(op: &str, backend: &str) -> Option<fn(f32) -> f32> {
    use micromath::F32Ext;
    Some(match (op, backend) {
        ("sqrt", "libm" | "vsqrt") => libm::sqrtf,
        ("sqrt", "micromath") => |x| F32Ext::sqrt(x),
        ("exp", "libm") => libm::expf,
        ("exp", "micromath") => |x| F32Ext::exp(x),
        ("ln", "libm") => libm::logf,
        ("ln", "micromath") => |x| F32Ext::ln(x),
        ("pow1.5", "libm") => |x| libm::powf(x, 1.5),
        ("pow1.5", "vsqrt") => |x| x * libm::sqrtf(x),
        ("pow1.5", "micromath") => |x| F32Ext::powf(x, 1.5),
        ("sin", "libm") => libm::sinf,
        ("sin", "micromath") => |x| F32Ext::sin(x),
        ("cos", "libm") => libm::cosf,
        ("cos", "micromath") => |x| F32Ext::cos(x),
        ("asin", "libm") => libm::asinf,
        ("asin", "micromath") => |x| F32Ext::asin(x),
        ("acos", "libm") => libm::acosf,
        ("acos", "micromath") => |x| F32Ext::acos(x),
        _ => return None,
    })
}

/// Largest relative error of `f` against `reference` over 2^16 points of `range` (relative
/// to max(|exact|, 1e-3) so that zeros of sin and cos do not dominate).
fn math_error(f: fn(f32) -> f32, reference: fn(f64) -> f64, range: (f32, f32)) -> f64 {
    let n = 1 << 16;
    (0..=n)
        .map(|k| {
            let x = range.0 + (range.1 - range.0) * (k as f32 / n as f32);
            let exact = reference(x as f64);
            ((f(x) as f64 - exact) / exact.abs().max(1e-3)).abs()
        })
        .fold(0.0, f64::max)
}

/// Builds the bench ELF with cargo (a no-op when up to date).
fn build() -> Result<PathBuf, String> {
    crate::firmware_link::qemu::build_firmware_bin("m4-bench", Some("m4-bench"))
}

/// Runs the whole benchmark (about a minute: the trace run dominates).
pub fn run(args: &M4Args) -> Result<(M4Report, String), String> {
    crate::firmware_link::qemu::tools_available()?;
    let elf = match &args.elf {
        Some(e) => e.clone(),
        None => build()?,
    };
    let code = disassemble(&elf)?;
    let samples = seed_recording()?;
    let dir = std::env::temp_dir();
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.subsec_nanos());
    let stem = format!("impact-m4-{}-{nanos}", std::process::id());
    let raw = dir.join(format!("{stem}.i16"));
    let bytes: Vec<u8> = samples.iter().flat_map(|c| c.to_le_bytes()).collect();
    std::fs::write(&raw, bytes).map_err(|e| format!("{}: {e}", raw.display()))?;
    let trace_jobs = dir.join(format!("{stem}-trace.txt"));
    let count_jobs = dir.join(format!("{stem}-count.txt"));
    let result = (|| {
        std::fs::write(
            &trace_jobs,
            format!("selftest\n{}\nstream pipeline\n", scene_line(NO_FITS)),
        )
        .map_err(|e| e.to_string())?;
        // Trace run: per-block regions.
        let mut regions: Vec<Region> = Vec::new();
        let mut profile: Vec<HashMap<String, u64>> = Vec::new();
        let mut state = TraceState::default();
        let mut on_line =
            |line: &str| state.line(line, &code, &mut regions, &mut profile, args.profile);
        let out = run_qemu(
            &elf,
            &["trace".into(), path_arg(&raw)?, path_arg(&trace_jobs)?],
            Some(&mut on_line),
            false,
        )?;
        if !out.lines().any(|l| l == "selftest ok") {
            return Err(format!("the M4 self-test did not pass:\n{out}"));
        }
        let kinds: String = out
            .lines()
            .filter_map(|l| l.strip_prefix("kinds "))
            .collect();
        if kinds.len() != regions.len() {
            return Err(format!(
                "trace: {} regions for {} blocks",
                regions.len(),
                kinds.len()
            ));
        }
        let stream = out
            .lines()
            .find(|l| l.starts_with("stream "))
            .map(fields)
            .ok_or("trace run: no stream line")?;
        let n_samples: usize = number(&stream, "samples")?;
        let block: usize = number(&stream, "block")?;
        let reports: u32 = number(&stream, "reports")?;
        if reports != 1 {
            return Err(format!("the seed recording gave {reports} reports, not 1"));
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
            return Err(format!("trace: unexpected block kinds {kinds}"));
        }
        let per = |r: Region, n: u64| r.instructions as f64 / n as f64;
        let per_c = |r: Region, n: u64| r.cycles as f64 / n as f64;
        let idle_ips = per(idle, idle_n);
        let impact_ips = per(active, active_n);
        // The trigger and end blocks: their samples at the in-impact rate, the rest per impact.
        let trigger_instructions =
            (trigger.instructions as f64 - impact_ips * trigger_n as f64).max(0.0) as u64;
        let report_instructions =
            (end.instructions as f64 - impact_ips * end_n as f64).max(0.0) as u64;
        let idle_cps = per_c(idle, idle_n);
        let impact_cps = per_c(active, active_n);
        let worst = idle_cps.max(impact_cps);

        // Count run: fits, solves, maths.
        let mut jobs = String::new();
        jobs.push_str(&format!("{}\nstream no-fit\n", scene_line(NO_FITS)));
        for (i, (_, keys)) in FIT_VARIANTS.iter().enumerate() {
            jobs.push_str(&format!("{}\nstream fit{i}\n", scene_line(keys)));
        }
        jobs.push_str(&format!("{}\nstream srs\n", scene_line(SPECTRUM_KEYS)));
        let mut solve_rows = Vec::new();
        for case in solve_cases() {
            let exact = solve(&case.model, &case.impact, &Settings::exact())
                .map_err(|e| format!("{}: {e}", case.name))?;
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
                let f = host_math(op, b).ok_or("no host maths function")?;
                math_rows.push((op, *b, math_error(f, reference, range)));
            }
        }
        std::fs::write(&count_jobs, jobs).map_err(|e| e.to_string())?;
        let out = run_qemu(
            &elf,
            &["count".into(), path_arg(&raw)?, path_arg(&count_jobs)?],
            None,
            true,
        )?;
        let lines: Vec<&str> = out.lines().collect();
        let find = |prefix: &str| {
            lines
                .iter()
                .find(|l| l.starts_with(prefix))
                .map(|l| fields(l))
                .ok_or_else(|| format!("count run: no `{prefix}` line"))
        };
        let cal = find("calibrate ")?;
        let ipt = number::<f64>(&cal, "instructions")? / number::<f64>(&cal, "ticks")?;
        let ticks_total = |label: &str| -> Result<f64, String> {
            number::<f64>(&find(&format!("ticks {label} "))?, "total")
        };
        let base = ticks_total("no-fit")?;
        let mut fits = Vec::new();
        for (i, (name, _)) in FIT_VARIANTS.iter().enumerate() {
            let s = find(&format!("stream fit{i} "))?;
            let got: String = number(&s, "fits")?;
            if !got.contains('1') {
                return Err(format!("the {name} fit gave no result on the seed impact"));
            }
            fits.push(FitCost {
                fit: name.to_string(),
                instructions: ((ticks_total(&format!("fit{i}"))? - base) * ipt).max(0.0) as u64,
            });
        }
        let spectrum_instructions = ((ticks_total("srs")? - base) * ipt).max(0.0) as u64;
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
                instructions: (number::<f64>(&s, "ticks")? * ipt / number::<f64>(&s, "reps")?)
                    .round() as u64,
                same_bits_as_host: ok == 1 && m4_bits == host_bits,
            });
        }
        let loop_ticks = number::<f64>(&find("math none libm ")?, "ticks")?;
        let mut maths_out = Vec::new();
        for (op, b, err) in math_rows {
            let m = find(&format!("math {op} {b} "))?;
            let calls: f64 = number(&m, "calls")?;
            let ticks: f64 = number(&m, "ticks")?;
            maths_out.push(MathCost {
                op: op.to_string(),
                backend: b.to_string(),
                instructions_per_call: ((ticks - loop_ticks) * ipt / calls).max(0.0),
                max_relative_error: err,
            });
        }
        let firmware = crate::firmware_link::qemu::build_firmware()?;
        let firmware_idle = firmware_idle_marginal(&firmware)?;
        let report = M4Report {
            block,
            idle_instructions_per_sample: idle_ips,
            impact_instructions_per_sample: impact_ips,
            idle_cycles_per_sample: idle_cps,
            impact_cycles_per_sample: impact_cps,
            estimated_cycles_per_sample: worst,
            headroom_at_500k: 1.0 - worst / (BOARD_CLOCK_HZ / SEED_RATE_HZ),
            headroom_at_adc_top_rate: 1.0 - worst / (BOARD_CLOCK_HZ / ADC_TOP_RATE_HZ),
            trigger_instructions,
            report_instructions,
            impact_samples: trigger_n + active_n + end_n,
            analysis_instructions: report_instructions
                + fits
                    .iter()
                    .find(|f| f.fit == BOARD_FITS)
                    .map_or(0, |f| f.instructions),
            spectrum_instructions,
            fits,
            solves,
            maths: maths_out,
            instructions_per_tick: ipt,
            firmware_idle_instructions_per_sample: firmware_idle,
        };
        let prof = if args.profile {
            profile_text(&kinds, &profile)
        } else {
            String::new()
        };
        Ok((report, prof))
    })();
    for f in [&raw, &trace_jobs, &count_jobs] {
        let _ = std::fs::remove_file(f);
    }
    result
}

/// Instructions the whole emulator firmware executes per idle sample (see
/// [`M4Report::firmware_idle_instructions_per_sample`]).
fn firmware_idle_marginal(firmware: &Path) -> Result<f64, String> {
    let dir = std::env::temp_dir();
    let mut totals = Vec::new();
    for n in [1usize << 17, 1 << 18] {
        let counts = crate::bench::throughput::impact_stream(n, 0);
        let raw = dir.join(format!("impact-m4-idle-{}-{n}.i16", std::process::id()));
        let bytes: Vec<u8> = counts.iter().flat_map(|c| c.to_le_bytes()).collect();
        std::fs::write(&raw, bytes).map_err(|e| format!("{}: {e}", raw.display()))?;
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

fn path_arg(p: &Path) -> Result<String, String> {
    let s = p.to_string_lossy().into_owned();
    if s.contains([' ', ',']) {
        return Err(format!(
            "{s}: semihosting cannot pass a path with spaces or commas"
        ));
    }
    Ok(s)
}

/// Walks the trace: counts the instructions between the marks.
#[derive(Default)]
struct TraceState {
    /// Inside a measured region.
    counting: bool,
    /// Inside `bench_begin` (the region starts when it returns).
    in_begin: bool,
    current: Region,
    /// The last counted instruction, whose cycles wait for the next address.
    prev: Option<u32>,
    after_load: bool,
    symbols: HashMap<String, u64>,
}

impl TraceState {
    fn line(
        &mut self,
        line: &str,
        code: &Code,
        regions: &mut Vec<Region>,
        profile: &mut Vec<HashMap<String, u64>>,
        keep_profile: bool,
    ) {
        // `Trace 0: 0x7ff9dc000100 [00800408/00000400/00000110/ff000201] Reset`
        let Some(pc) = line
            .split_once('[')
            .and_then(|(_, r)| r.split('/').nth(1))
            .and_then(|p| u32::from_str_radix(p, 16).ok())
        else {
            return;
        };
        let inside = |r: (u32, u32)| pc >= r.0 && pc < r.1;
        if inside(code.begin) {
            self.in_begin = true;
            self.counting = false;
            self.prev = None;
            return;
        }
        if self.in_begin {
            self.in_begin = false;
            self.counting = true;
            self.current = Region::default();
            self.after_load = false;
            self.symbols.clear();
        }
        if pc == code.end.0 && self.counting {
            // The previous instruction (the call) is counted; close it.
            self.close_prev(pc, code);
            self.counting = false;
            regions.push(self.current);
            if keep_profile {
                profile.push(std::mem::take(&mut self.symbols));
            }
            return;
        }
        if !self.counting {
            return;
        }
        self.close_prev(pc, code);
        self.prev = Some(pc);
        self.current.instructions += 1;
        if keep_profile {
            let sym = line.rsplit(' ').next().unwrap_or("?").trim().to_string();
            *self.symbols.entry(sym).or_default() += 1;
        }
    }

    /// Adds the cycles of the previous instruction, now that the next address is known.
    fn close_prev(&mut self, next_pc: u32, code: &Code) {
        if let Some(pc) = self.prev.take() {
            if let Some(insn) = code.insns.get(&pc) {
                let taken = next_pc != pc + insn.size;
                self.current.cycles += cycles(insn, taken, self.after_load) as u64;
                let base = insn.mnemonic.split('.').next().unwrap_or("");
                self.after_load = base.starts_with("ldr") && !base.starts_with("ldrd");
            } else {
                self.current.cycles += 1;
                self.after_load = false;
            }
        }
    }
}

fn profile_text(kinds: &str, profile: &[HashMap<String, u64>]) -> String {
    let mut out = String::new();
    for (kind, name) in [
        ('i', "idle"),
        ('t', "trigger"),
        ('a', "in impact"),
        ('e', "end (report)"),
    ] {
        let mut sum: HashMap<&str, u64> = HashMap::new();
        for (k, p) in kinds.chars().zip(profile) {
            if k == kind {
                for (s, n) in p {
                    *sum.entry(s.as_str()).or_default() += n;
                }
            }
        }
        let mut v: Vec<_> = sum.into_iter().collect();
        v.sort_by_key(|e| std::cmp::Reverse(e.1));
        out.push_str(&format!("{name}:\n"));
        for (s, n) in v.into_iter().take(8) {
            out.push_str(&format!("  {n:>10}  {s}\n"));
        }
    }
    out
}

/// The report as a table.
pub fn table(r: &M4Report) -> String {
    let mut s = String::new();
    s.push_str(&format!(
        "Cortex-M4F (QEMU mps2-an386, exact instruction counts), board scene, {}-sample blocks\n",
        r.block
    ));
    s.push_str(&format!(
        "  idle        {:6.2} instructions/sample (target <= {IDLE_TARGET}), ~{:.1} cycles\n",
        r.idle_instructions_per_sample, r.idle_cycles_per_sample
    ));
    s.push_str(&format!(
        "  in impact   {:6.2} instructions/sample (target <= {IMPACT_TARGET}), ~{:.1} cycles\n",
        r.impact_instructions_per_sample, r.impact_cycles_per_sample
    ));
    s.push_str(&format!(
        "  whole emulator firmware, idle: {:.2} instructions/sample (tasks, channel, executor, replay source)\n",
        r.firmware_idle_instructions_per_sample
    ));
    s.push_str(&format!(
        "  worst ~{:.1} cycles/sample: headroom {:.1} % at 500 kS/s (336 cycles), {:.1} % at 2.4 MS/s (70 cycles)\n",
        r.estimated_cycles_per_sample,
        100.0 * r.headroom_at_500k,
        100.0 * r.headroom_at_adc_top_rate
    ));
    s.push_str(&format!(
        "  per impact: trigger {} instructions, report (no fit) {} instructions ({} samples)\n",
        r.trigger_instructions, r.report_instructions, r.impact_samples
    ));
    for f in &r.fits {
        s.push_str(&format!(
            "  fit {:<38} {:>12} instructions ({:.1} ms at 168 MHz, 1 instruction/cycle)\n",
            f.fit,
            f.instructions,
            f.instructions as f64 / BOARD_CLOCK_HZ * 1e3
        ));
    }
    s.push_str(&format!(
        "  the board's whole analysis of one impact (report + fits, n fitted): {} instructions ({:.1} ms at 125 M instructions/s)\n",
        r.analysis_instructions,
        r.analysis_instructions as f64 / 125e6 * 1e3
    ));
    s.push_str(&format!(
        "  shock spectra of the impact (SRS, PVSS, half-sine; 1/6 octave from 10 Hz): {} instructions ({:.1} ms at 125 M instructions/s)\n",
        r.spectrum_instructions,
        r.spectrum_instructions as f64 / 125e6 * 1e3,
    ));
    for (name, now, target) in targets(r) {
        s.push_str(&format!(
            "  target: {name:<40} {now:>10} <= {target:>9}: {}\n",
            if now <= target { "met" } else { "MISSED" }
        ));
    }
    s.push_str("\nOne impact in f32 at <= 1e-4 relative error (cheapest setting on the ladder):\n");
    s.push_str("  case                       method     setting       error   instructions  same bits as host\n");
    for v in &r.solves {
        s.push_str(&format!(
            "  {:<26} {:<9} {:>8}  {:>10.1e}  {:>13}  {}\n",
            v.case,
            v.method,
            if v.method == "adaptive" {
                format!("{:.0e}", v.setting)
            } else {
                format!("{}", v.setting)
            },
            v.error,
            v.instructions,
            if v.same_bits_as_host { "yes" } else { "NO" }
        ));
    }
    s.push_str(
        "\nMaths back-ends (f32): instructions per call on the M4, largest relative error:\n",
    );
    for m in &r.maths {
        s.push_str(&format!(
            "  {:<7} {:<10} {:>8.1}  {:>9.1e}\n",
            m.op, m.backend, m.instructions_per_call, m.max_relative_error
        ));
    }
    s
}

/// Compares `r` with a stored baseline: every instruction count may grow by 10 % at most.
pub fn check(r: &M4Report, baseline: &M4Report) -> Result<String, String> {
    let mut rows: Vec<(String, f64, f64)> = vec![
        (
            "idle instructions/sample".into(),
            r.idle_instructions_per_sample,
            baseline.idle_instructions_per_sample,
        ),
        (
            "in-impact instructions/sample".into(),
            r.impact_instructions_per_sample,
            baseline.impact_instructions_per_sample,
        ),
        (
            "firmware idle instructions/sample".into(),
            r.firmware_idle_instructions_per_sample,
            baseline.firmware_idle_instructions_per_sample,
        ),
        (
            "trigger instructions".into(),
            r.trigger_instructions as f64,
            baseline.trigger_instructions as f64,
        ),
        (
            "report instructions".into(),
            r.report_instructions as f64,
            baseline.report_instructions as f64,
        ),
        (
            "whole analysis instructions".into(),
            r.analysis_instructions as f64,
            baseline.analysis_instructions as f64,
        ),
        (
            "shock spectra instructions".into(),
            r.spectrum_instructions as f64,
            baseline.spectrum_instructions as f64,
        ),
    ];
    for f in &r.fits {
        if let Some(b) = baseline.fits.iter().find(|b| b.fit == f.fit) {
            rows.push((
                format!("fit {}", f.fit),
                f.instructions as f64,
                b.instructions as f64,
            ));
        }
    }
    for v in &r.solves {
        if let Some(b) = baseline
            .solves
            .iter()
            .find(|b| b.case == v.case && b.method == v.method && b.setting == v.setting)
        {
            rows.push((
                format!("solve {} {}", v.case, v.method),
                v.instructions as f64,
                b.instructions as f64,
            ));
        }
    }
    let mut text = String::new();
    let mut failed = Vec::new();
    for (name, now, then) in rows {
        let ratio = if then > 0.0 { now / then } else { 1.0 };
        text.push_str(&format!(
            "  {name:<44} {now:>14.2} vs {then:>14.2} ({:+.1} %)\n",
            100.0 * (ratio - 1.0)
        ));
        if ratio > 1.10 {
            failed.push(format!("{name}: {now:.2} against {then:.2}"));
        }
    }
    for v in r.solves.iter().filter(|v| !v.same_bits_as_host) {
        failed.push(format!(
            "solve {} {}: the M4 and the host disagree",
            v.case, v.method
        ));
    }
    for (name, now, target) in targets(r) {
        if now > target {
            failed.push(format!(
                "{name}: {now} instructions, over its target of {target}"
            ));
        }
    }
    if failed.is_empty() {
        Ok(text)
    } else {
        Err(format!(
            "M4 instruction counts regressed by more than 10 %:\n{text}{}",
            failed.join("\n")
        ))
    }
}

/// The per-impact targets with what was measured: (name, instructions, target).
fn targets(r: &M4Report) -> Vec<(&'static str, u64, u64)> {
    let fit = |name: &str| {
        r.fits
            .iter()
            .find(|f| f.fit == name)
            .map_or(0, |f| f.instructions)
    };
    vec![
        ("report without fits", r.report_instructions, REPORT_TARGET),
        (
            "two-phase + nonlinear (n fixed) + hertz",
            fit("two-phase + nonlinear (n fixed) + hertz"),
            THREE_FITS_TARGET,
        ),
        (
            "nonlinear (n fitted)",
            fit("nonlinear (n fitted)"),
            EXPONENT_FIT_TARGET,
        ),
        (
            "the board's whole analysis",
            r.analysis_instructions,
            ANALYSIS_TARGET,
        ),
        (
            "shock spectra (1/6 octave)",
            r.spectrum_instructions,
            SPECTRUM_TARGET,
        ),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn insn(mnemonic: &str, operands: &str) -> Insn {
        Insn {
            size: 4,
            mnemonic: mnemonic.into(),
            operands: operands.into(),
        }
    }

    #[test]
    fn cortex_m4_timings() {
        // Cortex-M4 TRM: ALU 1, loads 2 (1 when pipelined after a load), immediate-offset
        // stores 1, LDM/STM/PUSH/POP 1 + N (+ refill when loading pc), taken branches
        // 1 + refill, MLA 2, divisions 2..12 (12 taken), VMLA 3, VDIV/VSQRT 14.
        assert_eq!(cycles(&insn("adds", "r0, r1, r2"), false, false), 1);
        assert_eq!(
            cycles(&insn("ldrsh.w", "r6, [r0, r3, lsl #1]"), false, false),
            2
        );
        assert_eq!(cycles(&insn("ldr", "r1, [r2, #4]"), false, true), 1);
        assert_eq!(cycles(&insn("str", "r1, [r2, #4]"), false, false), 1);
        assert_eq!(cycles(&insn("str.w", "r1, [r2, r3]"), false, false), 2);
        assert_eq!(
            cycles(&insn("push", "{r4, r5, r6, r7, lr}"), false, false),
            6
        );
        assert_eq!(
            cycles(&insn("pop", "{r4, r5, r6, pc}"), true, false),
            5 + REFILL
        );
        assert_eq!(
            cycles(&insn("ldmia", "r1!, {r3, r4, r5, r6}"), false, false),
            5
        );
        assert_eq!(cycles(&insn("vpush", "{d8-d9}"), false, false), 5);
        assert_eq!(
            cycles(&insn("bne.n", "75ec <f+0x38c>"), true, false),
            1 + REFILL
        );
        assert_eq!(cycles(&insn("bne.n", "75ec <f+0x38c>"), false, false), 1);
        assert_eq!(cycles(&insn("bl", "15eaa <g>"), true, false), 1 + REFILL);
        assert_eq!(cycles(&insn("mla", "r2, r5, r4, r2"), false, false), 2);
        assert_eq!(cycles(&insn("sdiv", "r0, r1, r2"), false, false), 12);
        assert_eq!(cycles(&insn("vmla.f32", "s0, s1, s2"), false, false), 3);
        assert_eq!(cycles(&insn("vsqrt.f32", "s0, s0"), false, false), 14);
        assert_eq!(cycles(&insn("vldr", "d0, [r0]"), false, false), 3);
        assert_eq!(cycles(&insn("vmov", "r0, r1, d0"), false, false), 2);
    }

    fn report(idle: f64, solve_instructions: u64, same: bool) -> M4Report {
        M4Report {
            block: 256,
            idle_instructions_per_sample: idle,
            impact_instructions_per_sample: 40.0,
            idle_cycles_per_sample: 0.0,
            impact_cycles_per_sample: 0.0,
            estimated_cycles_per_sample: 0.0,
            headroom_at_500k: 0.0,
            headroom_at_adc_top_rate: 0.0,
            trigger_instructions: 1000,
            report_instructions: 1000,
            impact_samples: 100,
            analysis_instructions: 2000,
            spectrum_instructions: 3000,
            fits: vec![],
            solves: vec![SolveCost {
                case: "c".into(),
                method: "rk4".into(),
                setting: 16.0,
                error: 1e-5,
                instructions: solve_instructions,
                same_bits_as_host: same,
            }],
            maths: vec![],
            instructions_per_tick: 40.0,
            firmware_idle_instructions_per_sample: 20.0,
        }
    }

    #[test]
    fn baseline_check_fails_on_a_regression_beyond_ten_percent() {
        let base = report(10.0, 1000, true);
        assert!(check(&report(10.9, 1099, true), &base).is_ok());
        assert!(check(&report(11.1, 1000, true), &base).is_err());
        assert!(check(&report(10.0, 1101, true), &base).is_err());
        assert!(check(&report(10.0, 1000, false), &base).is_err());
        // Getting faster is never a failure.
        assert!(check(&report(5.0, 10, true), &base).is_ok());
    }

    #[test]
    fn baseline_check_fails_over_an_absolute_target() {
        let base = report(10.0, 1000, true);
        let mut r = report(10.0, 1000, true);
        r.fits.push(FitCost {
            fit: "nonlinear (n fitted)".into(),
            instructions: EXPONENT_FIT_TARGET + 1,
        });
        let e = check(&r, &base).unwrap_err();
        assert!(e.contains("over its target"), "{e}");
        r.fits[0].instructions = EXPONENT_FIT_TARGET;
        assert!(check(&r, &base).is_ok());
        r.analysis_instructions = ANALYSIS_TARGET + 1;
        assert!(check(&r, &base).is_err());
        r.analysis_instructions = ANALYSIS_TARGET;
        r.spectrum_instructions = SPECTRUM_TARGET + 1;
        assert!(check(&r, &base).is_err());
    }
}
