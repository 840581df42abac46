//! Raw binary recordings (`FILE.i16` or `FILE.f32`: little-endian 16-bit integers or 32-bit
//! floats, `--rate` and `--gain` given, channels interleaved by `--raw-channels`), as DAQ
//! programs and DMA dumps write them.

use std::path::Path;

use super::channel::RawType;

use crate::channel::{check_rate, evenly_sampled, numbered_column, Channel, ReadOptions};
use crate::error::{Numbered, ReadError, ReadErrorKind};

impl RawType {
    /// The values at byte `at` of each `frame`-byte frame of `bytes` (whole frames), handed
    /// to `push`; a float that is not finite stops it: its frame's index and value.
    pub fn decode(
        self,
        bytes: &[u8],
        frame: usize,
        at: usize,
        mut push: impl FnMut(f64),
    ) -> Result<(), (usize, f32)> {
        let frames = bytes.chunks_exact(frame);
        match self {
            RawType::I16 => {
                for f in frames {
                    push(f64::from(i16::from_le_bytes([f[at], f[at + 1]])));
                }
            }
            RawType::F32 => {
                for (k, f) in frames.enumerate() {
                    let v = f32::from_le_bytes([f[at], f[at + 1], f[at + 2], f[at + 3]]);
                    if !v.is_finite() {
                        return Err((k, v));
                    }
                    push(f64::from(v));
                }
            }
        }
        Ok(())
    }

    pub fn bytes(self) -> usize {
        match self {
            RawType::I16 => 2,
            RawType::F32 => 4,
        }
    }
}

/// Most bytes of a FIFO or a device read whole (`/dev/zero` is endless; read in passes, such an
/// input is spooled instead, [`crate::spool`]).
pub const MAX_WHOLE_STREAM_BYTES: u64 = 1 << 28;

/// The bytes of a FIFO or device `path`, at most `limit`: more, or more than the memory
/// there is, is an error, never an abort.
pub fn read_stream(path: &Path, limit: u64) -> Result<Vec<u8>, ReadError> {
    use std::io::Read;
    let err = |kind: ReadErrorKind| ReadError::new(path, kind);
    let mut input = std::fs::File::open(path).map_err(|e| err(e.into()))?;
    let mut bytes: Vec<u8> = Vec::new();
    let mut block = vec![0u8; crate::sources::CHUNK];
    loop {
        let n = match input.read(&mut block) {
            Ok(0) => return Ok(bytes),
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(err(e.into())),
        };
        if (bytes.len() + n) as u64 > limit {
            return Err(err(ReadErrorKind::StreamTooLong {
                limit,
                memory: false,
            }));
        }
        if bytes.try_reserve(n).is_err() {
            return Err(err(ReadErrorKind::StreamTooLong {
                limit,
                memory: true,
            }));
        }
        bytes.extend_from_slice(&block[..n]);
    }
}

/// Reads channel `opts.column` (0-based) of `channels` interleaved ones.
pub fn read_raw(
    path: &Path,
    kind: RawType,
    channels: usize,
    opts: &ReadOptions,
) -> Result<Channel, ReadError> {
    let err = |kind: ReadErrorKind| ReadError::new(path, kind);
    let Some(rate_hz) = opts.rate_hz else {
        return Err(err(ReadErrorKind::RawNoTime));
    };
    check_rate(rate_hz).map_err(err)?;
    if opts.time_column.is_some() || opts.resample || !opts.axes.is_empty() {
        return Err(err(ReadErrorKind::RawOptions));
    }
    if !(1..=64).contains(&channels) {
        return Err(err(ReadErrorKind::RawChannels { channels }));
    }
    let column =
        numbered_column(opts.column.as_ref(), channels, Numbered::FileChannels).map_err(err)?;
    let bytes = if crate::error::reads_once(path) {
        read_stream(path, MAX_WHOLE_STREAM_BYTES)?
    } else {
        std::fs::read(path).map_err(|e| err(e.into()))?
    };
    let frame = kind.bytes() * channels;
    if bytes.len() % frame != 0 {
        return Err(err(ReadErrorKind::RawPartialFrame {
            bytes: bytes.len() as u64,
            frame,
            channels,
            sample_bytes: kind.bytes(),
        }));
    }
    let mut values = Vec::new();
    if values.try_reserve_exact(bytes.len() / frame).is_err() {
        return Err(err(ReadErrorKind::StreamTooLong {
            limit: MAX_WHOLE_STREAM_BYTES,
            memory: true,
        }));
    }
    let at = column * kind.bytes();
    kind.decode(&bytes, frame, at, |v| values.push(v))
        .map_err(|(k, value)| {
            err(ReadErrorKind::RawNotFinite {
                frame: k as u64,
                byte: (k * frame + at) as u64,
                value,
            })
        })?;
    evenly_sampled(format!("channel {column}"), values, rate_hz)
        .map_err(|e| err(ReadErrorKind::TooFewSamples(e)))
}
