//! A user's tolerance band (`--spec …,band-file=FILE`): read from a CSV into the rows the
//! core's verdict interpolates ([`impact_core::spec::BandPoint`]), over the spec's duration
//! and peak.

use std::io::Read;
use std::path::Path;

use impact_core::consts::STANDARD_GRAVITY;
use impact_core::spec::{BandPoint, Spec, MAX_BAND_POINTS};

/// Largest band file read, bytes (64 rows take a few KiB; anything far beyond is not a band).
const MAX_FILE_BYTES: u64 = 1 << 20;

/// Reads a band: a CSV (`#` starts a comment line) whose header names a time column —
/// `time_s` (s from the nominal pulse's start) or `time_over_duration` — and a lower and an
/// upper limit in one unit: `lower_m_s2`/`upper_m_s2`, `lower_g`/`upper_g` or
/// `lower_over_peak`/`upper_over_peak`; other columns are ignored. At most
/// [`MAX_BAND_POINTS`] rows (the board holds them), times non-decreasing (two rows at one
/// time are a step); linear between rows; the nominal pulse inside at every row. The rows
/// come over `spec`'s duration and peak, kept for the run (the verdict reads a `'static`
/// table, as the board's is).
pub fn read(path: &Path, spec: &Spec) -> Result<&'static [BandPoint], String> {
    let err = |what: String| format!("band-file={}: {what}", path.display());
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .and_then(|f| f.take(MAX_FILE_BYTES + 1).read_to_end(&mut bytes))
        .map_err(|e| err(e.to_string()))?;
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(err(format!(
            "larger than {MAX_FILE_BYTES} bytes: not a band"
        )));
    }
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .comment(Some(b'#'))
        .from_reader(bytes.as_slice());
    let header = reader.headers().map_err(|e| err(e.to_string()))?.clone();
    let column = |name: &str| header.iter().position(|h| h.eq_ignore_ascii_case(name));
    let peak = f64::from(spec.peak_m_s2);
    let duration = f64::from(spec.duration_s);
    let time = column("time_s")
        .map(|c| (c, 1.0 / duration))
        .or_else(|| column("time_over_duration").map(|c| (c, 1.0)));
    let limits = [
        ("m_s2", 1.0 / peak),
        ("g", STANDARD_GRAVITY / peak),
        ("over_peak", 1.0),
    ]
    .into_iter()
    .find_map(|(unit, scale)| {
        Some((
            column(&format!("lower_{unit}"))?,
            column(&format!("upper_{unit}"))?,
            scale,
        ))
    });
    let (Some((t_col, t_scale)), Some((lo_col, hi_col, scale))) = (time, limits) else {
        return Err(err(format!(
            "needs a time column (time_s or time_over_duration) and the limits in one unit \
             (lower_m_s2 and upper_m_s2, lower_g and upper_g, or lower_over_peak and \
             upper_over_peak); its header is {:?}",
            header.iter().collect::<Vec<_>>().join(",")
        )));
    };
    let mut rows = Vec::new();
    let mut lines = Vec::new();
    for record in reader.records() {
        let record = record.map_err(|e| err(e.to_string()))?;
        let line = record.position().map_or(0, csv::Position::line);
        let value = |col: usize| -> Result<f64, String> {
            let text = record.get(col).unwrap_or("");
            text.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    err(format!(
                        "line {line}: {} {text:?} is not a number",
                        &header[col]
                    ))
                })
        };
        if rows.len() == MAX_BAND_POINTS {
            return Err(err(format!(
                "more than {MAX_BAND_POINTS} rows (the board holds {MAX_BAND_POINTS}): \
                 keep the band's corners"
            )));
        }
        let row = BandPoint {
            u: (value(t_col)? * t_scale) as f32,
            lower: (value(lo_col)? * scale) as f32,
            upper: (value(hi_col)? * scale) as f32,
        };
        if let Some(last) = rows.last().map(|r: &BandPoint| r.u) {
            if row.u < last {
                return Err(err(format!("line {line}: the time goes back")));
            }
        }
        if row.lower > row.upper {
            return Err(err(format!(
                "line {line}: the lower limit is above the upper"
            )));
        }
        rows.push(row);
        lines.push(line);
    }
    if rows.len() < 2 {
        return Err(err("needs at least two rows".into()));
    }
    // The nominal pulse inside the band at every row (the core refuses it otherwise; here
    // the row is named, in the file's units).
    let rows: &'static [BandPoint] = Box::leak(rows.into_boxed_slice());
    let with_band = Spec {
        band: Some(rows),
        ..*spec
    };
    for (row, line) in rows.iter().zip(&lines) {
        let (lo, hi) = with_band.band_at(row.u);
        let nominal = spec.shape.at(row.u);
        if !(lo <= nominal && nominal <= hi) {
            let unit = match header[lo_col].to_ascii_lowercase().as_str() {
                "lower_m_s2" => " m/s²",
                "lower_g" => " g",
                _ => " × the peak",
            };
            let v = |v: f32| crate::report::fmt::sig(f64::from(v) / scale, 6);
            return Err(err(format!(
                "line {line}: the nominal pulse ({}{unit}) lies outside the band ({}…{}{unit}) \
                 there: are the limits in the column's unit?",
                v(nominal),
                v(lo),
                v(hi),
            )));
        }
    }
    Ok(rows)
}
