//! A user's tolerance band (`--spec …,band-file=FILE`): read from a CSV into the rows the
//! core's verdict interpolates ([`impact_core::spec::BandPoint`]), over the spec's duration
//! and peak.

use std::path::{Path, PathBuf};

use impact_core::consts::STANDARD_GRAVITY;
use impact_core::spec::{BandPoint, Spec, MAX_BAND_POINTS};

use crate::small_csv::{SmallCsv, SmallCsvError};

/// A band file refused: the file as given and what is wrong with it (`band-file=FILE: what`).
#[derive(Debug, thiserror::Error)]
#[error("band-file={}: {fault}", .path.display())]
pub struct BandFileError {
    pub path: PathBuf,
    #[source]
    pub fault: Box<BandFault>,
}

/// What is wrong with a band file; lines numbered as an editor numbers them.
#[derive(Debug, thiserror::Error)]
pub enum BandFault {
    #[error(transparent)]
    Csv(#[from] SmallCsvError),
    /// The header (its names as read) names no time column or no pair of limits in one unit.
    #[error(
        "needs a time column (time_s or time_over_duration) and the limits in one unit \
         (lower_m_s2 and upper_m_s2, lower_g and upper_g, or lower_over_peak and \
         upper_over_peak); its header is {:?}",
        .header.join(",")
    )]
    Columns { header: Vec<String> },
    /// A field (`text`, as read) of the column `column` (its header) is no finite number.
    #[error("line {line}: {column} {text:?} is not a number")]
    NotANumber {
        line: usize,
        column: String,
        text: String,
    },
    #[error(
        "line {line}: more than {MAX_BAND_POINTS} rows (the board holds \
         {MAX_BAND_POINTS}): keep the band's corners"
    )]
    TooManyRows { line: usize },
    /// The core's check of a row ([`impact_core::spec::band_row_fault`]).
    #[error("line {line}: {fault}")]
    Row { line: usize, fault: &'static str },
    #[error("needs at least two rows")]
    TooFewRows,
    /// The nominal pulse outside the band: where, at the time `time` in the time column's
    /// unit (`time_column` its header), the nominal and the limits in the limits' `unit`.
    #[error(
        "{at}, at {time_column} = {}: the nominal pulse ({}{unit}) lies outside the band \
         ({}…{}{unit}): are the limits in the column's unit?",
        sig(*.time, 6),
        sig(*.nominal, 6),
        sig(*.lower, 6),
        sig(*.upper, 6)
    )]
    MissesNominal {
        at: Rows,
        time_column: String,
        time: f64,
        nominal: f64,
        lower: f64,
        upper: f64,
        unit: &'static str,
    },
}

/// Where in a band file: a line, or between two lines.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rows {
    Line(usize),
    Between(usize, usize),
}

impl std::fmt::Display for Rows {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Rows::Line(l) => write!(f, "line {l}"),
            Rows::Between(a, b) => write!(f, "between lines {a} and {b}"),
        }
    }
}

use crate::report::fmt::sig;

/// The limits' units a band file may use: the column suffix, the unit's name, and m/s² per unit
/// (`None`: over the peak).
const UNITS: [(&str, &str, Option<f64>); 3] = [
    ("m_s2", " m/s²", Some(1.0)),
    ("g", " g", Some(STANDARD_GRAVITY)),
    ("over_peak", " × the peak", None),
];

/// Reads a band: a small CSV ([`SmallCsv`]: `#` comments, LF or CRLF, at most 1 MiB) whose
/// header names a time column — `time_s` (s from the nominal pulse's start) or
/// `time_over_duration` — and a lower and an upper limit in one unit: `lower_m_s2`/`upper_m_s2`,
/// `lower_g`/`upper_g` or `lower_over_peak`/`upper_over_peak` (names in any case; other
/// columns ignored). At most [`MAX_BAND_POINTS`] rows (the board holds them), times
/// non-decreasing (two rows at one time are a step); linear between rows; the nominal pulse
/// inside. The rows come over `spec`'s duration and peak, kept for the run (the verdict reads
/// a `'static` table, as the board's is). Every refusal names the file and its line.
pub fn read(path: &Path, spec: &Spec) -> Result<&'static [BandPoint], BandFileError> {
    let err = |fault: BandFault| BandFileError {
        path: path.to_path_buf(),
        fault: Box::new(fault),
    };
    let csv = SmallCsv::read(path, "band file").map_err(|e| err(e.into()))?;
    let header = &csv.header;
    let column = |name: &str| csv.column(name);
    let peak = f64::from(spec.peak_m_s2);
    let duration = f64::from(spec.duration_s);
    let time = column("time_s")
        .map(|c| (c, 1.0 / duration))
        .or_else(|| column("time_over_duration").map(|c| (c, 1.0)));
    let limits = UNITS.iter().find_map(|&(suffix, unit, scale)| {
        Some((
            column(&format!("lower_{suffix}"))?,
            column(&format!("upper_{suffix}"))?,
            unit,
            scale.map_or(1.0, |s| s / peak),
        ))
    });
    let (Some((t_col, t_scale)), Some((lo_col, hi_col, unit, scale))) = (time, limits) else {
        return Err(err(BandFault::Columns {
            header: header.clone(),
        }));
    };
    let mut rows: Vec<BandPoint> = Vec::new();
    let mut numbers = Vec::new();
    for (line, fields) in &csv.rows {
        let line = *line;
        let value = |col: usize| -> Result<f64, BandFileError> {
            let text = fields.get(col).map_or("", String::as_str);
            text.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    err(BandFault::NotANumber {
                        line,
                        column: header[col].clone(),
                        text: text.to_string(),
                    })
                })
        };
        if rows.len() == MAX_BAND_POINTS {
            return Err(err(BandFault::TooManyRows { line }));
        }
        rows.push(BandPoint {
            u: (value(t_col)? * t_scale) as f32,
            lower: (value(lo_col)? * scale) as f32,
            upper: (value(hi_col)? * scale) as f32,
        });
        numbers.push(line);
    }
    // The core's own checks, each fault named at its line.
    if let Some((k, fault)) = impact_core::spec::band_row_fault(&rows) {
        return Err(err(BandFault::Row {
            line: numbers[k],
            fault,
        }));
    }
    if rows.len() < 2 {
        return Err(err(BandFault::TooFewRows));
    }
    let rows: &'static [BandPoint] = Box::leak(rows.into_boxed_slice());
    let with_band = Spec {
        band: Some(rows),
        ..*spec
    };
    if let Some(m) = with_band.band_misses_nominal() {
        // The row it misses (at a step, the side's own), or the rows around the miss.
        let at = match m.row {
            Some(k) => Rows::Line(numbers[k]),
            None => {
                let after = rows.partition_point(|r| r.u < m.u);
                Rows::Between(
                    numbers[after.saturating_sub(1)],
                    numbers[after.min(rows.len() - 1)],
                )
            }
        };
        let v = |v: f32| f64::from(v) / scale;
        return Err(err(BandFault::MissesNominal {
            at,
            time_column: header[t_col].clone(),
            time: f64::from(m.u) / t_scale,
            nominal: v(m.nominal),
            lower: v(m.lower),
            upper: v(m.upper),
            unit,
        }));
    }
    Ok(rows)
}
