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
