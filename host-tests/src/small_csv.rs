//! Small CSV files a user writes by hand (a tolerance band, a required SRS): read whole up to
//! 1 MiB, lines numbered as an editor numbers them (LF or CRLF), `#` comment lines and blank
//! lines skipped, fields split on commas and trimmed (surrounding quotes dropped).

use std::path::Path;

/// Largest file read, bytes (a hand-written table takes a few KiB).
const MAX_BYTES: u64 = 1 << 20;

/// A small CSV: its header's names, and each further line's number (from 1) and fields.
#[derive(Debug)]
pub struct SmallCsv {
    pub header: Vec<String>,
    pub rows: Vec<(usize, Vec<String>)>,
}

impl SmallCsv {
    /// Reads `path` (`what` names the kind of file in the size error). Errors are the bare
    /// reason, for the caller to prefix with the option and file.
    pub fn read(path: &Path, what: &str) -> Result<Self, String> {
        let bytes = impact_io::read_limited(path, MAX_BYTES, what).map_err(|e| {
            // read_limited names the file; the caller does too.
            e.strip_prefix(&format!("{}: ", path.display()))
                .unwrap_or(&e)
                .to_string()
        })?;
        let text = String::from_utf8(bytes).map_err(|_| "not UTF-8 text".to_string())?;
        let mut lines = text.lines().enumerate().filter_map(|(i, line)| {
            let line = line.trim();
            (!line.is_empty() && !line.starts_with('#')).then(|| {
                let fields = line
                    .split(',')
                    .map(|f| f.trim().trim_matches('"').to_string())
                    .collect();
                (i + 1, fields)
            })
        });
        let Some((_, header)) = lines.next() else {
            return Err("empty: no header".into());
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_are_numbered_as_an_editor_numbers_them() {
        let dir = std::env::temp_dir().join(format!("small-csv-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("t.csv");
        std::fs::write(
            &path,
            "# a\r\n\"Time_S\", x \r\n\r\n1,2\r\n# b\r\n3 , \"4\"\r\n",
        )
        .unwrap();
        let t = SmallCsv::read(&path, "table").unwrap();
        assert_eq!(t.header, ["Time_S", "x"]);
        assert_eq!(t.column("time_s"), Some(0));
        assert_eq!(
            t.rows,
            [
                (4, vec!["1".to_string(), "2".into()]),
                (6, vec!["3".into(), "4".into()])
            ]
        );
        std::fs::write(&path, "# only\n\n").unwrap();
        assert!(SmallCsv::read(&path, "table")
            .unwrap_err()
            .contains("no header"));
        let _ = std::fs::remove_dir_all(&dir);
    }
}
