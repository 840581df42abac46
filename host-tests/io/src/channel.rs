//! What every reader shares: the channel a recording gives (values, rate, first time), the
//! options a reader takes, which column is meant, the time axis's units and checks. The leaf
//! of `io`: the formats depend on it.

use std::path::Path;

pub use crate::error::{input_name, is_stdin, one_line, reads_once, ColumnRef, DriftFault};
use crate::error::{At, Numbered, ReadError, ReadErrorKind, TooFewSamples};
pub use crate::limits::{sig, DRIFT_BLOCK, DRIFT_LIMIT};
pub use crate::time_axis::{Drift, INTERVAL_RANGE};

/// How the text is laid out.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CsvFormat {
    /// Field separator [default: tab if the first lines hold one, else `;` if they hold one,
    /// else `,`].
    pub delimiter: Option<u8>,
    /// Numbers are written with a decimal comma (`6,77e-1`); the delimiter must then be
    /// another character.
    pub decimal_comma: bool,
}

/// A delimiter that is not one ASCII character (other than a quote or line break) or `tab`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("must be one ASCII character other than a quote or line break, or `tab`")]
pub struct BadDelimiter;

/// Parses a delimiter's name: one ASCII character, or `tab`.
pub fn parse_delimiter(s: &str) -> Result<u8, BadDelimiter> {
    match s {
        "tab" | "\\t" | "\t" => Ok(b'\t'),
        _ if s.len() == 1 && s.is_ascii() && s != "\"" && s != "\n" && s != "\r" => {
            Ok(s.as_bytes()[0])
        }
        _ => Err(BadDelimiter),
    }
}

/// The words of a header (letters, digits, `µ`).
pub fn words(h: &str) -> impl Iterator<Item = &str> {
    h.split(|c: char| !(c.is_alphanumeric() || c == 'µ'))
        .filter(|w| !w.is_empty())
}

/// One channel of a recording.
#[derive(Clone, Debug)]
pub struct Channel {
    /// The column's header name (or `column N`).
    pub name: String,
    pub values: Vec<f64>,
    /// Time of each sample, s (from the time column, or `index / rate`).
    pub time_s: Vec<f64>,
    /// Mean sample rate, Hz.
    pub rate_hz: f64,
    /// Largest deviation of a sample interval from the mean interval, relative.
    pub jitter: f64,
    /// Whether the samples were interpolated onto an even grid (`resample`).
    pub resampled: bool,
    /// With [`ReadOptions::axes`]: each axis (header name, values on the same time base);
    /// `values` is then their resultant `sqrt(x² + y² + z²)`.
    pub axes: Vec<(String, Vec<f64>)>,
    /// The time column's header when its unit was neither named there nor given (read in
    /// seconds: an assumption the report states).
    pub time_unit_assumed: Option<String>,
}

/// How to read the file.
#[derive(Clone, Debug, Default)]
pub struct ReadOptions {
    /// The channel [default: the first column that is not the time column].
    pub column: Option<ColumnRef>,
    /// Two or three axes read together instead of `column`: the channel is their resultant.
    pub axes: Vec<ColumnRef>,
    /// The time column [default: the one column whose header looks like a time, if any].
    pub time_column: Option<ColumnRef>,
    /// Sample rate, Hz, when there is no time column (overrides it if both are given).
    pub rate_hz: Option<f64>,
    /// Interpolate an uneven time axis onto an even grid at the median interval (instead of
    /// refusing it).
    pub resample: bool,
    /// Delimiter and decimal mark.
    pub format: CsvFormat,
    /// Interleaved channels of a raw `.i16`/`.f32` file [default: 1].
    pub raw_channels: Option<usize>,
    /// The time column's unit [default: the one its header names, else s].
    pub time_unit: Option<TimeUnit>,
    /// The sample type of a raw file without the `.i16`/`.f32` extension.
    pub raw_type: Option<RawType>,
    /// Called with the fraction of the file read, for progress display.
    pub progress: crate::progress::Progress,
}

/// The 0-based channel `column` asks for among `count` numbered ones (default 0), or the
/// error naming what the file has (`of`).
pub fn numbered_column(
    column: Option<&ColumnRef>,
    count: usize,
    of: Numbered,
) -> Result<usize, ReadErrorKind> {
    match column {
        None => Ok(0),
        Some(ColumnRef::Index(i)) if *i < count => Ok(*i),
        Some(c) => Err(ReadErrorKind::ColumnNumbered {
            column: c.clone(),
            count,
            of,
        }),
    }
}

/// A channel of `values` sampled evenly at `rate_hz` from t = 0 (binary formats), or the
/// error if it has fewer than two samples.
pub fn evenly_sampled(
    name: String,
    values: Vec<f64>,
    rate_hz: f64,
) -> Result<Channel, TooFewSamples> {
    if values.len() < 2 {
        return Err(TooFewSamples {
            samples: values.len(),
        });
    }
    let time_s = (0..values.len()).map(|k| k as f64 / rate_hz).collect();
    Ok(Channel {
        name,
        values,
        time_s,
        rate_hz,
        jitter: 0.0,
        resampled: false,
        axes: Vec::new(),
        time_unit_assumed: None,
    })
}

/// The unit of a time column (`--time-unit`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum TimeUnit {
    S,
    Ms,
    Us,
    Ns,
}

impl TimeUnit {
    /// Seconds per unit.
    pub fn seconds(self) -> f64 {
        match self {
            TimeUnit::S => 1.0,
            TimeUnit::Ms => 1e-3,
            TimeUnit::Us => 1e-6,
            TimeUnit::Ns => 1e-9,
        }
    }
}

/// Seconds per unit of a time column, from a unit word in its header (`timestamp_us`,
/// `time [ms]`, `time - seconds`); `None` when the header names none.
pub fn named_time_unit_s(header: &str) -> Option<f64> {
    let h = header.to_ascii_lowercase();
    let unit = words(&h).skip(1).find_map(|w| match w {
        "s" | "sec" | "secs" | "second" | "seconds" => Some(1.0),
        "ms" | "msec" | "millisecond" | "milliseconds" => Some(1e-3),
        "us" | "µs" | "usec" | "microsecond" | "microseconds" => Some(1e-6),
        "ns" | "nsec" | "nanosecond" | "nanoseconds" => Some(1e-9),
        _ => None,
    });
    unit
}

/// The time column's header if its unit is neither `given` nor named there (then seconds
/// are assumed).
pub fn time_unit_assumed(header: &str, given: Option<TimeUnit>) -> Option<String> {
    (given.is_none() && named_time_unit_s(header).is_none()).then(|| header.to_string())
}

/// Seconds per unit of a time column: `given` (`--time-unit`), else the one its header names,
/// else seconds.
pub fn time_unit_s(header: &str, given: Option<TimeUnit>) -> f64 {
    given
        .map(TimeUnit::seconds)
        .or_else(|| named_time_unit_s(header))
        .unwrap_or(1.0)
}

/// A rate given (not read from the file) if it lies within [`crate::limits::RATE_HZ`].
pub fn check_rate(rate_hz: f64) -> Result<f64, ReadErrorKind> {
    if crate::limits::RATE_HZ.contains(rate_hz) {
        Ok(rate_hz)
    } else {
        Err(ReadErrorKind::RateOutOfRange { rate_hz })
    }
}

/// The slowest rate an impact recording can have, S/s: a pulse of milliseconds needs many
/// samples. A time column that names no unit and, read in seconds, gives less was written in
/// another unit.
pub const SLOWEST_RATE_HZ: f64 = 100.0;

/// An error with the fix if a time column whose unit is neither named nor given gives a rate
/// below [`SLOWEST_RATE_HZ`] read in seconds, or if any gives a rate beyond
/// [`crate::limits::RATE_HZ`].
pub fn check_time_unit(
    header: &str,
    given: Option<TimeUnit>,
    rate_hz: f64,
) -> Result<(), ReadErrorKind> {
    if !crate::limits::RATE_HZ.contains(rate_hz) {
        return Err(ReadErrorKind::TimeUnitOutOfRange {
            header: header.to_string(),
            rate_hz,
        });
    }
    if given.is_some() || named_time_unit_s(header).is_some() || rate_hz >= SLOWEST_RATE_HZ {
        return Ok(());
    }
    Err(ReadErrorKind::TimeUnitTooSlow {
        header: header.to_string(),
        rate_hz,
    })
}

/// The intervals whose median every interval is checked against: the first 65 535 (those
/// among the first 65 536 rows, as a file read in passes or a stream has them at hand).
pub const HEAD_INTERVALS: usize = (1 << 16) - 1;

/// Checks a time column: finite, strictly increasing and evenly sampled (every interval within
/// [`INTERVAL_RANGE`] times the median of the first [`HEAD_INTERVALS`]). Returns `(rate,
/// jitter)`; with `resample`, uneven intervals are allowed and the rate is the median
/// interval's (of all of them). `at` says where sample `k` is (a line, the sample).
pub fn check_time(
    path: &Path,
    t: &[f64],
    resample: bool,
    at: impl Fn(usize) -> At,
) -> Result<(f64, f64), ReadError> {
    let err = |k: usize, kind: ReadErrorKind| ReadError::at(path, at(k), kind);
    // One pass: time going back is the first error, then one sample, then the first uneven
    // interval (against the head's median), then drift.
    let mut axis = crate::time_axis::TimeAxis::new(true);
    let (mut uneven, mut drift) = (None, None);
    for (k, &tk) in t.iter().enumerate() {
        let f = axis.push(tk, k as u64);
        if let Some(e) = f.not_increasing {
            return Err(err(k, ReadErrorKind::NotIncreasing(e)));
        }
        uneven = uneven.or(f.uneven.map(|e| (k as u64, e)));
        drift = drift.or(f.drift.map(|e| (k, e)));
        if k == HEAD_INTERVALS {
            uneven = uneven.or(axis.close_head());
        }
    }
    if t.len() < 2 {
        return Err(ReadError::new(path, ReadErrorKind::OneSample));
    }
    if resample {
        let mut dts: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
        let median = crate::time_axis::median(&mut dts).unwrap_or(f64::NAN);
        return Ok((1.0 / median, 0.0));
    }
    if let Some((k, e)) = uneven.or_else(|| axis.close_head()) {
        return Err(err(k as usize, ReadErrorKind::Uneven(e)));
    }
    if let Some((k, e)) = drift {
        return Err(err(k, ReadErrorKind::Drift(e)));
    }
    // (Two samples at least, checked above.)
    let dt = axis.mean_interval_s().unwrap_or(f64::NAN);
    let jitter = t
        .windows(2)
        .map(|w| ((w[1] - w[0]) / dt - 1.0).abs())
        .fold(0.0, f64::max);
    Ok((1.0 / dt, jitter))
}

/// The sample type a raw file's extension names.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum RawType {
    I16,
    F32,
}

impl RawType {
    /// From the extension: `.i16` or `.f32` (any case).
    pub fn of(path: &Path) -> Option<Self> {
        let e = path.extension()?.to_str()?.to_ascii_lowercase();
        match e.as_str() {
            "i16" => Some(RawType::I16),
            "f32" => Some(RawType::F32),
            _ => None,
        }
    }
}
