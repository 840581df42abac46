//! The figures' primitives: the output checked and written, panels of curves drawn with
//! plotters; the impacts figure ([`impacts`]) and the tick labels ([`ticks`]).

mod impacts;
pub(crate) mod ticks;

pub use impacts::{impacts, window, Signal, SHOWN};
use ticks::tick;

use plotters::prelude::*;

/// Checks that `path` can take an SVG before any work is done: its directory exists and it is
/// none of the `inputs` (the same file, a link to one, standard input's file: the output rule
/// of [`crate::output`]), and it is named `.svg`.
pub fn check_output(path: &std::path::Path, inputs: &[&std::path::Path]) -> Result<(), String> {
    let all = inputs
        .iter()
        .fold(crate::output::Inputs::new(), |all, i| all.with(i));
    crate::output::check("--plot", path, &all, None)?;
    let svg = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("svg"));
    if !svg {
        return Err(format!(
            "--plot {}: the figure is SVG: name the file .svg (rsvg-convert FILE.svg -o FILE.png makes a PNG of it)",
            path.display()
        ));
    }
    Ok(())
}

/// Draws a `size` SVG with `draw` and writes it to `path` whole or not at all
/// ([`crate::output::write`]).
pub(crate) fn write_svg(
    path: &std::path::Path,
    size: (u32, u32),
    draw: impl FnOnce(&DrawingArea<SVGBackend, plotters::coord::Shift>) -> Result<(), String>,
) -> Result<(), String> {
    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, size).into_drawing_area();
        draw(&root)?;
        root.present().map_err(|e| e.to_string())?;
    }
    crate::output::write(path, text.as_bytes())
}

/// A named, coloured series of (time, value) points.
pub(crate) type Curve = (&'static str, RGBColor, Vec<(f64, f64)>);

/// The measured curve: broad and light, so that fits drawn over it stay visible.
pub(crate) const MEASURED: RGBColor = RGBColor(120, 170, 250);

/// One panel: its title, axis labels, the measured series and each model's, whether both
/// axes are logarithmic, and whether it carries the legend (the first of a row: the colours
/// are the same in every panel).
pub(crate) struct Panel<'a> {
    pub(crate) title: &'a str,
    pub(crate) x_label: &'a str,
    pub(crate) measured: Vec<(f64, f64)>,
    pub(crate) measured_label: &'a str,
    pub(crate) models: Vec<Curve>,
    pub(crate) log: bool,
    pub(crate) legend: bool,
}

/// A panel's width in pixel columns, at most (its curves are drawn at most twice this many
/// points each).
const COLUMNS: usize = 400;

/// `points` as at most about `2 columns` points: where there are more and x only grows (a
/// curve against time), the least and the greatest y of each of `columns` equal spans of x,
/// in their order (what a pixel column shows: a window of a million samples draws as it
/// looks, in a file of a few kB); a curve that turns back in x (a force–deformation loop)
/// keeps every n-th point, its last one included.
pub(crate) fn decimate(points: &[(f64, f64)], columns: usize) -> Vec<(f64, f64)> {
    if points.len() <= 2 * columns || columns == 0 {
        return points.to_vec();
    }
    if points.windows(2).any(|w| w[1].0 < w[0].0) {
        let every = points.len().div_ceil(2 * columns);
        let mut out: Vec<(f64, f64)> = points.iter().copied().step_by(every).collect();
        if (points.len() - 1) % every != 0 {
            out.push(points[points.len() - 1]);
        }
        return out;
    }
    let (first, last) = (points[0].0, points[points.len() - 1].0);
    let span = (last - first) / columns as f64;
    if !(span.is_finite() && span > 0.0) {
        return points.to_vec();
    }
    let column = |x: f64| (((x - first) / span) as usize).min(columns - 1);
    let mut out = Vec::with_capacity(2 * columns + 2);
    let mut k = 0;
    while k < points.len() {
        let c = column(points[k].0);
        let (mut lo, mut hi) = (k, k);
        let mut j = k;
        while j < points.len() && column(points[j].0) == c {
            if points[j].1 < points[lo].1 {
                lo = j;
            }
            if points[j].1 > points[hi].1 {
                hi = j;
            }
            j += 1;
        }
        let (a, b) = (lo.min(hi), lo.max(hi));
        out.push(points[a]);
        if b != a {
            out.push(points[b]);
        }
        k = j.max(k + 1);
    }
    out
}

/// Draws one panel on `area`.
pub(crate) fn draw_panel(
    area: &DrawingArea<SVGBackend, plotters::coord::Shift>,
    index: Option<u32>,
    p: &Panel,
) -> Result<(), String> {
    let finite =
        |q: &(f64, f64)| q.0.is_finite() && q.1.is_finite() && (!p.log || (q.0 > 0.0 && q.1 > 0.0));
    let all = p
        .measured
        .iter()
        .chain(p.models.iter().flat_map(|c| c.2.iter()))
        .filter(|q| finite(q));
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for q in all {
        (x0, x1, y0, y1) = (x0.min(q.0), x1.max(q.0), y0.min(q.1), y1.max(q.1));
    }
    if x0 > x1 {
        (x0, x1, y0, y1) = (0.0, 1.0, 0.0, 1.0);
    }
    let caption = match index {
        Some(i) => format!("impact {i} — {}", p.title),
        None => p.title.to_string(),
    };
    let mut builder = ChartBuilder::on(area);
    builder
        .caption(caption, ("sans-serif", 15))
        .margin(8)
        .x_label_area_size(30)
        .y_label_area_size(60);
    macro_rules! finish {
        ($chart:expr) => {{
            let mut chart = $chart;
            chart
                .configure_mesh()
                .x_desc(p.x_label)
                .x_label_formatter(&|v| tick(*v))
                .y_label_formatter(&|v| tick(*v))
                .draw()
                .map_err(|e| e.to_string())?;
            if !p.measured.is_empty() {
                chart
                    .draw_series(LineSeries::new(
                        decimate(&p.measured, COLUMNS)
                            .into_iter()
                            .filter(|q| finite(q)),
                        MEASURED.stroke_width(4),
                    ))
                    .map_err(|e| e.to_string())?
                    .label(p.measured_label)
                    .legend(|(x, y)| {
                        PathElement::new(vec![(x, y), (x + 18, y)], MEASURED.stroke_width(4))
                    });
            }
            for (name, color, s) in &p.models {
                let c = *color;
                chart
                    .draw_series(LineSeries::new(
                        decimate(s, COLUMNS).into_iter().filter(|q| finite(q)),
                        c.stroke_width(2),
                    ))
                    .map_err(|e| e.to_string())?
                    .label(*name)
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 18, y)], c.stroke_width(2))
                    });
            }
            if p.legend {
                chart
                    .configure_series_labels()
                    .position(SeriesLabelPosition::UpperRight)
                    .background_style(WHITE.mix(0.85))
                    .border_style(BLACK)
                    .draw()
                    .map_err(|e| e.to_string())?;
            }
        }};
    }
    if p.log {
        finish!(builder
            .build_cartesian_2d(
                (x0..x1.max(x0 * 1.01)).log_scale(),
                (y0 * 0.8..(y1 * 1.25).max(y0 * 1.01)).log_scale()
            )
            .map_err(|e| e.to_string())?);
    } else {
        let pad = (y1 - y0).abs().max(1e-12) * 0.08;
        finish!(builder
            .build_cartesian_2d(x0..x1.max(x0 + 1e-9), (y0 - pad)..(y1 + pad))
            .map_err(|e| e.to_string())?);
    }
    Ok(())
}
