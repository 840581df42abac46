//! Where a pulse is drawn and what is drawn around it: the window the verdict watched (else a
//! quarter of the duration either side), and the specification's band and nominal pulse
//! placed where the verdict put them (the report's figures and the live view's).

use impact_core::spec::Spec;

/// A point of a tolerance band: `(t_s, lower, upper, nominal)`, the last three in m/s².
pub type BandPoint = (f64, f64, f64, f64);

/// `spec`'s tolerance band and nominal pulse placed at `start_s`, at 201 times over
/// `[from_s, to_s]` (s from the stream's start); a user's band also at each of its rows, with
/// the row's own limits (a step's two rows one after the other, and `outside` on the far side
/// of its first and last rows), so that its corners and steps are drawn as judged.
pub fn band(spec: &Spec, start_s: f64, from_s: f64, to_s: f64) -> Vec<BandPoint> {
    let peak = f64::from(spec.peak_m_s2);
    let duration = f64::from(spec.duration_s);
    let u_at = |t: f64| ((t - start_s) / duration) as f32;
    let point = |t: f64, (lo, hi): (f32, f32)| {
        (
            t,
            f64::from(lo) * peak,
            f64::from(hi) * peak,
            f64::from(spec.shape.at(u_at(t))) * peak,
        )
    };
    let grid = (0..=200).map(|k| from_s + (to_s - from_s) * f64::from(k) / 200.0);
    let Some(rows) = spec.band else {
        return grid.map(|t| point(t, spec.band_at(u_at(t)))).collect();
    };
    let outside = (-spec.tolerance.outside, spec.tolerance.outside);
    let row_t = |u: f32| start_s + f64::from(u) * duration;
    let mut points: Vec<BandPoint> = grid
        .filter(|&t| rows.iter().all(|r| row_t(r.u) != t))
        .map(|t| point(t, spec.band_at(u_at(t))))
        .collect();
    for (k, r) in rows.iter().enumerate() {
        let t = row_t(r.u);
        if !(from_s..=to_s).contains(&t) {
            continue;
        }
        if k == 0 {
            points.push(point(t, outside));
        }
        points.push(point(t, (r.lower, r.upper)));
        if k + 1 == rows.len() {
            points.push(point(t, outside));
        }
    }
    // In time; at one time, in the order pushed (the grid's first, then the rows').
    points.sort_by(|a, b| a.0.total_cmp(&b.0));
    points
}

/// Where impact `r`'s pulse is drawn, s from the stream's start: with a verdict against
/// `spec`, over the window it watched, with where it placed the nominal pulse; else from a
/// quarter of its duration before first touch to a quarter after.
pub fn window<'a>(
    spec: Option<&'a Spec>,
    r: &impact_core::ImpactReport,
) -> (f64, f64, Option<(&'a Spec, f64)>) {
    match (spec, &r.verdict) {
        (Some(spec), Some(Ok(v))) => {
            let d = f64::from(spec.duration_s);
            let (before, watch) = spec.watched();
            (
                v.start_s - f64::from(before) * d,
                v.start_s + f64::from(1.0 + watch) * d,
                Some((spec, v.start_s)),
            )
        }
        _ => {
            let d = f64::from(r.duration_s);
            (r.start_s - 0.25 * d, r.start_s + 1.25 * d, None)
        }
    }
}
