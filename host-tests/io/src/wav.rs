//! WAV recordings (`impact analyze FILE.wav`): one channel of integer or float PCM, at the
//! rate the header gives, in the file's own units (integer codes or floats; `--gain` and
//! `--units` turn them into an acceleration).

use std::path::{Path, PathBuf};

use crate::channel::{evenly_sampled, numbered_column, Channel, ReadOptions};
use crate::error::{Numbered, ReadError, ReadErrorKind, WavFault};

/// True for a `.wav` file name (any case).
pub fn is_wav(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("wav"))
}

/// One channel of a WAV file, read as it is asked for (hound's sample iterator): each value,
/// or an error naming the frame.
pub struct WavChannel {
    path: PathBuf,
    samples: Samples,
    /// Samples read (all channels), the channels, the one wanted, and the frames the header
    /// announces.
    k: usize,
    channels: usize,
    column: usize,
    frames: usize,
    /// Bytes a sample takes in the file.
    sample_bytes: usize,
    /// Sample rate, Hz (within [`crate::limits::RATE_HZ`]).
    pub rate_hz: f64,
}

enum Samples {
    Int(hound::WavIntoSamples<std::io::BufReader<std::fs::File>, i32>),
    Float(hound::WavIntoSamples<std::io::BufReader<std::fs::File>, f32>),
}

impl WavChannel {
    /// Opens `path` and chooses the channel `column` (0-based, default 0).
    pub fn open(
        path: &Path,
        column: Option<&crate::channel::ColumnRef>,
    ) -> Result<Self, ReadError> {
        let err = |kind: ReadErrorKind| ReadError::new(path, kind);
        let reader = hound::WavReader::open(path).map_err(|e| err(WavFault::Header(e).into()))?;
        let spec = reader.spec();
        let channels = usize::from(spec.channels);
        let column = numbered_column(column, channels, Numbered::WavChannels).map_err(err)?;
        let rate_hz = f64::from(spec.sample_rate);
        if !crate::limits::RATE_HZ.contains(rate_hz) {
            return Err(err(WavFault::RateOutOfRange { rate_hz }.into()));
        }
        let frames = reader.duration() as usize;
        let samples = match spec.sample_format {
            hound::SampleFormat::Int => Samples::Int(reader.into_samples()),
            hound::SampleFormat::Float => Samples::Float(reader.into_samples()),
        };
        Ok(Self {
            path: path.to_path_buf(),
            samples,
            k: 0,
            channels: channels.max(1),
            column,
            frames,
            sample_bytes: usize::from(spec.bits_per_sample.div_ceil(8)).max(1),
            rate_hz: f64::from(spec.sample_rate),
        })
    }

    /// Frames the header announces.
    pub fn frames(&self) -> usize {
        self.frames
    }
}

impl WavChannel {
    /// The channel read (0-based).
    pub fn column(&self) -> usize {
        self.column
    }
}

impl Iterator for WavChannel {
    type Item = Result<f64, ReadError>;

    fn next(&mut self) -> Option<Self::Item> {
        loop {
            let sample = match &mut self.samples {
                Samples::Int(s) => s.next()?.map(f64::from),
                Samples::Float(s) => s.next()?.map(f64::from),
            };
            let frame = self.k / self.channels;
            let mine = self.k % self.channels == self.column;
            self.k += 1;
            let fault = match sample {
                Ok(v) if v.is_finite() => {
                    if mine {
                        return Some(Ok(v));
                    }
                    continue;
                }
                Ok(value) => WavFault::NotFinite { frame, value },
                Err(error) => WavFault::Frame {
                    frame,
                    frames: self.frames,
                    error,
                },
            };
            return Some(Err(ReadError::new(&self.path, fault)));
        }
    }
}

/// Reads the channel `opts.column` (a 0-based index, default 0).
pub fn read_wav(path: &Path, opts: &ReadOptions) -> Result<Channel, ReadError> {
    let err = |kind: ReadErrorKind| ReadError::new(path, kind);
    if opts.rate_hz.is_some() || opts.time_column.is_some() || opts.resample {
        return Err(err(ReadErrorKind::WavGivesRate { resample: true }));
    }
    if !opts.axes.is_empty() {
        return Err(err(ReadErrorKind::WavAxes));
    }
    let channel = WavChannel::open(path, opts.column.as_ref())?;
    let rate_hz = channel.rate_hz;
    let column = channel.column;
    // The header's frame count, but never more than the file's bytes could hold.
    let file_bytes = std::fs::metadata(path).map_or(0, |m| m.len() as usize);
    let frame_bytes = channel.channels * channel.sample_bytes;
    let mut values = Vec::with_capacity(channel.frames().min(file_bytes / frame_bytes));
    for v in channel {
        values.push(v?);
    }
    evenly_sampled(format!("channel {column}"), values, rate_hz)
        .map_err(|e| err(WavFault::Samples(e).into()))
}
