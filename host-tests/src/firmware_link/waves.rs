//! The board's captured windows put back together from its `wave` and `wave_frame` lines
//! (docs/board.md), and written out as recordings `impact analyze` reads again.

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

use impact_core::waveform::{self, FRAME_LEN};

use crate::firmware_link::fields::num;
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

impl Waveform {
    /// A `wave` line's fields.
    pub fn from_header(m: &HashMap<String, String>) -> Result<Self, String> {
        let every: u16 = num(m, "every")?;
        if every == 0 {
            return Err("every=0: a window is sent with every >= 1".into());
        }
        let samples: u32 = num(m, "samples")?;
        let frames: u32 = num(m, "frames")?;
        let expected = waveform::frames(samples as usize, every);
        if frames as usize != expected {
            return Err(format!(
                "frames={frames}: {samples} samples at every={every} make {expected} frames"
            ));
        }
        let base_n: i64 = num(m, "base_n")?;
        let base_sum: i64 = num(m, "base_sum")?;
        Ok(Self {
            index: num(m, "index")?,
            first_sample: num(m, "first_sample")?,
            samples,
            every,
            base_sum,
            base_n,
            frames,
            received: BTreeMap::new(),
        })
    }

    /// Values the window holds (one per `every` samples).
    pub fn values(&self) -> usize {
        waveform::values(self.samples as usize, self.every)
    }

    /// Takes frame `frame`'s values, checking its number and length.
    pub fn add_frame(&mut self, frame: u32, counts: Vec<i16>) -> Result<(), String> {
        if frame >= self.frames {
            return Err(format!(
                "frame={frame}: impact {} has {} frames",
                self.index, self.frames
            ));
        }
        let want = (self.values() - frame as usize * FRAME_LEN).min(FRAME_LEN);
        if counts.len() != want {
            return Err(format!(
                "frame={frame} of impact {} holds {} values, not {want}",
                self.index,
                counts.len()
            ));
        }
        if self.received.insert(frame, counts).is_some() {
            return Err(format!("frame={frame} of impact {} twice", self.index));
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

/// A `wave_frame` line: its impact, frame number and values. The values are the last field,
/// `counts=[v, v, ...]` as defmt prints a slice.
pub fn parse_frame(
    line: &str,
    m: &HashMap<String, String>,
) -> Result<(u32, u32, Vec<i16>), String> {
    let index: u32 = num(m, "index")?;
    let frame: u32 = num(m, "frame")?;
    let list = line
        .split_once("counts=[")
        .and_then(|(_, rest)| rest.split_once(']'))
        .map(|(list, _)| list)
        .ok_or("missing field counts=[...]")?;
    let counts = if list.trim().is_empty() {
        Vec::new()
    } else {
        list.split(',')
            .map(|v| {
                v.trim()
                    .parse::<i16>()
                    .map_err(|_| format!("counts: {} is not an i16", v.trim()))
            })
            .collect::<Result<Vec<_>, _>>()?
    };
    Ok((index, frame, counts))
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
) -> Result<Vec<PathBuf>, String> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    if ext != "csv" && ext != "wav" {
        return Err(format!(
            "--export {}: the name must end in .csv or .wav",
            path.display()
        ));
    }
    if waves.is_empty() {
        return Err("--export: the log has no waveforms (the scene's wave=0)".into());
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
            for k in 0..w.values() {
                if let Some(c) = w.value(k) {
                    let sample = w.first_sample + k as u64 * every;
                    text.push_str(&format!(
                        "{:.9},{:e}\n",
                        sample as f64 / rate_hz,
                        f64::from(c) * gain_m_s2_per_count
                    ));
                }
            }
            crate::output::write(&out, text.as_bytes())?;
        } else {
            let rate = rate_hz / every as f64;
            if !(rate.fract() == 0.0 && rate >= 1.0 && rate <= f64::from(u32::MAX)) {
                return Err(format!(
                    "--export {}: a WAV file's rate is a whole number of Hz, not {rate}",
                    path.display()
                ));
            }
            let values = w.complete().ok_or_else(|| {
                format!(
                    "--export {}: impact {} misses {} frames, and a WAV file has no gaps (export .csv)",
                    path.display(),
                    w.index,
                    w.missing_frames()
                )
            })?;
            let spec = hound::WavSpec {
                channels: 1,
                sample_rate: rate as u32,
                bits_per_sample: 16,
                sample_format: hound::SampleFormat::Int,
            };
            // A window is at most a capture: made in memory, written whole.
            let mut bytes = std::io::Cursor::new(Vec::new());
            let mut writer = hound::WavWriter::new(&mut bytes, spec)
                .map_err(|e| format!("{}: {e}", out.display()))?;
            for v in values {
                writer
                    .write_sample(v)
                    .map_err(|e| format!("{}: {e}", out.display()))?;
            }
            writer
                .finalize()
                .map_err(|e| format!("{}: {e}", out.display()))?;
            crate::output::write(&out, bytes.get_ref())?;
        }
        written.push(out);
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn header(samples: u32, every: u16) -> HashMap<String, String> {
        let frames = waveform::frames(samples as usize, every);
        [
            ("index", "3".to_string()),
            ("first_sample", "1000".into()),
            ("samples", samples.to_string()),
            ("every", every.to_string()),
            ("frames", frames.to_string()),
            ("base_sum", "-12".into()),
            ("base_n", "4".into()),
        ]
        .into_iter()
        .map(|(k, v)| (k.to_string(), v))
        .collect()
    }

    #[test]
    fn frames_rebuild_the_window_and_missing_ones_are_counted() {
        let mut w = Waveform::from_header(&header(130, 1)).unwrap();
        assert_eq!(w.frames, 3);
        let line = "INFO wave_frame index=3 frame=2 counts=[-5, 7]";
        let (i, f, c) = parse_frame(
            line,
            &HashMap::from([("index".into(), "3".into()), ("frame".into(), "2".into())]),
        )
        .unwrap();
        assert_eq!((i, f, c.clone()), (3, 2, vec![-5, 7]));
        w.add_frame(2, c).unwrap();
        w.add_frame(0, vec![1; 64]).unwrap();
        assert_eq!(w.missing_frames(), 1);
        assert_eq!(w.at_sample(1000), Some(1));
        assert_eq!(w.at_sample(1000 + 64), None);
        assert_eq!(w.at_sample(1000 + 129), Some(7));
        assert_eq!(w.at_sample(1000 + 130), None);
        assert!(w.complete().is_none());
        // Wrong lengths, numbers and repeats are errors.
        assert!(w
            .add_frame(1, vec![0; 63])
            .unwrap_err()
            .contains("63 values"));
        assert!(w
            .add_frame(3, vec![0; 2])
            .unwrap_err()
            .contains("has 3 frames"));
        assert!(w.add_frame(2, vec![0; 2]).unwrap_err().contains("twice"));
    }

    #[test]
    fn a_header_whose_counts_disagree_is_refused() {
        let mut m = header(130, 2);
        m.insert("frames".into(), "3".into());
        assert!(Waveform::from_header(&m)
            .unwrap_err()
            .contains("make 2 frames"));
        m.insert("every".into(), "0".into());
        assert!(Waveform::from_header(&m).unwrap_err().contains("every=0"));
    }
}
