//! The report's title block: what the lab says of the test (`--meta KEY=VALUE`, `--meta-file
//! FILE`: test id, operator, device under test, sensor, calibration due, any key, in the order
//! given), what an enDAQ `.IDE` recording says of its recorder, sensor and calibration, and
//! when and by what the report was written.

use std::path::{Path, PathBuf};

use impact_io::ColumnRef;

use super::provenance::{self, Written};
use crate::html;
use crate::html::Html;

/// The largest meta file read (a title block, not a document).
pub const MAX_META_FILE: u64 = 64 << 10;

/// `--meta` and `--meta-file`.
#[derive(clap::Args, Clone, Debug, Default)]
pub struct MetaArgs {
    /// A line of the report's title block: `test-id=T-0042` (repeatable; in the order given).
    ///
    /// A line of the report's title block, `KEY=VALUE` (repeatable; shown in the order given,
    /// after the --meta-file's): any key; `test-id`, `operator`, `dut`, `dut-serial`,
    /// `sensor`, `sensor-serial`, `sensitivity`, `calibration-due`, `procedure`, `standard`,
    /// `customer`, `lab`, `location`, `fixture`, `date`, `notes` are shown with their label
    /// (`Test ID`, `Device under test`, …). A key given here and in the --meta-file takes this
    /// value.
    #[arg(long, value_name = "KEY=VALUE", value_parser = parse_meta, help_heading = "Output")]
    pub meta: Vec<(String, String)>,
    /// The title block's lines from a file: `key = value` or `key: value` a line.
    ///
    /// The title block's lines from a UTF-8 text file (at most 64 KiB): one `key = value` or
    /// `key: value` a line (split at the first `=` or `:`, spaces around both trimmed), blank
    /// lines and lines starting with `#` skipped. Its lines come first, in the file's order.
    #[arg(long, value_name = "FILE", help_heading = "Output")]
    pub meta_file: Option<PathBuf>,
}

/// Why a title block's line was refused.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum MetaLineError {
    #[error("no `=` or `:` between a key and its value")]
    NoSeparator,
    #[error("no `=` between a key and its value")]
    NoEquals,
    #[error("an empty key")]
    EmptyKey,
    #[error("a control character in {0}")]
    Control(&'static str),
    #[error("the key {0:?} given twice")]
    Twice(String),
    /// A key that would show as one of the rows the tool writes itself.
    #[error("the key {0:?} is the tool's own row (the report writes it): give another")]
    Reserved(String),
}

/// Why the title block could not be read.
#[derive(Debug, thiserror::Error)]
pub enum MetaError {
    #[error("--meta-file {}: {source}", path.display())]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("--meta-file {}: {size} bytes, more than the {MAX_META_FILE} a title block may hold", path.display())]
    TooLarge { path: PathBuf, size: u64 },
    #[error("--meta-file {}: not UTF-8 text", path.display())]
    NotText { path: PathBuf },
    #[error("--meta-file {}: line {line}: {error}", path.display())]
    Line {
        path: PathBuf,
        line: usize,
        error: MetaLineError,
    },
    #[error("--meta: {0}")]
    Option(MetaLineError),
}

/// A `--meta` value: `KEY=VALUE`.
fn parse_meta(s: &str) -> Result<(String, String), MetaLineError> {
    let (k, v) = s.split_once('=').ok_or(MetaLineError::NoEquals)?;
    entry(k, v)
}

/// A key and its value, trimmed and checked.
fn entry(key: &str, value: &str) -> Result<(String, String), MetaLineError> {
    let (key, value) = (key.trim(), value.trim());
    if key.is_empty() {
        return Err(MetaLineError::EmptyKey);
    }
    // Control characters, and the invisible ones that reorder or hide text (bidi overrides,
    // zero-width marks): a signed page shows what it holds.
    let hidden = |c: char| {
        c.is_control()
            || matches!(c, '\u{200b}'..='\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2060}'..='\u{2069}' | '\u{feff}')
    };
    if key.chars().any(hidden) {
        return Err(MetaLineError::Control("the key"));
    }
    if value.chars().any(hidden) {
        return Err(MetaLineError::Control("the value"));
    }
    if RESERVED.contains(&norm(key).as_str()) {
        return Err(MetaLineError::Reserved(key.to_string()));
    }
    Ok((key.to_string(), value.to_string()))
}

/// A key as its label reads it: any case, `_` and spaces as `-` (two keys the same here are
/// one row).
fn norm(key: &str) -> String {
    key.to_lowercase().replace(['_', ' '], "-")
}

/// The rows the tool writes itself, as [`norm`] reads them: not a `--meta` key (a line
/// claiming another report time or tool would sit beside the real one, styled the same).
const RESERVED: [&str; 4] = ["report-written", "tool", "recorder", "factory-calibration"];
/// A meta file's lines (`text`): `key = value` or `key: value`, split at the first of the two.
pub fn parse_meta_file(text: &str) -> Result<Vec<(String, String)>, (usize, MetaLineError)> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut out: Vec<(String, String)> = Vec::new();
    for (k, line) in text.lines().enumerate() {
        let at = k + 1;
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let cut = line
            .find(['=', ':'])
            .ok_or((at, MetaLineError::NoSeparator))?;
        let (key, value) = entry(&line[..cut], &line[cut + 1..]).map_err(|e| (at, e))?;
        if out.iter().any(|(k, _)| norm(k) == norm(&key)) {
            return Err((at, MetaLineError::Twice(key)));
        }
        out.push((key, value));
    }
    Ok(out)
}

/// The title block's lines, the meta file's first, then `--meta`'s (one for a key both give, in
/// the file's place).
pub fn read_meta(args: &MetaArgs) -> Result<Vec<(String, String)>, MetaError> {
    let mut lines = match &args.meta_file {
        Some(path) => read_meta_file(path)?,
        None => Vec::new(),
    };
    for (k, (key, value)) in args.meta.iter().enumerate() {
        if args.meta[..k]
            .iter()
            .any(|(other, _)| norm(other) == norm(key))
        {
            return Err(MetaError::Option(MetaLineError::Twice(key.clone())));
        }
        match lines.iter_mut().find(|(other, _)| norm(other) == norm(key)) {
            Some(line) => line.1 = value.clone(),
            None => lines.push((key.clone(), value.clone())),
        }
    }
    Ok(lines)
}

fn read_meta_file(path: &Path) -> Result<Vec<(String, String)>, MetaError> {
    let read = |source| MetaError::Read {
        path: path.to_path_buf(),
        source,
    };
    // A regular file (a FIFO or a device would be read once for the title block and again,
    // differently or never ending, for its hash), read to at most the cap.
    let meta = std::fs::metadata(path).map_err(read)?;
    if !meta.is_file() {
        return Err(read(std::io::Error::other(
            "not a regular file (a title block is read from a file, and hashed from it)",
        )));
    }
    let mut bytes = Vec::new();
    std::io::Read::read_to_end(
        &mut std::io::Read::take(std::fs::File::open(path).map_err(read)?, MAX_META_FILE + 1),
        &mut bytes,
    )
    .map_err(read)?;
    let size = bytes.len() as u64;
    if size > MAX_META_FILE {
        return Err(MetaError::TooLarge {
            path: path.to_path_buf(),
            size,
        });
    }
    let text = String::from_utf8(bytes).map_err(|_| MetaError::NotText {
        path: path.to_path_buf(),
    })?;
    parse_meta_file(&text).map_err(|(line, error)| MetaError::Line {
        path: path.to_path_buf(),
        line,
        error,
    })
}

/// The label a known key is shown with (any case; `_` and spaces as `-`), else the key.
pub fn label(key: &str) -> String {
    let k = key.to_lowercase().replace(['_', ' '], "-");
    let known = match k.as_str() {
        "test-id" | "test" => "Test ID",
        "operator" => "Operator",
        "dut" => "Device under test",
        "dut-serial" => "DUT serial",
        "sensor" => "Sensor",
        "sensor-serial" => "Sensor serial",
        "sensitivity" => "Sensitivity",
        "calibration-due" | "cal-due" => "Calibration due",
        "procedure" => "Procedure",
        "standard" => "Standard",
        "customer" => "Customer",
        "lab" | "laboratory" => "Laboratory",
        "location" => "Location",
        "fixture" => "Fixture",
        "date" => "Test date",
        "notes" | "note" => "Notes",
        _ => return key.to_string(),
    };
    known.to_string()
}

/// What an `.IDE` recording says of the recorder, the analysed subchannel's sensor and the
/// factory calibration.
#[derive(Clone, Debug, PartialEq)]
pub struct Recorded {
    pub file: String,
    pub recorder: impact_io::ide::Recorder,
    /// The analysed subchannel (`8.0 X (2000g)`) and its sensor, if the file names one.
    pub subchannel: Option<String>,
    pub sensor: Option<impact_io::ide::Sensor>,
    pub calibration: impact_io::ide::Calibration,
}

/// What `file` (an `.IDE` recording, read with `column` or `axes`) says of itself; `None` for
/// another format or a file whose header cannot be read (its analysis says why).
pub fn recorded(file: &Path, column: Option<&ColumnRef>, axes: &[ColumnRef]) -> Option<Recorded> {
    if !impact_io::ide::is_ide(file) {
        return None;
    }
    let ide = impact_io::ide::IdeFile::open(file).ok()?;
    // (The analysis gave the pick's notes already.)
    let (pick, _) = impact_io::with_own_notes(crate::read_errors::flag, || {
        impact_io::ide::pick(&ide, column, axes).ok()
    });
    let info = ide.info();
    let (subchannel, sensor) = match &pick {
        Some(p) => (
            Some(
                p.names
                    .iter()
                    .map(|n| n.split(" [").next().unwrap_or(n).to_string())
                    .collect::<Vec<_>>()
                    .join(", "),
            ),
            p.subs
                .iter()
                .find_map(|&s| ide.sensor_of(p.channel, s))
                .cloned(),
        ),
        None => (None, None),
    };
    Some(Recorded {
        file: file.display().to_string(),
        recorder: info.recorder.clone(),
        subchannel,
        sensor,
        calibration: info.calibration,
    })
}

/// The title block: the lab's lines, each `.IDE` recording's own account, and when and by what
/// the report was written.
pub fn title_block(
    h: &mut Html,
    meta: &[(String, String)],
    recorded: &[Recorded],
    written: Written,
) {
    h.raw("<table class=\"title\">\n");
    let row = |h: &mut Html, k: &str, v: &str| {
        html!(
            h,
            "<tr><th class=\"l\">{}</th><td class=\"l\">{}</td></tr>\n",
            k,
            v
        )
    };
    for (k, v) in meta {
        row(h, &label(k), v);
    }
    row(
        h,
        "Report written",
        &format!(
            "{} (UTC{})",
            written.iso8601(),
            if written.fixed {
                ", from SOURCE_DATE_EPOCH"
            } else {
                ""
            }
        ),
    );
    row(
        h,
        "Tool",
        &format!(
            "impact {}, git commit {}{}",
            env!("CARGO_PKG_VERSION"),
            provenance::COMMIT,
            if provenance::DIRTY {
                " with changes not committed (a development build: not for a signed report)"
            } else {
                ""
            }
        ),
    );
    for r in recorded {
        html!(
            h,
            "<tr><th class=\"l sub\" colspan=\"2\">From the recording {}</th></tr>\n",
            r.file
        );
        let rec = &r.recorder;
        let mut recorder = vec![rec.product_name.clone()];
        if !rec.part_number.is_empty() {
            recorder.push(format!("part number {}", rec.part_number));
        }
        if let Some(s) = rec.serial {
            recorder.push(format!("serial {s}"));
        }
        if !rec.user_name.is_empty() {
            recorder.push(format!("named {}", rec.user_name));
        }
        if !rec.firmware.is_empty() {
            recorder.push(format!("firmware {}", rec.firmware));
        }
        if let Some(hw) = rec.hardware_revision {
            recorder.push(format!("hardware revision {hw}"));
        }
        if let Some(t) = rec.manufactured_unix_s.and_then(|t| i64::try_from(t).ok()) {
            recorder.push(format!("made {}", provenance::iso8601_date(t)));
        }
        recorder.retain(|s| !s.is_empty());
        row(
            h,
            "Recorder",
            &if recorder.is_empty() {
                "not named in the file".to_string()
            } else {
                recorder.join(", ")
            },
        );
        let sensor = match (&r.sensor, &r.subchannel) {
            (Some(s), Some(sub)) => format!(
                "{}{} (subchannel {sub})",
                s.name,
                s.serial
                    .as_ref()
                    .map_or(String::new(), |n| format!(", serial {n}"))
            ),
            (None, Some(sub)) => format!("not named in the file (subchannel {sub})"),
            _ => "not named in the file".to_string(),
        };
        row(h, "Sensor", &sensor);
        let c = &r.calibration;
        let date = |t: Option<u64>| {
            t.and_then(|t| i64::try_from(t).ok())
                .map(provenance::iso8601_date)
        };
        let mut cal = Vec::new();
        if let Some(d) = date(c.date_unix_s) {
            cal.push(format!("calibrated {d}"));
        }
        if let Some(n) = c.serial {
            cal.push(format!("calibration no. {n}"));
        }
        cal.push(match date(c.expiry_unix_s) {
            Some(d) => format!("due {d}"),
            None => "no expiry recorded".to_string(),
        });
        row(h, "Factory calibration", &cal.join(", "));
    }
    h.raw("</table>\n");
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_meta_file_takes_equals_or_colons_comments_and_blank_lines() {
        let text = "\u{feff}# the drop of 29 November\ntest-id = T-0042\n\noperator: A. Smith\nnote = ratio 1:2\nurl: http://lab/x=1\n";
        assert_eq!(
            parse_meta_file(text).unwrap(),
            [
                ("test-id".to_string(), "T-0042".to_string()),
                ("operator".into(), "A. Smith".into()),
                ("note".into(), "ratio 1:2".into()),
                ("url".into(), "http://lab/x=1".into()),
            ]
        );
        assert_eq!(
            parse_meta_file("a = 1\nno separator\n"),
            Err((2, MetaLineError::NoSeparator))
        );
        assert_eq!(parse_meta_file("= 1\n"), Err((1, MetaLineError::EmptyKey)));
        assert_eq!(
            parse_meta_file("a = 1\nb = 2\na: 3\n"),
            Err((3, MetaLineError::Twice("a".into())))
        );
        assert_eq!(
            parse_meta_file("a = x\u{7}y\n"),
            Err((1, MetaLineError::Control("the value")))
        );
    }

    #[test]
    fn the_command_line_follows_the_file_and_overrides_its_key() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("meta.txt");
        std::fs::write(&file, "test-id = T-1\noperator = B\n").unwrap();
        let args = MetaArgs {
            meta: vec![
                ("dut".into(), "bracket".into()),
                ("test-id".into(), "T-2".into()),
            ],
            meta_file: Some(file),
        };
        assert_eq!(
            read_meta(&args).unwrap(),
            [
                ("test-id".to_string(), "T-2".to_string()),
                ("operator".into(), "B".into()),
                ("dut".into(), "bracket".into()),
            ]
        );
        assert_eq!(parse_meta("x = 1 = 2"), Ok(("x".into(), "1 = 2".into())));
        assert_eq!(parse_meta("x: 1"), Err(MetaLineError::NoEquals));
        assert_eq!(label("Test_ID"), "Test ID");
        assert_eq!(label("DUT"), "Device under test");
        assert_eq!(label("shaker"), "shaker");
    }
}
