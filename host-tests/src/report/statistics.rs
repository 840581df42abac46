//! A metric's statistics across a series of impacts (n, mean, sample standard deviation,
//! coefficient of variation, min, max) and the pass rate against a specification.

use impact_core::consts::STANDARD_GRAVITY;
use serde::Serialize;

use super::ImpactJson;

/// A series' statistics over its impacts, as `impact analyze FILES… --json` gives them (with
/// the series' recordings and entries around them): the impacts, the pass rate, each
/// metric's statistics over the comparable impacts, those left out, the later bounces'.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct SeriesStatistics {
    pub impacts: usize,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub spec: Option<PassRate>,
    /// Over the comparable impacts only: complete, unclipped, each drop's first.
    pub statistics: Vec<Statistic>,
    /// The impacts the statistics left out, by why.
    pub statistics_left_out: LeftOut,
    /// The drops' later bounces, compared bounce by bounce: empty without bounces.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub bounce_statistics: Vec<BounceGroup>,
}

/// The series' statistics over `impacts` (every impact of the series, in order).
pub fn series_statistics<'a>(
    impacts: impl Iterator<Item = &'a ImpactJson> + Clone,
) -> SeriesStatistics {
    let (kept, left_out) = comparable(impacts.clone());
    SeriesStatistics {
        impacts: impacts.clone().count(),
        spec: pass_rate(impacts.clone()),
        statistics: statistics(kept.iter().copied()),
        statistics_left_out: left_out,
        bounce_statistics: bounce_groups(impacts),
    }
}

/// A series' recordings of one shock direction (`--direction`) and their statistics, as
/// the whole series' ([`SeriesStatistics`]).
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct DirectionGroup {
    /// Null: the recordings whose direction was not found.
    pub direction: Option<String>,
    pub recordings: usize,
    #[serde(flatten)]
    pub summary: SeriesStatistics,
}

impl DirectionGroup {
    /// Its direction as the table and the report show it (`none found` for the recordings
    /// without one).
    pub fn shown(&self) -> &str {
        self.direction.as_deref().unwrap_or("none found")
    }
}

/// The series' `recordings` (each one's direction and impacts) grouped by direction, in the
/// order each direction first appears (the recordings with none last).
pub fn direction_groups<'a>(
    recordings: impl Iterator<Item = (Option<&'a str>, &'a [ImpactJson])> + Clone,
) -> Vec<DirectionGroup> {
    let mut directions: Vec<Option<&str>> = Vec::new();
    for (d, _) in recordings.clone() {
        if !directions.contains(&d) {
            directions.push(d);
        }
    }
    // The recordings with no direction last.
    directions.sort_by_key(Option::is_none);
    directions
        .into_iter()
        .map(|d| {
            let of = recordings.clone().filter(move |(x, _)| *x == d);
            DirectionGroup {
                direction: d.map(str::to_string),
                recordings: of.clone().count(),
                summary: series_statistics(of.flat_map(|(_, i)| i.iter())),
            }
        })
        .collect()
}

/// A metric across the series: its values' count, mean, sample standard deviation,
/// coefficient of variation (sd / |mean|), least and greatest. `sd` and `cv` are null with a
/// reason when they cannot be known (one value; a mean of zero).
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct Statistic {
    pub metric: &'static str,
    pub n: usize,
    pub mean: f64,
    pub sd: Option<f64>,
    pub cv: Option<f64>,
    pub min: f64,
    pub max: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub null_reason: Option<&'static str>,
}

impl Statistic {
    /// The row a table shows: metric, n, mean, sd, CV, min, max, each value in the metric's
    /// unit (`unknown` where sd or CV is null).
    pub fn cells(&self, unknown: &str) -> [String; 7] {
        let unit = METRICS
            .iter()
            .find(|(name, _, _)| *name == self.metric)
            .map_or("", |(_, u, _)| u);
        let q = |v: f64| super::fmt::human(v, unit).trim_end().to_string();
        [
            self.metric.to_string(),
            self.n.to_string(),
            q(self.mean),
            self.sd.map_or(unknown.into(), q),
            self.cv
                .map_or(unknown.into(), |c| format!("{:.2} %", 100.0 * c)),
            q(self.min),
            q(self.max),
        ]
    }
}

/// The metrics the statistics cover, with their units (for the table), and how each is read
/// off an impact.
type Metric = (&'static str, &'static str, fn(&ImpactJson) -> Option<f64>);
pub const METRICS: [Metric; 14] = [
    ("peak_acceleration_m_s2", "m/s²", |i| {
        Some(i.peak_acceleration_m_s2)
    }),
    ("peak_acceleration_g", "g", |i| {
        Some(i.peak_acceleration_m_s2 / STANDARD_GRAVITY)
    }),
    ("filtered_peak_acceleration_m_s2", "m/s²", |i| {
        i.filtered_peak_acceleration_m_s2
    }),
    ("peak_force_n", "N", |i| i.peak_force_n),
    ("delta_v_m_s", "m/s", |i| i.delta_v_m_s),
    ("duration_s", "s", |i| Some(i.duration_s)),
    ("fwhm_s", "s", |i| i.fwhm_s),
    ("crush_time_s", "s", |i| i.crush_time_s),
    ("max_deformation_m", "m", |i| i.max_deformation_m),
    ("separation_deformation_m", "m", |i| {
        i.separation_deformation_m
    }),
    ("permanent_deformation_m", "m", |i| {
        i.permanent_deformation_m
    }),
    ("rebound_velocity_m_s", "m/s", |i| i.rebound_velocity_m_s),
    ("cor", "", |i| i.cor),
    ("absorbed_energy_j", "J", |i| i.absorbed_energy_j),
];

/// Impacts the statistics leave out, by why: they do not measure the same pulse as the rest
/// (an impact cut short by the recording or a gap, or still under way; a clipped one, whose
/// peak and Δv are lower bounds; a later bounce of a drop, a different, slower impact).
#[derive(Clone, Copy, Debug, Default, Serialize, PartialEq, Eq)]
pub struct LeftOut {
    pub incomplete: usize,
    pub clipped: usize,
    pub later_bounces: usize,
}

impl LeftOut {
    /// Impacts left out in all.
    pub fn total(&self) -> usize {
        self.incomplete + self.clipped + self.later_bounces
    }

    /// The sentence the table and the report print when any impact of the `impacts` was left
    /// out.
    pub fn text(&self, impacts: usize) -> Option<String> {
        let why: Vec<String> = [
            (self.incomplete, "incomplete"),
            (self.clipped, "clipped"),
            (
                self.later_bounces,
                "later bounces of a drop (compared bounce by bounce below)",
            ),
        ]
        .iter()
        .filter(|(n, _)| *n > 0)
        .map(|(n, what)| format!("{n} {what}"))
        .collect();
        (!why.is_empty()).then(|| {
            format!(
                "statistics over the {} comparable impacts (complete, unclipped, each drop's first); left out: {}",
                impacts.saturating_sub(self.total()),
                why.join(", ")
            )
        })
    }
}

/// The impacts the statistics compare, and those left out (counted by why): complete,
/// unclipped, and each drop's first impact (a train's later bounces are other pulses).
pub fn comparable<'a>(
    impacts: impl Iterator<Item = &'a ImpactJson> + Clone,
) -> (Vec<&'a ImpactJson>, LeftOut) {
    let mut left = LeftOut::default();
    let kept = impacts
        .filter(|i| {
            if i.status != "complete" {
                left.incomplete += 1;
                false
            } else if i.clipped {
                left.clipped += 1;
                false
            } else if i.bounce.as_ref().is_some_and(|b| b.number > 0) {
                left.later_bounces += 1;
                false
            } else {
                true
            }
        })
        .collect();
    (kept, left)
}

/// The later bounces of the series' drops, compared bounce by bounce: bounce `number` (1
/// for the first after the drop's first impact) of every drop, complete and unclipped.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct BounceGroup {
    pub bounce_number: u32,
    pub statistics: Vec<Statistic>,
}

/// The later bounces (those [`comparable`] left out as `later_bounces`), complete and
/// unclipped, grouped by their bounce number, each group's statistics; numbers in order.
pub fn bounce_groups<'a>(
    impacts: impl Iterator<Item = &'a ImpactJson> + Clone,
) -> Vec<BounceGroup> {
    let whole = |i: &&ImpactJson| i.status == "complete" && !i.clipped;
    let mut numbers: Vec<u32> = impacts
        .clone()
        .filter(whole)
        .filter_map(|i| i.bounce.as_ref().map(|b| b.number))
        .filter(|&n| n > 0)
        .collect();
    numbers.sort_unstable();
    numbers.dedup();
    numbers
        .into_iter()
        .map(|number| BounceGroup {
            bounce_number: number,
            statistics: statistics(
                impacts
                    .clone()
                    .filter(whole)
                    .filter(move |i| i.bounce.as_ref().is_some_and(|b| b.number == number)),
            ),
        })
        .collect()
}

/// Each metric's statistics over `impacts` (a metric no impact has is left out). Sums in f64
/// with the mean taken out first (two passes), so a series of nearly equal values keeps its
/// spread.
pub fn statistics<'a>(impacts: impl Iterator<Item = &'a ImpactJson> + Clone) -> Vec<Statistic> {
    METRICS
        .iter()
        .filter_map(|(metric, _, read)| {
            let values = impacts.clone().filter_map(read).filter(|v| v.is_finite());
            let n = values.clone().count();
            if n == 0 {
                return None;
            }
            let mean = values.clone().sum::<f64>() / n as f64;
            let (min, max) = values
                .clone()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                    (lo.min(v), hi.max(v))
                });
            let (sd, cv, null_reason) = if n < 2 {
                (None, None, Some("one value: no spread"))
            } else {
                let ss: f64 = values.map(|v| (v - mean) * (v - mean)).sum();
                let sd = (ss / (n - 1) as f64).sqrt();
                if mean == 0.0 {
                    (
                        Some(sd),
                        None,
                        Some("mean zero: no coefficient of variation"),
                    )
                } else {
                    (Some(sd), Some(sd / mean.abs()), None)
                }
            };
            Some(Statistic {
                metric,
                n,
                mean,
                sd,
                cv,
                min,
                max,
                null_reason,
            })
        })
        .collect()
}

/// A metric's statistics kept as values arrive, in constant memory (Welford's update), for a
/// session whose impacts are not all kept (`impact watch`): the same numbers as
/// [`statistics`] to rounding.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Running {
    n: usize,
    mean: f64,
    /// Σ (x − mean)² so far.
    m2: f64,
    min: f64,
    max: f64,
}

impl Running {
    /// Takes `v` (a value that is not finite is not a measurement and is left out).
    pub fn add(&mut self, v: f64) {
        if !v.is_finite() {
            return;
        }
        self.n += 1;
        if self.n == 1 {
            (self.min, self.max) = (v, v);
        }
        let d = v - self.mean;
        self.mean += d / self.n as f64;
        self.m2 += d * (v - self.mean);
        (self.min, self.max) = (self.min.min(v), self.max.max(v));
    }

    /// The statistics so far under `metric`'s name; `None` before the first value.
    pub fn statistic(&self, metric: &'static str) -> Option<Statistic> {
        if self.n == 0 {
            return None;
        }
        let (sd, cv, null_reason) = if self.n < 2 {
            (None, None, Some("one value: no spread"))
        } else {
            let sd = (self.m2.max(0.0) / (self.n - 1) as f64).sqrt();
            if self.mean == 0.0 {
                (
                    Some(sd),
                    None,
                    Some("mean zero: no coefficient of variation"),
                )
            } else {
                (Some(sd), Some(sd / self.mean.abs()), None)
            }
        };
        Some(Statistic {
            metric,
            n: self.n,
            mean: self.mean,
            sd,
            cv,
            min: self.min,
            max: self.max,
            null_reason,
        })
    }
}

/// With `--spec`: how many of the series' impacts were judged and passed.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct PassRate {
    pub judged: usize,
    pub passed: usize,
    /// Impacts the capture could not judge (each with its reason).
    pub not_judged: usize,
    /// `passed / judged`; null when none was judged.
    pub pass_rate: Option<f64>,
}

/// The pass rate of `impacts` against `--spec`, `None` without one.
pub fn pass_rate<'a>(impacts: impl Iterator<Item = &'a ImpactJson>) -> Option<PassRate> {
    let mut rate = PassRate {
        judged: 0,
        passed: 0,
        not_judged: 0,
        pass_rate: None,
    };
    let mut asked = false;
    for v in impacts.filter_map(|i| i.spec.as_ref()) {
        asked = true;
        match v {
            Some(v) => {
                rate.judged += 1;
                rate.passed += usize::from(v.pass);
            }
            None => rate.not_judged += 1,
        }
    }
    rate.pass_rate = (rate.judged > 0).then(|| rate.passed as f64 / rate.judged as f64);
    asked.then_some(rate)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn impact(peak: f64, cor: Option<f64>) -> ImpactJson {
        ImpactJson {
            peak_acceleration_m_s2: peak,
            cor,
            ..Default::default()
        }
    }

    #[test]
    fn statistics_are_the_textbook_ones_and_unknowns_are_null() {
        let impacts = [
            impact(2.0, Some(0.5)),
            impact(4.0, None),
            impact(4.0, None),
            impact(4.0, None),
            impact(5.0, None),
            impact(5.0, None),
            impact(7.0, None),
            impact(9.0, None),
        ];
        let st = statistics(impacts.iter());
        let peak = &st[0];
        assert_eq!(peak.metric, "peak_acceleration_m_s2");
        assert_eq!((peak.n, peak.mean, peak.min, peak.max), (8, 5.0, 2.0, 9.0));
        // Σ(x - 5)² = 32, over n - 1 = 7.
        let sd = (32.0f64 / 7.0).sqrt();
        assert!((peak.sd.unwrap() - sd).abs() < 1e-12);
        assert!((peak.cv.unwrap() - sd / 5.0).abs() < 1e-12);
        let cor = st.iter().find(|s| s.metric == "cor").unwrap();
        assert_eq!((cor.n, cor.mean, cor.sd, cor.cv), (1, 0.5, None, None));
        assert_eq!(cor.null_reason, Some("one value: no spread"));
        assert!(
            st.iter().all(|s| s.metric != "delta_v_m_s"),
            "no impact has one"
        );
    }

    #[test]
    fn an_impact_reads_back_as_it_was_written() {
        // Every optional part present and absent, a verdict not judged (`null`) apart from
        // none asked (absent), and floats that a fast parser reads one ulp off.
        let verdict = crate::report::spec::VerdictJson {
            pass: false,
            band_pass: true,
            delta_v_pass: false,
            margin: 0.012199679389595984,
            worst_time_s: 0.1,
            worst_m_s2: 1.0,
            limit_m_s2: 2.0,
            worst_limit: crate::report::spec::Limit::Upper,
            delta_v_m_s: 3.0,
            nominal_start_s: 0.0,
            transverse: Some(crate::report::axes::TransverseJson {
                main_axis: "z_g".into(),
                main_axis_from: "largest-peak".into(),
                limit_fraction: 0.3,
                limit_m_s2: 147.0,
                cross_axes: vec![crate::report::axes::CrossAxisJson {
                    column: "x_g".into(),
                    peak_acceleration_m_s2: -12.5,
                    peak_time_s: 0.25,
                    fraction_of_nominal_peak: 0.025,
                    pass: true,
                }],
                pass: true,
            }),
        };
        let mut judged = impact(1.0, Some(0.012199679389595985));
        judged.spec = Some(Some(verdict));
        judged
            .null_reasons
            .insert("fits.hertz".into(), "not-asked".into());
        let mut unjudged = impact(2.0, None);
        unjudged.spec = Some(None);
        unjudged.run = Some(2);
        let none_asked = impact(3.0, None);
        for i in [judged, unjudged, none_asked] {
            let text = serde_json::to_string(&i).unwrap();
            let back: ImpactJson = serde_json::from_str(&text).unwrap();
            assert_eq!(back, i, "{text}");
        }
    }

    #[test]
    fn running_statistics_are_the_two_pass_ones() {
        let values = [2.0, 4.0, 4.0, 4.0, 5.0, 5.0, 7.0, 9.0, 1e8 + 1.0, 1e8 - 1.0];
        let impacts: Vec<ImpactJson> = values.iter().map(|&v| impact(v, None)).collect();
        let two_pass = &statistics(impacts.iter())[0];
        let mut running = Running::default();
        assert_eq!(running.statistic("peak_acceleration_m_s2"), None);
        for v in values {
            running.add(v);
        }
        running.add(f64::NAN);
        let r = running.statistic("peak_acceleration_m_s2").unwrap();
        assert_eq!(
            (r.n, r.min, r.max),
            (two_pass.n, two_pass.min, two_pass.max)
        );
        assert!((r.mean - two_pass.mean).abs() <= 1e-9 * two_pass.mean.abs());
        assert!((r.sd.unwrap() - two_pass.sd.unwrap()).abs() <= 1e-9 * two_pass.sd.unwrap());
        let mut one = Running::default();
        one.add(3.0);
        assert_eq!(
            one.statistic("cor").unwrap().null_reason,
            Some("one value: no spread")
        );
    }

    #[test]
    fn nearly_equal_values_keep_their_spread() {
        let impacts: Vec<ImpactJson> = (0..1000)
            .map(|k| impact(1e8 + if k % 2 == 0 { 1.0 } else { -1.0 }, None))
            .collect();
        let st = statistics(impacts.iter());
        assert!((st[0].sd.unwrap() - (1000.0f64 / 999.0).sqrt()).abs() < 1e-9);
    }
}
