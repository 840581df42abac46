//! The firmware's raw defmt stream (what QEMU's semihosting or an RTT reader saves) decoded
//! against its ELF with `defmt-decoder`, the decoder `defmt-print` and `probe-rs` use: one
//! text line per frame, as `defmt-print` prints it, for [`crate::firmware_link::log::LogReader`].

use std::io::Read;
use std::path::{Path, PathBuf};

use defmt_decoder::{DecodeError, Table};
use impact_io::ReadError;

/// The most bytes a stream may hold without a frame ending: the firmware's frames are a few
/// KiB at most (a `wave` line's chunk, the logger's staging); anything longer is no defmt
/// stream, and the decoder would hold it all.
const MAX_FRAME_BYTES: usize = 1 << 20;

/// Why a raw defmt stream could not be decoded: its ELF, or the stream (`name`: the input as
/// the tool names it, `stdin` or its path, or the emulator's stream).
#[derive(Debug, thiserror::Error)]
pub enum DefmtError {
    /// The ELF could not be read (a secondary input: `-` is a file there).
    #[error("{}", crate::read_errors::input_file_message(.0))]
    Elf(ReadError),
    /// `defmt-decoder` refused the ELF's defmt table.
    #[error("{}: not the firmware's ELF ({source})", .elf.display())]
    NotTheElf { elf: PathBuf, source: anyhow::Error },
    #[error("{}: no defmt data (not the firmware's ELF)", .elf.display())]
    NoDefmtData { elf: PathBuf },
    #[error("{name}: {source}")]
    Read {
        name: String,
        source: std::io::Error,
    },
    #[error(
        "{name}: no defmt frame ends in {mib} MiB: not this firmware's raw defmt stream \
         (text lines are read without --elf)"
    )]
    NoFrameEnds { name: String, mib: usize },
    #[error(
        "{name}: frame {frame}: malformed, and this encoding cannot recover: not this firmware's stream"
    )]
    Unrecoverable { name: String, frame: u64 },
}

/// Decodes `input` against the ELF at `elf`, handing each frame's text line to `on_line`
/// (numbered from 1); returns how many malformed frames were skipped (a stream cut by a
/// dropped link recovers at the next frame with the `rzcobs` encoding), or an error naming
/// the file ([`DefmtError`]) or `on_line`'s own.
pub fn decode<E: From<DefmtError>>(
    elf: &Path,
    mut input: impl Read,
    name: &str,
    mut on_line: impl FnMut(u64, &str) -> Result<(), E>,
) -> Result<u64, E> {
    let bytes = impact_io::read_limited(elf, 256 << 20, "firmware ELF").map_err(DefmtError::Elf)?;
    let table = Table::parse(&bytes)
        .map_err(|source| DefmtError::NotTheElf {
            elf: elf.to_path_buf(),
            source,
        })?
        .ok_or_else(|| DefmtError::NoDefmtData {
            elf: elf.to_path_buf(),
        })?;
    let mut decoder = table.new_stream_decoder();
    let mut buf = vec![0u8; 1 << 16];
    let (mut frames, mut skipped) = (0u64, 0u64);
    // Bytes received since a frame last ended (decoded or skipped): the decoder holds them.
    let mut pending = 0usize;
    loop {
        let n = input.read(&mut buf).map_err(|source| DefmtError::Read {
            name: name.to_string(),
            source,
        })?;
        if n == 0 {
            break;
        }
        pending += n;
        if pending > MAX_FRAME_BYTES {
            return Err(DefmtError::NoFrameEnds {
                name: name.to_string(),
                mib: MAX_FRAME_BYTES >> 20,
            }
            .into());
        }
        decoder.received(&buf[..n]);
        loop {
            match decoder.decode() {
                Ok(frame) => {
                    pending = 0;
                    frames += 1;
                    let line = match (frame.display_timestamp(), frame.level()) {
                        (Some(t), Some(l)) => {
                            format!(
                                "{t} {} {}",
                                l.as_str().to_uppercase(),
                                frame.display_message()
                            )
                        }
                        (Some(t), None) => format!("{t} {}", frame.display_message()),
                        (None, _) => frame.display_message().to_string(),
                    };
                    on_line(frames, &line)?;
                }
                Err(DecodeError::UnexpectedEof) => break,
                Err(DecodeError::Malformed) if table.encoding().can_recover() => {
                    pending = 0;
                    skipped += 1
                }
                Err(DecodeError::Malformed) => {
                    return Err(DefmtError::Unrecoverable {
                        name: name.to_string(),
                        frame: frames + 1,
                    }
                    .into())
                }
            }
        }
    }
    Ok(skipped)
}
