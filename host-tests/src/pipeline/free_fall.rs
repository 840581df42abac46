//! The approach speed from a free fall measured on a DC channel before the impact
//! (`--free-fall`).

use impact_core::consts::STANDARD_GRAVITY;
use impact_io::channel::time_unit_s;
use impact_io::channel::ColumnRef;
use impact_io::channel::CsvFormat;
use impact_io::csv_read::read_table;
use impact_io::units::Units;
use impact_io::ReadErrorKind;

use crate::pipeline::Assumption;
use crate::read_errors::{kind_message, ReadFailure};
use std::path::{Path, PathBuf};

/// Why the free fall before an impact could not be measured (`--free-fall FILE[:COLUMN]`).
#[derive(Debug, thiserror::Error)]
pub enum FreeFallError {
    /// The file not read.
    #[error(transparent)]
    Read(#[from] ReadFailure),
    /// The file read, its columns not found (a column named that is not there).
    #[error("--free-fall {}: {}", .path.display(), kind_message(.kind))]
    Columns { path: PathBuf, kind: ReadErrorKind },
    #[error("--free-fall {}: needs a time column", .path.display())]
    NoTimeColumn { path: PathBuf },
    #[error("--free-fall: the DC channel starts after the impact")]
    StartsAfterImpact,
    /// The DC channel's last time, s, before the impact's, s.
    #[error(
        "--free-fall {}: the DC channel ends at {ends_s:.6} s, before the impact at {impact_s:.6} s",
        .path.display()
    )]
    EndsBeforeImpact {
        path: PathBuf,
        ends_s: f64,
        impact_s: f64,
    },
    #[error("--free-fall: no free fall (|a| < 0.5 g) within 50 ms before the impact")]
    NoFreeFall,
}

/// The file of a `--free-fall FILE[:COLUMN]` (an input: no output may write over it).
pub fn file(spec: &str) -> &Path {
    split(spec).0
}

/// `FILE[:COLUMN]` split: the whole of it if that is a file; else at the first colon whose
/// left part is a file (a column's name may hold colons and slashes: `Acceleration z
/// (m/s^2)`); else, where no such file exists, at the last colon not followed by a path
/// (the error then names that file).
fn split(spec: &str) -> (&Path, Option<&str>) {
    if Path::new(spec).is_file() {
        return (Path::new(spec), None);
    }
    let at_file = spec
        .match_indices(':')
        .map(|(i, _)| (&spec[..i], &spec[i + 1..]))
        .find(|(p, _)| !p.is_empty() && Path::new(p).is_file());
    if let Some((p, c)) = at_file {
        return (Path::new(p), Some(c));
    }
    match spec.rsplit_once(':') {
        Some((p, c)) if !p.is_empty() && !c.contains('/') => (Path::new(p), Some(c)),
        _ => (Path::new(spec), None),
    }
}

/// Free-fall time ending at or before `impact_s`, from a DC accelerometer file in g: the
/// stretch where |a| < 0.5 g (half way between rest and free fall) that ends within 50 ms
/// before the impact; and what was assumed of the file (units its headers do not name).
pub fn free_fall_before(
    spec: &str,
    impact_s: f64,
) -> Result<(f64, Vec<Assumption>), FreeFallError> {
    let mut assumed = Vec::new();
    let (path, column) = split(spec);
    let column = column.map(|c| c.parse::<ColumnRef>().unwrap_or(ColumnRef::Name(c.into())));
    let table = read_table(
        path,
        &CsvFormat::default(),
        impact_io::progress::Progress::none(),
    )
    .map_err(ReadFailure::from)?;
    let in_file = |kind: ReadErrorKind| FreeFallError::Columns {
        path: path.to_path_buf(),
        kind,
    };
    let tcol =
        table
            .time_column(None)
            .map_err(in_file)?
            .ok_or_else(|| FreeFallError::NoTimeColumn {
                path: path.to_path_buf(),
            })?;
    let time_header = table.headers.get(tcol).cloned().unwrap_or_default();
    if impact_io::channel::named_time_unit_s(&time_header).is_none() {
        assumed.push(
            Assumption::FreeFallTimeUnit {
                file: path.display().to_string(),
                column: time_header.clone(),
            }
            .noted(),
        );
    }
    let unit = time_unit_s(&time_header, None);
    let time: Vec<f64> = table.columns[tcol].iter().map(|t| t * unit).collect();
    let cols: Vec<usize> = match &column {
        Some(c) => vec![table.find(c, "column").map_err(in_file)?],
        None => (0..table.columns.len()).filter(|&c| c != tcol).collect(),
    };
    // Each column in g, by the unit its header names (as the main input's); a column that
    // names none is read as g, and a note says so.
    let header = |c: usize| table.headers.get(c).cloned().unwrap_or_default();
    let to_g: Vec<f64> = cols
        .iter()
        .map(|&c| match Units::of_header(&header(c)) {
            Some(u) => u.to_m_s2(None) / STANDARD_GRAVITY,
            None => {
                let name = if header(c).is_empty() {
                    format!("column {c}")
                } else {
                    header(c)
                };
                assumed.push(
                    Assumption::FreeFallUnits {
                        file: path.display().to_string(),
                        column: name,
                    }
                    .noted(),
                );
                1.0
            }
        })
        .collect();
    let mag = |i: usize| {
        cols.iter()
            .zip(&to_g)
            .map(|(&c, k)| (table.columns[c][i] * k).powi(2))
            .sum::<f64>()
            .sqrt()
    };
    let end = time
        .iter()
        .rposition(|&t| t <= impact_s)
        .ok_or(FreeFallError::StartsAfterImpact)?;
    // The DC channel must run up to the impact: a file that ends before it cannot tell when
    // the fall ended.
    let interval = (time[time.len() - 1] - time[0]) / (time.len().max(2) - 1) as f64;
    if end + 1 == time.len() && impact_s - time[end] > 2.0 * interval {
        return Err(FreeFallError::EndsBeforeImpact {
            path: path.to_path_buf(),
            ends_s: time[end],
            impact_s,
        });
    }
    // Walk back from the impact to the last free-falling sample, then to the release.
    let mut i = end;
    while i > 0 && mag(i) >= FREE_FALL_G && impact_s - time[i] < 0.05 {
        i -= 1;
    }
    if mag(i) >= FREE_FALL_G {
        return Err(FreeFallError::NoFreeFall);
    }
    let last = i;
    while i > 0 && mag(i - 1) < FREE_FALL_G {
        i -= 1;
    }
    let dt = if last > 0 {
        time[last] - time[last - 1]
    } else {
        0.0
    };
    // Free fall runs from half a sample before the first quiet sample to the impact.
    let release = time[i] - dt / 2.0;
    Ok((impact_s - release, assumed))
}

/// Below this magnitude (g) the DC channel is taken as free-falling.
const FREE_FALL_G: f64 = 0.5;
