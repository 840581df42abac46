//! Recordings read a block at a time, in memory that does not grow with their length (an
//! hour at 500 kS/s is 3.6 GB of i16, ~60 GB of CSV): a CSV, WAV, .npy, TDMS or raw
//! (`.i16`/`.f32`) file, or (CSV, raw) standard input.
//!
//! - `impact analyze FILE` on a regular file or standard input ([`analyze_in_passes`]): a
//!   survey of the whole recording ([`crate::pipeline::survey`]), then the analysis; the whole-file
//!   path's reports. A CSV's or standard input's values are kept from the first pass for the
//!   later ones in a temporary file ([`impact_io::spool`]), so a CSV is parsed once.
//! - `impact analyze --stream` ([`analyze`]): one pass, with what needs the whole signal given
//!   (`--range`, `--trigger`) or refused (spike screening is not done; figures, axes, free fall,
//!   resampling); with the same levels, the same reports (tested).
//!
//! The per-sample arithmetic (units, gain, quantisation) is the whole-file path's. A reader
//! thread reads ahead of the survey or the monitor; a CSV file's plain rows past the head are
//! parsed in parallel ([`impact_io::csv_fast`]).

use impact_core::{Calibration, ImpactReport};

use crate::pipeline::screen::Removal;
use crate::pipeline::survey::{self, Survey, Surveyed};
use std::sync::Arc;

use crate::pipeline::{self, AnalyzeArgs, MonitorRun, PipelineError, Reading, Setup};
use crate::read_errors::ReadFailure;
use impact_io::channel::{input_name, reads_once};
use impact_io::error::SpoolError;
use impact_io::open_source;
use impact_io::progress::Progress;
use impact_io::quantise::Quantiser;
use impact_io::sources::{read_head, Source, CHUNK};
use impact_io::spool::{Axis, SpoolWriter};

/// Reads and analyses `args.file` as a stream; the setup (without samples) and the reports.
/// `progress` (a CSV's fraction read) for a bar on a terminal.
pub fn analyze(
    args: &AnalyzeArgs,
    progress: Progress,
) -> Result<(Setup, Vec<ImpactReport>), PipelineError> {
    let refuse = |option| Err(PipelineError::StreamNeedsWhole { option });
    if args.plot.is_some() {
        return refuse("--plot");
    }
    if !args.axes.is_empty() {
        return refuse("--axes");
    }
    if args.free_fall.is_some() {
        return refuse("--free-fall");
    }
    if args.resample {
        return refuse("--resample");
    }
    let file = pipeline::scene_file(args)?;
    let mut source =
        open_source(&args.file, &args.read_options(progress)).map_err(ReadFailure::from)?;
    let column = source.column().to_string();
    let (mass, scale, units, assumed) = pipeline::mass_and_scale(args, &file, &column)?;
    let full_scale =
        pipeline::full_scale_m_s2(args, &file, mass).ok_or(PipelineError::StreamNeedsRange)?;
    let (trigger, edge) = pipeline::given_levels(args, &file, mass);
    let trigger = trigger.ok_or(PipelineError::StreamNeedsTrigger)?;
    let gain = impact_io::quantise::gain_for(full_scale);
    let clipping = crate::pipeline::screen::from_range(full_scale);
    // The head: its noise sets the default edge level, a CSV's first intervals the rate; its
    // readings are checked against the range.
    let head = read_head(&mut *source, scale).map_err(ReadFailure::from)?;
    survey::check_range(head.iter().fold(0.0f64, |m, v| m.max(v.abs())), full_scale)?;
    let rate_hz = source.rate_hz().map_err(ReadFailure::from)?;
    let calibration = Calibration {
        gain_m_s2_per_count: gain as f32,
        sample_rate_hz: rate_hz as f32,
    };
    // (A vertical scene's edge level takes the head's quantum: its noise may read as none.)
    let quantum = pipeline::vertical(args, &file)
        .then(|| survey::Survey::of(&head, false).map_or(0.0, |s| s.resolution_m_s2));
    let edge =
        edge.unwrap_or_else(|| survey::default_edge(survey::noise_rms(&head), trigger, quantum));
    let resolved = pipeline::build_scene(
        args,
        &file,
        calibration,
        trigger,
        edge,
        Some(&clipping),
        mass,
    )?;
    let q = Quantiser { scale, gain };
    let run = run_monitor(source, q.counts_m_s2(&head), q, &resolved, Vec::new())?;
    let reading = Reading {
        column,
        units,
        t0: run.source.t0(),
        samples: run.samples,
        rate_hz: run.source.final_rate_hz(),
    };
    let time_assumed = run
        .source
        .time_unit_assumed()
        .as_deref()
        .map(pipeline::assumed_time_unit);
    let mut setup = Setup::new(reading, resolved);
    setup.assumptions.extend(assumed);
    setup.assumptions.extend(time_assumed);
    setup.clipping = Some(clipping);
    Ok((setup, run.reports))
}

/// Reads and analyses a regular file or standard input in passes, in memory that does not
/// grow with its length, with the whole-file path's rules: a survey of the whole recording
/// (its median, noise, extremes, flat tops and glitches, [`Survey`]), a second one if
/// glitches were removed, then the analysis. The later passes read the first's values back
/// from a spool ([`impact_io::spool`]: a CSV, standard input) or the file again. The same code
/// as the whole-file path on the same values, so the same reports (tested); only the time
/// axis is checked against the first intervals' median, as in a stream (the whole-file path
/// takes the median of all of them).
pub fn analyze_in_passes(
    args: &AnalyzeArgs,
    progress: Progress,
) -> Result<(Setup, Vec<ImpactReport>), PipelineError> {
    in_passes_then(args, progress, Last::Analyse)
}

/// The recording's counts (little-endian i16, as the board's ADC gives them to the stream),
/// written to `out` in a last pass after the survey, in bounded memory: what `impact emulate`
/// replays. The setup says how many (`samples`).
pub fn counts_file(
    args: &AnalyzeArgs,
    out: &mut dyn std::io::Write,
) -> Result<Setup, PipelineError> {
    in_passes_then(args, Progress::none(), Last::Counts(out)).map(|(setup, _)| setup)
}

/// What the last pass does: analyse, or write the counts.
enum Last<'a> {
    Analyse,
    Counts(&'a mut dyn std::io::Write),
}

fn in_passes_then(
    args: &AnalyzeArgs,
    progress: Progress,
    last: Last,
) -> Result<(Setup, Vec<ImpactReport>), PipelineError> {
    let name = input_name(&args.file);
    let file = pipeline::scene_file(args)?;
    // The survey; again with the glitches replaced if there are any (they set the extremes).
    // One bar over the passes: the survey fills its first half, a second survey (if any)
    // the next sixth, the analysis the rest.
    let bar = |from: f64, to: f64| progress.span(from, to);
    // (The spool first: standard input without one is refused before it is read.)
    let spool = Spooling::for_input(args, &name)?;
    let input =
        open_source(&args.file, &args.read_options(bar(0.0, 0.5))).map_err(ReadFailure::from)?;
    let column = input.column().to_string();
    let (mass, scale, units, assumed) = pipeline::mass_and_scale(args, &file, &column)?;
    let full_scale = pipeline::full_scale_m_s2(args, &file, mass);
    let SurveyPass {
        survey: first,
        source,
        spool,
    } = survey_pass(input, scale, &[], !args.keep_spikes, spool)?;
    let time_unit_assumed = source.time_unit_assumed();
    let axis = Axis {
        rate_hz: source.rate_hz().map_err(ReadFailure::from)?,
        final_rate_hz: source.final_rate_hz(),
        t0_s: source.t0(),
    };
    let (t0, rate_hz) = (axis.t0_s, axis.final_rate_hz);
    if first.samples < 2 {
        return Err(PipelineError::TooFewSamples {
            path: args.file.clone(),
            column,
            samples: first.samples,
        });
    }
    drop(source);
    // The later passes read the spool if there is one; a file whose spool failed (a full
    // disk) is read again (standard input's failure ended its pass).
    let spool = match spool {
        Some(Ok(writer)) => Some(writer.finish(&args.file, axis)),
        Some(Err(e)) => {
            crate::errln!("note: {e}: {name} is read again");
            None
        }
        None => None,
    };
    let reopen = |progress: Progress| match &spool {
        Some(s) => Ok((s.source(progress).map_err(ReadFailure::from)?, 1.0)),
        None => Ok::<_, PipelineError>((
            open_source(&args.file, &args.read_options(progress)).map_err(ReadFailure::from)?,
            scale,
        )),
    };
    let removals = first.removals.clone();
    let survey = if removals.is_empty() {
        first
    } else {
        let (input, scale) = reopen(bar(0.5, 2.0 / 3.0))?;
        survey_pass(input, scale, &removals, false, None)?.survey
    };
    let (trigger, edge) = pipeline::given_levels(args, &file, mass);
    let levels = survey::levels(
        &survey,
        full_scale,
        trigger,
        edge,
        pipeline::vertical(args, &file),
    )?;
    let gain = levels.gain_m_s2_per_count;
    let calibration = Calibration {
        gain_m_s2_per_count: gain as f32,
        sample_rate_hz: rate_hz as f32,
    };
    let resolved = pipeline::build_scene(
        args,
        &file,
        calibration,
        levels.trigger_m_s2,
        levels.edge_m_s2,
        levels.clipping.as_ref(),
        mass,
    )?;
    let from = if removals.is_empty() { 0.5 } else { 2.0 / 3.0 };
    let (source, scale) = reopen(bar(from, 1.0))?;
    let q = Quantiser { scale, gain };
    let (source, head) = head_counts(source, q)?;
    let (reports, samples) = match last {
        Last::Analyse => {
            let run = run_monitor(source, head, q, &resolved, removals.clone())?;
            (run.reports, run.samples)
        }
        Last::Counts(out) => (
            Vec::new(),
            write_counts(source, head, q, removals.clone(), out)?,
        ),
    };
    // The figure's windows: a last pass keeps just them (memory bounded by the impacts
    // drawn, not the recording).
    let windows = match &args.plot {
        Some(_) => {
            let (source, scale) = reopen(Progress::none())?;
            let spans = figure_spans(&reports, &resolved.scene);
            let q = Quantiser { scale, gain };
            let (source, head) = head_counts(source, q)?;
            collect_windows(source, head, q, removals.clone(), spans)?
        }
        None => Vec::new(),
    };
    let spikes = removals.iter().map(|r| r.timed(t0, rate_hz)).collect();
    let reading = Reading {
        column,
        units,
        t0,
        samples,
        rate_hz,
    };
    let time_assumed = time_unit_assumed
        .as_deref()
        .map(pipeline::assumed_time_unit);
    let mut setup = Setup::new(reading, resolved);
    setup.assumptions.extend(assumed);
    setup.assumptions.extend(time_assumed);
    setup.spikes = spikes;
    setup.clipping = levels.clipping;
    setup.windows = windows;
    Ok((setup, reports))
}

/// The spans `(first sample, samples)` of the impacts a figure draws (with the scene's
/// filter padding).
fn figure_spans(reports: &[ImpactReport], scene: &impact_core::Scene) -> Vec<(u64, u64)> {
    let rate = f64::from(scene.calibration.sample_rate_hz);
    let padding = u64::from(scene.padding_samples());
    reports
        .iter()
        .take(crate::plot::SHOWN)
        .map(|r| crate::plot::read_window(r, rate, padding))
        .collect()
}

/// The head of `source` (its values at `q`'s scale, in m/s²: what [`read_head`] reads) in
/// counts.
fn head_counts(
    mut source: Box<dyn Source>,
    q: Quantiser,
) -> Result<(Box<dyn Source>, Vec<i16>), PipelineError> {
    let head = read_head(&mut *source, q.scale).map_err(ReadFailure::from)?;
    Ok((source, q.counts_m_s2(&head)))
}

/// Whether `impact analyze` reads `args.file` in passes ([`analyze_in_passes`]): a regular
/// file, or an input read once (standard input, a FIFO, a device: from a spool), without the options that need the whole recording in memory
/// (axes, free fall, resampling; a figure takes its windows in a last pass).
pub fn in_passes(args: &AnalyzeArgs) -> bool {
    // (`IMPACT_READ_WHOLE` set: read whole, for the tests that compare the two ways.)
    !args.stream
        && std::env::var_os("IMPACT_READ_WHOLE").is_none()
        && (reads_once(&args.file) || std::fs::metadata(&args.file).is_ok_and(|m| m.is_file()))
        && args.axes.is_empty()
        && args.free_fall.is_none()
        && !args.resample
}

/// One survey of `source` (values × `scale`, the `removals` put in); the source read, and
/// the `spool` with the values surveyed written (the first pass's, with no removals).
fn survey_pass(
    mut source: Box<dyn Source>,
    scale: f64,
    removals: &[Removal],
    screen: bool,
    spool: Option<Spooling>,
) -> Result<SurveyPass, PipelineError> {
    let mut survey = Survey::new(screen);
    // The shape's two scans on threads of their own (a copy of each block to each, as
    // read); with a spool, which a CSV's parse or standard input comes with, both on one
    // thread with the spool (the parse keeps both cores busy: a third thread only costs).
    // A spool that fails is dropped at once (its space freed); one that must not fail ends
    // the pass.
    let stops = spool.as_ref().is_some_and(|s| s.stops);
    let input = spool.as_ref().map(|s| s.input.clone()).unwrap_or_default();
    let spool_failed = |error: &Arc<SpoolError>| PipelineError::Spool {
        input: input.clone(),
        error: Arc::clone(error),
    };
    let spool = spool.map(|s| Ok(s.writer));
    let failure = Arc::new(std::sync::OnceLock::<Arc<SpoolError>>::new());
    let (flat, spikes) = survey.take_shape().split();
    let (with_flat, spikes) = match spool {
        Some(_) => (spikes, None),
        None => (None, spikes),
    };
    let flat = Scan::spawn((flat, with_flat, spool), {
        let failure = std::sync::Arc::clone(&failure);
        move |(flat, spikes, spool), block| {
            if let Some(Ok(w)) = spool {
                if let Err(e) = w.write(block).map_err(Arc::new) {
                    let _ = failure.set(Arc::clone(&e));
                    *spool = Some(Err(e));
                }
            }
            flat.push(block);
            if let Some(s) = spikes {
                s.push(block);
            }
        }
    });
    let spikes = spikes.map(|s| Scan::spawn(s, |s, block| s.push(block)));
    let mut patch = Patches::new(removals);
    // Each block, the head first: the removals put in, surveyed here and sent to the scans.
    let mut take = |block: &mut [f64]| {
        if let (true, Some(e)) = (stops, failure.get()) {
            return Err(spool_failed(e));
        }
        patch.values(block);
        survey.push_levels(block);
        flat.send(block);
        if let Some(s) = &spikes {
            s.send(block);
        }
        Ok(())
    };
    let read = read_head(&mut *source, scale)
        .map_err(|e| PipelineError::Read(e.into()))
        .and_then(|mut head| {
            take(&mut head)?;
            read_ahead(
                source,
                move |s, _, out: &mut Vec<f64>| {
                    s.next_values(CHUNK, out).map_err(ReadFailure::from)?;
                    out.iter_mut().for_each(|v| *v *= scale);
                    Ok(())
                },
                take,
            )
        });
    let (flat, with_flat, spool) = flat.finish()?;
    let spikes = spikes.map(Scan::finish).transpose()?.or(with_flat);
    let source = read?;
    if let (true, Some(Err(e))) = (stops, &spool) {
        return Err(spool_failed(e));
    }
    survey.put_shape(crate::pipeline::survey::Shape::join(flat, spikes));
    Ok(SurveyPass {
        survey: survey.finish()?,
        source,
        spool,
    })
}

/// A scan on a thread of its own, given a copy of each block in order (the copies go back to
/// be filled again; a few in flight).
struct Scan<S> {
    blocks: std::sync::mpsc::SyncSender<Vec<f64>>,
    spare: std::sync::mpsc::Receiver<Vec<f64>>,
    thread: std::thread::JoinHandle<(S, impact_io::WorkerNotes)>,
}

impl<S: Send + 'static> Scan<S> {
    fn spawn(mut state: S, mut push: impl FnMut(&mut S, &[f64]) + Send + 'static) -> Self {
        let (blocks, rx) = std::sync::mpsc::sync_channel::<Vec<f64>>(4);
        let (back, spare) = std::sync::mpsc::channel::<Vec<f64>>();
        let scope = impact_io::NoteScope::here();
        let thread = std::thread::spawn(move || {
            scope.run(|| {
                for block in rx {
                    push(&mut state, &block);
                    let _ = back.send(block);
                }
                state
            })
        });
        Self {
            blocks,
            spare,
            thread,
        }
    }

    fn send(&self, block: &[f64]) {
        let mut copy = self.spare.try_recv().unwrap_or_default();
        copy.clear();
        copy.extend_from_slice(block);
        let _ = self.blocks.send(copy);
    }

    /// The scan's state once it has every block sent.
    fn finish(self) -> Result<S, PipelineError> {
        drop(self.blocks);
        let (state, notes) = self
            .thread
            .join()
            .map_err(|_| PipelineError::SurveyPanicked)?;
        notes.keep();
        Ok(state)
    }
}

/// A spool for a first pass to write, and whether its failure ends the pass (standard
/// input, which cannot be read again).
struct Spooling {
    writer: SpoolWriter,
    stops: bool,
    /// The input, as messages name it (`stdin`, or its path).
    input: String,
}

impl Spooling {
    /// The spool `args.file` (named `name`) is read into, if it gets one ([`spooled`]): a
    /// spool that cannot be made is an error for standard input (read once), a note for a
    /// file (read again for each pass).
    fn for_input(args: &AnalyzeArgs, name: &str) -> Result<Option<Self>, PipelineError> {
        let stdin = reads_once(&args.file);
        match spooled(args).then(SpoolWriter::new).transpose() {
            Err(e) if stdin => Err(PipelineError::Spool {
                input: name.to_string(),
                error: Arc::new(e),
            }),
            Err(e) => {
                crate::errln!("note: {e}: {name} is read again for each pass");
                Ok(None)
            }
            Ok(writer) => Ok(writer.map(|writer| Spooling {
                writer,
                stops: stdin,
                input: name.to_string(),
            })),
        }
    }
}

/// What [`survey_pass`] gives: the survey, the source read and the spool written (or why
/// it failed).
struct SurveyPass {
    survey: Surveyed,
    source: Box<dyn Source>,
    spool: Option<Result<SpoolWriter, Arc<SpoolError>>>,
}

/// Whether the first pass keeps the values for the later ones ([`impact_io::spool`]): standard
/// input (read once) and a CSV file (its parse costs more than reading the spool).
fn spooled(args: &AnalyzeArgs) -> bool {
    reads_once(&args.file)
        || impact_io::Format::of(&args.file, args.raw_type) == impact_io::Format::Csv
}

/// Runs `fill` on a reader thread a few chunks ahead of `take` (so memory stays bounded),
/// until `fill` gives nothing; the source back, or the first error (of either).
fn read_ahead<T: Send + 'static>(
    mut source: Box<dyn Source>,
    fill: impl Fn(&mut dyn Source, &mut Vec<f64>, &mut Vec<T>) -> Result<(), PipelineError>
        + Send
        + 'static,
    mut take: impl FnMut(&mut [T]) -> Result<(), PipelineError>,
) -> Result<Box<dyn Source>, PipelineError> {
    let (tx, rx) = std::sync::mpsc::sync_channel::<Result<Vec<T>, PipelineError>>(4);
    let (back, spare) = std::sync::mpsc::channel::<Vec<T>>();
    // The reader's notes (a channel chosen, a row skipped) go where the caller's go.
    let scope = impact_io::NoteScope::here();
    let reader = std::thread::spawn(move || {
        scope.run(|| {
            let mut scratch = Vec::with_capacity(CHUNK);
            loop {
                let mut chunk = spare.try_recv().unwrap_or_default();
                chunk.clear();
                if let Err(e) = fill(&mut *source, &mut scratch, &mut chunk) {
                    let _ = tx.send(Err(e));
                    break;
                }
                if chunk.is_empty() || tx.send(Ok(chunk)).is_err() {
                    break;
                }
            }
            source
        })
    });
    let mut failed = None;
    for chunk in rx.iter() {
        match chunk {
            Ok(mut c) => {
                if let Err(e) = take(&mut c) {
                    failed = Some(e);
                    break;
                }
                let _ = back.send(c);
            }
            Err(e) => {
                failed = Some(e);
                break;
            }
        }
    }
    drop(rx);
    let (source, notes) = reader.join().map_err(|_| PipelineError::ReaderPanicked)?;
    notes.keep();
    match failed {
        Some(e) => Err(e),
        None => Ok(source),
    }
}

/// Runs the monitor over the head's counts and the rest of the source (as counts under
/// `q`, the `removals` put in); the reports, the samples read and the source.
fn run_monitor(
    source: Box<dyn Source>,
    head: Vec<i16>,
    q: Quantiser,
    resolved: &pipeline::Resolved,
    removals: Vec<Removal>,
) -> Result<Analysed, PipelineError> {
    let (scene, capture_len) = (resolved.scene, resolved.capture_len);
    crate::on_big_stack(move || {
        let mut run = MonitorRun::new(scene, capture_len)?;
        let source = for_each_count(source, head, q, &removals, |counts| {
            run.push(counts);
            Ok(())
        })?;
        let (reports, samples) = run.finish()?;
        Ok(Analysed {
            reports,
            samples,
            source,
        })
    })
}

/// Writes the head's counts and the rest of the source's (under `q`, the `removals` put
/// in, as the analysis sees them) to `out` as little-endian i16; how many.
fn write_counts(
    source: Box<dyn Source>,
    head: Vec<i16>,
    q: Quantiser,
    removals: Vec<Removal>,
    out: &mut dyn std::io::Write,
) -> Result<u64, PipelineError> {
    let mut count = 0u64;
    let mut bytes = Vec::new();
    for_each_count(source, head, q, &removals, |counts| {
        bytes.clear();
        bytes.extend(counts.iter().flat_map(|c| c.to_le_bytes()));
        out.write_all(&bytes).map_err(PipelineError::Counts)?;
        count += counts.len() as u64;
        Ok(())
    })?;
    out.flush().map_err(PipelineError::Counts)?;
    Ok(count)
}

/// Reads the head's counts and the rest of the source (as counts under `q`, the `removals`
/// put in, as the analysis saw them) and keeps the samples of each span `(first, count)`:
/// the windows a figure draws.
fn collect_windows(
    source: Box<dyn Source>,
    head: Vec<i16>,
    q: Quantiser,
    removals: Vec<Removal>,
    spans: Vec<(u64, u64)>,
) -> Result<Vec<(u64, Vec<i16>)>, PipelineError> {
    let mut windows: Vec<(u64, Vec<i16>)> =
        spans.iter().map(|&(from, _)| (from, Vec::new())).collect();
    let mut at = 0u64;
    for_each_count(source, head, q, &removals, |counts| {
        let end = at + counts.len() as u64;
        for ((from, w), &(_, len)) in windows.iter_mut().zip(&spans) {
            let (a, b) = ((*from).max(at), (*from + len).min(end));
            if a < b {
                w.extend_from_slice(&counts[(a - at) as usize..(b - at) as usize]);
            }
        }
        at = end;
        Ok(())
    })?;
    Ok(windows)
}

/// Hands `take` the head's counts, then the rest of the source's a chunk at a time (as counts
/// under `q`, the `removals` put in: as the analysis sees them); the source.
fn for_each_count(
    source: Box<dyn Source>,
    mut head: Vec<i16>,
    q: Quantiser,
    removals: &[Removal],
    mut take: impl FnMut(&[i16]) -> Result<(), PipelineError>,
) -> Result<Box<dyn Source>, PipelineError> {
    let mut patch = Patches::new(removals);
    let mut patched = |counts: &mut [i16]| {
        patch.counts(counts, q);
        take(counts)
    };
    patched(&mut head)?;
    read_ahead(
        source,
        move |s, scratch, counts| {
            Ok(s.next_counts(CHUNK, q, scratch, counts)
                .map_err(ReadFailure::from)?)
        },
        patched,
    )
}

/// What [`run_monitor`] gives: the reports, the samples read and the source.
struct Analysed {
    reports: Vec<ImpactReport>,
    samples: u64,
    source: Box<dyn Source>,
}

/// Puts removed glitches' straight lines into a stream's blocks as they pass.
struct Patches<'a> {
    removals: &'a [Removal],
    /// The index of the next sample to pass.
    at: u64,
}

impl<'a> Patches<'a> {
    fn new(removals: &'a [Removal]) -> Self {
        Self { removals, at: 0 }
    }

    /// The (removal, sample) pairs in the next `len` samples, as (index in the block, value).
    fn each(&mut self, len: usize, mut f: impl FnMut(usize, f64)) {
        let end = self.at + len as u64;
        while let Some(r) = self.removals.first() {
            let first = r.spike.sample;
            let last = first + u64::from(r.spike.samples);
            if first >= end {
                break;
            }
            for k in first.max(self.at)..last.min(end) {
                f((k - self.at) as usize, r.value((k - first) as usize));
            }
            if last > end {
                break;
            }
            self.removals = &self.removals[1..];
        }
        self.at = end;
    }

    fn values(&mut self, block: &mut [f64]) {
        let len = block.len();
        self.each(len, |i, v| block[i] = v);
    }

    fn counts(&mut self, block: &mut [i16], q: Quantiser) {
        let len = block.len();
        self.each(len, |i, v| block[i] = q.count_m_s2(v));
    }
}
