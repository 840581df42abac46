//! The readers a recording is taken from a block at a time, one per format (CSV, WAV, .npy,
//! TDMS, raw), for a file read in passes or a stream (`impact_host::pipeline::streaming`): values as they
//! are read, the rate, the first time, and a CSV's checks as the whole-file path makes them.

use std::io::Read;

use std::path::{Path, PathBuf};

use super::channel::RawType;
use super::channel::{check_rate, is_stdin, ReadOptions};
use super::csv_fast::{Layout, Parsed};
use super::csv_read::{Handover, HandoverError, Step};
use super::quantise::Quantiser;
use super::table::Rows;
use super::time_axis::{NotIncreasing, TimeAxis, UnevenInterval};
use crate::channel::DriftFault;
use crate::error::{At, NpyFault, Numbered, ReadError, ReadErrorKind};

/// Samples whose noise sets the default edge level (the whole-file path uses the whole
/// recording's): the first 65 536.
pub const HEAD: usize = 1 << 16;

/// Bytes read at a time.
pub const CHUNK: usize = 1 << 16;

/// The first [`HEAD`] values × `scale` (fewer if the input is shorter); then what the head
/// tells is fixed ([`Source::head_read`]).
pub fn read_head(source: &mut dyn Source, scale: f64) -> Result<Vec<f64>, ReadError> {
    let mut head = Vec::with_capacity(HEAD);
    while head.len() < HEAD {
        let before = head.len();
        source.next_values(HEAD - head.len(), &mut head)?;
        if head.len() == before {
            break;
        }
    }
    for v in &mut head {
        *v *= scale;
    }
    source.head_read()?;
    Ok(head)
}

/// Where the stream's values come from.
pub trait Source: Send {
    /// Appends up to about `want` values to `out` (none at the end of the input).
    fn next_values(&mut self, want: usize, out: &mut Vec<f64>) -> Result<(), ReadError>;
    /// Appends up to about `want` values to `out` as counts (`to_count(v × scale, gain)`),
    /// through `scratch`.
    fn next_counts(
        &mut self,
        want: usize,
        q: Quantiser,
        scratch: &mut Vec<f64>,
        out: &mut Vec<i16>,
    ) -> Result<(), ReadError> {
        values_as_counts(self, want, q, scratch, out)
    }
    /// The head has been read: what it tells (a CSV's rate) is fixed, and checked.
    fn head_read(&mut self) -> Result<(), ReadError> {
        Ok(())
    }
    /// The rate the scene runs at (after the head).
    fn rate_hz(&self) -> Result<f64, ReadError>;
    /// The rate the report gives (at the end: a CSV's mean interval over the whole file, as
    /// the whole-file path computes it); the scene's by default.
    fn final_rate_hz(&self) -> f64 {
        self.rate_hz().unwrap_or(0.0)
    }
    /// Time of the first sample, s (0 without a time column).
    fn t0(&self) -> f64 {
        0.0
    }
    /// The channel's header (a CSV's column name; empty where the format names none), for
    /// the units it names.
    fn column(&self) -> &str {
        ""
    }

    /// The time column's header when its unit was assumed (seconds), as
    /// [`crate::channel::Channel::time_unit_assumed`].
    fn time_unit_assumed(&self) -> Option<String> {
        None
    }
}

/// [`Source::next_counts`] through [`Source::next_values`] and `scratch`.
fn values_as_counts<S: Source + ?Sized>(
    source: &mut S,
    want: usize,
    q: Quantiser,
    scratch: &mut Vec<f64>,
    out: &mut Vec<i16>,
) -> Result<(), ReadError> {
    scratch.clear();
    source.next_values(want, scratch)?;
    out.extend(scratch.iter().map(|&v| q.count(v)));
    Ok(())
}

/// A raw file or stream: the chosen channel of interleaved little-endian frames.
pub struct RawSource {
    input: Box<dyn Read + Send>,
    kind: RawType,
    /// Bytes per frame (all channels) and the channel's offset in it.
    frame: usize,
    at: usize,
    buf: Vec<u8>,
    /// Bytes in `buf` not yet used (a partial frame).
    held: usize,
    /// Bytes read so far.
    read: u64,
    path: PathBuf,
    rate_hz: f64,
    /// For 16-bit codes: each code's count under the quantiser.
    table: Option<(Quantiser, Vec<i16>)>,
    /// The channel's name, as the whole-file reader gives it (`channel N`).
    name: String,
}

impl RawSource {
    pub fn open(path: &Path, opts: &ReadOptions, kind: RawType) -> Result<Self, ReadError> {
        let err = |kind: ReadErrorKind| ReadError::new(path, kind);
        if opts.time_column.is_some() {
            return Err(err(ReadErrorKind::RawOptions));
        }
        let rate_hz = opts.rate_hz.ok_or_else(|| err(ReadErrorKind::RawNoTime))?;
        check_rate(rate_hz).map_err(err)?;
        let channels = opts.raw_channels.unwrap_or(1);
        if !(1..=64).contains(&channels) {
            return Err(err(ReadErrorKind::RawChannels { channels }));
        }
        let column = crate::channel::numbered_column(
            opts.column.as_ref(),
            channels,
            Numbered::StreamChannels,
        )
        .map_err(err)?;
        let input: Box<dyn Read + Send> = if is_stdin(path) {
            Box::new(std::io::stdin())
        } else {
            Box::new(std::fs::File::open(path).map_err(|e| err(e.into()))?)
        };
        Ok(Self {
            input,
            kind,
            frame: kind.bytes() * channels,
            at: column * kind.bytes(),
            buf: vec![0u8; CHUNK],
            held: 0,
            read: 0,
            path: path.to_path_buf(),
            rate_hz,
            table: None,
            name: format!("channel {column}"),
        })
    }
}

impl Source for RawSource {
    fn rate_hz(&self) -> Result<f64, ReadError> {
        Ok(self.rate_hz)
    }

    fn column(&self) -> &str {
        &self.name
    }

    fn next_values(&mut self, want: usize, out: &mut Vec<f64>) -> Result<(), ReadError> {
        let (kind, frame, at) = (self.kind, self.frame, self.at);
        self.next_with(want, |bytes| kind.decode(bytes, frame, at, |v| out.push(v)))
    }

    /// 16-bit codes through a table of the 65 536 codes' counts (the same arithmetic, once
    /// per code).
    fn next_counts(
        &mut self,
        want: usize,
        q: Quantiser,
        scratch: &mut Vec<f64>,
        out: &mut Vec<i16>,
    ) -> Result<(), ReadError> {
        if self.kind != RawType::I16 {
            return values_as_counts(self, want, q, scratch, out);
        }
        let table = match self.table.take() {
            Some(t) if t.0 == q => t,
            _ => (
                q,
                (0..=u16::MAX)
                    .map(|c| q.count(f64::from(c as i16)))
                    .collect(),
            ),
        };
        let (frame, at) = (self.frame, self.at);
        let result = self.next_with(want, |bytes| {
            out.extend(bytes.chunks_exact(frame).map(|f| {
                let code = u16::from_le_bytes([f[at], f[at + 1]]);
                table.1.get(usize::from(code)).copied().unwrap_or(0)
            }));
            Ok(())
        });
        self.table = Some(table);
        result
    }
}

impl RawSource {
    /// Reads at most `want` frames (the head stops at exactly HEAD samples whatever a pipe's
    /// reads return), at least one whole frame's room, and hands the whole frames to
    /// `decode`.
    fn next_with(
        &mut self,
        want: usize,
        decode: impl FnOnce(&[u8]) -> Result<(), (usize, f32)>,
    ) -> Result<(), ReadError> {
        let end = (self.held + want.max(1) * self.frame).min(self.buf.len());
        let n = loop {
            match self.input.read(&mut self.buf[self.held..end]) {
                Ok(n) => break n,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
                Err(e) => return Err(ReadError::new(&self.path, e)),
            }
        };
        if n == 0 {
            if self.held > 0 {
                return Err(ReadError::new(
                    &self.path,
                    ReadErrorKind::RawStreamPartialFrame {
                        bytes: self.read,
                        frame: self.frame,
                        last_frame: self.read - self.held as u64,
                    },
                ));
            }
            return Ok(());
        }
        self.read += n as u64;
        let have = self.held + n;
        let whole = have / self.frame * self.frame;
        if let Err((k, v)) = decode(&self.buf[..whole]) {
            let frame_no = (self.read - have as u64) / self.frame as u64 + k as u64;
            return Err(ReadError::new(
                &self.path,
                ReadErrorKind::RawNotFinite {
                    frame: frame_no,
                    byte: frame_no * self.frame as u64 + self.at as u64,
                    value: v,
                },
            ));
        }
        self.buf.copy_within(whole..have, 0);
        self.held = have - whole;
        Ok(())
    }
}

/// A CSV file or stream: the channel's column, and the time column (or `--rate`), row by
/// row, with the whole-file reader's checks ([`crate::table::Rows`]).
pub struct CsvSource {
    /// The sequential reader, handing plain rows past the head to the parallel one.
    reader: Handover,
    /// One row's values (reused).
    row: Vec<f64>,
    path: PathBuf,
    channel: usize,
    /// The channel's header; the time column's, and its unit if given.
    column: String,
    time_header: String,
    time_unit: Option<crate::channel::TimeUnit>,
    /// The time column and its unit, s.
    time: Option<(usize, f64)>,
    /// `--rate`, if given.
    rate_given: Option<f64>,
    /// The time axis (the rows read; without a time column, only counted), and the head's
    /// mean rate.
    axis: TimeAxis,
    head_rate: Option<f64>,
    /// The first row's value, read while resolving the columns and not yet handed on.
    pending: Option<f64>,
    head_done: bool,
    ended: bool,
    /// The first time that does not increase, and the first uneven interval (reported at
    /// the end, in this order, as the whole-file path does), with their lines.
    not_increasing: Option<(u64, NotIncreasing)>,
    uneven: Option<(u64, UnevenInterval)>,
    /// The time stamps' drift check's first error (reported after those two).
    drifting: Option<(u64, DriftFault)>,
}

impl CsvSource {
    pub fn open(path: &Path, opts: &ReadOptions) -> Result<Self, ReadError> {
        let format = crate::channel::CsvFormat {
            delimiter: opts.format.delimiter,
            decimal_comma: opts.format.decimal_comma,
        };
        let mut rows = crate::table::Rows::open(path, &format, opts.progress.clone())?;
        let err = |kind: ReadErrorKind| ReadError::new(path, kind);
        // The first data row gives the columns their number (the header their names).
        let (line, first) = match rows.next_row()? {
            Some((line, _, row)) => (line, row.to_vec()),
            None => return Err(err(rows.no_data_rows())),
        };
        let shape = rows.shape();
        let tcol = shape
            .time_column_unless_rate(opts.rate_hz.is_some(), opts.time_column.as_ref())
            .map_err(err)?;
        // (With --rate a time column is not read, but it is no channel either.)
        let time_like = tcol.or_else(|| shape.time_column(None).ok().flatten());
        let channel = shape
            .channel(opts.column.as_ref(), time_like)
            .map_err(err)?;
        if Some(channel) == tcol {
            return Err(err(ReadErrorKind::ChannelIsTimeColumn {
                column: channel,
                axes: false,
            }));
        }
        if tcol.is_none() && opts.rate_hz.is_none() {
            return Err(err(ReadErrorKind::NoTimeColumn));
        }
        if let Some(r) = opts.rate_hz {
            check_rate(r).map_err(err)?;
        }
        let time_header = tcol
            .and_then(|t| shape.headers.get(t).cloned())
            .unwrap_or_default();
        let time = tcol.map(|t| (t, crate::channel::time_unit_s(&time_header, opts.time_unit)));
        let column = shape.headers.get(channel).cloned().unwrap_or_default();
        let mut source = Self {
            // The head is read row by row; the parallel reader may take over right after it.
            reader: Handover::new(
                rows,
                crate::csv_fast::SEQUENTIAL_ROWS,
                opts.progress.clone(),
            ),
            row: Vec::new(),
            path: path.to_path_buf(),
            channel,
            column,
            time_header,
            time_unit: opts.time_unit,
            time,
            rate_given: opts.rate_hz,
            axis: TimeAxis::new(opts.rate_hz.is_none()),
            head_rate: None,
            pending: None,
            head_done: false,
            ended: false,
            not_increasing: None,
            uneven: None,
            drifting: None,
        };
        source.pending = Some(source.take(line, &first));
        Ok(source)
    }

    /// Checks the time of row `line` and returns its channel's value.
    fn take(&mut self, line: u64, row: &[f64]) -> f64 {
        let value = row.get(self.channel).copied().unwrap_or(0.0);
        let time = self.time.map(|(c, _)| row.get(c).copied().unwrap_or(0.0));
        self.take_values(line, value, time.unwrap_or(0.0))
    }

    /// [`CsvSource::take`] of a row's channel value and time column's value.
    fn take_values(&mut self, line: u64, value: f64, time: f64) -> f64 {
        let Some((_, unit)) = self.time else {
            self.axis.count(1);
            return value;
        };
        // Errors wait for the end, as in the whole-file path: a value that is not a number
        // anywhere comes first, then time going back, then an uneven interval, then drift
        // (the first of each). With --rate the column gives only the first time, as in the
        // whole-file path (the axis does not check it).
        let faults = self.axis.push(time * unit, line);
        if let Some(e) = faults.drift {
            self.drifting.get_or_insert((line, e));
        }
        if let Some(e) = faults.not_increasing {
            self.not_increasing.get_or_insert((line, e));
        }
        if let Some(e) = faults.uneven {
            self.uneven.get_or_insert((line, e));
        }
        value
    }

    /// The first fault of the time axis, in the order the whole-file path reports them
    /// (taken: reported once).
    fn take_fault(&mut self) -> Option<ReadError> {
        let at = |line: u64, kind: ReadErrorKind| ReadError::at(&self.path, At::Line(line), kind);
        if let Some((line, e)) = self.not_increasing.take() {
            return Some(at(line, ReadErrorKind::NotIncreasing(e)));
        }
        if let Some((line, e)) = self.uneven.take() {
            return Some(at(line, ReadErrorKind::Uneven(e)));
        }
        let (line, e) = self.drifting.take()?;
        Some(at(line, ReadErrorKind::Drift(e)))
    }
}

impl CsvSource {
    /// Appends the next rows' values: about `want` (the sequential reader) or a chunk (the
    /// parallel one); none at a hand-over from one to the other, or at the end (then
    /// `ended` is set).
    fn next_some(&mut self, want: usize, out: &mut Vec<f64>) -> Result<(), ReadError> {
        // Past the head, plain rows go through the parallel reader (a file read again from
        // the row, or a stream's tape played from it), laid out for the channel and time
        // columns; its workers check what may still be the first error of its kind: time
        // going back, then an uneven interval.
        let (channel, time) = (self.channel, self.time);
        let increasing = self.rate_given.is_none() && self.not_increasing.is_none();
        let median_dt = self
            .axis
            .median_dt()
            .filter(|_| increasing && self.uneven.is_none());
        let layout = move |rows: &Rows| {
            let (delimiter, format) = rows.format();
            Layout {
                columns: rows.columns,
                channel,
                time: time.map(|(c, _)| c),
                delimiter,
                decimal_comma: format.decimal_comma,
                time_unit_s: time.map_or(1.0, |(_, unit)| unit),
                increasing,
                median_dt,
                all: false,
            }
        };
        let mut left = want.max(1);
        if let Some(v) = self.pending.take() {
            out.push(v);
            left -= 1;
        }
        let mut row = std::mem::take(&mut self.row);
        let mut read = 0;
        while read < left {
            // The parallel reader may take over only at the first row of a call.
            let fast = (self.head_done && read == 0).then_some(&layout as &dyn Fn(&Rows) -> Layout);
            let step = match self.reader.next(fast) {
                Ok(step) => step,
                Err(HandoverError::Input { error, .. }) => {
                    return Err(ReadError::new(&self.path, error))
                }
                Err(HandoverError::Rows(e)) => return Err(e),
            };
            match step {
                Step::End => {
                    self.ended = true;
                    break;
                }
                Step::Chunk(chunk) => {
                    self.row = row;
                    self.take_chunk(chunk, out);
                    return Ok(());
                }
                Step::Row((line, _, r)) => {
                    row.clear();
                    row.extend_from_slice(r);
                    let v = self.take(line, &row);
                    out.push(v);
                    read += 1;
                }
            }
        }
        self.row = row;
        Ok(())
    }

    /// A chunk of the parallel reader: the first row follows the previous chunk's last and
    /// is checked here; the others the worker checked against the row before them.
    fn take_chunk(&mut self, chunk: Parsed, out: &mut Vec<f64>) {
        out.reserve(chunk.rows.len());
        if let Some(&(value, time)) = chunk.rows.first() {
            out.push(self.take_values(chunk.line, value, time));
        }
        let rest = chunk.rows.iter().enumerate().skip(1);
        match self.time.map(|(_, unit)| unit) {
            Some(unit) => {
                for (k, &(value, time)) in rest {
                    if let Some(e) = self.axis.push_checked(time * unit) {
                        self.drifting.get_or_insert((chunk.line + k as u64, e));
                    }
                    out.push(value);
                }
            }
            None => {
                out.extend(rest.map(|(_, &(value, _))| value));
                self.axis.count(chunk.rows.len().saturating_sub(1) as u64);
            }
        }
    }
}

impl Source for CsvSource {
    fn next_values(&mut self, want: usize, out: &mut Vec<f64>) -> Result<(), ReadError> {
        // A hand-over between the readers can give no rows: only the end gives none.
        let before = out.len();
        while out.len() == before && !self.ended {
            self.next_some(want, out)?;
        }
        if self.ended {
            if let Some(e) = self.take_fault() {
                return Err(e);
            }
        }
        Ok(())
    }

    fn head_read(&mut self) -> Result<(), ReadError> {
        self.head_done = true;
        // The head's intervals against their median, as every later one.
        if let Some((line, e)) = self.axis.close_head() {
            self.uneven.get_or_insert((line, e));
        }
        if self.time.is_some() {
            // (None if time went back: `rate_hz` then gives that error.)
            self.head_rate = self.axis.rate_hz();
            if let (Some(rate), None) = (self.head_rate, self.rate_given) {
                crate::channel::check_time_unit(&self.time_header, self.time_unit, rate)
                    .map_err(|kind| ReadError::new(&self.path, kind))?;
            }
        }
        Ok(())
    }

    fn rate_hz(&self) -> Result<f64, ReadError> {
        if let Some(r) = self.rate_given {
            return Ok(r);
        }
        // A head without a rate: time went back (that error), or one sample.
        self.head_rate.ok_or_else(|| match self.not_increasing {
            Some((line, e)) => {
                ReadError::at(&self.path, At::Line(line), ReadErrorKind::NotIncreasing(e))
            }
            None => ReadError::new(&self.path, ReadErrorKind::OneSample),
        })
    }

    fn final_rate_hz(&self) -> f64 {
        match (self.rate_given, self.axis.rate_hz()) {
            (Some(r), _) => r,
            (None, Some(r)) => r,
            _ => self.head_rate.unwrap_or(0.0),
        }
    }

    fn t0(&self) -> f64 {
        self.axis.t0()
    }

    fn column(&self) -> &str {
        &self.column
    }

    fn time_unit_assumed(&self) -> Option<String> {
        self.time
            .filter(|_| self.rate_given.is_none())
            .and_then(|_| crate::channel::time_unit_assumed(&self.time_header, self.time_unit))
    }
}

/// An `.ide` file's subchannel, read block by block on a thread of its own
/// ([`crate::ide::Blocks`]), on the recorder's time stamps: the rate from the head's, every
/// interval checked against the head's median as a CSV's are.
pub struct IdeSource {
    blocks: crate::ide::Blocks,
    path: PathBuf,
    column: String,
    /// Values of the current block not yet handed on.
    pending: std::collections::VecDeque<f64>,
    axis: TimeAxis,
    head_rate: Option<f64>,
}

impl IdeSource {
    pub fn open(path: &Path, opts: &ReadOptions) -> Result<Self, ReadError> {
        let err = |kind: ReadErrorKind| ReadError::new(path, kind);
        if opts.rate_hz.is_some() || opts.time_column.is_some() {
            return Err(err(ReadErrorKind::IdeOwnTime));
        }
        let file = crate::ide::IdeFile::open(path).map_err(|e| err(e.into()))?;
        let pick = crate::ide::pick(&file, opts.column.as_ref(), &[]).map_err(err)?;
        drop(file);
        Ok(Self {
            blocks: crate::ide::Blocks::start(path, pick.channel, pick.subs[0]),
            path: path.to_path_buf(),
            column: pick.names[0].clone(),
            pending: std::collections::VecDeque::new(),
            axis: TimeAxis::new(true),
            head_rate: None,
        })
    }

    /// Takes the next block's times (checked) and values.
    fn refill(&mut self) -> Result<bool, ReadError> {
        let Some(block) = self.blocks.next_block() else {
            return Ok(false);
        };
        let (times, values) = block.map_err(|e| ReadError::new(&self.path, e))?;
        for &t in &times {
            // The first fault stops the read: drift, then time going back, then an uneven
            // interval.
            let n = self.axis.samples();
            let f = self.axis.push(t, n);
            let fault = match (f.drift, f.not_increasing, f.uneven) {
                (Some(e), _, _) => Some(ReadErrorKind::Drift(e)),
                (None, Some(e), _) => Some(ReadErrorKind::NotIncreasing(e)),
                (None, None, Some(e)) => Some(ReadErrorKind::Uneven(e)),
                (None, None, None) => None,
            };
            if let Some(kind) = fault {
                return Err(ReadError::at(&self.path, At::Sample(n), kind));
            }
        }
        self.pending.extend(values);
        Ok(true)
    }
}

impl Source for IdeSource {
    fn next_values(&mut self, want: usize, out: &mut Vec<f64>) -> Result<(), ReadError> {
        if self.pending.is_empty() && !self.refill()? {
            return Ok(());
        }
        let take = want.max(1).min(self.pending.len());
        out.extend(self.pending.drain(..take));
        Ok(())
    }

    fn head_read(&mut self) -> Result<(), ReadError> {
        if let Some((n, e)) = self.axis.close_head() {
            return Err(ReadError::at(
                &self.path,
                At::Sample(n),
                ReadErrorKind::Uneven(e),
            ));
        }
        if self.axis.median_dt().is_none() {
            return Err(ReadError::new(
                &self.path,
                ReadErrorKind::RateUnknown {
                    samples: self.axis.samples(),
                },
            ));
        }
        self.head_rate = self.axis.rate_hz();
        Ok(())
    }

    fn rate_hz(&self) -> Result<f64, ReadError> {
        self.head_rate
            .ok_or_else(|| ReadError::new(&self.path, ReadErrorKind::NoRate))
    }

    fn final_rate_hz(&self) -> f64 {
        self.axis.rate_hz().or(self.head_rate).unwrap_or(0.0)
    }

    fn t0(&self) -> f64 {
        self.axis.t0()
    }

    fn column(&self) -> &str {
        &self.column
    }
}

/// A WAV file's channel ([`crate::wav::WavChannel`], read as it goes).
pub struct WavSource {
    channel: crate::wav::WavChannel,
    /// The channel's name, as the whole-file reader gives it (`channel N`).
    name: String,
}

impl WavSource {
    pub fn open(path: &Path, opts: &ReadOptions) -> Result<Self, ReadError> {
        if opts.rate_hz.is_some() || opts.time_column.is_some() {
            return Err(ReadError::new(
                path,
                ReadErrorKind::WavGivesRate { resample: false },
            ));
        }
        let channel = crate::wav::WavChannel::open(path, opts.column.as_ref())?;
        let name = format!("channel {}", channel.column());
        Ok(Self { channel, name })
    }
}

impl Source for WavSource {
    fn next_values(&mut self, want: usize, out: &mut Vec<f64>) -> Result<(), ReadError> {
        for v in self.channel.by_ref().take(want.max(1)) {
            out.push(v?);
        }
        Ok(())
    }

    fn rate_hz(&self) -> Result<f64, ReadError> {
        Ok(self.channel.rate_hz)
    }

    fn column(&self) -> &str {
        &self.name
    }
}

/// An .npy array's column: every `cols`-th element from `column` on (C order), or the
/// `rows` elements after `column × rows` (Fortran order), as npyz reads them.
pub struct NpySource {
    elements: crate::npy::Elements,
    rows: u64,
    cols: u64,
    column: u64,
    fortran: bool,
    /// Elements read, values handed on.
    k: u64,
    given: u64,
    rate_hz: f64,
    path: PathBuf,
    /// The column's name, as the whole-file reader gives it (`column N`).
    name: String,
}

impl NpySource {
    pub fn open(path: &Path, opts: &ReadOptions) -> Result<Self, ReadError> {
        let err = |kind: ReadErrorKind| ReadError::new(path, kind);
        let rate_hz = opts.rate_hz.ok_or_else(|| err(ReadErrorKind::NpyNoTime))?;
        check_rate(rate_hz).map_err(err)?;
        if opts.time_column.is_some() {
            return Err(err(ReadErrorKind::NpyTimeColumn));
        }
        let (elements, shape, order) = crate::npy::open_elements(path)?;
        let (rows, cols, column) = crate::npy::layout(&shape, opts.column.as_ref()).map_err(err)?;
        let column = column as u64;
        Ok(Self {
            elements,
            rows,
            cols,
            column,
            fortran: order == npyz::Order::Fortran && cols > 1,
            k: 0,
            given: 0,
            rate_hz,
            path: path.to_path_buf(),
            name: format!("column {column}"),
        })
    }
}

impl Source for NpySource {
    fn next_values(&mut self, want: usize, out: &mut Vec<f64>) -> Result<(), ReadError> {
        let err = |fault: NpyFault| ReadError::new(&self.path, fault);
        let mut pushed = 0;
        while pushed < want.max(1) && self.given < self.rows {
            let Some(element) = self.elements.next() else {
                return Err(err(NpyFault::DataEnds {
                    element: self.k,
                    total: self.rows * self.cols,
                }));
            };
            let v = element.map_err(err)?;
            let mine = if self.fortran {
                self.k / self.rows == self.column
            } else {
                self.k % self.cols == self.column
            };
            self.k += 1;
            if mine {
                if !v.is_finite() {
                    return Err(err(NpyFault::NotFinite {
                        row: self.given,
                        value: v,
                    }));
                }
                out.push(v);
                pushed += 1;
                self.given += 1;
            }
        }
        Ok(())
    }

    fn rate_hz(&self) -> Result<f64, ReadError> {
        Ok(self.rate_hz)
    }

    fn column(&self) -> &str {
        &self.name
    }
}

/// A TDMS file's channel ([`crate::tdms::TdmsStream`], a range at a time).
pub struct TdmsSource {
    stream: crate::tdms::TdmsStream,
}

impl TdmsSource {
    pub fn open(path: &Path, opts: &ReadOptions) -> Result<Self, ReadError> {
        if opts.time_column.is_some() {
            return Err(ReadError::new(path, ReadErrorKind::TdmsOptions));
        }
        let stream = crate::tdms::TdmsStream::open(path, opts.column.as_ref(), opts.rate_hz)?;
        Ok(Self { stream })
    }
}

impl Source for TdmsSource {
    fn next_values(&mut self, want: usize, out: &mut Vec<f64>) -> Result<(), ReadError> {
        self.stream.next_values(want, out)
    }

    fn rate_hz(&self) -> Result<f64, ReadError> {
        Ok(self.stream.rate_hz)
    }

    fn column(&self) -> &str {
        &self.stream.name
    }
}
