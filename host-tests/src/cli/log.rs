//! `impact log`: a decoded firmware log (or, with `--elf`, a raw defmt stream) read back,
//! checked line by line, and turned into `impact analyze`'s JSON and CSV, its figure and its
//! windows as recordings.

use std::io::{BufRead, BufReader, BufWriter, Read, Write};
use std::path::PathBuf;

use clap::Args;

use crate::firmware_link::log::LogReader;
use crate::firmware_link::log_json::LogJson;
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

fn finite_f64(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err("must be finite".into()),
        Err(_) => Err("not a number".into()),
    }
}

/// `impact log`: a decoded firmware log as JSON (default) or CSV. The file (or stdin, `-`)
/// is read line by line, each line at most [`MAX_LINE_BYTES`].
pub fn log(args: &LogArgs) -> Result<(), String> {
    let name = impact_io::channel::input_name(&args.file);
    if let Some(path) = &args.plot {
        let mut inputs = vec![args.file.as_path()];
        inputs.extend(args.elf.as_deref());
        crate::plot::check_output(path, &inputs)?;
    }
    let input: Box<dyn Read> = if is_stdin(&args.file) {
        Box::new(std::io::stdin())
    } else {
        Box::new(std::fs::File::open(&args.file).map_err(|e| format!("{name}: {e}"))?)
    };
    let mut reader = LogReader::default();
    if let Some(elf) = &args.elf {
        let skipped = crate::firmware_link::decode::decode(elf, input, &name, |n, line| {
            reader
                .line(n, line)
                .map_err(|e| format!("{name}: {}", e.to_string().replacen("line ", "frame ", 1)))
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
pub fn for_each_line(
    input: impl Read,
    name: &str,
    mut on_line: impl FnMut(u64, &str, bool) -> Result<(), String>,
) -> Result<(), String> {
    let mut input = BufReader::with_capacity(1 << 16, input);
    let mut buf = Vec::new();
    for n in 1.. {
        buf.clear();
        let read = (&mut input)
            .take(MAX_LINE_BYTES as u64 + 1)
            .read_until(b'\n', &mut buf)
            .map_err(|e| format!("{name}:{n}: {e}"))?;
        if read == 0 {
            break;
        }
        let cut = buf.len() > MAX_LINE_BYTES;
        let rest = cut && buf.last() != Some(&b'\n');
        buf.truncate(MAX_LINE_BYTES);
        on_line(n, String::from_utf8_lossy(&buf).trim_end(), cut)?;
        if rest {
            input
                .skip_until(b'\n')
                .map_err(|e| format!("{name}:{n}: {e}"))?;
        }
    }
    Ok(())
}

/// Reads the decoded log `input` (called `name` in errors) line by line into `reader`; a line
/// longer than [`MAX_LINE_BYTES`] is an error.
fn read_text(input: impl Read, name: &str, reader: &mut LogReader) -> Result<(), String> {
    for_each_line(input, name, |n, line, cut| {
        if cut {
            return Err(format!(
                "{name}:{n}: a line longer than {MAX_LINE_BYTES} bytes: not a decoded defmt log"
            ));
        }
        reader.line(n, line).map_err(|e| format!("{name}: {e}"))
    })
}

/// The decoded log at `path` (`impact watch`'s session file), read and checked.
pub fn read_log(path: &std::path::Path) -> Result<crate::firmware_link::log::Log, String> {
    let name = path.display().to_string();
    let file = std::fs::File::open(path).map_err(|e| format!("{name}: {e}"))?;
    let mut reader = LogReader::default();
    read_text(file, &name, &mut reader)?;
    reader.finish().map_err(|e| format!("{name}: {e}"))
}

/// The decoded log at `path` (`impact watch`'s session file) as `impact log`'s JSON, or CSV,
/// written to `out`.
pub fn export(path: &std::path::Path, csv: bool, out: &mut impl Write) -> Result<(), String> {
    let name = path.display().to_string();
    let log = read_log(path)?;
    let json = LogJson::new(&log, 0.0).map_err(|e| e.to_string())?;
    if csv {
        crate::report::csv::write_csv(&json.head, json.impacts(), out)
    } else {
        crate::report::write_json(&json.head, json.impacts(), out)
    }
    .map_err(|e| format!("{name}: {e}"))
}

/// The log read: its warnings on stderr, the figure and exports asked for, the JSON or CSV.
fn report(args: &LogArgs, reader: LogReader, name: &str) -> Result<(), String> {
    let log = reader.finish().map_err(|e| format!("{name}: {e}"))?;
    if let (true, [_, second, ..]) = (
        args.plot.is_some() || args.export.is_some(),
        log.runs.as_slice(),
    ) {
        return Err(format!(
            "--plot/--export: {name} holds {} runs (the board restarted on line {}): their \
             sample positions overlap; split the log into runs",
            log.runs.len(),
            second.line
        ));
    }
    for w in &log.warnings {
        crate::errln!("warning: {name}: {w}");
    }
    let json = LogJson::new(&log, args.t0).map_err(|e| e.to_string())?;
    if args.plot.is_some() || args.export.is_some() {
        let scene = log
            .scene
            .as_ref()
            .ok_or("--plot/--export: the log has no scene line (the rate and the gain)")?;
        let rate = f64::from(scene.rate_hz);
        let gain = f64::from(scene.gain().map_err(|e| e.to_string())?);
        if let Some(path) = &args.plot {
            if log.waveforms.is_empty() {
                return Err("--plot: the log has no waveforms (the scene's wave=0)".into());
            }
            let mass = scene.mass_kg().map_err(|e| e.to_string())?;
            let waves = &log.waveforms;
            // The board sends the impact's window only: not the samples around it that its
            // CFC filtered.
            let cfc = scene.cfc();
            let signal = crate::plot::Signal {
                title: format!(
                    "{name}: the board's captured windows, m/s² above the baseline{}",
                    cfc.map_or(String::new(), |c| format!(
                        " (raw: the windows hold too little for its CFC {c} trace)"
                    ))
                ),
                cfc: None,
                rate_hz: rate,
                mass_kg: mass.map(f64::from),
                accel_m_s2: Box::new(move |i| {
                    waves
                        .iter()
                        .find_map(|w| w.at_sample(i))
                        .map(|c| f64::from(c) * gain)
                }),
            };
            // (plot::impacts says "wrote PATH".)
            crate::plot::impacts(&signal, &log.impacts, path)?;
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
    .map_err(|e| format!("stdout: {e}"))
}
