//! `analyze_file`, `analyze_array`, `series`, `statistics`, `simulate`: the tool's analyses
//! of a recording, an array, a series of recordings and a model, each returning the tool's
//! JSON text (as `impact analyze --json`, `impact analyze FILES… --json`, `impact simulate
//! --json` print it) with the notes the run gave.

use std::path::PathBuf;

use clap::Parser;
use impact_host::cli::analyze::AnalyzeCommand;
use impact_host::cli::series as tool_series;
use impact_host::pipeline::free_fall::FreeFallError;
use impact_host::pipeline::{self, options, AnalyzeArgs, PipelineError, Samples};
use impact_host::report::spec::Judged;
use impact_host::report::ImpactJson;
use impact_host::simulate::{self as tool_simulate, SimulateArgs, SimulateError};
use numpy::PyReadonlyArray1;
use pyo3::prelude::*;

use crate::{usage, AnalysisError, ReadError, SimulationError, UsageError};

// `impact analyze`'s command line, parsed as the tool parses it.
#[derive(Parser)]
#[command(name = "impact analyze", allow_negative_numbers = true)]
struct AnalyzeCli {
    #[command(flatten)]
    cmd: AnalyzeCommand,
}

// `impact simulate`'s command line.
#[derive(Parser)]
#[command(name = "impact simulate", allow_negative_numbers = true)]
struct SimulateCli {
    #[command(flatten)]
    args: SimulateArgs,
}

/// One analysis as Python receives it: the JSON text, the notes, how many impacts were
/// judged against a spec and how many of those failed, and the channel and its units (which
/// the table shows and the JSON leaves out).
type Analysed = (
    String,
    Vec<String>,
    usize,
    usize,
    Option<String>,
    &'static str,
);

/// The options (`argv`, the file first) parsed as `impact analyze`'s.
pub(crate) fn parse(argv: Vec<String>) -> PyResult<AnalyzeCommand> {
    AnalyzeCli::try_parse_from(std::iter::once("impact analyze".to_string()).chain(argv))
        .map(|c| c.cmd)
        .map_err(|e| usage(&e))
}

/// The Python exception of a failed analysis, by the error's kind: the recording (or a file
/// an option names) not read, the settings refused, or the analysis itself.
fn analysis_error(e: &PipelineError) -> PyErr {
    let message = e.to_string();
    match e {
        PipelineError::Read(_)
        | PipelineError::Spool { .. }
        | PipelineError::Memory { .. }
        | PipelineError::TooFewSamples { .. }
        | PipelineError::NotFinite { .. }
        | PipelineError::Scene(options::SceneError::Read(_))
        | PipelineError::FreeFall(
            FreeFallError::Read(_)
            | FreeFallError::Columns { .. }
            | FreeFallError::NoTimeColumn { .. },
        ) => ReadError::new_err(message),
        PipelineError::Units(_)
        | PipelineError::Scene(_)
        | PipelineError::Cfc { .. }
        | PipelineError::Invalid { .. }
        | PipelineError::Monitor(_)
        | PipelineError::LongestUnderHold { .. }
        | PipelineError::HoldOverLongest { .. }
        | PipelineError::SettleUnderHold { .. }
        | PipelineError::EdgeNotBelowTrigger { .. }
        | PipelineError::StreamNeedsWhole { .. }
        | PipelineError::StreamNeedsRange
        | PipelineError::StreamNeedsTrigger
        | PipelineError::AxesUnits { .. } => UsageError::new_err(message),
        _ => AnalysisError::new_err(message),
    }
}

/// Runs `f` with the notes it gives (its worker threads' too: `impact_io::NoteScope`) kept
/// apart from another call's, worded as the tool words them.
pub(crate) fn with_notes<R>(f: impl FnOnce() -> R) -> (R, Vec<String>) {
    impact_io::with_own_notes(impact_host::read_errors::flag, f)
}

/// One recording's analysis as Python receives it (the notes not yet added).
struct Done {
    json: String,
    judged: Judged,
    column: Option<String>,
    units: &'static str,
}

impl Done {
    fn of(
        setup: &pipeline::Setup,
        reports: &[impact_core::ImpactReport],
    ) -> Result<Self, serde_json::Error> {
        Ok(Self {
            json: serde_json::to_string(&pipeline::to_json(setup, reports))?,
            judged: Judged::reports(reports),
            column: setup.column.clone(),
            units: setup.units.name(),
        })
    }

    fn with(self, notes: Vec<String>) -> Analysed {
        let Done {
            json,
            judged,
            column,
            units,
        } = self;
        (json, notes, judged.judged, judged.failed, column, units)
    }
}

fn json_error(e: serde_json::Error) -> PyErr {
    AnalysisError::new_err(format!("the JSON not made: {e}"))
}

/// `impact analyze FILE [OPTIONS] --json` (one recording; `series` takes several), and its
/// `--plot` figure if asked.
#[pyfunction]
pub fn analyze_file(py: Python<'_>, argv: Vec<String>) -> PyResult<Analysed> {
    let cmd = parse(argv)?;
    if !cmd.more.is_empty() || !cmd.channels.is_empty() {
        return Err(UsageError::new_err(
            "one recording and one channel: a series is impact.series(files, ...)",
        ));
    }
    let args = cmd.args;
    let (result, notes) = py.detach(|| {
        with_notes(|| -> PyResult<Done> {
            if let Some(path) = &args.plot {
                impact_host::plot::check_output(path, &impact_host::cli::analyze::inputs(&args))
                    .map_err(|e| UsageError::new_err(e.to_string()))?;
            }
            let (setup, reports) = pipeline::analyze(&args, impact_io::progress::Progress::none())
                .map_err(|e| analysis_error(&e))?;
            impact_host::cli::analyze::draw(&args, &setup, &reports)
                .map_err(|e| AnalysisError::new_err(e.to_string()))?;
            Done::of(&setup, &reports).map_err(json_error)
        })
    });
    Ok(result?.with(notes))
}

/// The options that read a file, which an array (one channel of evenly spaced samples in
/// memory) has no use for: the first one given, as its flag.
fn file_option(args: &AnalyzeArgs) -> Option<&'static str> {
    [
        (args.stream, "--stream"),
        (args.column.is_some(), "--column"),
        (!args.axes.is_empty(), "--axes"),
        (args.time_column.is_some(), "--time-column"),
        (args.time_unit.is_some(), "--time-unit"),
        (args.resample, "--resample"),
        (args.delimiter.is_some(), "--delimiter"),
        (args.decimal_comma, "--decimal-comma"),
        (args.raw_channels.is_some(), "--raw-channels"),
        (args.raw_type.is_some(), "--raw-type"),
    ]
    .into_iter()
    .find_map(|(given, flag)| given.then_some(flag))
}

/// `impact analyze`'s analysis of `samples` (float64, borrowed from NumPy without a copy),
/// evenly spaced at `--rate` from time 0; `argv[0]` names the channel.
#[pyfunction]
pub fn analyze_array(
    py: Python<'_>,
    argv: Vec<String>,
    samples: PyReadonlyArray1<'_, f64>,
) -> PyResult<Analysed> {
    let cmd = parse(argv)?;
    let args = cmd.args;
    if let Some(flag) = file_option(&args) {
        return Err(UsageError::new_err(format!(
            "{flag} reads a file: an array is one channel of evenly spaced samples \
             (give its rate)"
        )));
    }
    if args.plot.is_some() {
        return Err(UsageError::new_err(
            "--plot draws a recording read from a file: save the array (numpy.save) and \
             analyse the .npy",
        ));
    }
    // An array has no header to name its unit: it is said, not guessed from its name.
    if args.units.is_none() && args.scene.is_none() {
        return Err(UsageError::new_err(
            "an array has no header to name its unit: give units= (g, m/s2, kgn or n)",
        ));
    }
    let Some(rate_hz) = args.rate else {
        return Err(UsageError::new_err(
            "an array has no time base: give rate= (samples per second)",
        ));
    };
    let values = samples
        .as_slice()
        .map_err(|e| UsageError::new_err(format!("the array: {e}")))?;
    let name = args.file.to_string_lossy().into_owned();
    let (result, notes) = py.detach(|| {
        with_notes(|| -> PyResult<Done> {
            let (setup, reports) =
                pipeline::analyze_samples(&args, Samples::even(&name, values, rate_hz))
                    .map_err(|e| analysis_error(&e))?;
            Done::of(&setup, &reports).map_err(json_error)
        })
    });
    Ok(result?.with(notes))
}

/// `impact analyze FILE FILE… [OPTIONS] --json`: a series (each recording analysed with
/// the same options, in parallel), its rows and statistics; a recording that failed is an
/// entry with its error, not an exception. The notes that name no recording.
#[pyfunction]
pub fn series(
    py: Python<'_>,
    argv: Vec<String>,
    files: Vec<PathBuf>,
) -> PyResult<(String, Vec<String>)> {
    let cmd = parse(argv)?;
    if cmd.args.plot.is_some() {
        return Err(UsageError::new_err(
            "--plot draws one recording: give one file (impact.analyze)",
        ));
    }
    let (result, notes) = py.detach(|| {
        with_notes(|| -> PyResult<String> {
            let entries = tool_series::entries(&files, &cmd.channels, cmd.args.column.as_ref())
                .map_err(|e| ReadError::new_err(e.to_string()))?;
            let results = tool_series::analyze(&cmd.args, &entries);
            serde_json::to_string(&tool_series::to_json(&results)).map_err(json_error)
        })
    });
    Ok((result?, notes))
}

/// A series' statistics over impacts analysed elsewhere (`impacts_json`: a JSON list of the
/// impacts as `analyze` gave them, every recording's in the series' order), as
/// `impact analyze FILES… --json` gives them: its `impacts`, `spec`, `statistics`,
/// `statistics_left_out` and `bounce_statistics`.
#[pyfunction]
pub fn statistics(impacts_json: &str) -> PyResult<String> {
    let impacts: Vec<ImpactJson> = serde_json::from_str(impacts_json)
        .map_err(|e| UsageError::new_err(format!("not impacts as analyze gives them: {e}")))?;
    let s = impact_host::report::statistics::series_statistics(impacts.iter());
    serde_json::to_string(&s).map_err(json_error)
}

/// An impact's fields as the JSON has them when nothing is known (every column of an
/// impacts table, for a table of no impact).
#[pyfunction]
pub fn impact_fields() -> PyResult<String> {
    serde_json::to_string(&ImpactJson::default()).map_err(json_error)
}

/// `impact simulate [OPTIONS] --json`: one impact of a contact model, on a wall or a target.
#[pyfunction]
pub fn simulate(py: Python<'_>, argv: Vec<String>) -> PyResult<String> {
    let args =
        SimulateCli::try_parse_from(std::iter::once("impact simulate".to_string()).chain(argv))
            .map_err(|e| usage(&e))?
            .args;
    py.detach(|| {
        let json = match tool_simulate::run_any(&args) {
            Ok(tool_simulate::Outcome::Wall(report)) => serde_json::to_string(&report),
            Ok(tool_simulate::Outcome::Target(report)) => serde_json::to_string(&*report),
            Err(SimulateError::Json(e)) => Err(e),
            Err(e) => return Err(SimulationError::new_err(e.to_string())),
        };
        json.map_err(json_error)
    })
}
