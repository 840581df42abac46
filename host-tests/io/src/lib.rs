//! Reading recordings: a CSV (a file or standard input), .ide, .wav, .npy, TDMS or raw
//! .i16/.f32 file, whole ([`read_recording`]) or a block at a time ([`open_source`]). The
//! format is found in one place ([`Format`]) and both readers are chosen here, side by side.
//! Below the pipeline, a package of its own (`impact-io`), so that cargo holds the line:
//! nothing here knows the command line or the analysis.

pub mod channel;
pub mod csv_fast;
pub mod csv_read;
pub mod error;
pub mod ide;
pub mod limits;
pub mod npy;
pub mod progress;
pub mod quantise;
pub mod raw;
pub mod recording;
pub mod sources;
pub mod spool;
pub mod table;
pub mod tape;
pub mod tdms;
pub mod time_axis;
pub mod units;
pub mod wav;

use std::path::Path;

pub use channel::{Channel, ColumnRef, CsvFormat, ReadOptions, TimeUnit};
use error::UnsupportedFormat;
pub use error::{At, Opt, OptionNames, ReadError, ReadErrorKind};
use sources::Source;

/// A recording's format: by the file's extension ([`crate::wav`], [`crate::npy`],
/// [`crate::tdms`], [`crate::raw`]), or raw if its sample type is given; CSV otherwise.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Format {
    Raw(channel::RawType),
    Wav,
    Npy,
    Tdms,
    Ide,
    Csv,
    /// A file no reader takes: what it is and what to do instead.
    Unsupported(UnsupportedFormat),
}

impl Format {
    pub fn of(path: &Path, raw_type: Option<channel::RawType>) -> Self {
        match raw_type.or_else(|| channel::RawType::of(path)) {
            Some(kind) => Format::Raw(kind),
            None if wav::is_wav(path) => Format::Wav,
            None if npy::is_npy(path) => Format::Npy,
            None if tdms::is_tdms(path) => Format::Tdms,
            None if ide::is_ide(path) => Format::Ide,
            None => match unsupported(path) {
                Some(what) => Format::Unsupported(what),
                None => Format::Csv,
            },
        }
    }
}

/// What a file that is no CSV is, from its first bytes or its extension (a spreadsheet, a
/// MATLAB or HDF5 file, an archive, other binary data); `None` for text.
fn unsupported(path: &Path) -> Option<UnsupportedFormat> {
    let mut head = [0u8; 1024];
    // Only a regular file is sniffed (a pipe's bytes would be gone).
    let n = match std::fs::metadata(path) {
        Ok(m) if m.is_file() => std::fs::File::open(path)
            .and_then(|mut f| std::io::Read::read(&mut f, &mut head))
            .unwrap_or(0),
        _ => 0,
    };
    let head = &head[..n];
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    if head.starts_with(b"PK\x03\x04") || matches!(ext.as_str(), "xlsx" | "ods") {
        Some(UnsupportedFormat::Spreadsheet)
    } else if head.starts_with(&[0xD0, 0xCF, 0x11, 0xE0]) || ext == "xls" {
        Some(UnsupportedFormat::Excel97)
    } else if head.starts_with(b"MATLAB") {
        Some(UnsupportedFormat::Matlab)
    } else if head.starts_with(b"\x89HDF") || matches!(ext.as_str(), "h5" | "hdf5" | "mat") {
        Some(UnsupportedFormat::Hdf5)
    } else if head.starts_with(&[0x1F, 0x8B]) {
        Some(UnsupportedFormat::Gzip)
    } else if head.starts_with(b"MDF ") || ext == "mf4" {
        Some(UnsupportedFormat::Mdf)
    } else if head.contains(&0) {
        Some(UnsupportedFormat::Binary)
    } else {
        None
    }
}

/// Reads one channel and its time base from a CSV file (see [`csv_read::read_table`]), a WAV file, an
/// `.npy` array, a TDMS file or a raw `.i16`/`.f32` file ([`Format`]).
pub fn read_recording(path: &Path, opts: &ReadOptions) -> Result<Channel, ReadError> {
    match Format::of(path, opts.raw_type) {
        Format::Wav => wav::read_wav(path, opts),
        Format::Npy => npy::read_npy(path, opts),
        Format::Tdms => tdms::read_tdms(path, opts),
        Format::Ide => ide::read_ide(path, opts),
        Format::Unsupported(what) => Err(ReadError::new(path, ReadErrorKind::Unsupported(what))),
        Format::Raw(kind) => raw::read_raw(path, kind, opts.raw_channels.unwrap_or(1), opts),
        Format::Csv => recording::read_csv(path, opts),
    }
}

/// Opens the reader for the file's format.
pub fn open_source(path: &Path, opts: &ReadOptions) -> Result<Box<dyn Source>, ReadError> {
    use sources::{CsvSource, IdeSource, NpySource, RawSource, TdmsSource, WavSource};
    Ok(match Format::of(path, opts.raw_type) {
        Format::Raw(kind) => Box::new(RawSource::open(path, opts, kind)?),
        Format::Wav => Box::new(WavSource::open(path, opts)?),
        Format::Npy => Box::new(NpySource::open(path, opts)?),
        Format::Tdms => Box::new(TdmsSource::open(path, opts)?),
        Format::Ide => Box::new(IdeSource::open(path, opts)?),
        Format::Unsupported(what) => {
            return Err(ReadError::new(path, ReadErrorKind::Unsupported(what)))
        }
        Format::Csv => Box::new(CsvSource::open(path, opts)?),
    })
}

/// Reads a secondary input (a scene, a target, an ELF) of at most `limit` bytes: a larger
/// one (or an endless one, `/dev/zero`) is an error naming the limit (`what`: what the input
/// is, `scene file`), read no further. (`-` is a file of that name here, not standard input,
/// though the error's Display, as every reader's, calls it `stdin`.)
pub fn read_limited(path: &Path, limit: u64, what: &'static str) -> Result<Vec<u8>, ReadError> {
    use std::io::Read;
    let err = |kind: ReadErrorKind| ReadError::new(path, kind);
    let file = std::fs::File::open(path).map_err(|e| err(ReadErrorKind::Io(e)))?;
    let mut bytes = Vec::new();
    file.take(limit + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| err(ReadErrorKind::Io(e)))?;
    if bytes.len() as u64 > limit {
        return Err(err(ReadErrorKind::TooLarge { limit, what }));
    }
    Ok(bytes)
}

/// A note for the user: a reader's own (its settings named as the caller names them), or a
/// caller's text.
#[derive(Clone, Debug, PartialEq)]
pub enum Note {
    Text(String),
    Read(ReadNote),
}

/// What a reader chose that the user may want to choose otherwise.
#[derive(Clone, Debug, PartialEq)]
pub enum ReadNote {
    /// A CSV's first data column (`channel`'s header, or `column N`) taken among `names`.
    ChannelChosen { channel: String, names: Vec<String> },
    /// An `.ide` file's first acceleration subchannel taken among `count` (the file has
    /// `subchannels`).
    SubchannelChosen {
        subchannel: String,
        count: usize,
        subchannels: Vec<String>,
    },
}

impl Note {
    /// The note's text, the settings it names written by `names`.
    pub fn text(&self, names: OptionNames) -> String {
        match self {
            Note::Text(t) => t.clone(),
            Note::Read(ReadNote::ChannelChosen { channel, names: all }) => format!(
                "analysing {channel} of {} channels ({}): choose one with {}, or {} for their resultant",
                all.len(),
                all.join(", "),
                names(Opt::Column),
                names(Opt::Axes)
            ),
            Note::Read(ReadNote::SubchannelChosen {
                subchannel,
                count,
                subchannels,
            }) => format!(
                "analysing {subchannel} of {count} acceleration subchannels: choose one with {} CH.SUB (the file has: {})",
                names(Opt::Column),
                subchannels.join(", ")
            ),
        }
    }
}

/// Notes for the user, each once (a file read in passes is opened again for each pass).
static NOTES: std::sync::Mutex<Vec<Note>> = std::sync::Mutex::new(Vec::new());

/// Keeps `note: MESSAGE` for stderr: the tool prints its notes after a run that succeeded
/// ([`take_notes`]), so that an error stays one line.
pub fn note(message: &str) {
    keep(Note::Text(message.to_string()));
}

/// Keeps a reader's note ([`note`]).
pub(crate) fn note_read(note: ReadNote) {
    keep(Note::Read(note));
}

fn keep(note: Note) {
    let note = OWN_NOTES.with(|own| match own.borrow_mut().as_mut() {
        Some(notes) => {
            if !notes.contains(&note) {
                notes.push(note);
            }
            None
        }
        None => Some(note),
    });
    let Some(note) = note else { return };
    if let Ok(mut notes) = NOTES.lock() {
        if !notes.contains(&note) {
            notes.push(note);
        }
    }
}

std::thread_local! {
    /// The notes of an analysis that keeps its own ([`with_own_notes`]).
    static OWN_NOTES: std::cell::RefCell<Option<Vec<Note>>> =
        const { std::cell::RefCell::new(None) };
}

/// Runs `f` with the notes it gives on this thread kept apart (a series' recordings,
/// analysed side by side, each with its own notes), and returns them with its result, the
/// settings they name written by `names`.
pub fn with_own_notes<R>(names: OptionNames, f: impl FnOnce() -> R) -> (R, Vec<String>) {
    OWN_NOTES.with(|own| *own.borrow_mut() = Some(Vec::new()));
    let r = f();
    let notes = OWN_NOTES.with(|own| own.borrow_mut().take());
    let notes = notes.unwrap_or_default();
    (r, notes.iter().map(|n| n.text(names)).collect())
}

/// Whether the thread that starts a worker keeps its own notes ([`with_own_notes`]): the
/// worker's notes then go back to it ([`WorkerNotes::keep`]), not to the process's, so an
/// analysis run beside another (a series, Python threads) has all its notes and no other's.
#[derive(Clone, Copy, Debug)]
pub struct NoteScope {
    own: bool,
}

/// The notes a worker thread gave in a [`NoteScope`] that keeps them apart.
#[derive(Debug, Default)]
pub struct WorkerNotes(Vec<Note>);

impl NoteScope {
    /// The calling thread's scope.
    pub fn here() -> Self {
        Self {
            own: OWN_NOTES.with(|o| o.borrow().is_some()),
        }
    }

    /// Runs `f` (on the worker thread) in this scope: its notes, if the starting thread
    /// keeps its own, kept apart and returned.
    pub fn run<R>(self, f: impl FnOnce() -> R) -> (R, WorkerNotes) {
        if !self.own {
            return (f(), WorkerNotes::default());
        }
        OWN_NOTES.with(|own| *own.borrow_mut() = Some(Vec::new()));
        let r = f();
        let notes = OWN_NOTES.with(|own| own.borrow_mut().take());
        (r, WorkerNotes(notes.unwrap_or_default()))
    }
}

impl WorkerNotes {
    /// Keeps the worker's notes on the calling thread (the one that started it), as if it
    /// had given them.
    pub fn keep(self) {
        for n in self.0 {
            keep(n);
        }
    }
}

/// The notes kept so far (and forgets them), the settings they name written by `names`.
pub fn take_notes(names: OptionNames) -> Vec<String> {
    NOTES
        .lock()
        .map(|mut n| std::mem::take(&mut *n))
        .unwrap_or_default()
        .iter()
        .map(|n| n.text(names))
        .collect()
}
