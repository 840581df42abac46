//! Where a panel's legend goes: the corner its curves leave emptiest, or (a specified pulse's
//! panel, whose band spans every corner) the upper right with the range raised to clear it.

use plotters::prelude::SeriesLabelPosition;

use super::Panel;

/// The top of linear panel `p`'s range (its axes' `ranges`, `size` in px) that leaves room
/// for a legend of `entries` lines in the upper right corner above its curves and band.
pub(super) fn above_legend(
    p: &Panel,
    (x0, x1, y0, y1): (f64, f64, f64, f64),
    (width, height): (f64, f64),
    entries: usize,
) -> f64 {
    // The legend's box: some 160 px wide, 16 px a line, as a share of the plot area.
    let (w, h) = (
        (160.0 / width).min(0.9),
        ((16.0 * entries as f64 + 14.0) / height).min(0.8),
    );
    let from = x1 - w * (x1 - x0);
    let top = (p.measured.iter())
        .chain(p.models.iter().chain(&p.dashed).flat_map(|c| c.2.iter()))
        .copied()
        .chain(
            p.spec
                .iter()
                .flat_map(|s| s.band.iter().map(|b| (b.0, b.2))),
        )
        .filter(|q| q.0 >= from && q.1.is_finite())
        .fold(f64::NEG_INFINITY, |m, q| m.max(q.1));
    // (top - h y0) / (1 - h): the top at h below the range's.
    if top.is_finite() {
        y1.max((top - h * y0) / (1.0 - h))
    } else {
        y1
    }
}

/// The corner of `p`'s plot area (its axes' `ranges`, `size` in px) where a legend of
/// `entries` lines covers the fewest points of its curves: upper right unless another corner
/// is emptier.
pub(super) fn legend_corner(
    p: &Panel,
    (x0, x1, y0, y1): (f64, f64, f64, f64),
    (width, height): (f64, f64),
    entries: usize,
) -> SeriesLabelPosition {
    // Where a value lies across an axis, 0 to 1.
    let unit = |v: f64, lo: f64, hi: f64| {
        if p.log {
            (v / lo).ln() / (hi / lo).ln()
        } else {
            (v - lo) / (hi - lo)
        }
    };
    // The legend's box: some 150 px wide, 19 px a line, as a share of the plot area.
    let (w, h) = (
        (150.0 / width).min(0.9),
        ((19.0 * entries as f64 + 12.0) / height).min(0.9),
    );
    let corners = [
        (
            SeriesLabelPosition::UpperRight,
            1.0 - w..=1.0,
            1.0 - h..=1.0,
        ),
        (SeriesLabelPosition::LowerRight, 1.0 - w..=1.0, 0.0..=h),
        (SeriesLabelPosition::UpperLeft, 0.0..=w, 1.0 - h..=1.0),
        (SeriesLabelPosition::LowerLeft, 0.0..=w, 0.0..=h),
    ];
    // Every curve's points across the plot area; a curve of few points (a required SRS's
    // breakpoints) 16 to each straight piece, so that one crossing a corner is seen there.
    let mut points: Vec<(f64, f64)> = Vec::new();
    let spec: Vec<(f64, f64)> = (p.spec.iter())
        .flat_map(|s| s.band.iter().flat_map(|b| [(b.0, b.1), (b.0, b.2)]))
        .collect();
    for curve in std::iter::once(&p.measured)
        .chain(p.models.iter().chain(&p.dashed).map(|c| &c.2))
        .chain(std::iter::once(&spec))
    {
        let across: Vec<(f64, f64)> = curve
            .iter()
            .map(|q| (unit(q.0, x0, x1), unit(q.1, y0, y1)))
            .filter(|q| q.0.is_finite() && q.1.is_finite())
            .collect();
        if across.len() < 200 {
            for w in across.windows(2) {
                points.extend((0..16).map(|k| {
                    let t = f64::from(k) / 16.0;
                    (
                        w[0].0 + t * (w[1].0 - w[0].0),
                        w[0].1 + t * (w[1].1 - w[0].1),
                    )
                }));
            }
            points.extend(across.last());
        } else {
            points.extend(across);
        }
    }
    let covered = |xs: &std::ops::RangeInclusive<f64>, ys: &std::ops::RangeInclusive<f64>| {
        points
            .iter()
            .filter(|q| xs.contains(&q.0) && ys.contains(&q.1))
            .count()
    };
    corners
        .into_iter()
        .min_by_key(|(_, xs, ys)| covered(xs, ys))
        .map_or(SeriesLabelPosition::UpperRight, |c| c.0)
}
