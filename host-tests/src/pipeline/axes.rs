//! Three axes (`--axes x,y,z`): the pipeline runs on the magnitude of the axes' deviations from
//! their own zeros, `|f − f₀|` ([`impact_core::signal::axes_zero`]: each axis zeroed before
//! the magnitude, as SAE J211 and ISO 6487 zero each channel; the trigger on it, as crash and
//! drop practice report |a|), and each impact gets every axis's own peak and Δv over its
//! contact.

use impact_core::report::AC_COUPLED_RATIO;
use impact_core::ImpactReport;
use impact_io::channel::ColumnRef;

use crate::pipeline::{screen, PipelineError};
use crate::report::axes::{AxesJson, AxisJson};
use crate::report::Clipping;

/// One axis of a recording, in m/s², and its rails.
#[derive(Clone, Debug)]
pub struct Axis {
    /// The column's header name.
    pub name: String,
    pub accel_m_s2: Vec<f64>,
    /// From the sensor's full scale (`--range`, per axis) or the axis's flat tops (beyond its
    /// noise floor, as the channel's).
    pub rails: Option<Clipping>,
}

impl Axis {
    /// An axis with its rails from `full_scale_m_s2` if given, else from its flat tops
    /// beyond its noise (as the channel's, [`crate::pipeline::survey`]).
    pub fn new(name: String, accel_m_s2: Vec<f64>, full_scale_m_s2: Option<f64>) -> Self {
        let rails = match full_scale_m_s2 {
            Some(fs) => Some(screen::from_range(fs)),
            None => crate::pipeline::survey::Survey::of(&accel_m_s2, false)
                .ok()
                .and_then(|s| s.flat_tops),
        };
        Self {
            name,
            accel_m_s2,
            rails,
        }
    }

    fn at_rail(&self, v: f64) -> bool {
        self.rails.as_ref().is_some_and(|r| {
            r.low_m_s2.is_some_and(|lo| v <= lo) || r.high_m_s2.is_some_and(|hi| v >= hi)
        })
    }
}

/// Samples before the onset the axis baselines are taken over (ending [`BASELINE_GAP`]
/// samples before it, and never before the previous impact's end): the stream's own
/// baseline is a stride of 64.
const BASELINE_SAMPLES: usize = 64;
const BASELINE_GAP: usize = 4;

/// The axes over `r`'s window; `axes` are in m/s² on the recording's time base starting at
/// `t0`, `resultant` their resultant, `rate` the sample rate; `previous_end` is the sample
/// after the previous impact (0 for the first).
pub fn impact_axes(
    r: &ImpactReport,
    previous_end: u64,
    axes: &[Axis],
    resultant: &[f64],
    rate: f64,
    t0: f64,
) -> AxesJson {
    let n = resultant.len();
    let onset = (r.start_sample as usize).min(n);
    let end = (r.end_sample as usize).clamp(onset, n);
    // The contact: from first touch to separation, whole samples inside.
    let touch = (r.start_s * rate).ceil().max(0.0) as usize;
    let separation = ((r.start_s + r.duration_s as f64) * rate).floor().max(0.0) as usize;
    let contact = touch.min(n)..separation.clamp(touch.min(n), n);
    let before = onset.saturating_sub(BASELINE_GAP);
    let quiet = before
        .saturating_sub(BASELINE_SAMPLES)
        .max((previous_end as usize).min(before))..before;
    let resultant_peak_m_s2 = resultant
        .get(onset..end)
        .unwrap_or(&[])
        .iter()
        .fold(0.0f64, |m, v| m.max(*v));
    let axes: Vec<AxisJson> = axes
        .iter()
        .map(|axis| {
            let a = &axis.accel_m_s2;
            let base = match a.get(quiet.clone()) {
                Some(q) if !q.is_empty() => q.iter().sum::<f64>() / q.len() as f64,
                _ => a.get(onset).copied().unwrap_or(0.0),
            };
            let (peak_i, peak) = (onset..end)
                .filter_map(|i| a.get(i).map(|v| (i, v - base)))
                .fold((onset, 0.0f64), |best, (i, d)| {
                    if d.abs() > best.1.abs() {
                        (i, d)
                    } else {
                        best
                    }
                });
            let sum = |r: std::ops::Range<usize>| {
                a.get(r)
                    .unwrap_or(&[])
                    .iter()
                    .map(|v| v - base)
                    .sum::<f64>()
                    / rate
            };
            let dv = sum(contact.clone());
            // As the core judges a single channel: the whole window undoing most of the
            // contact's Δv is the mark of an axis that does not hold DC (judged below,
            // against the other axes).
            let window = sum(onset..end);
            let clipped = a
                .get(onset..end)
                .unwrap_or(&[])
                .iter()
                .any(|&v| axis.at_rail(v));
            AxisJson {
                column: axis.name.clone(),
                clipped,
                baseline_m_s2: base,
                peak_acceleration_m_s2: peak,
                peak_time_s: t0 + peak_i as f64 / rate,
                delta_v_m_s: Some(dv),
                ac_coupled: dv != 0.0 && window / dv < AC_COUPLED_RATIO,
            }
        })
        .collect();
    // A cross axis's Δv near zero is all noise: its ratio says nothing. Judged only where
    // the axis carries a tenth of the largest axis's Δv.
    let largest = axes
        .iter()
        .filter_map(|a: &AxisJson| a.delta_v_m_s)
        .fold(0.0f64, |m, v| m.max(v.abs()));
    let axes: Vec<AxisJson> = axes
        .into_iter()
        .map(|mut a| {
            let dv = a.delta_v_m_s.unwrap_or(0.0);
            a.ac_coupled &= dv.abs() >= 0.1 * largest;
            if a.ac_coupled {
                a.delta_v_m_s = None;
            }
            a
        })
        .collect();
    let delta_v_magnitude_m_s = axes
        .iter()
        .map(|a: &AxisJson| a.delta_v_m_s.map(|v| v * v))
        .sum::<Option<f64>>()
        .map(f64::sqrt);
    AxesJson {
        resultant_peak_m_s2,
        delta_v_magnitude_m_s,
        axes,
    }
}

/// The transverse-motion check's settings (`--axes` with `--spec`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TransverseCheck {
    /// A cross axis's peak limit over the nominal peak.
    pub limit_fraction: f64,
    /// The main axis, an index into `--axes` (none: each impact's largest).
    pub main: Option<usize>,
}

/// IEC 60068-2-27:2008, 4.1.3 (recalled): a cross axis within 30 % of the nominal peak.
pub const TRANSVERSE_LIMIT: f64 = 0.3;

impl TransverseCheck {
    /// The check `args` ask for: none without both `--axes` and `--spec`.
    /// `names` are the axes' header names, in `--axes`' order: `--main-axis` is one of
    /// `--axes` as written there, or an axis's header name (`--axes 1,2,3 --main-axis z_g`).
    pub fn of(
        args: &crate::pipeline::AnalyzeArgs,
        names: &[&str],
    ) -> Result<Option<Self>, PipelineError> {
        if args.axes.is_empty() || args.spec.is_none() {
            return Ok(None);
        }
        let named = |m: &ColumnRef| match m {
            ColumnRef::Name(n) => names.iter().position(|a| a == n),
            ColumnRef::Index(_) => None,
        };
        let main = match &args.main_axis {
            None => None,
            Some(m) => Some(
                args.axes
                    .iter()
                    .position(|a| a == m)
                    .or_else(|| named(m))
                    .ok_or_else(|| PipelineError::MainAxis {
                        given: m.to_string(),
                        axes: args
                            .axes
                            .iter()
                            .map(ToString::to_string)
                            .collect::<Vec<_>>()
                            .join(","),
                    })?,
            ),
        };
        Ok(Some(Self {
            limit_fraction: args.transverse_limit.unwrap_or(TRANSVERSE_LIMIT),
            main,
        }))
    }

    /// Adds the transverse check of `axes` to the impact's verdict against a nominal peak
    /// `nominal_m_s2`: a cross axis beyond the limit fails it; a clipped one within it makes
    /// a passing verdict unknown (null, reason `transverse-clipped`) and leaves a failing one
    /// failed (`null_reasons["spec.transverse"]`).
    pub fn judge(&self, j: &mut crate::report::ImpactJson, axes: &AxesJson, nominal_m_s2: f64) {
        let Some(Some(v)) = &mut j.spec else { return };
        match crate::report::axes::transverse(axes, nominal_m_s2, self.limit_fraction, self.main) {
            Ok(t) => {
                v.pass &= t.pass;
                v.transverse = Some(t);
            }
            // A pulse that failed its band or Δv fails whatever the cross axes; one that
            // passed them is not judged.
            Err(why) if v.pass => {
                j.spec = Some(None);
                j.null_reasons.insert("spec".into(), why.reason().into());
            }
            Err(why) => {
                j.null_reasons
                    .insert("spec.transverse".into(), why.reason().into());
            }
        }
    }
}

/// The counts the stream analyses with `--axes`: each axis in counts of `gain_m_s2_per_count`
/// (a third axis of zeros for two), zeroed each on its own and their magnitude taken
/// ([`impact_core::signal::axes_zero::AxesZero`]) with the scene's edge level and settle time
/// and each axis's rails, from the record's first quiet stride (found ahead: a record that
/// starts inside a pulse is not zeroed there).
pub fn zeroed_counts(
    axes: &[Axis],
    scene: &impact_core::Scene,
    gain_m_s2_per_count: f64,
    to_count: impl Fn(f64, f64) -> i16,
) -> Vec<i16> {
    use impact_core::signal::axes_zero::{AxesZero, Settings};
    let rate = f64::from(scene.calibration.sample_rate_hz);
    let n = axes.iter().map(|a| a.accel_m_s2.len()).max().unwrap_or(0);
    let samples: Vec<[i16; 3]> = (0..n)
        .map(|i| {
            std::array::from_fn(|k| {
                axes.get(k)
                    .and_then(|a| a.accel_m_s2.get(i))
                    .map_or(0, |&v| to_count(v, gain_m_s2_per_count))
            })
        })
        .collect();
    let rails = std::array::from_fn(|k| {
        let rail = |v: Option<f64>, none: i16| v.map_or(none, |v| to_count(v, gain_m_s2_per_count));
        axes.get(k)
            .and_then(|a| a.rails.as_ref())
            .map_or((i16::MIN, i16::MAX), |r| {
                (rail(r.low_m_s2, i16::MIN), rail(r.high_m_s2, i16::MAX))
            })
    });
    let settings = Settings {
        edge_counts: (f64::from(scene.edge_m_s2) / gain_m_s2_per_count) as f32,
        settle_samples: (f64::from(scene.settle_s) * rate).clamp(0.0, f64::from(u32::MAX)) as u32,
        free_fall: free_fall(f64::from(scene.gravity_m_s2), gain_m_s2_per_count, rate),
        rails,
    };
    let mut zero = AxesZero::new(settings);
    if let Some(first) = AxesZero::first_quiet(&samples, &settings) {
        zero.seed(first);
    }
    samples.into_iter().map(|s| zero.push(s)).collect()
}

/// Free fall for three axes: their magnitude below a quarter of g for 10 ms (at least 8
/// samples): a pulse's zero crossing is quicker; a flight between bounces, longer.
pub fn free_fall(
    gravity_m_s2: f64,
    gain_m_s2_per_count: f64,
    rate_hz: f64,
) -> impact_core::signal::axes_zero::FreeFall {
    impact_core::signal::axes_zero::FreeFall {
        below_counts: (0.25 * gravity_m_s2 / gain_m_s2_per_count) as f32,
        samples: (0.01 * rate_hz).clamp(8.0, f64::from(u32::MAX)) as u32,
    }
}

/// Removes the spikes found on the resultant (`removals`) from an axis: each spike's samples
/// replaced by the straight line between the axis's own neighbours.
pub fn remove_spikes(axis: &mut [f64], removals: &[screen::Removal]) {
    // One at a time, in order: a spike's neighbour may be the one just removed.
    for r in removals {
        let (at, len) = (r.spike.sample as usize, r.spike.samples as usize);
        let before = at.checked_sub(1).and_then(|k| axis.get(k)).copied();
        let after = axis.get(at + len).copied();
        let (a, b) = match (before, after) {
            (Some(a), Some(b)) => (a, b),
            (Some(a), None) => (a, a),
            (None, Some(b)) => (b, b),
            (None, None) => continue,
        };
        screen::fill(&[r.between(a, b)], axis);
    }
}
