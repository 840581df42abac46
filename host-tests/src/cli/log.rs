//! `impact log`: a decoded firmware log (or, with `--elf`, a raw defmt stream) read back,
//! checked line by line, and turned into `impact analyze`'s JSON and CSV, its figure and its
//! windows as recordings.

use crate::report::spec::Judged;
use std::io::{BufRead, BufReader, BufWriter, Read, Write};
use std::path::PathBuf;

use clap::Args;

use crate::firmware_link::decode::DefmtError;
use crate::firmware_link::line::FieldError;
use crate::firmware_link::log::{LogError, LogReader};
use crate::firmware_link::log_json::LogJson;
use crate::firmware_link::waves::ExportError;
use impact_io::channel::is_stdin;
use impact_io::table::MAX_LINE_BYTES;

/// `impact log` options.
#[derive(Args, Clone, Debug)]
pub struct LogArgs {
    /// The firmware's decoded defmt log (probe-rs's or defmt-print's text output, `impact
    /// emulate --log`; `-`: standard input), or with --elf its raw defmt stream.
    pub file: PathBuf,
    /// Print one JSON object (the default).
    #[arg(short = 'j', long, help_heading = "Output", conflicts_with = "csv")]
    pub json: bool,
    /// Print one CSV row per impact.
    #[arg(long, help_heading = "Output")]
    pub csv: bool,
    /// Time of the stream's first sample, s (added to start_s and peak_time_s, as
    /// `impact analyze` adds the recording's first time stamp).
    #[arg(long, help_heading = "Input", default_value_t = 0.0, value_parser = finite_f64, allow_negative_numbers = true)]
    pub t0: f64,
    /// The input is the firmware's raw defmt stream (as QEMU's semihosting, `impact emulate
    /// --defmt` or an RTT reader saves it), decoded against this ELF (the firmware that wrote
    /// it) with defmt-decoder.
    #[arg(long, help_heading = "Input")]
    pub elf: Option<PathBuf>,
    /// Draw the impacts from the board's waveforms (the figure of `impact analyze --plot`)
    /// to this SVG or PNG file (by its extension).
    #[arg(short = 'p', long, help_heading = "Output", value_name = "FILE")]
    pub plot: Option<PathBuf>,
    /// Write each waveform as a recording `impact analyze` reads: `NAME.csv` (time_s,
    /// accel_m_s2) or `NAME.wav` (16-bit counts, give `--gain`), one file per impact,
    /// `NAME-<index>.csv`.
    #[arg(long, help_heading = "Output")]
    pub export: Option<PathBuf>,
}

/// Why `impact log` (or `impact watch`'s export of its session file) could not read a log or
/// write what it gives. `name` is the input as the tool names it (`stdin`, or its path).
#[derive(Debug, thiserror::Error)]
pub enum LogCommandError {
    /// `--plot`: refused before any work, or its figure not written.
    #[error(transparent)]
    Plot(#[from] crate::plot::PlotError),
    #[error("{name}: {source}")]
    Open {
        name: String,
        source: std::io::Error,
    },
    #[error(transparent)]
    ReadLine(#[from] ReadLineError),
    #[error("{name}:{line}: a line longer than {MAX_LINE_BYTES} bytes: not a decoded defmt log")]
    LineTooLong { name: String, line: u64 },
    #[error(transparent)]
    Defmt(#[from] DefmtError),
    /// A raw defmt stream's log error: its lines are the stream's frames.
    #[error("{name}: {}", in_frames(.error))]
    InFrames { name: String, error: Box<LogError> },
    #[error("{name}: {error}")]
    Log { name: String, error: Box<LogError> },
    /// What the whole log lacks for its report (no rate).
    #[error(transparent)]
    Report(LogError),
    /// No rate: the lines that state one were passed over (the first named).
    #[error(
        "{name}: line {}: {}; no other scene, heartbeat or summary line gives the sample rate",
        .skipped.line, .skipped.kind
    )]
    RateRefused {
        name: String,
        skipped: Box<crate::firmware_link::log::Skipped>,
    },
    /// A value of the scene line the figure or the export needs.
    #[error(transparent)]
    Scene(#[from] FieldError),
    #[error(
        "--plot/--export: {name} holds {runs} runs (the board restarted on line {restart}): their \
         sample positions overlap; split the log into runs"
    )]
    Runs {
        name: String,
        runs: usize,
        restart: u64,
    },
    #[error("--plot/--export: the log has no scene line (the rate and the gain)")]
    NoScene,
    #[error("--plot: the log has no waveforms (the scene's wave=0)")]
    NoWaveforms,
    #[error(transparent)]
    Export(#[from] ExportError),
    /// The report written to `name` (an export of the session file).
    #[error("{name}: {source}")]
    Write {
        name: String,
        source: std::io::Error,
    },
    #[error("stdout: {0}")]
    Stdout(std::io::Error),
}

/// A log error of a raw defmt stream, its line numbers the frames': `frame N: what`.
fn in_frames(e: &LogError) -> String {
    match e.line {
        Some(n) => format!("frame {n}: {}", e.kind),
        None => e.kind.to_string(),
    }
}

/// A line of `name` that could not be read.
#[derive(Debug, thiserror::Error)]
#[error("{name}:{line}: {source}")]
pub struct ReadLineError {
    pub name: String,
    pub line: u64,
    pub source: std::io::Error,
}

/// `--t0` refused (clap shows it after the option and the value).
#[derive(Debug, thiserror::Error)]
pub enum FiniteError {
    #[error("must be finite")]
    NotFinite,
    #[error("not a number")]
    NotANumber,
}

fn finite_f64(s: &str) -> Result<f64, FiniteError> {
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(FiniteError::NotFinite),
        Err(_) => Err(FiniteError::NotANumber),
    }
}

/// `impact log`: a decoded firmware log as JSON (default) or CSV. The file (or stdin, `-`)
/// is read line by line, each line at most [`MAX_LINE_BYTES`].
/// Runs `impact log`; returns the board's verdicts (the exit status says whether one failed).
pub fn log(args: &LogArgs) -> Result<Judged, LogCommandError> {
    let name = impact_io::channel::input_name(&args.file);
    if let Some(path) = &args.plot {
        let mut inputs = vec![args.file.as_path()];
        inputs.extend(args.elf.as_deref());
        crate::plot::check_output(path, &inputs)?;
    }
    let input: Box<dyn Read> = if is_stdin(&args.file) {
        Box::new(std::io::stdin())
    } else {
        Box::new(
            std::fs::File::open(&args.file).map_err(|source| LogCommandError::Open {
                name: name.clone(),
                source,
            })?,
        )
    };
    let mut reader = LogReader::skipping();
    if let Some(elf) = &args.elf {
        let skipped = crate::firmware_link::decode::decode(elf, input, &name, |n, line| {
            reader
                .line(n, line)
                .map_err(|error| LogCommandError::InFrames {
                    name: name.clone(),
                    error: Box::new(error),
                })
        })?;
        if skipped > 0 {
            crate::errln!(
                "warning: {name}: {skipped} malformed defmt frames skipped (a cut stream)"
            );
        }
        return report(args, reader, &name);
    }
    read_text(input, &name, &mut reader)?;
    report(args, reader, &name)
}

/// Reads `input` (called `name` in errors) line by line: `on_line` gets each line's number
/// (from 1), its text, and whether it was cut: a line is at most [`MAX_LINE_BYTES`] with its
/// newline; of a longer one `on_line` gets the first [`MAX_LINE_BYTES`] bytes (it may end the
/// reading there) and the rest is passed over, never held.
pub fn for_each_line<E: From<ReadLineError>>(
    input: impl Read,
    name: &str,
    mut on_line: impl FnMut(u64, &str, bool) -> Result<(), E>,
) -> Result<(), E> {
    let failed = |line: u64| {
        move |source| ReadLineError {
            name: name.to_string(),
            line,
            source,
        }
    };
    let mut input = BufReader::with_capacity(1 << 16, input);
    let mut buf = Vec::new();
    for n in 1.. {
        buf.clear();
        let read = (&mut input)
            .take(MAX_LINE_BYTES as u64 + 1)
            .read_until(b'\n', &mut buf)
            .map_err(failed(n))?;
        if read == 0 {
            break;
        }
        let cut = buf.len() > MAX_LINE_BYTES;
        let rest = cut && buf.last() != Some(&b'\n');
        buf.truncate(MAX_LINE_BYTES);
        on_line(n, String::from_utf8_lossy(&buf).trim_end(), cut)?;
        if rest {
            input.skip_until(b'\n').map_err(failed(n))?;
        }
    }
    Ok(())
}

/// Reads the decoded log `input` (called `name` in errors) line by line into `reader`; a line
/// longer than [`MAX_LINE_BYTES`] is an error (not a decoded defmt log).
fn read_text(input: impl Read, name: &str, reader: &mut LogReader) -> Result<(), LogCommandError> {
    for_each_line(input, name, |n, line, cut| {
        if cut {
            return Err(LogCommandError::LineTooLong {
                name: name.to_string(),
                line: n,
            });
        }
        reader.line(n, line).map_err(in_log(name))
    })
}

/// A log error of the input `name`.
fn in_log(name: &str) -> impl Fn(LogError) -> LogCommandError + '_ {
    move |error| LogCommandError::Log {
        name: name.to_string(),
        error: Box::new(error),
    }
}

/// The decoded log at `path` (`impact watch`'s session file), read and checked as `impact
/// log` reads it (a bad line passed over and named: [`Log::skipped`](crate::firmware_link::log::Log)).
pub fn read_log(path: &std::path::Path) -> Result<crate::firmware_link::log::Log, LogCommandError> {
    let name = path.display().to_string();
    let file = std::fs::File::open(path).map_err(|source| LogCommandError::Open {
        name: name.clone(),
        source,
    })?;
    let mut reader = LogReader::skipping();
    read_text(file, &name, &mut reader)?;
    reader.finish().map_err(in_log(&name))
}

/// The log read (`impact watch`'s session file), ready to be written as `impact log`'s JSON
/// or CSV: [`Export::write`] writes it an impact at a time.
pub struct Export<'a> {
    json: LogJson<'a>,
}

impl<'a> Export<'a> {
    pub fn new(log: &'a crate::firmware_link::log::Log) -> Result<Self, LogCommandError> {
        let name = "the session file";
        Ok(Self {
            json: LogJson::new(log, 0.0).map_err(|e| no_rate(e, log, name))?,
        })
    }

    /// Writes the JSON, or the CSV, to `out`, an impact at a time (never held whole).
    pub fn write(&self, csv: bool, out: &mut impl Write) -> std::io::Result<()> {
        let json = &self.json;
        if csv {
            crate::report::csv::write_csv(&json.head, json.impacts(), out)
        } else {
            crate::report::write_json(&json.head, json.impacts(), out)
        }
    }
}

/// A log's report that could not be made: without a rate because the lines that gave one
/// were passed over, the first of them named.
fn no_rate(e: LogError, log: &crate::firmware_link::log::Log, name: &str) -> LogCommandError {
    use crate::firmware_link::line::LineKind;
    let gave_rate = |s: &&crate::firmware_link::log::Skipped| {
        matches!(
            s.of,
            Some(LineKind::Scene | LineKind::Heartbeat | LineKind::Summary)
        )
    };
    match (&e.kind, log.skipped.iter().find(gave_rate)) {
        (crate::firmware_link::log::LogErrorKind::NoRate, Some(s)) => {
            LogCommandError::RateRefused {
                name: name.to_string(),
                skipped: Box::new(s.clone()),
            }
        }
        _ => LogCommandError::Report(e),
    }
}

/// The log read: its warnings on stderr, the figure and exports asked for, the JSON or CSV.
fn report(args: &LogArgs, reader: LogReader, name: &str) -> Result<Judged, LogCommandError> {
    let log = reader.finish().map_err(in_log(name))?;
    if let (true, [_, second, ..]) = (
        args.plot.is_some() || args.export.is_some(),
        log.runs.as_slice(),
    ) {
        return Err(LogCommandError::Runs {
            name: name.to_string(),
            runs: log.runs.len(),
            restart: second.line,
        });
    }
    let json = LogJson::new(&log, args.t0).map_err(|e| no_rate(e, &log, name))?;
    for w in &log.warnings {
        crate::errln!("warning: {name}: {w}");
    }
    for s in &log.skipped {
        crate::errln!("warning: {name}: {s}");
    }
    if args.plot.is_some() || args.export.is_some() {
        let scene = log.scene.as_ref().ok_or(LogCommandError::NoScene)?;
        let rate = f64::from(scene.rate_hz);
        let gain = f64::from(scene.gain()?);
        if let Some(path) = &args.plot {
            if log.waveforms.is_empty() {
                return Err(LogCommandError::NoWaveforms);
            }
            let mass = scene.mass_kg()?;
            let waves = &log.waveforms;
            // The board sends the impact's window only: not the samples around it that its
            // CFC (or low-pass) filtered.
            let filter = match (scene.cfc(), scene.lowpass()) {
                (Some(c), _) => Some(format!("CFC {c}")),
                (None, Some(l)) => Some(crate::report::filter::name(
                    &impact_core::signal::window_filter::WindowFilter::Lowpass(l),
                )),
                (None, None) => None,
            };
            let signal = crate::plot::Signal {
                title: format!(
                    "{name}: the board's captured windows, m/s² above the baseline{}",
                    filter.map_or(String::new(), |f| format!(
                        " (raw: the windows hold too little for its {f} trace)"
                    ))
                ),
                filter: None,
                rate_hz: rate,
                mass_kg: mass.map(f64::from),
                force_kg: None,
                t0_s: 0.0,
                accel_m_s2: Box::new(move |i| {
                    waves
                        .iter()
                        .find_map(|w| w.at_sample(i))
                        .map(|c| f64::from(c) * gain)
                }),
            };
            // The pulse the board's scene line states, as the report's pulses take it.
            let spec = scene.spec().ok().flatten();
            // (plot::impacts says "wrote PATH".)
            crate::plot::impacts(&signal, spec.as_ref(), &log.impacts, path)?;
        }
        if let Some(path) = &args.export {
            let inputs = crate::output::Inputs::new()
                .with(&args.file)
                .with_some(args.elf.as_deref());
            for p in crate::firmware_link::waves::export(&log.waveforms, path, &inputs, rate, gain)?
            {
                crate::errln!("wrote {}", p.display());
            }
        }
    }
    // Written an impact at a time: a long log's report is never held whole.
    let mut out = BufWriter::with_capacity(1 << 16, crate::output::stdout());
    if args.csv {
        crate::report::csv::write_csv(&json.head, json.impacts(), &mut out)
    } else {
        crate::report::write_json(&json.head, json.impacts(), &mut out)
    }
    .and_then(|()| out.flush())
    .map_err(LogCommandError::Stdout)?;
    Ok(Judged::reports(&log.impacts))
}
