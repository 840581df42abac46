//! Three axes (`--axes`) in the report: the resultant's peak and each axis's peak and Δv.

use serde::Serialize;

/// One axis over one impact. SI.
#[derive(Clone, Debug, Serialize, serde::Deserialize, PartialEq)]
pub struct AxisJson {
    /// The column's header name.
    pub column: String,
    /// The axis's level before the impact (mean over the pre-trigger stretch), m/s².
    pub baseline_m_s2: f64,
    /// Largest deviation from that level inside the impact (signed), m/s².
    pub peak_acceleration_m_s2: f64,
    /// Time of that peak, s.
    pub peak_time_s: f64,
    /// `Σ (a - baseline) dt` over the contact (first touch to separation), m/s; null for an
    /// axis that does not hold DC (`ac_coupled`).
    pub delta_v_m_s: Option<f64>,
    /// The axis's whole window (contact and hold) undid more than half its contact's Δv: it
    /// does not hold DC (judged per axis, as the single channel's `ac-coupled`).
    pub ac_coupled: bool,
    /// The axis reached its rail inside the impact: its peak and Δv are lower bounds (and
    /// the impact is marked clipped).
    pub clipped: bool,
}

/// The per-axis part of an impact: the resultant's own peak (gravity included) and each axis.
#[derive(Clone, Debug, Serialize, serde::Deserialize, PartialEq)]
pub struct AxesJson {
    /// Largest resultant inside the impact, m/s² (the report's peak is above its baseline).
    pub resultant_peak_m_s2: f64,
    /// `sqrt(Σ Δv_axis²)`, m/s: the size of the velocity change (the report's own Δv is
    /// null, reason `resultant`: `∫|a| dt` is not one); null if an axis's Δv is.
    pub delta_v_magnitude_m_s: Option<f64>,
    pub axes: Vec<AxisJson>,
}

/// The table's line for an impact's axes.
pub fn table_line(a: &AxesJson) -> String {
    let h = crate::report::fmt::human;
    let axes: Vec<String> = a
        .axes
        .iter()
        .map(|x| {
            format!(
                "{} {}{} (Δv {})",
                x.column,
                if x.clipped { "≥" } else { "" },
                h(x.peak_acceleration_m_s2, "m/s²"),
                x.delta_v_m_s
                    .map_or_else(|| "unknown (ac-coupled)".to_string(), |v| h(v, "m/s"))
            )
        })
        .collect();
    format!(
        "    resultant peak {}{}, |Δv| {}; {}\n",
        if a.axes.iter().any(|x| x.clipped) {
            "≥"
        } else {
            ""
        },
        h(a.resultant_peak_m_s2, "m/s²"),
        a.delta_v_magnitude_m_s
            .map_or_else(|| "unknown".to_string(), |v| h(v, "m/s")),
        axes.join(", ")
    )
}

/// The transverse-motion check (IEC 60068-2-27:2008, 4.1.3, recalled: the peak acceleration
/// in any direction perpendicular to the intended one within 30 % of the nominal pulse's
/// peak): each cross axis's largest deviation from its baseline inside the impact, over the
/// nominal peak, against `limit_fraction`. Part of the verdict: a cross axis beyond it fails
/// the pulse.
#[derive(Clone, Debug, Serialize, serde::Deserialize, PartialEq)]
pub struct TransverseJson {
    /// The intended direction's axis (its column).
    pub main_axis: String,
    /// How it was chosen: `main-axis` (given), or `largest-peak` (the axis with the largest
    /// peak deviation in this impact: say `--main-axis` where the test names it).
    pub main_axis_from: String,
    /// The limit over the nominal peak (`--transverse-limit`, 0.3 unless given).
    pub limit_fraction: f64,
    /// That limit, m/s².
    pub limit_m_s2: f64,
    /// Every other axis.
    pub cross_axes: Vec<CrossAxisJson>,
    pub pass: bool,
}

/// One cross axis of the transverse check.
#[derive(Clone, Debug, Serialize, serde::Deserialize, PartialEq)]
pub struct CrossAxisJson {
    pub column: String,
    /// Its peak deviation from its baseline inside the impact (signed), m/s².
    pub peak_acceleration_m_s2: f64,
    pub peak_time_s: f64,
    /// `|peak|` over the nominal pulse's peak.
    pub fraction_of_nominal_peak: f64,
    pub pass: bool,
}

impl TransverseJson {
    /// The cross axis with the largest share of the nominal peak.
    pub fn worst(&self) -> Option<&CrossAxisJson> {
        self.cross_axes
            .iter()
            .fold(None, |w: Option<&CrossAxisJson>, c| match w {
                Some(w) if w.fraction_of_nominal_peak >= c.fraction_of_nominal_peak => Some(w),
                _ => Some(c),
            })
    }

    /// The worst cross axis in words: its name, share and the limit (the main axis named).
    pub fn worst_words(&self) -> String {
        match self.worst() {
            Some(c) => format!(
                "{} {:.1} % of the nominal peak (limit {:.0} %, main axis {})",
                c.column,
                100.0 * c.fraction_of_nominal_peak,
                100.0 * self.limit_fraction,
                self.main_axis
            ),
            None => String::new(),
        }
    }
}

/// Why an impact's transverse motion cannot be judged.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TransverseUnknown {
    /// A cross axis reached its rail within the limit: its true peak may lie beyond it.
    CrossAxisClipped,
}

impl TransverseUnknown {
    /// The verdict's null reason.
    pub fn reason(self) -> &'static str {
        match self {
            TransverseUnknown::CrossAxisClipped => "transverse-clipped",
        }
    }
}

/// The transverse check of an impact's axes against a nominal peak `nominal_m_s2`: the main
/// axis `main` (an index into `a.axes`) or else the one with the largest peak.
pub fn transverse(
    a: &AxesJson,
    nominal_m_s2: f64,
    limit_fraction: f64,
    main: Option<usize>,
) -> Result<TransverseJson, TransverseUnknown> {
    let largest = a
        .axes
        .iter()
        .enumerate()
        .fold(None::<(usize, f64)>, |best, (k, x)| {
            let p = x.peak_acceleration_m_s2.abs();
            match best {
                Some((_, b)) if b >= p => best,
                _ => Some((k, p)),
            }
        })
        .map_or(0, |(k, _)| k);
    let (m, from) = match main {
        Some(k) => (k, "main-axis"),
        None => (largest, "largest-peak"),
    };
    let limit_m_s2 = limit_fraction * nominal_m_s2;
    let cross_axes: Vec<CrossAxisJson> = a
        .axes
        .iter()
        .enumerate()
        .filter(|(k, _)| *k != m)
        .map(|(_, x)| {
            let fraction = x.peak_acceleration_m_s2.abs() / nominal_m_s2;
            CrossAxisJson {
                column: x.column.clone(),
                peak_acceleration_m_s2: x.peak_acceleration_m_s2,
                peak_time_s: x.peak_time_s,
                fraction_of_nominal_peak: fraction,
                pass: fraction <= limit_fraction,
            }
        })
        .collect();
    let pass = cross_axes.iter().all(|c| c.pass);
    // A clipped cross axis is a lower bound: beyond the limit it fails; within it, unknown.
    let clipped_within = a
        .axes
        .iter()
        .enumerate()
        .filter(|(k, x)| *k != m && x.clipped)
        .any(|(_, x)| x.peak_acceleration_m_s2.abs() <= limit_m_s2);
    if pass && clipped_within {
        return Err(TransverseUnknown::CrossAxisClipped);
    }
    Ok(TransverseJson {
        main_axis: a.axes.get(m).map_or_else(String::new, |x| x.column.clone()),
        main_axis_from: from.to_string(),
        limit_fraction,
        limit_m_s2,
        cross_axes,
        pass,
    })
}

/// The table's words for a transverse check: each cross axis's share of the nominal peak.
pub fn transverse_words(t: &TransverseJson) -> String {
    let axes: Vec<String> = t
        .cross_axes
        .iter()
        .map(|c| {
            format!(
                "{} {:.1} %{}",
                c.column,
                100.0 * c.fraction_of_nominal_peak,
                if c.pass { "" } else { " EXCEEDED" }
            )
        })
        .collect();
    format!(
        "transverse (main axis {}{}): {} of the nominal peak, limit {:.0} %",
        t.main_axis,
        if t.main_axis_from == "largest-peak" {
            ", its largest peak"
        } else {
            ""
        },
        axes.join(", "),
        100.0 * t.limit_fraction
    )
}
