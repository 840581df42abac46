//! The board's captured windows put back together from its `wave` and `wave_frame` lines
//! (docs/board.md), and written out as recordings `impact analyze` reads again.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use impact_core::waveform::{self, FRAME_LEN};

use crate::firmware_link::line::WaveLine;
use crate::report::waveform::WaveformJson;

/// One impact's window as the board sent it.
#[derive(Clone, Debug)]
pub struct Waveform {
    /// The impact's index.
    pub index: u32,
    /// Stream index of the window's first sample.
    pub first_sample: u64,
    /// Samples in the window (on the board).
    pub samples: u32,
    /// One value per `every` samples (their mean when > 1).
    pub every: u16,
    /// The frozen baseline, `base_sum / base_n` counts.
    pub base_sum: i64,
    pub base_n: i64,
    /// Frames sent.
    pub frames: u32,
    /// Frames received, by number.
    received: BTreeMap<u32, Vec<i16>>,
}

/// A frame the window cannot take.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum WaveError {
    #[error("frame={frame}: impact {index} has {frames} frames")]
    NoSuchFrame { frame: u32, index: u32, frames: u32 },
    #[error("frame={frame} of impact {index} holds {got} values, not {want}")]
    Length {
        frame: u32,
        index: u32,
        got: usize,
        want: usize,
    },
    #[error("frame={frame} of impact {index} twice")]
    Twice { frame: u32, index: u32 },
}

impl Waveform {
    /// The window a `wave` line announces, no frame received yet.
    pub fn new(w: WaveLine) -> Self {
        Self {
            index: w.index,
            first_sample: w.first_sample,
            samples: w.samples,
            every: w.every,
            base_sum: w.base_sum,
            base_n: w.base_n,
            frames: w.frames,
            received: BTreeMap::new(),
        }
    }

    /// Values the window holds (one per `every` samples).
    pub fn values(&self) -> usize {
        waveform::values(self.samples as usize, self.every)
    }

    /// Takes frame `frame`'s values, checking its number and length.
    pub fn add_frame(&mut self, frame: u32, counts: Vec<i16>) -> Result<(), WaveError> {
        let index = self.index;
        if frame >= self.frames {
            return Err(WaveError::NoSuchFrame {
                frame,
                index,
                frames: self.frames,
            });
        }
        let want = (self.values() - frame as usize * FRAME_LEN).min(FRAME_LEN);
        if counts.len() != want {
            return Err(WaveError::Length {
                frame,
                index,
                got: counts.len(),
                want,
            });
        }
        if self.received.insert(frame, counts).is_some() {
            return Err(WaveError::Twice { frame, index });
        }
        Ok(())
    }

    /// Frames not received.
    pub fn missing_frames(&self) -> u32 {
        self.frames - self.received.len() as u32
    }

    /// Value `k` (0-based, one per `every` samples), if its frame came.
    pub fn value(&self, k: usize) -> Option<i16> {
        let frame = self.received.get(&((k / FRAME_LEN) as u32))?;
        frame.get(k % FRAME_LEN).copied()
    }

    /// The value that stands for stream sample `i`: its group's, if `i` is in the window
    /// and its frame came.
    pub fn at_sample(&self, i: u64) -> Option<i16> {
        let offset = i.checked_sub(self.first_sample)?;
        if offset >= u64::from(self.samples) {
            return None;
        }
        self.value((offset / u64::from(self.every)) as usize)
    }

    /// The values received, each with its number (0-based, one per `every` samples), in
    /// order: what arrived, whatever the `wave` line declared.
    pub fn received(&self) -> impl Iterator<Item = (usize, i16)> + '_ {
        self.received.iter().flat_map(|(&frame, counts)| {
            let first = frame as usize * FRAME_LEN;
            counts.iter().enumerate().map(move |(j, &c)| (first + j, c))
        })
    }

    /// Every value, if no frame is missing.
    pub fn complete(&self) -> Option<Vec<i16>> {
        (0..self.values()).map(|k| self.value(k)).collect()
    }

    pub fn json(&self) -> WaveformJson {
        WaveformJson {
            index: self.index,
            first_sample: self.first_sample,
            samples: self.samples,
            every: self.every,
            frames: self.frames,
            missing_frames: self.missing_frames(),
            run: None,
        }
    }
}

/// Where window `index` of an export to `path` goes: `<stem>-<index>.<ext>`.
fn numbered(path: &Path, index: u32) -> PathBuf {
    let stem = path.file_stem().map_or_else(
        || "impact".to_string(),
        |s| s.to_string_lossy().into_owned(),
    );
    let ext = path
        .extension()
        .map_or_else(String::new, |e| format!(".{}", e.to_string_lossy()));
    path.with_file_name(format!("{stem}-{index}{ext}"))
}

/// Why the board's windows could not be written as recordings (`impact log --export`).
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    #[error("--export {}: the name must end in .csv or .wav", .path.display())]
    Extension { path: PathBuf },
    #[error("--export: the log has no waveforms (the scene's wave=0)")]
    NoWaveforms,
    #[error(transparent)]
    Output(#[from] crate::output::OutputError),
    #[error("--export {}: a WAV file's rate is a whole number of Hz, not {rate}", .path.display())]
    WavRate { path: PathBuf, rate: f64 },
    #[error(
        "--export {}: impact {index} misses {missing} frames, and a WAV file has no gaps (export .csv)",
        .path.display()
    )]
    WavGaps {
        path: PathBuf,
        index: u32,
        missing: u32,
    },
    /// The WAV encoder's own error, for the file `out`.
    #[error("{}: {source}", .out.display())]
    Wav { out: PathBuf, source: hound::Error },
}

/// Writes each window as a recording: `.csv` (`time_s,accel_m_s2`, the stream's time and the
/// counts times the gain, baseline included; a missing frame leaves a gap in the time
/// column) or `.wav` (16-bit PCM of the counts at rate / every, the gain for `--gain`). One
/// file per impact, `<stem>-<index>.<ext>`; the paths written.
pub fn export(
    waves: &[Waveform],
    path: &Path,
    inputs: &crate::output::Inputs,
    rate_hz: f64,
    gain_m_s2_per_count: f64,
) -> Result<Vec<PathBuf>, ExportError> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    if ext != "csv" && ext != "wav" {
        return Err(ExportError::Extension {
            path: path.to_path_buf(),
        });
    }
    if waves.is_empty() {
        return Err(ExportError::NoWaveforms);
    }
    // Every numbered name checked before any is written: none may be an input (`x-0.csv`
    // read, `--export x.csv` asked).
    for w in waves {
        crate::output::check("--export", &numbered(path, w.index), inputs, None)?;
    }
    let mut written = Vec::new();
    for w in waves {
        let out = numbered(path, w.index);
        let every = u64::from(w.every);
        if ext == "csv" {
            let mut text = String::from("time_s,accel_m_s2\n");
            for (k, c) in w.received() {
                let sample = w.first_sample.saturating_add(k as u64 * every);
                text.push_str(&format!(
                    "{:.9},{:e}\n",
                    sample as f64 / rate_hz,
                    f64::from(c) * gain_m_s2_per_count
                ));
            }
            crate::output::write(&out, text.as_bytes())?;
        } else {
            let rate = rate_hz / every as f64;
            if !(rate.fract() == 0.0 && rate >= 1.0 && rate <= f64::from(u32::MAX)) {
                return Err(ExportError::WavRate {
                    path: path.to_path_buf(),
                    rate,
                });
            }
            let values = w.complete().ok_or_else(|| ExportError::WavGaps {
                path: path.to_path_buf(),
                index: w.index,
                missing: w.missing_frames(),
            })?;
            let spec = hound::WavSpec {
                channels: 1,
                sample_rate: rate as u32,
                bits_per_sample: 16,
                sample_format: hound::SampleFormat::Int,
            };
            // A window is at most a capture: made in memory, written whole.
            let mut bytes = std::io::Cursor::new(Vec::new());
            let wav = |source| ExportError::Wav {
                out: out.clone(),
                source,
            };
            let mut writer = hound::WavWriter::new(&mut bytes, spec).map_err(wav)?;
            for v in values {
                writer.write_sample(v).map_err(wav)?;
            }
            writer.finalize().map_err(wav)?;
            crate::output::write(&out, bytes.get_ref())?;
        }
        written.push(out);
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::firmware_link::line::{Fields, WaveFrameLine};

    /// A `wave` line's fields, `frames` as given or as the samples make.
    fn header(samples: u32, every: u16, frames: Option<usize>) -> Fields {
        let frames = frames.unwrap_or_else(|| waveform::frames(samples as usize, every));
        Fields::parse(&format!(
            "index=3 first_sample=1000 samples={samples} every={every} frames={frames} \
             base_sum=-12 base_n=4"
        ))
        .unwrap()
    }

    #[test]
    fn frames_rebuild_the_window_and_missing_ones_are_counted() {
        let mut w = Waveform::new(WaveLine::parse(&header(130, 1, None)).unwrap());
        assert_eq!(w.frames, 3);
        let line = "INFO wave_frame index=3 frame=2 counts=[-5, 7]";
        let f = WaveFrameLine::parse(line, &Fields::parse("index=3 frame=2").unwrap()).unwrap();
        assert_eq!((f.index, f.frame, f.counts.clone()), (3, 2, vec![-5, 7]));
        w.add_frame(2, f.counts).unwrap();
        w.add_frame(0, vec![1; 64]).unwrap();
        assert_eq!(w.missing_frames(), 1);
        assert_eq!(w.at_sample(1000), Some(1));
        assert_eq!(w.at_sample(1000 + 64), None);
        assert_eq!(w.at_sample(1000 + 129), Some(7));
        assert_eq!(w.at_sample(1000 + 130), None);
        assert!(w.complete().is_none());
        // Wrong lengths, numbers and repeats are errors.
        let e = |r: Result<(), WaveError>| r.unwrap_err().to_string();
        assert!(e(w.add_frame(1, vec![0; 63])).contains("63 values"));
        assert!(e(w.add_frame(3, vec![0; 2])).contains("has 3 frames"));
        assert!(e(w.add_frame(2, vec![0; 2])).contains("twice"));
    }

    #[test]
    fn a_header_whose_counts_disagree_is_refused() {
        let e = |f: Fields| WaveLine::parse(&f).unwrap_err().to_string();
        assert!(e(header(130, 2, Some(3))).contains("make 2 frames"));
        assert!(e(header(130, 0, Some(3))).contains("every=0"));
    }
}
