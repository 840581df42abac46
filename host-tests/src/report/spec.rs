//! The verdicts against `--spec` as JSON: the specified pulse and its tolerances once, each
//! impact's verdict (null with its reason when it cannot be judged).

use impact_core::spec::verdict::{Missing, Verdict};
use impact_core::spec::{Shape, Spec};
use serde::Serialize;

use super::fmt::shortest;

/// The verdicts of a run: how many impacts were judged and how many of them failed. Any
/// failure makes the tool's exit status [`EXIT_FAILED_VERDICT`], so a script or CI can gate on
/// it (an impact not judged is neither).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Judged {
    pub judged: usize,
    pub failed: usize,
}

/// The exit status when the run finished and at least one judged impact failed its
/// specification: distinct from 1 (an error: the run did not finish) and 2 (a usage error).
pub const EXIT_FAILED_VERDICT: u8 = 3;

impl Judged {
    /// The verdicts among the analysis's (or the board's) reports.
    pub fn reports<'a>(reports: impl IntoIterator<Item = &'a impact_core::ImpactReport>) -> Self {
        reports
            .into_iter()
            .filter_map(|r| r.verdict.as_ref()?.as_ref().ok())
            .fold(Self::default(), |j, v| j.with(v.pass))
    }

    /// The verdicts among the impacts of JSON outputs (a series).
    pub fn impacts<'a>(impacts: impl IntoIterator<Item = &'a super::ImpactJson>) -> Self {
        impacts
            .into_iter()
            .filter_map(|i| i.spec.as_ref()?.as_ref())
            .fold(Self::default(), |j, v| j.with(v.pass))
    }

    fn with(self, pass: bool) -> Self {
        Self {
            judged: self.judged + 1,
            failed: self.failed + usize::from(!pass),
        }
    }
}

/// The specified pulse and the tolerances it is judged with (fractions of the peak, or of
/// the duration for the windows and the slack).
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct SpecJson {
    pub shape: &'static str,
    /// A trapezoid's rise and fall, × the duration.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rise: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fall: Option<f64>,
    pub peak_m_s2: f64,
    pub duration_s: f64,
    pub nominal_delta_v_m_s: f64,
    /// The standard the tolerances are from (`custom`: set by hand); docs/standards.md.
    pub standard: String,
    pub band: f64,
    pub outside: f64,
    pub slack: f64,
    pub delta_v_tolerance: f64,
    pub before: f64,
    pub after: f64,
    pub watch: f64,
    /// A user's band (`band-file=`) in place of `band` and `slack`: its rows, over the
    /// duration and the peak.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub band_table: Option<Vec<BandRowJson>>,
    /// Another reading of the standard's Δv tolerance (MIL-STD-810H: ±20 % in a public
    /// transcription of its figure, where its text was ±10 %), and its source: each verdict
    /// says whether Δv passes under it too.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub delta_v_tolerance_other: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub delta_v_tolerance_other_source: Option<&'static str>,
    /// Where each of the standard's numbers comes from, and how directly (`quoted`,
    /// `secondary`, `recalled`; docs/standards.md); none for tolerances set by hand.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub sources: Vec<SourceJson>,
}

/// One of a standard's numbers, its source and how directly it was read.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct SourceJson {
    pub tolerance: &'static str,
    pub confidence: &'static str,
    pub source: &'static str,
}

/// A row of a user's band: at this time from the nominal pulse's start over the duration,
/// the least and the greatest acceptable acceleration over the peak.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct BandRowJson {
    pub time_over_duration: f64,
    pub lower_over_peak: f64,
    pub upper_over_peak: f64,
}

/// The standard whose tolerances `spec` has, and its name in the reports: the one `named`
/// (`--spec`'s `standard=`) when the spec has its tolerances, else the one preset whose
/// tolerances it has; several presets with the same tolerances and none named (a board's
/// scene line names none) are listed (`mil-std-810h or mil-std-202h`) with no preset;
/// `custom` for tolerances of none.
pub fn standard_of(
    spec: &Spec,
    named: Option<&str>,
) -> (Option<&'static crate::standards::Standard>, String) {
    let matching: Vec<&'static crate::standards::Standard> = crate::standards::STANDARDS
        .iter()
        .filter(|s| s.tolerance == spec.tolerance && spec.band.is_none())
        .collect();
    let preset = match named.and_then(|n| matching.iter().find(|s| s.name == n)) {
        Some(s) => Some(*s),
        None if matching.len() == 1 => matching.first().copied(),
        None => None,
    };
    let name = match (preset, matching.len()) {
        (Some(p), _) => p.name.to_string(),
        (None, 0) => "custom".to_string(),
        (None, _) => matching
            .iter()
            .map(|s| s.name)
            .collect::<Vec<_>>()
            .join(" or "),
    };
    (preset, name)
}

/// `spec` as JSON, its standard [`standard_of`] it (sources and another Δv reading only for
/// one preset).
pub fn spec_json(spec: &Spec, named: Option<&str>) -> SpecJson {
    let t = spec.tolerance;
    let (preset, standard) = standard_of(spec, named);
    // A trapezoid's rise and fall are the standard's only at its own ramp.
    let own_ramp = match spec.shape {
        Shape::Trapezoid { rise, fall } => preset.is_some_and(|p| rise == p.ramp && fall == p.ramp),
        _ => false,
    };
    let (rise, fall) = match spec.shape {
        Shape::Trapezoid { rise, fall } => (Some(shortest(rise)), Some(shortest(fall))),
        _ => (None, None),
    };
    SpecJson {
        shape: spec.shape.name(),
        rise,
        fall,
        peak_m_s2: shortest(spec.peak_m_s2),
        duration_s: shortest(spec.duration_s),
        nominal_delta_v_m_s: f64::from(spec.delta_v_m_s()),
        standard,
        band: shortest(t.band),
        outside: shortest(t.outside),
        slack: shortest(t.slack),
        delta_v_tolerance: shortest(t.delta_v),
        before: shortest(t.before),
        after: shortest(t.after),
        watch: shortest(t.watch),
        delta_v_tolerance_other: preset.and_then(|p| p.delta_v_other).map(|o| shortest(o.0)),
        delta_v_tolerance_other_source: preset.and_then(|p| p.delta_v_other).map(|o| o.1),
        sources: preset.map_or_else(Vec::new, |p| {
            p.sources
                .iter()
                .filter(|x| x.key != "rise, fall" || own_ramp)
                .map(|x| SourceJson {
                    tolerance: x.key,
                    confidence: x.confidence.name(),
                    source: x.from,
                })
                .collect()
        }),
        band_table: spec.band.map(|rows| {
            rows.iter()
                .map(|r| BandRowJson {
                    time_over_duration: shortest(r.u),
                    lower_over_peak: shortest(r.lower),
                    upper_over_peak: shortest(r.upper),
                })
                .collect()
        }),
    }
}

/// One impact's verdict: pass only if every sample in the watched window lies within the band
/// around the nominal pulse placed where it fits best (`nominal_start_s`) and the velocity
/// change over the standards' window is within its tolerance. `margin` is the worst
/// excursion beyond its limit over the nominal peak (negative: inside, by that much), at
/// `worst_time_s`, against the band's `worst_limit` (`limit_m_s2`).
#[derive(Clone, Debug, Serialize, serde::Deserialize, PartialEq)]
pub struct VerdictJson {
    pub pass: bool,
    pub band_pass: bool,
    pub delta_v_pass: bool,
    pub margin: f64,
    pub worst_time_s: f64,
    pub worst_m_s2: f64,
    pub limit_m_s2: f64,
    pub worst_limit: Limit,
    pub delta_v_m_s: f64,
    pub nominal_start_s: f64,
    /// With `--axes`: the transverse-motion check, part of `pass`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub transverse: Option<super::axes::TransverseJson>,
}

/// Which of the band's limits the worst point is measured against: beyond it when the band
/// fails there, else the nearer one.
#[derive(Clone, Copy, Debug, Serialize, serde::Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum Limit {
    Upper,
    Lower,
}

impl Limit {
    /// The limit the core's verdict measured its worst excursion against: its value `worst`
    /// and the limit `limit` (m/s²) and how far beyond it (`margin`, negative inside). Beyond
    /// the upper limit the value is above it; inside, the nearer limit is the upper one when
    /// the value lies at or below it (the lower one lies below the value).
    pub fn of(worst: f32, limit: f32, margin: f32) -> Limit {
        if (margin > 0.0) == (worst > limit) {
            Limit::Upper
        } else {
            Limit::Lower
        }
    }
}

/// A criterion of the verdict an impact failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Criterion {
    /// A sample above the band's upper limit (at the worst point).
    BandUpper,
    /// A sample below the band's lower limit.
    BandLower,
    /// The velocity change outside its tolerance.
    DeltaV,
    /// A cross axis beyond the transverse-motion limit (`--axes`).
    Transverse,
}

impl Criterion {
    /// In words, for the report.
    pub fn words(self) -> &'static str {
        match self {
            Criterion::BandUpper => "above the band's upper limit",
            Criterion::BandLower => "below the band's lower limit",
            Criterion::DeltaV => "Δv outside its tolerance",
            Criterion::Transverse => "a cross axis beyond the transverse limit",
        }
    }
}

impl VerdictJson {
    /// The criteria it failed, the band's first (none: it passed).
    pub fn failed(&self) -> Vec<Criterion> {
        let mut out = Vec::new();
        if !self.band_pass {
            out.push(match self.worst_limit {
                Limit::Upper => Criterion::BandUpper,
                Limit::Lower => Criterion::BandLower,
            });
        }
        if !self.delta_v_pass {
            out.push(Criterion::DeltaV);
        }
        if self.transverse.as_ref().is_some_and(|t| !t.pass) {
            out.push(Criterion::Transverse);
        }
        out
    }
}

/// The verdict as JSON, times from `t0`; `None` (null) if it could not be judged.
pub fn verdict_json(v: &Result<Verdict, Missing>, t0: f64) -> Option<VerdictJson> {
    let v = v.as_ref().ok()?;
    Some(VerdictJson {
        pass: v.pass,
        band_pass: v.band_pass,
        delta_v_pass: v.delta_v_pass,
        margin: f64::from(v.margin),
        worst_time_s: t0 + v.worst_s,
        worst_m_s2: f64::from(v.worst_m_s2),
        limit_m_s2: f64::from(v.limit_m_s2),
        worst_limit: Limit::of(v.worst_m_s2, v.limit_m_s2, v.margin),
        delta_v_m_s: f64::from(v.delta_v_m_s),
        nominal_start_s: t0 + v.start_s,
        transverse: None,
    })
}

/// The table's line for the specified pulse (before the impacts).
pub fn table_head(s: &SpecJson) -> String {
    use super::fmt::human;
    let band = match &s.band_table {
        Some(rows) => format!(
            "the user's band of {} rows (±{:.0} % beyond it)",
            rows.len(),
            100.0 * s.outside
        ),
        None => format!(
            "band ±{:.0} % of the peak (±{:.0} % outside)",
            100.0 * s.band,
            100.0 * s.outside
        ),
    };
    let other = s.delta_v_tolerance_other.map_or(String::new(), |o| {
        format!(" (±{:.0} % in another reading)", 100.0 * o)
    });
    format!(
        "spec: {} {} ({}), {}; {} tolerances: {band}, Δv {} ±{:.0} %{other} over −{}D…+{}D\n",
        s.shape,
        human(s.peak_m_s2 / impact_core::consts::STANDARD_GRAVITY, "g"),
        human(s.peak_m_s2, "m/s²"),
        human(s.duration_s, "s"),
        crate::standards::title(&s.standard),
        human(s.nominal_delta_v_m_s, "m/s"),
        100.0 * s.delta_v_tolerance,
        s.before,
        s.after,
    )
}

/// Whether Δv passes under the standard's other reading of its tolerance (none without one).
pub fn delta_v_pass_other(v: &VerdictJson, spec: Option<&SpecJson>) -> Option<bool> {
    let s = spec?;
    let tolerance = s.delta_v_tolerance_other?;
    Some((v.delta_v_m_s - s.nominal_delta_v_m_s).abs() <= tolerance * s.nominal_delta_v_m_s)
}

/// The table's line for an impact's verdict (`spec`: the specified pulse, for another
/// reading of its Δv tolerance).
pub fn table_line(
    v: Option<&VerdictJson>,
    why: Option<&String>,
    spec: Option<&SpecJson>,
) -> String {
    use super::fmt::human;
    let Some(v) = v else {
        return format!(
            "    spec: not judged ({})\n",
            not_judged(why.map_or("unknown", String::as_str))
        );
    };
    format!(
        "    spec: {}: band {} (worst {} at {:.6} s, limit {}: {} {:.1} % of the peak), Δv {} {}{}\n",
        if v.pass { "PASS" } else { "FAIL" },
        if v.band_pass { "within" } else { "EXCEEDED" },
        human(v.worst_m_s2, "m/s²"),
        v.worst_time_s,
        human(v.limit_m_s2, "m/s²"),
        if v.margin <= 0.0 {
            "inside by"
        } else {
            "beyond by"
        },
        100.0 * v.margin.abs(),
        human(v.delta_v_m_s, "m/s"),
        match (v.delta_v_pass, delta_v_pass_other(v, spec)) {
            (true, Some(false)) => "within (outside the other reading's)",
            (true, _) => "within",
            (false, Some(true)) => "OUTSIDE its tolerance (within the other reading's)",
            (false, _) => "OUTSIDE its tolerance",
        },
        v.transverse
            .as_ref()
            .map_or(String::new(), |t| format!("; {}", super::axes::transverse_words(t))),
    )
}

/// Why an impact was not judged, in words after the reason's name (`spec-window-after: …`).
pub fn not_judged(reason: &str) -> String {
    let words = match reason {
        "spec-window" => "the record holds neither side of the window the verdict watches",
        "spec-window-before" => {
            "the record starts too soon before the pulse for the window the verdict watches"
        }
        "spec-window-after" => {
            "the record (or the capture) ends before the window the verdict watches after the pulse"
        }
        "spec-resolution" => "the nominal duration is shorter than 4 samples at this rate",
        "spec-overflow" => "a number of the verdict is beyond f32",
        "transverse-clipped" => {
            "a cross axis reached its rail within the transverse limit: its true peak may lie beyond it"
        }
        _ => return reason.to_string(),
    };
    format!("{reason}: {words}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_worst_point_s_limit_is_the_one_it_is_beyond_or_nearest() {
        // Beyond: above the upper limit, below the lower one.
        assert_eq!(Limit::of(120.0, 110.0, 0.1), Limit::Upper);
        assert_eq!(Limit::of(80.0, 90.0, 0.1), Limit::Lower);
        // Inside: the upper limit above the value, the lower one below it.
        assert_eq!(Limit::of(100.0, 110.0, -0.1), Limit::Upper);
        assert_eq!(Limit::of(100.0, 90.0, -0.1), Limit::Lower);
    }
}
