//! Bounce trains (`--train`) in the report: each bounce's flight, approach speeds and CORs,
//! and each train's COR against impact speed.

use impact_core::ImpactReport;
use serde::Serialize;

use super::ImpactJson;

/// One bounce in the JSON: the flight and both measures of the approach speed, with the COR
/// each gives and their disagreement.
#[derive(Clone, Debug, Serialize, serde::Deserialize, PartialEq)]
pub struct BounceJson {
    /// 1 for the first bounce after the train's first impact.
    pub number: u32,
    /// From the previous separation to this first touch, s.
    pub flight_s: f64,
    /// The landing speed the flight gives, `g t / 2 - h / t`, m/s.
    pub v0_flight_m_s: f64,
    /// The previous impact's rebound `v_r` brought down by the flight `t`, `g t - v_r`, m/s
    /// (null: it had none, or the flight was too short to come back from it).
    pub v0_rebound_m_s: Option<f64>,
    /// `h`, how far above the previous separation the body landed, m: the previous separation
    /// deformation (the pad recovered its shape) or 0 (it kept the dent), as the previous
    /// rebound chose (core's `stream/train.rs`).
    pub landing_height_m: f64,
    /// `(Δv - v0) / v0` with each speed; null when it cannot be known, the reason beside:
    /// `clipped` (Δv a lower bound), `ac-coupled` (no Δv), `no-rebound` (no previous rebound,
    /// it was clipped, or the flight was too short to come back from it), `cor-out-of-range` (outside
    /// core's [-0.02, 1.02]: that speed or the signal is wrong).
    pub cor_flight: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cor_flight_null_reason: Option<String>,
    pub cor_rebound: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cor_rebound_null_reason: Option<String>,
    /// `v0_rebound / v0_flight - 1`.
    pub v0_disagreement: Option<f64>,
}

/// The bounce of `r`, if it continues a train; `gravity_m_s2` in its contact.
pub fn bounce_json(r: &ImpactReport, gravity_m_s2: Option<f32>) -> Option<BounceJson> {
    let b = r.bounce?;
    let f = |v: f32| v as f64;
    let tol = impact_core::report::COR_TOLERANCE as f64;
    let cor = |v0: Option<f32>| -> Result<f64, &'static str> {
        if r.clipped {
            return Err("clipped");
        }
        let v0 = v0.ok_or("no-rebound")?;
        let rebound = impact_core::report::rebound_m_s(r, v0, gravity_m_s2).ok_or("ac-coupled")?;
        let c = f(rebound / v0);
        if c.is_finite() && (-tol..=1.0 + tol).contains(&c) {
            Ok(c)
        } else {
            Err("cor-out-of-range")
        }
    };
    let (flight, rebound) = (cor(Some(b.v0_flight_m_s)), cor(b.v0_rebound_m_s));
    Some(BounceJson {
        number: b.number,
        flight_s: f(b.flight_s),
        v0_flight_m_s: f(b.v0_flight_m_s),
        v0_rebound_m_s: b.v0_rebound_m_s.map(f),
        landing_height_m: f(b.landing_height_m),
        cor_flight: flight.ok(),
        cor_flight_null_reason: flight.err().map(str::to_string),
        cor_rebound: rebound.ok(),
        cor_rebound_null_reason: rebound.err().map(str::to_string),
        v0_disagreement: b
            .v0_rebound_m_s
            .map(|r| f(r) / f(b.v0_flight_m_s) - 1.0)
            .filter(|d| d.is_finite()),
    })
}

/// One impact of a train on the COR-vs-speed curve.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct TrainPoint {
    pub index: u32,
    pub impact_velocity_m_s: f64,
    pub cor: f64,
}

/// A train's COR against impact speed, `COR = intercept + slope v0` by least squares.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct CorVsSpeed {
    pub intercept: f64,
    /// Change of COR per m/s of impact speed, s/m.
    pub slope_s_m: f64,
    /// Its standard error, s/m.
    pub slope_standard_error_s_m: f64,
    /// RMS residual of a constant COR (a Kelvin–Voigt contact) and of the line.
    pub constant_rms: f64,
    pub linear_rms: f64,
    /// `constant` when the slope is within two standard errors of zero (or below 0.005 COR
    /// over the train's speeds), else `falls-with-speed` (the nonlinear law, Hunt–Crossley:
    /// COR ≈ 1 - α v0) or `rises-with-speed`.
    pub verdict: String,
}

/// One bounce train: its impacts and, with three or more COR values, the curve.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct TrainJson {
    /// Index of the train's first impact.
    pub first_index: u32,
    pub impacts: Vec<u32>,
    pub points: Vec<TrainPoint>,
    /// Null with fewer than three CORs (the reason in `cor_vs_speed_null_reason`).
    pub cor_vs_speed: Option<CorVsSpeed>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cor_vs_speed_null_reason: Option<String>,
}

/// The trains among `impacts` (an impact without a bounce starts one); only trains with a
/// bounce are listed. `impacts`: a slice's, or JSON made one at a time.
pub fn trains<I: std::borrow::Borrow<ImpactJson>>(
    impacts: impl IntoIterator<Item = I>,
) -> Vec<TrainJson> {
    let mut out: Vec<TrainJson> = Vec::new();
    let mut current: Option<TrainJson> = None;
    for i in impacts {
        let i = i.borrow();
        if i.bounce.is_none() {
            out.extend(current.take().filter(|t| t.impacts.len() > 1));
            current = Some(TrainJson {
                first_index: i.index,
                impacts: Vec::new(),
                points: Vec::new(),
                cor_vs_speed: None,
                cor_vs_speed_null_reason: None,
            });
        }
        let Some(t) = current.as_mut() else { continue };
        t.impacts.push(i.index);
        if let (Some(v0), Some(cor)) = (i.impact_velocity_m_s, i.cor) {
            t.points.push(TrainPoint {
                index: i.index,
                impact_velocity_m_s: v0,
                cor,
            });
        }
    }
    out.extend(current.filter(|t| t.impacts.len() > 1));
    for t in &mut out {
        t.cor_vs_speed = cor_vs_speed(&t.points);
        if t.cor_vs_speed.is_none() {
            t.cor_vs_speed_null_reason = Some("fewer-than-three-cors".into());
        }
    }
    out
}

/// Least-squares line through the points; `None` with fewer than three or equal speeds.
pub fn cor_vs_speed(points: &[TrainPoint]) -> Option<CorVsSpeed> {
    let n = points.len();
    if n < 3 {
        return None;
    }
    let nf = n as f64;
    let mean_v = points.iter().map(|p| p.impact_velocity_m_s).sum::<f64>() / nf;
    let mean_e = points.iter().map(|p| p.cor).sum::<f64>() / nf;
    let sxx: f64 = points
        .iter()
        .map(|p| (p.impact_velocity_m_s - mean_v).powi(2))
        .sum();
    let sxy: f64 = points
        .iter()
        .map(|p| (p.impact_velocity_m_s - mean_v) * (p.cor - mean_e))
        .sum();
    if sxx.is_nan() || sxx <= 0.0 {
        return None;
    }
    let slope = sxy / sxx;
    let intercept = mean_e - slope * mean_v;
    let rss: f64 = points
        .iter()
        .map(|p| (p.cor - intercept - slope * p.impact_velocity_m_s).powi(2))
        .sum();
    let constant: f64 = points.iter().map(|p| (p.cor - mean_e).powi(2)).sum();
    let se = (rss / (nf - 2.0) / sxx).sqrt();
    let (lo, hi) = points
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.impact_velocity_m_s), hi.max(p.impact_velocity_m_s))
        });
    // A change of COR the speeds span that no one would call a dependence.
    let negligible = (slope * (hi - lo)).abs() < 0.005;
    let verdict = if negligible || slope.abs() <= 2.0 * se {
        "constant"
    } else if slope < 0.0 {
        "falls-with-speed"
    } else {
        "rises-with-speed"
    };
    let all = [intercept, slope, se, constant, rss];
    all.iter().all(|v| v.is_finite()).then(|| CorVsSpeed {
        intercept,
        slope_s_m: slope,
        slope_standard_error_s_m: se,
        constant_rms: (constant / nf).sqrt(),
        linear_rms: (rss / nf).sqrt(),
        verdict: verdict.into(),
    })
}

/// The table's line for a bounce.
pub fn table_line(b: &BounceJson) -> String {
    let h = crate::report::fmt::human;
    let cor = |c: Option<f64>, why: &Option<String>| match (c, why) {
        (Some(c), _) => format!("{c:.4}"),
        (None, Some(why)) => why.clone(),
        (None, None) => "-".to_string(),
    };
    format!(
        "    bounce {}: flight {}{} → v0 {} (COR {}); previous rebound {} (COR {}){}\n",
        b.number,
        h(b.flight_s, "s"),
        if b.landing_height_m > 0.0 {
            format!(", landing {} up", h(b.landing_height_m, "m"))
        } else {
            String::new()
        },
        h(b.v0_flight_m_s, "m/s"),
        cor(b.cor_flight, &b.cor_flight_null_reason),
        b.v0_rebound_m_s
            .map_or("unknown".to_string(), |v| h(v, "m/s")),
        cor(b.cor_rebound, &b.cor_rebound_null_reason),
        b.v0_disagreement
            .map_or(String::new(), |d| format!(", {:+.2} % apart", 100.0 * d)),
    )
}

/// The table's lines for the trains.
pub fn table_lines(trains: &[TrainJson]) -> String {
    let mut s = String::new();
    for t in trains {
        s.push_str(&format!(
            "bounce train from impact {} ({} impacts)",
            t.first_index,
            t.impacts.len()
        ));
        match &t.cor_vs_speed {
            Some(c) => s.push_str(&format!(
                ": COR = {:.4} {:+.4} s/m × v0 (± {:.4}): {}\n",
                c.intercept, c.slope_s_m, c.slope_standard_error_s_m, c.verdict
            )),
            None => s.push_str(": fewer than three CORs\n"),
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn points(f: impl Fn(f64) -> f64) -> Vec<TrainPoint> {
        (0..6)
            .map(|i| {
                let v = 1.5 * 0.8f64.powi(i);
                TrainPoint {
                    index: i as u32,
                    impact_velocity_m_s: v,
                    cor: f(v),
                }
            })
            .collect()
    }

    #[test]
    fn a_constant_cor_and_a_falling_one_are_told_apart() {
        let c = cor_vs_speed(&points(|_| 0.8)).unwrap();
        assert_eq!(c.verdict, "constant");
        assert!(c.slope_s_m.abs() < 1e-12);
        let c = cor_vs_speed(&points(|v| 0.95 - 0.1 * v)).unwrap();
        assert_eq!(c.verdict, "falls-with-speed");
        assert!((c.slope_s_m + 0.1).abs() < 1e-9 && (c.intercept - 0.95).abs() < 1e-9);
        let c = cor_vs_speed(&points(|v| 0.5 + 0.1 * v)).unwrap();
        assert_eq!(c.verdict, "rises-with-speed");
        assert!(cor_vs_speed(&points(|_| 0.8)[..2]).is_none());
    }
}
