//! `impact bench realtime`: the firmware in real-time emulation (QEMU `-icount shift=3`, the
//! emulated DMA) on trains of impacts: how late each report comes, and how many impacts per
//! second it sustains with nothing lost and every impact fully analysed, with and without
//! the fits, for the seed bench at 500 kS/s and for AFRL-like short pulses at 1 MS/s; and
//! the seed bench with everything on (the fits, the shock spectra and a verdict).

use std::path::Path;
use std::time::Duration;

use clap::Args;
use impact_core::model::{Linear, TwoPhase};
use impact_core::{Analysis, Approach, Calibration, FitSet, Impact, Scene};
use serde::Serialize;

use crate::firmware_link::line::Counter;
use crate::firmware_link::qemu::{self, Pacing};
use crate::synth::{record, DynLaw, Placed, Sensor};
use crate::testkit::cases;

use super::BenchError;

/// `impact bench realtime` options.
#[derive(Args, Clone, Debug)]
pub struct RealtimeArgs {
    /// Impacts per train.
    #[arg(long, default_value_t = 10)]
    pub impacts: usize,
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
    /// Emulator firmware ELF [default: build it].
    #[arg(long)]
    pub elf: Option<std::path::PathBuf>,
    /// Virtual time per instruction, 2^N ns: 3 (125 M instructions/s) stands for the
    /// STM32F407 at 168 MHz; 4 is a chip half as fast (the margin of that estimate).
    #[arg(long, default_value_t = qemu::BOARD_CLOCK_SHIFT, value_parser = clap::value_parser!(u8).range(0..=8))]
    pub clock_shift: u8,
}

/// One bench and pulse shape.
struct Case {
    name: &'static str,
    sensor: Sensor,
    law: Box<dyn DynLaw>,
    impact: Impact<f64>,
    scene: Scene,
    /// Spacings tried, s, from the widest: the train's nominal spacing first.
    spacings: &'static [f64],
    /// With everything on, if the case runs that too: its spacings (the analysis takes
    /// longer than some of the others').
    everything: Option<&'static [f64]>,
}

/// What the board does with each impact in a run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Work {
    /// The streaming fields only.
    Stream,
    /// The analysis with the three fits (the exponent fitted).
    Fits,
    /// The fits, the shock spectra (SRS and PVSS, 1/6 octave from 10 Hz) and a verdict
    /// ([`EVERYTHING_SPEC`]).
    Everything,
}

/// The specified pulse the seed bench is judged against with everything on (a rig striking
/// at one speed; its pulse is no such half-sine and fails it, which costs the verdict its
/// whole search).
pub const EVERYTHING_SPEC: &str = "half-sine,10g,3ms";

impl Work {
    fn label(self) -> &'static str {
        match self {
            Work::Stream => "no",
            Work::Fits => "fits",
            Work::Everything => "fits, spectra, verdict",
        }
    }
}

fn cases() -> Vec<Case> {
    // The seed bench as the board sees it: 12-bit ADC over ±800 m/s², 500 kS/s, its scene.
    let seed_sensor = Sensor::adc12(800.0);
    let kc = cases::bench_kc();
    let seed = Case {
        name: "seed bench (two-phase, 26 ms pulses), 500 kS/s",
        scene: scene(&seed_sensor, 10.0, 2.0, 2e-3, cases::BENCH_V0_M_S),
        sensor: seed_sensor,
        law: Box::new(TwoPhase {
            kc,
            kr: 40.0 * kc,
            c: 2.0,
            permanent_m: Some(cases::BENCH_X_P),
        }),
        impact: Impact::new(cases::BENCH_MASS_KG, cases::BENCH_V0_M_S),
        // Below ~27.3 ms (26 ms of pulse and the 2 ms hold) two impacts are one.
        spacings: &[0.08, 0.06, 0.05, 0.04, 0.035, 0.03, 0.028],
        everything: Some(&[
            0.32, 0.25, 0.2, 0.16, 0.125, 0.1, 0.08, 0.06, 0.05, 0.04, 0.035, 0.03, 0.028,
        ]),
    };
    // AFRL-like: a 150 µs pulse of ~7 kg_n (Δv 7 m/s), 12 bits over ±2e5 m/s², 1 MS/s.
    let mut afrl_sensor = Sensor::adc12(2e5);
    afrl_sensor.rate_hz = 1e6;
    let (m, v0, t_contact) = (0.06, 3.5, 150e-6);
    let k = m * (std::f64::consts::PI / t_contact).powi(2);
    let afrl = Case {
        name: "AFRL-like (150 µs pulses, ~7 kg_n), 1 MS/s",
        scene: scene(&afrl_sensor, 2000.0, 500.0, 1e-3, v0),
        sensor: afrl_sensor,
        law: Box::new(Linear { k }),
        impact: Impact::new(m, v0),
        // Below ~1.2 ms (the pulse and the 1 ms hold) two impacts are one.
        spacings: &[0.01, 0.005, 0.003, 0.002, 0.0015, 0.00125],
        everything: None,
    };
    vec![seed, afrl]
}

fn scene(sensor: &Sensor, trigger: f32, edge: f32, hold: f32, v0: f64) -> Scene {
    let mut s = Scene::new(sensor.calibration(), trigger);
    s.edge_m_s2 = edge;
    s.hold_s = hold;
    s.mass_kg = Some(0.06);
    s.approach = Approach::Speed { v0_m_s: v0 as f32 };
    // A train of strikes, every one at v0.
    s.v0_every = true;
    s.clip_counts = (0, 4095);
    s
}

/// What one train gave.
#[derive(Clone, Debug, Serialize)]
pub struct TrainRun {
    pub spacing_s: f64,
    pub impacts: usize,
    pub reports: usize,
    pub samples_lost: u64,
    pub analyses_skipped: u64,
    /// Reports without the spectra or the verdict the scene asked for.
    pub missing_work: u64,
    pub latency_median_s: Option<f64>,
    pub latency_max_s: Option<f64>,
    /// The last report's latency less the first's: a train whose analyses queue up (each
    /// longer than the spacing) keeps every impact analysed only while the captures last,
    /// its latency growing impact by impact.
    pub latency_growth_s: Option<f64>,
}

impl TrainRun {
    /// Every impact reported and analysed with nothing lost, at a pace the board keeps:
    /// latency growing by less than a tenth of the spacing over the train.
    fn sustained(&self) -> bool {
        self.samples_lost == 0
            && self.reports == self.impacts
            && self.analyses_skipped == 0
            && self.missing_work == 0
            && self
                .latency_growth_s
                .is_some_and(|g| g < 0.1 * self.spacing_s)
    }
}

/// One case with or without fits.
#[derive(Clone, Debug, Serialize)]
pub struct CaseResult {
    pub case: String,
    pub rate_hz: f64,
    pub work: Work,
    /// The train at the widest spacing.
    pub nominal: TrainRun,
    /// Highest impact rate tried with nothing lost and every impact analysed, per second.
    pub max_rate_fully_analysed_hz: Option<f64>,
    /// Highest impact rate tried with nothing lost (analyses may be skipped), per second.
    pub max_rate_lossless_hz: Option<f64>,
    pub runs: Vec<TrainRun>,
}

fn counts(case: &Case, n: usize, spacing: f64) -> Result<(Vec<i16>, Calibration), BenchError> {
    let placed: Vec<Placed<'_>> = (0..n)
        .map(|k| Placed {
            touch_s: 0.01 + spacing * k as f64,
            law: case.law.as_ref(),
            impact: case.impact,
        })
        .collect();
    let duration = 0.01 + spacing * n as f64;
    let rec = record(&case.sensor, duration, &placed)?;
    Ok((rec.samples, rec.calibration))
}

fn train(
    elf: &Path,
    case: &Case,
    scene: &Scene,
    n: usize,
    spacing: f64,
    clock_shift: u8,
) -> Result<TrainRun, BenchError> {
    let (samples, _) = counts(case, n, spacing)?;
    let run = qemu::run_emulator(
        elf,
        qemu::Samples::Adc(&samples),
        scene,
        false,
        Pacing::RealTime {
            rate_scale: 1.0,
            clock_shift,
            inject: None,
        },
        Duration::from_secs(1200),
        |_| {},
    )?;
    let log = crate::firmware_link::log::parse_log(&run.lines.join("\n"))?;
    let summary = log.summary.as_ref().ok_or(BenchError::NoSummary)?;
    let get = |counter: Counter| {
        (summary.state.readable(counter)).ok_or(BenchError::NoCounter { counter })
    };
    let mut latencies: Vec<f64> = log.latencies.iter().flatten().map(|&l| l as f64).collect();
    let growth = match (latencies.first(), latencies.last()) {
        (Some(first), Some(last)) => Some(last - first),
        _ => None,
    };
    // (A skipped analysis is counted as such, not here.)
    let missing = |r: &&impact_core::ImpactReport| {
        r.analysis == Analysis::Full
            && ((scene.spectrum.is_some() && r.spectrum.is_none())
                || (scene.spec.is_some() && r.verdict.is_none()))
    };
    let max = latencies.iter().copied().reduce(f64::max);
    Ok(TrainRun {
        spacing_s: spacing,
        impacts: n,
        reports: log.impacts.len(),
        samples_lost: get(Counter::SamplesLost)?,
        analyses_skipped: log
            .impacts
            .iter()
            .filter(|r| r.analysis == Analysis::Skipped)
            .count() as u64,
        missing_work: log.impacts.iter().filter(missing).count() as u64,
        latency_median_s: impact_io::time_axis::median(&mut latencies),
        latency_max_s: max,
        latency_growth_s: growth,
    })
}

/// Runs every case with and without fits, and the seed bench with everything on.
pub fn run(args: &RealtimeArgs) -> Result<Vec<CaseResult>, BenchError> {
    qemu::tools_available()?;
    let elf = match &args.elf {
        Some(p) => p.clone(),
        None => qemu::build_firmware()?,
    };
    let mut out = Vec::new();
    for case in cases() {
        let works = [
            (Work::Fits, Some(case.spacings)),
            (Work::Stream, Some(case.spacings)),
            (Work::Everything, case.everything),
        ];
        for (work, spacings) in works {
            let Some(spacings) = spacings else { continue };
            let scene = work_scene(case.scene, work)?;
            let mut runs = Vec::new();
            for &spacing in spacings {
                let r = train(&elf, &case, &scene, args.impacts, spacing, args.clock_shift)?;
                if !args.json {
                    crate::errln!(
                        "{}, {}, {:.1} ms apart: {} of {} reported, lost {}, skipped {}, without their spectra or verdict {}, latency median {} max {}",
                        case.name,
                        work.label(),
                        spacing * 1e3,
                        r.reports,
                        r.impacts,
                        r.samples_lost,
                        r.analyses_skipped,
                        r.missing_work,
                        ms(r.latency_median_s),
                        ms(r.latency_max_s),
                    );
                }
                runs.push(r);
            }
            let ok = |r: &&TrainRun| r.samples_lost == 0 && r.reports == r.impacts;
            let rate = |r: Option<&TrainRun>| r.map(|r| 1.0 / r.spacing_s);
            out.push(CaseResult {
                case: case.name.to_string(),
                rate_hz: case.sensor.rate_hz,
                work,
                nominal: runs[0].clone(),
                max_rate_fully_analysed_hz: rate(runs.iter().take_while(|r| r.sustained()).last()),
                max_rate_lossless_hz: rate(runs.iter().take_while(ok).last()),
                runs,
            });
        }
    }
    Ok(out)
}

/// The case's scene for `work`.
fn work_scene(mut scene: Scene, work: Work) -> Result<Scene, BenchError> {
    scene.fits = if work == Work::Stream {
        FitSet::none()
    } else {
        FitSet::all()
    };
    if work == Work::Everything {
        scene.spectrum = Some(impact_core::signal::spectrum::SpectrumSettings::new());
        scene.spec = Some(crate::pipeline::spec::parse(EVERYTHING_SPEC)?.spec);
    }
    Ok(scene)
}

/// A rate, per second: whole, or to a tenth where it is not (12.5 /s).
fn per_second(h: f64) -> String {
    if (h - h.round()).abs() < 0.05 {
        format!("{h:.0} /s")
    } else {
        format!("{h:.1} /s")
    }
}

fn ms(v: Option<f64>) -> String {
    v.map_or("-".into(), |v| format!("{:.1} ms", v * 1e3))
}

/// The results as a table.
pub fn table(results: &[CaseResult]) -> String {
    let mut s = String::from(
        "case | analysis | report latency at the widest spacing (median / max) | highest rate tried, every impact analysed | highest rate tried, nothing lost\n",
    );
    for r in results {
        s.push_str(&format!(
            "{} | {} | {} / {} ({:.0} ms apart) | {} | {}\n",
            r.case,
            r.work.label(),
            ms(r.nominal.latency_median_s),
            ms(r.nominal.latency_max_s),
            r.nominal.spacing_s * 1e3,
            r.max_rate_fully_analysed_hz
                .map_or("below the widest spacing".into(), per_second),
            r.max_rate_lossless_hz
                .map_or("below the widest spacing".into(), per_second),
        ));
    }
    s
}
