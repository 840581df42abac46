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
    let bytes = std::fs::read(path).map_err(|e| err(e.into()))?;
    let frame = kind.bytes() * channels;
    if bytes.len() % frame != 0 {
        return Err(err(ReadErrorKind::RawPartialFrame {
            bytes: bytes.len() as u64,
            frame,
            channels,
            sample_bytes: kind.bytes(),
        }));
    }
    let mut values = Vec::with_capacity(bytes.len() / frame);
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
