//! A recorded signal through the same core pipeline the firmware runs: the options and the
//! scene resolved ([`options`], [`build_scene`]), the recording read ([`impact_io`]), surveyed
//! ([`survey`], [`histogram`]) and screened ([`screen`]), quantised to counts, and analysed
//! by the core's monitor; whole, in passes or as a stream ([`streaming`]); the three axes'
//! part ([`axes`]), the free fall ([`free_fall`]) and the spectra's reference ([`spectrum`]).

pub mod axes;
pub mod free_fall;
pub mod histogram;
pub mod level;
pub mod options;
pub mod screen;
pub mod spectrum;
pub mod streaming;
pub mod survey;

use impact_core::consts::STANDARD_GRAVITY;
use impact_core::monitor::Monitor;
use impact_core::signal::cfc::Cfc;
use impact_core::{Approach, Calibration, FitSet, ImpactReport, Scene};

use crate::pipeline::free_fall::free_fall_before;
use crate::report::fmt::shortest;
use crate::report::{impact_json, AnalysisJson, Clipping, Spike, SPIKE_REMOVED};
use impact_io::quantise::to_count;
use impact_io::read_recording;
pub use options::{scene_file, AnalyzeArgs, FitsFile, Level, SceneFile, Units};
use survey::Survey;

/// Analyses a recording: the one entry of the three ways of reading it. A regular file or
/// standard input is read in passes in bounded memory ([`streaming::analyze_in_passes`]),
/// unless an option needs the whole recording in memory (then a large file gets a note of
/// the memory it takes, about 40 bytes a row); `--stream` reads it once with the levels
/// given ([`streaming::analyze`]). The setup (without the samples for the passes and the
/// stream) and the reports.
pub fn analyze(
    args: &AnalyzeArgs,
    progress: Option<fn(f64)>,
) -> Result<(Setup, Vec<ImpactReport>), String> {
    let in_passes = streaming::in_passes(args);
    let size = std::fs::metadata(&args.file).map_or(0, |m| m.len());
    if !args.stream && !in_passes && size > 1 << 30 {
        eprintln!(
            "note: {} is {:.1} GB: read whole (for --plot, --axes, --free-fall or --resample) it takes some {:.0} GB of memory",
            args.file.display(),
            size as f64 / 1e9,
            size as f64 * 2.0 / 1e9
        );
    }
    if args.stream {
        streaming::analyze(args, progress)
    } else if in_passes {
        streaming::analyze_in_passes(args, progress)
    } else {
        let setup = setup(args, progress)?;
        let reports = run(&setup.prepared.counts, &setup.scene)?;
        Ok((setup, reports))
    }
}

/// The host's monitor: a 2^15-sample ring (the flanks reach back 4096 samples, as on the board;
/// the rest is history for a CFC's lead-in: CFC 60's 10 ms up to 3.2 MS/s), a 2^17-sample
/// capture.
pub type HostMonitor = Monitor<32768, 131072>;

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
    pub axes: Vec<crate::pipeline::axes::Axis>,
}

impl Setup {
    /// A setup of `samples` samples at `rate_hz` (the first at `t0`, s) of the channel
    /// `column` in `units`, analysed with `scene`: no counts or signal kept, no glitches
    /// removed, no rails known, no axes, not resampled (a whole-file read fills them in).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        column: String,
        units: Units,
        calibration: Calibration,
        t0: f64,
        scene: Scene,
        v0_source: Option<&str>,
        samples: u64,
        rate_hz: f64,
    ) -> Self {
        Self {
            column: (!column.is_empty()).then_some(column),
            units,
            prepared: Prepared {
                counts: Vec::new(),
                calibration,
                t0,
                accel_m_s2: Vec::new(),
            },
            scene,
            v0_source: v0_source.map(str::to_string),
            free_fall_s: None,
            samples,
            rate_hz,
            spikes: Vec::new(),
            clipping: None,
            resampled: false,
            axes: Vec::new(),
        }
    }

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
    let axes: Vec<crate::pipeline::axes::Axis> = ch
        .axes
        .iter()
        .map(|(name, v)| {
            let a = v.iter().map(|x| x * scale).collect();
            crate::pipeline::axes::Axis::new(name.clone(), a, full_scale)
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
    let mut setup = Setup::new(
        ch.name.clone(),
        units,
        calibration,
        t0,
        scene,
        source,
        ch.values.len() as u64,
        ch.rate_hz,
    );
    setup.prepared.counts = counts;
    setup.prepared.accel_m_s2 = accel;
    setup.spikes = spikes;
    setup.clipping = clipping;
    setup.resampled = ch.resampled;
    setup.axes = axes;
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

/// The core's monitor fed blocks of counts: the one analysis loop of every way of reading a
/// recording (whole, in passes, a stream). Big (the capture buffers are inline): build it
/// on a thread with a big stack ([`crate::on_big_stack`]).
pub struct MonitorRun {
    monitor: HostMonitor,
    reports: Vec<ImpactReport>,
    samples: u64,
}

impl MonitorRun {
    pub fn new(scene: Scene) -> Result<Self, String> {
        Ok(Self {
            monitor: HostMonitor::new(scene).map_err(|e| e.to_string())?,
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
    pub fn finish(mut self) -> Result<(Vec<ImpactReport>, u64), String> {
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
pub fn run(counts: &[i16], scene: &Scene) -> Result<Vec<ImpactReport>, String> {
    let scene = *scene;
    let counts = counts.to_vec();
    crate::on_big_stack(move || {
        let mut run = MonitorRun::new(scene)?;
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
