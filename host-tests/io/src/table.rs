//! Numeric tables from CSV text (a file or stdin), on the `csv` crate: header lines, the
//! delimiter, decimal commas, quoting and a UTF-8 byte-order mark handled; every size bounded.

use std::fs::File;
use std::io::{self, BufRead, BufReader, Read};
use std::path::Path;
use std::sync::Arc;

use crate::channel::is_stdin;
use crate::channel::words;
use crate::channel::ColumnRef;
use crate::channel::CsvFormat;
use crate::error::{NumberHint, ReadError, ReadErrorKind, RecordFault};
pub use crate::limits::{MAX_LINE_BYTES, MAX_VALUE};
use crate::tape::Tape;

/// All numeric columns of a CSV file, with the header names.
#[derive(Clone, Debug, Default)]
pub struct Table {
    pub headers: Vec<String>,
    pub columns: Vec<Vec<f64>>,
    /// Line of the first data row (1-based).
    pub first_data_line: u64,
    /// `(row, line)` wherever a data row is not on the line after the previous one (blank
    /// lines or quoted line breaks in between), so rows map back to lines.
    pub breaks: Vec<(usize, u64)>,
}

impl Table {
    /// The file line of data row `row` (0-based).
    pub fn line_of(&self, row: usize) -> u64 {
        match self.breaks.partition_point(|&(r, _)| r <= row) {
            0 => self.first_data_line + row as u64,
            i => {
                let (r, l) = self.breaks[i - 1];
                l + (row - r) as u64
            }
        }
    }
}

/// How far behind its reading the sequential reader may still hand over on a stream's tape:
/// a record (at most [`MAX_LINE_BYTES`]) and the `BufReader`'s and `csv`'s buffers (64 KiB
/// each), with room to spare. The tape is released up to there as the reader reads, so a
/// run of blank lines or of long rows is not held.
const SEQUENTIAL_TRAIL: u64 = MAX_LINE_BYTES as u64 + (1 << 18);

/// The sequential reader's input on a stream's tape from `byte` on, releasing it
/// [`SEQUENTIAL_TRAIL`] behind.
fn sequential_reader(tape: &Arc<Tape>, byte: u64) -> io::Result<Box<dyn Read + Send>> {
    Ok(Box::new(
        tape.reader_at(byte)?.releasing_behind(SEQUENTIAL_TRAIL),
    ))
}

/// Counts bytes since the last record end (a line break outside quotes, as `csv-core` reads
/// quotes: opened at a field's start, `""` inside them an escaped quote) and fails past
/// [`MAX_LINE_BYTES`], or at the end of the input inside a quote, naming the line where
/// the record or the quote began ([`RecordLimit::failed_at`]); also reports how many bytes
/// went through, for progress.
struct RecordLimit<R> {
    inner: R,
    delimiter: u8,
    since_break: usize,
    quote: Quote,
    field_start: bool,
    read: u64,
    /// Line breaks read so far, and their count where the record (the last line break
    /// outside quotes) and the open quote began.
    breaks: u64,
    record_breaks: u64,
    quote_breaks: u64,
    /// Line breaks before the line that failed (counted as `breaks`), once it has.
    failed_at: Option<u64>,
    /// The last byte read, and whether the input has ended.
    last: u8,
    ended: bool,
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Quote {
    Outside,
    Inside,
    /// A quote inside quotes: the end of the quoted text, or the first half of `""`.
    Closing,
}

impl<R: Read> Read for RecordLimit<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let mut n = self.inner.read(buf)?;
        if n == 0 && !self.ended && !buf.is_empty() {
            if self.quote == Quote::Inside {
                // (csv would take the rest of the input for one field.)
                return Err(self.fail(self.quote_breaks, RecordFault::QuoteNeverClosed));
            }
            // Every record ends with a line break, so that its line is `csv`'s line count
            // less one (see `read_table`).
            self.ended = true;
            if self.read > 0 && self.last != b'\n' {
                buf[0] = b'\n';
                n = 1;
            }
        }
        if n > 0 {
            self.last = buf[n - 1];
        }
        self.read += n as u64;
        let chunk = &buf[..n];
        if self.quote == Quote::Outside && !chunk.contains(&b'"') {
            // The common case, without a byte-by-byte walk: only line breaks matter.
            self.breaks += chunk.iter().filter(|&&b| b == b'\n').count() as u64;
            match chunk.iter().rposition(|&b| b == b'\n') {
                Some(p) => {
                    self.since_break = n - p - 1;
                    self.record_breaks = self.breaks;
                }
                None => self.since_break += n,
            }
            if let Some(&b) = chunk.last() {
                self.field_start = matches!(b, b'\n' | b'\r') || b == self.delimiter;
            }
            self.check()?;
            return Ok(n);
        }
        for &b in chunk {
            self.breaks += u64::from(b == b'\n');
            match self.quote {
                Quote::Inside => {
                    if b == b'"' {
                        self.quote = Quote::Closing;
                    }
                    self.since_break += 1;
                    self.check()?;
                    continue;
                }
                Quote::Closing if b == b'"' => {
                    self.quote = Quote::Inside;
                    self.since_break += 1;
                    continue;
                }
                Quote::Closing => self.quote = Quote::Outside,
                Quote::Outside => {}
            }
            if b == b'\n' {
                self.since_break = 0;
                self.record_breaks = self.breaks;
                self.field_start = true;
            } else {
                if b == b'"' && self.field_start {
                    self.quote = Quote::Inside;
                    self.quote_breaks = self.breaks;
                }
                self.field_start = b == self.delimiter || b == b'\r';
                self.since_break += 1;
                self.check()?;
            }
        }
        Ok(n)
    }
}

impl<R> RecordLimit<R> {
    /// The limit over `inner`, read from the start of a line on (its first line's breaks
    /// counted from 0).
    fn new(inner: R, delimiter: u8) -> Self {
        Self {
            inner,
            delimiter,
            since_break: 0,
            quote: Quote::Outside,
            field_start: true,
            read: 0,
            breaks: 0,
            record_breaks: 0,
            quote_breaks: 0,
            failed_at: None,
            last: 0,
            ended: false,
        }
    }

    fn check(&mut self) -> io::Result<()> {
        if self.since_break <= MAX_LINE_BYTES {
            return Ok(());
        }
        Err(if self.quote == Quote::Outside {
            self.fail(self.record_breaks, RecordFault::LineTooLong)
        } else {
            self.fail(self.quote_breaks, RecordFault::QuoteTooLong)
        })
    }

    /// The error of a record that began after `breaks` line breaks (the fault inside an
    /// `io::Error`, as `csv` passes its input's errors on).
    fn fail(&mut self, breaks: u64, fault: RecordFault) -> io::Error {
        self.failed_at = Some(breaks);
        io::Error::new(io::ErrorKind::InvalidData, fault)
    }
}

/// Opens a file (or stdin for `-`) once, for reading (a FIFO is not opened twice); the size,
/// if known, for progress.
fn open(path: &Path) -> Result<(Box<dyn Read + Send>, Option<u64>), ReadErrorKind> {
    if is_stdin(path) {
        return Ok((Box::new(io::stdin()), None));
    }
    let file = File::open(path)?;
    let meta = file.metadata()?;
    if meta.is_dir() {
        return Err(ReadErrorKind::IsDirectory);
    }
    let size = meta.is_file().then_some(meta.len());
    Ok((Box::new(file), size))
}

/// The delimiter of `head` (the file's first bytes): tab if its lines hold one, else `;`,
/// else `,`.
fn sniff_delimiter(head: &[u8]) -> u8 {
    if head.contains(&b'\t') {
        b'\t'
    } else if head.contains(&b';') {
        b';'
    } else {
        b','
    }
}

/// A field's parts: the field trimmed, or, where white space lies inside it and `split`, each
/// run of other bytes (a row aligned with spaces read under another delimiter). An empty field stays
/// one empty field.
fn white_space_fields(field: &[u8], split: bool) -> impl Iterator<Item = &[u8]> {
    let field = field.trim_ascii();
    let inside = split && field.iter().any(|&b| b == b' ' || b == b'\t');
    let whole = (!inside).then_some(field);
    let parts = field
        .split(|&b| b == b' ' || b == b'\t')
        .filter(move |p| inside && !p.is_empty());
    whole.into_iter().chain(parts)
}

/// A decimal number (`1.5e-3`, `-2`, `.5`; also `NaN` and `inf`, refused by the caller).
fn parse_number(field: &[u8]) -> Option<f64> {
    match field.first() {
        // fast-float2 reads a leading `+` as std does.
        Some(_) => fast_float2::parse::<f64, _>(field).ok(),
        None => None,
    }
}

/// A trimmed field's number, its decimal commas read as points with `decimal_comma` (through
/// `scratch`).
pub fn read_number(field: &[u8], decimal_comma: bool, scratch: &mut Vec<u8>) -> Option<f64> {
    if decimal_comma && field.contains(&b',') {
        scratch.clear();
        scratch.extend(field.iter().map(|&b| if b == b',' { b'.' } else { b }));
        parse_number(scratch)
    } else {
        parse_number(field)
    }
}

/// A number a data row may hold: finite, within ±[`MAX_VALUE`].
pub fn is_reading(v: f64) -> bool {
    v.is_finite() && v.abs() <= MAX_VALUE
}

/// Why a field is not a number, with a hint where the layout suggests one.
fn not_a_number(field: &str, format: &CsvFormat, delimiter: u8) -> ReadErrorKind {
    let hint = if field.contains('\u{feff}') {
        Some(NumberHint::ByteOrderMark)
    } else if !format.decimal_comma && delimiter != b',' && field.contains(',') {
        Some(NumberHint::DecimalComma)
    } else {
        None
    };
    ReadErrorKind::NotANumber {
        field: field.to_string(),
        hint,
    }
}

/// A data row: its line, the number of line breaks it spans (quoted ones and its end), and
/// its values.
pub type Row<'a> = (u64, u64, &'a [f64]);

/// A numeric table's rows, read one at a time. Leading lines with a field that is not a
/// number are headers (the last one names the columns); from the first numeric row on, every
/// row must be numeric (finite, within ±[`MAX_VALUE`]) with the first row's number of fields,
/// at most the header's. Errors name the file and line.
pub struct Rows {
    path: std::path::PathBuf,
    format: CsvFormat,
    delimiter: u8,
    reader: csv::Reader<RecordLimit<BufReader<Box<dyn Read + Send>>>>,
    record: csv::ByteRecord,
    row: Vec<f64>,
    scratch: Vec<u8>,
    /// The header line's names (empty without one) and fields, and its line.
    pub headers: Vec<String>,
    header_fields: usize,
    header_line: u64,
    /// Fields per data row (0 before the first).
    pub columns: usize,
    /// Lines taken for headers, and the first text field of the second of them (a line
    /// after the header that still holds text: what kept the rows from being data).
    text_lines: u64,
    text_after_header: Option<(u64, String)>,
    /// The header line's first field names a column (is not empty).
    header_leads: bool,
    /// Line of the first data row.
    pub first_data_line: u64,
    /// Whether a data row's fields split further on white space (`None` before the first
    /// data row, which decides it for the file: tabs delimit, or no delimiter split it).
    /// Decided once, so a `,` table's later row of one field (`"1 234"`) is refused as the
    /// number it is not, not read as two columns.
    white_space: Option<bool>,
    /// Lines before the first one read (a reader resumed mid-file), and the file's bytes
    /// before the first one read (a byte-order mark, or a resumed reader's start).
    line_offset: u64,
    skip: u64,
    progress: crate::progress::Progress,
    size: Option<u64>,
    step: Option<u64>,
    next_progress: u64,
    /// A stream that cannot be read again (standard input, a pipe), kept from a record and
    /// the buffers behind the reading on ([`SEQUENTIAL_TRAIL`]), so that another reader can
    /// take over at a line ([`Rows::input_from`]).
    tape: Option<Arc<Tape>>,
}

impl Rows {
    /// Opens `path` (or stdin for `-`), past a byte-order mark, with the delimiter given or
    /// sniffed from the first bytes.
    pub fn open(
        path: &Path,
        format: &CsvFormat,
        progress: crate::progress::Progress,
    ) -> Result<Self, ReadError> {
        let (input, size) = open(path).map_err(|e| ReadError::new(path, e))?;
        Self::from_input(path, input, size, format, progress)
    }

    /// [`Rows::open`] on an input opened (`size`: a regular file's, `None` for a stream,
    /// which is read through a tape).
    fn from_input(
        path: &Path,
        input: Box<dyn Read + Send>,
        size: Option<u64>,
        format: &CsvFormat,
        progress: crate::progress::Progress,
    ) -> Result<Self, ReadError> {
        let err = |kind: ReadErrorKind| ReadError::new(path, kind);
        let (input, tape): (Box<dyn Read + Send>, _) = match size {
            Some(_) => (input, None),
            None => {
                let tape = Tape::new(input);
                let reader = sequential_reader(&tape, 0).map_err(|e| err(e.into()))?;
                (reader, Some(tape))
            }
        };
        let mut buffered = BufReader::with_capacity(1 << 16, input);
        // Peek at the first bytes for a byte-order mark and the delimiter.
        let head = buffered.fill_buf().map_err(|e| err(e.into()))?;
        let bom = head.starts_with(b"\xEF\xBB\xBF");
        let delimiter = format.delimiter.unwrap_or_else(|| sniff_delimiter(head));
        if bom {
            buffered.consume(3);
        }
        if format.decimal_comma && delimiter == b',' {
            return Err(err(ReadErrorKind::DecimalCommaDelimiter));
        }
        let mut rows = Self::build(path, format, delimiter, buffered, size, progress);
        rows.skip = if bom { 3 } else { 0 };
        rows.tape = tape;
        Ok(rows)
    }

    /// The reader over `input` (past any byte-order mark) with `delimiter`.
    fn build(
        path: &Path,
        format: &CsvFormat,
        delimiter: u8,
        input: BufReader<Box<dyn Read + Send>>,
        size: Option<u64>,
        progress: crate::progress::Progress,
    ) -> Self {
        let limited = RecordLimit::new(input, delimiter);
        let reader = csv::ReaderBuilder::new()
            .has_headers(false)
            .flexible(true)
            .delimiter(delimiter)
            // `\r` is trimmed as white space with the fields; only `\n` ends a record (see the
            // line count in `next`).
            .terminator(csv::Terminator::Any(b'\n'))
            .buffer_capacity(1 << 16)
            .from_reader(limited);
        let step = size.map(|s| (s / 20).max(1));
        Self {
            path: path.to_path_buf(),
            format: *format,
            delimiter,
            reader,
            record: csv::ByteRecord::new(),
            row: Vec::new(),
            scratch: Vec::new(),
            headers: Vec::new(),
            header_fields: 0,
            header_line: 0,
            columns: 0,
            text_lines: 0,
            text_after_header: None,
            header_leads: false,
            first_data_line: 0,
            white_space: None,
            line_offset: 0,
            skip: 0,
            progress,
            size,
            step,
            next_progress: step.unwrap_or(u64::MAX),
            tape: None,
        }
    }

    /// The same table read again from byte `byte` of the file, the start of line `line`,
    /// past its header and first data row (so what it reads there reads as it would have
    /// in one pass).
    pub fn resume(&self, byte: u64, line: u64) -> Result<Self, ReadError> {
        let input = match &self.tape {
            Some(tape) => sequential_reader(tape, byte),
            None => self.input_from(byte),
        }
        .map_err(|e| self.err(Some(line), e.into()))?;
        // `csv` drops a byte-order mark at the start of its input: a line break (a blank
        // line, skipped) ahead of the line keeps one there in the row, which is refused as
        // on any line but the first.
        let ahead = u64::from(byte > 0);
        let lead: &'static [u8] = if byte > 0 { b"\n" } else { b"" };
        let input: Box<dyn Read + Send> = Box::new(lead.chain(input));
        let mut rows = Self::build(
            &self.path,
            &self.format,
            self.delimiter,
            BufReader::with_capacity(1 << 16, input),
            None,
            crate::progress::Progress::none(),
        );
        rows.headers = self.headers.clone();
        rows.header_fields = self.header_fields;
        rows.header_line = self.header_line;
        rows.columns = self.columns;
        rows.first_data_line = self.first_data_line;
        rows.white_space = self.white_space;
        // (Less the line break put ahead.)
        rows.line_offset = line.saturating_sub(1 + ahead);
        rows.skip = byte - ahead;
        rows.tape = self.tape.clone();
        Ok(rows)
    }

    /// The input from its byte `byte` on: the file opened again, or a stream's tape played
    /// from there (an error if that byte was released).
    pub fn input_from(&self, byte: u64) -> io::Result<Box<dyn Read + Send>> {
        use std::io::{Seek, SeekFrom};
        if let Some(tape) = &self.tape {
            return Ok(Box::new(tape.reader_at(byte)?));
        }
        let mut file = File::open(&self.path)?;
        file.seek(SeekFrom::Start(byte))?;
        Ok(Box::new(file))
    }

    /// A stream's tape (none for a regular file), for a reader that takes over to release
    /// what it has read.
    pub fn tape(&self) -> Option<Arc<Tape>> {
        self.tape.clone()
    }

    /// The size of the file opened (none for a stream, or a reader resumed mid-file).
    pub fn size(&self) -> Option<u64> {
        self.size
    }

    /// The byte of the file and the line the next row starts on.
    pub fn position(&self) -> (u64, u64) {
        let p = self.reader.position();
        (p.byte() + self.skip, p.line() + self.line_offset)
    }

    /// The delimiter and the format.
    pub fn format(&self) -> (u8, CsvFormat) {
        (self.delimiter, self.format)
    }

    /// Columns per data row, the field counts a header allows, for the fast path.
    pub fn header_fields(&self) -> usize {
        self.header_fields
    }

    /// The file read (`-` for stdin).
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// An error of the file read, at `line` if given.
    pub fn err(&self, line: Option<u64>, kind: ReadErrorKind) -> ReadError {
        ReadError {
            path: self.path.clone(),
            at: line.map(crate::error::At::Line),
            kind,
        }
    }

    /// The next data row ([`Row`]); `None` at the end.
    pub fn next_row(&mut self) -> Result<Option<Row<'_>>, ReadError> {
        loop {
            let more = match self.reader.read_byte_record(&mut self.record) {
                Ok(more) => more,
                Err(e) => {
                    // The line where the record (or its open quote) began, if the input
                    // failed on it; else the line being read (lines consumed so far, plus
                    // one).
                    let line = match self.reader.get_ref().failed_at {
                        Some(breaks) => breaks + 1,
                        None => e
                            .position()
                            .map_or(self.reader.position().line(), |p| p.line()),
                    } + self.line_offset;
                    return Err(self.err(Some(line), e.into()));
                }
            };
            if !more {
                return Ok(None);
            }
            // Every record ends with a consumed `\n` (the input's last one added if missing),
            // and `csv` counts lines as it consumes `\n`s: the record's line is the count less
            // its own line breaks (inside quotes, and the end).
            let breaks = self
                .record
                .as_slice()
                .iter()
                .filter(|&&b| b == b'\n')
                .count() as u64;
            let lineno = self.reader.position().line() - breaks - 1 + self.line_offset;
            if let (true, Some(size)) = (self.progress.is_shown(), self.size) {
                let read = self.reader.get_ref().read;
                if read >= self.next_progress {
                    self.progress.report(read as f64 / size.max(1) as f64);
                    self.next_progress = read + self.step.unwrap_or(u64::MAX);
                }
            }
            // Empty lines are no records; a line of delimiters and white space only is blank
            // too.
            if self.record.iter().all(|f| f.trim_ascii().is_empty()) {
                continue;
            }
            self.row.clear();
            let mut bad = None;
            let mut text_field = false;
            // A field with white space inside is several (a table whose columns are aligned
            // with spaces, as LabVIEW and many loggers write them, even under a header whose
            // names a tab separates): each run of spaces and tabs separates two fields. Only
            // where tabs delimit, or no delimiter split the line (a `;` or `,` table's field
            // with a space inside is an error: a thousands separator, say).
            // A tab at the line's start or end (LabVIEW ends every row with one) opens no
            // field; an empty field between two is still an error.
            let split = self
                .white_space
                .unwrap_or(self.delimiter == b'\t' || self.record.len() == 1);
            let last = self.record.len().saturating_sub(1);
            let edge =
                |k: usize, f: &[u8]| split && (k == 0 || k == last) && f.trim_ascii().is_empty();
            for f in self
                .record
                .iter()
                .enumerate()
                .filter(|&(k, f)| !edge(k, f))
                .flat_map(|(_, f)| white_space_fields(f, split))
            {
                match read_number(f, self.format.decimal_comma, &mut self.scratch) {
                    Some(v) if is_reading(v) => self.row.push(v),
                    Some(v) => {
                        bad.get_or_insert(ReadErrorKind::NotReading { value: v });
                    }
                    None => {
                        let text = String::from_utf8_lossy(f);
                        // A number written with a decimal comma is a number, not header text:
                        // a data row read without --decimal-comma is an error, not a header.
                        let comma_number = !self.format.decimal_comma
                            && text.contains(',')
                            && parse_number(text.replace(',', ".").as_bytes()).is_some();
                        text_field |= !comma_number;
                        bad.get_or_insert_with(|| {
                            not_a_number(&text, &self.format, self.delimiter)
                        });
                    }
                }
            }
            if self.columns == 0 {
                if text_field {
                    self.text_lines += 1;
                    if self.text_lines == 2 {
                        let text = self
                            .record
                            .iter()
                            .flat_map(|f| white_space_fields(f, split))
                            .find(|f| {
                                read_number(f, self.format.decimal_comma, &mut Vec::new()).is_none()
                            })
                            .map(|f| String::from_utf8_lossy(f).into_owned())
                            .unwrap_or_default();
                        self.text_after_header = Some((lineno, text));
                    }
                    // Text makes a header line; a number that is not finite or beyond any
                    // sensor is an error wherever it is (a NaN row before the data is not a
                    // header).
                    // The same edges as the data's: a tab at the header's start or end names
                    // no column.
                    self.headers = self
                        .record
                        .iter()
                        .enumerate()
                        .filter(|&(k, f)| !edge(k, f))
                        .map(|(_, f)| String::from_utf8_lossy(f.trim_ascii()).into_owned())
                        .collect();
                    self.header_fields = self.headers.len();
                    self.header_line = lineno;
                    self.header_leads = self
                        .record
                        .get(0)
                        .is_some_and(|f| !f.trim_ascii().is_empty());
                    continue;
                }
                // A row whose first field is empty under a header whose first field names a
                // column: dropping it would put every value under its neighbour's name.
                let leading_empty = split
                    && self.record.len() > 1
                    && self
                        .record
                        .get(0)
                        .is_some_and(|f| f.trim_ascii().is_empty());
                if bad.is_none() && leading_empty && self.header_leads {
                    return Err(self.err(
                        Some(lineno),
                        ReadErrorKind::EmptyUnderName {
                            name: self.headers.first().cloned().unwrap_or_default(),
                            header_line: self.header_line,
                        },
                    ));
                }
                if bad.is_none() {
                    // Rows split on white space under a header of one field: the header's
                    // names are split too (on tabs, else on runs of two or more spaces, else
                    // on each space), and must name every column.
                    if self.header_fields == 1 && self.row.len() > 1 && self.record.len() == 1 {
                        self.split_header(lineno)?;
                    }
                    // A row wider than its header has fields no name covers (decimal commas
                    // split in two, most often); a narrower one leaves names over, as the
                    // AFRL drop tower's files do (seven names, six columns), and is read.
                    if self.header_fields != 0 && self.row.len() > self.header_fields {
                        return Err(self.err(
                            Some(lineno),
                            ReadErrorKind::WiderThanHeader {
                                fields: self.row.len(),
                                header_line: self.header_line,
                                header_fields: self.header_fields,
                                comma_delimited: self.delimiter == b',',
                            },
                        ));
                    }
                    self.columns = self.row.len();
                    self.first_data_line = lineno;
                    self.white_space = Some(split);
                }
            }
            if let Some(kind) = bad {
                return Err(self.err(Some(lineno), kind));
            }
            if self.row.len() != self.columns {
                return Err(self.err(
                    Some(lineno),
                    ReadErrorKind::FieldCount {
                        fields: self.row.len(),
                        expected: self.columns,
                    },
                ));
            }
            return Ok(Some((lineno, breaks, &self.row)));
        }
    }

    /// The one-field header split into names for rows of `self.row.len()` white-space
    /// separated fields (the first data row, at `lineno`): on tabs if it has any, else on runs
    /// of two or more spaces, else on each space. Names that do not match the columns one to
    /// one are an error naming both (a guess would put a unit's name on a column).
    fn split_header(&mut self, lineno: u64) -> Result<(), ReadError> {
        let Some(header) = self.headers.first().cloned() else {
            return Ok(());
        };
        let names: Vec<String> = if header.contains('\t') {
            header
                .split('\t')
                .map(str::trim)
                .map(String::from)
                .collect()
        } else if header.contains("  ") {
            header
                .split("  ")
                .map(str::trim)
                .filter(|n| !n.is_empty())
                .map(String::from)
                .collect()
        } else {
            header.split_ascii_whitespace().map(String::from).collect()
        };
        if names.len() != self.row.len() {
            return Err(self.err(
                Some(lineno),
                ReadErrorKind::HeaderNamesColumns {
                    header_line: self.header_line,
                    names,
                    fields: self.row.len(),
                },
            ));
        }
        self.header_fields = names.len();
        self.headers = names;
        Ok(())
    }

    /// Why the file gave no data row: none at all, or lines that all held text (then the
    /// first one after the header and its text, which kept it from being data).
    pub fn no_data_rows(&self) -> ReadErrorKind {
        match &self.text_after_header {
            Some((line, field)) => ReadErrorKind::NoNumericRows {
                lines: self.text_lines,
                line: *line,
                field: field.clone(),
            },
            None => ReadErrorKind::NoDataRows,
        }
    }

    /// An empty table with this file's headers and number of columns (for resolving column
    /// names before the rows are read).
    pub fn shape(&self) -> Table {
        Table {
            headers: self.headers.clone(),
            columns: vec![Vec::new(); self.columns],
            first_data_line: self.first_data_line,
            breaks: Vec::new(),
        }
    }
}

impl Table {
    /// Resolves a column reference (`what`: `column`, `time column`, `axis`, as the error
    /// names it).
    pub fn find(&self, c: &ColumnRef, what: &'static str) -> Result<usize, ReadErrorKind> {
        let n = self.columns.len();
        match c {
            ColumnRef::Index(i) if *i < n => Ok(*i),
            ColumnRef::Index(i) => Err(ReadErrorKind::ColumnIndex {
                what,
                index: *i,
                fields: n,
            }),
            ColumnRef::Name(name) => self
                .headers
                .iter()
                .position(|h| h.eq_ignore_ascii_case(name))
                .filter(|&p| p < n)
                .ok_or_else(|| ReadErrorKind::ColumnName {
                    what,
                    name: name.clone(),
                    headers: self.headers.clone(),
                }),
        }
    }

    /// The time column to read: none when a rate is given and no time column asked for,
    /// else [`Self::time_column`].
    pub fn time_column_unless_rate(
        &self,
        rate_given: bool,
        asked: Option<&ColumnRef>,
    ) -> Result<Option<usize>, ReadErrorKind> {
        if rate_given && asked.is_none() {
            Ok(None)
        } else {
            self.time_column(asked)
        }
    }

    /// The channel: the column asked for, or the first one that is not the time column (a
    /// note on stderr names it when there are others to choose from).
    pub fn channel(
        &self,
        asked: Option<&ColumnRef>,
        time: Option<usize>,
    ) -> Result<usize, ReadErrorKind> {
        match asked {
            Some(c) => self.find(c, "column"),
            None => {
                let data: Vec<usize> = (0..self.columns.len())
                    .filter(|&c| Some(c) != time)
                    .collect();
                let first = *data.first().ok_or(ReadErrorKind::NoDataColumn)?;
                if data.len() > 1 {
                    let name = |c: usize| {
                        self.headers
                            .get(c)
                            .filter(|h| !h.is_empty())
                            .cloned()
                            .unwrap_or_else(|| format!("column {c}"))
                    };
                    crate::note_read(crate::ReadNote::ChannelChosen {
                        channel: name(first),
                        names: data.iter().map(|&c| name(c)).collect(),
                    });
                }
                Ok(first)
            }
        }
    }

    /// The time column: the one asked for, or the one column whose header looks like a time
    /// (`time…`, `t`, `t_…`); several such columns without `--time-column` are an error naming
    /// them.
    pub fn time_column(&self, asked: Option<&ColumnRef>) -> Result<Option<usize>, ReadErrorKind> {
        if let Some(c) = asked {
            return self.find(c, "time column").map(Some);
        }
        let candidates: Vec<usize> = (0..self.columns.len().min(self.headers.len()))
            .filter(|&c| looks_like_time(&self.headers[c]))
            .collect();
        match candidates.as_slice() {
            [] => Ok(None),
            [one] => Ok(Some(*one)),
            many => Err(ReadErrorKind::SeveralTimeColumns {
                headers: many.iter().map(|&c| self.headers[c].clone()).collect(),
            }),
        }
    }
}

/// Whether a header names a time column: its first word is `time`, `timestamp` or `t`.
fn looks_like_time(header: &str) -> bool {
    let h = header.to_ascii_lowercase();
    let first = words(&h).next();
    matches!(first, Some("time" | "timestamp" | "times" | "t"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::channel::parse_delimiter;
    use crate::csv_read::read_table;

    /// A stream read row by row holds only what a hand-over may still need: a run of blank
    /// lines or of long rows is released as it is read, not held until rows are counted.
    #[test]
    fn a_stream_read_row_by_row_holds_a_bounded_tail() {
        let mut text = String::from("t,a\n0,1\n");
        text.push_str(&"\n".repeat(40 << 20));
        let long = format!("1,{}2\n", "0".repeat(600_000));
        for _ in 0..64 {
            text.push_str(&long);
        }
        text.push_str("2,3\n");
        let input = Box::new(std::io::Cursor::new(text.into_bytes()));
        let mut rows = Rows::from_input(
            Path::new("-"),
            input,
            None,
            &CsvFormat::default(),
            crate::progress::Progress::none(),
        )
        .unwrap();
        let tape = rows.tape().unwrap();
        let mut most = 0;
        let mut n = 0;
        while let Some((line, _, row)) = rows.next_row().unwrap() {
            n += 1;
            if n == 2 {
                assert_eq!((line, row.len()), (40 * (1 << 20) + 3, 2));
            }
            most = most.max(tape.held());
        }
        assert_eq!(n, 66);
        assert!(most < 2 * SEQUENTIAL_TRAIL, "{most} bytes held");
    }

    fn read(text: &str, format: CsvFormat) -> Result<Table, ReadError> {
        let dir = std::env::temp_dir().join(format!("impact-table-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(format!(
            "{:x}.csv",
            text.len() * 31 + text.bytes().map(usize::from).sum::<usize>()
        ));
        std::fs::write(&path, text).unwrap();
        let t = read_table(&path, &format, crate::progress::Progress::none());
        std::fs::remove_file(&path).unwrap();
        t
    }

    #[test]
    fn quoted_fields_bom_and_semicolons() {
        let t = read(
            "\u{feff}\"time_s\";\"a\"\n\"0.0\";\"1.5\"\n0.5;2\n",
            CsvFormat::default(),
        )
        .unwrap();
        assert_eq!(t.headers, ["time_s", "a"]);
        assert_eq!(t.columns, [vec![0.0, 0.5], vec![1.5, 2.0]]);
    }

    #[test]
    fn decimal_commas_need_the_option_and_another_delimiter() {
        let text = "time_s;a\n0,0;6,771553e-1\n0,5;1,25\n";
        let e = read(text, CsvFormat::default()).unwrap_err().to_string();
        assert!(
            e.contains(":2: not a number: \"0,0\" (decimal commas? give `format.decimal_comma`)"),
            "{e}"
        );
        let t = read(
            text,
            CsvFormat {
                delimiter: None,
                decimal_comma: true,
            },
        )
        .unwrap();
        assert_eq!(t.columns[1], [0.6771553, 1.25]);
        let e = read(
            "a\n1,5\n",
            CsvFormat {
                delimiter: None,
                decimal_comma: true,
            },
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("`format.decimal_comma`: the delimiter is ','"),
            "{e}"
        );
    }

    #[test]
    fn a_row_wider_than_its_header_is_an_error_at_its_line() {
        let e = read("accel_g\n6,771553e-1\n", CsvFormat::default())
            .unwrap_err()
            .to_string();
        assert!(e.ends_with(":2: 2 fields, but the header (line 1) has 1 (decimal commas? give `format.decimal_comma` and `format.delimiter`)"), "{e}");
        let e = read("t,a\n0,1\n1,2,3\n", CsvFormat::default())
            .unwrap_err()
            .to_string();
        assert!(e.ends_with(":3: 3 fields, expected 2"), "{e}");
    }

    #[test]
    fn rows_map_back_to_lines_across_blank_lines() {
        let t = read("t,a\n\n0,1\n1,2\n\n\n2,3\n3,4\n", CsvFormat::default()).unwrap();
        assert_eq!(t.first_data_line, 3);
        let lines: Vec<u64> = (0..4).map(|r| t.line_of(r)).collect();
        assert_eq!(lines, [3, 4, 7, 8]);
    }

    #[test]
    fn an_unclosed_quote_or_endless_line_is_bounded() {
        // Reported at the line the quote was opened on (the text after it spans many), or
        // that the long line began on.
        let mut text = String::from("t,a\n0,1\n\"");
        text.push_str(&"1,2\n".repeat(MAX_LINE_BYTES / 4 + 10));
        let e = read(&text, CsvFormat::default()).unwrap_err().to_string();
        assert!(
            e.ends_with(":3: a quote opened on this line is not closed within 1048576 bytes"),
            "{e}"
        );
        let e = read("t,a\n0,1\n\"1,2\n3,4\n", CsvFormat::default())
            .unwrap_err()
            .to_string();
        assert!(
            e.ends_with(":3: a quote opened on this line is never closed"),
            "{e}"
        );
        let mut text = String::from("t,a\n0,1\n\n1,");
        text.push_str(&"2".repeat(MAX_LINE_BYTES + 10));
        let e = read(&text, CsvFormat::default()).unwrap_err().to_string();
        assert!(
            e.ends_with(":4: a line longer than 1048576 bytes: not a CSV recording"),
            "{e}"
        );
        // A quote inside a field is text, not an opening quote.
        let t = read("t,a 5\" bar\n0,1\n", CsvFormat::default()).unwrap();
        assert_eq!(t.headers, ["t", "a 5\" bar"]);
    }

    #[test]
    fn delimiters_are_parsed_by_name() {
        assert_eq!(parse_delimiter("tab"), Ok(b'\t'));
        assert_eq!(parse_delimiter(";"), Ok(b';'));
        assert!(parse_delimiter("ab").is_err());
        assert!(parse_delimiter("\"").is_err());
    }
}
