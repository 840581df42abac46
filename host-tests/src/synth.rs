//! Synthetic accelerometer recordings: model impacts turned into raw ADC samples with offset,
//! noise, quantisation, clipping, drift and dropped samples, for tests.

use std::io::Write;

use impact_core::solve::trajectory;
use impact_core::{Calibration, ContactLaw, Error, Impact, ImpactOutcome};

/// How the virtual sensor and ADC behave.
#[derive(Clone, Debug)]
pub struct Sensor {
    /// Samples per second, Hz.
    pub rate_hz: f64,
    /// ADC resolution: codes run from 0 to 2^bits - 1 (clipped there).
    pub bits: u32,
    /// Acceleration at full scale, m/s²: the codes span ±full_scale around mid-scale.
    pub full_scale_m_s2: f64,
    /// Sensor offset, codes from mid-scale.
    pub offset_counts: f64,
    /// White noise, RMS codes.
    pub noise_rms_counts: f64,
    /// Offset drift, codes per second.
    pub drift_counts_per_s: f64,
    /// Every `n`-th sample is lost (0: none).
    pub drop_every: usize,
    /// Seed of the noise generator.
    pub seed: u64,
}

impl Sensor {
    /// A 12-bit ADC at 500 kS/s over ±`full_scale_m_s2`, half a code of noise, small offset.
    pub fn adc12(full_scale_m_s2: f64) -> Self {
        Self {
            rate_hz: 500_000.0,
            bits: 12,
            full_scale_m_s2,
            offset_counts: 17.0,
            noise_rms_counts: 0.5,
            drift_counts_per_s: 0.0,
            drop_every: 0,
            seed: 1,
        }
    }

    /// m/s² per code.
    pub fn gain(&self) -> f64 {
        2.0 * self.full_scale_m_s2 / (1u64 << self.bits) as f64
    }

    /// The calibration the pipeline should use (the offset is learned from the baseline).
    pub fn calibration(&self) -> Calibration {
        Calibration {
            gain_m_s2_per_count: self.gain() as f32,
            sample_rate_hz: self.rate_hz as f32,
        }
    }
}

/// One contact placed in a recording.
pub struct Placed<'a> {
    /// Time of first touch, s.
    pub touch_s: f64,
    pub law: &'a dyn DynLaw,
    pub impact: Impact<f64>,
}

/// Object-safe view of a contact law (so a recording can mix models).
pub trait DynLaw {
    /// Decelerations at `lead_s + k period_s` after first touch, m/s², and the exact outcome.
    /// At most `max` samples are kept (the rest fall outside the recording): memory follows
    /// the recording, not the model's contact time.
    fn decelerations(
        &self,
        impact: &Impact<f64>,
        lead_s: f64,
        period_s: f64,
        max: usize,
    ) -> Result<(Vec<f64>, ImpactOutcome<f64>), Error>;
}

impl<L: ContactLaw<f64>> DynLaw for L {
    fn decelerations(
        &self,
        impact: &Impact<f64>,
        lead_s: f64,
        period_s: f64,
        max: usize,
    ) -> Result<(Vec<f64>, ImpactOutcome<f64>), Error> {
        let mut a = Vec::new();
        let exact = self.exact(impact)?;
        // The trajectory at the samples, to 1e-12 (far below any ADC's resolution).
        trajectory::sample(self, impact, 1e-12, lead_s, period_s, max as u64, |s| {
            a.push(s.force_n / impact.mass_kg)
        })?;
        Ok((a, exact))
    }
}

/// A recording and what is true about it.
pub struct Recording {
    /// Raw ADC codes.
    pub samples: Vec<i16>,
    pub calibration: Calibration,
    /// Exact outcome of each placed contact.
    pub truth: Vec<ImpactOutcome<f64>>,
    /// Samples that hit a rail.
    pub clipped: usize,
    /// A physical drop's end, where it came before `--duration` (the recording is shorter).
    pub ended: Option<(f64, crate::drop::End)>,
}

/// xorshift64* and Box–Muller: reproducible noise without a dependency.
struct Noise(u64);

impl Noise {
    fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let r = self.0.wrapping_mul(0x2545_f491_4f6c_dd1d);
        ((r >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
    fn gauss(&mut self) -> f64 {
        let (u, v) = (self.uniform(), self.uniform());
        (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
    }
}

/// Renders `contacts` into `duration_s` of recording; a touch may fall between samples.
pub fn record(
    sensor: &Sensor,
    duration_s: f64,
    contacts: &[Placed<'_>],
) -> Result<Recording, Error> {
    let n = (duration_s * sensor.rate_hz).ceil() as usize;
    let period = 1.0 / sensor.rate_hz;
    let mut accel = vec![0.0f64; n];
    let mut truth = Vec::new();
    for c in contacts {
        // Sample times k*period measured from a touch at touch_s.
        let first = (c.touch_s * sensor.rate_hz).ceil() as usize;
        // Rounding can make the lead a hair negative when the touch falls on a sample.
        let lead = (first as f64 * period - c.touch_s).max(0.0);
        let (a, exact) = c
            .law
            .decelerations(&c.impact, lead, period, n.saturating_sub(first))?;
        for (k, v) in a.into_iter().enumerate() {
            if let Some(slot) = accel.get_mut(first + k) {
                *slot += v;
            }
        }
        truth.push(exact);
    }
    let (samples, clipped) = quantise(sensor, &accel);
    Ok(Recording {
        samples,
        calibration: sensor.calibration(),
        truth,
        clipped,
        ended: None,
    })
}

/// The sensor's codes for the accelerations `accel` (m/s², one per sample period): offset,
/// drift, noise, rounding, rails, dropped samples; and how many hit a rail.
pub fn quantise(sensor: &Sensor, accel: &[f64]) -> (Vec<i16>, usize) {
    let period = 1.0 / sensor.rate_hz;
    let mut noise = Noise(sensor.seed.max(1));
    let gain = sensor.gain();
    let top = ((1u64 << sensor.bits) - 1) as f64;
    let mid = (1u64 << (sensor.bits - 1)) as f64;
    let mut samples = Vec::with_capacity(accel.len());
    let mut clipped = 0;
    for (k, a) in accel.iter().enumerate() {
        if sensor.drop_every > 0 && k % sensor.drop_every == sensor.drop_every - 1 {
            continue;
        }
        let t = k as f64 * period;
        let code = mid
            + sensor.offset_counts
            + sensor.drift_counts_per_s * t
            + a / gain
            + sensor.noise_rms_counts * noise.gauss();
        let q = code.round();
        if q <= 0.0 || q >= top {
            clipped += 1;
        }
        samples.push(q.clamp(0.0, top) as i16);
    }
    (samples, clipped)
}

/// Most samples `impact synth` renders (80 s at 500 kS/s; the recording is held in memory).
pub const MAX_SAMPLES: usize = 40_000_000;

/// `impact synth` options: one model impact rendered as an accelerometer recording.
#[derive(clap::Args, Clone, Debug)]
pub struct SynthArgs {
    /// Contact law (as `impact simulate --model`).
    #[arg(long, help_heading = "Model", value_enum, alias = "law")]
    pub model: crate::simulate::ModelName,
    /// Mass of the body, kg.
    #[arg(short = 'm', long, help_heading = "Model")]
    pub mass: f64,
    /// Approach speed, m/s (or --drop-height).
    #[arg(
        long,
        help_heading = "Model",
        required_unless_present = "drop_height",
        conflicts_with = "drop_height"
    )]
    pub v0: Option<f64>,
    /// A drop from rest: held on a support for --rest (the sensor reads +1 g), released, and
    /// falling this far to the pad, m (v0 = sqrt(2 g h)); gravity in every contact.
    #[arg(long, help_heading = "Model", conflicts_with_all = ["touch", "impacts"])]
    pub drop_height: Option<f64>,
    /// Time at rest on the support before the release, s (with --drop-height).
    #[arg(
        long,
        help_heading = "Model",
        requires = "drop_height",
        default_value_t = 0.05
    )]
    pub rest: f64,
    /// A vertical impact at --v0: gravity in the contact, the body in free fall before it
    /// (implied by --bounces and --drop-height; without it, a horizontal strike).
    #[arg(long, help_heading = "Model", conflicts_with = "impacts")]
    pub vertical: bool,
    #[command(flatten)]
    pub params: crate::simulate::ModelArgs,
    /// Sample rate, Hz.
    #[arg(
        short = 'r',
        long,
        help_heading = "Recording",
        default_value_t = 500_000.0
    )]
    pub rate: f64,
    /// ADC bits.
    #[arg(long, help_heading = "Recording", default_value_t = 12)]
    pub bits: u32,
    /// Full scale, m/s² (codes span ± this).
    #[arg(long, help_heading = "Recording", default_value_t = 800.0)]
    pub full_scale: f64,
    /// Noise, RMS codes.
    #[arg(long, help_heading = "Recording", default_value_t = 0.5)]
    pub noise: f64,
    /// Offset from mid-scale, codes.
    #[arg(long, help_heading = "Recording", default_value_t = 17.0)]
    pub offset: f64,
    /// Drift, codes per second.
    #[arg(long, help_heading = "Recording", default_value_t = 0.0)]
    pub drift: f64,
    /// Drop every N-th sample (0: none; 1 would drop them all).
    #[arg(long, help_heading = "Recording", default_value_t = 0, value_parser = drop_every)]
    pub drop_every: usize,
    /// Time of first touch, s.
    #[arg(long, help_heading = "Recording", default_value_t = 0.01)]
    pub touch: f64,
    /// Recording length, s.
    #[arg(long, help_heading = "Recording", default_value_t = 0.1)]
    pub duration: f64,
    /// Noise seed.
    #[arg(long, help_heading = "Recording", default_value_t = 1)]
    pub seed: u64,
    /// The same impact this many times, `--every` apart (a train for the real-time
    /// emulation).
    #[arg(long, help_heading = "Trains", default_value_t = 1, alias = "repeat")]
    pub impacts: usize,
    /// Time between the first touches of an `--impacts` train, s.
    #[arg(long, help_heading = "Trains", default_value_t = 0.08)]
    pub every: f64,
    /// A bounce train: the body touches at --v0 and bounces under standard gravity, this
    /// many contacts in all (the physical drop of `impact_host::drop`: gravity in each
    /// contact, ballistic flights from where the body left to the pad's recovered surface, a
    /// two-phase pad keeping its dent); the recording ends at the landing after the last
    /// contact, after a rebound below 1 mm/s, or where the pad could not recover in a flight.
    #[arg(
        long,
        help_heading = "Trains",
        default_value_t = 1,
        conflicts_with = "impacts"
    )]
    pub bounces: u32,
    /// The body strikes a target on a spring and damper to ground, not a wall: its mass, kg
    /// (one strike at --v0, horizontal or --vertical; the recording is the body's reading,
    /// `F / m`).
    #[arg(long, help_heading = "Target", conflicts_with_all = ["drop_height", "bounces", "impacts"])]
    pub target_mass: Option<f64>,
    /// The body strikes a linear target in state-space form instead (JSON, as `impact
    /// simulate --target`: input the contact force, N; outputs the contact point's
    /// displacement, m, and velocity, m/s; at rest at first touch).
    #[arg(long, help_heading = "Target", value_name = "FILE",
          conflicts_with_all = ["drop_height", "bounces", "impacts", "target_mass"])]
    pub target: Option<std::path::PathBuf>,
    /// The target's spring to ground, N/m [default: 0, a free body].
    #[arg(long, help_heading = "Target", requires = "target_mass")]
    pub target_stiffness: Option<f64>,
    /// The target's damper to ground, N s/m [default: 0].
    #[arg(long, help_heading = "Target", requires = "target_mass")]
    pub target_damping: Option<f64>,
}

/// `impact synth` arguments of the seed-001 bench impact (60 g at 1.3357 m/s into the
/// two-phase Kelvin–Voigt law matching Table 1's x_m and x_p), shared by the tests and the M4
/// benchmark.
pub const SEED_BENCH_ARGS: [&str; 14] = [
    "--model",
    "two-phase",
    "--mass",
    "0.06",
    "--v0",
    "1.3357",
    "--max-deformation",
    "0.0186",
    "--kr",
    "12376",
    "--permanent",
    "0.0182",
    "--damping",
    "2",
];

/// Why `impact synth` refused, or could not render or write the recording.
#[derive(Debug, thiserror::Error)]
pub enum SynthError {
    #[error(transparent)]
    Model(#[from] crate::simulate::ModelError),
    /// A parameter out of its domain (or a contact not resolved), named as its option.
    #[error("{}", crate::flags::core(*.0))]
    Core(#[from] Error),
    /// An option's value outside what it takes: `{option}: must {rule}`.
    #[error("{option}: must {rule}")]
    Invalid {
        option: &'static str,
        rule: &'static str,
    },
    #[error(
        "--duration x --rate: {samples:.3e} samples; at most {MAX_SAMPLES:.0e} in one synthetic recording"
    )]
    TooManySamples { samples: f64 },
    #[error("--output and --raw are both {}", .path.display())]
    SameFile { path: std::path::PathBuf },
    #[error(transparent)]
    Output(#[from] crate::output::OutputError),
    #[error("stdout: {0}")]
    Stdout(std::io::Error),
    /// `--target FILE` not read or refused (boxed: its path and reasons are large).
    #[error(transparent)]
    Target(Box<crate::simulate::two_body::TargetError>),
}

/// `--drop-every` refused (clap shows it after the option and the value).
#[derive(Debug, thiserror::Error)]
pub enum DropEveryError {
    #[error("1 would drop every sample: give 0 (none) or at least 2")]
    All,
    #[error(transparent)]
    NotANumber(#[from] std::num::ParseIntError),
}

/// Renders the recording described by `args` (raw codes; [`write_csv`] writes it as the
/// tool's CSV).
pub fn synth(args: &SynthArgs) -> Result<Recording, SynthError> {
    let invalid = |option, rule| Err(SynthError::Invalid { option, rule });
    if let Some(h) = args.drop_height {
        if !(h.is_finite() && h > 0.0) {
            return invalid("--drop-height", "be finite and > 0");
        }
        if !(args.rest.is_finite() && args.rest >= 0.0) {
            return invalid("--rest", "be finite and >= 0");
        }
    }
    let impact = Impact::new(args.mass, args.v0_m_s());
    impact.validate()?;
    let model = args.params.model(args.model, &impact)?;
    if !(args.rate.is_finite() && args.rate > 0.0) {
        return invalid("--rate", "be finite and > 0");
    }
    if !(2..=15).contains(&args.bits) {
        // Codes are offset binary (mid-scale is zero) in the i16 sample path.
        return invalid(
            "--bits",
            "lie in 2..=15 (offset-binary codes in the i16 sample path)",
        );
    }
    for (option, x) in [("--offset", args.offset), ("--drift", args.drift)] {
        if !x.is_finite() {
            return invalid(option, "be finite");
        }
    }
    if !(args.noise.is_finite() && args.noise >= 0.0) {
        return invalid("--noise", "be finite and >= 0");
    }
    if !(args.full_scale.is_finite() && args.full_scale > 0.0) {
        return invalid("--full-scale", "be finite and > 0");
    }
    if !(args.duration.is_finite() && args.duration > 0.0) {
        return invalid("--duration", "be finite and > 0");
    }
    let samples = args.duration * args.rate;
    if samples > MAX_SAMPLES as f64 {
        return Err(SynthError::TooManySamples { samples });
    }
    if !(args.touch.is_finite() && args.touch >= 0.0 && args.touch < args.duration) {
        return invalid("--touch", "lie in [0, --duration)");
    }
    let sensor = sensor(args);
    if args.impacts == 0 || args.impacts > 100_000 {
        return invalid("--impacts", "lie in 1..=100000");
    }
    if args.impacts > 1 && !(args.every.is_finite() && args.every > 0.0) {
        return invalid("--every", "be finite and > 0");
    }
    if args.bounces == 0 || args.bounces > 10_000 {
        return invalid("--bounces", "lie in 1..=10000");
    }
    if let Some(strike) = args.strike(&model) {
        let n = (args.duration * args.rate).ceil() as usize;
        let space = (args.target.as_deref())
            .map(crate::simulate::two_body::read_state_space)
            .transpose()
            .map_err(|e| SynthError::Target(Box::new(e)))?;
        let (accel, truth) = strike.render_on(space.as_ref(), args.rate, n)?;
        let (samples, clipped) = quantise(&sensor, &accel);
        return Ok(Recording {
            samples,
            calibration: sensor.calibration(),
            truth: vec![strike_outcome(&truth)],
            clipped,
            ended: None,
        });
    }
    if args.physical() {
        let n = (args.duration * args.rate).ceil() as usize;
        let rendered = bounce_drop(args, &model).render(args.rate, n)?;
        let (samples, clipped) = quantise(&sensor, &rendered.accel_m_s2);
        let ended = (samples.len() < n).then(|| (samples.len() as f64 / args.rate, rendered.end));
        return Ok(Recording {
            samples,
            calibration: sensor.calibration(),
            truth: rendered.contacts.iter().map(outcome).collect(),
            clipped,
            ended,
        });
    }
    let contacts: Vec<Placed> = {
        (0..args.impacts)
            .map(|k| Placed {
                touch_s: args.touch + k as f64 * args.every,
                law: &model,
                impact,
            })
            .collect()
    };
    Ok(record(&sensor, args.duration, &contacts)?)
}

impl SynthArgs {
    /// The approach speed: `--v0`, or a drop's from `--drop-height` under standard gravity.
    pub fn v0_m_s(&self) -> f64 {
        match (self.v0, self.drop_height) {
            (Some(v0), _) => v0,
            (None, Some(h)) => (2.0 * impact_core::consts::STANDARD_GRAVITY * h).sqrt(),
            (None, None) => f64::NAN,
        }
    }

    /// True if the recording is a physical drop ([`crate::drop`]): a train, a drop from
    /// rest, or a vertical impact.
    pub fn physical(&self) -> bool {
        self.bounces > 1 || self.drop_height.is_some() || self.vertical
    }
}

impl SynthArgs {
    /// The strike on a target `--target-mass` (or `--target`, whose state space the strike
    /// is rendered on: its mount is then a placeholder) asks for, if it does.
    pub fn strike(&self, model: &impact_core::Model<f64>) -> Option<crate::drop::mounted::Strike> {
        let mass_kg = match (self.target_mass, &self.target) {
            (Some(m), _) => m,
            (None, Some(_)) => 1.0,
            (None, None) => return None,
        };
        Some(crate::drop::mounted::Strike {
            law: *model,
            mass_kg: self.mass,
            v0_m_s: self.v0_m_s(),
            touch_s: self.touch,
            gravity_m_s2: if self.vertical {
                impact_core::consts::STANDARD_GRAVITY
            } else {
                0.0
            },
            mount: crate::drop::mounted::Mount {
                mass_kg,
                stiffness_n_m: self.target_stiffness.unwrap_or(0.0),
                damping_n_s_m: self.target_damping.unwrap_or(0.0),
            },
        })
    }
}

/// A strike's truth as a model outcome (relative to the target: Newton's COR, `δ`).
fn strike_outcome(t: &crate::drop::mounted::StrikeTruth) -> ImpactOutcome<f64> {
    ImpactOutcome {
        max_deformation_m: t.max_deformation_m,
        crush_time_s: t.crush_time_s,
        contact_time_s: t.contact_time_s,
        rebound_velocity_m_s: t.rebound_m_s,
        cor: t.cor,
        peak_force_n: t.peak_force_n,
        permanent_deformation_m: t.separation_deformation_m,
        rhs_evaluations: 0,
    }
}

/// The physical drop `--bounces`, `--drop-height` or `--vertical` renders under standard
/// gravity: from rest on a support (`--drop-height`, `--rest`), or in free flight from the
/// record's start, touching at `--touch` at `--v0`.
pub fn bounce_drop(args: &SynthArgs, model: &impact_core::Model<f64>) -> crate::drop::Drop {
    let start = match args.drop_height {
        Some(height_m) => crate::drop::Start::Rest {
            rest_s: args.rest,
            height_m,
        },
        None => crate::drop::Start::Moving {
            touch_s: args.touch,
            v0_m_s: args.v0_m_s(),
        },
    };
    crate::drop::Drop {
        law: *model,
        mass_kg: args.mass,
        gravity_m_s2: impact_core::consts::STANDARD_GRAVITY,
        start,
        max_contacts: args.bounces,
        min_rebound_m_s: 1e-3,
    }
}

/// The contacts of `--bounces` as the generator rendered them (the oracle of the
/// bounce-train tests): times from the record's start.
pub fn bounce_train(
    args: &SynthArgs,
    model: &impact_core::Model<f64>,
) -> Result<Vec<crate::drop::ContactTruth>, Error> {
    let n = (args.duration * args.rate).ceil() as usize;
    Ok(bounce_drop(args, model).render(args.rate, n)?.contacts)
}

/// A contact's truth as a model outcome (`permanent_deformation_m`: the deformation at
/// separation, as the analysis reports it; zeros where the record ended first).
fn outcome(t: &crate::drop::ContactTruth) -> ImpactOutcome<f64> {
    let s = t.separation;
    ImpactOutcome {
        max_deformation_m: t.max_deformation_m.unwrap_or(0.0),
        crush_time_s: t.crush_time_s.unwrap_or(0.0),
        contact_time_s: s.map_or(0.0, |s| s.contact_time_s),
        rebound_velocity_m_s: s.map_or(0.0, |s| s.rebound_m_s),
        cor: s.map_or(0.0, |s| s.cor),
        peak_force_n: t.peak_force_n,
        permanent_deformation_m: s.map_or(0.0, |s| s.deformation_m),
        rhs_evaluations: 0,
    }
}

/// The virtual sensor `args` describe.
fn sensor(args: &SynthArgs) -> Sensor {
    Sensor {
        rate_hz: args.rate,
        bits: args.bits,
        full_scale_m_s2: args.full_scale,
        offset_counts: args.offset,
        noise_rms_counts: args.noise,
        drift_counts_per_s: args.drift,
        drop_every: args.drop_every,
        seed: args.seed,
    }
}

/// Writes a synthetic recording as `time_s,accel_g` (mid-scale code taken as zero), row by
/// row: memory stays at the recording's codes (2 bytes a sample), whatever the text's size.
pub fn write_csv(rec: &Recording, args: &SynthArgs, out: &mut impl Write) -> std::io::Result<()> {
    let mid = (1u64 << (args.bits - 1)) as f64;
    // The sensor's gain in f64, as the codes were made (the calibration holds it in f32).
    let gain = sensor(args).gain();
    let g = impact_core::consts::STANDARD_GRAVITY;
    writeln!(out, "time_s,accel_g")?;
    for (k, &c) in rec.samples.iter().enumerate() {
        writeln!(
            out,
            "{:.9},{:.6e}",
            k as f64 / args.rate,
            (c as f64 - mid) * gain / g
        )?;
    }
    out.flush()
}

/// `--drop-every`: 0 (none) or at least 2 (1 would drop every sample and write no recording).
fn drop_every(s: &str) -> Result<usize, DropEveryError> {
    match s.parse::<usize>()? {
        1 => Err(DropEveryError::All),
        n => Ok(n),
    }
}
