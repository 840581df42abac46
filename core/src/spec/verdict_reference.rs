//! The verdict's search as it was before it skipped the band's flat stretches (#44): kept
//! for the tests only, which hold the search to give the same verdicts bit for bit (on windows
//! of numbers: the search refuses a NaN or an infinity, which this one passed over).

use super::verdict::{Missing, Verdict, BUCKETS};
use super::{band_over, Nominal, Spec};

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
/// (`base`), the half-sine tabulated, compensated f32 sums for the velocity change.
pub fn judge_reference(
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
    let mut table = [0.0f32; Nominal::LEN];
    let nominal = Nominal::fill(spec.shape, &mut table);
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
