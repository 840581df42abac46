//! Reading recorded signals from CSV: one channel and its time base, with errors that name
//! the file and line.

use std::path::Path;

use crate::table::{read_table, words, CsvFormat};
pub use crate::table::{ColumnRef, RecordingError};

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
    /// Called with the fraction of the file read, for progress display.
    pub progress: Option<fn(f64)>,
}

/// The 0-based channel `column` asks for among `count` numbered ones (default 0), or the
/// message naming what the file has (`what`, e.g. "a WAV file's channels").
pub(crate) fn numbered_column(
    column: Option<&ColumnRef>,
    count: usize,
    what: &str,
) -> Result<usize, String> {
    match column {
        None => Ok(0),
        Some(ColumnRef::Index(i)) if *i < count => Ok(*i),
        Some(c) => {
            let c = match c {
                ColumnRef::Index(i) => i.to_string(),
                ColumnRef::Name(n) => n.clone(),
            };
            Err(format!(
                "--column {c}: {what} are numbered 0..{}",
                count.saturating_sub(1)
            ))
        }
    }
}

/// A channel of `values` sampled evenly at `rate_hz` from t = 0 (binary formats), or the
/// message if it has fewer than two samples.
pub(crate) fn evenly_sampled(
    name: String,
    values: Vec<f64>,
    rate_hz: f64,
) -> Result<Channel, String> {
    if values.len() < 2 {
        return Err(format!("{} samples; at least 2", values.len()));
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
    })
}

/// The unit of a time column (`--time-unit`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
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

/// Seconds per unit of a time column: `given` (`--time-unit`), else the one its header names,
/// else seconds.
pub fn time_unit_s(header: &str, given: Option<TimeUnit>) -> f64 {
    given
        .map(TimeUnit::seconds)
        .or_else(|| named_time_unit_s(header))
        .unwrap_or(1.0)
}

/// The slowest rate an impact recording can have, S/s: a pulse of milliseconds needs many
/// samples. A time column that names no unit and, read in seconds, gives less was written in
/// another unit.
pub const SLOWEST_RATE_HZ: f64 = 100.0;

/// An error with the fix if a time column whose unit is neither named nor given gives a rate
/// below [`SLOWEST_RATE_HZ`] read in seconds.
pub fn check_time_unit(header: &str, given: Option<TimeUnit>, rate_hz: f64) -> Result<(), String> {
    if given.is_some() || named_time_unit_s(header).is_some() || rate_hz >= SLOWEST_RATE_HZ {
        return Ok(());
    }
    Err(format!(
        "the time column {header:?} names no unit: read in seconds it gives {} S/s, too slow for an impact recording; if it is in ms or µs, give --time-unit ms (or us), or name the column time_ms (time_us)",
        crate::report::fmt::sig(rate_hz, 4)
    ))
}

/// Every sample interval must lie within this range of the median interval, or the time axis
/// counts as uneven (a gap or a rate change). Jittered time stamps, as enDAQ's, stay within
/// 0.6..1.25.
pub(crate) const INTERVAL_RANGE: std::ops::RangeInclusive<f64> = 0.5..=1.5;

/// The intervals whose median every interval is checked against: the first 65 535 (those
/// among the first 65 536 rows, as a file read in passes or a stream has them at hand).
pub(crate) const HEAD_INTERVALS: usize = (1 << 16) - 1;

/// Checks a time column: finite, strictly increasing and evenly sampled (every interval within
/// [`INTERVAL_RANGE`] times the median of the first [`HEAD_INTERVALS`]). Returns `(rate,
/// jitter)`; with `resample`, uneven intervals are allowed and the rate is the median
/// interval's (of all of them).
pub(crate) fn check_time(
    path: &Path,
    t: &[f64],
    resample: bool,
    at: impl Fn(usize, String) -> RecordingError,
) -> Result<(f64, f64), RecordingError> {
    for (i, w) in t.windows(2).enumerate() {
        if w[1] <= w[0] {
            return Err(at(
                i + 1,
                format!("time {} s does not increase (previous {} s)", w[1], w[0]),
            ));
        }
    }
    if t.len() < 2 {
        return Err(RecordingError {
            file: path.to_path_buf(),
            line: None,
            message: "one sample: the rate cannot be told; give --rate".into(),
        });
    }
    let dts: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    let median_of = |d: &[f64]| {
        let mut d = d.to_vec();
        let mid = d.len() / 2;
        *d.select_nth_unstable_by(mid, f64::total_cmp).1
    };
    if !resample {
        let median = median_of(&dts[..dts.len().min(HEAD_INTERVALS)]);
        for (i, &dt) in dts.iter().enumerate() {
            crate::sources::check_interval(dt, median).map_err(|m| at(i + 1, m))?;
        }
        let dt = (t[t.len() - 1] - t[0]) / (t.len() - 1) as f64;
        let jitter = t
            .windows(2)
            .map(|w| ((w[1] - w[0]) / dt - 1.0).abs())
            .fold(0.0, f64::max);
        Ok((1.0 / dt, jitter))
    } else {
        Ok((1.0 / median_of(&dts), 0.0))
    }
}

/// A resampled recording may hold at most this many times the file's samples (a long gap in
/// a fast recording would otherwise fill the memory with interpolated nothing).
const MAX_RESAMPLE_GROWTH: usize = 4;

/// Linear interpolation of `(t, v)` onto `t0 + k / rate`.
pub(crate) fn resample(
    path: &Path,
    t: &[f64],
    v: &[f64],
    rate: f64,
) -> Result<(Vec<f64>, Vec<f64>), RecordingError> {
    let span = t[t.len() - 1] - t[0];
    let n = (span * rate).floor() as usize + 1;
    if n > MAX_RESAMPLE_GROWTH * t.len() + 1024 {
        return Err(RecordingError {
            file: path.to_path_buf(),
            line: None,
            message: format!(
                "--resample: {span:.6e} s at {rate:.6e} Hz would be {n} samples from {} in the \
                 file (a long gap?): cut the file",
                t.len()
            ),
        });
    }
    let mut times = Vec::with_capacity(n);
    let mut values = Vec::with_capacity(n);
    let mut j = 0;
    for k in 0..n {
        let tk = t[0] + k as f64 / rate;
        while j + 2 < t.len() && t[j + 1] < tk {
            j += 1;
        }
        let f = ((tk - t[j]) / (t[j + 1] - t[j])).clamp(0.0, 1.0);
        times.push(tk);
        values.push(v[j] + f * (v[j + 1] - v[j]));
    }
    Ok((times, values))
}

/// A recording's format: by the file's extension ([`crate::wav`], [`crate::npy`],
/// [`crate::tdms`], [`crate::raw`]), or raw if its sample type is given; CSV otherwise.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Format {
    Raw(crate::raw::RawType),
    Wav,
    Npy,
    Tdms,
    Ide,
    Csv,
    /// A file no reader takes: what it is and what to do instead.
    Unsupported(&'static str),
}

impl Format {
    pub fn of(path: &Path, raw_type: Option<crate::raw::RawType>) -> Self {
        match raw_type.or_else(|| crate::raw::RawType::of(path)) {
            Some(kind) => Format::Raw(kind),
            None if crate::wav::is_wav(path) => Format::Wav,
            None if crate::npy::is_npy(path) => Format::Npy,
            None if crate::tdms::is_tdms(path) => Format::Tdms,
            None if crate::ide::is_ide(path) => Format::Ide,
            None => match unsupported(path) {
                Some(what) => Format::Unsupported(what),
                None => Format::Csv,
            },
        }
    }

    /// The error for a file no reader takes.
    pub fn refuse(what: &str, name: &str) -> String {
        format!("{name}: unsupported format: {what}")
    }
}

/// What a file that is no CSV is, from its first bytes or its extension (a spreadsheet, a
/// MATLAB or HDF5 file, an archive, other binary data); `None` for text.
fn unsupported(path: &Path) -> Option<&'static str> {
    let mut head = [0u8; 1024];
    // Only a regular file is sniffed (a pipe's bytes would be gone).
    let n = match std::fs::metadata(path) {
        Ok(m) if m.is_file() => std::fs::File::open(path)
            .and_then(|mut f| std::io::Read::read(&mut f, &mut head))
            .unwrap_or(0),
        _ => 0,
    };
    let head = &head[..n];
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    if head.starts_with(b"PK\x03\x04") || matches!(ext.as_str(), "xlsx" | "ods") {
        Some("a spreadsheet or zip archive (.xlsx, .ods, .zip): save the sheet as CSV")
    } else if head.starts_with(&[0xD0, 0xCF, 0x11, 0xE0]) || ext == "xls" {
        Some("an Excel 97 workbook (.xls): save the sheet as CSV")
    } else if head.starts_with(b"MATLAB") {
        Some("a MATLAB .mat file: save the channel as CSV or .npy (scipy.io.loadmat, numpy.save)")
    } else if head.starts_with(b"\x89HDF") || matches!(ext.as_str(), "h5" | "hdf5" | "mat") {
        Some("an HDF5 file (.h5, MATLAB 7.3 .mat): save the channel as CSV or .npy (h5py, numpy.save)")
    } else if head.starts_with(&[0x1F, 0x8B]) {
        Some("a gzip archive: unpack it first")
    } else if head.starts_with(b"MDF ") || ext == "mf4" {
        Some("an ASAM MDF file: export the channel as CSV")
    } else if head.contains(&0) {
        Some("binary data: for raw samples name the file .i16 or .f32, or give --raw-type")
    } else {
        None
    }
}

/// Reads one channel and its time base from a CSV file (see [`read_table`]), a WAV file, an
/// `.npy` array, a TDMS file or a raw `.i16`/`.f32` file ([`Format`]).
pub fn read_recording(path: &Path, opts: &ReadOptions) -> Result<Channel, RecordingError> {
    match Format::of(path, None) {
        Format::Wav => crate::wav::read_wav(path, opts),
        Format::Npy => crate::npy::read_npy(path, opts),
        Format::Tdms => crate::tdms::read_tdms(path, opts),
        Format::Ide => crate::ide::read_ide(path, opts),
        Format::Unsupported(what) => Err(RecordingError {
            file: path.to_path_buf(),
            line: None,
            message: format!("unsupported format: {what}"),
        }),
        Format::Raw(kind) => crate::raw::read_raw(path, kind, opts.raw_channels.unwrap_or(1), opts),
        Format::Csv => read_csv(path, opts),
    }
}

/// Reads one channel and its time base (see [`read_table`] for the format).
pub fn read_csv(path: &Path, opts: &ReadOptions) -> Result<Channel, RecordingError> {
    let err = |message: String| RecordingError {
        file: path.to_path_buf(),
        line: None,
        message,
    };
    let table = read_table(path, &opts.format, opts.progress)?;
    let tcol = table
        .time_column_unless_rate(opts.rate_hz.is_some(), opts.time_column.as_ref())
        .map_err(err)?;
    let name_of = |c: usize| {
        table
            .headers
            .get(c)
            .cloned()
            .unwrap_or_else(|| format!("column {c}"))
    };
    let cols: Vec<usize> = if opts.axes.is_empty() {
        // (With --rate a time column is not read, but it is no channel either.)
        let time_like = tcol.or_else(|| table.time_column(None).ok().flatten());
        vec![table
            .channel(opts.column.as_ref(), time_like)
            .map_err(err)?]
    } else {
        if !(2..=3).contains(&opts.axes.len()) {
            return Err(err(format!(
                "--axes: {} columns given; two or three (x,y or x,y,z)",
                opts.axes.len()
            )));
        }
        opts.axes
            .iter()
            .map(|c| table.find(c, "axis").map_err(err))
            .collect::<Result<_, _>>()?
    };
    for (i, &col) in cols.iter().enumerate() {
        if Some(col) == tcol {
            return Err(err(format!(
                "column {col} is the time column: choose another with --column or --axes"
            )));
        }
        if cols[..i].contains(&col) {
            return Err(err(format!("--axes: column {} given twice", name_of(col))));
        }
    }
    let mut channels: Vec<Vec<f64>> = cols.iter().map(|&c| table.columns[c].clone()).collect();
    let len = channels[0].len();
    let header = |t: usize| table.headers.get(t).cloned().unwrap_or_default();
    let unit = |t: usize| time_unit_s(&header(t), opts.time_unit);
    let (rate_hz, time_s, jitter, resampled) = match (opts.rate_hz, tcol) {
        (Some(r), _) => {
            if !(r.is_finite() && r > 0.0 && r <= 1e9) {
                return Err(err(format!("rate {r} Hz is not in (0, 1e9]")));
            }
            let t0 = tcol.map_or(0.0, |t| table.columns[t][0] * unit(t));
            let times = (0..len).map(|i| t0 + i as f64 / r).collect();
            (r, times, 0.0, false)
        }
        (None, Some(t)) => {
            let scale = unit(t);
            let times: Vec<f64> = table.columns[t].iter().map(|v| v * scale).collect();
            let at = |i: usize, message: String| RecordingError {
                file: path.to_path_buf(),
                line: Some(table.line_of(i)),
                message,
            };
            let (rate, jitter) = check_time(path, &times, opts.resample, at)?;
            check_time_unit(&header(t), opts.time_unit, rate).map_err(err)?;
            if opts.resample {
                let mut grid = Vec::new();
                for values in &mut channels {
                    let (t, v) = resample(path, &times, values, rate)?;
                    *values = v;
                    grid = t;
                }
                (rate, grid, 0.0, true)
            } else {
                (rate, times, jitter, false)
            }
        }
        (None, None) => {
            return Err(err(
                "no time column found: give --time-column or --rate".into()
            ))
        }
    };
    let (name, values, axes) = if opts.axes.is_empty() {
        (name_of(cols[0]), channels.remove(0), Vec::new())
    } else {
        let resultant = (0..time_s.len())
            .map(|k| {
                channels
                    .iter()
                    .map(|c| c.get(k).map_or(0.0, |v| v * v))
                    .sum::<f64>()
                    .sqrt()
            })
            .collect();
        let names: Vec<String> = cols.iter().map(|&c| name_of(c)).collect();
        (
            format!("|{}|", names.join(",")),
            resultant,
            names.into_iter().zip(channels).collect(),
        )
    };
    Ok(Channel {
        name,
        values,
        time_s,
        rate_hz,
        jitter,
        resampled,
        axes,
    })
}
