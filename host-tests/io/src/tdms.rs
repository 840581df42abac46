//! NI TDMS files (`impact analyze FILE.tdms`), read by this module's own bounded parser of NI's
//! "TDMS File Format Internal Structure": one channel, named `group/channel` or `channel` (or a
//! 0-based index over the file's channels in order), at the rate of its waveform properties
//! (`wf_increment`) or `--rate`. Numeric channels of any integer (8 to 64 bits) or float (32,
//! 64 bits) type, in every chunk of every segment, contiguous or interleaved (ToC bit 5).
//! Refused: big-endian segments and DAQmx raw data.
//!
//! Every size a segment gives (its metadata's and its raw data's length, an object path's or a
//! string's length, a value count, a chunk's size) is checked against the bytes there before
//! anything is allocated for it: a size that lies is an error naming its byte.

use std::os::unix::fs::FileExt;
use std::path::{Path, PathBuf};

use crate::channel::{check_rate, evenly_sampled, Channel, ColumnRef, ReadOptions};
use crate::error::TdmsStructureFault as Fault;
use crate::error::{ReadError, ReadErrorKind, TdmsChannelFault, TdmsFault};
use crate::limits::RATE_HZ;

/// True for a `.tdms` file name (any case).
pub fn is_tdms(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("tdms"))
}

/// Most bytes of metadata one segment may hold (a damaged length is not allocated).
const MAX_METADATA: u64 = 64 << 20;

/// Most bytes read at once from a channel's data (an interleaved row of many channels is
/// read a few rows at a time).
const MAX_READ: u64 = 1 << 20;

/// The ToC bits of a segment's lead-in.
const TOC_META_DATA: u32 = 1 << 1;
const TOC_NEW_OBJ_LIST: u32 = 1 << 2;
const TOC_RAW_DATA: u32 = 1 << 3;
const TOC_INTERLEAVED: u32 = 1 << 5;
const TOC_BIG_ENDIAN: u32 = 1 << 6;

/// The lead-in's bytes.
const LEAD_IN: u64 = 28;

/// A numeric type this reader takes (its TDMS type code).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Numeric {
    I8,
    I16,
    I32,
    I64,
    U8,
    U16,
    U32,
    U64,
    F32,
    F64,
}

impl Numeric {
    fn of(code: u32) -> Option<Self> {
        Some(match code {
            1 => Numeric::I8,
            2 => Numeric::I16,
            3 => Numeric::I32,
            4 => Numeric::I64,
            5 => Numeric::U8,
            6 => Numeric::U16,
            7 => Numeric::U32,
            8 => Numeric::U64,
            // (0x19, 0x1A: floats "with unit", stored as plain floats.)
            9 | 0x19 => Numeric::F32,
            10 | 0x1A => Numeric::F64,
            _ => return None,
        })
    }

    fn bytes(self) -> usize {
        match self {
            Numeric::I8 | Numeric::U8 => 1,
            Numeric::I16 | Numeric::U16 => 2,
            Numeric::I32 | Numeric::U32 | Numeric::F32 => 4,
            Numeric::I64 | Numeric::U64 | Numeric::F64 => 8,
        }
    }

    /// The little-endian value at the start of `b` (at least [`Numeric::bytes`] long).
    fn decode(self, b: &[u8]) -> f64 {
        let a = |n: usize| -> [u8; 8] {
            let mut x = [0u8; 8];
            x[..n].copy_from_slice(&b[..n]);
            x
        };
        match self {
            Numeric::I8 => f64::from(b[0] as i8),
            Numeric::U8 => f64::from(b[0]),
            Numeric::I16 => f64::from(i16::from_le_bytes([b[0], b[1]])),
            Numeric::U16 => f64::from(u16::from_le_bytes([b[0], b[1]])),
            Numeric::I32 => f64::from(i32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            Numeric::U32 => f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            Numeric::F32 => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            Numeric::I64 => i64::from_le_bytes(a(8)) as f64,
            Numeric::U64 => u64::from_le_bytes(a(8)) as f64,
            Numeric::F64 => f64::from_le_bytes(a(8)),
        }
    }
}

/// Bytes of one value of type `code` in raw data or a property (strings apart); `None` for a
/// type without a fixed size.
fn fixed_size(code: u32) -> Option<u64> {
    match code {
        1 | 5 | 0x21 => Some(1),
        2 | 6 => Some(2),
        3 | 7 | 9 | 0x19 => Some(4),
        4 | 8 | 10 | 0x1A => Some(8),
        11 => Some(10),
        0x44 => Some(16),
        0x08000C => Some(8),
        0x10000D => Some(16),
        _ => None,
    }
}

/// An object's raw data index: its type, values a chunk and their bytes.
#[derive(Clone, Copy, Debug)]
struct Index {
    dtype: u32,
    count: u64,
    bytes: u64,
}

/// A run of a channel's values in one segment: `chunks` chunks of `chunk` bytes from byte
/// `start`, each holding `count` values from `offset` on, `step` bytes apart (the value's
/// size when contiguous, a row's when interleaved).
#[derive(Clone, Copy, Debug)]
struct Run {
    start: u64,
    chunk: u64,
    chunks: u64,
    offset: u64,
    count: u64,
    step: u64,
}

impl Run {
    fn values(&self) -> u64 {
        self.chunks.saturating_mul(self.count)
    }
}

/// An object of the file (`/`, a group, a channel) and what the reader keeps of it.
#[derive(Debug, Default)]
struct Object {
    /// The path's components: none for the root, the group, the group and the channel.
    names: Vec<String>,
    /// Its latest raw data index, and its data type (the first, which never changes).
    index: Option<Index>,
    dtype: Option<u32>,
    runs: Vec<Run>,
    wf_increment: Option<f64>,
    unit_string: Option<String>,
}

/// The file's objects, in the order they first appear.
struct Parsed {
    objects: Vec<Object>,
}

/// The metadata of a segment read, a cursor over it that checks every length against the
/// bytes left.
struct Cursor<'a> {
    b: &'a [u8],
    /// The file's byte where `b` starts.
    base: u64,
    at: usize,
}

impl Cursor<'_> {
    fn take(&mut self, n: u64) -> Result<&[u8], TdmsFault> {
        let left = self.b.len() - self.at;
        let Some(n) = usize::try_from(n).ok().filter(|&n| n <= left) else {
            return Err(self.fault(Fault::Announced {
                announced: usize::try_from(n).unwrap_or(usize::MAX),
                left,
            }));
        };
        let s = &self.b[self.at..self.at + n];
        self.at += n;
        Ok(s)
    }
    fn u32(&mut self) -> Result<u32, TdmsFault> {
        let s = self.take(4)?;
        Ok(u32::from_le_bytes([s[0], s[1], s[2], s[3]]))
    }
    fn u64(&mut self) -> Result<u64, TdmsFault> {
        let s = self.take(8)?;
        let mut a = [0u8; 8];
        a.copy_from_slice(s);
        Ok(u64::from_le_bytes(a))
    }
    fn string(&mut self) -> Result<String, TdmsFault> {
        let n = self.u32()?;
        Ok(String::from_utf8_lossy(self.take(u64::from(n))?).into_owned())
    }
    /// A fault at the cursor's byte less `back`.
    fn fault_back(&self, back: usize, fault: Fault) -> TdmsFault {
        TdmsFault::Structure {
            byte: self.base + (self.at - back) as u64,
            fault,
        }
    }
    fn fault(&self, fault: Fault) -> TdmsFault {
        self.fault_back(0, fault)
    }
}

/// An object path's components (`/'group'/'channel'`, a `'` inside a name doubled); `None`
/// if it is none.
fn path_names(path: &str) -> Option<Vec<String>> {
    if path == "/" {
        return Some(Vec::new());
    }
    let mut names = Vec::new();
    let mut chars = path.chars().peekable();
    while chars.peek().is_some() {
        if chars.next() != Some('/') || chars.next() != Some('\'') {
            return None;
        }
        let mut name = String::new();
        loop {
            match chars.next()? {
                '\'' if chars.peek() == Some(&'\'') => {
                    chars.next();
                    name.push('\'');
                }
                '\'' => break,
                c => name.push(c),
            }
        }
        names.push(name);
    }
    (names.len() <= 2).then_some(names)
}

/// Walks the file's segments (each lead-in and metadata read, never the data) and indexes
/// every object's values: their runs, chunk by chunk, contiguous or interleaved. Every length
/// is checked against the bytes there, so nothing is allocated for a length a damaged file
/// claims: the byte where the first inconsistency is, if any.
fn index_file(file: &std::fs::File) -> Result<Parsed, TdmsFault> {
    let len = file.metadata().map_err(TdmsFault::Io)?.len();
    let at = |byte: u64, fault: Fault| TdmsFault::Structure { byte, fault };
    let read_at = |byte: u64, n: u64| -> Result<Vec<u8>, TdmsFault> {
        // (n is at most MAX_METADATA or a lead-in, and lies within the file.)
        let mut buf = vec![0u8; n as usize];
        file.read_exact_at(&mut buf, byte)
            .map_err(|e| at(byte, Fault::Read(e)))?;
        Ok(buf)
    };
    let mut objects: Vec<Object> = Vec::new();
    let mut by_path: std::collections::HashMap<String, usize> = Default::default();
    // The objects with data in the current segment, in their order.
    let mut active: Vec<usize> = Vec::new();
    let mut seg = 0u64;
    while seg < len {
        if len - seg < LEAD_IN {
            return Err(at(seg, Fault::LeadInCut));
        }
        let lead = read_at(seg, LEAD_IN)?;
        if &lead[..4] != b"TDSm" {
            return Err(at(seg, Fault::NoTag));
        }
        let u64_at = |i: usize| {
            let mut a = [0u8; 8];
            a.copy_from_slice(&lead[i..i + 8]);
            u64::from_le_bytes(a)
        };
        let toc = u32::from_le_bytes([lead[4], lead[5], lead[6], lead[7]]);
        let next = u64_at(12);
        let raw = u64_at(20);
        let body = seg + LEAD_IN;
        if toc & TOC_BIG_ENDIAN != 0 {
            return Err(at(seg, Fault::BigEndian));
        }
        if raw > len - body {
            return Err(at(seg, Fault::MetadataPastEnd { bytes: raw }));
        }
        // The segment's end: the next one's start, or the file's end for the last one while
        // it is being written; one announced past the file's end is a file cut short.
        // (NI's writers leave the offset all ones while they write the segment.)
        let next_seg = body.checked_add(next).filter(|_| next != u64::MAX);
        let (end, cut) = match next_seg {
            Some(e) if e <= len => (e, false),
            None if next == u64::MAX => (len, true),
            _ => {
                return Err(at(
                    seg,
                    Fault::SegmentPastEnd {
                        bytes: next,
                        left: len - body,
                    },
                ))
            }
        };
        if raw > end - body {
            return Err(at(seg, Fault::MetadataPastSegment { raw, next }));
        }
        if toc & TOC_META_DATA != 0 {
            if raw > MAX_METADATA {
                return Err(at(seg, Fault::MetadataTooLarge { bytes: raw }));
            }
            let meta = read_at(body, raw)?;
            let mut c = Cursor {
                b: &meta,
                base: body,
                at: 0,
            };
            if toc & TOC_NEW_OBJ_LIST != 0 {
                active.clear();
            }
            // Each object takes at least 12 bytes: the count is bounded by the metadata's.
            let count = c.u32()?;
            for _ in 0..count {
                let path_at = c.at;
                let path = c.string()?;
                let id = match by_path.get(&path) {
                    Some(&id) => id,
                    None => {
                        let names = path_names(&path).ok_or_else(|| {
                            c.fault_back(c.at - path_at, Fault::ObjectPath(path.clone()))
                        })?;
                        objects.push(Object {
                            names,
                            ..Object::default()
                        });
                        by_path.insert(path, objects.len() - 1);
                        objects.len() - 1
                    }
                };
                let has_data = match c.u32()? {
                    0xFFFF_FFFF => false,
                    0 => {
                        if objects[id].index.is_none() {
                            return Err(c.fault_back(4, Fault::NoPreviousIndex));
                        }
                        true
                    }
                    0x6912_0000 | 0x6913_0000 => return Err(c.fault_back(4, Fault::DaqmxRaw)),
                    n => {
                        // Its length (counted), type, dimension, values, and for strings
                        // their bytes.
                        let index_at = c.at - 4;
                        if !(20..=28).contains(&n) {
                            return Err(c.fault_back(4, Fault::RawIndex { bytes: n as usize }));
                        }
                        let dtype = c.u32()?;
                        let dimension = c.u32()?;
                        if dimension != 1 {
                            return Err(c.fault_back(4, Fault::Dimension(dimension)));
                        }
                        let count = c.u64()?;
                        let bytes = match fixed_size(dtype) {
                            Some(size) => {
                                if n != 20 {
                                    c.take(u64::from(n) - 20)?;
                                }
                                count.checked_mul(size).ok_or_else(|| {
                                    c.fault_back(
                                        c.at - index_at,
                                        Fault::ValuesTooMany {
                                            values: count,
                                            bytes: size,
                                        },
                                    )
                                })?
                            }
                            // A string's (or another type's) bytes follow its count.
                            None if n == 28 => c.u64()?,
                            None => c.take(u64::from(n) - 20).map(|_| 0)?,
                        };
                        let o = &mut objects[id];
                        match o.dtype {
                            Some(from) if from != dtype => {
                                return Err(c.fault_back(
                                    c.at - index_at,
                                    Fault::TypeChanges { from, to: dtype },
                                ))
                            }
                            _ => o.dtype = Some(dtype),
                        }
                        o.index = Some(Index {
                            dtype,
                            count,
                            bytes,
                        });
                        true
                    }
                };
                let listed = active.iter().position(|&a| a == id);
                match (has_data, listed) {
                    (true, None) => active.push(id),
                    (false, Some(k)) => {
                        active.remove(k);
                    }
                    _ => {}
                }
                let properties = c.u32()?;
                for _ in 0..properties {
                    let name = c.string()?;
                    let o = &mut objects[id];
                    match c.u32()? {
                        0x20 => {
                            let value = c.string()?;
                            if name == "unit_string" {
                                o.unit_string = Some(value);
                            }
                        }
                        t => {
                            let n = fixed_size(t)
                                .ok_or_else(|| c.fault_back(4, Fault::PropertyType(t)))?;
                            let value = c.take(n)?;
                            if name == "wf_increment" {
                                o.wf_increment = match t {
                                    9 => Some(Numeric::F32.decode(value)),
                                    10 => Some(Numeric::F64.decode(value)),
                                    _ => None,
                                };
                            }
                        }
                    }
                }
            }
        }
        if toc & TOC_RAW_DATA != 0 {
            let start = body + raw;
            let data = end - start;
            let interleaved = toc & TOC_INTERLEAVED != 0;
            let mut chunk = 0u64;
            for &id in &active {
                let ix = objects[id].index.unwrap_or(Index {
                    dtype: 0,
                    count: 0,
                    bytes: 0,
                });
                let bytes = if interleaved {
                    fixed_size(ix.dtype).ok_or_else(|| at(seg, Fault::InterleavedType(ix.dtype)))?
                } else {
                    ix.bytes
                };
                chunk = chunk.checked_add(bytes).ok_or_else(|| {
                    at(
                        seg,
                        Fault::ValuesTooMany {
                            values: ix.count,
                            bytes,
                        },
                    )
                })?;
            }
            // An interleaved chunk is `count` rows of one value of each channel.
            let rows = match active.first().and_then(|&id| objects[id].index) {
                Some(first) if interleaved => {
                    for &id in &active {
                        let other = objects[id].index.map_or(0, |i| i.count);
                        if other != first.count {
                            return Err(at(
                                seg,
                                Fault::InterleavedCounts {
                                    first: first.count,
                                    other,
                                },
                            ));
                        }
                    }
                    first.count
                }
                _ => 1,
            };
            let chunk_bytes = chunk.checked_mul(rows).ok_or_else(|| {
                at(
                    seg,
                    Fault::ValuesTooMany {
                        values: rows,
                        bytes: chunk,
                    },
                )
            })?;
            if chunk_bytes > 0 {
                // A last segment still being written keeps its whole chunks; in a closed one
                // the data is a whole number of chunks, or a size lies.
                if !cut && data % chunk_bytes != 0 {
                    return Err(at(
                        seg,
                        Fault::NotWholeChunks {
                            data,
                            chunk: chunk_bytes,
                        },
                    ));
                }
                let chunks = data / chunk_bytes;
                let mut offset = 0u64;
                for &id in &active {
                    let o = &mut objects[id];
                    let Some(ix) = o.index else { continue };
                    let size = fixed_size(ix.dtype).unwrap_or(0);
                    let (step, width) = if interleaved {
                        (chunk, size)
                    } else {
                        (size.max(1), ix.bytes)
                    };
                    if chunks > 0 && ix.count > 0 {
                        o.runs.push(Run {
                            start,
                            chunk: chunk_bytes,
                            chunks,
                            offset,
                            count: ix.count,
                            step,
                        });
                    }
                    offset += width;
                }
            }
        }
        match next_seg {
            Some(n) => {
                if n <= seg {
                    return Err(at(seg, Fault::NextGoesBack(next)));
                }
                seg = n;
            }
            // The last segment, still being written: nothing follows it.
            None => break,
        }
    }
    Ok(Parsed { objects })
}

/// Reads the channel `opts.column` [default: the first one].
pub fn read_tdms(path: &Path, opts: &ReadOptions) -> Result<Channel, ReadError> {
    if opts.time_column.is_some() || opts.resample || !opts.axes.is_empty() {
        return Err(ReadError::new(path, ReadErrorKind::TdmsOptions));
    }
    let mut open = TdmsStream::open(path, opts.column.as_ref(), opts.rate_hz)?;
    // (The count is bounded by the file's bytes: every value was found in its data.)
    let mut values = Vec::with_capacity(open.len);
    while values.len() < open.len {
        let before = values.len();
        open.next_values(open.len - values.len(), &mut values)?;
        if values.len() == before {
            break;
        }
    }
    let name = open.name.clone();
    evenly_sampled(name, values, open.rate_hz).map_err(|e| open.fault(TdmsChannelFault::Samples(e)))
}

/// One channel of a TDMS file, read a range at a time (`impact analyze --stream`).
pub struct TdmsStream {
    path: PathBuf,
    file: std::fs::File,
    dtype: u32,
    runs: Vec<Run>,
    /// `group/channel` (and its `unit_string` in brackets when the name names no unit), its
    /// rate (Hz) and its values' count.
    pub name: String,
    pub rate_hz: f64,
    pub len: usize,
    /// Values read so far: in all, the run being read and in it.
    at: usize,
    run: usize,
    in_run: u64,
    buf: Vec<u8>,
}

impl TdmsStream {
    /// Opens `path`'s channel `column` [default: the first] after indexing the file's
    /// segments (without reading the data); the rate from `rate_hz` or the channel's
    /// `wf_increment`.
    pub fn open(
        path: &Path,
        column: Option<&ColumnRef>,
        rate_hz: Option<f64>,
    ) -> Result<Self, ReadError> {
        let err = |kind: ReadErrorKind| ReadError::new(path, kind);
        let file = std::fs::File::open(path).map_err(|e| err(TdmsFault::Io(e).into()))?;
        let parsed = index_file(&file).map_err(|e| err(e.into()))?;
        // The channels by group, the groups and the channels in the order they first appear.
        let mut groups: Vec<&str> = Vec::new();
        for o in &parsed.objects {
            if let Some(g) = o.names.first() {
                if !groups.contains(&g.as_str()) {
                    groups.push(g);
                }
            }
        }
        let all: Vec<&Object> = groups
            .iter()
            .flat_map(|g| {
                parsed
                    .objects
                    .iter()
                    .filter(move |o| o.names.len() == 2 && o.names[0] == *g)
            })
            .collect();
        let full = |o: &Object| format!("{}/{}", o.names[0], o.names[1]);
        if all.is_empty() {
            return Err(err(TdmsFault::NoChannels.into()));
        }
        let found = match column {
            None => all.first(),
            Some(ColumnRef::Index(i)) => all.get(*i),
            Some(ColumnRef::Name(n)) => all.iter().find(|o| full(o) == *n || o.names[1] == *n),
        };
        let Some(ch) = found.copied() else {
            return Err(err(ReadErrorKind::TdmsNoSuchChannel {
                column: column.cloned(),
                channels: all.iter().map(|o| full(o)).collect(),
            }));
        };
        let channel_name = full(ch);
        // NI's writers keep the channel's unit in `unit_string`: it names the units as a
        // CSV header's brackets do (`group/channel (m/s^2)`), unless the name already does.
        let unit = ch
            .unit_string
            .as_deref()
            .map(str::trim)
            .filter(|u| !u.is_empty());
        // An acceleration or force unit the header parser knows is taken; another (a voltage,
        // `EU`, a velocity's `m/s`) is said, and the channel read as an unnamed one.
        let known =
            |u: &str| u != "m/s" && crate::units::Units::of_header(&format!("x ({u})")).is_some();
        let name = match unit {
            Some(u) if crate::units::Units::of_header(&channel_name).is_none() && known(u) => {
                format!("{channel_name} ({u})")
            }
            Some(u) if !known(u) => {
                crate::note(&format!(
                    "{channel_name}: its unit_string {u:?} is no acceleration or force unit this tool reads",
                ));
                channel_name.clone()
            }
            _ => channel_name.clone(),
        };
        let increment = ch.wf_increment.filter(|d| d.is_finite() && *d > 0.0);
        let rate_hz = match (rate_hz, increment) {
            (Some(r), _) => check_rate(r).map_err(err)?,
            (None, Some(dt)) => {
                // The interval between samples, s: its limits are the rate's.
                if !RATE_HZ.reciprocal("s").contains(dt) {
                    return Err(err(ReadErrorKind::TdmsIncrementOutOfRange {
                        channel: name,
                        increment_s: dt,
                    }));
                }
                1.0 / dt
            }
            (None, None) => return Err(err(ReadErrorKind::TdmsNoIncrement { channel: name })),
        };
        let values = ch
            .runs
            .iter()
            .fold(0u64, |n, r| n.saturating_add(r.values()));
        let open = Self {
            path: path.to_path_buf(),
            file,
            dtype: ch.dtype.unwrap_or(0),
            runs: ch.runs.clone(),
            name,
            rate_hz,
            len: usize::try_from(values).unwrap_or(usize::MAX),
            at: 0,
            run: 0,
            in_run: 0,
            buf: Vec::new(),
        };
        if values > 0 && Numeric::of(open.dtype).is_none() {
            return Err(open.fault(TdmsChannelFault::DataType(open.dtype)));
        }
        Ok(open)
    }

    /// The error of the channel's `fault`.
    fn fault(&self, fault: TdmsChannelFault) -> ReadError {
        ReadError::new(
            &self.path,
            ReadErrorKind::TdmsChannel {
                channel: self.name.clone(),
                fault,
            },
        )
    }

    /// Appends the next values (at most `want`, at least one unless at the end) to `out`; an
    /// error names the value that is not finite.
    pub fn next_values(&mut self, want: usize, out: &mut Vec<f64>) -> Result<(), ReadError> {
        let Some(kind) = Numeric::of(self.dtype) else {
            return Ok(());
        };
        let size = kind.bytes() as u64;
        let mut left = want.max(1) as u64;
        while left > 0 {
            let Some(run) = self.runs.get(self.run).copied() else {
                break;
            };
            if self.in_run >= run.values() {
                (self.run, self.in_run) = (self.run + 1, 0);
                continue;
            }
            // The values left in this chunk, as many as a read of MAX_READ bytes takes.
            let (c, i) = (self.in_run / run.count, self.in_run % run.count);
            let n = left.min(run.count - i).min((MAX_READ / run.step).max(1));
            let byte = run.start + c * run.chunk + run.offset + i * run.step;
            let span = (n - 1) * run.step + size;
            self.buf.resize(span as usize, 0);
            if let Err(error) = self.file.read_exact_at(&mut self.buf, byte) {
                return Err(self.fault(TdmsChannelFault::Read { byte, error }));
            }
            let from = out.len();
            out.extend(
                self.buf
                    .chunks(run.step as usize)
                    .take(n as usize)
                    .map(|b| kind.decode(b)),
            );
            if let Some(k) = out[from..].iter().position(|v| !v.is_finite()) {
                return Err(self.fault(TdmsChannelFault::NotFinite(self.at + k)));
            }
            self.in_run += n;
            self.at += n as usize;
            left -= n;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn object_paths_split_into_group_and_channel() {
        assert_eq!(path_names("/"), Some(vec![]));
        assert_eq!(path_names("/'g'"), Some(vec!["g".to_string()]));
        assert_eq!(
            path_names("/'a''b'/'c/d'"),
            Some(vec!["a'b".to_string(), "c/d".to_string()])
        );
        assert_eq!(path_names("/'g'/'c'/'x'"), None);
        assert_eq!(path_names("g/c"), None);
        assert_eq!(path_names("/'unclosed"), None);
    }
}
