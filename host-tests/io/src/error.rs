//! What a reader's error is, typed: the file ([`ReadError::path`]), where in it (a line of a
//! text file or a sample, [`At`]) and what went wrong ([`ReadErrorKind`], its numbers, names
//! and the libraries' own errors as fields). The file is named once, by the Display.
//!
//! The readers do not know the command line: where a message tells the user to give an
//! option, it names a [`ReadOptions`](crate::ReadOptions) setting ([`Opt`]), which the Display
//! writes as the field (`` `rate_hz` ``) and a front end writes as it spells the option
//! ([`ReadErrorKind::display_with`] with its own [`OptionNames`]: the `impact` tool's flags).

use std::fmt;
use std::path::{Path, PathBuf};

use crate::limits::{number, sig, DRIFT_BLOCK, DRIFT_LIMIT, MAX_LINE_BYTES, MAX_VALUE, RATE_HZ};

/// A setting of the reading that a message asks for or refuses: the fields of
/// [`ReadOptions`](crate::ReadOptions) (and the channel's stated units).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Opt {
    /// [`ReadOptions::rate_hz`](crate::ReadOptions::rate_hz).
    Rate,
    TimeColumn,
    TimeUnit,
    Column,
    Axes,
    Resample,
    RawChannels,
    RawType,
    /// [`CsvFormat::decimal_comma`](crate::CsvFormat::decimal_comma).
    DecimalComma,
    /// [`CsvFormat::delimiter`](crate::CsvFormat::delimiter).
    Delimiter,
    /// The units a channel is stated to be in ([`crate::units::Units::resolve`]).
    Units,
}

impl Opt {
    /// The setting as this crate's messages name it: the field of
    /// [`ReadOptions`](crate::ReadOptions) (`` `rate_hz` ``).
    pub fn field(self) -> &'static str {
        match self {
            Opt::Rate => "`rate_hz`",
            Opt::TimeColumn => "`time_column`",
            Opt::TimeUnit => "`time_unit`",
            Opt::Column => "`column`",
            Opt::Axes => "`axes`",
            Opt::Resample => "`resample`",
            Opt::RawChannels => "`raw_channels`",
            Opt::RawType => "`raw_type`",
            Opt::DecimalComma => "`format.decimal_comma`",
            Opt::Delimiter => "`format.delimiter`",
            Opt::Units => "`units`",
        }
    }
}

/// How a message writes the settings it names: [`Opt::field`] by default; a front end passes
/// its own (the command line's option names).
pub type OptionNames = fn(Opt) -> &'static str;

/// Where in the file: a line of a text file (`name:LINE: …`) or a sample (`name: sample N:
/// …`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum At {
    Line(u64),
    Sample(u64),
}

/// A reader's error: the file (`-` for standard input, named `stdin`), where in it, and what.
#[derive(Debug, thiserror::Error)]
pub struct ReadError {
    pub path: PathBuf,
    pub at: Option<At>,
    #[source]
    pub kind: ReadErrorKind,
}

impl ReadError {
    /// An error of the file as a whole.
    pub fn new(path: &Path, kind: impl Into<ReadErrorKind>) -> Self {
        Self {
            path: path.to_path_buf(),
            at: None,
            kind: kind.into(),
        }
    }

    /// An error at a line or sample of the file.
    pub fn at(path: &Path, at: At, kind: impl Into<ReadErrorKind>) -> Self {
        Self {
            path: path.to_path_buf(),
            at: Some(at),
            kind: kind.into(),
        }
    }

    /// The message with the settings named by `names` (`name:LINE: what`).
    pub fn display_with(&self, names: OptionNames) -> impl fmt::Display + '_ {
        Rendered(move |f: &mut fmt::Formatter<'_>| {
            if !self.kind.names_the_file() {
                return self.kind.write(f, names);
            }
            let file = input_name(&self.path);
            match self.at {
                Some(At::Line(l)) => write!(f, "{file}:{l}: ")?,
                Some(At::Sample(n)) => write!(f, "{file}: sample {n}: ")?,
                None => write!(f, "{file}: ")?,
            }
            self.kind.write(f, names)
        })
    }
}

impl fmt::Display for ReadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.display_with(Opt::field).fmt(f)
    }
}

/// A closure as a Display.
struct Rendered<F>(F);

impl<F: Fn(&mut fmt::Formatter<'_>) -> fmt::Result> fmt::Display for Rendered<F> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        (self.0)(f)
    }
}

/// A column chosen by header name or 0-based index.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ColumnRef {
    Name(String),
    Index(usize),
}

impl std::str::FromStr for ColumnRef {
    type Err = std::convert::Infallible;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Ok(match s.parse::<usize>() {
            Ok(i) => ColumnRef::Index(i),
            Err(_) => ColumnRef::Name(s.to_string()),
        })
    }
}

impl fmt::Display for ColumnRef {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ColumnRef::Name(n) => f.write_str(n),
            ColumnRef::Index(i) => write!(f, "{i}"),
        }
    }
}

// The vocabulary of the errors: an input's name, a column, the time axis's faults, the
// readers' own errors.

/// An external library's message on one line (some span several, with pointers under a
/// quoted source).
pub fn one_line(message: impl std::fmt::Display) -> String {
    message
        .to_string()
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect::<Vec<_>>()
        .join(" ")
}

/// Whether a path names standard input (`-`).
pub fn is_stdin(path: &Path) -> bool {
    path.as_os_str() == "-"
}

/// Whether an input can be read only once, as it comes: standard input, or a path that names
/// no regular file (a FIFO, a serial port, a device such as `/dev/zero`). Such an input is
/// read in passes from a spool, never whole into memory (a FIFO's 30 MB took 462 MiB, a
/// device without end every byte there was).
pub fn reads_once(path: &Path) -> bool {
    is_stdin(path) || std::fs::metadata(path).is_ok_and(|m| !m.is_file() && !m.is_dir())
}

/// How messages name an input: `stdin`, or the path.
pub fn input_name(path: &Path) -> String {
    if is_stdin(path) {
        "stdin".to_string()
    } else {
        path.display().to_string()
    }
}

/// A time that does not increase.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NotIncreasing {
    /// The time, s, and the one before it.
    pub t: f64,
    pub previous: f64,
}

impl fmt::Display for NotIncreasing {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "time {} s does not increase (previous {} s)",
            self.t, self.previous
        )
    }
}

/// An interval far from the head's median: a gap or a rate change.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UnevenInterval {
    /// The interval, s.
    pub dt: f64,
    /// The head's median interval, s.
    pub median: f64,
}

impl UnevenInterval {
    /// The message, naming the settings as `n` does.
    pub(crate) fn write(&self, f: &mut fmt::Formatter<'_>, n: OptionNames) -> fmt::Result {
        let (dt, median) = (self.dt, self.median);
        let ratio = dt / median;
        write!(
            f,
            "uneven time axis: {dt:.6e} s since the previous sample, {ratio:.3} times the first \
             intervals' median {median:.6e} s (a gap or a rate change); give {} to \
             interpolate onto an even grid, or cut the file",
            n(Opt::Resample)
        )
    }
}

impl fmt::Display for UnevenInterval {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.write(f, Opt::field)
    }
}

/// A block of intervals whose mean is more than [`DRIFT_LIMIT`] off the first block's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DriftFault {
    /// The block's last sample (its first is [`DRIFT_BLOCK`] before).
    pub block_end: u64,
    /// The block's mean interval and the first block's, s.
    pub mean_dt: f64,
    pub first_dt: f64,
}

impl DriftFault {
    /// The message, naming the settings as `n` does.
    pub(crate) fn write(&self, f: &mut fmt::Formatter<'_>, n: OptionNames) -> fmt::Result {
        let (k, mean, first) = (self.block_end, self.mean_dt, self.first_dt);
        write!(
            f,
            "the time axis drifts: the mean interval of samples {}..{k} is {mean:.6e} s, \
             {:+.2} % off the first {DRIFT_BLOCK} intervals' {first:.6e} s (more than \
             {} %: no steady sample clock); give {} to interpolate onto an even \
             grid, or {} if the column is wrong",
            k - DRIFT_BLOCK,
            100.0 * (mean / first - 1.0),
            100.0 * DRIFT_LIMIT,
            n(Opt::Resample),
            n(Opt::Rate)
        )
    }
}

impl fmt::Display for DriftFault {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.write(f, Opt::field)
    }
}

/// An `.ide` file's error ([`crate::ide`]).
#[derive(Debug, thiserror::Error)]
pub enum IdeError {
    #[error("I/O error: {0}")]
    Io(#[from] std::io::Error),
    /// Not an IDE file (no EBML header, or another DocType).
    #[error("not an enDAQ IDE file: {0}")]
    NotIde(NotIde),
    /// An element that cannot be decoded, at a byte offset.
    #[error("malformed IDE file at byte {offset}: {what}")]
    Malformed { offset: u64, what: Malformation },
    /// An element running past the end of its parent or of the file.
    #[error("IDE file truncated: element at byte {offset} runs past its end")]
    Truncated { offset: u64 },
    /// An element bigger than this reader will hold in memory.
    #[error("IDE element at byte {offset} declares {size} bytes, more than this reader accepts")]
    TooLarge { offset: u64, size: u64 },
    #[error("no channel {channel} in the IDE file")]
    NoSuchChannel { channel: u64 },
    #[error("no subchannel {channel}.{subchannel} in the IDE file")]
    NoSuchSubchannel { channel: u64, subchannel: u64 },
    #[error("unsupported IDE content: {0}")]
    Unsupported(IdeUnsupported),
}

/// Why a file is no `.ide` recording.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum NotIde {
    #[error("empty file")]
    Empty,
    #[error("no EBML header")]
    NoEbmlHeader,
    /// An EBML file of another DocType.
    #[error("DocType {0:?}")]
    DocType(String),
}

/// An `.ide` element that cannot be decoded.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum Malformation {
    #[error("timecode overflow")]
    TimecodeOverflow,
    /// A variable-size integer's first byte (`what`: `element ID`, `element size`).
    #[error("invalid {what} byte 0x{byte:02X}")]
    Vint { what: &'static str, byte: u8 },
    #[error("{0}-byte unsigned integer")]
    UintLength(usize),
    #[error("{0}-byte float")]
    FloatLength(usize),
    #[error("calibration polynomial without CalID")]
    CalibrationWithoutId,
    /// A calibration used by the channel read whose coefficients or references include a
    /// NaN or an infinity: its values cannot be calibrated.
    #[error(
        "calibration {id} holds a coefficient that is not a finite number (NaN or infinite, \
         or so large that folding it in overflows): the recorder's calibration is damaged, its \
         values cannot be calibrated \
         (recalibrate the recorder, or read another channel with --column)"
    )]
    CalibrationNotFinite { id: u64 },
    #[error("bivariate calibration {id} without its channel reference")]
    BivariateWithoutReference { id: u64 },
    #[error("Channel without ChannelID")]
    ChannelWithoutId,
    #[error("channel {channel} payload of {payload} bytes is not a whole number of {record}-byte samples")]
    PartialSample {
        channel: u64,
        payload: usize,
        record: usize,
    },
    #[error("SimpleChannelDataBlock shorter than its header")]
    ShortSimpleBlock,
    /// A ChannelDataBlock without a child (`what`: `ChannelIDRef`, `a start timecode`).
    #[error("ChannelDataBlock without {0}")]
    BlockWithout(&'static str),
}

/// `.ide` content this reader does not read (never a silently different number).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum IdeUnsupported {
    #[error("no ChannelList (old recorder using a default channel table)")]
    NoChannelList,
    #[error("element 0x{id:X} at byte {offset} has an unknown (streamed) size")]
    UnknownSize { id: u32, offset: u64 },
    /// A subchannel beyond its channel's sample format (`format`).
    #[error("subchannel {channel}.{subchannel} has no field in the sample format {format:?}")]
    NoField {
        channel: u64,
        subchannel: u64,
        format: String,
    },
    #[error("sample field outside its record")]
    FieldOutsideRecord,
    #[error("calibration {id} on channel {channel}: only a linear univariate polynomial is supported at channel level")]
    ChannelCalibration { id: u64, channel: u64 },
    #[error("bivariate calibration {id} on channel {channel}.{subchannel} with {coefficients} coefficients")]
    BivariateCoefficients {
        id: u64,
        channel: u64,
        subchannel: u64,
        coefficients: usize,
    },
    #[error("univariate calibration {id} with {coefficients} coefficients")]
    UnivariateCoefficients { id: u64, coefficients: usize },
    #[error("bivariate calibration {id} used where only a univariate one is supported")]
    BivariateAsUnivariate { id: u64 },
    /// A bivariate calibration (on `user`, channel.subchannel) whose reference
    /// (`channel`.`subchannel`) cannot be used.
    #[error("bivariate calibration on channel {}.{} references {channel}.{subchannel}, {problem}", .user.0, .user.1)]
    Reference {
        user: (u64, u64),
        channel: u64,
        subchannel: u64,
        problem: ReferenceProblem,
    },
    #[error("multi-sample block without an end timecode (channel {channel}, byte {offset})")]
    MultiSampleWithoutEnd { channel: u64, offset: u64 },
    /// A channel this reader cannot read (`name`), and why.
    #[error("channel {channel} ({name}): {problem}")]
    Channel {
        channel: u64,
        name: String,
        problem: ChannelProblem,
    },
}

/// Why a bivariate calibration's reference cannot be used.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ReferenceProblem {
    #[error("which is not defined")]
    NotDefined,
    #[error("which has no sample field")]
    NoSampleField,
    #[error("itself bivariate")]
    Bivariate,
    #[error("which has no samples")]
    NoSamples,
}

/// Why this reader cannot read an `.ide` channel ([`crate::ide::Channel::unsupported`]).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ChannelProblem {
    /// A legacy named sample parser (`MPL3115`, `LEGACYACCELEROMETER`).
    #[error("legacy named sample parser {0}")]
    LegacyParser(String),
    #[error("no ChannelFormat")]
    NoFormat,
    /// A sample format (`format`) with a type code this reader does not know.
    #[error("sample format {format:?}: type code {code:?}")]
    TypeCode { format: String, code: char },
    #[error("empty sample format {0:?}")]
    EmptyFormat(String),
    /// A TimeCodeScale that is no positive ratio.
    #[error("TimeCodeScale {0:?}")]
    TimeCodeScale(String),
    #[error("TimeCodeModulus 0")]
    ZeroModulus,
}

/// A file no reader takes: what it is, and what to do instead.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UnsupportedFormat {
    /// `.xlsx`, `.ods`, `.zip`.
    Spreadsheet,
    /// `.xls`.
    Excel97,
    /// A MATLAB `.mat` file (before 7.3).
    Matlab,
    /// HDF5 (`.h5`, MATLAB 7.3 `.mat`).
    Hdf5,
    Gzip,
    /// ASAM MDF (`.mf4`).
    Mdf,
    /// Other binary data (a NUL byte in the first KiB).
    Binary,
}

impl UnsupportedFormat {
    fn write(self, f: &mut fmt::Formatter<'_>, n: OptionNames) -> fmt::Result {
        f.write_str(match self {
            Self::Spreadsheet => {
                "a spreadsheet or zip archive (.xlsx, .ods, .zip): save the sheet as CSV"
            }
            Self::Excel97 => "an Excel 97 workbook (.xls): save the sheet as CSV",
            Self::Matlab => {
                "a MATLAB .mat file: save the channel as CSV or .npy (scipy.io.loadmat, numpy.save)"
            }
            Self::Hdf5 => {
                "an HDF5 file (.h5, MATLAB 7.3 .mat): save the channel as CSV or .npy (h5py, numpy.save)"
            }
            Self::Gzip => "a gzip archive: unpack it first",
            Self::Mdf => "an ASAM MDF file: export the channel as CSV",
            Self::Binary => {
                return write!(
                    f,
                    "binary data: for raw samples name the file .i16 or .f32, or give {}",
                    n(Opt::RawType)
                )
            }
        })
    }
}

/// Why a CSV record could not be read whole: the line it began on is the error's.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum RecordFault {
    #[error("a quote opened on this line is never closed")]
    QuoteNeverClosed,
    #[error("a quote opened on this line is not closed within {MAX_LINE_BYTES} bytes")]
    QuoteTooLong,
    #[error("a line longer than {MAX_LINE_BYTES} bytes: not a CSV recording")]
    LineTooLong,
}

/// What suggests why a field is not a number.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NumberHint {
    /// A byte-order mark inside the field (files joined).
    ByteOrderMark,
    /// A comma in it, without decimal commas being read.
    DecimalComma,
}

/// The numbered channels or columns a reader has (`count` of them).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Numbered {
    WavChannels,
    ArrayColumns,
    /// A raw stream's interleaved channels.
    StreamChannels,
    /// A raw file's interleaved channels.
    FileChannels,
}

/// Fewer than two samples: no rate, no analysis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{samples} samples; at least 2")]
pub struct TooFewSamples {
    pub samples: usize,
}

/// A WAV file's faults (`WAV: …`).
#[derive(Debug, thiserror::Error)]
pub enum WavFault {
    /// The header, as hound read it.
    #[error("{}", one_line(.0))]
    Header(#[source] hound::Error),
    #[error("the header's sample rate {}: out of range ({RATE_HZ})", number(*.rate_hz))]
    RateOutOfRange { rate_hz: f64 },
    #[error("frame {frame} (of {frames} the header announces): {}", one_line(.error))]
    Frame {
        frame: usize,
        frames: usize,
        #[source]
        error: hound::Error,
    },
    #[error("frame {frame}: {value} is not finite")]
    NotFinite { frame: usize, value: f64 },
    #[error(transparent)]
    Samples(TooFewSamples),
}

/// An `.npy` array's faults (`npy: …`).
#[derive(Debug, thiserror::Error)]
pub enum NpyFault {
    /// The header, as npyz read it.
    #[error("{}", one_line(.0))]
    Header(#[source] std::io::Error),
    /// A header length (the prefix's) beyond the bytes after it, or beyond numpy's own limit
    /// (`max_header_size`, 10 000 bytes): read no further.
    #[error(
        "the header declares {declared} bytes, but the file holds {available} after its prefix \
         and numpy reads at most {limit}: not an array numpy wrote"
    )]
    HeaderSize {
        declared: u64,
        available: u64,
        limit: u64,
    },
    /// Brackets nested deeper than a numeric array's header (a dict holding a shape tuple).
    #[error(
        "the header nests brackets {depth} deep; a numeric array's holds a dict and its shape \
         tuple (2): a structured or malformed header"
    )]
    HeaderNesting { depth: usize },
    #[error("dtype {}: not one of float64, float32, int32, int16, uint16, int8, uint8", .0.descr())]
    Dtype(npyz::DType),
    #[error("shape {0:?}; a 1-D array or 2-D (samples × channels)")]
    Shape(Vec<u64>),
    #[error("element {element}: {}", one_line(.error))]
    Element {
        element: usize,
        #[source]
        error: std::io::Error,
    },
    #[error("{elements} elements for shape {shape:?}")]
    ElementCount { elements: usize, shape: Vec<u64> },
    #[error("the data ends at element {element} of the {total} its shape holds")]
    DataEnds { element: u64, total: u64 },
    #[error("row {row}: {value} is not finite")]
    NotFinite { row: u64, value: f64 },
    #[error("row {row} missing")]
    RowMissing { row: usize },
    #[error(transparent)]
    Samples(TooFewSamples),
}

/// A TDMS file's faults (`TDMS: …`).
#[derive(Debug, thiserror::Error)]
pub enum TdmsFault {
    /// The file could not be opened or measured.
    #[error("{}", one_line(.0))]
    Io(#[source] std::io::Error),
    /// The segments' structure, checked before any data is read: at byte `byte`.
    #[error("byte {byte}: {}", one_line(.fault))]
    Structure {
        byte: u64,
        #[source]
        fault: TdmsStructureFault,
    },
    #[error("the file holds no channels")]
    NoChannels,
    #[error("channel {channel} not found again")]
    ChannelLost { channel: String },
}

/// What is wrong at a byte of a TDMS file's segments.
#[derive(Debug, thiserror::Error)]
pub enum TdmsStructureFault {
    #[error(transparent)]
    Read(std::io::Error),
    #[error("{announced} bytes announced, {left} left in the segment's metadata")]
    Announced { announced: usize, left: usize },
    #[error("a segment's lead-in is cut short")]
    LeadInCut,
    #[error("no TDSm segment tag")]
    NoTag,
    #[error("metadata of {bytes} bytes runs past the file")]
    MetadataPastEnd { bytes: u64 },
    #[error("a big-endian segment, which this reader does not read")]
    BigEndian,
    #[error("interleaved channels (ToC bit 5) of {first} and {other} values a chunk: interleaved channels hold one value each a row; the segment's value counts are wrong")]
    InterleavedCounts { first: u64, other: u64 },
    #[error("an interleaved channel of type {0:#x} (strings or no type): interleaved channels must be numbers")]
    InterleavedType(u32),
    #[error(
        "a segment of {bytes} bytes announced, {left} left in the file: the file is cut short"
    )]
    SegmentPastEnd { bytes: u64, left: u64 },
    #[error(
        "metadata of {raw} bytes, beyond the segment's {next}: a size in its lead-in is wrong"
    )]
    MetadataPastSegment { raw: u64, next: u64 },
    #[error("{data} bytes of raw data, no whole number of its {chunk}-byte chunks (the value counts of its channels): a size in the segment is wrong")]
    NotWholeChunks { data: u64, chunk: u64 },
    #[error("{values} values of {bytes} bytes: more than any file holds")]
    ValuesTooMany { values: u64, bytes: u64 },
    #[error("an object's raw data index is the previous segment's, which it has none of")]
    NoPreviousIndex,
    #[error("an array of dimension {0}; a channel's values have dimension 1")]
    Dimension(u32),
    #[error("object path {0:?} is not '/', /'group' or /'group'/'channel'")]
    ObjectPath(String),
    #[error("the channel's data type changes from {from:#x} to {to:#x}")]
    TypeChanges { from: u32, to: u32 },
    #[error("metadata of {bytes} bytes, more than a recording's")]
    MetadataTooLarge { bytes: u64 },
    #[error("DAQmx raw data, which this reader does not read")]
    DaqmxRaw,
    #[error("raw data index of {bytes} bytes")]
    RawIndex { bytes: usize },
    #[error("property type {0:#x}")]
    PropertyType(u32),
    #[error("next segment offset {0} goes back")]
    NextGoesBack(u64),
}

/// A TDMS channel's faults (`TDMS group/channel: …`).
#[derive(Debug, thiserror::Error)]
pub enum TdmsChannelFault {
    /// Reading the values, at byte `byte`.
    #[error("byte {byte}: {}", one_line(.error))]
    Read {
        byte: u64,
        #[source]
        error: std::io::Error,
    },
    #[error("channel type {0:#x} is not a number this reads (integers of 8 to 64 bits, floats of 32 or 64)")]
    DataType(u32),
    #[error("value {0} is not finite")]
    NotFinite(usize),
    #[error(transparent)]
    Samples(TooFewSamples),
}

/// The spool of a recording's values (a temporary file) failed.
#[derive(Debug, thiserror::Error)]
pub enum SpoolError {
    /// Creating it, in the directory `dir`.
    #[error("a temporary file in {}: {error}", .dir.display())]
    Create {
        dir: PathBuf,
        #[source]
        error: std::io::Error,
    },
    /// An input read once that went on past half the space free where its values are kept
    /// (`limit` bytes, 8 a sample): one without end (a device, a FIFO left open).
    #[error(
        "the input went on past {} samples, the limit of its spool in {} ({} MB, at most half \
         the space free there): an input without end is analysed as it comes with --stream (and --range, \
         --trigger), or give a recording that ends",
        .limit / 8,
        .dir.display(),
        .limit / 1_000_000
    )]
    Full { dir: PathBuf, limit: u64 },
    /// Writing or reading it.
    #[error("the spool in {}: {error}", .dir.display())]
    Use {
        dir: PathBuf,
        #[source]
        error: std::io::Error,
    },
}

/// What went wrong reading a recording (or a secondary input). The Display names settings as
/// [`Opt::field`]; [`ReadErrorKind::display_with`] as a front end spells them.
#[derive(Debug, thiserror::Error)]
pub enum ReadErrorKind {
    // The file.
    Io(#[source] std::io::Error),
    IsDirectory,
    Unsupported(UnsupportedFormat),
    /// A secondary input (`what`: a scene file, a target, an ELF) beyond `limit` bytes.
    TooLarge {
        limit: u64,
        what: &'static str,
    },
    /// The spool of the values read (not of the file itself).
    Spool(#[source] SpoolError),
    /// A FIFO or a device read whole (not in passes) beyond `limit` bytes, or beyond the
    /// memory there is (`memory`: the allocation failed first).
    StreamTooLong {
        limit: u64,
        memory: bool,
    },

    // CSV text.
    Record(#[source] RecordFault),
    /// The `csv` crate's error (other than the input's).
    Csv(csv::ErrorKind),
    /// Decimal commas with `,` as the delimiter.
    DecimalCommaDelimiter,
    /// A number that is no finite reading within ±[`MAX_VALUE`].
    NotReading {
        value: f64,
    },
    /// A field of a data row that is no number.
    NotANumber {
        field: String,
        hint: Option<NumberHint>,
    },
    /// The first data row has more fields than the header line (at `header_line`).
    WiderThanHeader {
        fields: usize,
        header_line: u64,
        header_fields: usize,
        /// The delimiter is `,` (decimal commas may have split the numbers).
        comma_delimited: bool,
    },
    FieldCount {
        fields: usize,
        expected: usize,
    },
    /// Rows split on white space under a one-field header whose names, split too, do not
    /// name the columns one to one.
    HeaderNamesColumns {
        header_line: u64,
        names: Vec<String>,
        fields: usize,
    },
    NoDataRows,
    /// The first data row's first field is empty under a header that names that column:
    /// the values would shift under their neighbours' names.
    EmptyUnderName {
        name: String,
        header_line: u64,
    },
    /// Every line held text: `lines` of them, the first after the header at `line` with
    /// `field`, not a number.
    NoNumericRows {
        lines: u64,
        line: u64,
        field: String,
    },

    // Columns and channels.
    /// A column index past the rows' fields (`what`: `column`, `time column`, `axis`).
    ColumnIndex {
        what: &'static str,
        index: usize,
        fields: usize,
    },
    /// No column of that header name.
    ColumnName {
        what: &'static str,
        name: String,
        headers: Vec<String>,
    },
    NoDataColumn,
    /// More than one header looks like a time.
    SeveralTimeColumns {
        headers: Vec<String>,
    },
    /// The channel asked for is the time column (`axes`: the channel may be axes too).
    ChannelIsTimeColumn {
        column: usize,
        axes: bool,
    },
    NoTimeColumn,
    /// Not two or three axes (`what`: `columns`, `subchannels`).
    AxesCount {
        given: usize,
        what: &'static str,
    },
    /// An axis given twice (`what`: `column`, `subchannel`; `name` its name).
    AxisTwice {
        what: &'static str,
        name: String,
    },
    /// A numbered channel or column past the `count` there are.
    ColumnNumbered {
        column: ColumnRef,
        count: usize,
        of: Numbered,
    },

    // The time axis.
    RateOutOfRange {
        rate_hz: f64,
    },
    OneSample,
    NotIncreasing(NotIncreasing),
    Uneven(UnevenInterval),
    Drift(DriftFault),
    /// A time column (`header`) whose rate is beyond [`RATE_HZ`].
    TimeUnitOutOfRange {
        header: String,
        rate_hz: f64,
    },
    /// A time column (`header`) that names no unit and read in seconds is too slow.
    TimeUnitTooSlow {
        header: String,
        rate_hz: f64,
    },
    /// Resampling would give too many samples (a long gap).
    ResampleTooLong {
        span_s: f64,
        rate_hz: f64,
        samples: usize,
        file_samples: usize,
    },
    /// The head's time stamps give no rate.
    RateUnknown {
        samples: u64,
    },
    /// No rate (the head gave none).
    NoRate,
    TooFewSamples(#[source] TooFewSamples),

    // Formats and the settings they take.
    /// A WAV file and a rate or time column (`resample`: resampling too).
    WavGivesRate {
        resample: bool,
    },
    WavAxes,
    Wav(#[source] WavFault),
    NpyNoTime,
    NpyOptions,
    NpyTimeColumn,
    Npy(#[source] NpyFault),
    RawNoTime,
    RawOptions,
    RawChannels {
        channels: usize,
    },
    /// A raw file's length is no whole number of frames.
    RawPartialFrame {
        bytes: u64,
        frame: usize,
        channels: usize,
        sample_bytes: usize,
    },
    /// A raw stream ended inside a frame.
    RawStreamPartialFrame {
        bytes: u64,
        frame: usize,
        last_frame: u64,
    },
    RawNotFinite {
        frame: u64,
        byte: u64,
        value: f32,
    },
    TdmsOptions,
    Tdms(#[source] TdmsFault),
    TdmsChannel {
        channel: String,
        #[source]
        fault: TdmsChannelFault,
    },
    /// The channel asked for is not in the file (which has `channels`, `group/channel`).
    TdmsNoSuchChannel {
        column: Option<ColumnRef>,
        channels: Vec<String>,
    },
    TdmsIncrementOutOfRange {
        channel: String,
        increment_s: f64,
    },
    TdmsNoIncrement {
        channel: String,
    },
    /// An `.ide` file and a rate or time column.
    IdeOwnTime,
    /// An `.ide` file and a rate.
    IdeRate,
    Ide(#[source] IdeError),
    /// No subchannel of that name or index (the file has `subchannels`).
    IdeNoSubchannel {
        column: ColumnRef,
        subchannels: Vec<String>,
    },
    IdeNoAcceleration {
        subchannels: Vec<String>,
    },
    /// Axes of more than one channel.
    IdeAxesChannels,
    /// A subchannel in units that are no acceleration or force.
    IdeNotAcceleration {
        subchannel: String,
        units: String,
    },
    IdeTooFewSamples {
        subchannel: String,
        samples: usize,
    },
}

impl From<std::io::Error> for ReadErrorKind {
    /// An input's error: a CSV record's fault if it is one ([`RecordFault`]), else as it is.
    fn from(e: std::io::Error) -> Self {
        match e
            .get_ref()
            .and_then(|inner| inner.downcast_ref::<RecordFault>())
        {
            Some(fault) => ReadErrorKind::Record(*fault),
            None => ReadErrorKind::Io(e),
        }
    }
}

impl From<csv::Error> for ReadErrorKind {
    fn from(e: csv::Error) -> Self {
        match e.into_kind() {
            csv::ErrorKind::Io(io) => io.into(),
            other => ReadErrorKind::Csv(other),
        }
    }
}

impl From<WavFault> for ReadErrorKind {
    fn from(e: WavFault) -> Self {
        ReadErrorKind::Wav(e)
    }
}

impl From<NpyFault> for ReadErrorKind {
    fn from(e: NpyFault) -> Self {
        ReadErrorKind::Npy(e)
    }
}

impl From<TdmsFault> for ReadErrorKind {
    fn from(e: TdmsFault) -> Self {
        ReadErrorKind::Tdms(e)
    }
}

impl From<IdeError> for ReadErrorKind {
    fn from(e: IdeError) -> Self {
        ReadErrorKind::Ide(e)
    }
}

impl From<SpoolError> for ReadErrorKind {
    fn from(e: SpoolError) -> Self {
        ReadErrorKind::Spool(e)
    }
}

impl fmt::Display for ReadErrorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.write(f, Opt::field)
    }
}

/// `"a", "b"` (each quoted), or `a, b`.
fn list(items: &[String], quoted: bool) -> String {
    let items: Vec<String> = items
        .iter()
        .map(|s| if quoted { format!("{s:?}") } else { s.clone() })
        .collect();
    items.join(", ")
}

impl ReadErrorKind {
    /// The message with the settings named by `names` (no file: [`ReadError::display_with`]
    /// names it).
    pub fn display_with(&self, names: OptionNames) -> impl fmt::Display + '_ {
        Rendered(move |f: &mut fmt::Formatter<'_>| self.write(f, names))
    }

    /// Whether the message names the file: not for a setting's value refused before the
    /// file is read (`raw_channels` out of range), which the setting names alone.
    pub fn names_the_file(&self) -> bool {
        !matches!(self, ReadErrorKind::RawChannels { .. })
    }

    fn write(&self, f: &mut fmt::Formatter<'_>, n: OptionNames) -> fmt::Result {
        use ReadErrorKind as K;
        match self {
            K::Io(e) => write!(f, "{e}"),
            K::IsDirectory => f.write_str("is a directory"),
            K::Unsupported(u) => {
                f.write_str("unsupported format: ")?;
                u.write(f, n)
            }
            K::TooLarge { limit, what } => write!(
                f,
                "more than {} KiB, larger than any {what}",
                limit / 1024
            ),
            K::Spool(e) => write!(f, "{e}"),
            K::StreamTooLong { limit, memory } => write!(
                f,
                "a FIFO or device read whole {}: save it to a file first, or read it in passes (without axes, free fall or resampling)",
                if *memory {
                    "needs more memory than there is".to_string()
                } else {
                    format!("holds more than {} MiB", limit >> 20)
                }
            ),
            K::Record(e) => write!(f, "{e}"),
            K::Csv(kind) => write!(f, "{kind:?}"),
            K::DecimalCommaDelimiter => write!(
                f,
                "{}: the delimiter is ',' too; give {} (e.g. ';')",
                n(Opt::DecimalComma),
                n(Opt::Delimiter)
            ),
            K::NotReading { value } => write!(
                f,
                "value is {value:e}: not a finite reading within ±{MAX_VALUE:e}"
            ),
            K::NotANumber { field, hint } => {
                match field.char_indices().nth(64) {
                    Some((cut, _)) => write!(f, "not a number: {:?}...", &field[..cut])?,
                    None => write!(f, "not a number: {field:?}")?,
                }
                match hint {
                    Some(NumberHint::ByteOrderMark) => f.write_str(
                        " (a byte-order mark is read only at the start of the file: files joined?)",
                    ),
                    Some(NumberHint::DecimalComma) => {
                        write!(f, " (decimal commas? give {})", n(Opt::DecimalComma))
                    }
                    None => Ok(()),
                }
            }
            K::HeaderNamesColumns {
                header_line,
                names,
                fields,
            } => write!(
                f,
                "{fields} columns split on white space, but the header (line {header_line}) splits into {} names ({}), which cannot be matched to them: separate the header's names with a tab or two spaces",
                names.len(),
                names
                    .iter()
                    .map(|n| format!("{n:?}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
            K::WiderThanHeader {
                fields,
                header_line,
                header_fields,
                comma_delimited,
            } => {
                write!(
                    f,
                    "{fields} fields, but the header (line {header_line}) has {header_fields}"
                )?;
                if *comma_delimited {
                    write!(
                        f,
                        " (decimal commas? give {} and {})",
                        n(Opt::DecimalComma),
                        n(Opt::Delimiter)
                    )?;
                }
                Ok(())
            }
            K::FieldCount { fields, expected } => {
                write!(f, "{fields} fields, expected {expected}")
            }
            K::NoDataRows => f.write_str("no data rows"),
            K::EmptyUnderName { name, header_line } => write!(
                f,
                "the first field is empty under {name:?} (the header, line {header_line}): a column with no values, which would put every value under its neighbour's name; remove {name:?} from the header"
            ),
            K::NoNumericRows { lines, line, field } => write!(
                f,
                "no data rows: all {lines} lines hold text; line {line}, the first after the header, has {field:?}, not a number"
            ),
            K::ColumnIndex {
                what,
                index,
                fields,
            } => write!(f, "{what} {index} does not exist (rows have {fields} fields)"),
            K::ColumnName {
                what,
                name,
                headers,
            } => write!(
                f,
                "no {what} named {name:?} (columns: {})",
                list(headers, false)
            ),
            K::NoDataColumn => f.write_str("no data column besides the time column"),
            K::SeveralTimeColumns { headers } => write!(
                f,
                "several columns could be the time: {}; choose one with {}",
                list(headers, true),
                n(Opt::TimeColumn)
            ),
            K::ChannelIsTimeColumn { column, axes } => {
                write!(
                    f,
                    "column {column} is the time column: choose another with {}",
                    n(Opt::Column)
                )?;
                if *axes {
                    write!(f, " or {}", n(Opt::Axes))?;
                }
                Ok(())
            }
            K::NoTimeColumn => write!(
                f,
                "no time column found: give {} or {}",
                n(Opt::TimeColumn),
                n(Opt::Rate)
            ),
            K::AxesCount { given, what } => write!(
                f,
                "{}: {given} {what} given; two or three (x,y or x,y,z)",
                n(Opt::Axes)
            ),
            K::AxisTwice { what, name } => {
                write!(f, "{}: {what} {name} given twice", n(Opt::Axes))
            }
            K::ColumnNumbered { column, count, of } => {
                let of = match of {
                    Numbered::WavChannels => "a WAV file's channels".to_string(),
                    Numbered::ArrayColumns => "the array's columns".to_string(),
                    Numbered::StreamChannels => {
                        format!("the stream's {count} interleaved channels")
                    }
                    Numbered::FileChannels => format!("the file's {count} interleaved channels"),
                };
                write!(
                    f,
                    "{} {column}: {of} are numbered 0..{}",
                    n(Opt::Column),
                    count.saturating_sub(1)
                )
            }
            K::RateOutOfRange { rate_hz } => write!(
                f,
                "{} {}: out of range ({RATE_HZ})",
                n(Opt::Rate),
                number(*rate_hz)
            ),
            K::OneSample => write!(
                f,
                "one sample: the rate cannot be told; give {}",
                n(Opt::Rate)
            ),
            K::NotIncreasing(e) => write!(f, "{e}"),
            K::Uneven(e) => e.write(f, n),
            K::Drift(e) => e.write(f, n),
            K::TimeUnitOutOfRange { header, rate_hz } => write!(
                f,
                "the time column {header:?} gives {} S/s: out of range ({RATE_HZ}); is its unit right ({})?",
                number(*rate_hz),
                n(Opt::TimeUnit)
            ),
            K::TimeUnitTooSlow { header, rate_hz } => write!(
                f,
                "the time column {header:?} names no unit: read in seconds it gives {} S/s, too slow for an impact recording; if it is in ms or µs, give {} ms (or us), or name the column time_ms (time_us)",
                sig(*rate_hz, 4),
                n(Opt::TimeUnit)
            ),
            K::ResampleTooLong {
                span_s,
                rate_hz,
                samples,
                file_samples,
            } => write!(
                f,
                "{}: {span_s:.6e} s at {rate_hz:.6e} Hz would be {samples} samples from \
                 {file_samples} in the file (a long gap?): cut the file",
                n(Opt::Resample)
            ),
            K::RateUnknown { samples } => {
                write!(f, "{samples} samples: the rate cannot be told")
            }
            K::NoRate => f.write_str("the rate cannot be told"),
            K::TooFewSamples(e) => write!(f, "{e}"),
            K::WavGivesRate { resample } => {
                write!(
                    f,
                    "a WAV file gives its own rate: no {}",
                    n(Opt::Rate)
                )?;
                if *resample {
                    write!(f, ", {} or {}", n(Opt::TimeColumn), n(Opt::Resample))
                } else {
                    write!(f, " or {}", n(Opt::TimeColumn))
                }
            }
            K::WavAxes => write!(
                f,
                "{}: not for WAV files yet; give {}",
                n(Opt::Axes),
                n(Opt::Column)
            ),
            K::Wav(e) => write!(f, "WAV: {e}"),
            K::NpyNoTime => write!(f, "an .npy array holds no time: give {}", n(Opt::Rate)),
            K::NpyOptions => write!(
                f,
                "an .npy array takes {} and {} only (no {}, {}, {})",
                n(Opt::Rate),
                n(Opt::Column),
                n(Opt::TimeColumn),
                n(Opt::Resample),
                n(Opt::Axes)
            ),
            K::NpyTimeColumn => write!(
                f,
                "an .npy array has no time column (give {})",
                n(Opt::Rate)
            ),
            K::Npy(e) => write!(f, "npy: {e}"),
            K::RawNoTime => write!(f, "a raw file holds no time: give {}", n(Opt::Rate)),
            K::RawOptions => write!(
                f,
                "a raw file takes {}, {} and {} only",
                n(Opt::Rate),
                n(Opt::RawChannels),
                n(Opt::Column)
            ),
            K::RawChannels { channels } => write!(
                f,
                "{} {channels}: must lie in 1..=64",
                n(Opt::RawChannels)
            ),
            K::RawPartialFrame {
                bytes,
                frame,
                channels,
                sample_bytes,
            } => write!(
                f,
                "{bytes} bytes: not a whole number of {frame}-byte frames ({channels} channel(s) of {sample_bytes} bytes); the last frame starts at byte {}",
                bytes / *frame as u64 * *frame as u64
            ),
            K::RawStreamPartialFrame {
                bytes,
                frame,
                last_frame,
            } => write!(
                f,
                "{bytes} bytes: not a whole number of {frame}-byte frames; the last frame starts at byte {last_frame}"
            ),
            K::RawNotFinite { frame, byte, value } => {
                write!(f, "frame {frame} (byte {byte}): {value} is not finite")
            }
            K::TdmsOptions => write!(
                f,
                "a TDMS file takes {} (group/channel) and {} only",
                n(Opt::Column),
                n(Opt::Rate)
            ),
            K::Tdms(e) => write!(f, "TDMS: {e}"),
            K::TdmsChannel { channel, fault } => write!(f, "TDMS {channel}: {fault}"),
            K::TdmsNoSuchChannel { column, channels } => {
                f.write_str("no such channel")?;
                if let Some(c) = column {
                    write!(f, " {c}")?;
                }
                write!(f, "; the file has: {}", list(channels, false))
            }
            K::TdmsIncrementOutOfRange {
                channel,
                increment_s,
            } => write!(
                f,
                "{channel}: wf_increment {}: out of range ({})",
                number(*increment_s),
                RATE_HZ.reciprocal("s")
            ),
            K::TdmsNoIncrement { channel } => write!(
                f,
                "{channel} has no wf_increment property: give {}",
                n(Opt::Rate)
            ),
            K::IdeOwnTime => write!(
                f,
                "an .ide file's samples carry their own time stamps: no {} or {}",
                n(Opt::Rate),
                n(Opt::TimeColumn)
            ),
            K::IdeRate => write!(
                f,
                "{}: an .ide file's samples carry their own time stamps",
                n(Opt::Rate)
            ),
            K::Ide(e) => write!(f, "{e}"),
            K::IdeNoSubchannel {
                column,
                subchannels,
            } => write!(
                f,
                "no subchannel {column} (the file has: {})",
                list(subchannels, false)
            ),
            K::IdeNoAcceleration { subchannels } => write!(
                f,
                "no acceleration subchannel (the file has: {})",
                list(subchannels, false)
            ),
            K::IdeAxesChannels => write!(
                f,
                "{}: the subchannels must be of one channel (one time base), e.g. 32.0,32.1,32.2",
                n(Opt::Axes)
            ),
            K::IdeNotAcceleration { subchannel, units } => write!(
                f,
                "subchannel {subchannel} is in {units:?}, not an acceleration (g, m/s²) or a force (N): choose another with {}",
                n(Opt::Column)
            ),
            K::IdeTooFewSamples {
                subchannel,
                samples,
            } => write!(f, "subchannel {subchannel}: {samples} samples; at least 2"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::time_axis::{NotIncreasing, UnevenInterval};

    /// Whether `text` spells a command-line flag: `--` and a letter.
    fn spells_a_flag(text: &str) -> bool {
        text.as_bytes()
            .windows(3)
            .any(|w| w[0] == b'-' && w[1] == b'-' && w[2].is_ascii_alphabetic())
    }

    /// A kind of each shape, every one that names a setting among them.
    fn representative() -> Vec<ReadErrorKind> {
        use ReadErrorKind as K;
        let headers = vec!["time".to_string(), "t_ms".to_string()];
        vec![
            K::Io(std::io::Error::other("disk on fire")),
            K::IsDirectory,
            K::Unsupported(UnsupportedFormat::Binary),
            K::Unsupported(UnsupportedFormat::Spreadsheet),
            K::TooLarge {
                limit: 1 << 20,
                what: "scene file",
            },
            K::StreamTooLong {
                limit: 1 << 28,
                memory: false,
            },
            K::Record(RecordFault::LineTooLong),
            K::DecimalCommaDelimiter,
            K::NotReading { value: 1e300 },
            K::NotANumber {
                field: "0,5".into(),
                hint: Some(NumberHint::DecimalComma),
            },
            K::NotANumber {
                field: "\u{feff}1".into(),
                hint: Some(NumberHint::ByteOrderMark),
            },
            K::WiderThanHeader {
                fields: 3,
                header_line: 1,
                header_fields: 2,
                comma_delimited: true,
            },
            K::FieldCount {
                fields: 3,
                expected: 2,
            },
            K::HeaderNamesColumns {
                header_line: 1,
                names: vec!["Time".into(), "(ms)".into(), "Accel".into()],
                fields: 2,
            },
            K::NoDataRows,
            K::EmptyUnderName {
                name: "X_Value".into(),
                header_line: 1,
            },
            K::NoNumericRows {
                lines: 5500,
                line: 2,
                field: "12:00:01.5".into(),
            },
            K::ColumnIndex {
                what: "column",
                index: 9,
                fields: 2,
            },
            K::ColumnName {
                what: "time column",
                name: "x".into(),
                headers: headers.clone(),
            },
            K::NoDataColumn,
            K::SeveralTimeColumns {
                headers: headers.clone(),
            },
            K::ChannelIsTimeColumn {
                column: 0,
                axes: true,
            },
            K::NoTimeColumn,
            K::AxesCount {
                given: 4,
                what: "columns",
            },
            K::AxisTwice {
                what: "column",
                name: "x".into(),
            },
            K::ColumnNumbered {
                column: ColumnRef::Index(5),
                count: 2,
                of: Numbered::StreamChannels,
            },
            K::RateOutOfRange { rate_hz: -1.0 },
            K::OneSample,
            K::NotIncreasing(NotIncreasing {
                t: 1.0,
                previous: 2.0,
            }),
            K::Uneven(UnevenInterval {
                dt: 2.0,
                median: 1.0,
            }),
            K::Drift(DriftFault {
                block_end: 2048,
                mean_dt: 1.1,
                first_dt: 1.0,
            }),
            K::TimeUnitOutOfRange {
                header: "t".into(),
                rate_hz: 1e12,
            },
            K::TimeUnitTooSlow {
                header: "t".into(),
                rate_hz: 1.0,
            },
            K::ResampleTooLong {
                span_s: 100.0,
                rate_hz: 1e6,
                samples: 100_000_001,
                file_samples: 10,
            },
            K::RateUnknown { samples: 1 },
            K::NoRate,
            K::TooFewSamples(TooFewSamples { samples: 1 }),
            K::WavGivesRate { resample: true },
            K::WavGivesRate { resample: false },
            K::WavAxes,
            K::Wav(WavFault::RateOutOfRange { rate_hz: 0.0 }),
            K::NpyNoTime,
            K::NpyOptions,
            K::NpyTimeColumn,
            K::Npy(NpyFault::Shape(vec![1, 2, 3])),
            K::RawNoTime,
            K::RawOptions,
            K::RawChannels { channels: 65 },
            K::RawPartialFrame {
                bytes: 5,
                frame: 2,
                channels: 1,
                sample_bytes: 2,
            },
            K::RawNotFinite {
                frame: 1,
                byte: 4,
                value: f32::NAN,
            },
            K::TdmsOptions,
            K::Tdms(TdmsFault::Structure {
                byte: 0,
                fault: TdmsStructureFault::NoTag,
            }),
            K::TdmsNoSuchChannel {
                column: Some(ColumnRef::Name("g/x".into())),
                channels: vec!["g/a".into()],
            },
            K::TdmsIncrementOutOfRange {
                channel: "g/a".into(),
                increment_s: 0.0,
            },
            K::TdmsNoIncrement {
                channel: "g/a".into(),
            },
            K::IdeOwnTime,
            K::IdeRate,
            K::IdeNoSubchannel {
                column: ColumnRef::Name("Z".into()),
                subchannels: vec!["8.0 X (2000g) [g]".into()],
            },
            K::IdeAxesChannels,
            K::IdeNotAcceleration {
                subchannel: "36.1 Temperature".into(),
                units: "°C".into(),
            },
        ]
    }

    #[test]
    fn the_messages_spell_no_command_line_flag() {
        for kind in representative() {
            let text = kind.to_string();
            assert!(!spells_a_flag(&text), "{text}");
            assert!(!text.is_empty());
        }
        let conflict = crate::units::UnitsConflict {
            stated: crate::units::Units::G,
            header: "a_m_s2".into(),
            named: crate::units::Units::MS2,
        };
        assert!(!spells_a_flag(&conflict.to_string()), "{conflict}");
        for note in [
            crate::ReadNote::ChannelChosen {
                channel: "a".into(),
                names: vec!["a".into(), "b".into()],
            },
            crate::ReadNote::SubchannelChosen {
                subchannel: "8.0 X (2000g) [g]".into(),
                count: 2,
                subchannels: vec!["8.0 X (2000g) [g]".into(), "80.0 X (40g) [g]".into()],
            },
        ] {
            let text = crate::Note::Read(note).text(Opt::field);
            assert!(!spells_a_flag(&text), "{text}");
        }
    }

    #[test]
    fn the_file_is_named_once_and_settings_as_the_caller_names_them() {
        fn flag(o: Opt) -> &'static str {
            match o {
                Opt::Rate => "--rate",
                _ => "--other",
            }
        }
        let e = ReadError::new(Path::new("a.csv"), ReadErrorKind::OneSample);
        assert_eq!(
            e.to_string(),
            "a.csv: one sample: the rate cannot be told; give `rate_hz`"
        );
        assert_eq!(
            e.display_with(flag).to_string(),
            "a.csv: one sample: the rate cannot be told; give --rate"
        );
        let e = ReadError::at(
            Path::new("-"),
            At::Line(7),
            ReadErrorKind::FieldCount {
                fields: 3,
                expected: 2,
            },
        );
        assert_eq!(e.to_string(), "stdin:7: 3 fields, expected 2");
        let e = ReadError::at(
            Path::new("r.ide"),
            At::Sample(12),
            ReadErrorKind::NotIncreasing(NotIncreasing {
                t: 1.0,
                previous: 2.0,
            }),
        );
        assert_eq!(
            e.to_string(),
            "r.ide: sample 12: time 1 s does not increase (previous 2 s)"
        );
        // An input's error is a CSV record's fault when it is one.
        let io = std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            RecordFault::QuoteNeverClosed,
        );
        assert!(matches!(
            ReadErrorKind::from(io),
            ReadErrorKind::Record(RecordFault::QuoteNeverClosed)
        ));
    }
}
