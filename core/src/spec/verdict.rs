//! A captured impact judged against a specified pulse: the nominal pulse placed where the
//! measured one fits its band best, the worst excursion there, and the velocity change over the
//! standards' window against its tolerance.
//!
//! The placement is a search over the nominal pulse's start, within half a duration of where
//! its peak meets the measured peak, for the least worst excursion: first on the signal's
//! extremes in [`BUCKETS`] spans against the band on the same grid (at most 129 starts of
//! 128 comparisons), then over every sample for 17 starts around the best one.

use super::{band_over, Nominal, Spec};

/// Spans the signal is summarised in for the search (its least and greatest value each).
pub const BUCKETS: usize = 128;

/// The verdict of one impact.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Verdict {
    /// Within the band and the velocity tolerance.
    pub pass: bool,
    pub band_pass: bool,
    pub delta_v_pass: bool,
    /// The nominal pulse's start, s from the stream's first sample.
    pub start_s: f64,
    /// The worst excursion: how far beyond its limit (negative: inside), over the peak.
    pub margin: f32,
    /// Where (s from the stream's first sample), and the acceleration there and its limit,
    /// m/s².
    pub worst_s: f64,
    pub worst_m_s2: f32,
    pub limit_m_s2: f32,
    /// The velocity change over the standards' window, m/s.
    pub delta_v_m_s: f32,
}

/// Why there is no verdict.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Missing {
    /// The record holds neither side of the window the verdict watches around the pulse (a
    /// nominal duration too long for the capture at this rate, or for the recording).
    Window,
    /// The capture (or the recording) does not reach back over the window the verdict
    /// watches before the pulse (`before` × D before it, and the search's half duration): the
    /// record starts too soon before the pulse.
    WindowBefore,
    /// The capture (or the recording) ends before the window the verdict watches after the
    /// pulse (`watch` × D after it): the pulse is cut by the capture's length, or the record
    /// ends too soon after it.
    WindowAfter,
    /// The nominal duration is shorter than 4 samples at this rate.
    Resolution,
    /// A number of the verdict is beyond f32 (the scene's gain or peak out of any real range).
    Overflow,
}

impl Missing {
    /// Every reason.
    pub const ALL: [Missing; 5] = [
        Missing::Window,
        Missing::WindowBefore,
        Missing::WindowAfter,
        Missing::Resolution,
        Missing::Overflow,
    ];

    /// The reason's name in the reports.
    pub fn name(self) -> &'static str {
        match self {
            Missing::Window => "spec-window",
            Missing::WindowBefore => "spec-window-before",
            Missing::WindowAfter => "spec-window-after",
            Missing::Resolution => "spec-resolution",
            Missing::Overflow => "spec-overflow",
        }
    }
}

/// Whether a placement of worst excursion `worst` is better than the best so far, the
/// placements tried nearest first: one that passes (the standards: a pulse that "can be
/// contained" in the band complies) over one that fails, and among failing ones the least
/// excursion; among passing ones the nearest stays.
fn better(worst: f32, best: f32) -> bool {
    match (worst <= 0.0, best <= 0.0) {
        (true, false) => true,
        (false, false) => worst < best,
        _ => false,
    }
}

/// Judges the acceleration `a(i)` (m/s² in the pulse's direction, stream index `i`; `None`
/// outside what is held) at `rate_hz` against `spec`, the measured peak at stream index
/// `peak_index`. Written for the FPU: positions in f32 samples from the first sample watched
/// (`base`), the shape tabulated, f64 only for the velocity change's sum.
pub fn judge(
    a: impl Fn(u64) -> Option<f32>,
    rate_hz: f32,
    spec: &Spec,
    peak_index: u64,
) -> Result<Verdict, Missing> {
    let t = &spec.tolerance;
    let d = spec.duration_s * rate_hz; // samples
    if !(d >= 4.0) {
        return Err(Missing::Resolution);
    }
    let peak = spec.peak_m_s2;
    let nominal = Nominal::new(spec.shape);
    let band = |u: f32| spec.band_with(|u| nominal.at(u), u);
    // The start where the nominal peak meets the measured one; the search half a duration
    // either way; the span the signal must cover for any of them, from `base` (its first
    // sample) over `span` samples.
    // The band's watched window (a user's band widens it to its rows), × D.
    let (before, watch) = spec.watched();
    let lead = before * d;
    let reach = spec.shape.peak_at() * d + d / 2.0 + lead;
    let before_reach = libm::ceilf(reach) as u64;
    // From base: the difference of the two indices is exact in u64, where each index alone in
    // f32 is not (past 2^24 samples, 33 s of a board's stream at 500 kS/s).
    let guess = before_reach as f32 - spec.shape.peak_at() * d;
    let from = guess - d / 2.0 - lead; // >= 0
    let to = guess + d / 2.0 + (1.0 + watch.max(t.after)) * d;
    // A window beyond any record's reach (2^32 samples) is held by none.
    if !(to < u32::MAX as f32) {
        return Err(Missing::Window);
    }
    let span = libm::ceilf(to) as u32 + 1;
    // Which side of the window the record lacks, if any: both, or the one it lacks.
    let last = peak_index
        .saturating_add(u64::from(span))
        .saturating_sub(before_reach.saturating_add(1));
    let after_held = a(last).is_some();
    let base = match peak_index.checked_sub(before_reach) {
        Some(base) if a(base).is_some() => base,
        _ if after_held => return Err(Missing::WindowBefore),
        _ => return Err(Missing::Window),
    };
    // A sample the record does not hold is missing before the pulse when it lies before the
    // measured peak, after it otherwise.
    let a = |i: u64| {
        a(i).ok_or(if i < peak_index {
            Missing::WindowBefore
        } else {
            Missing::WindowAfter
        })
    };
    // The signal's extremes in BUCKETS spans of `w` samples from `base`.
    let w = span as f32 / BUCKETS as f32;
    let mut ext = [(f32::INFINITY, f32::NEG_INFINITY); BUCKETS];
    for k in 0..span {
        let v = a(base + u64::from(k))?;
        let j = (k as usize * BUCKETS / span as usize).min(BUCKETS - 1);
        if let Some(e) = ext.get_mut(j) {
            e.0 = e.0.min(v);
            e.1 = e.1.max(v);
        }
    }
    // The band over bucket j of a nominal pulse starting at bucket `s`'s start plus `lead`:
    // the loosest limits over the bucket's two ends and a user's band's rows between them (a
    // bucket's extremes inside them is necessary for its samples to lie inside: the search
    // finds where the pulse can fit, the exact pass below says whether it does). The band is
    // watched from `before` × D before the pulse to `watch` × D after it.
    let watched = (((lead + (1.0 + watch) * d) / w) as usize).min(BUCKETS);
    let mut limits = [(0.0f32, 0.0f32); BUCKETS];
    for (j, l) in limits.iter_mut().enumerate().take(watched) {
        let u = |j: f32| (j * w - lead) / d;
        let (lo, hi) = band_over(spec, |u| nominal.at(u), u(j as f32), u(j as f32 + 1.0));
        *l = (lo * peak, hi * peak);
    }
    // The start in whole buckets: nearest the peak-aligned one (`centre`) among those that
    // may pass, else of least worst excursion ([`better`]).
    let first = libm::ceilf(from / w) as usize;
    let steps = ((d / w) as usize).min(BUCKETS);
    let centre = libm::roundf((guess - lead) / w) as usize;
    let mut best = (centre, f32::INFINITY);
    for k in 0..=2 * steps {
        // centre, centre + 1, centre - 1, centre + 2, …
        let offset = k.div_ceil(2);
        let Some(s) = (if k % 2 == 1 {
            Some(centre + offset)
        } else {
            centre.checked_sub(offset)
        })
        .filter(|&s| (first..=first + steps).contains(&s)) else {
            continue;
        };
        let mut worst = f32::NEG_INFINITY;
        for (&(lo, hi), &(lower, upper)) in ext.iter().skip(s).zip(limits.iter().take(watched)) {
            worst = worst.max(hi - upper).max(lower - lo);
        }
        if better(worst, best.1) {
            best = (s, worst);
        }
    }
    // Every sample, for the coarse start and then, halving the step from half a bucket down
    // to an eighth (at least a sample), a step either way of the best so far: the worst
    // excursion at the best of them. The first start that passes is the one (the nearest);
    // a start whose excursion so far already exceeds the best's is left there (it cannot be
    // better), after a look at the best's worst sample first.
    let coarse = best.0 as f32 * w + lead;
    let mut fine = (coarse, f32::INFINITY, 0u32, 0.0f32, 0.0f32);
    let try_start = |start: f32, fine: &mut (f32, f32, u32, f32, f32)| -> Result<(), Missing> {
        let k0 = libm::ceilf((start - lead).max(0.0)) as u32;
        let k1 = (libm::floorf(start + (1.0 + watch) * d) as u32).min(span - 1);
        let excursion = |k: u32| -> Result<(f32, f32, f32), Missing> {
            let v = a(base + u64::from(k))?;
            let (lo, hi) = band((k as f32 - start) / d);
            let (lo, hi) = (lo * peak, hi * peak);
            Ok(if v - hi >= lo - v {
                (v - hi, v, hi)
            } else {
                (lo - v, v, lo)
            })
        };
        if fine.1.is_finite() && (k0..=k1).contains(&fine.2) && excursion(fine.2)?.0 > fine.1 {
            return Ok(());
        }
        let (mut worst, mut worst_k, mut worst_v, mut limit) =
            (f32::NEG_INFINITY, 0u32, 0.0f32, 0.0f32);
        for k in k0..=k1 {
            if worst > fine.1 {
                return Ok(());
            }
            let (over, v, lim) = excursion(k)?;
            if over > worst {
                (worst, worst_k, worst_v, limit) = (over, k, v, lim);
            }
        }
        if better(worst, fine.1) {
            *fine = (start, worst, worst_k, worst_v, limit);
        }
        Ok(())
    };
    try_start(coarse, &mut fine)?;
    let mut step = w / 2.0;
    while fine.1 > 0.0 {
        let around = fine.0;
        try_start(around - step, &mut fine)?;
        if fine.1 > 0.0 {
            try_start(around + step, &mut fine)?;
        }
        if step <= 1.0 || step <= w / 8.0 {
            break;
        }
        step = (step / 2.0).max(1.0);
    }
    let (start, worst, worst_k, worst_v, limit) = fine;
    // The velocity change from `before` × D before the pulse to `after` × D after it.
    let k0 = libm::ceilf((start - t.before * d).max(0.0)) as u32;
    let k1 = (libm::floorf(start + (1.0 + t.after) * d) as u32).min(span - 1);
    // Compensated f32 sums (Kahan): an f64's accuracy at the FPU's speed.
    let (mut sum, mut carry) = (0.0f32, 0.0f32);
    for k in k0..=k1 {
        let y = a(base + u64::from(k))? - carry;
        let next = sum + y;
        carry = (next - sum) - y;
        sum = next;
    }
    let delta_v = sum / rate_hz;
    let nominal_dv = spec.delta_v_m_s();
    let band_pass = worst <= 0.0;
    let delta_v_pass = libm::fabsf(delta_v - nominal_dv) <= t.delta_v * nominal_dv;
    let seconds = |k: f64| (base as f64 + k) / f64::from(rate_hz);
    let margin = worst / peak;
    if ![margin, worst_v, limit, delta_v]
        .iter()
        .all(|x| x.is_finite())
    {
        return Err(Missing::Overflow);
    }
    Ok(Verdict {
        pass: band_pass && delta_v_pass,
        band_pass,
        delta_v_pass,
        start_s: seconds(f64::from(start)),
        margin,
        worst_s: seconds(f64::from(worst_k)),
        worst_m_s2: worst_v,
        limit_m_s2: limit,
        delta_v_m_s: delta_v,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spec::{BandPoint, Shape, Tolerance};

    fn spec(shape: Shape) -> Spec {
        Spec {
            shape,
            peak_m_s2: 500.0,
            duration_s: 0.011,
            tolerance: Tolerance {
                band: 0.2,
                outside: 0.2,
                slack: 0.0,
                delta_v: 0.15,
                before: 0.4,
                after: 0.1,
                watch: 1.5,
            },
            band: None,
        }
    }

    /// A pulse of `shape` of `peak` (m/s²) and `dur` (s), at 50 kS/s, its start at
    /// sample 2000 (and `glitch` added at a sample).
    fn judge_pulse(shape: Shape, peak: f32, dur: f32, glitch: Option<(u64, f32)>) -> Verdict {
        judge_against(&spec(shape), peak, dur, glitch)
    }

    /// [`judge_pulse`] against `spec`, its shape's pulse measured.
    fn judge_against(spec: &Spec, peak: f32, dur: f32, glitch: Option<(u64, f32)>) -> Verdict {
        let shape = spec.shape;
        let rate = 50_000.0f32;
        let start = 2000.0;
        let a = |i: u64| {
            let u = (i as f32 - start) / (dur * rate);
            let g = glitch.filter(|g| g.0 == i).map_or(0.0, |g| g.1);
            Some(peak * shape.at(u) + g)
        };
        let peak_index = (start + shape.peak_at() * dur * rate) as u64;
        let held = |i: u64| (i < 10_000).then(|| a(i)).flatten();
        judge(
            held,
            rate,
            spec,
            peak_index.min(2000 + (dur * rate) as u64 - 1),
        )
        .unwrap()
    }

    /// The same pulse late in a long stream (its indices past 2^31, where an index alone in
    /// f32 is off by hundreds of samples) gets the same verdict as at its start: the
    /// placement works from the indices' difference.
    #[test]
    fn a_pulse_late_in_the_stream_is_judged_as_an_early_one() {
        let s = spec(Shape::HalfSine);
        let (rate, dur, start) = (50_000.0f32, 0.011f32, 2000u64);
        let at = |offset: u64| {
            let a = move |i: u64| {
                let k = i.checked_sub(offset)?;
                (k < 10_000).then(|| {
                    let u = (k as f32 - start as f32) / (dur * rate);
                    500.0 * s.shape.at(u)
                })
            };
            let peak = offset + start + (0.5 * dur * rate) as u64;
            judge(a, rate, &s, peak).unwrap()
        };
        let (early, late) = (at(0), at((1 << 31) + 12_345));
        assert!(early.pass && late.pass, "{early:?} {late:?}");
        assert_eq!(early.margin, late.margin);
        assert_eq!(early.delta_v_m_s, late.delta_v_m_s);
    }

    #[test]
    fn a_nominal_pulse_passes_and_its_delta_v_is_the_nominal_one() {
        for shape in [
            Shape::HalfSine,
            Shape::Sawtooth,
            Shape::Trapezoid {
                rise: 0.1,
                fall: 0.1,
            },
        ] {
            let v = judge_pulse(shape, 500.0, 0.011, None);
            assert!(v.pass, "{shape:?}: {v:?}");
            let want = spec(shape).delta_v_m_s();
            assert!(
                (v.delta_v_m_s / want - 1.0).abs() < 0.01,
                "{shape:?}: {v:?}"
            );
            assert!(
                (v.start_s * 50_000.0 - 2000.0).abs() < 10.0,
                "{shape:?}: {v:?}"
            );
        }
    }

    #[test]
    fn a_pulse_too_high_or_too_short_fails_by_its_margin() {
        // 30 % high: beyond the ±20 % band by 10 % of the peak.
        let v = judge_pulse(Shape::HalfSine, 650.0, 0.011, None);
        assert!(!v.band_pass, "{v:?}");
        assert!((v.margin - 0.1).abs() < 0.01, "{v:?}");
        // Half as long: its Δv is half the nominal one.
        let v = judge_pulse(Shape::HalfSine, 500.0, 0.0055, None);
        assert!(!v.pass && !v.delta_v_pass, "{v:?}");
        // A spike after the pulse beyond ±20 %: the band fails there.
        let v = judge_pulse(Shape::HalfSine, 500.0, 0.011, Some((2800, 150.0)));
        assert!(
            !v.band_pass && (v.worst_s * 50_000.0 - 2800.0).abs() < 1e-6,
            "{v:?}"
        );
        assert!((v.margin - 0.1).abs() < 0.01, "{v:?}");
    }

    /// `spec(shape)`'s band as a user's table: from `before` to `watch` around the pulse, and
    /// the standard band at `n` + 1 rows over it (a step where the nominal ends at its peak).
    fn tabulated(shape: Shape, n: usize) -> Spec {
        extern crate std;
        let s = spec(shape);
        let mut rows = std::vec![BandPoint {
            u: -0.4,
            lower: -0.2,
            upper: 0.2,
        }];
        for k in 0..=n {
            let u = k as f32 / n as f32;
            let (lower, upper) = s.band_at(u);
            rows.push(BandPoint { u, lower, upper });
        }
        rows.push(BandPoint {
            u: 1.0,
            lower: -0.2,
            upper: 0.2,
        });
        rows.push(BandPoint {
            u: 1.5,
            lower: -0.2,
            upper: 0.2,
        });
        let t = Spec {
            band: Some(rows.leak()),
            ..s
        };
        t.validate().unwrap();
        t
    }

    #[test]
    fn a_users_table_of_the_standard_band_judges_as_the_standard_band() {
        for shape in [Shape::HalfSine, Shape::Sawtooth] {
            let table = tabulated(shape, 60);
            for (peak, dur, glitch) in [
                (500.0, 0.011, None),
                (650.0, 0.011, None),
                (500.0, 0.0055, None),
                (500.0, 0.011, Some((2800, 150.0))),
                (560.0, 0.012, None),
            ] {
                let (a, b) = (
                    judge_pulse(shape, peak, dur, glitch),
                    judge_against(&table, peak, dur, glitch),
                );
                // The table is the band to within its chords' sag (sin over 1/60: 3.4e-4).
                assert_eq!((a.band_pass, a.delta_v_pass), (b.band_pass, b.delta_v_pass));
                assert!(
                    (a.margin - b.margin).abs() < 2e-3,
                    "{shape:?} {peak}: {a:?} {b:?}"
                );
            }
        }
    }

    #[test]
    fn a_users_narrow_band_fails_by_its_own_margin() {
        // The standard band, but at most 1.05 × the peak from 0.3 to 0.7 of the pulse: a
        // half-sine 10 % high fails there by 5 % (the standard band passes it).
        extern crate std;
        let s = spec(Shape::HalfSine);
        let rows = std::vec![
            BandPoint {
                u: -0.4,
                lower: -0.2,
                upper: 0.2
            },
            BandPoint {
                u: 0.0,
                lower: -0.2,
                upper: 0.2
            },
            BandPoint {
                u: 0.3,
                lower: 0.6,
                upper: 1.05
            },
            BandPoint {
                u: 0.7,
                lower: 0.6,
                upper: 1.05
            },
            BandPoint {
                u: 1.0,
                lower: -0.2,
                upper: 0.2
            },
            BandPoint {
                u: 1.5,
                lower: -0.2,
                upper: 0.2
            },
        ];
        let narrow = Spec {
            band: Some(rows.leak()),
            ..s
        };
        narrow.validate().unwrap();
        assert!(judge_pulse(Shape::HalfSine, 550.0, 0.011, None).band_pass);
        let v = judge_against(&narrow, 550.0, 0.011, None);
        assert!(!v.band_pass, "{v:?}");
        assert!((v.margin - 0.05).abs() < 2e-3, "{v:?}");
        assert!((v.limit_m_s2 - 525.0).abs() < 0.5, "{v:?}");
        // The nominal pulse passes it.
        assert!(judge_against(&narrow, 500.0, 0.011, None).pass);
    }

    #[test]
    fn a_users_band_reads_between_its_rows_and_its_steps() {
        extern crate std;
        let rows: &'static [BandPoint] = std::vec![
            BandPoint {
                u: 0.0,
                lower: 0.1,
                upper: 0.2
            },
            BandPoint {
                u: 0.5,
                lower: 0.4,
                upper: 0.7
            },
            BandPoint {
                u: 1.0,
                lower: 0.8,
                upper: 1.2
            },
            BandPoint {
                u: 1.0,
                lower: -0.2,
                upper: 0.2
            },
            BandPoint {
                u: 1.2,
                lower: -0.2,
                upper: 0.2
            },
        ]
        .leak();
        let s = Spec {
            shape: Shape::Sawtooth,
            band: Some(rows),
            ..spec(Shape::Sawtooth)
        };
        // The sawtooth starts at 0: below the first row's 0.1.
        assert!(s.validate().is_err());
        let t = Spec {
            tolerance: Tolerance {
                outside: 0.3,
                ..s.tolerance
            },
            band: Some(&rows[1..]),
            ..s
        };
        t.validate().unwrap();
        let (lo, hi) = t.band_at(0.75);
        assert!(
            (lo - 0.6).abs() < 1e-6 && (hi - 0.95).abs() < 1e-6,
            "{lo} {hi}"
        );
        assert_eq!(t.band_at(1.0), (-0.2, 1.2)); // the step: the looser limits
        assert_eq!(t.band_at(1.1), (-0.2, 0.2));
        assert_eq!(t.band_at(0.4), (-0.3, 0.3)); // before the table: `outside`
        assert_eq!(t.band_at(1.3), (-0.3, 0.3));
        let bad = |rows: std::vec::Vec<BandPoint>| {
            Spec {
                band: Some(rows.leak()),
                ..t
            }
            .validate()
            .is_err()
        };
        let p = |u, lower, upper| BandPoint { u, lower, upper };
        assert!(bad(std::vec![p(0.5, 0.0, 1.0)])); // one row
        assert!(bad(std::vec![p(0.6, 0.0, 1.0), p(0.5, 0.0, 1.0)])); // back in time
        assert!(bad(std::vec![p(0.5, 0.0, 1.0); 3])); // three rows at one time
        assert!(bad(std::vec![p(0.5, 1.0, 0.0), p(0.6, 0.0, 1.0)])); // lower above upper
        assert!(bad(std::vec![p(0.5, 0.0, f32::NAN), p(0.6, 0.0, 1.0)]));
        assert!(bad((0..65)
            .map(|k| p(k as f32 / 64.0, -1.0, 2.0))
            .collect()));
        assert!(!bad((0..64)
            .map(|k| p(k as f32 / 63.0, -1.0, 2.0))
            .collect()));
        // Times from -10 to 11 durations.
        assert!(!bad(std::vec![p(-10.0, -1.0, 1.0), p(11.0, -1.0, 1.0)]));
        assert!(bad(std::vec![p(-10.5, -1.0, 1.0), p(1.0, -1.0, 1.0)]));
        assert!(bad(std::vec![p(0.0, -1.0, 1.0), p(11.5, -1.0, 1.0)]));
        // The band is watched over its rows: the window widened to them, not beyond 10 D.
        let wide = Spec {
            band: Some(std::vec![p(-2.0, -1.0, 1.0), p(4.0, -1.0, 2.0)].leak()),
            ..t
        };
        assert_eq!(wide.watched(), (2.0, 3.0));
        assert_eq!(t.watched(), (0.4, 1.5));
        // A band the nominal pulse cannot pass between its rows or on one side of a step.
        let sine = |rows: std::vec::Vec<BandPoint>| Spec {
            shape: Shape::HalfSine,
            band: Some(rows.leak()),
            ..spec(Shape::HalfSine)
        };
        let flat = sine(std::vec![p(0.0, -0.2, 0.2), p(1.0, -0.2, 0.2)]);
        assert!(flat.band_misses_nominal().is_some() && flat.validate().is_err());
        let chord = sine(std::vec![
            p(0.0, -0.2, 0.2),
            p(0.5, 0.8, 1.1),
            p(1.0, -0.2, 0.2)
        ]);
        let u = chord.band_misses_nominal().unwrap().u; // the sine above the chord to 1.1
        assert!((0.0..0.5).contains(&u) || (0.5..1.0).contains(&u), "{u}");
        let step = sine(std::vec![
            p(0.0, -0.2, 0.2),
            p(0.5, 0.8, 1.2),
            p(0.5, -0.2, 0.2),
            p(1.0, -0.2, 0.2),
        ]);
        let miss = step.band_misses_nominal();
        assert_eq!(miss.map(|m| m.u), Some(0.5));
        assert_eq!(miss.and_then(|m| m.row), Some(2)); // the step's second row
        let fine = sine(std::vec![
            p(0.0, -0.2, 0.2),
            p(0.25, 0.5, 0.95),
            p(0.5, 0.8, 1.2),
            p(0.75, 0.5, 0.95),
            p(1.0, -0.2, 0.2),
        ]);
        assert_eq!(fine.band_misses_nominal(), None);
        fine.validate().unwrap();
    }

    #[test]
    fn a_users_band_at_its_ends_and_over_spans() {
        extern crate std;
        let p = |u, lower, upper| BandPoint { u, lower, upper };
        let rows: &'static [BandPoint] = std::vec![
            p(0.0, -0.5, 0.5),
            p(0.0, -0.3, 0.3),
            p(0.5, 0.0, 2.0),
            p(1.0, -0.3, 0.3),
            p(1.0, -0.1, 0.1),
        ]
        .leak();
        let s = Spec {
            shape: Shape::Sawtooth,
            band: Some(rows),
            ..spec(Shape::Sawtooth)
        };
        // Steps at both ends: the looser rows' limits at the instant; `outside` (0.2) beyond.
        assert_eq!(s.band_at(0.0), (-0.5, 0.5));
        assert_eq!(s.band_at(1.0), (-0.3, 0.3));
        assert_eq!(s.band_at(-0.01), (-0.2, 0.2));
        assert_eq!(s.band_at(1.01), (-0.2, 0.2));
        // On an interior row, and an ulp or two off an end row, the row.
        assert_eq!(s.band_at(0.5), (0.0, 2.0));
        assert_eq!(s.band_at(1.0 + 2e-7), (-0.3, 0.3));
        assert_eq!(s.band_at(-1e-7), (-0.5, 0.5));
        // Over a span: the loosest of its ends and of the rows inside it.
        let at = |u| s.shape.at(u);
        let (lo, hi) = super::band_over(&s, at, 0.4, 0.6);
        assert!((lo + 0.06).abs() < 1e-6 && hi == 2.0, "{lo} {hi}"); // 0.4's lower, the row's upper
        let (lo, hi) = super::band_over(&s, at, -0.1, 0.1);
        assert!(lo == -0.5 && (hi - 0.64).abs() < 1e-5, "{lo} {hi}"); // the step's, 0.1's
        let (lo, hi) = super::band_over(&s, at, 0.9, 1.5);
        assert!(lo == -0.3 && (hi - 0.64).abs() < 1e-5, "{lo} {hi}"); // the step's, 0.9's
    }

    /// A user's band that reaches further back than `before` widens the band's window, not
    /// the velocity change's: a slow pre-pulse dip before −0.4 D leaves Δv as it is.
    #[test]
    fn a_wide_users_band_leaves_the_delta_v_window_alone() {
        extern crate std;
        let shape = Shape::HalfSine;
        let s = spec(shape);
        let p = |u, lower, upper| BandPoint { u, lower, upper };
        let wide = Spec {
            band: Some(
                std::vec![
                    p(-2.0, -0.2, 0.2),
                    p(0.0, -0.2, 0.2),
                    p(0.25, 0.5, 0.95),
                    p(0.5, 0.8, 1.2),
                    p(0.75, 0.5, 0.95),
                    p(1.0, -0.2, 0.2),
                    p(1.5, -0.2, 0.2),
                ]
                .leak(),
            ),
            ..s
        };
        wide.validate().unwrap();
        let rate = 50_000.0f32;
        let d = 0.011 * rate;
        let a = |i: u64| {
            let u = (i as f32 - 3000.0) / d;
            let dip = if (-1.5..-0.5).contains(&u) {
                -60.0
            } else {
                0.0
            };
            (i < 12_000).then_some(500.0 * shape.at(u) + dip)
        };
        let peak = (3000.0 + 0.5 * d) as u64;
        let (narrow, wide) = (
            judge(a, rate, &s, peak).unwrap(),
            judge(a, rate, &wide, peak).unwrap(),
        );
        assert!(
            (wide.delta_v_m_s / narrow.delta_v_m_s - 1.0).abs() < 1e-3,
            "{narrow:?} {wide:?}"
        );
        assert!(wide.delta_v_pass && wide.band_pass, "{wide:?}");
    }
}
