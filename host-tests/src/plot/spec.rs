//! A specified pulse on a panel against time: its tolerance band and nominal pulse where the
//! verdict placed them, the window the verdict watched and its worst point; what an impact's
//! verdict puts there ([`SpecDrawn::of`]).

use impact_core::spec::Spec;
use plotters::coord::ranged1d::Ranged;
use plotters::prelude::*;

use super::{band, PlotError};

/// A specified pulse drawn on a panel against time, in the panel's units: its tolerance band
/// and nominal pulse where the verdict placed them ([`band::band`]), the window the verdict
/// watched ([`band::window`]) and its worst point.
pub(crate) struct SpecDrawn {
    /// `(t, lower, upper, nominal)`.
    pub(crate) band: Vec<band::BandPoint>,
    /// The window the verdict watched, `(from, to)`.
    pub(crate) watched: (f64, f64),
    /// The verdict's worst point `(t, value)` and whether it lies beyond the band.
    pub(crate) worst: Option<(f64, f64, bool)>,
}

/// The band's colour, and the nominal pulse's (green: apart from the measured blue).
const BAND: RGBColor = RGBColor(46, 139, 87);
const NOMINAL: RGBColor = RGBColor(20, 90, 50);

/// The watched window's shade and edges.
const WATCHED: RGBColor = RGBColor(120, 120, 120);

/// The worst point's colours: beyond the band, within it (the report's and the live view's).
const FAILS: RGBColor = RGBColor(214, 39, 40);
const WITHIN: RGBColor = RGBColor(227, 168, 43);

impl SpecDrawn {
    /// With a verdict against `spec`, what impact `r`'s deceleration panel draws of it
    /// (placed as the verdict placed it: [`band::window`], [`band::band`]): the band and the
    /// nominal pulse, the window it watched and its worst point, in ms from the touch and in
    /// the direction of the peak, times `scale` (m/s² to the panel's unit).
    pub(crate) fn of(
        spec: Option<&Spec>,
        r: &impact_core::ImpactReport,
        scale: f64,
    ) -> Option<Self> {
        let (from_s, to_s, placed) = band::window(spec, r);
        let (spec, start_s) = placed?;
        let Some(Ok(v)) = &r.verdict else {
            return None;
        };
        let k = scale
            * if r.peak_acceleration_m_s2 < 0.0 {
                -1.0
            } else {
                1.0
            };
        let ms = |t: f64| (t - r.start_s) * 1e3;
        let band = band::band(spec, start_s, from_s, to_s)
            .into_iter()
            .map(|(t, lo, hi, nominal)| {
                (
                    ms(t),
                    (lo * k).min(hi * k),
                    (lo * k).max(hi * k),
                    nominal * k,
                )
            })
            .collect();
        let worst = (ms(v.worst_s), f64::from(v.worst_m_s2) * k, !v.band_pass);
        Some(SpecDrawn {
            band,
            watched: (ms(from_s), ms(to_s)),
            worst: (worst.0.is_finite() && worst.1.is_finite()).then_some(worst),
        })
    }

    /// Its points: the band's limits and the nominal pulse, the watched window's edges at
    /// `y`, the worst point.
    pub(super) fn points(&self, y: f64) -> impl Iterator<Item = (f64, f64)> + '_ {
        self.band
            .iter()
            .flat_map(|b| [(b.0, b.1), (b.0, b.2), (b.0, b.3)])
            .chain([(self.watched.0, y), (self.watched.1, y)])
            .chain(self.worst.map(|w| (w.0, w.1)))
    }

    /// Its legend's lines: the window, the band, the nominal pulse, the worst point.
    pub(super) fn entries(&self) -> usize {
        1 + 2 * usize::from(!self.band.is_empty()) + usize::from(self.worst.is_some())
    }
}

/// Draws `s` under a panel's curves on `chart` (from `y0` to `y1`): the window the verdict
/// watched, shaded between its edges, and the tolerance band, shaded between its limits.
pub(super) fn draw_spec_under<X, Y>(
    chart: &mut ChartContext<'_, SVGBackend<'_>, Cartesian2d<X, Y>>,
    s: &SpecDrawn,
    (y0, y1): (f64, f64),
) -> Result<(), PlotError>
where
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    let (w0, w1) = s.watched;
    chart
        .draw_series(std::iter::once(Rectangle::new(
            [(w0, y0), (w1, y1)],
            WATCHED.mix(0.1).filled(),
        )))?
        .label("watched window")
        .legend(|(x, y)| {
            Rectangle::new(
                [(x, y - 5), (x + 18, y + 5)],
                ShapeStyle::from(WATCHED.mix(0.25)).filled(),
            )
        });
    chart.draw_series(
        [w0, w1].map(|t| PathElement::new(vec![(t, y0), (t, y1)], WATCHED.stroke_width(1))),
    )?;
    if s.band.is_empty() {
        return Ok(());
    }
    let outline: Vec<(f64, f64)> = (s.band.iter().map(|b| (b.0, b.2)))
        .chain(s.band.iter().rev().map(|b| (b.0, b.1)))
        .collect();
    chart
        .draw_series(std::iter::once(Polygon::new(
            outline,
            BAND.mix(0.18).filled(),
        )))?
        .label("tolerance band")
        .legend(|(x, y)| {
            Rectangle::new(
                [(x, y - 5), (x + 18, y + 5)],
                ShapeStyle::from(BAND.mix(0.35)).filled(),
            )
        });
    for limit in [
        |b: &band::BandPoint| (b.0, b.1),
        |b: &band::BandPoint| (b.0, b.2),
    ] {
        chart.draw_series(LineSeries::new(
            s.band.iter().map(limit),
            BAND.mix(0.7).stroke_width(1),
        ))?;
    }
    Ok(())
}

/// Draws `s` over a panel's curves on `chart`: the nominal pulse dashed, the worst point
/// circled (red beyond the band, amber within it).
pub(super) fn draw_spec_over<X, Y>(
    chart: &mut ChartContext<'_, SVGBackend<'_>, Cartesian2d<X, Y>>,
    s: &SpecDrawn,
) -> Result<(), PlotError>
where
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    if !s.band.is_empty() {
        chart
            .draw_series(DashedLineSeries::new(
                s.band.iter().map(|b| (b.0, b.3)),
                6,
                4,
                NOMINAL.stroke_width(2),
            ))?
            .label("nominal pulse")
            .legend(|(x, y)| {
                plotters::element::DashedPathElement::new(
                    vec![(x, y), (x + 18, y)],
                    5,
                    3,
                    NOMINAL.stroke_width(2),
                )
            });
    }
    if let Some((t, v, beyond)) = s.worst {
        let c = if beyond { FAILS } else { WITHIN };
        chart
            .draw_series(std::iter::once(Circle::new((t, v), 6, c.stroke_width(2))))?
            .label(if beyond {
                "worst point: fails"
            } else {
                "worst point: within"
            })
            .legend(move |(x, y)| Circle::new((x + 9, y), 4, c.stroke_width(2)));
    }
    Ok(())
}
