//! A recorded signal through the same core pipeline the firmware runs: the options and the
//! scene resolved ([`options`], [`build_scene`]), the recording read ([`impact_io`]), surveyed
//! ([`survey`], [`histogram`]) and screened ([`screen`]), quantised to counts, and analysed
//! by the core's monitor; whole, in passes or as a stream ([`streaming`]); the three axes'
//! part ([`axes`]), the free fall ([`free_fall`]) and the spectra's reference ([`spectrum`]).

pub mod axes;
pub mod band_file;
pub mod free_fall;
pub mod histogram;
pub mod level;
pub mod options;
pub mod screen;
pub mod spec;
pub mod spectrum;
pub mod streaming;
pub mod survey;

use impact_core::consts::STANDARD_GRAVITY;
use impact_core::monitor::Monitor;
use impact_core::signal::cfc::Cfc;
use impact_core::signal::lowpass::Lowpass;
use impact_core::{Approach, Calibration, FitSet, ImpactReport, Scene};

use crate::pipeline::free_fall::free_fall_before;
use crate::report::fmt::{shortest, sig};
use crate::report::{impact_json, AnalysisJson, Clipping, Spike, SPIKE_REMOVED};
use impact_io::quantise::to_count;
use impact_io::read_recording;
pub use options::{scene_file, AnalyzeArgs, FitsFile, Level, SceneFile, Setting, Units};
use survey::Survey;

use crate::read_errors::{ReadFailure, UnitsFailure};
use std::path::PathBuf;

/// Why a recording could not be analysed: its read, the settings, its survey, the stream's
/// needs, the threads. Each message as the tool prints it.
#[derive(Debug, thiserror::Error)]
pub enum PipelineError {
    /// The recording not read (its file named, the settings by their options).
    #[error(transparent)]
    Read(#[from] ReadFailure),
    #[error(transparent)]
    Units(#[from] UnitsFailure),
    #[error(transparent)]
    Scene(#[from] options::SceneError),
    #[error(transparent)]
    Survey(#[from] survey::SurveyError),
    #[error(transparent)]
    FreeFall(#[from] free_fall::FreeFallError),
    #[error(transparent)]
    Worker(#[from] crate::WorkerError),
    /// `--target FILE` not read, or not a target the analysis can push (boxed: its path
    /// and reasons are large).
    #[error(transparent)]
    Target(Box<crate::simulate::two_body::TargetError>),
    /// A recording read whole would take `need_bytes` of memory, which cannot be had.
    #[error("{}: {}", .path.display(), NeedsMemory(*.need_bytes))]
    Memory { path: PathBuf, need_bytes: u64 },
    #[error("--free-fall: no impact in the recording")]
    NoImpactForFreeFall,
    /// `--main-axis` not one of `--axes`.
    #[error("--main-axis {given}: not one of --axes ({axes}): name the intended direction's axis as --axes does")]
    MainAxis { given: String, axes: String },
    /// A CFC class (`--cfc`, the scene file's `cfc`, `--trigger-cfc`) none of SAE J211's.
    #[error("{setting}: {class} is not one of 60, 180, 600, 1000")]
    Cfc { setting: Setting, class: u32 },
    /// `--lowpass`'s cut-off at or above the Nyquist frequency of the recording's rate.
    #[error(
        "--lowpass: cut-off {} Hz is not below the Nyquist frequency, {} Hz (half the \
         recording's {} S/s): choose a cut-off below it",
        sig(*.cutoff_hz, 6), sig(*.rate_hz / 2.0, 6), sig(*.rate_hz, 6)
    )]
    LowpassAboveNyquist { cutoff_hz: f64, rate_hz: f64 },
    /// `--lowpass`'s cut-off below the core's lowest for the rate
    /// (`impact_core::signal::lowpass::MAX_RATE_OVER_CUTOFF`).
    #[error(
        "--lowpass: cut-off {} Hz is below {} Hz, the recording's {} S/s over 100 000 (the \
         filter's gain at 0 Hz drifts below it): choose a cut-off of at least {} Hz, or \
         resample the recording slower",
        sig(*.cutoff_hz, 6), sig(*.rate_hz / impact_core::signal::lowpass::MAX_RATE_OVER_CUTOFF, 6),
        sig(*.rate_hz, 6), sig(*.rate_hz / impact_core::signal::lowpass::MAX_RATE_OVER_CUTOFF, 6)
    )]
    LowpassTooLow { cutoff_hz: f64, rate_hz: f64 },
    /// The scene refused by the core: its parameter named as it was given (an option or
    /// the scene file's key).
    #[error("{setting}: {reason}")]
    Invalid {
        setting: Setting,
        reason: &'static str,
    },
    /// The core refused the scene otherwise.
    #[error(transparent)]
    Core(impact_core::Error),
    /// The core's monitor refused the scene: a parameter named as its option
    /// ([`crate::flags::core`]).
    #[error("{}", crate::flags::core(*.0))]
    Monitor(impact_core::Error),
    /// The longest impact (given or its default) shorter than the hold.
    #[error("{longest}: shorter than the hold (at least {hold})")]
    LongestUnderHold { longest: TimeGiven, hold: TimeGiven },
    /// The hold given longer than the longest impact (its default).
    #[error("{hold}: longer than the longest impact (at most {longest})")]
    HoldOverLongest { hold: TimeGiven, longest: TimeGiven },
    /// The settling time given, s, shorter than the hold.
    #[error("{setting} {}: shorter than the hold (at least {hold})", impact_io::limits::number(*.settle_s))]
    SettleUnderHold {
        setting: Setting,
        settle_s: f64,
        hold: TimeGiven,
    },
    /// The edge level given not below the trigger level (`trigger_m_s2`).
    #[error(
        "{setting} {level}: not below the trigger level (below {trigger}, {})",
        crate::report::fmt::human(*.trigger_m_s2, "m/s²")
    )]
    EdgeNotBelowTrigger {
        setting: Setting,
        level: options::LevelAsGiven,
        trigger: TriggerGiven,
        trigger_m_s2: f64,
    },
    /// `--stream` with an option (`--plot`) that needs the whole recording.
    #[error("--stream: {option} needs the whole recording")]
    StreamNeedsWhole { option: &'static str },
    #[error(
        "--stream: give --range (the sensor's full scale sets the quantisation before the \
         recording's extremes are known)"
    )]
    StreamNeedsRange,
    #[error(
        "--stream: give --trigger (the level cannot be learned from a recording not yet read)"
    )]
    StreamNeedsTrigger,
    /// `--axes` whose headers name different units (one scale takes every axis to m/s²).
    #[error(
        "--axes: {first:?} is in {first_units}, {other:?} in {other_units}: give axes in one unit"
    )]
    AxesUnits {
        first: String,
        first_units: &'static str,
        other: String,
        other_units: &'static str,
    },
    /// A recording of fewer than 2 samples (`column`: its channel's header, empty if none).
    #[error(
        "{}: {}",
        impact_io::channel::input_name(.path),
        FewSamples(.column, *.samples)
    )]
    TooFewSamples {
        path: PathBuf,
        column: String,
        samples: u64,
    },
    /// The spool of an input read once (standard input, a FIFO, a device: its values kept for
    /// the later passes) not made or written; `input` as messages name it.
    #[error("{input}: {error}")]
    Spool {
        input: String,
        #[source]
        error: std::sync::Arc<impact_io::error::SpoolError>,
    },
    /// A sample given in memory that is not a finite number (the readers refuse the like in
    /// a file: [`analyze_samples`]); `index` from 0.
    #[error("{name}: sample {index} is {value}: not a finite number")]
    NotFinite {
        name: String,
        index: u64,
        value: f64,
    },
    #[error("the survey's thread panicked")]
    SurveyPanicked,
    #[error("the reader thread panicked")]
    ReaderPanicked,
    /// The counts for `impact emulate` not written.
    #[error("the recording's counts for the emulator: {0}")]
    Counts(#[source] std::io::Error),
}

impl PipelineError {
    /// The message without the recording's name where it begins with it (`file`, as a
    /// series names its entry): what the error says of the recording.
    pub fn of_recording<'a>(&'a self, file: &'a std::path::Path) -> OfRecording<'a> {
        OfRecording { error: self, file }
    }
}

/// A [`PipelineError`] as said of the recording `file` ([`PipelineError::of_recording`]):
/// an error that names the file first (its read, its memory, its length) without it.
pub struct OfRecording<'a> {
    error: &'a PipelineError,
    file: &'a std::path::Path,
}

impl std::fmt::Display for OfRecording<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.error {
            PipelineError::Read(ReadFailure(e))
                if e.at.is_none() && e.kind.names_the_file() && e.path == self.file =>
            {
                f.write_str(&crate::read_errors::kind_message(&e.kind))
            }
            PipelineError::Memory { path, need_bytes } if path == self.file => {
                NeedsMemory(*need_bytes).fmt(f)
            }
            PipelineError::TooFewSamples {
                path,
                column,
                samples,
            } if path == self.file => FewSamples(column, *samples).fmt(f),
            e => e.fmt(f),
        }
    }
}

/// What a recording read whole needs, bytes, that cannot be had (without its file).
struct NeedsMemory(u64);

impl std::fmt::Display for NeedsMemory {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "read whole (for --axes, --free-fall, --resample, --adxl375) it takes some {:.1} GB of memory, which is not available: analyse it without those options (read in passes, in bounded memory)",
            self.0 as f64 / 1e9
        )
    }
}

/// A recording's channel (its header, empty if none) with too few samples (without its
/// file).
struct FewSamples<'a>(&'a str, u64);

impl std::fmt::Display for FewSamples<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if !self.0.is_empty() {
            write!(f, "{}: ", self.0)?;
        }
        write!(f, "{} samples; at least 2", self.1)
    }
}

/// One of the times given (or its default), s, as messages name it: `--hold 0.5`,
/// `scene.json: max_impact 1e-9`, `the default --hold, 0.002 s`.
#[derive(Clone, Debug, PartialEq)]
pub enum TimeGiven {
    Given {
        setting: Setting,
        value_s: f64,
    },
    /// The option's default (`name`: `hold`).
    Default {
        name: &'static str,
        value_s: f64,
    },
}

impl std::fmt::Display for TimeGiven {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            TimeGiven::Given { setting, value_s } => {
                write!(f, "{setting} {}", impact_io::limits::number(*value_s))
            }
            TimeGiven::Default { name, value_s } => write!(
                f,
                "the default --{name}, {} s",
                impact_io::limits::number(*value_s)
            ),
        }
    }
}

/// Where the trigger level an edge level is checked against came from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TriggerGiven {
    /// `--trigger`, as given.
    Option(Level),
    /// The scene file's `trigger`, as given.
    SceneFile(Level),
    /// Learned from the signal's noise.
    Learned,
}

impl std::fmt::Display for TriggerGiven {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            TriggerGiven::Option(t) => write!(f, "--trigger {t}"),
            TriggerGiven::SceneFile(t) => write!(f, "the scene file's trigger {t}"),
            TriggerGiven::Learned => {
                f.write_str("the trigger level learned from the signal's noise")
            }
        }
    }
}

/// Analyses a recording: the one entry of the three ways of reading it. A regular file or
/// standard input is read in passes in bounded memory ([`streaming::analyze_in_passes`]),
/// unless an option needs the whole recording in memory (then a large file gets a note of
/// the memory it takes, about 40 bytes a row); `--stream` reads it once with the levels
/// given ([`streaming::analyze`]). The setup (without the samples for the passes and the
/// stream) and the reports.
pub fn analyze(
    args: &AnalyzeArgs,
    progress: impact_io::progress::Progress,
) -> Result<(Setup, Vec<ImpactReport>), PipelineError> {
    let in_passes = streaming::in_passes(args);
    if !args.stream && !in_passes {
        memory_for_whole(&args.file)?;
    }
    let (setup, reports) = if args.stream {
        streaming::analyze(args, progress)
    } else if in_passes {
        streaming::analyze_in_passes(args, progress)
    } else {
        let setup = setup(args, progress)?;
        let reports = run(&setup.prepared.counts, &setup.scene, setup.capture_len)?;
        Ok((setup, reports))
    }?;
    note_results(args, &setup, &reports);
    Ok((setup, reports))
}

/// [`analyze`] of samples given in memory (the Python package's arrays): the options that
/// read a file (`--stream`, the columns, the time base) do not apply; `args.file` only
/// names the samples.
pub fn analyze_samples(
    args: &AnalyzeArgs,
    samples: Samples<'_>,
) -> Result<(Setup, Vec<ImpactReport>), PipelineError> {
    // What the readers hold a file's samples to: two at least, every one finite.
    let n = samples.values.len();
    if n < 2 {
        return Err(PipelineError::TooFewSamples {
            path: PathBuf::from(samples.name),
            column: String::new(),
            samples: n as u64,
        });
    }
    if let Some((index, &value)) = samples
        .values
        .iter()
        .enumerate()
        .find(|(_, v)| !v.is_finite())
    {
        return Err(PipelineError::NotFinite {
            name: samples.name.to_string(),
            index: index as u64,
            value,
        });
    }
    // The signal (8 bytes a sample) and the counts twice (2 each): refused with the need
    // when it cannot be had, never an abort half way.
    memory_to_be_had(
        std::path::Path::new(samples.name),
        (n as u64).saturating_mul(12),
    )?;
    let setup = setup_of(args, samples)?;
    let reports = run(&setup.prepared.counts, &setup.scene, setup.capture_len)?;
    note_results(args, &setup, &reports);
    Ok((setup, reports))
}

/// The notes on an analysis's results: a spec far from every pulse, an implausible time
/// base, decimated captures.
fn note_results(args: &AnalyzeArgs, setup: &Setup, reports: &[ImpactReport]) {
    if let Some(note) = args
        .spec
        .and_then(|s| spec::far_from_every_pulse(&s, reports))
    {
        impact_io::note(&note);
    }
    if let Some(note) = time_base_implausible(&setup.assumptions, reports) {
        impact_io::note(&note);
    }
    if let Some(note) = decimated(args, &setup.scene, setup.rate_hz, reports) {
        impact_io::note(&note);
    }
}

/// A note when impacts outlasted the capture and were analysed at a coarser step: how many,
/// what they lack, and the option that holds every sample (if it can).
pub fn decimated(
    args: &AnalyzeArgs,
    scene: &Scene,
    rate_hz: f64,
    reports: &[ImpactReport],
) -> Option<String> {
    let coarse: Vec<_> = reports
        .iter()
        .filter(|r| r.flags.contains(impact_core::report::Flags::DECIMATED))
        .collect();
    let step = coarse.iter().map(|r| r.decimation).max()?;
    let len = capture_len(args);
    let human = crate::report::fmt::human;
    let whose = if args.capture_samples.is_some() {
        "the capture"
    } else {
        "the board's capture"
    };
    let lift = if len < HOST_CAPTURE_LEN {
        format!(
            "; --capture-samples {HOST_CAPTURE_LEN} holds {} at every sample",
            human(HOST_CAPTURE_LEN as f64 / rate_hz, "s")
        )
    } else {
        String::new()
    };
    // Against a target the kinematics are the capture's pass's (the online sums are the
    // body's alone).
    let kinematics = if scene.target.is_some() {
        "their kinematics against the target, widths, filter, spectra, verdict and fits come from those means"
    } else {
        "their kinematics come from every sample, their widths, filter, spectra, verdict and fits from those means"
    };
    Some(format!(
        "{} of {} impacts outlasted {whose} ({len} samples, {}) and were held as the means of up to {step} samples (flag decimated): {kinematics}{lift}",
        coarse.len(),
        reports.len(),
        human(len as f64 / rate_hz, "s"),
    ))
}

/// The largest velocity change a drop, shock or impact test makes, m/s: a Δv beyond it comes
/// from a time base read in the wrong unit (ms read as s makes every Δv 1000× too large).
pub const PLAUSIBLE_DELTA_V_M_S: f64 = 1000.0;

/// A note when the time column's unit was assumed (seconds) and an impact's Δv under it is
/// beyond [`PLAUSIBLE_DELTA_V_M_S`]: the largest named, with what it would be in ms and µs.
pub fn time_base_implausible(
    assumptions: &[Assumption],
    reports: &[ImpactReport],
) -> Option<String> {
    let column = assumptions.iter().find_map(|a| match a {
        Assumption::TimeUnit { column } => Some(column),
        _ => None,
    })?;
    let (index, dv) = reports
        .iter()
        .filter_map(|r| r.delta_v_m_s.map(|dv| (r.index, f64::from(dv).abs())))
        .max_by(|a, b| a.1.total_cmp(&b.1))?;
    (dv > PLAUSIBLE_DELTA_V_M_S).then(|| {
        let human = crate::report::fmt::human;
        format!(
            "the time column {column:?} was read in seconds (it names no unit), and impact {index}'s Δv is then {}, beyond any drop or shock test ({}): if the column is in ms, give --time-unit ms (Δv {}); in µs, --time-unit us (Δv {})",
            human(dv, "m/s"),
            human(PLAUSIBLE_DELTA_V_M_S, "m/s"),
            human(dv * 1e-3, "m/s"),
            human(dv * 1e-6, "m/s"),
        )
    })
}

/// Whether `need_bytes` of memory can be had now (reserved and given back): the analysis of
/// `path` refused with its need when it cannot ([`PipelineError::Memory`]), never an abort half
/// way.
fn memory_to_be_had(path: &std::path::Path, need_bytes: u64) -> Result<(), PipelineError> {
    let mut probe: Vec<u8> = Vec::new();
    probe
        .try_reserve_exact(usize::try_from(need_bytes).unwrap_or(usize::MAX))
        .map_err(|_| PipelineError::Memory {
            path: path.to_path_buf(),
            need_bytes,
        })
}

/// Checks that a recording read whole (for `--axes`, `--free-fall`, `--resample` or an
/// ADXL375's axes) finds the memory it takes (its values, the signal and the counts: about
/// three times a CSV's size, ten times a binary file's): a message naming the need when it
/// does not (a memory limit), never an abort half way; a note for one over 1 GB.
pub fn memory_for_whole(file: &std::path::Path) -> Result<(), PipelineError> {
    let size = std::fs::metadata(file).map_or(0, |m| m.len());
    let binary = matches!(
        impact_io::Format::of(file, None),
        impact_io::Format::Raw(_) | impact_io::Format::Wav | impact_io::Format::Npy
    );
    let need = size.saturating_mul(if binary { 10 } else { 3 });
    let gb = |b: u64| b as f64 / 1e9;
    memory_to_be_had(file, need)?;
    if size > 1 << 30 {
        crate::errln!(
            "note: {} is {:.1} GB: read whole (for --axes, --free-fall, --resample or --adxl375) it takes some {:.0} GB of memory",
            file.display(),
            gb(size),
            gb(need)
        );
    }
    Ok(())
}

/// The host's monitor: a 2^15-sample ring (the flanks reach back 4096 samples, as on the board;
/// the rest is history for a CFC's lead-in: CFC 60's 10 ms up to 3.2 MS/s), a 2^17-sample
/// capture, of which `--capture-samples` are used (the board's by default).
pub type HostMonitor = Monitor<32768, HOST_CAPTURE_LEN>;

/// The host's capture buffer, samples: the most `--capture-samples` may ask for.
pub const HOST_CAPTURE_LEN: usize = 131_072;

/// The capture length `analyze` uses: `--capture-samples`, else the board's.
pub fn capture_len(args: &AnalyzeArgs) -> usize {
    args.capture_samples
        .map_or(impact_core::board::CAPTURE_LEN, |n| n as usize)
}

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

/// Whether the scene the options and the scene file make is vertical (core's rule,
/// `Scene::contact_gravity_m_s2`: `--vertical`, a free fall, a drop height or a train),
/// known before the scene is built: its default edge level depends on it.
pub(crate) fn vertical(args: &AnalyzeArgs, file: &SceneFile) -> bool {
    args.train.vertical
        || file.vertical.unwrap_or(false)
        || args.free_fall.is_some()
        || args.train.train.is_some()
        || {
            // (As `build_scene` takes the approach: the command line's over the file's.)
            let (v0, height) = if args.v0.is_some() || args.drop_height.is_some() {
                (args.v0, args.drop_height)
            } else {
                (file.v0, file.drop_height)
            };
            v0.is_none() && height.is_some()
        }
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
    /// The capture's length, samples ([`capture_len`]).
    pub capture_len: usize,
    /// Isolated spikes removed before quantising (see [`screen::SpikeScan`]).
    pub spikes: Vec<Spike>,
    /// The channel's rails, if known.
    pub clipping: Option<Clipping>,
    /// Whether the time axis was interpolated onto an even grid.
    pub resampled: bool,
    /// With `--axes`: each axis in m/s² and its rails.
    pub axes: Vec<crate::pipeline::axes::Axis>,
    /// With `--axes` and `--spec`: the transverse-motion check's limit and main axis.
    pub transverse: Option<crate::pipeline::axes::TransverseCheck>,
    /// A recording read in passes keeps no counts: the windows `--plot` draws, read in a
    /// last pass (first sample's stream index, counts).
    pub windows: Vec<(u64, Vec<i16>)>,
    /// What the tool assumed that neither the file nor the options said (a unit).
    pub assumptions: Vec<Assumption>,
    /// The standard `--spec` named, if a spec was given ([`Resolved::spec_standard`]).
    pub spec_standard: Option<&'static str>,
}

/// What was read of a recording, however it was read: its channel, units, time base and
/// length.
pub struct Reading {
    /// The channel's header (empty where the format names none) and its units.
    pub column: String,
    pub units: Units,
    /// Time of the first sample, s; the samples; the rate, S/s.
    pub t0: f64,
    pub samples: u64,
    pub rate_hz: f64,
}

/// The scene resolved from the options and the scene file ([`build_scene`]), and where its
/// approach speed came from (`v0`, `drop-height`; none without one).
pub struct Resolved {
    pub scene: Scene,
    pub v0_source: Option<&'static str>,
    /// The standard `--spec` named (its tolerances' source), if a spec was given.
    pub spec_standard: Option<&'static str>,
    /// The capture's length, samples ([`capture_len`]).
    pub capture_len: usize,
}

impl Setup {
    /// The setup of `reading` analysed with `resolved`'s scene (its calibration the
    /// scene's): no counts or signal kept, no glitches removed, no rails known, no axes, not
    /// resampled (a whole-file read fills them in).
    pub fn new(reading: Reading, resolved: Resolved) -> Self {
        let Reading {
            column,
            units,
            t0,
            samples,
            rate_hz,
        } = reading;
        Self {
            column: (!column.is_empty()).then_some(column),
            units,
            prepared: Prepared {
                counts: Vec::new(),
                calibration: resolved.scene.calibration,
                t0,
                accel_m_s2: Vec::new(),
            },
            scene: resolved.scene,
            capture_len: resolved.capture_len,
            spec_standard: resolved.spec_standard,
            v0_source: resolved.v0_source.map(str::to_string),
            free_fall_s: None,
            samples,
            rate_hz,
            spikes: Vec::new(),
            clipping: None,
            resampled: false,
            axes: Vec::new(),
            transverse: None,
            windows: Vec::new(),
            assumptions: Vec::new(),
        }
    }

    /// The signal the figure draws: the counts the pipeline analysed times the gain.
    pub fn plot_signal(&self) -> crate::plot::Signal<'_> {
        // A force channel's values were divided by the mass (1 kg without one) into m/s².
        let force_kg = (self.units == Units::N).then(|| self.scene.mass_kg.map_or(1.0, f64::from));
        crate::plot::Signal {
            title: format!(
                "{}: raw signal above its baseline, {}{}",
                self.column.as_deref().unwrap_or("acceleration"),
                if force_kg.is_some() { "N" } else { "m/s²" },
                self.scene
                    .window_filter()
                    .map_or(String::new(), |f| format!(
                        "; {} over the {}",
                        crate::report::filter::description(&f),
                        if force_kg.is_some() {
                            "force"
                        } else {
                            "deceleration"
                        }
                    )),
            ),
            filter: self
                .scene
                .window_filter()
                .map(|f| (f, u64::from(self.scene.padding_samples()))),
            rate_hz: f64::from(self.scene.calibration.sample_rate_hz),
            mass_kg: self.scene.mass_kg.map(f64::from),
            t0_s: self.prepared.t0,
            force_kg,
            accel_m_s2: Box::new(move |i| {
                let gain = f64::from(self.scene.calibration.gain_m_s2_per_count);
                let count = match self
                    .windows
                    .iter()
                    .find(|(from, w)| i >= *from && i - from < w.len() as u64)
                {
                    Some((from, w)) => w.get(usize::try_from(i - from).ok()?),
                    None => self.prepared.counts.get(usize::try_from(i).ok()?),
                };
                count.map(|&c| f64::from(c) * gain)
            }),
        }
    }
}

/// Reads the file and builds the scene (v0 from a free fall needs a first pass).
pub fn setup(
    args: &AnalyzeArgs,
    progress: impact_io::progress::Progress,
) -> Result<Setup, PipelineError> {
    let ch = read_recording(&args.file, &args.read_options(progress)).map_err(ReadFailure::from)?;
    setup_of(args, Samples::of(&ch))
}

/// A channel's samples as the pipeline takes them, however they were had: a recording read
/// ([`Samples::of`]) or an array given in memory (the Python package's, borrowed as it is).
#[derive(Clone, Copy, Debug)]
pub struct Samples<'a> {
    /// The channel's header (empty where there is none).
    pub name: &'a str,
    /// The values in the channel's units (the resultant with `axes`).
    pub values: &'a [f64],
    /// Time of the first sample, s; the rate, S/s.
    pub t0: f64,
    pub rate_hz: f64,
    /// Whether the samples were interpolated onto an even grid.
    pub resampled: bool,
    /// With `--axes`: each axis (header, values).
    pub axes: &'a [(String, Vec<f64>)],
    /// The time column's header when its unit was assumed (seconds).
    pub time_unit_assumed: Option<&'a str>,
}

impl<'a> Samples<'a> {
    /// The samples of a channel read from a recording.
    pub fn of(ch: &'a impact_io::channel::Channel) -> Self {
        Self {
            name: &ch.name,
            values: &ch.values,
            t0: ch.time_s.first().copied().unwrap_or(0.0),
            rate_hz: ch.rate_hz,
            resampled: ch.resampled,
            axes: &ch.axes,
            time_unit_assumed: ch.time_unit_assumed.as_deref(),
        }
    }

    /// Evenly spaced samples from time 0, one channel named `name`.
    pub fn even(name: &'a str, values: &'a [f64], rate_hz: f64) -> Self {
        Self {
            name,
            values,
            t0: 0.0,
            rate_hz,
            resampled: false,
            axes: &[],
            time_unit_assumed: None,
        }
    }
}

/// [`setup`] of samples already had (the options' reading of the file left out).
pub fn setup_of(args: &AnalyzeArgs, ch: Samples<'_>) -> Result<Setup, PipelineError> {
    let file = scene_file(args)?;
    let column = ch.axes.first().map_or(ch.name, |(name, _)| name.as_str());
    let (mass, scale, units, first_assumed) = mass_and_scale(args, &file, column)?;
    // Every axis in the first one's units (one scale takes them all to m/s²): axes whose
    // headers name other units are refused, not read 9.8× off.
    let mut assumed: Vec<Assumption> = first_assumed;
    for (name, _) in ch.axes.iter().skip(1) {
        let (_, _, u, axis_assumed) = mass_and_scale(args, &file, name)?;
        if u != units {
            return Err(PipelineError::AxesUnits {
                first: column.to_string(),
                first_units: units.name(),
                other: name.clone(),
                other_units: u.name(),
            });
        }
        // (Each assumption once: every axis is in the first one's units.)
        for a in axis_assumed {
            if !assumed.contains(&a) {
                assumed.push(a);
            }
        }
    }
    let mut accel: Vec<f64> = ch.values.iter().map(|v| v * scale).collect();
    let full_scale = full_scale_m_s2(args, &file, mass);
    let t0 = ch.t0;
    // The survey, and again after glitches are removed (they set the extremes).
    let first = Survey::of(&accel, !args.keep_spikes)?;
    let spikes = screen::apply(&first.removals, &mut accel, t0, ch.rate_hz);
    let first_removals = first.removals.clone();
    let survey = if spikes.is_empty() {
        first
    } else {
        Survey::of(&accel, false)?
    };
    // With --axes the range is each axis's (the resultant reaches sqrt(n) times it), and
    // clipping is found per axis.
    let axes: Vec<crate::pipeline::axes::Axis> = ch
        .axes
        .iter()
        .map(|(name, v)| {
            let mut a: Vec<f64> = v.iter().map(|x| x * scale).collect();
            crate::pipeline::axes::remove_spikes(&mut a, &first_removals);
            crate::pipeline::axes::Axis::new(name.clone(), a, full_scale)
        })
        .collect();
    let (trigger, edge) = given_levels(args, &file, mass);
    let levels = if axes.is_empty() {
        survey::levels(&survey, full_scale, trigger, edge, vertical(args, &file))?
    } else {
        let fs = full_scale.map(|fs| fs * (axes.len() as f64).sqrt());
        let levels = survey::levels(&survey, fs, trigger, edge, vertical(args, &file))?;
        // The zeroed magnitude |f − f₀| reaches |f| + |f₀|: counts for twice the resultant's
        // range (the sensor's, or the largest reading; checked as such above).
        let range = fs.unwrap_or_else(|| survey.peak_m_s2());
        survey::Levels {
            clipping: None,
            gain_m_s2_per_count: impact_io::quantise::gain_for(2.0 * range),
            ..levels
        }
    };
    let clipping = levels.clipping.clone();
    let calibration = Calibration {
        gain_m_s2_per_count: levels.gain_m_s2_per_count as f32,
        sample_rate_hz: ch.rate_hz as f32,
    };
    let (trigger, edge) = (levels.trigger_m_s2, levels.edge_m_s2);
    let resolved = build_scene(
        args,
        &file,
        calibration,
        trigger,
        edge,
        clipping.as_ref(),
        mass,
    )?;
    // With --axes, each axis zeroed before the magnitude (the scene's edge and settle time).
    let counts = if axes.is_empty() {
        accel
            .iter()
            .map(|v| to_count(*v, levels.gain_m_s2_per_count))
            .collect()
    } else {
        crate::pipeline::axes::zeroed_counts(
            &axes,
            &resolved.scene,
            levels.gain_m_s2_per_count,
            to_count,
        )
    };
    let reading = Reading {
        column: ch.name.to_string(),
        units,
        t0,
        samples: ch.values.len() as u64,
        rate_hz: ch.rate_hz,
    };
    let mut setup = Setup::new(reading, resolved);
    setup.assumptions.extend(assumed);
    setup
        .assumptions
        .extend(ch.time_unit_assumed.map(assumed_time_unit));
    setup.prepared.counts = counts;
    setup.prepared.accel_m_s2 = accel;
    setup.spikes = spikes;
    setup.clipping = clipping;
    setup.resampled = ch.resampled;
    setup.axes = axes;
    let names: Vec<&str> = setup.axes.iter().map(|a| a.name.as_str()).collect();
    setup.transverse = crate::pipeline::axes::TransverseCheck::of(args, &names)?;
    if let Some(spec) = &args.free_fall {
        // First pass without v0 to find the first impact, then the free fall before it.
        let first = run(&setup.prepared.counts, &setup.scene, setup.capture_len)?;
        let start = first
            .first()
            .map(|r| setup.prepared.t0 + r.start_s)
            .ok_or(PipelineError::NoImpactForFreeFall)?;
        let (t_ff, assumed) = free_fall_before(spec, start)?;
        setup.assumptions.extend(assumed);
        setup.free_fall_s = Some(t_ff);
        setup.scene.approach = Approach::Speed {
            v0_m_s: (STANDARD_GRAVITY * t_ff) as f32,
        };
        setup.v0_source = Some("free-fall".into());
    }
    Ok(setup)
}

/// The body's mass and the factor from the file's values to m/s² (units, `--gain`,
/// `--invert`), from the options or the scene file (checked as they were read: the options'
/// parsers, [`scene_file`]); the units are those stated, else those the channel's header
/// (`column`) names, else g (an error if the two disagree), and that assumption if g was
/// assumed (kept as a note too).
pub fn mass_and_scale(
    args: &AnalyzeArgs,
    file: &SceneFile,
    column: &str,
) -> Result<(Option<f64>, f64, Units, Vec<Assumption>), PipelineError> {
    let mass = args.mass.or(file.mass);
    let units = Units::resolve(args.units.or(file.units), column).map_err(UnitsFailure)?;
    let mut assumed: Vec<Assumption> = assumed_units(args, file, column)
        .map(Assumption::noted)
        .into_iter()
        .collect();
    // A force is an acceleration only over a mass: without one, per kilogram, said.
    if units == Units::N && mass.is_none() {
        assumed.push(Assumption::ForcePerKilogram.noted());
    }
    let invert = args.invert || file.invert.unwrap_or(false);
    let scale = units.to_m_s2(mass) * args.gain.unwrap_or(1.0) * if invert { -1.0 } else { 1.0 };
    Ok((mass, scale, units, assumed))
}

/// What the tool assumed that neither the file nor the options said.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Assumption {
    /// The channel (`column`'s header names no unit) read as g.
    Units { column: String },
    /// The time column (`column`) read in seconds.
    TimeUnit { column: String },
    /// `--free-fall`'s file (`file`): its time column (`column`) read in seconds.
    FreeFallTimeUnit { file: String, column: String },
    /// `--free-fall`'s file (`file`): a column (`column`) that names no unit read as g.
    FreeFallUnits { file: String, column: String },
    /// A force channel (N) without a mass: analysed per kilogram (its "accelerations" are
    /// the force over 1 kg).
    ForcePerKilogram,
}

impl Assumption {
    /// The sentence: the assumption and the option that changes it.
    pub fn text(&self) -> String {
        match self {
            Assumption::Units { column } if column.is_empty() => "the channel names no unit: its values read as g (give --units g, m/s2, kgn or n)".to_string(),
            Assumption::Units { column } => format!(
                "{column:?} names no unit: its values read as g (give --units g, m/s2, kgn or n, or name the unit in the header: accel_m_s2, accel (g))"
            ),
            Assumption::TimeUnit { column } => format!(
                "the time column {column:?} names no unit: read in seconds (give --time-unit ms, us or ns, or name the unit in the header: time_ms, time (ms))"
            ),
            Assumption::FreeFallTimeUnit { file, column } => format!(
                "--free-fall {file}: the time column {column:?} names no unit: read in seconds (name it in the header: time_ms, time (ms))"
            ),
            Assumption::FreeFallUnits { file, column } => {
                format!("--free-fall {file}: {column} names no unit: read as g")
            }
            Assumption::ForcePerKilogram => "the channel is a force (N) and no --mass was given: it is analysed per kilogram, its accelerations and Δv those of a 1 kg body (give --mass for the body's own)".to_string(),
        }
    }

    /// Kept as a note for stderr too (each once), and returned.
    pub(crate) fn noted(self) -> Self {
        impact_io::note(&self.text());
        self
    }
}

/// The channel read as g when neither the options, the scene file nor its header (`column`)
/// named a unit; none for an enDAQ `.ide`, whose channels are in g by the recorder's
/// calibration.
fn assumed_units(args: &AnalyzeArgs, file: &SceneFile, column: &str) -> Option<Assumption> {
    let stated = args.units.or(file.units).is_some() || Units::of_header(column).is_some();
    // (The format sniffed only when no unit was stated: it reads the file's first bytes.)
    let ide = || {
        matches!(
            impact_io::Format::of(&args.file, args.raw_type),
            impact_io::Format::Ide
        )
    };
    (!stated && !ide()).then(|| Assumption::Units {
        column: column.to_string(),
    })
}

/// A time column (`column`) read in seconds, its header naming no unit and none given.
pub fn assumed_time_unit(column: &str) -> Assumption {
    Assumption::TimeUnit {
        column: column.to_string(),
    }
    .noted()
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
) -> Result<Resolved, PipelineError> {
    let mut scene = Scene::new(calibration, trigger as f32);
    scene.edge_m_s2 = edge as f32;
    if let Some(c) = clipping {
        let gain = calibration.gain_m_s2_per_count as f64;
        scene.clip_counts = (
            c.low_m_s2.map_or(i16::MIN, |v| to_count(v, gain)),
            c.high_m_s2.map_or(i16::MAX, |v| to_count(v, gain)),
        );
    }
    check_times(args, file, f64::from(scene.max_impact_s))?;
    check_edge(args, file, trigger, edge, mass)?;
    scene.hold_s = args.hold.or(file.hold).unwrap_or(DEFAULT_HOLD_S) as f32;
    if let Some(m) = args.max_impact.or(file.max_impact) {
        scene.max_impact_s = m as f32;
    }
    scene.settle_s = match args.settle.or(file.settle) {
        Some(s) => s as f32,
        None => scene.settle_s.max(scene.hold_s),
    };
    scene.mass_kg = mass.map(|m| m as f32);
    scene.cfc = match args.cfc.or(file.cfc) {
        Some(c) => Some(Cfc::from_class(c).ok_or_else(|| PipelineError::Cfc {
            setting: name_of(args, file, "cfc"),
            class: c,
        })?),
        None => None,
    };
    // `--lowpass` on the command line overrides a scene file's `cfc` (clap refuses it with
    // `--cfc`).
    if let Some(l) = args.lowpass {
        scene.cfc = None;
        let lowpass = Lowpass::new(l.order, l.cutoff_hz as f32).map_err(PipelineError::Core)?;
        let rate = calibration.sample_rate_hz;
        if lowpass.check(rate).is_err() {
            let (cutoff_hz, rate_hz) = (shortest(lowpass.cutoff_hz), shortest(rate));
            return Err(if f64::from(lowpass.cutoff_hz) >= f64::from(rate) / 2.0 {
                PipelineError::LowpassAboveNyquist { cutoff_hz, rate_hz }
            } else {
                PipelineError::LowpassTooLow { cutoff_hz, rate_hz }
            });
        }
        scene.lowpass = Some(lowpass);
    }
    scene.trigger_cfc = match args.trigger_cfc {
        Some(c) => Some(Cfc::from_class(c).ok_or(PipelineError::Cfc {
            setting: Setting::Option("trigger-cfc"),
            class: c,
        })?),
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
    if let Some(g) = args.train.gravity.or(file.gravity) {
        scene.gravity_m_s2 = g as f32;
    }
    // A free fall is a drop: vertical (`Scene::contact_gravity_m_s2` has the rule).
    scene.vertical =
        args.train.vertical || file.vertical.unwrap_or(false) || args.free_fall.is_some();
    scene.train = args.train.train();
    scene.v0_every = args.v0_every || file.v0_every.unwrap_or(false);
    scene.target = target(args, file)?;
    args.spectrum
        .check()
        .map_err(|setting| PipelineError::Invalid {
            setting,
            reason: "a shock spectrum's setting without the spectra: add --srs",
        })?;
    scene.spectrum = args.spectrum.settings();
    scene.spec = args.spec.map(|s| s.spec);
    scene.validate().map_err(|e| match e {
        // Named as it was given: an option, or the scene file's key.
        impact_core::Error::InvalidParameter { name, reason } => PipelineError::Invalid {
            setting: name_of(args, file, name),
            reason,
        },
        e => PipelineError::Core(e),
    })?;
    Ok(Resolved {
        scene,
        v0_source: source,
        spec_standard: args.spec.map(|s| s.standard),
        capture_len: capture_len(args),
    })
}

/// The target. The command line's, if it gives one, over the scene file's: `--target`'s
/// state space, else the spring–mass of `--target-mass` (its spring and damper the command
/// line's, else the file's); else the scene file's, its state space (`target`) or its
/// spring–mass (`target_mass`, both in one file refused). A spring or damper without a mass is
/// refused.
fn target(
    args: &AnalyzeArgs,
    file: &SceneFile,
) -> Result<Option<impact_core::two_body::SceneTarget>, PipelineError> {
    use impact_core::two_body::{SceneTarget, SpringMass};
    let space = |t: impact_core::two_body::Target<f64>| {
        Some(SceneTarget::StateSpace(
            crate::simulate::two_body::interned(crate::simulate::two_body::narrow(&t)),
        ))
    };
    let target_error = |e| PipelineError::Target(Box::new(e));
    let spring_mass = |m: f64, k2: Option<f64>, c2: Option<f64>| {
        Some(SceneTarget::SpringMass(SpringMass {
            mass_kg: m as f32,
            stiffness_n_m: k2.unwrap_or(0.0) as f32,
            damping_n_s_m: c2.unwrap_or(0.0) as f32,
        }))
    };
    let (k2, c2) = (
        args.target_stiffness.or(file.target_stiffness),
        args.target_damping.or(file.target_damping),
    );
    let file_spring_mass = file.target_mass.is_some()
        || file.target_stiffness.is_some()
        || file.target_damping.is_some();
    let file_space = args.scene.as_deref().zip(file.target.as_ref());
    if let Some((scene, _)) = file_space.filter(|_| file_spring_mass) {
        return Err(PipelineError::Invalid {
            setting: Setting::SceneKey {
                scene: scene.to_path_buf(),
                name: "target",
            },
            reason: "a state-space target, and a spring–mass too (target_mass, target_stiffness, target_damping): give one target",
        });
    }
    Ok(match (&args.target, args.target_mass, file_space) {
        // The command line's state space over any of the scene file's.
        (Some(path), _, _) => {
            space(crate::simulate::two_body::read_state_space(path).map_err(target_error)?)
        }
        // The command line's spring–mass over the file's state space.
        (None, Some(m), Some(_)) => spring_mass(m, args.target_stiffness, args.target_damping),
        (None, None, Some((scene, value))) if k2.is_none() && c2.is_none() => {
            space(crate::simulate::two_body::scene_state_space(scene, value).map_err(target_error)?)
        }
        (None, m, _) => match (m.or(file.target_mass), k2.is_some() || c2.is_some()) {
            (Some(m), _) => spring_mass(m, k2, c2),
            // (A spring or damper given without a mass on either.)
            (None, true) => {
                let name = if k2.is_some() {
                    "target-stiffness"
                } else {
                    "target-damping"
                };
                return Err(PipelineError::Invalid {
                    setting: name_of(args, file, name),
                    reason:
                        "needs the target's mass (--target-mass, or a scene file's target_mass)",
                });
            }
            (None, false) => None,
        },
    })
}

/// The quiet time that ends an impact when none is given, s.
const DEFAULT_HOLD_S: f64 = 2e-3;

/// How messages name the core's parameter `name` (`hold`, `max-impact`): the scene file's
/// key if the file gives it and the command line does not, else the option.
fn name_of(args: &AnalyzeArgs, file: &SceneFile, name: &'static str) -> Setting {
    // (On the command line, and in the file.)
    let (cli, in_file) = match name {
        "mass" => (args.mass.is_some(), file.mass.is_some()),
        "v0" => (args.v0.is_some(), file.v0.is_some()),
        "drop-height" => (args.drop_height.is_some(), file.drop_height.is_some()),
        "trigger" => (args.trigger.is_some(), file.trigger.is_some()),
        "edge" => (args.edge.is_some(), file.edge.is_some()),
        "hold" => (args.hold.is_some(), file.hold.is_some()),
        "max-impact" => (args.max_impact.is_some(), file.max_impact.is_some()),
        "settle" => (args.settle.is_some(), file.settle.is_some()),
        "cfc" => (args.cfc.is_some(), file.cfc.is_some()),
        "lowpass" => (args.lowpass.is_some(), false),
        "target-mass" => (args.target_mass.is_some(), file.target_mass.is_some()),
        "target-stiffness" => (
            args.target_stiffness.is_some(),
            file.target_stiffness.is_some(),
        ),
        "target-damping" => (args.target_damping.is_some(), file.target_damping.is_some()),
        "target" => (args.target.is_some(), file.target.is_some()),
        // Only the scene file sets the exponent.
        "exponent" => (false, true),
        _ => (true, false),
    };
    options::setting_name(args, cli, in_file, name).unwrap_or(Setting::Option(name))
}

/// One of the times given (or its default), s, and how messages name it: `--hold 0.5`,
/// `scene.json: max_impact 1e-9`, `the default --hold, 0.002 s`; and whether it was given.
fn time_given(
    args: &AnalyzeArgs,
    file: &SceneFile,
    name: &'static str,
    (cli, in_file): (Option<f64>, Option<f64>),
    default: f64,
) -> (f64, TimeGiven, bool) {
    match cli.or(in_file) {
        Some(v) => (
            v,
            TimeGiven::Given {
                setting: name_of(args, file, name),
                value_s: v,
            },
            true,
        ),
        None => (
            default,
            TimeGiven::Default {
                name,
                value_s: default,
            },
            false,
        ),
    }
}

/// The hold at most the longest impact (`default_longest_s` if none is given), the settling
/// time at least the hold: an error names the time given that breaks it (and the other,
/// given or its default).
fn check_times(
    args: &AnalyzeArgs,
    file: &SceneFile,
    default_longest_s: f64,
) -> Result<(), PipelineError> {
    let (hold, hold_name, hold_given) =
        time_given(args, file, "hold", (args.hold, file.hold), DEFAULT_HOLD_S);
    let (longest, longest_name, longest_given) = time_given(
        args,
        file,
        "max-impact",
        (args.max_impact, file.max_impact),
        default_longest_s,
    );
    if hold > longest {
        return Err(if longest_given || !hold_given {
            PipelineError::LongestUnderHold {
                longest: longest_name,
                hold: hold_name,
            }
        } else {
            PipelineError::HoldOverLongest {
                hold: hold_name,
                longest: longest_name,
            }
        });
    }
    if let Some(settle) = args.settle.or(file.settle) {
        if settle < hold {
            return Err(PipelineError::SettleUnderHold {
                setting: name_of(args, file, "settle"),
                settle_s: settle,
                hold: hold_name,
            });
        }
    }
    Ok(())
}

/// An edge level given below the trigger level (given, or learned from the signal).
fn check_edge(
    args: &AnalyzeArgs,
    file: &SceneFile,
    trigger: f64,
    edge: f64,
    mass: Option<f64>,
) -> Result<(), PipelineError> {
    let Some(level) = args.edge.or(file.edge) else {
        return Ok(());
    };
    if (edge as f32) < (trigger as f32) {
        return Ok(());
    }
    let trigger_given = match (args.trigger, file.trigger) {
        (Some(t), _) => TriggerGiven::Option(t),
        (None, Some(t)) => TriggerGiven::SceneFile(t),
        (None, None) => TriggerGiven::Learned,
    };
    Err(PipelineError::EdgeNotBelowTrigger {
        setting: name_of(args, file, "edge"),
        level: options::LevelAsGiven { level, mass },
        trigger: trigger_given,
        trigger_m_s2: trigger,
    })
}

/// The core's monitor fed blocks of counts: the one analysis loop of every way of reading a
/// recording (whole, in passes, a stream). Big (the capture buffers are inline): build it
/// on a thread with a big stack ([`crate::on_big_stack`]).
pub struct MonitorRun {
    monitor: HostMonitor,
    reports: Vec<ImpactReport>,
    samples: u64,
}

impl MonitorRun {
    /// With captures of `capture_len` samples (at most the host monitor's).
    pub fn new(scene: Scene, capture_len: usize) -> Result<Self, PipelineError> {
        let mut monitor = HostMonitor::unconfigured();
        monitor
            .configure_with_capture(scene, capture_len)
            .map_err(PipelineError::Monitor)?;
        Ok(Self {
            monitor,
            reports: Vec::new(),
            samples: 0,
        })
    }

    /// The next counts, in the board's blocks (any split gives the same reports).
    pub fn push(&mut self, counts: &[i16]) {
        let reports = &mut self.reports;
        for block in counts.chunks(impact_core::board::BLOCK_LEN) {
            self.monitor
                .push_block(block, &mut |r: &ImpactReport| reports.push(*r));
        }
        self.samples += counts.len() as u64;
    }

    /// The stream has ended: the reports and the samples seen. A signal that never gave a
    /// baseline has no impacts, as on the board (`impact emulate` on the same file): a note
    /// says why.
    pub fn finish(mut self) -> Result<(Vec<ImpactReport>, u64), PipelineError> {
        let reports = &mut self.reports;
        self.monitor
            .finish(&mut |r: &ImpactReport| reports.push(*r));
        if !self.monitor.is_armed() {
            impact_io::note("the signal never settled to a baseline (no quiet stretch of 64 samples within the edge level), so no impact could be detected: give a larger --edge if it is noisy");
        }
        Ok((self.reports, self.samples))
    }
}

/// Analyses the counts of a whole recording.
pub fn run(
    counts: &[i16],
    scene: &Scene,
    capture_len: usize,
) -> Result<Vec<ImpactReport>, PipelineError> {
    let scene = *scene;
    let counts = counts.to_vec();
    crate::on_big_stack(move || {
        let mut run = MonitorRun::new(scene, capture_len)?;
        run.push(&counts);
        run.finish().map(|(reports, _)| reports)
    })
}

/// The report JSON.
pub fn to_json(setup: &Setup, reports: &[ImpactReport]) -> AnalysisJson {
    let mut a = AnalysisJson {
        lines_dropped: 0,
        lines_missing: 0,
        column: setup.column.clone(),
        units: Some(setup.units.name().to_string()),
        assumptions: setup.assumptions.iter().map(Assumption::text).collect(),
        units_assumed: setup
            .assumptions
            .iter()
            .any(|x| matches!(x, Assumption::Units { .. })),
        time_unit_assumed: setup
            .assumptions
            .iter()
            .any(|x| matches!(x, Assumption::TimeUnit { .. })),
        samples: setup.samples,
        sample_rate_hz: setup.rate_hz,
        v0_m_s: match setup.scene.approach {
            Approach::Speed { v0_m_s } => Some(shortest(v0_m_s)),
            Approach::DropHeight { height_m } => {
                // Gravity as its decimal digits name it, as `impact log` reads it off the
                // board's scene line.
                Some((2.0 * shortest(setup.scene.gravity_m_s2) * f64::from(height_m)).sqrt())
            }
            _ => None,
        },
        v0_source: setup.v0_source.clone(),
        contact_gravity_m_s2: setup.scene.contact_gravity_m_s2().map(shortest),
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
        spec: setup
            .scene
            .spec
            .as_ref()
            .map(|s| crate::report::spec::spec_json(s, setup.spec_standard)),
        target: setup
            .scene
            .target
            .as_ref()
            .map(crate::report::TargetJson::of),
        lowpass: (setup.scene.lowpass.as_ref()).map(|l| {
            crate::report::filter::LowpassJson::of(l, setup.scene.calibration.sample_rate_hz)
        }),
        trains: Vec::new(),
        waveforms: Vec::new(),
        impacts: reports
            .iter()
            .enumerate()
            .map(|(k, r)| {
                let mut j = impact_json(
                    r,
                    setup.prepared.t0,
                    &setup.scene.fits,
                    setup.scene.contact_gravity_m_s2(),
                    Some(setup.scene.calibration.sample_rate_hz as f64),
                );
                if !setup.axes.is_empty() {
                    let previous_end = k
                        .checked_sub(1)
                        .and_then(|p| reports.get(p))
                        .map_or(0, |p| p.end_sample);
                    let x = crate::pipeline::axes::impact_axes(
                        r,
                        previous_end,
                        &setup.axes,
                        &setup.prepared.accel_m_s2,
                        setup.rate_hz,
                        setup.prepared.t0,
                    );
                    j.clipped |= x.axes.iter().any(|a| a.clipped);
                    // ∫|a| dt is no velocity change: the axes give it, and judge their own
                    // coupling (the resultant's window says nothing about it).
                    j.flags.retain(|f| f != "ac-coupled");
                    j.delta_v_m_s = None;
                    j.null_reasons
                        .insert("delta_v_m_s".into(), "resultant".into());
                    if let (Some(check), Some(spec)) = (&setup.transverse, &setup.scene.spec) {
                        check.judge(&mut j, &x, f64::from(spec.peak_m_s2));
                    }
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
        drifts: Vec::new(),
        skipped_lines: Vec::new(),
    };
    crate::report::separate_drifts(&mut a);
    a.trains = crate::report::train::trains(&a.impacts);
    a.assume_rigid_barrier();
    a
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    #[test]
    fn an_error_said_of_its_recording_drops_the_file_it_begins_with() {
        let file = Path::new("runs/a.csv");
        let few = PipelineError::TooFewSamples {
            path: file.to_path_buf(),
            column: "x_g".into(),
            samples: 1,
        };
        assert_eq!(few.to_string(), "runs/a.csv: x_g: 1 samples; at least 2");
        assert_eq!(
            few.of_recording(file).to_string(),
            "x_g: 1 samples; at least 2"
        );
        // Another file's error, and an error at a line, keep their file.
        assert_eq!(
            few.of_recording(Path::new("b.csv")).to_string(),
            few.to_string()
        );
        let read = |at| {
            PipelineError::Read(
                impact_io::ReadError {
                    path: file.to_path_buf(),
                    at,
                    kind: impact_io::ReadErrorKind::OneSample,
                }
                .into(),
            )
        };
        assert_eq!(
            read(None).of_recording(file).to_string(),
            "one sample: the rate cannot be told; give --rate"
        );
        let at_line = read(Some(impact_io::At::Line(3)));
        assert_eq!(at_line.of_recording(file).to_string(), at_line.to_string());
        assert!(at_line.to_string().starts_with("runs/a.csv:3: "));
    }

    /// The edge level's rule for a vertical scene is the scene's own, for every way a scene
    /// becomes vertical (or not), from the command line and from a scene file.
    #[test]
    fn the_edge_levels_vertical_is_the_scenes() {
        use clap::Parser;
        #[derive(Parser)]
        struct Wrap {
            #[command(flatten)]
            analyze: AnalyzeArgs,
        }
        let calibration = Calibration {
            gain_m_s2_per_count: 0.1,
            sample_rate_hz: 1e5,
        };
        let cases: [(&[&str], &str); 10] = [
            (&[], "{}"),
            (&["--v0", "1"], "{}"),
            (&["--vertical", "--v0", "1"], "{}"),
            (&["--drop-height", "0.1"], "{}"),
            (&["--train", "flight", "--v0", "1"], "{}"),
            (&[], r#"{"drop_height": 0.1}"#),
            (&[], r#"{"v0": 1.0, "drop_height": 0.1}"#),
            (&["--v0", "1"], r#"{"drop_height": 0.1}"#),
            (&[], r#"{"vertical": true}"#),
            (&["--free-fall", "release.csv"], "{}"),
        ];
        for (options, json) in cases {
            let argv = ["analyze", "x.csv"].iter().chain(options).copied();
            let args = Wrap::try_parse_from(argv).unwrap().analyze;
            let file: SceneFile = serde_json::from_str(json).unwrap();
            let scene = build_scene(&args, &file, calibration, 10.0, 2.0, None, Some(0.06))
                .unwrap()
                .scene;
            assert_eq!(
                vertical(&args, &file),
                scene.contact_gravity_m_s2().is_some(),
                "{options:?} with {json}"
            );
        }
    }
}
