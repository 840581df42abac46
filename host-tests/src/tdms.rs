//! NI TDMS files (`impact analyze FILE.tdms`), read by the `tdms-rs` crate: one channel, named
//! `group/channel` or `channel` (or a 0-based index over the file's channels in order), at the
//! rate of its waveform properties (`wf_increment`) or `--rate`. Numeric channels of any
//! integer or float type; DAQmx raw (scaled) data is what the crate reads, and it is not
//! checked against NI's own files here.

use std::path::Path;

use tdms_rs::{DataType, PropertyValue, TdmsChannel, TdmsFile};

use crate::recording::{evenly_sampled, Channel, ReadOptions};
use crate::table::{one_line, ColumnRef, RecordingError};

/// True for a `.tdms` file name (any case).
pub fn is_tdms(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("tdms"))
}

/// Walks the file's segments and their metadata (NI's "TDMS File Format Internal Structure")
/// and checks every length against the bytes there, so that the reader never allocates for a
/// length a damaged file claims: the byte where the first inconsistency is, if any.
fn check_structure(bytes: &[u8]) -> Result<(), String> {
    struct Cursor<'a> {
        b: &'a [u8],
        at: usize,
        end: usize,
    }
    impl Cursor<'_> {
        fn take(&mut self, n: usize) -> Result<&[u8], String> {
            let to = self
                .at
                .checked_add(n)
                .filter(|&t| t <= self.end)
                .ok_or(format!(
                    "byte {}: {n} bytes announced, {} left in the segment's metadata",
                    self.at,
                    self.end.saturating_sub(self.at)
                ))?;
            let s = &self.b[self.at..to];
            self.at = to;
            Ok(s)
        }
        fn u32(&mut self) -> Result<u32, String> {
            let s = self.take(4)?;
            Ok(u32::from_le_bytes([s[0], s[1], s[2], s[3]]))
        }
        fn string(&mut self) -> Result<(), String> {
            let n = self.u32()? as usize;
            self.take(n).map(|_| ())
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
    while seg < bytes.len() {
        let lead = bytes
            .get(seg..seg + 28)
            .ok_or(format!("byte {seg}: a segment's lead-in is cut short"))?;
        if &lead[..4] != b"TDSm" {
            return Err(format!("byte {seg}: no TDSm segment tag"));
        }
        let u64_at = |i: usize| u64::from_le_bytes(lead[i..i + 8].try_into().unwrap_or([0; 8]));
        let toc = u32::from_le_bytes([lead[4], lead[5], lead[6], lead[7]]);
        let next = u64_at(12);
        let raw = u64_at(20);
        let body = seg + 28;
        let meta_end = body
            .checked_add(raw as usize)
            .filter(|&e| e <= bytes.len())
            .ok_or(format!(
                "byte {seg}: metadata of {raw} bytes runs past the file"
            ))?;
        if toc & (1 << 6) != 0 {
            return Err(format!(
                "byte {seg}: a big-endian segment, which this reader does not read"
            ));
        }
        // Metadata (1 << 1) or a new object list (1 << 2): the reader parses either.
        if toc & 0b110 != 0 {
            let mut c = Cursor {
                b: bytes,
                at: body,
                end: meta_end,
            };
            let objects = c.u32()?;
            for _ in 0..objects {
                c.string()?;
                match c.u32()? {
                    0xFFFF_FFFF | 0 => {}
                    0x6912_0000 | 0x6913_0000 => {
                        return Err(format!(
                            "byte {}: DAQmx raw data, which this reader does not read",
                            c.at - 4
                        ))
                    }
                    n => {
                        // Data type, dimension, value count, and for strings their size.
                        let n = n as usize;
                        if !(20..=28).contains(&n) {
                            return Err(format!("byte {}: raw data index of {n} bytes", c.at - 4));
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
                            let n = fixed(t)
                                .ok_or(format!("byte {}: property type {t:#x}", c.at - 4))?;
                            c.take(n)?;
                        }
                    }
                }
            }
        }
        let next_seg = body
            .checked_add(next as usize)
            .ok_or(format!("byte {seg}: next segment offset {next}"))?;
        if next == u64::MAX || next_seg > bytes.len() {
            // The last segment (still being written, or cut): nothing follows it.
            break;
        }
        if next_seg <= seg {
            return Err(format!("byte {seg}: next segment offset {next} goes back"));
        }
        seg = next_seg;
    }
    Ok(())
}

/// Every value of `ch` as f64.
fn values(ch: &TdmsChannel) -> Result<Vec<f64>, String> {
    fn read<T: tdms_rs::api::reader::Pod + Default + Into<f64>>(
        ch: &TdmsChannel,
    ) -> Result<Vec<f64>, String> {
        let mut out = vec![T::default(); ch.len()];
        ch.read(0..ch.len(), &mut out).map_err(|e| e.to_string())?;
        Ok(out.into_iter().map(Into::into).collect())
    }
    match ch.dtype() {
        DataType::Double => read::<f64>(ch),
        DataType::Float => read::<f32>(ch),
        DataType::I8 => read::<i8>(ch),
        DataType::I16 => read::<i16>(ch),
        DataType::I32 => read::<i32>(ch),
        DataType::U8 => read::<u8>(ch),
        DataType::U16 => read::<u16>(ch),
        DataType::U32 => read::<u32>(ch),
        other => Err(format!("channel type {other:?} is not a number this reads")),
    }
}

/// Reads the channel `opts.column` [default: the first one].
pub fn read_tdms(path: &Path, opts: &ReadOptions) -> Result<Channel, RecordingError> {
    let err = |message: String| RecordingError {
        file: path.to_path_buf(),
        line: None,
        message,
    };
    if opts.time_column.is_some() || opts.resample || !opts.axes.is_empty() {
        return Err(err(
            "a TDMS file takes --column (group/channel) and --rate only".into(),
        ));
    }
    let bytes = std::fs::read(path).map_err(|e| err(e.to_string()))?;
    check_structure(&bytes).map_err(|e| err(format!("TDMS: {}", one_line(e))))?;
    drop(bytes);
    let file = TdmsFile::open(path).map_err(|e| err(format!("TDMS: {}", one_line(e))))?;
    let all: Vec<(String, TdmsChannel)> = file
        .groups()
        .flat_map(|g| {
            let group = g.name().to_string();
            g.channels()
                .map(move |c| (format!("{group}/{}", c.name()), c))
                .collect::<Vec<_>>()
        })
        .collect();
    let names = || {
        all.iter()
            .map(|(n, _)| n.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    };
    let found = match &opts.column {
        None => all.first(),
        Some(ColumnRef::Index(i)) => all.get(*i),
        Some(ColumnRef::Name(n)) => all
            .iter()
            .find(|(full, c)| full == n || c.name() == n.as_str()),
    };
    let Some((name, ch)) = found else {
        return Err(err(format!(
            "no such channel{}; the file has: {}",
            opts.column.as_ref().map_or(String::new(), |c| match c {
                ColumnRef::Index(i) => format!(" {i}"),
                ColumnRef::Name(n) => format!(" {n}"),
            }),
            names()
        )));
    };
    let increment = match ch.property("wf_increment") {
        Some(PropertyValue::Double(d)) if d.is_finite() && *d > 0.0 => Some(*d),
        _ => None,
    };
    let rate_hz = match (opts.rate_hz, increment) {
        (Some(r), _) => r,
        (None, Some(dt)) => 1.0 / dt,
        (None, None) => {
            return Err(err(format!(
                "{name} has no wf_increment property: give --rate"
            )))
        }
    };
    if !(rate_hz.is_finite() && rate_hz > 0.0 && rate_hz <= 1e9) {
        return Err(err(format!("rate {rate_hz} Hz is not in (0, 1e9]")));
    }
    // A header may claim more values than the file holds: check before allocating.
    let file_bytes = std::fs::metadata(path).map(|m| m.len()).unwrap_or(0);
    let item = match ch.dtype() {
        DataType::I8 | DataType::U8 => 1,
        DataType::I16 | DataType::U16 => 2,
        DataType::I32 | DataType::U32 | DataType::Float => 4,
        _ => 8,
    };
    if (ch.len() as u128) * item > u128::from(file_bytes) {
        return Err(err(format!(
            "TDMS {name}: {} values announced, more than the file's {file_bytes} bytes hold",
            ch.len()
        )));
    }
    let values = values(ch).map_err(|e| err(format!("TDMS {name}: {}", one_line(e))))?;
    if let Some(k) = values.iter().position(|v| !v.is_finite()) {
        return Err(err(format!("TDMS {name}: value {k} is not finite")));
    }
    evenly_sampled(name.clone(), values, rate_hz).map_err(|e| err(format!("TDMS {name}: {e}")))
}
