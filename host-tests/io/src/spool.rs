//! A recording's values kept after its first pass, so the later passes read them back at
//! memory speed instead of parsing the file again (a CSV's parse is most of its cost), or
//! at all (standard input can be read only once).
//!
//! The values (× the units, as f64, so exactly those read) go to an unnamed temporary file
//! in the system's temporary directory (`TMPDIR`): 8 bytes a sample, about 40 % of a CSV's
//! size, on disk or in the page cache, not in the process's own memory (on a `tmpfs`, in
//! RAM or swap). The file is gone when the spool is dropped, or the process ends.

use std::fs::File;
use std::io::Write;
use std::os::unix::fs::FileExt;
use std::path::{Path, PathBuf};

use crate::error::{ReadError, SpoolError};
use crate::sources::{Source, CHUNK};

/// Values being written to the spool.
pub struct SpoolWriter {
    /// (Written a block at a time: no buffer of its own.)
    out: File,
    bytes: Vec<u8>,
    samples: u64,
    /// The most bytes it takes: half the space free where it is made (an input without end,
    /// `/dev/zero`, a logger's FIFO left open, fills no disk).
    limit: u64,
}

impl SpoolWriter {
    pub fn new() -> Result<Self, SpoolError> {
        let file = tempfile::tempfile().map_err(|error| SpoolError::Create {
            dir: std::env::temp_dir(),
            error,
        })?;
        // (`IMPACT_SPOOL_LIMIT_BYTES`: a lower bound, for the tests.)
        let test_limit = std::env::var("IMPACT_SPOOL_LIMIT_BYTES")
            .ok()
            .and_then(|v| v.parse::<u64>().ok());
        let limit = free_bytes(&file)
            .map_or(u64::MAX, |free| free / 2)
            .min(test_limit.unwrap_or(u64::MAX));
        Ok(Self {
            out: file,
            bytes: Vec::new(),
            samples: 0,
            limit,
        })
    }

    /// Appends the values. An error (a full disk) ends the spool: drop it, and its space is
    /// freed at once.
    pub fn write(&mut self, values: &[f64]) -> Result<(), SpoolError> {
        let after = (self.samples + values.len() as u64).saturating_mul(8);
        if after > self.limit {
            return Err(SpoolError::Full {
                dir: std::env::temp_dir(),
                limit: self.limit,
            });
        }
        self.bytes.clear();
        self.bytes
            .extend(values.iter().flat_map(|v| v.to_le_bytes()));
        self.out.write_all(&self.bytes).map_err(failed)?;
        self.samples += values.len() as u64;
        Ok(())
    }

    /// The spool of the recording `path`'s values, with what the first pass's source told
    /// of the time axis.
    pub fn finish(self, path: &Path, axis: Axis) -> Spool {
        Spool {
            path: path.to_path_buf(),
            file: self.out,
            samples: self.samples,
            axis,
        }
    }
}

/// What the first pass's source told of the time axis, which the spool's passes tell again.
#[derive(Clone, Copy, Debug)]
pub struct Axis {
    pub rate_hz: f64,
    pub final_rate_hz: f64,
    pub t0_s: f64,
}

/// The values of a pass, read back as often as needed.
pub struct Spool {
    /// The recording (its errors' file).
    path: PathBuf,
    file: File,
    samples: u64,
    axis: Axis,
}

impl Spool {
    /// A source of the values from the first, `progress` the fraction read.
    pub fn source(
        &self,
        progress: crate::progress::Progress,
    ) -> Result<Box<dyn Source>, ReadError> {
        let file = self
            .file
            .try_clone()
            .map_err(|e| ReadError::new(&self.path, failed(e)))?;
        Ok(Box::new(SpoolSource {
            path: self.path.clone(),
            file,
            at: 0,
            samples: self.samples,
            axis: self.axis,
            bytes: vec![0; CHUNK * 8],
            progress,
        }))
    }
}

/// A spool read from its start (at its own offset, so two never interfere).
struct SpoolSource {
    path: PathBuf,
    file: File,
    /// Samples read.
    at: u64,
    samples: u64,
    axis: Axis,
    bytes: Vec<u8>,
    progress: crate::progress::Progress,
}

impl SpoolSource {
    /// The next values' bytes (up to `want` values, none at the end).
    fn next_bytes(&mut self, want: usize) -> Result<&[u8], ReadError> {
        let n = (want.clamp(1, CHUNK) as u64).min(self.samples - self.at) as usize;
        let bytes = &mut self.bytes[..n * 8];
        self.file
            .read_exact_at(bytes, self.at * 8)
            .map_err(|e| ReadError::new(&self.path, failed(e)))?;
        self.at += n as u64;
        self.progress
            .report(self.at as f64 / self.samples.max(1) as f64);
        Ok(bytes)
    }
}

fn value(b: &[u8]) -> f64 {
    f64::from_le_bytes([b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]])
}

impl Source for SpoolSource {
    fn next_values(&mut self, want: usize, out: &mut Vec<f64>) -> Result<(), ReadError> {
        out.extend(self.next_bytes(want)?.chunks_exact(8).map(value));
        Ok(())
    }

    fn next_counts(
        &mut self,
        want: usize,
        q: crate::quantise::Quantiser,
        _scratch: &mut Vec<f64>,
        out: &mut Vec<i16>,
    ) -> Result<(), ReadError> {
        // (As `values_as_counts`, without the values' round trip through memory.)
        let bytes = self.next_bytes(want)?;
        out.extend(bytes.chunks_exact(8).map(|b| q.count(value(b))));
        Ok(())
    }

    fn rate_hz(&self) -> Result<f64, ReadError> {
        Ok(self.axis.rate_hz)
    }

    fn final_rate_hz(&self) -> f64 {
        self.axis.final_rate_hz
    }

    fn t0(&self) -> f64 {
        self.axis.t0_s
    }
}

/// The bytes free to this user on the file system holding `file` (`fstatvfs`), if known.
/// (`statvfs`'s field types differ between platforms: the conversions are not useless
/// everywhere.)
#[cfg(unix)]
#[allow(clippy::useless_conversion, clippy::unnecessary_cast)]
fn free_bytes(file: &File) -> Option<u64> {
    use std::os::unix::io::AsRawFd;
    let mut st = std::mem::MaybeUninit::<libc::statvfs>::uninit();
    // SAFETY: the descriptor is open for the call; `st` is written whole on success.
    let ok = unsafe { libc::fstatvfs(file.as_raw_fd(), st.as_mut_ptr()) } == 0;
    ok.then(|| {
        // SAFETY: fstatvfs returned 0, so it filled `st`.
        let st = unsafe { st.assume_init() };
        u64::from(st.f_bavail).saturating_mul(st.f_frsize as u64)
    })
}

#[cfg(not(unix))]
fn free_bytes(_: &File) -> Option<u64> {
    None
}

fn failed(error: std::io::Error) -> SpoolError {
    SpoolError::Use {
        dir: std::env::temp_dir(),
        error,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_and_counts_come_back_bit_for_bit_in_any_reads() {
        let values: Vec<f64> = (0..200_000)
            .map(|i| (i as f64 * 0.37).sin() * 1e3 + f64::from(i % 7) * 1e-300)
            .chain([0.0, -0.0, f64::MAX, f64::MIN_POSITIVE])
            .collect();
        let mut w = SpoolWriter::new().unwrap();
        for block in values.chunks(7777) {
            w.write(block).unwrap();
        }
        let axis = Axis {
            rate_hz: 5e5,
            final_rate_hz: 4.9e5,
            t0_s: 1.5,
        };
        let spool = w.finish(Path::new("-"), axis);
        for want in [1, 1000, CHUNK, 10 * CHUNK] {
            let mut s = spool.source(crate::progress::Progress::none()).unwrap();
            let mut back = Vec::new();
            loop {
                let before = back.len();
                s.next_values(want, &mut back).unwrap();
                if back.len() == before {
                    break;
                }
            }
            assert_eq!(back.len(), values.len());
            let mut s = spool.source(crate::progress::Progress::none()).unwrap();
            let (mut counts, mut scratch) = (Vec::new(), Vec::new());
            loop {
                let before = counts.len();
                s.next_counts(
                    want,
                    crate::quantise::Quantiser {
                        scale: 2.5,
                        gain: 0.01,
                    },
                    &mut scratch,
                    &mut counts,
                )
                .unwrap();
                if counts.len() == before {
                    break;
                }
            }
            let want_counts: Vec<i16> = values
                .iter()
                .map(|v| crate::quantise::to_count(v * 2.5, 0.01))
                .collect();
            assert_eq!(counts, want_counts);
            assert!(back
                .iter()
                .zip(&values)
                .all(|(a, b)| a.to_bits() == b.to_bits()));
            assert_eq!(
                (s.rate_hz().unwrap(), s.final_rate_hz(), s.t0()),
                (5e5, 4.9e5, 1.5)
            );
        }
    }
}
