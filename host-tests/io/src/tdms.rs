//! NI TDMS files (`impact analyze FILE.tdms`), read by the `tdms-rs` crate: one channel, named
//! `group/channel` or `channel` (or a 0-based index over the file's channels in order), at the
//! rate of its waveform properties (`wf_increment`) or `--rate`. Numeric channels of any
//! integer or float type; DAQmx raw (scaled) data is what the crate reads, and it is not
//! checked against NI's own files here. Segments written interleaved are refused.

use std::path::{Path, PathBuf};

use tdms_rs::{DataType, PropertyValue, TdmsChannel, TdmsFile};

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

/// Walks the file's segments and their metadata (NI's "TDMS File Format Internal Structure")
/// and checks every length against the bytes there, so that the reader never allocates for a
/// length a damaged file claims: the byte where the first inconsistency is, if any.
fn check_structure(path: &Path) -> Result<(), TdmsFault> {
    use std::io::{Read, Seek, SeekFrom};
    let mut file = std::fs::File::open(path).map_err(TdmsFault::Io)?;
    let len = file.metadata().map_err(TdmsFault::Io)?.len() as usize;
    let at = |byte: usize, fault: Fault| TdmsFault::Structure {
        byte: byte as u64,
        fault,
    };
    // Each segment's lead-in and metadata are read, never its data.
    let mut read_at = |byte: usize, n: usize| -> Result<Vec<u8>, TdmsFault> {
        let mut buf = vec![0u8; n];
        file.seek(SeekFrom::Start(byte as u64))
            .and_then(|_| file.read_exact(&mut buf))
            .map_err(|e| at(byte, Fault::Read(e)))?;
        Ok(buf)
    };
    struct Cursor<'a> {
        b: &'a [u8],
        /// The file's byte where `b` starts.
        base: usize,
        at: usize,
        end: usize,
    }
    impl Cursor<'_> {
        fn take(&mut self, n: usize) -> Result<&[u8], TdmsFault> {
            let Some(to) = self.at.checked_add(n).filter(|&t| t <= self.end) else {
                return Err(self.fault(Fault::Announced {
                    announced: n,
                    left: self.end.saturating_sub(self.at),
                }));
            };
            let s = &self.b[self.at..to];
            self.at = to;
            Ok(s)
        }
        fn u32(&mut self) -> Result<u32, TdmsFault> {
            let s = self.take(4)?;
            Ok(u32::from_le_bytes([s[0], s[1], s[2], s[3]]))
        }
        fn string(&mut self) -> Result<(), TdmsFault> {
            let n = self.u32()? as usize;
            self.take(n).map(|_| ())
        }
        /// A fault at the cursor's byte less `back`.
        fn fault_back(&self, back: usize, fault: Fault) -> TdmsFault {
            TdmsFault::Structure {
                byte: (self.base + self.at - back) as u64,
                fault,
            }
        }
        fn fault(&self, fault: Fault) -> TdmsFault {
            self.fault_back(0, fault)
        }
    }
    // Bytes of a property value of type `t` (strings are handled apart).
    let fixed = |t: u32| -> Option<usize> {
        match t {
            1 | 5 | 0x21 => Some(1),
            2 | 6 => Some(2),
            3 | 7 | 9 => Some(4),
            4 | 8 | 10 => Some(8),
            11 => Some(10),
            0x19 => Some(4),
            0x1A => Some(8),
            0x44 => Some(16),
            0x08000C => Some(8),
            0x10000D => Some(16),
            _ => None,
        }
    };
    let mut seg = 0usize;
    while seg < len {
        if seg + 28 > len {
            return Err(at(seg, Fault::LeadInCut));
        }
        let lead = read_at(seg, 28)?;
        if &lead[..4] != b"TDSm" {
            return Err(at(seg, Fault::NoTag));
        }
        let u64_at = |i: usize| u64::from_le_bytes(lead[i..i + 8].try_into().unwrap_or([0; 8]));
        let toc = u32::from_le_bytes([lead[4], lead[5], lead[6], lead[7]]);
        let next = u64_at(12);
        let raw = u64_at(20);
        let body = seg + 28;
        let meta_end = body
            .checked_add(raw as usize)
            .filter(|&e| e <= len)
            .ok_or_else(|| at(seg, Fault::MetadataPastEnd { bytes: raw }))?;
        if toc & (1 << 6) != 0 {
            return Err(at(seg, Fault::BigEndian));
        }
        // Interleaved raw data (1 << 5, with raw data 1 << 3): the crate reads it as if
        // contiguous, which gives another channel's values or none; refused.
        if toc & (1 << 5) != 0 && toc & (1 << 3) != 0 {
            return Err(at(seg, Fault::Interleaved));
        }
        // Metadata (1 << 1) or a new object list (1 << 2): the reader parses either.
        if toc & 0b110 != 0 {
            if raw > MAX_METADATA {
                return Err(at(seg, Fault::MetadataTooLarge { bytes: raw }));
            }
            let meta = read_at(body, meta_end - body)?;
            let mut c = Cursor {
                b: &meta,
                base: body,
                at: 0,
                end: meta.len(),
            };
            let objects = c.u32()?;
            for _ in 0..objects {
                c.string()?;
                match c.u32()? {
                    0xFFFF_FFFF | 0 => {}
                    0x6912_0000 | 0x6913_0000 => return Err(c.fault_back(4, Fault::DaqmxRaw)),
                    n => {
                        // Data type, dimension, value count, and for strings their size.
                        let n = n as usize;
                        if !(20..=28).contains(&n) {
                            return Err(c.fault_back(4, Fault::RawIndex { bytes: n }));
                        }
                        c.take(n - 4)?;
                    }
                }
                let properties = c.u32()?;
                for _ in 0..properties {
                    c.string()?;
                    match c.u32()? {
                        0x20 => c.string()?,
                        t => {
                            let n =
                                fixed(t).ok_or_else(|| c.fault_back(4, Fault::PropertyType(t)))?;
                            c.take(n)?;
                        }
                    }
                }
            }
        }
        let next_seg = body
            .checked_add(next as usize)
            .ok_or_else(|| at(seg, Fault::NextOffset(next)))?;
        if next == u64::MAX || next_seg > len {
            // The last segment (still being written, or cut): nothing follows it.
            break;
        }
        if next_seg <= seg {
            return Err(at(seg, Fault::NextGoesBack(next)));
        }
        seg = next_seg;
    }
    Ok(())
}

/// Reads the channel `opts.column` [default: the first one].
pub fn read_tdms(path: &Path, opts: &ReadOptions) -> Result<Channel, ReadError> {
    if opts.time_column.is_some() || opts.resample || !opts.axes.is_empty() {
        return Err(ReadError::new(path, ReadErrorKind::TdmsOptions));
    }
    let mut open = TdmsStream::open(path, opts.column.as_ref(), opts.rate_hz)?;
    let mut values = Vec::with_capacity(open.len);
    open.next_values(open.len, &mut values)?;
    let name = open.name.clone();
    evenly_sampled(name, values, open.rate_hz).map_err(|e| open.fault(TdmsChannelFault::Samples(e)))
}

/// One channel of a TDMS file, read a range at a time (`impact analyze --stream`).
pub struct TdmsStream {
    path: PathBuf,
    file: TdmsFile,
    group: String,
    channel: String,
    /// `group/channel` (and its `unit_string` in brackets when the name names no unit), its
    /// rate (Hz) and its values' count.
    pub name: String,
    pub rate_hz: f64,
    pub len: usize,
    /// Values read so far.
    at: usize,
}

impl TdmsStream {
    /// Opens `path`'s channel `column` [default: the first] after checking the file's
    /// structure (segment by segment, without reading the data); the rate from `rate_hz` or
    /// the channel's `wf_increment`.
    pub fn open(
        path: &Path,
        column: Option<&ColumnRef>,
        rate_hz: Option<f64>,
    ) -> Result<Self, ReadError> {
        let err = |kind: ReadErrorKind| ReadError::new(path, kind);
        check_structure(path).map_err(|e| err(e.into()))?;
        let file = TdmsFile::open(path).map_err(|e| err(TdmsFault::Library(e).into()))?;
        let all: Vec<(String, String)> = file
            .groups()
            .flat_map(|g| {
                let group = g.name().to_string();
                g.channels()
                    .map(move |c| (group.clone(), c.name().to_string()))
                    .collect::<Vec<_>>()
            })
            .collect();
        let names = || all.iter().map(|(g, c)| format!("{g}/{c}")).collect();
        if all.is_empty() {
            return Err(err(TdmsFault::NoChannels.into()));
        }
        let found = match column {
            None => all.first(),
            Some(ColumnRef::Index(i)) => all.get(*i),
            Some(ColumnRef::Name(n)) => {
                all.iter().find(|(g, c)| format!("{g}/{c}") == *n || c == n)
            }
        };
        let Some((group, channel)) = found.cloned() else {
            return Err(err(ReadErrorKind::TdmsNoSuchChannel {
                column: column.cloned(),
                channels: names(),
            }));
        };
        let mut open = Self {
            path: path.to_path_buf(),
            file,
            name: format!("{group}/{channel}"),
            group,
            channel,
            rate_hz: 0.0,
            len: 0,
            at: 0,
        };
        let ch = open.channel()?;
        // NI's writers keep the channel's unit in `unit_string`: it names the units as a
        // CSV header's brackets do (`group/channel (m/s^2)`), unless the name already does.
        let unit = match ch.property("unit_string") {
            Some(PropertyValue::String(u)) if !u.trim().is_empty() => Some(u.trim().to_string()),
            _ => None,
        };
        // An acceleration or force unit the header parser knows is taken; another (a voltage,
        // `EU`, a velocity's `m/s`) is said, and the channel read as an unnamed one.
        let known =
            |u: &str| u != "m/s" && crate::units::Units::of_header(&format!("x ({u})")).is_some();
        let name = match unit {
            Some(u) if crate::units::Units::of_header(&open.name).is_none() && known(&u) => {
                format!("{} ({u})", open.name)
            }
            Some(u) if !known(&u) => {
                crate::note(&format!(
                    "{}: its unit_string {u:?} is no acceleration or force unit this tool reads",
                    open.name
                ));
                open.name.clone()
            }
            _ => open.name.clone(),
        };
        let increment = match ch.property("wf_increment") {
            Some(PropertyValue::Double(d)) if d.is_finite() && *d > 0.0 => Some(*d),
            _ => None,
        };
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
        // A header may claim more values than the file holds: check before allocating.
        let file_bytes = std::fs::metadata(path).map(|m| m.len()).unwrap_or(0);
        let item = match ch.dtype() {
            DataType::I8 | DataType::U8 => 1,
            DataType::I16 | DataType::U16 => 2,
            DataType::I32 | DataType::U32 | DataType::Float => 4,
            _ => 8,
        };
        if (ch.len() as u128) * item > u128::from(file_bytes) {
            return Err(open.fault(TdmsChannelFault::TooManyValues {
                values: ch.len(),
                file_bytes,
            }));
        }
        let len = ch.len();
        (open.rate_hz, open.len, open.name) = (rate_hz, len, name);
        Ok(open)
    }

    /// The channel in the file.
    fn channel(&self) -> Result<TdmsChannel<'_>, ReadError> {
        self.file
            .groups()
            .find(|g| g.name() == self.group)
            .and_then(|g| g.channels().find(|c| c.name() == self.channel))
            .ok_or_else(|| {
                ReadError::new(
                    &self.path,
                    TdmsFault::ChannelLost {
                        channel: self.name.clone(),
                    },
                )
            })
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

    /// Appends the next values (at most `want`, none at the end) to `out`; an error names the
    /// value that is not finite.
    pub fn next_values(&mut self, want: usize, out: &mut Vec<f64>) -> Result<(), ReadError> {
        let range = self.at..(self.at + want.max(1)).min(self.len);
        if range.is_empty() {
            return Ok(());
        }
        let ch = self.channel()?;
        let from = out.len();
        read_range(&ch, range.clone(), out).map_err(|e| self.fault(e))?;
        if let Some(k) = out[from..].iter().position(|v| !v.is_finite()) {
            return Err(self.fault(TdmsChannelFault::NotFinite(range.start + k)));
        }
        self.at = range.end;
        Ok(())
    }
}

/// Values `range` of `ch` appended to `out` as f64.
fn read_range(
    ch: &TdmsChannel,
    range: std::ops::Range<usize>,
    out: &mut Vec<f64>,
) -> Result<(), TdmsChannelFault> {
    fn read<T: tdms_rs::api::reader::Pod + Default + Into<f64>>(
        ch: &TdmsChannel,
        range: std::ops::Range<usize>,
        out: &mut Vec<f64>,
    ) -> Result<(), TdmsChannelFault> {
        let mut buf = vec![T::default(); range.len()];
        ch.read(range, &mut buf).map_err(TdmsChannelFault::Read)?;
        out.extend(buf.into_iter().map(Into::into));
        Ok(())
    }
    match ch.dtype() {
        DataType::Double => read::<f64>(ch, range, out),
        DataType::Float => read::<f32>(ch, range, out),
        DataType::I8 => read::<i8>(ch, range, out),
        DataType::I16 => read::<i16>(ch, range, out),
        DataType::I32 => read::<i32>(ch, range, out),
        DataType::U8 => read::<u8>(ch, range, out),
        DataType::U16 => read::<u16>(ch, range, out),
        DataType::U32 => read::<u32>(ch, range, out),
        other => Err(TdmsChannelFault::DataType(other)),
    }
}
