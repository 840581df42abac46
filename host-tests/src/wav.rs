//! WAV recordings (`impact analyze FILE.wav`): one channel of integer or float PCM, at the
//! rate the header gives, in the file's own units (integer codes or floats; `--gain` and
//! `--units` turn them into an acceleration).

use std::path::Path;

use crate::recording::{evenly_sampled, numbered_column, Channel, ReadOptions};
use crate::table::{one_line, RecordingError};

/// True for a `.wav` file name (any case).
pub fn is_wav(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("wav"))
}

/// Reads the channel `opts.column` (a 0-based index, default 0).
pub fn read_wav(path: &Path, opts: &ReadOptions) -> Result<Channel, RecordingError> {
    let err = |message: String| RecordingError {
        file: path.to_path_buf(),
        line: None,
        message,
    };
    if opts.rate_hz.is_some() || opts.time_column.is_some() || opts.resample {
        return Err(err(
            "a WAV file gives its own rate: no --rate, --time-column or --resample".into(),
        ));
    }
    if !opts.axes.is_empty() {
        return Err(err("--axes: not for WAV files yet; give --column".into()));
    }
    let mut reader =
        hound::WavReader::open(path).map_err(|e| err(format!("WAV: {}", one_line(e))))?;
    let spec = reader.spec();
    let channels = usize::from(spec.channels);
    let column =
        numbered_column(opts.column.as_ref(), channels, "a WAV file's channels").map_err(err)?;
    let rate_hz = f64::from(spec.sample_rate);
    if spec.sample_rate == 0 {
        return Err(err("WAV: sample rate 0 in the header".into()));
    }
    let frames = reader.duration() as usize;
    // Room for what the file can hold, whatever its header announces.
    let file_bytes = std::fs::metadata(path).map_or(0, |m| m.len() as usize);
    let frame_bytes = channels.max(1) * usize::from(spec.bits_per_sample.div_ceil(8)).max(1);
    let mut values = Vec::with_capacity(frames.min(file_bytes / frame_bytes));
    // A sample that cannot be read (a file cut short) is an error naming its frame.
    let at = |k: usize, e: hound::Error| {
        err(format!(
            "WAV: frame {} (of {frames} the header announces): {}",
            k / channels.max(1),
            one_line(e)
        ))
    };
    match spec.sample_format {
        hound::SampleFormat::Int => {
            for (k, s) in reader.samples::<i32>().enumerate() {
                let s = s.map_err(|e| at(k, e))?;
                if k % channels == column {
                    values.push(f64::from(s));
                }
            }
        }
        hound::SampleFormat::Float => {
            for (k, s) in reader.samples::<f32>().enumerate() {
                let s = s.map_err(|e| at(k, e))?;
                if !s.is_finite() {
                    return Err(err(format!(
                        "WAV: frame {}: {s} is not finite",
                        k / channels
                    )));
                }
                if k % channels == column {
                    values.push(f64::from(s));
                }
            }
        }
    }
    evenly_sampled(format!("channel {column}"), values, rate_hz)
        .map_err(|e| err(format!("WAV: {e}")))
}
