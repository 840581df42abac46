//! Reading recorded signals from CSV: one channel and its time base, with errors that name
//! the file and line.

use std::path::Path;

use crate::channel::{check_rate, check_time, check_time_unit, time_unit_s};
use crate::channel::{Channel, ReadOptions};
use crate::csv_read::read_table;
use crate::error::{At, ReadError, ReadErrorKind};

/// A resampled recording may hold at most this many times the file's samples (a long gap in
/// a fast recording would otherwise fill the memory with interpolated nothing).
const MAX_RESAMPLE_GROWTH: usize = 4;

/// Linear interpolation of `(t, v)` onto `t0 + k / rate`.
pub fn resample(
    path: &Path,
    t: &[f64],
    v: &[f64],
    rate: f64,
) -> Result<(Vec<f64>, Vec<f64>), ReadError> {
    let span = t[t.len() - 1] - t[0];
    let n = (span * rate).floor() as usize + 1;
    if n > MAX_RESAMPLE_GROWTH * t.len() + 1024 {
        return Err(ReadError::new(
            path,
            ReadErrorKind::ResampleTooLong {
                span_s: span,
                rate_hz: rate,
                samples: n,
                file_samples: t.len(),
            },
        ));
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

/// Reads one channel and its time base (see [`read_table`] for the format).
pub fn read_csv(path: &Path, opts: &ReadOptions) -> Result<Channel, ReadError> {
    let err = |kind: ReadErrorKind| ReadError::new(path, kind);
    let table = read_table(path, &opts.format, opts.progress.clone())?;
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
            return Err(err(ReadErrorKind::AxesCount {
                given: opts.axes.len(),
                what: "columns",
            }));
        }
        opts.axes
            .iter()
            .map(|c| table.find(c, "axis").map_err(err))
            .collect::<Result<_, _>>()?
    };
    for (i, &col) in cols.iter().enumerate() {
        if Some(col) == tcol {
            return Err(err(ReadErrorKind::ChannelIsTimeColumn {
                column: col,
                axes: true,
            }));
        }
        if cols[..i].contains(&col) {
            return Err(err(ReadErrorKind::AxisTwice {
                what: "column",
                name: name_of(col),
            }));
        }
    }
    let mut channels: Vec<Vec<f64>> = cols.iter().map(|&c| table.columns[c].clone()).collect();
    let len = channels[0].len();
    let header = |t: usize| table.headers.get(t).cloned().unwrap_or_default();
    let unit = |t: usize| time_unit_s(&header(t), opts.time_unit);
    let (rate_hz, time_s, jitter, resampled) = match (opts.rate_hz, tcol) {
        (Some(r), _) => {
            check_rate(r).map_err(err)?;
            let t0 = tcol.map_or(0.0, |t| table.columns[t][0] * unit(t));
            let times = (0..len).map(|i| t0 + i as f64 / r).collect();
            (r, times, 0.0, false)
        }
        (None, Some(t)) => {
            let scale = unit(t);
            let times: Vec<f64> = table.columns[t].iter().map(|v| v * scale).collect();
            let at = |i: usize| At::Line(table.line_of(i));
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
        (None, None) => return Err(err(ReadErrorKind::NoTimeColumn)),
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
    // Read in seconds where the column names no unit and none was given (with a rate given,
    // the time column sets only the start).
    let time_unit_assumed = tcol
        .filter(|_| opts.rate_hz.is_none())
        .and_then(|t| crate::channel::time_unit_assumed(&header(t), opts.time_unit));
    Ok(Channel {
        name,
        values,
        time_s,
        rate_hz,
        jitter,
        resampled,
        axes,
        time_unit_assumed,
    })
}
