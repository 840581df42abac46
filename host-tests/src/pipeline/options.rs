//! The analysis's options: the command line's (shared by `impact analyze` and `impact
//! emulate`, in the help's sections), the scene file's, the bounce trains' and the spectra's;
//! and what the readers take of them ([`AnalyzeArgs::read_options`]).

use std::path::{Path, PathBuf};

use clap::{Args, ValueEnum};
use impact_core::signal::spectrum::SpectrumSettings;
use impact_core::{Train, TrainSpeed};
use serde::Deserialize;

pub use super::level::Level;
use crate::parse;
use impact_io::channel::{ColumnRef, CsvFormat, ReadOptions};
pub use impact_io::units::Units;

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
    /// Gravity along the sensor's axis, m/s² (as `--gravity`).
    #[serde(alias = "gravity_m_s2")]
    pub gravity: Option<f64>,
    /// The impact is vertical (as `--vertical`).
    pub vertical: Option<bool>,
    /// Every impact comes at `v0` (as `--v0-every`).
    pub v0_every: Option<bool>,
    /// The target (as `--target-mass`, `--target-stiffness`, `--target-damping`).
    pub target_mass: Option<f64>,
    pub target_stiffness: Option<f64>,
    pub target_damping: Option<f64>,
    /// A linear target in state-space form (as `--target`): the name of its JSON file,
    /// relative to the scene file's folder, or its object `{"a", "b", "c", "d"}` itself.
    pub target: Option<serde_json::Value>,
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
    /// With `--axes` and `--spec`: the intended shock direction's axis, one of `--axes`.
    ///
    /// With `--axes` and `--spec`: the intended shock direction's axis, as `--axes` names it
    /// or by its header name; the others are cross axes, checked against
    /// `--transverse-limit` [default: in each impact the axis with the largest peak, which
    /// the verdict says].
    #[arg(long, help_heading = "Analysis", value_name = "AXIS", requires_all = ["axes", "spec"])]
    pub main_axis: Option<ColumnRef>,
    /// With `--axes` and `--spec`: a cross axis's peak limit, over the nominal peak [default: 0.3].
    ///
    /// With `--axes` and `--spec`: the transverse-motion limit, a cross axis's peak deviation
    /// over the nominal pulse's peak [default: 0.3, IEC 60068-2-27's 30 %]; beyond it the
    /// pulse fails.
    #[arg(long, help_heading = "Analysis", value_name = "FRACTION", requires_all = ["axes", "spec"], value_parser = parse::positive_f64)]
    pub transverse_limit: Option<f64>,
    /// The time column [default: the column whose header starts with "time"].
    #[arg(long, help_heading = "Input")]
    pub time_column: Option<ColumnRef>,
    /// The time column's unit [default: named in its header, else s].
    ///
    /// The time column's unit [default: the one its header names (`time_ms`, `time [us]`),
    /// else s; a header naming none that read in s gives under 100 S/s is refused].
    #[arg(long, help_heading = "Input", value_enum)]
    pub time_unit: Option<impact_io::channel::TimeUnit>,
    /// Sample rate, Hz (instead of a time column).
    #[arg(short = 'r', long, help_heading = "Input", value_parser = parse::rate_hz)]
    pub rate: Option<f64>,
    /// Interpolate an uneven time axis onto an even grid [default: refuse it].
    ///
    /// Interpolate an uneven time axis (gaps, rate changes) onto an even grid at the median
    /// interval [default: refuse it, naming the line].
    #[arg(long, help_heading = "Input", conflicts_with = "rate")]
    pub resample: bool,
    /// Field separator: one character, or `tab` [default: tab or `;` if the first lines hold
    /// one, else `,`].
    #[arg(long, help_heading = "Input", value_parser = impact_io::channel::parse_delimiter)]
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
    pub raw_type: Option<impact_io::channel::RawType>,
    /// One pass as the recording is read (needs --range and --trigger).
    ///
    /// Analyse the recording (CSV, WAV, .npy, TDMS, raw `.i16`/`.f32`; CSV and raw also
    /// from standard input) in one pass as it is read, in memory that does not grow with its
    /// length; needs --range and --trigger (and --rate where the file holds no time); spikes
    /// are not screened; no --plot, --axes, --free-fall, --resample. Without it a regular
    /// file or standard input (or a FIFO, a device) is read in passes (a survey of the whole
    /// recording, then the analysis), also in bounded memory, with the levels learned and
    /// spikes screened; a CSV's or standard input's values are kept from the first pass in a
    /// temporary file (TMPDIR, 8 bytes a sample, at most half its free space).
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
    #[arg(long, help_heading = "Channel", value_parser = parse::gain)]
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
    #[arg(short = 'm', long, help_heading = "Bench", value_parser = parse::mass_kg)]
    pub mass: Option<f64>,
    /// Approach speed, m/s.
    #[arg(long, help_heading = "Bench", conflicts_with_all = ["drop_height", "free_fall"], value_parser = parse::speed_m_s)]
    pub v0: Option<f64>,
    /// Every impact comes at --v0 (a rig that strikes again and again at one speed).
    ///
    /// Every impact comes at --v0 (a rig that strikes again and again at one speed). Without
    /// it --v0 and --drop-height are a drop's first impact's: an impact that follows a flight
    /// (within 2 s of the previous contact) came back at a speed nothing measured, so it has
    /// no kinematics (`approach-unknown`); --train measures a bounce's from its flight.
    #[arg(long, help_heading = "Bench", conflicts_with = "train")]
    pub v0_every: bool,
    /// Drop height, m: v0 = sqrt(2 g h).
    #[arg(long, help_heading = "Bench", conflicts_with = "free_fall", value_parser = parse::height_m)]
    pub drop_height: Option<f64>,
    /// Target mass m2, kg: the body struck a mass on a spring and damper to ground, not a
    /// rigid wall.
    ///
    /// Target mass m2, kg: the body struck a mass on a spring and damper to ground (a mounted
    /// anvil, a load cell's platen, a specimen on its fixture), not a rigid wall. The
    /// measured force (--mass times the reading) drives the target, and the COR (Newton's,
    /// relative), the crush time, the deformations and the absorbed energy (the contact's
    /// work) are the contact's, relative to the target's motion. Without it (or --target) a
    /// rigid, fixed barrier is assumed, and said.
    #[arg(long, help_heading = "Target", value_parser = parse::mass_kg)]
    pub target_mass: Option<f64>,
    /// The target's spring to ground k2, N/m [default: 0, a free body].
    #[arg(long, help_heading = "Target")]
    pub target_stiffness: Option<f64>,
    /// The target's damper to ground c2, N s/m [default: 0].
    #[arg(long, help_heading = "Target")]
    pub target_damping: Option<f64>,
    /// A linear target in state-space form (JSON, as `impact simulate --target`): input the
    /// contact force (N), outputs the contact point's displacement (m) and velocity (m/s).
    ///
    /// A linear target in state-space form, JSON `{"a": [[..]], "b": [..], "c": [[..], [..]],
    /// "d": [0, 0]}` as `impact simulate --target` takes it: input the contact force (N),
    /// outputs the contact point's displacement (m) and velocity (m/s), at most 6 states, at
    /// rest at each first touch (a fixture of two masses, a mount identified by a modal fit).
    /// The kinematics are the contact's relative to it, as with --target-mass; `impact
    /// emulate` hands it to the board in its scene, whose scene line states it. A scene
    /// file's `target` (the file's name, relative to the scene file, or the object itself)
    /// gives it too; this overrides it.
    #[arg(long, help_heading = "Target", value_name = "FILE",
          conflicts_with_all = ["target_mass", "target_stiffness", "target_damping"])]
    pub target: Option<PathBuf>,
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
    /// trigger, at least 3 × the noise; in a vertical scene, where a flight reads the
    /// free-fall level, 5 × the noise, at least 3 of the recording's quanta and a twentieth of
    /// the trigger].
    #[arg(long, help_heading = "Detection", value_name = "LEVEL")]
    pub edge: Option<Level>,
    /// Quiet time that ends an impact, s [default: 2 ms].
    #[arg(long, help_heading = "Detection", value_parser = parse::seconds)]
    pub hold: Option<f64>,
    /// How long a new level must last to be a level change, not an impact, s [default: 50 ms].
    ///
    /// How long a flat new level must last to be a level change (a DC channel's free fall
    /// or rest), not an impact, s [default: 50 ms, at least the hold].
    #[arg(long, help_heading = "Detection", value_parser = parse::seconds)]
    pub settle: Option<f64>,
    /// Longest impact, s [default: 1 s].
    ///
    /// Longest impact, s: a signal away from its baseline longer is a stuck or drifting
    /// sensor (`too-long`) [default: 1 s].
    #[arg(long, help_heading = "Detection", value_parser = parse::seconds)]
    pub max_impact: Option<f64>,
    /// Causal SAE J211 class on the live trigger path (ignores glitches shorter than the class).
    #[arg(long, help_heading = "Detection")]
    pub trigger_cfc: Option<u32>,
    /// SAE J211 channel frequency class for the captured windows: 60, 180, 600 or 1000.
    #[arg(long, help_heading = "Analysis")]
    pub cfc: Option<u32>,
    /// Butterworth low-pass for the captured windows, not a CFC: ORDER,CUTOFF (`4,1kHz`).
    ///
    /// A phaseless Butterworth low-pass for the captured windows instead of a CFC: ORDER (1
    /// to 8) and CUTOFF in Hz (`4,1000`, `4,1kHz`), below half the sample rate; SciPy's
    /// `butter(ORDER, CUTOFF, fs=rate, output='sos')` run forward and backward
    /// (`sosfiltfilt`). CUTOFF is one pass's −3 dB point: forward and backward the filter is
    /// −6 dB there. Overrides a scene file's `cfc`.
    #[arg(long, help_heading = "Analysis", value_name = "ORDER,CUTOFF", value_parser = parse::lowpass, conflicts_with = "cfc")]
    pub lowpass: Option<parse::LowpassArg>,
    /// Capture length, samples [default: the board's, 15104].
    ///
    /// Capture length, samples, up to 131072 [default: the board's, 15104, so `analyze` and
    /// the board agree on every impact]: a contact longer is kept whole at a coarser step
    /// (the mean of 2, 4, 8 … samples: flag `decimated`, field `decimation`), where the
    /// widths, filter, spectra and verdict are measured and the fits are not. `emulate` runs
    /// the board's.
    #[arg(long, help_heading = "Analysis", value_name = "SAMPLES", value_parser = clap::value_parser!(u32).range(256..=crate::pipeline::HOST_CAPTURE_LEN as i64))]
    pub capture_samples: Option<u32>,
    #[command(flatten)]
    pub train: crate::pipeline::options::TrainArgs,
    #[command(flatten)]
    pub spectrum: crate::pipeline::options::SpectrumArgs,
    /// Judge each impact against a specified pulse: `half-sine,50g,11ms`.
    ///
    /// Judge each impact against a specified shock pulse: SHAPE,PEAK,DURATION
    /// (`half-sine`, `sawtooth` (terminal-peak) or `trapezoid`; `50g` or `490m/s2`; `11ms`),
    /// then KEY=VALUE: `standard=` iec-60068-2-27 (the default), mil-std-810h or
    /// mil-std-202h, whose tolerance band and velocity-change tolerance apply, or any
    /// tolerance by hand (`band`, `outside`, `slack`, `dv`, `before`, `after`, `watch`; a
    /// trapezoid's `rise`, `fall`), or `band-file=` a CSV of your own band (time_s,
    /// lower_g, upper_g; up to 64 rows). Every number and its source: docs/standards.md.
    #[arg(long, help_heading = "Analysis", value_name = "SHAPE,PEAK,DURATION", value_parser = crate::pipeline::spec::parse)]
    pub spec: Option<crate::pipeline::spec::SpecArg>,
    /// Print one JSON object.
    #[arg(short = 'j', long, help_heading = "Output", conflicts_with = "csv")]
    pub json: bool,
    /// Print one CSV row per impact.
    #[arg(long, help_heading = "Output")]
    pub csv: bool,
    /// Draw acceleration, velocity and deformation with the fitted models into this SVG or PNG
    /// file (by its extension).
    #[arg(short = 'p', long, help_heading = "Output", value_name = "FILE")]
    pub plot: Option<PathBuf>,
}

impl AnalyzeArgs {
    /// What the readers take of the options (they never see the command line).
    pub fn read_options(&self, progress: impact_io::progress::Progress) -> ReadOptions {
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

/// The state-space target's file an analysis reads: `--target`'s, else the one the scene
/// file's `target` names (`None` for one written in the scene file, one `--target-mass`
/// overrides, or a scene file that cannot be read or is not a regular file: the analysis
/// says why, or reads it once).
pub fn target_file(args: &AnalyzeArgs) -> Option<PathBuf> {
    if let Some(p) = &args.target {
        return Some(p.clone());
    }
    // (`--target-mass` overrides the scene file's; a scene file that is not a regular file,
    // a pipe, is left for the analysis to read, once.)
    let scene = args
        .scene
        .as_deref()
        .filter(|_| args.target_mass.is_none())?;
    if !std::fs::metadata(scene).is_ok_and(|m| m.is_file()) {
        return None;
    }
    let file = read_scene(scene).ok()?;
    crate::simulate::two_body::scene_target_path(scene, file.target.as_ref()?)
}

/// The scene file at `path`, read (at most 1 MiB) and parsed, not yet checked.
fn read_scene(path: &Path) -> Result<SceneFile, SceneError> {
    let bytes = impact_io::read_limited(path, 1 << 20, "scene file")
        .map_err(|e| SceneError::Read(e.into()))?;
    serde_json::from_slice(&bytes).map_err(|source| SceneError::Json {
        path: path.to_path_buf(),
        source,
    })
}

/// The `--scene` file's settings (all defaults without one), each number within its limits
/// ([`SceneFile::check`]); and the levels given, there or as options ([`check_levels`]).
pub fn scene_file(args: &AnalyzeArgs) -> Result<SceneFile, SceneError> {
    let file = match &args.scene {
        None => SceneFile::default(),
        Some(path) => {
            let file = read_scene(path)?;
            file.check(path)?;
            file
        }
    };
    check_levels(args, &file)?;
    Ok(file)
}

/// Each level given (`--trigger`, `--edge`, `--range`, or the scene file's) within
/// [`parse::LEVEL_M_S2`] once in m/s² (a force over the mass given), named as it was given.
pub fn check_levels(args: &AnalyzeArgs, file: &SceneFile) -> Result<(), SceneError> {
    let mass = args.mass.or(file.mass);
    for (name, cli, in_file) in [
        ("trigger", args.trigger, file.trigger),
        ("edge", args.edge, file.edge),
        ("range", args.range, file.range),
    ] {
        let (Some(level), Some(setting)) = (
            cli.or(in_file),
            setting_name(args, cli.is_some(), in_file.is_some(), name),
        ) else {
            continue;
        };
        if !parse::LEVEL_M_S2.contains(level.to_m_s2(mass)) {
            return Err(SceneError::LevelOutOfRange {
                setting,
                level: LevelAsGiven { level, mass },
            });
        }
    }
    Ok(())
}

/// A level as given, and in m/s² if it was given in another unit (a force over `mass`, kg):
/// `5g (49.03 m/s²)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LevelAsGiven {
    pub level: Level,
    pub mass: Option<f64>,
}

impl std::fmt::Display for LevelAsGiven {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let level = self.level;
        match level.units {
            Units::MS2 => write!(f, "{level}"),
            _ => write!(
                f,
                "{level} ({})",
                crate::report::fmt::human(level.to_m_s2(self.mass), "m/s²")
            ),
        }
    }
}

/// Why the scene's settings (the scene file's, the levels given) were refused.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The scene file not read (missing, over 1 MiB).
    #[error(transparent)]
    Read(InputFileFailure),
    #[error("{}: {source}", .path.display())]
    Json {
        path: PathBuf,
        source: serde_json::Error,
    },
    /// A number of the scene file (`key`: `hold`, `fits.exponent`) outside its limits.
    #[error("{}: {key} {}: {range}", .path.display(), impact_io::limits::number(.range.value))]
    OutOfRange {
        path: PathBuf,
        key: &'static str,
        range: impact_io::limits::OutOfRange,
    },
    /// The scene file's `target` neither a file's name nor an object.
    #[error("{}: target must be the name of a state-space target's file or the state space itself ({{\"a\": .., \"b\": .., \"c\": ..}})", .path.display())]
    TargetKind { path: PathBuf },
    /// A level (`--trigger`, `--edge`, `--range`, or the scene file's) outside
    /// [`parse::LEVEL_M_S2`] once in m/s².
    #[error("{setting} {level}: out of range ({})", parse::LEVEL_M_S2)]
    LevelOutOfRange {
        setting: Setting,
        level: LevelAsGiven,
    },
}

/// How a message names a setting: by its option (`--max-impact`), or by the scene file's key
/// (`scene.json: max_impact`) when only the file gives it.
#[derive(Clone, Debug, PartialEq)]
pub enum Setting {
    /// The option, by its name without the dashes (`max-impact`; the core's parameters are
    /// named as their options are).
    Option(&'static str),
    /// The scene file's key for the option `name`: `max-impact` is `max_impact`, the fits'
    /// `exponent` is `fits.exponent`.
    SceneKey { scene: PathBuf, name: &'static str },
}

impl std::fmt::Display for Setting {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Setting::Option(name) => write!(f, "--{name}"),
            Setting::SceneKey {
                scene,
                name: "exponent",
            } => write!(f, "{}: fits.exponent", scene.display()),
            Setting::SceneKey { scene, name } => {
                write!(f, "{}: {}", scene.display(), name.replace('-', "_"))
            }
        }
    }
}

use crate::read_errors::InputFileFailure;

impl SceneFile {
    /// Checks each number against its limits (as the options' are), naming the file and
    /// the key: `scene.json: hold 1e-300: out of range (between 1e-30 and 1e30 s)`. (The
    /// levels are checked in m/s², with the mass: [`check_levels`].)
    pub fn check(&self, path: &Path) -> Result<(), SceneError> {
        // The target's kind, even where the command line overrides it.
        if let Some(t) = &self.target {
            if !(t.is_object() || t.as_str().is_some_and(|n| !n.is_empty())) {
                return Err(SceneError::TargetKind {
                    path: path.to_path_buf(),
                });
            }
        }
        let exponent = self.fits.as_ref().and_then(|f| f.exponent);
        for (key, value, limits) in [
            ("mass", self.mass, &parse::MASS_KG),
            ("target_mass", self.target_mass, &parse::MASS_KG),
            ("v0", self.v0, &parse::SPEED_M_S),
            ("drop_height", self.drop_height, &parse::HEIGHT_M),
            ("hold", self.hold, &parse::SECONDS),
            ("max_impact", self.max_impact, &parse::SECONDS),
            ("settle", self.settle, &parse::SECONDS),
            ("fits.exponent", exponent, &parse::EXPONENT),
        ] {
            if let Some(v) = value {
                limits.check(v).map_err(|range| SceneError::OutOfRange {
                    path: path.to_path_buf(),
                    key,
                    range,
                })?;
            }
        }
        Ok(())
    }
}

/// How messages name the setting `name` (`hold`, `max-impact`) given on the command line
/// (`--hold`) or else in the scene file (`scene.json: hold`); `None` if neither gives it.
pub fn setting_name(
    args: &AnalyzeArgs,
    on_command_line: bool,
    in_file: bool,
    name: &'static str,
) -> Option<Setting> {
    match (&args.scene, on_command_line, in_file) {
        (_, true, _) => Some(Setting::Option(name)),
        (Some(path), false, true) => Some(Setting::SceneKey {
            scene: path.clone(),
            name,
        }),
        _ => None,
    }
}

/// Which measure of a bounce's approach speed the kinematics use.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum SpeedArg {
    /// `g t / 2 - h / t`, from the flight `t` since the previous separation (`h`: how far
    /// above where it left the body lands, the pad recovered or dented).
    Flight,
    /// The previous impact's rebound `v_r` (`Δv - v0 - g t_c`) brought down by the flight
    /// `t`: `g t - v_r`.
    Rebound,
}

/// `--train` options (flattened into `analyze` and `emulate`).
#[derive(Args, Clone, Debug, Default)]
pub struct TrainArgs {
    /// Bounce trains: each bounce's v0 from its flight time or from the previous rebound.
    ///
    /// Bounce trains: each impact after the first of a drop takes its approach speed from the
    /// flight time since the previous separation (`flight`, vertical flight under gravity
    /// along the sensor's axis, no drag) or from the previous rebound brought down by the
    /// flight (`rebound`, a chain: each bounce keeps the previous one's error); the first
    /// impact takes --v0, --drop-height or --free-fall. Both speeds are reported.
    #[arg(long, help_heading = "Analysis", value_enum)]
    pub train: Option<SpeedArg>,
    /// Gravity along the sensor's axis, m/s² [default: 9.80665].
    ///
    /// Gravity along the sensor's axis, m/s² [default: 9.80665]: taken out of each vertical
    /// contact (a drop, a train, --vertical), and a drop's and a flight's speed.
    #[arg(long, help_heading = "Analysis", value_parser = parse::gravity_m_s2)]
    pub gravity: Option<f64>,
    /// The impact is vertical: take gravity out of each contact.
    ///
    /// The impact is vertical: the accelerometer reads specific force, so in each contact the
    /// body's deceleration is the reading less gravity, and the kinematics integrate that.
    /// Implied by --drop-height, --free-fall and --train; give it for a vertical impact
    /// whose speed comes from --v0 (a light gate above the pad).
    #[arg(long, help_heading = "Analysis")]
    pub vertical: bool,
    /// A flight longer than this starts a new train (a new drop), s [default: 2].
    #[arg(long, help_heading = "Analysis", requires = "train", value_parser = parse::seconds)]
    pub max_flight: Option<f64>,
}

impl TrainArgs {
    /// The scene's train settings, if asked for.
    pub fn train(&self) -> Option<Train> {
        let speed = match self.train? {
            SpeedArg::Flight => TrainSpeed::Flight,
            SpeedArg::Rebound => TrainSpeed::Rebound,
        };
        let d = Train::new();
        Some(Train {
            speed,
            max_flight_s: self.max_flight.map_or(d.max_flight_s, |t| t as f32),
        })
    }
}

/// Shock-spectrum options. The settings are options without clap's `requires = "srs"`: `impact
/// report --srs-required` implies `--srs` after parsing, so [`SpectrumArgs::check`] refuses
/// a setting without the spectra once that is known.
#[derive(Args, Clone, Debug, Default)]
pub struct SpectrumArgs {
    /// Add each impact's SRS (maximax absolute acceleration), PVSS and enveloping half-sine.
    #[arg(long, help_heading = "Analysis")]
    pub srs: bool,
    /// Damping ratio of the oscillators, in [0, 0.5] [default: 0.05].
    #[arg(long, help_heading = "Analysis", value_parser = damping)]
    pub srs_damping: Option<f64>,
    /// Bands per octave: 6 or 12 (centres 1000 × 2^(k/n) Hz) [default: 6].
    #[arg(long, help_heading = "Analysis", value_parser = per_octave)]
    pub srs_bands: Option<u32>,
    /// Lowest band, Hz [default: 10].
    #[arg(long, help_heading = "Analysis", value_parser = parse::frequency_hz)]
    pub srs_low: Option<f64>,
    /// Highest band, Hz: a specification's range (10000 for MIL-STD-810's, say) need not pay for
    /// the bands above it [default: an eighth of the sample rate, and never above it].
    #[arg(long, help_heading = "Analysis", value_parser = parse::frequency_hz)]
    pub srs_high: Option<f64>,
}

impl SpectrumArgs {
    /// The oscillators' damping ratio (0.05 unless given).
    pub fn damping(&self) -> f64 {
        self.srs_damping.unwrap_or(0.05)
    }

    /// Bands per octave (6 unless given).
    pub fn bands_per_octave(&self) -> u32 {
        self.srs_bands.unwrap_or(6)
    }

    /// The lowest band, Hz (10 unless given).
    pub fn low_hz(&self) -> f64 {
        self.srs_low.unwrap_or(10.0)
    }

    /// The scene's spectrum settings, if asked for.
    pub fn settings(&self) -> Option<SpectrumSettings> {
        self.srs.then_some(SpectrumSettings {
            damping: self.damping() as f32,
            bands_per_octave: self.bands_per_octave() as u8,
            low_hz: self.low_hz() as f32,
            high_hz: self.srs_high.map(|h| h as f32),
        })
    }

    /// A spectrum's setting without the spectra (`--srs`, or `impact report
    /// --srs-required`) is refused, naming the first given: it would change nothing.
    pub fn check(&self) -> Result<(), Setting> {
        let given = [
            ("srs-damping", self.srs_damping.is_some()),
            ("srs-bands", self.srs_bands.is_some()),
            ("srs-low", self.srs_low.is_some()),
            ("srs-high", self.srs_high.is_some()),
        ];
        match given.iter().find(|(_, g)| *g) {
            Some((name, _)) if !self.srs => Err(Setting::Option(name)),
            _ => Ok(()),
        }
    }
}

/// Why a shock spectrum's option was refused (clap names the option and the value given).
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum SpectrumOptionError {
    #[error("must be 6 or 12")]
    BandsPerOctave,
    #[error("must lie in [0, 0.5]")]
    Damping,
    #[error("not a number")]
    NotANumber,
}

fn per_octave(s: &str) -> Result<u32, SpectrumOptionError> {
    match s {
        "6" => Ok(6),
        "12" => Ok(12),
        _ => Err(SpectrumOptionError::BandsPerOctave),
    }
}

fn damping(s: &str) -> Result<f64, SpectrumOptionError> {
    match s.parse::<f64>() {
        Ok(v) if (0.0..=0.5).contains(&v) => Ok(v),
        Ok(_) => Err(SpectrumOptionError::Damping),
        Err(_) => Err(SpectrumOptionError::NotANumber),
    }
}
