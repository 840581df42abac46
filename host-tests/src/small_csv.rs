//! Small CSV files a user writes by hand (a tolerance band, a required SRS): read whole up to
//! 1 MiB, lines numbered as an editor numbers them (LF or CRLF), a byte-order mark (Excel's
//! "CSV UTF-8") dropped, `#` comment lines and blank lines skipped, each line's fields read by
//! the `csv` crate (a quoted `"a,b"` is one field) and trimmed.

use std::path::Path;

/// Largest file read, bytes (a hand-written table takes a few KiB).
const MAX_BYTES: u64 = 1 << 20;

/// A small CSV: its header's names, and each further line's number (from 1) and fields.
#[derive(Debug)]
pub struct SmallCsv {
    pub header: Vec<String>,
    pub rows: Vec<(usize, Vec<String>)>,
}

/// Why a small CSV could not be read. Its text is the bare reason: the caller names the
/// option and the file.
#[derive(Debug, thiserror::Error)]
pub enum SmallCsvError {
    /// Not read ([`impact_io::read_limited`]: a missing file, one over 1 MiB); the file's
    /// kind of failure without its name.
    #[error("{}", crate::read_errors::kind_message(&.0.kind))]
    Read(impact_io::ReadError),
    #[error("not UTF-8 text")]
    NotUtf8,
    #[error("empty: no header")]
    NoHeader,
    #[error("line {line}: {source}")]
    Line { line: usize, source: csv::Error },
}

impl SmallCsv {
    /// Reads `path` (`what` names the kind of file in the size error).
    pub fn read(path: &Path, what: &'static str) -> Result<Self, SmallCsvError> {
        let bytes = impact_io::read_limited(path, MAX_BYTES, what).map_err(SmallCsvError::Read)?;
        let text = String::from_utf8(bytes).map_err(|_| SmallCsvError::NotUtf8)?;
        let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
        let mut lines = Vec::new();
        for (i, line) in text.lines().enumerate() {
            let line = line.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            let fields = fields(line).map_err(|source| SmallCsvError::Line {
                line: i + 1,
                source,
            })?;
            lines.push((i + 1, fields));
        }
        let mut lines = lines.into_iter();
        let Some((_, header)) = lines.next() else {
            return Err(SmallCsvError::NoHeader);
        };
        Ok(Self {
            header,
            rows: lines.collect(),
        })
    }

    /// The column named `name` (in any case).
    pub fn column(&self, name: &str) -> Option<usize> {
        self.header
            .iter()
            .position(|h| h.eq_ignore_ascii_case(name))
    }
}

/// `line` without the spaces after each comma outside quotes, so that a field quoted after
/// a space (`3, "4,5"`) is read as quoted (the `csv` crate takes a quote only as a field's
/// first character).
fn tight(line: &str) -> String {
    let mut out = String::with_capacity(line.len());
    let (mut quoted, mut after_comma) = (false, false);
    for c in line.chars() {
        if after_comma && (c == ' ' || c == '\t') {
            continue;
        }
        after_comma = !quoted && c == ',';
        if c == '"' {
            quoted = !quoted;
        }
        out.push(c);
    }
    out
}

/// One line's fields, as the `csv` crate reads them after [`tight`] (quotes around a field,
/// `""` inside one), each trimmed.
fn fields(line: &str) -> Result<Vec<String>, csv::Error> {
    let line = tight(line);
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .trim(csv::Trim::All)
        // (A line ends at its `\n`: a lone `\r` inside it is text, as an editor shows it.)
        .terminator(csv::Terminator::Any(b'\n'))
        .from_reader(line.as_bytes());
    let mut record = csv::StringRecord::new();
    reader.read_record(&mut record)?;
    Ok(record.iter().map(str::to_string).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_are_numbered_as_an_editor_numbers_them() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.csv");
        std::fs::write(
            &path,
            "\u{feff}# a\r\n\"Time_S\", x \r\n\r\n1,2\r\n# b\r\n3 , \"4\"\r\n\"5,6\",7\n8, \"9,10\"\n11\r12,13\n",
        )
        .unwrap();
        let t = SmallCsv::read(&path, "table").unwrap();
        assert_eq!(t.header, ["Time_S", "x"]);
        assert_eq!(t.column("time_s"), Some(0));
        assert_eq!(
            t.rows,
            [
                (4, vec!["1".to_string(), "2".into()]),
                (6, vec!["3".into(), "4".into()]),
                (7, vec!["5,6".into(), "7".into()]),
                (8, vec!["8".into(), "9,10".into()]),
                (9, vec!["11\r12".into(), "13".into()])
            ]
        );
        std::fs::write(&path, "# only\n\n").unwrap();
        assert!(matches!(
            SmallCsv::read(&path, "table"),
            Err(SmallCsvError::NoHeader)
        ));
        std::fs::write(&path, "\u{feff}frequency_hz\n").unwrap();
        assert_eq!(
            SmallCsv::read(&path, "table").unwrap().header,
            ["frequency_hz"]
        );
    }
}
