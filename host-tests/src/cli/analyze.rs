//! `impact analyze FILE…`: a recording through the pipeline ([`crate::pipeline::analyze`]),
//! printed as the table, JSON or CSV, and drawn (`--plot`); several recordings or channels
//! are a test series ([`super::series`]).

use std::path::PathBuf;

use impact_io::channel::ColumnRef;

use super::series;
use crate::pipeline::{self, AnalyzeArgs};
use crate::report::spec::Judged;
use crate::{plot, report};

/// `impact analyze`'s command line: one recording's options, and the series' recordings.
#[derive(clap::Args, Clone, Debug)]
pub struct AnalyzeCommand {
    #[command(flatten)]
    pub args: AnalyzeArgs,
    /// More recordings: a test series.
    ///
    /// More recordings, folders (their recordings, by name) or quoted patterns
    /// (`'runs/*.csv'`): a test series, each analysed with the same options, in parallel;
    /// one row per impact with its file and channel, and each metric's statistics across
    /// the series (mean, sample standard deviation, coefficient of variation, min, max).
    #[arg(value_name = "MORE")]
    pub more: Vec<PathBuf>,
    /// A series over channels: each file analysed once per channel (`1,2,3,4,5`).
    ///
    /// A series over channels: each file analysed once per channel (header names or 0-based
    /// indices, comma-separated: `accel 1,accel 2` or `1,2,3,4,5`), as if each were given
    /// with --column.
    #[arg(
        long,
        value_delimiter = ',',
        value_name = "LIST",
        conflicts_with_all = ["column", "axes"],
        help_heading = "Input"
    )]
    pub channels: Vec<ColumnRef>,
    /// A series' shock direction per recording: `channel` or `name:PATTERN`.
    ///
    /// Each recording's shock direction, for statistics and verdicts direction by direction
    /// (a shock test's 3 shocks in each of 6 directions): `channel` (each channel of
    /// --channels is a direction) or `name:PATTERN`, a regular expression over the file's
    /// name whose first group (else whole match) is the direction (`name:_([+-][XYZ])_`). A
    /// recording with none is named in a note. `impact report` also takes `--meta
    /// direction=+Z`, one direction for every recording.
    #[arg(long, value_name = "SOURCE", value_parser = super::direction::parse, help_heading = "Input")]
    pub direction: Option<super::direction::Direction>,
}

/// The files an analysis reads (no output may write over one): the recording, the scene
/// file, the free-fall recording, the user's band (`--spec …,band-file=`), the state-space
/// target's file (`--target`'s or the scene file's).
pub fn inputs(args: &AnalyzeArgs) -> Vec<std::path::PathBuf> {
    let mut inputs = vec![args.file.clone()];
    inputs.extend(args.scene.clone());
    inputs.extend(
        (args.free_fall.as_deref().map(pipeline::free_fall::file)).map(|p| p.to_path_buf()),
    );
    inputs.extend(args.spec.and_then(|s| s.band_file).map(|p| p.to_path_buf()));
    inputs.extend(pipeline::options::target_file(args));
    inputs
}

/// Why `impact analyze` failed.
#[derive(Debug, thiserror::Error)]
pub enum AnalyzeError {
    /// (Boxed: the analysis's error is large.)
    #[error(transparent)]
    Pipeline(Box<pipeline::PipelineError>),
    #[error(transparent)]
    Plot(#[from] plot::PlotError),
    #[error(transparent)]
    Series(#[from] series::SeriesError),
    /// The JSON not made.
    #[error(transparent)]
    Json(#[from] serde_json::Error),
    #[error(
        "--plot draws one recording: give one file and one channel (draw a series' \
         recordings one call each)"
    )]
    PlotSeries,
    /// One recording of the series failed (of `recordings`).
    #[error("1 of {recordings} recordings failed: {failed}")]
    OneFailed {
        recordings: usize,
        failed: Box<series::Failed>,
    },
    /// Several recordings of the series failed (the output names each).
    #[error("{failed} of {recordings} recordings failed (each named in the output)")]
    Failed { failed: usize, recordings: usize },
}

impl From<pipeline::PipelineError> for AnalyzeError {
    fn from(e: pipeline::PipelineError) -> Self {
        AnalyzeError::Pipeline(Box::new(e))
    }
}

/// Runs `impact analyze`; returns the verdicts (the exit status says whether one failed).
pub fn run(cmd: &AnalyzeCommand) -> Result<Judged, AnalyzeError> {
    let mut files = vec![cmd.args.file.clone()];
    files.extend(cmd.more.iter().cloned());
    if series::is_series(&files, &cmd.channels) || cmd.direction.is_some() {
        return run_series(cmd, &files);
    }
    let args = &cmd.args;
    let progress = super::progress::progress_for(&args.file);
    if let Some(path) = &args.plot {
        plot::check_output(path, &inputs(args))?;
    }
    let (setup, reports) = pipeline::analyze(args, progress)?;
    // Before the results: the bar's line cleared.
    super::progress::finish();
    let a = pipeline::to_json(&setup, &reports);
    if args.json {
        crate::outln!("{}", serde_json::to_string_pretty(&a)?);
    } else if args.csv {
        crate::out!("{}", report::to_csv(&a));
    } else {
        crate::out!("{}", report::to_table(&a));
    }
    draw(args, &setup, &reports)?;
    // The verdicts as the output shows them (with --axes, the transverse check's too), as a
    // series counts them.
    Ok(Judged::impacts(&a.impacts))
}

/// `--plot`'s figure of one recording's analysis, if asked, titled with the recording's name
/// (the output already checked against the inputs: [`plot::check_output`]).
pub fn draw(
    args: &AnalyzeArgs,
    setup: &pipeline::Setup,
    reports: &[impact_core::ImpactReport],
) -> Result<(), plot::PlotError> {
    let Some(path) = &args.plot else {
        return Ok(());
    };
    let mut signal = setup.plot_signal();
    let name = args.file.file_name().map_or_else(
        || args.file.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    );
    signal.title = format!("{name}, {}", signal.title);
    plot::impacts(&signal, setup.scene.spec.as_ref(), reports, path)
}

/// A test series: every recording analysed, the rows and statistics printed, each
/// recording's notes named by it; exit status 1 if one failed (its error in the output).
fn run_series(cmd: &AnalyzeCommand, files: &[PathBuf]) -> Result<Judged, AnalyzeError> {
    let args = &cmd.args;
    if args.plot.is_some() {
        return Err(AnalyzeError::PlotSeries);
    }
    let mut entries = series::entries(files, &cmd.channels, args.column.as_ref())?;
    if let Some(d) = &cmd.direction {
        series::with_directions(&mut entries, d);
    }
    let results = series::analyze(args, &entries);
    for e in &results {
        for n in &e.notes {
            crate::errln!("note: {}", series::failure(e, n));
        }
    }
    if args.json {
        crate::outln!(
            "{}",
            serde_json::to_string_pretty(&series::to_json(&results))?
        );
    } else if args.csv {
        crate::out!("{}", series::to_csv(&results));
    } else {
        crate::out!("{}", series::to_table(&results));
    }
    let recordings = results.len();
    let judged = Judged::impacts(
        results
            .iter()
            .filter_map(|e| e.analysis.as_ref())
            .flat_map(|a| &a.impacts),
    );
    let mut failed: Vec<series::Failed> = results
        .into_iter()
        .filter_map(series::EntryJson::into_failure)
        .collect();
    match failed.len() {
        0 => Ok(judged),
        1 => Err(AnalyzeError::OneFailed {
            recordings,
            failed: Box::new(failed.remove(0)),
        }),
        n => Err(AnalyzeError::Failed {
            failed: n,
            recordings,
        }),
    }
}
