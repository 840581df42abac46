//! `impact analyze`: a recorded signal through the same core pipeline the firmware runs.

use std::path::{Path, PathBuf};

use clap::Args;
use impact_core::consts::STANDARD_GRAVITY;
use impact_core::monitor::Monitor;
use impact_core::signal::cfc::Cfc;
use impact_core::{Approach, Calibration, FitSet, ImpactReport, Scene};
use serde::Deserialize;

use crate::io::channel::CsvFormat;
use crate::io::channel::{time_unit_s, ColumnRef, ReadOptions};
use crate::io::csv_read::read_table;
use crate::io::read_recording;
use crate::parse::positive_f64;
use crate::quantise::to_count;
use crate::report::fmt::shortest;
use crate::report::{impact_json, AnalysisJson, Clipping, Spike, SPIKE_REMOVED};
use crate::screen;
use crate::survey::{self, Survey};

pub use crate::io::units::{Level, Units};

/// A scene file (JSON): every field optional; command-line options override it. Its keys are
/// the options' names (`mass`, `v0`, `trigger`, ...), in the options' units; the earlier
/// spellings with the unit in the name (`mass_kg`, `v0_m_s`, `trigger_m_s2`, ...) are read too.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    #[serde(alias = "mass_kg")]
    pub mass: Option<f64>,
    #[serde(alias = "v0_m_s")]
    pub v0: Option<f64>,
    #[serde(alias = "drop_height_m")]
    pub drop_height: Option<f64>,
    /// m/s², or a string with a unit (`"5g"`).
    #[serde(alias = "trigger_m_s2")]
    pub trigger: Option<Level>,
    #[serde(alias = "edge_m_s2")]
    pub edge: Option<Level>,
    #[serde(alias = "hold_s")]
    pub hold: Option<f64>,
    #[serde(alias = "max_impact_s")]
    pub max_impact: Option<f64>,
    #[serde(alias = "settle_s")]
    pub settle: Option<f64>,
    pub cfc: Option<u32>,
    pub units: Option<Units>,
    /// The sensor's full scale (as `--range`): m/s², or a string with a unit (`"16g"`).
    pub range: Option<Level>,
    pub invert: Option<bool>,
    pub fits: Option<FitsFile>,
}

/// Which fits to run (scene file).
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FitsFile {
    pub two_phase: Option<bool>,
    pub nonlinear: Option<bool>,
    pub fit_exponent: Option<bool>,
    pub exponent: Option<f64>,
    pub hertz: Option<bool>,
}

/// Options shared by `analyze` and `emulate`, in the help's sections.
#[derive(Args, Clone, Debug, Default)]
pub struct AnalyzeArgs {
    /// The recording: CSV (`-`: standard input), .ide, .wav, .npy, .tdms, raw .i16/.f32.
    ///
    /// A CSV file (`-`: standard input) with a header line (or lines) and numeric rows; an enDAQ `.ide` file; a WAV file (`.wav`: integer or float PCM); a numpy
    /// array (`.npy`, with --rate: 1-D, or 2-D samples × channels); an NI TDMS file (`.tdms`);
    /// a raw little-endian file (`.i16`, `.f32`, with --rate and --raw-channels).
    pub file: PathBuf,
    /// The channel: header name or 0-based index.
    ///
    /// A header name or 0-based index (a WAV or .npy channel, `group/channel` in
    /// TDMS, `CH.SUB` or a subchannel's name in an .ide file) [default: the first column that
    /// is not the time; a note names it when there are others].
    #[arg(short = 'c', long, help_heading = "Input")]
    pub column: Option<ColumnRef>,
    /// Two or three axes (`x_g,y_g,z_g`): the resultant, with each axis's peak and Δv.
    ///
    /// Two or three axes (header names or indices, `x_g,y_g,z_g`): the pipeline runs on their
    /// resultant (the trigger on |a|) and each impact reports every axis's peak and Δv.
    /// The resultant's integral is not a velocity change, so Δv is per axis (and their
    /// magnitude) and no approach speed applies.
    #[arg(long, help_heading = "Input", value_delimiter = ',', conflicts_with_all = ["column", "invert", "v0", "drop_height", "free_fall", "train"])]
    pub axes: Vec<ColumnRef>,
    /// The time column [default: the column whose header starts with "time"].
    #[arg(long, help_heading = "Input")]
    pub time_column: Option<ColumnRef>,
    /// The time column's unit [default: named in its header, else s].
    ///
    /// The time column's unit [default: the one its header names (`time_ms`, `time [us]`),
    /// else s; a header naming none that read in s gives under 100 S/s is refused].
    #[arg(long, help_heading = "Input", value_enum)]
    pub time_unit: Option<crate::io::channel::TimeUnit>,
    /// Sample rate, Hz (instead of a time column).
    #[arg(short = 'r', long, help_heading = "Input", value_parser = positive_f64)]
    pub rate: Option<f64>,
    /// Interpolate an uneven time axis onto an even grid [default: refuse it].
    ///
    /// Interpolate an uneven time axis (gaps, rate changes) onto an even grid at the median
    /// interval [default: refuse it, naming the line].
    #[arg(long, help_heading = "Input", conflicts_with = "rate")]
    pub resample: bool,
    /// Field separator: one character, or `tab` [default: tab or `;` if the first lines hold
    /// one, else `,`].
    #[arg(long, help_heading = "Input", value_parser = crate::io::channel::parse_delimiter)]
    pub delimiter: Option<u8>,
    /// Numbers are written with a decimal comma (`0,5`); the delimiter must be another
    /// character.
    #[arg(long, help_heading = "Input")]
    pub decimal_comma: bool,
    /// Interleaved channels of a raw `.i16`/`.f32` file [default: 1].
    #[arg(long, help_heading = "Input")]
    pub raw_channels: Option<usize>,
    /// The sample type of a raw stream without a `.i16`/`.f32` name (standard input).
    #[arg(long, help_heading = "Input", value_enum)]
    pub raw_type: Option<crate::io::channel::RawType>,
    /// One pass as the recording is read (needs --range and --trigger).
    ///
    /// Analyse the recording (CSV, WAV, .npy, TDMS, raw `.i16`/`.f32`; CSV and raw also
    /// from standard input) in one pass as it is read, in memory that does not grow with its
    /// length; needs --range and --trigger (and --rate where the file holds no time); spikes
    /// are not screened; no --plot, --axes, --free-fall, --resample. Without it a regular
    /// file or standard input is read in passes (a survey of the whole recording, then the
    /// analysis), also in bounded memory, with the levels learned and spikes screened; a
    /// CSV's or standard input's values are kept from the first pass in a temporary file
    /// (TMPDIR, 8 bytes a sample).
    #[arg(long, help_heading = "Input")]
    pub stream: bool,
    /// Units of the channel [default: named in its header, else g].
    ///
    /// Units of the channel [default: the ones its header names (`x_g`, `bottom_kgn`,
    /// `table_m_s2`, `force_n`), else g; units that contradict the header are refused].
    #[arg(short = 'u', long, help_heading = "Channel", value_enum)]
    pub units: Option<Units>,
    /// Multiply the channel's values by this first (e.g. g per code of a WAV file's integer
    /// samples) [default: 1].
    #[arg(long, help_heading = "Channel", value_parser = positive_f64)]
    pub gain: Option<f64>,
    /// Negate the channel (by default a positive reading is a deceleration).
    #[arg(long, help_heading = "Channel")]
    pub invert: bool,
    /// The sensor's full scale, in m/s² or with a unit (`16g`): clips at the rails.
    ///
    /// The sensor's full scale, in m/s² or with a unit (`16g`, `200kgn`, `500n`): readings at
    /// the rail mark their impact clipped; a recording beyond twice the range is refused
    /// [default: flat tops at the recording's extremes, more than 10 steps of its resolution
    /// from its median, are taken for the rails].
    #[arg(long, help_heading = "Channel", value_name = "LEVEL")]
    pub range: Option<Level>,
    /// Keep isolated glitches (by default removed, listed and flagged).
    ///
    /// Keep isolated one- or two-sample spikes that dwarf the rest of the recording (by
    /// default they are removed, listed, and flag the impact they fall in).
    #[arg(long, help_heading = "Channel")]
    pub keep_spikes: bool,
    /// Mass of the instrumented body, kg.
    #[arg(short = 'm', long, help_heading = "Bench", value_parser = positive_f64)]
    pub mass: Option<f64>,
    /// Approach speed, m/s.
    #[arg(long, help_heading = "Bench", conflicts_with_all = ["drop_height", "free_fall"], value_parser = positive_f64)]
    pub v0: Option<f64>,
    /// Drop height, m: v0 = sqrt(2 g h).
    #[arg(long, help_heading = "Bench", conflicts_with = "free_fall", value_parser = positive_f64)]
    pub drop_height: Option<f64>,
    /// DC accelerometer file (g), optionally `:COLUMN`: v0 = g × free-fall time before the impact.
    #[arg(long, help_heading = "Bench", value_name = "FILE[:COLUMN]")]
    pub free_fall: Option<String>,
    /// Scene file (JSON) with any of these options; options given here override it.
    ///
    /// Scene file (JSON, keys as these options: `{"mass": 0.06, "v0": 1.3357, "range":
    /// "16g"}`); options given here override it.
    #[arg(long, help_heading = "Bench")]
    pub scene: Option<PathBuf>,
    /// Trigger level above the baseline, in m/s² or with a unit (`5g`) [default: from the
    /// signal's noise].
    #[arg(long, help_heading = "Detection", value_name = "LEVEL")]
    pub trigger: Option<Level>,
    /// Edge level (onset, separation), in m/s² or with a unit [default: a fifth of the
    /// trigger, at least 3 × the noise].
    #[arg(long, help_heading = "Detection", value_name = "LEVEL")]
    pub edge: Option<Level>,
    /// Quiet time that ends an impact, s [default: 2 ms].
    #[arg(long, help_heading = "Detection", value_parser = positive_f64)]
    pub hold: Option<f64>,
    /// How long a new level must last to be a level change, not an impact, s [default: 50 ms].
    ///
    /// How long a flat new level must last to be a level change (a DC channel's free fall
    /// or rest), not an impact, s [default: 50 ms, at least the hold].
    #[arg(long, help_heading = "Detection", value_parser = positive_f64)]
    pub settle: Option<f64>,
    /// Longest impact, s [default: 1 s].
    ///
    /// Longest impact, s: a signal away from its baseline longer is a stuck or drifting
    /// sensor (`too-long`) [default: 1 s].
    #[arg(long, help_heading = "Detection", value_parser = positive_f64)]
    pub max_impact: Option<f64>,
    /// Causal SAE J211 class on the live trigger path (ignores glitches shorter than the class).
    #[arg(long, help_heading = "Detection")]
    pub trigger_cfc: Option<u32>,
    /// SAE J211 channel frequency class for the captured windows: 60, 180, 600 or 1000.
    #[arg(long, help_heading = "Analysis")]
    pub cfc: Option<u32>,
    #[command(flatten)]
    pub train: crate::train::TrainArgs,
    #[command(flatten)]
    pub spectrum: crate::spectrum::SpectrumArgs,
    /// Print one JSON object.
    #[arg(short = 'j', long, help_heading = "Output", conflicts_with = "csv")]
    pub json: bool,
    /// Print one CSV row per impact.
    #[arg(long, help_heading = "Output")]
    pub csv: bool,
    /// Draw acceleration, velocity and deformation with the fitted models into this SVG file.
    #[arg(short = 'p', long, help_heading = "Output", value_name = "FILE.svg")]
    pub plot: Option<PathBuf>,
}

impl AnalyzeArgs {
    /// What the readers take of the options (they never see the command line).
    pub fn read_options(&self, progress: Option<fn(f64)>) -> ReadOptions {
        ReadOptions {
            column: self.column.clone(),
            axes: self.axes.clone(),
            raw_channels: self.raw_channels,
            raw_type: self.raw_type,
            time_column: self.time_column.clone(),
            rate_hz: self.rate,
            time_unit: self.time_unit,
            resample: self.resample,
            format: CsvFormat {
                delimiter: self.delimiter,
                decimal_comma: self.decimal_comma,
            },
            progress,
        }
    }
}

/// The host's monitor: 4096-sample pre-trigger ring, 2^17-sample capture.
pub type HostMonitor = Monitor<4096, 131072>;

/// A recording turned into raw counts for the core pipeline.
#[derive(Clone, Debug)]
pub struct Prepared {
    pub counts: Vec<i16>,
    pub calibration: Calibration,
    /// Time of the first sample in the file, s.
    pub t0: f64,
    /// The signal in m/s² (deceleration positive).
    pub accel_m_s2: Vec<f64>,
}

/// The sensor's full scale in m/s² (`--range` or the scene's), if given.
pub(crate) fn full_scale_m_s2(
    args: &AnalyzeArgs,
    file: &SceneFile,
    mass: Option<f64>,
) -> Option<f64> {
    args.range.or(file.range).map(|r| r.to_m_s2(mass))
}

/// The trigger and edge levels given (`--trigger`, `--edge` or the scene's), m/s².
pub(crate) fn given_levels(
    args: &AnalyzeArgs,
    file: &SceneFile,
    mass: Option<f64>,
) -> (Option<f64>, Option<f64>) {
    let m_s2 = |l: Option<Level>| l.map(|l| l.to_m_s2(mass));
    (
        m_s2(args.trigger.or(file.trigger)),
        m_s2(args.edge.or(file.edge)),
    )
}

/// The `--scene` file's settings (all defaults without one).
pub(crate) fn scene_file(args: &AnalyzeArgs) -> Result<SceneFile, String> {
    let Some(path) = &args.scene else {
        return Ok(SceneFile::default());
    };
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))
}

/// Everything the pipeline needs, resolved from the options, the scene file and the signal.
pub struct Setup {
    /// The channel's header (or the axes') and its units.
    pub column: Option<String>,
    pub units: Units,
    pub prepared: Prepared,
    pub scene: Scene,
    pub v0_source: Option<String>,
    pub free_fall_s: Option<f64>,
    pub samples: u64,
    pub rate_hz: f64,
    /// Isolated spikes removed before quantising (see [`screen::SpikeScan`]).
    pub spikes: Vec<Spike>,
    /// The channel's rails, if known.
    pub clipping: Option<Clipping>,
    /// Whether the time axis was interpolated onto an even grid.
    pub resampled: bool,
    /// With `--axes`: each axis in m/s² and its rails.
    pub axes: Vec<crate::axes::Axis>,
}

impl Setup {
    /// The signal the figure draws: the counts the pipeline analysed times the gain.
    pub fn plot_signal(&self) -> crate::plot::Signal<'_> {
        crate::plot::Signal {
            rate_hz: f64::from(self.scene.calibration.sample_rate_hz),
            mass_kg: self.scene.mass_kg.map(f64::from),
            accel_m_s2: Box::new(move |i| {
                let gain = f64::from(self.scene.calibration.gain_m_s2_per_count);
                self.prepared
                    .counts
                    .get(usize::try_from(i).ok()?)
                    .map(|&c| f64::from(c) * gain)
            }),
        }
    }
}

/// Reads the file and builds the scene (v0 from a free fall needs a first pass).
pub fn setup(args: &AnalyzeArgs, progress: Option<fn(f64)>) -> Result<Setup, String> {
    let file = scene_file(args)?;
    let ch = read_recording(&args.file, &args.read_options(progress)).map_err(|e| e.to_string())?;
    let column = ch
        .axes
        .first()
        .map_or(ch.name.as_str(), |(name, _)| name.as_str());
    let (mass, scale, units) = mass_and_scale(args, &file, column)?;
    for (name, _) in ch.axes.iter().skip(1) {
        mass_and_scale(args, &file, name)?;
    }
    let mut accel: Vec<f64> = ch.values.iter().map(|v| v * scale).collect();
    let full_scale = full_scale_m_s2(args, &file, mass);
    let t0 = ch.time_s.first().copied().unwrap_or(0.0);
    // The survey, and again after glitches are removed (they set the extremes).
    let first = Survey::of(&accel, !args.keep_spikes)?;
    let spikes = screen::apply(&first.removals, &mut accel, t0, ch.rate_hz);
    let survey = if spikes.is_empty() {
        first
    } else {
        Survey::of(&accel, false)?
    };
    // With --axes the range is each axis's (the resultant reaches sqrt(n) times it), and
    // clipping is found per axis.
    let axes: Vec<crate::axes::Axis> = ch
        .axes
        .iter()
        .map(|(name, v)| {
            let a = v.iter().map(|x| x * scale).collect();
            crate::axes::Axis::new(name.clone(), a, full_scale)
        })
        .collect();
    let (trigger, edge) = given_levels(args, &file, mass);
    let levels = if axes.is_empty() {
        survey::levels(&survey, full_scale, trigger, edge)?
    } else {
        let fs = full_scale.map(|fs| fs * (axes.len() as f64).sqrt());
        survey::Levels {
            clipping: None,
            ..survey::levels(&survey, fs, trigger, edge)?
        }
    };
    let clipping = levels.clipping.clone();
    let calibration = Calibration {
        gain_m_s2_per_count: levels.gain_m_s2_per_count as f32,
        sample_rate_hz: ch.rate_hz as f32,
    };
    let counts = accel
        .iter()
        .map(|v| to_count(*v, levels.gain_m_s2_per_count))
        .collect();
    let (trigger, edge) = (levels.trigger_m_s2, levels.edge_m_s2);
    let (scene, source) = build_scene(
        args,
        &file,
        calibration,
        trigger,
        edge,
        clipping.as_ref(),
        mass,
    )?;
    let mut setup = Setup {
        column: Some(ch.name.clone()),
        units,
        prepared: Prepared {
            counts,
            calibration,
            t0,
            accel_m_s2: accel,
        },
        scene,
        v0_source: source.map(str::to_string),
        free_fall_s: None,
        samples: ch.values.len() as u64,
        rate_hz: ch.rate_hz,
        spikes,
        clipping,
        resampled: ch.resampled,
        axes,
    };
    if let Some(spec) = &args.free_fall {
        // First pass without v0 to find the first impact, then the free fall before it.
        let first = run(&setup.prepared.counts, &setup.scene)?;
        let start = first
            .first()
            .map(|r| setup.prepared.t0 + r.start_s)
            .ok_or("--free-fall: no impact in the recording")?;
        let t_ff = free_fall_before(spec, start)?;
        setup.free_fall_s = Some(t_ff);
        setup.scene.approach = Approach::Speed {
            v0_m_s: (STANDARD_GRAVITY * t_ff) as f32,
        };
        setup.v0_source = Some("free-fall".into());
    }
    Ok(setup)
}

/// The body's mass (checked) and the factor from the file's values to m/s² (units, `--gain`,
/// `--invert`), from the options or the scene file; the units are those stated, else those
/// the channel's header (`column`) names, else g (an error if the two disagree).
pub(crate) fn mass_and_scale(
    args: &AnalyzeArgs,
    file: &SceneFile,
    column: &str,
) -> Result<(Option<f64>, f64, Units), String> {
    let mass = args.mass.or(file.mass);
    if let Some(m) = mass {
        if !(m.is_finite() && m > 0.0) {
            return Err("--mass: must be finite and > 0".into());
        }
    }
    let units = Units::resolve(args.units.or(file.units), column)?;
    let invert = args.invert || file.invert.unwrap_or(false);
    let scale = units.to_m_s2(mass) * args.gain.unwrap_or(1.0) * if invert { -1.0 } else { 1.0 };
    Ok((mass, scale, units))
}

/// The scene from the options and the scene file, with the levels and rails found; and
/// where v0 comes from.
pub(crate) fn build_scene(
    args: &AnalyzeArgs,
    file: &SceneFile,
    calibration: Calibration,
    trigger: f64,
    edge: f64,
    clipping: Option<&Clipping>,
    mass: Option<f64>,
) -> Result<(Scene, Option<&'static str>), String> {
    let mut scene = Scene::new(calibration, trigger as f32);
    scene.edge_m_s2 = edge as f32;
    if let Some(c) = clipping {
        let gain = calibration.gain_m_s2_per_count as f64;
        scene.clip_counts = (
            c.low_m_s2.map_or(i16::MIN, |v| to_count(v, gain)),
            c.high_m_s2.map_or(i16::MAX, |v| to_count(v, gain)),
        );
    }
    scene.hold_s = args.hold.or(file.hold).unwrap_or(2e-3) as f32;
    if let Some(m) = args.max_impact.or(file.max_impact) {
        scene.max_impact_s = m as f32;
    }
    scene.settle_s = match args.settle.or(file.settle) {
        Some(s) => s as f32,
        None => scene.settle_s.max(scene.hold_s),
    };
    scene.mass_kg = mass.map(|m| m as f32);
    scene.cfc = match args.cfc.or(file.cfc) {
        Some(c) => Some(
            Cfc::from_class(c)
                .ok_or_else(|| format!("--cfc: {c} is not one of 60, 180, 600, 1000"))?,
        ),
        None => None,
    };
    scene.trigger_cfc = match args.trigger_cfc {
        Some(c) => Some(
            Cfc::from_class(c)
                .ok_or_else(|| format!("--trigger-cfc: {c} is not one of 60, 180, 600, 1000"))?,
        ),
        None => None,
    };
    let f = file.fits.clone().unwrap_or_default();
    scene.fits = FitSet {
        two_phase: f.two_phase.unwrap_or(true),
        nonlinear: f.nonlinear.unwrap_or(true),
        fit_exponent: f.fit_exponent.unwrap_or(true),
        nonlinear_exponent: f.exponent.unwrap_or(1.0) as f32,
        hertz: f.hertz.unwrap_or(true),
    };
    if mass.is_none() {
        scene.fits = FitSet::none();
    }
    // A speed or height on the command line overrides either one from the scene.
    let (v0, height) = if args.v0.is_some() || args.drop_height.is_some() {
        (args.v0, args.drop_height)
    } else {
        (file.v0, file.drop_height)
    };
    let (approach, source) = match (v0, height) {
        (Some(v), _) => (Approach::Speed { v0_m_s: v as f32 }, Some("v0")),
        (None, Some(h)) => (
            Approach::DropHeight { height_m: h as f32 },
            Some("drop-height"),
        ),
        _ => (Approach::Unknown, None),
    };
    scene.approach = approach;
    scene.train = args.train.train();
    scene.spectrum = args.spectrum.settings();
    scene.validate().map_err(|e| e.to_string())?;
    Ok((scene, source))
}

/// Runs the core pipeline over the counts (in blocks of 256, as the firmware's DMA halves).
pub fn run(counts: &[i16], scene: &Scene) -> Result<Vec<ImpactReport>, String> {
    let scene = *scene;
    let counts = counts.to_vec();
    crate::on_big_stack(move || -> Result<Vec<ImpactReport>, String> {
        let mut m = HostMonitor::new(scene).map_err(|e| e.to_string())?;
        let mut out = Vec::new();
        for block in counts.chunks(256) {
            m.push_block(block, &mut |r: &ImpactReport| out.push(*r));
        }
        m.finish(&mut |r: &ImpactReport| out.push(*r));
        if !m.is_armed() {
            return Err("the signal never settled to a baseline (no quiet stretch of 64 samples within the edge level): give --edge".into());
        }
        Ok(out)
    })
}

/// Free-fall time ending at or before `impact_s`, from a DC accelerometer file in g: the
/// stretch where |a| < 0.5 g (half way between rest and free fall) that ends within 50 ms
/// before the impact.
pub fn free_fall_before(spec: &str, impact_s: f64) -> Result<f64, String> {
    let (path, column) = match spec.rsplit_once(':') {
        Some((p, c)) if !p.is_empty() && !c.contains('/') => (
            p,
            Some(c.parse::<ColumnRef>().unwrap_or(ColumnRef::Name(c.into()))),
        ),
        _ => (spec, None),
    };
    let path = Path::new(path);
    let table = read_table(path, &CsvFormat::default(), None).map_err(|e| e.to_string())?;
    let tcol = table
        .time_column(None)
        .map_err(|e| format!("--free-fall {}: {e}", path.display()))?
        .ok_or_else(|| format!("--free-fall {}: needs a time column", path.display()))?;
    let unit = time_unit_s(&table.headers.get(tcol).cloned().unwrap_or_default(), None);
    let time: Vec<f64> = table.columns[tcol].iter().map(|t| t * unit).collect();
    let cols: Vec<usize> = match &column {
        Some(c) => vec![table
            .find(c, "column")
            .map_err(|e| format!("--free-fall {}: {e}", path.display()))?],
        None => (0..table.columns.len()).filter(|&c| c != tcol).collect(),
    };
    let mag = |i: usize| {
        cols.iter()
            .map(|&c| table.columns[c][i].powi(2))
            .sum::<f64>()
            .sqrt()
    };
    let end = time
        .iter()
        .rposition(|&t| t <= impact_s)
        .ok_or("--free-fall: the DC channel starts after the impact")?;
    // The DC channel must run up to the impact: a file that ends before it cannot tell when
    // the fall ended.
    let interval = (time[time.len() - 1] - time[0]) / (time.len().max(2) - 1) as f64;
    if end + 1 == time.len() && impact_s - time[end] > 2.0 * interval {
        return Err(format!(
            "--free-fall {}: the DC channel ends at {:.6} s, before the impact at {:.6} s",
            path.display(),
            time[end],
            impact_s
        ));
    }
    // Walk back from the impact to the last free-falling sample, then to the release.
    let mut i = end;
    while i > 0 && mag(i) >= FREE_FALL_G && impact_s - time[i] < 0.05 {
        i -= 1;
    }
    if mag(i) >= FREE_FALL_G {
        return Err(
            "--free-fall: no free fall (|a| < 0.5 g) within 50 ms before the impact".into(),
        );
    }
    let last = i;
    while i > 0 && mag(i - 1) < FREE_FALL_G {
        i -= 1;
    }
    let dt = if last > 0 {
        time[last] - time[last - 1]
    } else {
        0.0
    };
    // Free fall runs from half a sample before the first quiet sample to the impact.
    let release = time[i] - dt / 2.0;
    Ok(impact_s - release)
}

/// Below this magnitude (g) the DC channel is taken as free-falling.
const FREE_FALL_G: f64 = 0.5;

/// The report JSON.
pub fn to_json(setup: &Setup, reports: &[ImpactReport]) -> AnalysisJson {
    let mut a = AnalysisJson {
        lines_dropped: 0,
        lines_missing: 0,
        column: setup.column.clone(),
        units: Some(setup.units.name().to_string()),
        samples: setup.samples,
        sample_rate_hz: setup.rate_hz,
        v0_m_s: match setup.scene.approach {
            Approach::Speed { v0_m_s } => Some(shortest(v0_m_s)),
            Approach::DropHeight { height_m } => {
                Some((2.0 * STANDARD_GRAVITY * f64::from(height_m)).sqrt())
            }
            _ => None,
        },
        v0_source: setup.v0_source.clone(),
        free_fall_s: setup.free_fall_s,
        samples_lost: 0,
        analyses_skipped: reports
            .iter()
            .filter(|r| r.analysis == impact_core::Analysis::Skipped)
            .count() as u64,
        resampled: setup.resampled,
        spikes_removed: setup.spikes.clone(),
        clipping: setup.clipping.clone(),
        train_speed: setup.scene.train.map(|t| t.speed.name().to_string()),
        trains: Vec::new(),
        waveforms: Vec::new(),
        impacts: reports
            .iter()
            .enumerate()
            .map(|(k, r)| {
                let mut j = impact_json(r, setup.prepared.t0, &setup.scene.fits);
                if !setup.axes.is_empty() {
                    let previous_end = k
                        .checked_sub(1)
                        .and_then(|p| reports.get(p))
                        .map_or(0, |p| p.end_sample);
                    let x = crate::axes::impact_axes(
                        r,
                        previous_end,
                        &setup.axes,
                        &setup.prepared.accel_m_s2,
                        setup.rate_hz,
                        setup.prepared.t0,
                    );
                    j.clipped |= x.axes.iter().any(|a| a.clipped);
                    // ∫|a| dt is no velocity change: the axes give it.
                    j.delta_v_m_s = None;
                    j.null_reasons
                        .insert("delta_v_m_s".into(), "resultant".into());
                    j.axes = Some(x);
                }
                if setup
                    .spikes
                    .iter()
                    .any(|s| (r.start_sample..=r.end_sample).contains(&s.sample))
                {
                    j.flags.push(SPIKE_REMOVED.to_string());
                }
                j
            })
            .collect(),
    };
    a.trains = crate::report::train::trains(&a.impacts);
    a
}
