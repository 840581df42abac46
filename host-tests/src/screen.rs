//! Screening a recorded channel before it is quantised: isolated glitches (removed and
//! listed) and clipped stretches (the sensor's rails, from its range or from flat tops).
//!
//! A recording is scaled to i16 counts by its own extremes, and the default trigger level
//! follows its range, so one glitch far above everything else would set both and hide the
//! real impacts. And a sensor driven past its range reads a flat top that must not pass for a
//! peak.

use serde::Serialize;

/// An isolated one- or two-sample glitch that was replaced by a straight line between its
/// neighbours.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct Spike {
    /// Index of its first sample.
    pub sample: u64,
    /// Time of its first sample, s (0 until the caller sets it from its time axis).
    pub time_s: f64,
    /// How many samples it spans (1 or 2).
    pub samples: u32,
    /// Its most extreme reading, m/s² (deceleration positive).
    pub value_m_s2: f64,
}

/// A glitch must stand this many times further from the line between its neighbours than the
/// neighbours' own steps (and the noise), and this many times further from the median than
/// any other sample of the recording.
const SPIKE_RATIO: f64 = 10.0;

/// Finds isolated spikes and replaces each by the straight line between its neighbours.
///
/// A spike is one or two samples of the same sign of deviation that stand [`SPIKE_RATIO`]
/// times further from the line joining their neighbours than any step among the two samples
/// on either side (or four times the noise `noise_m_s2`), and whose distance from the median
/// is [`SPIKE_RATIO`] times that of every other sample. The second rule keeps a real pulse
/// that is only one or two samples wide on a slow channel (the IMpack 40 g channel's water
/// entry is one): only a reading that dwarfs the whole recording is taken for a glitch.
pub fn remove_spikes(x: &mut [f64], noise_m_s2: f64) -> Vec<Spike> {
    let n = x.len();
    let mut candidates: Vec<(usize, usize)> = Vec::new();
    let mut i = 2;
    while i + 3 < n {
        let found = (1..=2).find(|&len| isolated(x, i, len, noise_m_s2));
        match found {
            Some(len) => {
                candidates.push((i, len));
                i += len + 1;
            }
            None => i += 1,
        }
    }
    if candidates.is_empty() {
        return Vec::new();
    }
    let median = median(x);
    let mut in_candidate = vec![false; n];
    for &(i, len) in &candidates {
        in_candidate[i..i + len].fill(true);
    }
    let rest = x
        .iter()
        .zip(&in_candidate)
        .filter(|(_, &c)| !c)
        .fold(0.0f64, |m, (v, _)| m.max((v - median).abs()));
    let mut spikes = Vec::new();
    for (i, len) in candidates {
        let extreme = x[i..i + len]
            .iter()
            .copied()
            .max_by(|a, b| (a - median).abs().total_cmp(&(b - median).abs()))
            .unwrap_or(x[i]);
        if (extreme - median).abs() < SPIKE_RATIO * rest {
            continue;
        }
        let (a, b) = (x[i - 1], x[i + len]);
        for j in 0..len {
            x[i + j] = a + (b - a) * (j + 1) as f64 / (len + 1) as f64;
        }
        spikes.push(Spike {
            sample: i as u64,
            time_s: 0.0,
            samples: len as u32,
            value_m_s2: extreme,
        });
    }
    spikes
}

/// Whether `x[i..i + len]` stands out from the line between `x[i - 1]` and `x[i + len]` (see
/// [`remove_spikes`]); needs two samples on each side.
fn isolated(x: &[f64], i: usize, len: usize, noise: f64) -> bool {
    if i < 2 || i + len + 1 >= x.len() {
        return false;
    }
    let (a, b) = (x[i - 1], x[i + len]);
    let mut sign = 0.0;
    let mut least = f64::INFINITY;
    for j in 0..len {
        let d = x[i + j] - (a + (b - a) * (j + 1) as f64 / (len + 1) as f64);
        if d == 0.0 || (sign != 0.0 && d.signum() != sign) {
            return false;
        }
        sign = d.signum();
        least = least.min(d.abs());
    }
    let local = (a - x[i - 2])
        .abs()
        .max((x[i + len + 1] - b).abs())
        .max((b - a).abs())
        .max(4.0 * noise);
    least >= SPIKE_RATIO * local && least > 0.0
}

fn median(x: &[f64]) -> f64 {
    let mut v = x.to_vec();
    let mid = v.len() / 2;
    *v.select_nth_unstable_by(mid, f64::total_cmp).1
}

/// The levels at which the channel is clipped, m/s²: nothing beyond them is known.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct Clipping {
    /// Readings at or below this are at the lower rail (if known).
    pub low_m_s2: Option<f64>,
    /// Readings at or above this are at the upper rail (if known).
    pub high_m_s2: Option<f64>,
    /// "range" (the sensor's full scale, given) or "flat-top" (found in the recording).
    pub from: String,
}

/// A reading within this fraction of the full scale counts as at the rail.
pub const RAIL_FRACTION: f64 = 0.995;

/// Clipping levels from the sensor's full scale, m/s² (readings at ±[`RAIL_FRACTION`] of it
/// and beyond are at the rail).
pub fn from_range(full_scale_m_s2: f64) -> Clipping {
    Clipping {
        low_m_s2: Some(-RAIL_FRACTION * full_scale_m_s2),
        high_m_s2: Some(RAIL_FRACTION * full_scale_m_s2),
        from: "range".into(),
    }
}

/// Clipping levels found as flat tops: a run of at least three equal readings at the
/// recording's maximum (or minimum), entered or left at a slope no smooth peak has at its top.
///
/// With `q` the recording's resolution (its smallest non-zero step) and `L` the run's length,
/// a smooth peak quantised by `q` holds its top for `L` samples only if it arrives there with
/// a slope of about `4 q / L`; a clipped pulse arrives with its full slope. So a run counts as
/// clipped when the steeper of its entry and exit (over one or two samples) is at least
/// `16 q / L` and at least `2 q`. `None` when no such run exists.
pub fn flat_tops(x: &[f64]) -> Option<Clipping> {
    let q = x
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .filter(|d| *d > 0.0)
        .fold(f64::INFINITY, f64::min);
    if !q.is_finite() {
        return None;
    }
    let max = x.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let min = x.iter().copied().fold(f64::INFINITY, f64::min);
    let high = clipped_run_at(x, max, q).then_some(max);
    let low = clipped_run_at(x, min, q).then_some(min);
    (high.is_some() || low.is_some()).then(|| Clipping {
        low_m_s2: low,
        high_m_s2: high,
        from: "flat-top".into(),
    })
}

/// Whether some run of at least three readings equal to `level` is entered or left steeply.
fn clipped_run_at(x: &[f64], level: f64, q: f64) -> bool {
    let mut i = 0;
    while i < x.len() {
        if x[i] != level {
            i += 1;
            continue;
        }
        let start = i;
        while i < x.len() && x[i] == level {
            i += 1;
        }
        let len = i - start;
        if len < 3 {
            continue;
        }
        let slope_at = |a: Option<usize>, b: Option<usize>| {
            let one = a.map_or(0.0, |a| (x[a] - level).abs());
            let two = b.map_or(0.0, |b| (x[b] - level).abs() / 2.0);
            one.max(two)
        };
        let entry = slope_at(start.checked_sub(1), start.checked_sub(2));
        let exit = slope_at(
            (i < x.len()).then_some(i),
            (i + 1 < x.len()).then_some(i + 1),
        );
        let slope = entry.max(exit);
        if slope >= 2.0 * q && slope >= 16.0 * q / len as f64 {
            return true;
        }
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A half-sine pulse on a baseline with ±0.01 of deterministic dither, rounded to 0.01.
    fn pulse(n: usize, at: usize, width: usize, peak: f64) -> Vec<f64> {
        (0..n)
            .map(|i| {
                let v = if i >= at && i < at + width {
                    peak * (std::f64::consts::PI * (i - at) as f64 / width as f64).sin()
                } else {
                    0.0
                };
                let dither = 0.01 * ((i * 7919 % 3) as f64 - 1.0);
                (v * 100.0).round() / 100.0 + dither
            })
            .collect()
    }

    #[test]
    fn a_glitch_far_above_the_recording_is_removed_and_listed() {
        let mut x = pulse(2000, 500, 50, 50.0);
        let clean = x.clone();
        x[1500] = 1e4;
        let spikes = remove_spikes(&mut x, 0.01);
        assert_eq!(spikes.len(), 1);
        assert_eq!(spikes[0].sample, 1500);
        assert_eq!(spikes[0].value_m_s2, 1e4);
        assert!((x[1500] - clean[1500]).abs() < 0.05);
        assert_eq!(&x[..1500], &clean[..1500]);
    }

    #[test]
    fn a_two_sample_glitch_is_removed() {
        let mut x = pulse(2000, 500, 50, 50.0);
        x[1500] = -3e3;
        x[1501] = -2e3;
        let spikes = remove_spikes(&mut x, 0.01);
        assert_eq!(spikes.len(), 1);
        assert_eq!((spikes[0].sample, spikes[0].samples), (1500, 2));
        assert_eq!(spikes[0].value_m_s2, -3e3);
    }

    #[test]
    fn a_real_short_pulse_stays() {
        // A two-sample pulse that does not dwarf the rest of the recording.
        let mut x = pulse(2000, 500, 50, 50.0);
        x[1500] = 200.0;
        x[1501] = 150.0;
        let before = x.clone();
        assert!(remove_spikes(&mut x, 0.01).is_empty());
        assert_eq!(x, before);
        // A smooth pulse is never a spike, however large.
        let mut y = pulse(2000, 500, 5, 1e6);
        let before = y.clone();
        assert!(remove_spikes(&mut y, 0.01).is_empty());
        assert_eq!(y, before);
    }

    #[test]
    fn a_clipped_half_sine_is_a_flat_top_and_a_smooth_one_is_not() {
        let x = pulse(4000, 1000, 1000, 40.0);
        assert_eq!(flat_tops(&x), None);
        let clipped: Vec<f64> = x.iter().map(|v| v.min(16.0)).collect();
        let c = flat_tops(&clipped).expect("flat top");
        assert_eq!(c.high_m_s2, Some(16.0));
        assert_eq!(c.low_m_s2, None);
        // Three samples at a steep edge are enough.
        let mut short = pulse(4000, 1000, 8, 40.0);
        let top = 36.0;
        short[1003..1006].fill(top);
        assert!(flat_tops(&short).is_some_and(|c| c.high_m_s2 == Some(top)));
    }

    #[test]
    fn range_levels_are_just_inside_full_scale() {
        let c = from_range(16.0 * 9.80665);
        assert!(c.high_m_s2.unwrap() < 16.0 * 9.80665);
        assert!(c.high_m_s2.unwrap() > 15.9 * 9.80665);
        assert_eq!(c.low_m_s2, c.high_m_s2.map(|v| -v));
    }
}
