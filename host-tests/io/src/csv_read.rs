//! Reading a CSV past its head: the one hand-over between the sequential row reader
//! ([`Rows`]: any line, every check) and the parallel one ([`csv_fast`]: plain rows in 1 MiB
//! chunks on worker threads), used by the whole-table reader ([`read_table`]) and by a CSV
//! read in passes or as a stream (`sources::CsvSource`).

use std::path::Path;

use super::channel::CsvFormat;
use super::csv_fast::{self, FastRows, Layout, Parsed};
use super::error::ReadError;
use super::table::{Row, Rows, Table};

/// What the next read gives.
pub enum Step<'a> {
    /// One row from the sequential reader: its line, the line breaks inside it, its values.
    Row(Row<'a>),
    /// A chunk of plain rows from the parallel reader.
    Chunk(Parsed),
    /// The input has ended.
    End,
}

/// A CSV read past its head: [`Rows`] until [`csv_fast::SEQUENTIAL_ROWS`] rows in a row were
/// read, then [`FastRows`] (a file read again from that row, or a stream's tape played from
/// it) until a line it cannot take, from which [`Rows`] goes on.
pub struct Handover {
    pub rows: Rows,
    fast: Option<FastRows>,
    /// Rows the sequential reader read since it last took over.
    sequential: usize,
    /// Where the parallel reader stopped: the sequential one resumes there next.
    resume_at: Option<(u64, u64)>,
    progress: crate::progress::Progress,
}

/// Why the hand-over failed: the input could not be opened again at a line, or resuming the
/// sequential reader failed.
pub enum HandoverError {
    Input { line: u64, error: std::io::Error },
    Rows(ReadError),
}

impl Handover {
    /// Starts with the sequential reader; the parallel one may take over once `sequential`
    /// rows have been read (0: not before [`csv_fast::SEQUENTIAL_ROWS`] rows, which is what
    /// a head read row by row leaves `sequential` at).
    pub fn new(rows: Rows, sequential: usize, progress: crate::progress::Progress) -> Self {
        Self {
            rows,
            fast: None,
            sequential,
            resume_at: None,
            progress,
        }
    }

    /// The next row or chunk. `fast` says whether the parallel reader may take over now and
    /// gives its layout.
    pub fn next(
        &mut self,
        fast: Option<&dyn Fn(&Rows) -> Layout>,
    ) -> Result<Step<'_>, HandoverError> {
        if let Some((byte, line)) = self.resume_at.take() {
            self.rows = self.rows.resume(byte, line).map_err(HandoverError::Rows)?;
            self.sequential = 0;
        }
        if let Some(layout) =
            fast.filter(|_| self.fast.is_none() && self.sequential >= csv_fast::SEQUENTIAL_ROWS)
        {
            let (byte, line) = self.rows.position();
            let input = self
                .rows
                .input_from(byte)
                .map_err(|error| HandoverError::Input { line, error })?;
            self.fast = Some(FastRows::start(
                input,
                (byte, line),
                layout(&self.rows),
                self.rows
                    .size()
                    .filter(|_| self.progress.is_shown())
                    .map(|size| (self.progress.clone(), size)),
                self.rows.tape(),
            ));
        }
        if let Some(reader) = &mut self.fast {
            let Some(chunk) = reader.next_chunk() else {
                self.fast = None;
                return Ok(Step::End);
            };
            if let Some(stop) = chunk.stop {
                // The sequential reader from the line the parallel one could not take.
                self.fast = None;
                self.resume_at = Some(stop);
            }
            return Ok(Step::Chunk(chunk));
        }
        match self.rows.next_row().map_err(HandoverError::Rows)? {
            None => Ok(Step::End),
            Some(row) => {
                self.sequential += 1;
                Ok(Step::Row(row))
            }
        }
    }
}

/// Reads a whole numeric table ([`Rows`]; plain rows past the first few thousand through the
/// parallel reader).
pub fn read_table(
    path: &Path,
    format: &CsvFormat,
    progress: crate::progress::Progress,
) -> Result<Table, ReadError> {
    let rows = Rows::open(path, format, progress.clone())?;
    let mut reader = Handover::new(rows, 0, progress);
    let mut table = Table::default();
    let mut next_line = 0;
    let mut n = 0usize;
    loop {
        let columns = table.columns.len();
        let layout = move |rows: &Rows| Layout {
            columns,
            channel: 0,
            time: None,
            delimiter: rows.format().0,
            decimal_comma: rows.format().1.decimal_comma,
            time_unit_s: 1.0,
            increasing: false,
            median_dt: None,
            all: true,
        };
        let step = match reader.next(Some(&layout)) {
            Ok(step) => step,
            Err(HandoverError::Input { line, error }) => {
                return Err(reader.rows.err(Some(line), error.into()))
            }
            Err(HandoverError::Rows(e)) => return Err(e),
        };
        match step {
            Step::End => break,
            Step::Chunk(chunk) => {
                if !chunk.rows.is_empty() && chunk.line != next_line {
                    table.breaks.push((n, chunk.line));
                }
                for row in chunk.fields.chunks_exact(table.columns.len().max(1)) {
                    for (c, v) in table.columns.iter_mut().zip(row) {
                        c.push(*v);
                    }
                }
                n += chunk.rows.len();
                next_line = chunk.line + chunk.rows.len() as u64;
            }
            Step::Row((lineno, breaks, row)) => {
                if table.columns.is_empty() {
                    table.columns = vec![Vec::new(); row.len()];
                    table.first_data_line = lineno;
                    next_line = lineno;
                }
                if lineno != next_line {
                    table.breaks.push((n, lineno));
                }
                next_line = lineno + breaks + 1;
                for (c, v) in table.columns.iter_mut().zip(row) {
                    c.push(*v);
                }
                n += 1;
            }
        }
    }
    if table.columns.first().is_none_or(|c| c.is_empty()) {
        return Err(ReadError::new(path, reader.rows.no_data_rows()));
    }
    table.headers = reader.rows.headers;
    Ok(table)
}
