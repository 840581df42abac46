//! The required SRS of `impact report --srs-required FILE`: read from a CSV, each impact's
//! measured SRS judged against it within MIL-STD-810H's −1.5/+3 dB, and drawn over it.

use std::path::{Path, PathBuf};

use impact_core::consts::STANDARD_GRAVITY;
use plotters::prelude::*;

use crate::plot::{draw_panel, svg_html, Panel, PlotError};
use crate::report::fmt::human;
use crate::small_csv::{SmallCsv, SmallCsvError};
use crate::standards::SRS_TOLERANCE_DB;

/// Breakpoints a required SRS may have at most (a specification has a handful).
const MAX_POINTS: usize = 10_000;

/// A required SRS refused: the file as given and what is wrong with it
/// (`--srs-required FILE: what`).
#[derive(Debug, thiserror::Error)]
#[error("--srs-required {}: {fault}", .path.display())]
pub struct RequiredSrsError {
    pub path: PathBuf,
    #[source]
    pub fault: Box<RequiredSrsFault>,
}

/// What is wrong with a required SRS's file; lines numbered as an editor numbers them.
#[derive(Debug, thiserror::Error)]
pub enum RequiredSrsFault {
    #[error(transparent)]
    Csv(#[from] SmallCsvError),
    /// No `frequency_hz` column (the header's names as read).
    #[error(
        "needs the columns frequency_hz and acceleration_m_s2 (or acceleration_g); its header is {:?}",
        .header.join(",")
    )]
    Columns { header: Vec<String> },
    #[error("needs a column acceleration_m_s2 (or acceleration_g)")]
    NoAcceleration,
    /// A field (`text`, as read) of the column `column` (its header) that is no positive
    /// number.
    #[error("line {line}: {column} {text:?} is not a positive number")]
    NotPositive {
        line: usize,
        column: String,
        text: String,
    },
    /// A value in g too large for m/s² (it overflows a 64-bit float).
    #[error(
        "line {line}: {column} {text:?} is too large to be an acceleration (give it in range)"
    )]
    Overflows {
        line: usize,
        column: String,
        text: String,
    },
    /// A natural frequency, Hz, not above the previous row's.
    #[error("line {line}: frequency_hz {frequency_hz} does not increase (after {last_hz})")]
    NotIncreasing {
        line: usize,
        frequency_hz: f64,
        last_hz: f64,
    },
    #[error("more than {MAX_POINTS} breakpoints")]
    TooMany,
    #[error("needs at least two breakpoints")]
    TooFew,
}

/// A required SRS: its breakpoints (natural frequency, Hz; acceleration, m/s²), the
/// frequencies increasing, straight between them on log–log axes (a constant dB/octave slope).
pub struct RequiredSrs {
    /// The file, as given.
    pub file: String,
    points: Vec<(f64, f64)>,
}

impl RequiredSrs {
    /// Reads a small CSV ([`SmallCsv`]: `#` comments, LF or CRLF, at most 1 MiB) with a
    /// header naming `frequency_hz` and `acceleration_m_s2` or `acceleration_g` (in any case;
    /// other columns ignored): at least two rows, frequencies increasing, every value a
    /// positive number.
    pub fn read(path: &Path) -> Result<Self, RequiredSrsError> {
        let file = path.display().to_string();
        let err = |fault: RequiredSrsFault| RequiredSrsError {
            path: path.to_path_buf(),
            fault: Box::new(fault),
        };
        let csv = SmallCsv::read(path, "required SRS").map_err(|e| err(e.into()))?;
        let header = &csv.header;
        let column = |name: &str| csv.column(name);
        let (Some(f_col), acceleration) = (
            column("frequency_hz"),
            column("acceleration_m_s2")
                .map(|c| (c, 1.0))
                .or_else(|| column("acceleration_g").map(|c| (c, STANDARD_GRAVITY))),
        ) else {
            return Err(err(RequiredSrsFault::Columns {
                header: header.clone(),
            }));
        };
        let Some((a_col, scale)) = acceleration else {
            return Err(err(RequiredSrsFault::NoAcceleration));
        };
        let mut points: Vec<(f64, f64)> = Vec::new();
        for (line, row) in &csv.rows {
            let line = *line;
            let value = |col: usize, name: &str| -> Result<f64, RequiredSrsError> {
                let text = row.get(col).map_or("", String::as_str);
                match text.parse::<f64>() {
                    Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
                    _ => Err(err(RequiredSrsFault::NotPositive {
                        line,
                        column: name.to_string(),
                        text: text.to_string(),
                    })),
                }
            };
            let f = value(f_col, "frequency_hz")?;
            let a = value(a_col, &header[a_col])? * scale;
            // In g, a finite number can overflow in m/s² (1e308 g): refused as the number it
            // is, never a comparison in NaN dB.
            if !a.is_finite() {
                return Err(err(RequiredSrsFault::Overflows {
                    line,
                    column: header[a_col].clone(),
                    text: row.get(a_col).cloned().unwrap_or_default(),
                }));
            }
            if let Some(&(last, _)) = points.last() {
                if f <= last {
                    return Err(err(RequiredSrsFault::NotIncreasing {
                        line,
                        frequency_hz: f,
                        last_hz: last,
                    }));
                }
            }
            if points.len() == MAX_POINTS {
                return Err(err(RequiredSrsFault::TooMany));
            }
            points.push((f, a));
        }
        if points.len() < 2 {
            return Err(err(RequiredSrsFault::TooFew));
        }
        Ok(Self { file, points })
    }

    /// The breakpoints: (natural frequency, Hz; acceleration, m/s²).
    pub fn points(&self) -> &[(f64, f64)] {
        &self.points
    }

    /// The required acceleration at `f_hz`, m/s² (log–log between the breakpoints); `None`
    /// outside them.
    pub fn at(&self, f_hz: f64) -> Option<f64> {
        self.log10_at(f_hz).map(|l| 10f64.powf(l))
    }

    /// The common logarithm of [`Self::at`], interpolated in the log domain: finite for any
    /// positive finite breakpoints (`at` itself can underflow or overflow between 1e-306 and
    /// 1e300, where a ratio of the two in dB would be infinite).
    pub fn log10_at(&self, f_hz: f64) -> Option<f64> {
        let (first, last) = (self.points[0].0, self.points[self.points.len() - 1].0);
        // A hair of slack: band centres computed as 1000 × 2^(k/n) are not always the
        // literal a file gives.
        let f = if (f_hz - first).abs() <= first * 1e-9 {
            first
        } else if (f_hz - last).abs() <= last * 1e-9 {
            last
        } else {
            f_hz
        };
        if !(first..=last).contains(&f) {
            return None;
        }
        let k = self
            .points
            .windows(2)
            .position(|w| f <= w[1].0)
            .unwrap_or(self.points.len() - 2);
        let ((f0, a0), (f1, a1)) = (self.points[k], self.points[k + 1]);
        let u = (f.ln() - f0.ln()) / (f1.ln() - f0.ln());
        let (l0, l1) = (a0.log10(), a1.log10());
        Some(l0 + (l1 - l0) * u)
    }
}

/// A measured SRS against the required one over the natural frequencies both have.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Comparison {
    /// Within [`SRS_TOLERANCE_DB`] at every one of them.
    pub within: bool,
    /// Where the measured SRS is nearest to a limit, or furthest beyond one, Hz.
    pub worst_hz: f64,
    /// The measured SRS there over the required, dB.
    pub worst_db: f64,
    /// The natural frequencies compared.
    pub compared: usize,
    /// The required range the bands compared leave out, Hz: where the next band below the
    /// lowest compared, or above the highest, would still lie within the requirement's
    /// breakpoints (a lowest band above its first breakpoint, a highest band stopped by
    /// `--srs-high` or the rate / 8 below its last, bands without a value at either end);
    /// `None` if they span it. A "yes" there holds for the compared part only.
    pub uncovered: Option<Uncovered>,
}

/// The measured bands against the requirement's range, Hz (see [`Comparison::uncovered`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Uncovered {
    /// The lowest and highest natural frequencies compared.
    pub compared: (f64, f64),
    /// The requirement's first and last breakpoints.
    pub required: (f64, f64),
}

/// The part of `required`'s range the bands compared (from `compared.0` to `compared.1`, Hz)
/// leave out: `None` unless the band next to either end, one step of `frequency_hz`'s
/// (increasing) beyond it, would still lie within the breakpoints (with
/// [`RequiredSrs::log10_at`]'s slack).
fn uncovered(
    required: &RequiredSrs,
    frequency_hz: &[f64],
    compared: (f64, f64),
) -> Option<Uncovered> {
    let points = required.points();
    let (first, last) = (points[0].0, points[points.len() - 1].0);
    // The bands' ratio from one to the next (with a single band, an octave).
    let step = match frequency_hz {
        [a, b, ..] if *b > *a && *a > 0.0 => b / a,
        _ => 2.0,
    };
    let short_below = compared.0 / step >= first * (1.0 - 1e-9);
    let short_above = compared.1 * step <= last * (1.0 + 1e-9);
    (short_below || short_above).then_some(Uncovered {
        compared,
        required: (first, last),
    })
}

/// The measured SRS (`srs_m_s2` at `frequency_hz`) against `required` at every natural
/// frequency where both are defined (a measured value positive and finite, the frequency
/// within the required breakpoints); `None` where there is none.
pub fn compare(
    required: &RequiredSrs,
    frequency_hz: &[f64],
    srs_m_s2: &[f64],
) -> Option<Comparison> {
    let (low, high) = SRS_TOLERANCE_DB;
    // Beyond the nearer limit, dB (negative: inside by that much).
    let excess = |db: f64| (db - high).max(low - db);
    let mut worst: Option<Comparison> = None;
    let mut span = (f64::INFINITY, 0.0f64);
    for (&f, &a) in frequency_hz.iter().zip(srs_m_s2) {
        let Some(r) = required.log10_at(f) else {
            continue;
        };
        if !(a.is_finite() && a > 0.0) {
            continue;
        }
        // In the log domain: finite for any positive finite pair (a ratio overflowed to an
        // infinite dB, once skipped, which could turn a "no" into a "yes").
        let db = 20.0 * (a.log10() - r);
        span = (span.0.min(f), span.1.max(f));
        let compared = worst.map_or(0, |w| w.compared) + 1;
        let within = worst.is_none_or(|w| w.within) && excess(db) <= 0.0;
        worst = Some(match worst {
            Some(w) if excess(w.worst_db) >= excess(db) => Comparison {
                within,
                compared,
                ..w
            },
            _ => Comparison {
                within,
                worst_hz: f,
                worst_db: db,
                compared,
                uncovered: None,
            },
        });
    }
    worst.map(|w| Comparison {
        uncovered: uncovered(required, frequency_hz, span),
        ..w
    })
}

/// The report's cell: `yes, worst at 1250 Hz, +2.10 dB` (or `no, …`), or why not compared;
/// over part of the requirement's range, `…; compared from 11.05 Hz to 8980 Hz only, required
/// from 10.00 Hz to 50000 Hz`.
pub fn cell(c: Option<&Comparison>) -> String {
    let hz = |f: f64| human(f, "Hz").trim_end().to_string();
    match c {
        Some(c) => format!(
            "{}, worst at {}, {:+.2} dB{}",
            if c.within { "yes" } else { "no" },
            hz(c.worst_hz),
            c.worst_db,
            c.uncovered.map_or(String::new(), |u| format!(
                "; compared from {} to {} only, required from {} to {}",
                hz(u.compared.0),
                hz(u.compared.1),
                hz(u.required.0),
                hz(u.required.1)
            )),
        ),
        None => "not compared (no natural frequency in both)".into(),
    }
}

/// The cell's class: `pass` within the tolerance over the whole required range, `fail`
/// beyond it anywhere compared, neither for within over part of the range.
pub fn class(c: Option<&Comparison>) -> &'static str {
    match c {
        Some(c) if !c.within => " fail",
        Some(c) if c.uncovered.is_none() => " pass",
        _ => "",
    }
}

/// The measured SRS, and the required one (if given) with its tolerance's limits dashed,
/// log–log in m/s² (g on the right), titled `title`: an inline SVG for the report.
pub fn svg(
    title: &str,
    frequency_hz: &[f64],
    srs_m_s2: &[f64],
    required: Option<&RequiredSrs>,
) -> Result<crate::html::Html, PlotError> {
    let (low, high) = SRS_TOLERANCE_DB;
    let scaled = |r: &RequiredSrs, db: f64| -> Vec<(f64, f64)> {
        let k = 10f64.powf(db / 20.0);
        r.points.iter().map(|&(f, a)| (f, a * k)).collect()
    };
    const REQUIRED: RGBColor = RGBColor(30, 30, 30);
    const LIMIT: RGBColor = RGBColor(110, 110, 110);
    let panel = Panel {
        title: title.into(),
        x_label: "natural frequency, Hz",
        measured: frequency_hz
            .iter()
            .copied()
            .zip(srs_m_s2.iter().copied())
            .collect(),
        measured_label: "measured SRS",
        models: required
            .map(|r| vec![("required", REQUIRED, scaled(r, 0.0))])
            .unwrap_or_default(),
        dashed: required
            .map(|r| {
                vec![
                    ("+3 dB", LIMIT, scaled(r, high)),
                    ("−1.5 dB", LIMIT, scaled(r, low)),
                ]
            })
            .unwrap_or_default(),
        log: true,
        g_axis: true,
        legend: true,
        spec: None,
    };
    svg_html((530, 340), |root| {
        root.fill(&WHITE)?;
        draw_panel(root, None, &panel)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn required(points: &[(f64, f64)]) -> RequiredSrs {
        RequiredSrs {
            file: "test.csv".into(),
            points: points.to_vec(),
        }
    }

    #[test]
    fn the_required_srs_is_straight_on_log_log_axes_between_breakpoints() {
        // +6 dB/octave from 100 Hz to 1 kHz, flat to 10 kHz.
        let r = required(&[(100.0, 10.0), (1000.0, 100.0), (10_000.0, 100.0)]);
        assert_eq!(r.at(99.0), None);
        assert_eq!(r.at(10_001.0), None);
        assert!((r.at(316.227_766).unwrap() - 31.622_776_6).abs() < 1e-6);
        assert!((r.at(5000.0).unwrap() - 100.0).abs() < 1e-9);
        assert_eq!(r.at(100.000_000_01), Some(10.0));
    }

    /// A required SRS of 1e-306 m/s² at 100–200 Hz (its ratio to a measured 100 m/s²
    /// overflows: an infinite dB, once skipped) then 100 m/s² at 300–400 Hz, where the
    /// measurement meets it: "no", at 100 Hz (it said "yes").
    #[test]
    fn a_ratio_beyond_f64_is_still_judged() {
        let r = required(&[
            (100.0, 1e-306),
            (200.0, 1e-306),
            (300.0, 100.0),
            (400.0, 100.0),
        ]);
        let f = [100.0, 150.0, 300.0, 400.0];
        let c = compare(&r, &f, &[100.0, 100.0, 100.0, 100.0]).unwrap();
        assert!(!c.within && c.compared == 4, "{c:?}");
        assert_eq!(c.worst_hz, 100.0);
        assert!((c.worst_db - 20.0 * 308.0).abs() < 1e-6, "{c:?}");
    }

    #[test]
    fn a_measured_srs_is_within_the_tolerance_or_named_where_it_is_worst() {
        let r = required(&[(100.0, 100.0), (1000.0, 100.0)]);
        let db = |d: f64| 100.0 * 10f64.powf(d / 20.0);
        // Inside: the nearest a limit is +2.5 dB at 400 Hz; 50 Hz and 2 kHz not compared.
        let f = [50.0, 100.0, 200.0, 400.0, 800.0, 2000.0];
        let c = compare(&r, &f, &[1.0, db(0.0), db(-0.9), db(2.5), db(0.5), 1.0]).unwrap();
        assert!(c.within && c.worst_hz == 400.0 && c.compared == 4, "{c:?}");
        assert!((c.worst_db - 2.5).abs() < 1e-9);
        assert_eq!(cell(Some(&c)), "yes, worst at 400.0 Hz, +2.50 dB");
        // Outside: −2 dB at 200 Hz is beyond −1.5 dB by more than +3.4 dB is beyond +3.
        let c = compare(&r, &f, &[1.0, db(3.4), db(-2.0), db(0.0), db(0.0), 1.0]).unwrap();
        assert!(!c.within && c.worst_hz == 200.0, "{c:?}");
        assert_eq!(cell(Some(&c)), "no, worst at 200.0 Hz, -2.00 dB");
        // Nothing in common.
        assert_eq!(compare(&r, &[20.0, 5000.0], &[1.0, 1.0]), None);
        assert_eq!(class(None), "");
    }

    /// Bands that stop short of the requirement's range by more than their spacing (a
    /// highest band by `--srs-high` or the rate / 8, a lowest band by `--srs-low`) say which
    /// part was compared, and a "yes" there is no pass; within one step, or beyond the
    /// range, it is.
    #[test]
    fn bands_short_of_the_required_range_say_what_was_compared() {
        let r = required(&[(10.0, 100.0), (50_000.0, 100.0)]);
        let bands = |from: f64, to: f64| -> Vec<f64> {
            (0..200)
                .map(|k| 1000.0 * 2f64.powf(k as f64 / 6.0 - 10.0))
                .filter(|f| (from..=to).contains(f))
                .collect()
        };
        let judge = |f: &[f64]| compare(&r, f, &vec![100.0; f.len()]).unwrap();
        // The rate / 8 at 500 kS/s: 11.05 Hz to 57 kHz spans it.
        let c = judge(&bands(10.0, 62_500.0));
        assert!(c.within && c.uncovered.is_none(), "{c:?}");
        assert_eq!(class(Some(&c)), " pass");
        // Within one step short at either end (11.05 Hz, 45.3 kHz): spanned.
        let c = judge(&bands(11.0, 46_000.0));
        assert!(c.uncovered.is_none(), "{c:?}");
        // --srs-high 10000: 8980 Hz of 50 kHz.
        let c = judge(&bands(10.0, 10_000.0));
        let u = c.uncovered.expect("short of 50 kHz");
        assert!(
            u.compared.1 < 9000.0 && u.required == (10.0, 50_000.0),
            "{u:?}"
        );
        assert_eq!(class(Some(&c)), "");
        let text = cell(Some(&c));
        assert!(
            text.starts_with("yes, worst at ")
                && text.ends_with(
                    " dB; compared from 11.05 Hz to 8980 Hz only, required from 10.00 Hz to 50000 Hz"
                ),
            "{text}"
        );
        // --srs-low 100 against a requirement from 10 Hz; a failure stays one.
        let c = compare(&r, &bands(100.0, 62_500.0), &vec![1.0; 45]).unwrap();
        assert!(!c.within && c.uncovered.is_some(), "{c:?}");
        assert_eq!(class(Some(&c)), " fail");
        let text = cell(Some(&c));
        assert!(text.starts_with("no, worst at "), "{text}");
        assert!(text.contains("; compared from 111.4 Hz to "), "{text}");
        // The next band exactly on the last breakpoint, not computed: 2000 Hz of a
        // requirement to 2000 Hz (--srs-high 1900).
        let to_2k = required(&[(100.0, 100.0), (2000.0, 100.0)]);
        let f = bands(100.0, 1900.0);
        let c = compare(&to_2k, &f, &vec![100.0; f.len()]).unwrap();
        assert!(c.within && c.uncovered.is_some(), "{c:?}");
        // Bands without a value at the top are not compared: the range is the compared one.
        let f = bands(10.0, 62_500.0);
        let mut a = vec![100.0; f.len()];
        let cut = f.iter().position(|&x| x > 9000.0).unwrap();
        a[cut..].iter_mut().for_each(|v| *v = 0.0);
        let c = compare(&r, &f, &a).unwrap();
        let u = c.uncovered.expect("the top not compared");
        assert!(u.compared.1 < 9000.0, "{u:?}");
        // One band, inside a range an octave wide either side: short.
        let c = compare(&r, &[1000.0], &[100.0]).unwrap();
        assert!(c.uncovered.is_some(), "{c:?}");
        assert!(cell(None).starts_with("not compared"));
    }
}
