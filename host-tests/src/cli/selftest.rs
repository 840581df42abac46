//! `impact selftest`: the board's bring-up self-test (`cargo fw-run --features selftest`,
//! docs/board.md) on the emulated board. What the DAC plays is replayed as the ADC's codes
//! ([`impact_firmware::selftest::code_at`]) through the whole monitor (stream, capture,
//! analysis, reporter), and the firmware's own judge gives its `selftest` lines and verdict:
//! everything the board's self-test runs but the wire, the DAC and the ADC themselves.
//! `--wire-gain` and `--adc-rate` stand for a faulty loop, so the FAIL path is seen too.

use std::path::PathBuf;
use std::time::Duration;

use clap::Args;
use impact_firmware::selftest::{self, Verdict, PULSES, ZERO_CODE};

use crate::firmware_link::line::{FieldError, Fields};
use crate::firmware_link::qemu::{build_firmware, run_emulator, Pacing, QemuError, Samples};
use crate::report::spec::Judged;

/// `impact selftest` options.
#[derive(Args, Clone, Debug)]
pub struct SelftestArgs {
    /// The played pulse reaches the ADC times this: 1 is the jumper; 0.9 a divider (or a gain
    /// error) of 10 %.
    #[arg(long, default_value_t = 1.0, value_parser = positive)]
    pub wire_gain: f64,
    /// The rate the emulated ADC really samples at, Hz (1 kS/s to 10 MS/s), while the
    /// firmware takes it for the board's nominal rate (a mis-set trigger timer) [default: the
    /// nominal rate].
    #[arg(long, value_parser = adc_rate)]
    pub adc_rate: Option<f64>,
    /// Emulator firmware ELF [default: build it with cargo into target/emulator when its
    /// sources changed].
    #[arg(long)]
    pub elf: Option<PathBuf>,
    /// Write the firmware's whole decoded log to this file.
    #[arg(long, value_name = "FILE")]
    pub log: Option<PathBuf>,
    /// Stop QEMU after this many seconds.
    #[arg(long, default_value_t = 600)]
    pub timeout: u64,
}

/// A positive, finite number.
#[derive(Debug, thiserror::Error)]
#[error("{value}: not a positive number")]
pub struct NotPositive {
    value: String,
}

fn positive(s: &str) -> Result<f64, NotPositive> {
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(NotPositive {
            value: s.to_string(),
        }),
    }
}

/// An ADC rate in 1 kS/s – 10 MS/s.
#[derive(Debug, thiserror::Error)]
#[error("{value}: not a rate from 1000 to 10000000 Hz")]
pub struct NotARate {
    value: String,
}

fn adc_rate(s: &str) -> Result<f64, NotARate> {
    match s.parse::<f64>() {
        Ok(v) if (1e3..=1e7).contains(&v) => Ok(v),
        _ => Err(NotARate {
            value: s.to_string(),
        }),
    }
}

/// Why the emulated self-test gave no verdict.
#[derive(Debug, thiserror::Error)]
pub enum SelftestError {
    #[error(transparent)]
    Qemu(#[from] QemuError),
    #[error("the emulated firmware failed ({status}); see its log above")]
    Firmware { status: std::process::ExitStatus },
    #[error("the firmware's log has no selftest_result line")]
    NoVerdict,
    #[error("the selftest_result line: {0}")]
    Field(#[from] FieldError),
    #[error(transparent)]
    Output(#[from] crate::output::OutputError),
}

/// Seconds replayed: the settling time and [`PULSES`] periods, the first pulse 50 ms in, and
/// half a period to spare.
fn replayed_s() -> f64 {
    selftest::SETTLE_S + (f64::from(PULSES) + 0.5) * f64::from(selftest::PERIOD_S)
}

/// DAC updates before the first sample: the table's rest, so the first pulse starts 50 ms in.
const OFFSET_UPDATES: u64 = selftest::TABLE_LEN as u64 - selftest::DAC_RATE_HZ as u64 / 20;

/// The ADC's codes for the replay: the DAC's held codes sampled at `adc_rate_hz`, their
/// excursion from rest times `wire_gain`, within the ADC's 12 bits.
pub fn codes(n: usize, adc_rate_hz: f64, wire_gain: f64) -> Vec<i16> {
    (0..n as u64)
        .map(|i| {
            let code = f64::from(selftest::code_at(i, adc_rate_hz, OFFSET_UPDATES));
            let at_adc = f64::from(ZERO_CODE) + (code - f64::from(ZERO_CODE)) * wire_gain;
            at_adc.round().clamp(0.0, 4095.0) as i16
        })
        .collect()
}

/// Runs the self-test on the emulated board; the verdict as judged pulses (a failed one
/// makes the exit status 3).
pub fn run(args: &SelftestArgs) -> Result<Judged, SelftestError> {
    let scene = impact_firmware::scene::BENCH;
    let nominal = f64::from(scene.calibration.sample_rate_hz);
    let n = (replayed_s() * nominal) as usize;
    let samples = codes(n, args.adc_rate.unwrap_or(nominal), args.wire_gain);
    if let Some(path) = &args.log {
        let inputs = args
            .elf
            .iter()
            .fold(crate::output::Inputs::new(), |all, i| all.with(i));
        crate::output::check("--log", path, &inputs, None)?;
    }
    let elf = match &args.elf {
        Some(p) => p.clone(),
        None => build_firmware()?,
    };
    let run = run_emulator(
        &elf,
        Samples::Adc(&samples),
        &scene,
        true,
        Pacing::Lossless,
        Duration::from_secs(args.timeout),
        |line| {
            if line.contains("selftest") || line.contains("self-test") {
                crate::outln!("{line}");
            }
        },
    )?;
    if let Some(path) = &args.log {
        crate::output::write(path, (run.lines.join("\n") + "\n").as_bytes())?;
        crate::errln!("wrote {}", path.display());
    }
    if !run.status.success() {
        // Only the self-test's lines were shown: the rest says why the run failed.
        for line in run.lines.iter().filter(|l| !l.contains("selftest")) {
            crate::errln!("{line}");
        }
        return Err(SelftestError::Firmware { status: run.status });
    }
    let verdict = verdict(&run.lines)?;
    if verdict.judged < PULSES {
        crate::errln!(
            "self-test: {} of {PULSES} pulses came; the {} that did not count as failed",
            verdict.judged,
            PULSES - verdict.judged
        );
    }
    // The pulses that did not come count as failed: the verdict is PASS only with all of them.
    Ok(Judged {
        judged: PULSES as usize,
        failed: (PULSES - verdict.passed.min(PULSES)) as usize,
    })
}

/// The `selftest_result` line's verdict.
pub fn verdict(lines: &[String]) -> Result<Verdict, SelftestError> {
    let marker = "selftest_result ";
    let line = lines
        .iter()
        .find_map(|l| l.find(marker).map(|at| &l[at + marker.len()..]))
        .ok_or(SelftestError::NoVerdict)?;
    let f = Fields::parse(line)?;
    Ok(Verdict {
        pass: f.flag("pass")?,
        passed: f.num("passed")?,
        judged: f.num("judged")?,
    })
}
