//! The figures' primitives: the output checked and written (SVG, or PNG: [`png`]), panels of
//! curves drawn with plotters; the impacts figure ([`mod@impacts`]), what it draws from
//! ([`signal`]), where a pulse is drawn and a specification's band placed ([`band`]), a
//! specified pulse on a panel ([`spec`]), where a legend goes ([`legend`]) and the tick
//! labels, one format per axis ([`ticks`]).

pub mod band;
mod impacts;
mod legend;
mod png;
mod signal;
mod spec;
pub(crate) mod ticks;

pub use impacts::{impacts, SHOWN};
use legend::{above_legend, legend_corner};
pub use signal::{filtered, read_window, window, Signal};
pub(crate) use spec::SpecDrawn;
use spec::{draw_spec_over, draw_spec_under};
use ticks::{log_ticks, AxisFormat, LABELS};

use impact_core::consts::STANDARD_GRAVITY;
use plotters::prelude::*;

/// Why a figure was not drawn or written.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// The output refused ([`crate::output::check`]) or its write failed.
    #[error(transparent)]
    Output(#[from] crate::output::OutputError),
    /// `--plot` named neither `.svg` nor `.png`, found before any work.
    #[error("--plot {}: the figure is SVG or PNG: name the file .svg or .png", .path.display())]
    Format { path: std::path::PathBuf },
    /// A figure to write to a file named neither `.svg` nor `.png`.
    #[error("--plot {}: name the figure .svg or .png", .path.display())]
    Name { path: std::path::PathBuf },
    /// plotters' drawing on the SVG backend (whose errors are `std::io::Error`s).
    #[error(transparent)]
    Draw(#[from] DrawingAreaErrorKind<std::io::Error>),
    /// The SVG not parsed for the PNG.
    #[error("the figure: {0}")]
    Svg(#[from] resvg::usvg::Error),
    #[error("the figure: {width} × {height} px is too large for a PNG")]
    TooLarge { width: u32, height: u32 },
    /// The PNG not encoded: tiny-skia's `png::EncodingError` (the `png` crate, which this
    /// crate does not depend on to name it), boxed.
    #[error("the figure: {0}")]
    Png(#[source] Box<dyn std::error::Error + Send + Sync>),
}

/// The figures' formats, by the file's extension.
const FORMATS: [&str; 2] = ["svg", "png"];

/// Checks that `path` can take a figure before any work is done: its directory exists and it
/// is none of the `inputs` (the same file, a link to one, standard input's file: the output
/// rule of [`crate::output`]), and it is named `.svg` or `.png` (the format).
pub fn check_output<P: AsRef<std::path::Path>>(
    path: &std::path::Path,
    inputs: &[P],
) -> Result<(), PlotError> {
    let all = inputs
        .iter()
        .fold(crate::output::Inputs::new(), |all, i| all.with(i.as_ref()));
    crate::output::check("--plot", path, &all, None)?;
    if format(path).is_none() {
        return Err(PlotError::Format {
            path: path.to_path_buf(),
        });
    }
    Ok(())
}

/// The figure's format for `path` (`svg` or `png`, whatever the case of its extension).
fn format(path: &std::path::Path) -> Option<&'static str> {
    let ext = path.extension()?.to_str()?;
    FORMATS.into_iter().find(|f| ext.eq_ignore_ascii_case(f))
}

/// Draws a `size` SVG with `draw` and writes it to `path` ([`write_figure`]).
pub(crate) fn write_svg(
    path: &std::path::Path,
    size: (u32, u32),
    draw: impl FnOnce(&DrawingArea<SVGBackend, plotters::coord::Shift>) -> Result<(), PlotError>,
) -> Result<(), PlotError> {
    write_figure(path, &svg_text(size, draw)?)
}

/// Writes the figure `svg` to `path` whole or not at all ([`crate::output::write`]): as it is
/// to a `.svg`, rasterised ([`png::from_svg`]) to a `.png`.
pub(crate) fn write_figure(path: &std::path::Path, svg: &str) -> Result<(), PlotError> {
    match format(path) {
        Some("png") => Ok(crate::output::write(path, &png::from_svg(svg)?)?),
        Some(_) => Ok(crate::output::write(path, svg.as_bytes())?),
        None => Err(PlotError::Name {
            path: path.to_path_buf(),
        }),
    }
}

/// A `size` SVG drawn with `draw`, as text.
pub(crate) fn svg_text(
    size: (u32, u32),
    draw: impl FnOnce(&DrawingArea<SVGBackend, plotters::coord::Shift>) -> Result<(), PlotError>,
) -> Result<String, PlotError> {
    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, size).into_drawing_area();
        draw(&root)?;
        root.present()?;
    }
    Ok(text)
}

/// A `size` SVG drawn with `draw`, as markup for a page (plotters escapes its text).
pub(crate) fn svg_html(
    size: (u32, u32),
    draw: impl FnOnce(&DrawingArea<SVGBackend, plotters::coord::Shift>) -> Result<(), PlotError>,
) -> Result<crate::html::Html, PlotError> {
    svg_text(size, draw).map(crate::html::Html::from_plotters)
}

/// A named, coloured series of (time, value) points.
pub(crate) type Curve = (&'static str, RGBColor, Vec<(f64, f64)>);

/// The measured curve: broad and light, so that fits drawn over it stay visible.
pub(crate) const MEASURED: RGBColor = RGBColor(120, 170, 250);

/// One panel: its title, axis labels, the measured series and each model's, whether both
/// axes are logarithmic, whether its values (m/s²) get a second axis in g on the right, and
/// whether it carries the legend (the first of a row: the colours are the same in every
/// panel).
pub(crate) struct Panel<'a> {
    pub(crate) title: std::borrow::Cow<'a, str>,
    pub(crate) x_label: &'a str,
    pub(crate) measured: Vec<(f64, f64)>,
    pub(crate) measured_label: &'a str,
    pub(crate) models: Vec<Curve>,
    /// Curves drawn dashed, thin (a tolerance's limits).
    pub(crate) dashed: Vec<Curve>,
    pub(crate) log: bool,
    /// The values are m/s²: the same range in g on a second axis on the right.
    pub(crate) g_axis: bool,
    pub(crate) legend: bool,
    /// A specified pulse against time: its band, the window its verdict watched, its worst
    /// point.
    pub(crate) spec: Option<SpecDrawn>,
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
) -> Result<(), PlotError> {
    let finite =
        |q: &(f64, f64)| q.0.is_finite() && q.1.is_finite() && (!p.log || (q.0 > 0.0 && q.1 > 0.0));
    let first_y = p.measured.first().map_or(0.0, |q| q.1);
    let all = p
        .measured
        .iter()
        .copied()
        .chain(
            p.models
                .iter()
                .chain(&p.dashed)
                .flat_map(|c| c.2.iter().copied()),
        )
        .chain(p.spec.iter().flat_map(|s| s.points(first_y)))
        .filter(|q| finite(q));
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for q in all {
        (x0, x1, y0, y1) = (x0.min(q.0), x1.max(q.0), y0.min(q.1), y1.max(q.1));
    }
    if x0 > x1 {
        (x0, x1, y0, y1) = (0.0, 1.0, 0.0, 1.0);
    }
    // The axes' ranges: a log axis a little beyond the curves, a linear one padded by 8 %.
    let (x1, y0, y1) = if p.log {
        (x1.max(x0 * 1.01), y0 * 0.8, (y1 * 1.25).max(y0 * 1.01))
    } else {
        let pad = (y1 - y0).abs().max(1e-12) * 0.08;
        (x1.max(x0 + 1e-9), y0 - pad, y1 + pad)
    };
    let (w, h) = area.dim_in_pixel();
    // The plot area's size: the area less its margins, caption and label areas.
    let width = f64::from(w) - 76.0 - if p.g_axis { 60.0 } else { 0.0 };
    let height = f64::from(h) - 71.0;
    let entries = usize::from(!p.measured.is_empty())
        + p.models.len()
        + p.dashed.len()
        + p.spec.as_ref().map_or(0, SpecDrawn::entries);
    // A specified pulse's panel: its legend upper right, the range raised until the curves
    // pass below it (its band spans every corner: the report's pulses do the same).
    let (y1, corner) = match &p.spec {
        Some(_) if p.legend && !p.log => (
            above_legend(p, (x0, x1, y0, y1), (width, height), entries),
            SeriesLabelPosition::UpperRight,
        ),
        _ => (
            y1,
            legend_corner(p, (x0, x1, y0, y1), (width, height), entries),
        ),
    };
    let caption = match index {
        Some(i) => format!("impact {i} — {}", p.title),
        None => p.title.to_string(),
    };
    let g = STANDARD_GRAVITY;
    // A log axis's decades numbered, never crowding (ticks::log_ticks): labels 40 px apart
    // across (`100k` is some 25 px wide), 16 px up (a line).
    let (x_ticks, y_ticks, g_ticks) = if p.log {
        (
            log_ticks(x0, x1, width, 40.0),
            log_ticks(y0, y1, height, 16.0),
            log_ticks(y0 / g, y1 / g, height, 16.0),
        )
    } else {
        Default::default()
    };
    // Each axis's labels in one format, chosen from all of them (ticks::AxisFormat).
    let (fx, fy, fg) = if p.log {
        (
            AxisFormat::log(&x_ticks.0),
            AxisFormat::log(&y_ticks.0),
            AxisFormat::log(&g_ticks.0),
        )
    } else {
        (
            AxisFormat::linear(x0, x1),
            AxisFormat::linear(y0, y1),
            AxisFormat::linear(y0 / g, y1 / g),
        )
    };
    // The caption within the panel: a long one (an impact whose Δv was refused says why) in
    // a smaller type. DejaVu Sans sets some 0.55 em a character, and the SVG backend draws a
    // size at about 0.8 of its pixels.
    let chars = caption.chars().count().max(1) as f64;
    let size = (f64::from(w) / (0.55 * 0.8 * chars)).clamp(9.0, 15.0);
    let mut builder = ChartBuilder::on(area);
    builder
        .caption(caption, ("sans-serif", size))
        .margin(8)
        .x_label_area_size(30)
        .y_label_area_size(60)
        .right_y_label_area_size(if p.g_axis { 60 } else { 0 });
    // The measured curve and each model's on `chart`, the mesh, the legend.
    macro_rules! curves {
        ($chart:ident) => {{
            let (x_format, y_format) = (|v: &f64| fx.label(*v), |v: &f64| fy.label(*v));
            let mut mesh = $chart.configure_mesh();
            mesh.x_desc(p.x_label)
                .x_labels(LABELS)
                .y_labels(LABELS)
                .x_label_formatter(&x_format)
                .y_label_formatter(&y_format);
            if p.g_axis {
                mesh.y_desc("m/s²");
            }
            mesh.draw()?;
            if let Some(s) = &p.spec {
                draw_spec_under(&mut $chart, s, (y0, y1))?;
            }
            if !p.measured.is_empty() {
                $chart
                    .draw_series(LineSeries::new(
                        decimate(&p.measured, COLUMNS)
                            .into_iter()
                            .filter(|q| finite(q)),
                        MEASURED.stroke_width(4),
                    ))?
                    .label(p.measured_label)
                    .legend(|(x, y)| {
                        PathElement::new(vec![(x, y), (x + 18, y)], MEASURED.stroke_width(4))
                    });
            }
            for (name, color, s) in &p.models {
                let c = *color;
                $chart
                    .draw_series(LineSeries::new(
                        decimate(s, COLUMNS).into_iter().filter(|q| finite(q)),
                        c.stroke_width(2),
                    ))?
                    .label(*name)
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 18, y)], c.stroke_width(2))
                    });
            }
            for (name, color, s) in &p.dashed {
                let c = *color;
                $chart
                    .draw_series(DashedLineSeries::new(
                        decimate(s, COLUMNS).into_iter().filter(|q| finite(q)),
                        6,
                        4,
                        c.stroke_width(1),
                    ))?
                    .label(*name)
                    .legend(move |(x, y)| {
                        plotters::element::DashedPathElement::new(
                            vec![(x, y), (x + 18, y)],
                            5,
                            3,
                            c.stroke_width(1),
                        )
                    });
            }
            if let Some(s) = &p.spec {
                draw_spec_over(&mut $chart, s)?;
            }
            if p.legend {
                $chart
                    .configure_series_labels()
                    .position(corner)
                    .background_style(WHITE.mix(0.85))
                    .border_style(BLACK)
                    .draw()?;
            }
        }};
    }
    // The chart on ranges `x` and `y` (in m/s² with the g axis: `y_g` is the same range in g).
    macro_rules! chart {
        ($x:expr, $y:expr, $y_g:expr) => {{
            let mut chart = builder.build_cartesian_2d($x, $y)?;
            if p.g_axis {
                let mut chart = chart.set_secondary_coord($x, $y_g);
                chart
                    .configure_secondary_axes()
                    .y_desc("g")
                    .y_labels(LABELS)
                    .y_label_formatter(&|v| fg.label(*v))
                    .draw()?;
                curves!(chart);
            } else {
                curves!(chart);
            }
        }};
    }
    if p.log {
        let axis = |(labelled, light): &(Vec<f64>, Vec<f64>), lo: f64, hi: f64| {
            (lo..hi)
                .log_scale()
                .with_key_points(labelled.clone())
                .with_light_points(light.clone())
        };
        chart!(
            axis(&x_ticks, x0, x1),
            axis(&y_ticks, y0, y1),
            axis(&g_ticks, y0 / g, y1 / g)
        );
    } else {
        chart!(x0..x1, y0..y1, y0 / g..y1 / g);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The labels of an SVG's `<text>` elements placed in `xs` × `ys`, top to bottom, then
    /// left to right.
    pub(super) fn labels_in(
        svg: &str,
        xs: std::ops::Range<f64>,
        ys: std::ops::Range<f64>,
    ) -> Vec<String> {
        let mut out: Vec<(f64, f64, String)> = Vec::new();
        for t in svg.split("<text").skip(1) {
            let attr = |name: &str| -> Option<f64> {
                let key = format!(" {name}=\"");
                let rest = &t[t.find(&key)? + key.len()..];
                rest[..rest.find('"')?].parse().ok()
            };
            let (Some(x), Some(y)) = (attr("x"), attr("y")) else {
                continue;
            };
            let text = &t[t.find('>').unwrap() + 1..t.find("</text>").unwrap()];
            if xs.contains(&x) && ys.contains(&y) {
                out.push((y, x, text.trim().to_string()));
            }
        }
        out.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
        out.into_iter().map(|(_, _, t)| t).collect()
    }

    /// A 400 × 300 panel of `measured` drawn alone, as SVG text.
    pub(super) fn panel_svg(measured: Vec<(f64, f64)>, log: bool, g_axis: bool) -> String {
        svg_text((400, 300), |root| {
            root.fill(&WHITE)?;
            draw_panel(
                root,
                None,
                &Panel {
                    title: "test".into(),
                    x_label: "x",
                    measured,
                    measured_label: "measured",
                    models: Vec::new(),
                    dashed: Vec::new(),
                    log,
                    g_axis,
                    legend: false,
                    spec: None,
                },
            )
        })
        .unwrap()
    }

    #[test]
    fn the_g_axis_is_the_same_range_divided_by_standard_gravity() {
        // 0 to 10 g.
        let svg = panel_svg(
            (0..=100)
                .map(|k| (f64::from(k), f64::from(k) / 10.0 * STANDARD_GRAVITY))
                .collect(),
            false,
            true,
        );
        // Right of the plot area (the 60 px label area's ticks): whole g.
        let right = labels_in(&svg, 335.0..400.0, 0.0..300.0);
        let g: Vec<&str> = right
            .iter()
            .map(String::as_str)
            .filter(|t| *t != "g")
            .collect();
        assert_eq!(
            g,
            ["10", "9", "8", "7", "6", "5", "4", "3", "2", "1", "0"],
            "{right:?}"
        );
        // Each axis named by its unit.
        assert!(right.iter().any(|t| t == "g"), "{right:?}");
        assert!(labels_in(&svg, 0.0..60.0, 0.0..300.0)
            .iter()
            .any(|t| t == "m/s²"));
        // Without it, no labels on the right.
        let svg = panel_svg(vec![(0.0, 0.0), (1.0, 98.0)], false, false);
        assert!(labels_in(&svg, 345.0..400.0, 0.0..250.0).is_empty());
    }

    #[test]
    fn each_axis_labels_its_ticks_in_one_format() {
        use super::ticks::tests::one_format;
        // A deformation from 0 to -3 µm against time from -0.08 ms: one by one, the labels
        // read -500µ next to -0.001 and 0.1 next to 0.15.
        let svg = panel_svg(
            (0..=50)
                .map(|k| {
                    let t = -0.08 + f64::from(k) * 0.01;
                    (t, -3e-3 * (t.max(0.0) / 0.42).powi(2))
                })
                .collect(),
            false,
            true,
        );
        let left = labels_in(&svg, 0.0..68.0, 30.0..262.0);
        let left: Vec<String> = left.into_iter().filter(|t| t != "m/s²").collect();
        let under = labels_in(&svg, 60.0..340.0, 262.0..285.0);
        let right = labels_in(&svg, 330.0..400.0, 30.0..262.0);
        let right: Vec<String> = right.into_iter().filter(|t| t != "g").collect();
        for labels in [&left, &under, &right] {
            assert!(labels.len() >= 4 && one_format(labels), "{labels:?}");
        }
        assert!(left.contains(&"-1000µ".to_string()), "{left:?}");
        assert!(under.contains(&"0.10".to_string()), "{under:?}");
    }

    #[test]
    fn log_panels_number_their_decades() {
        // 10 Hz to 100 kHz, 100 to 1M m/s².
        let spectrum: Vec<(f64, f64)> = (0..=40)
            .map(|k| {
                let f = 10f64.powf(1.0 + f64::from(k) / 10.0);
                (f, 10.0 * f)
            })
            .collect();
        let svg = panel_svg(spectrum, true, true);
        // Under the plot area: the decades of frequency.
        let x = labels_in(&svg, 60.0..340.0, 262.0..285.0);
        assert_eq!(x, ["10", "100", "1k", "10k", "100k"], "{x:?}");
        // Left: m/s², right: g, each decade (80 to 1.25M m/s² is 8.2 to 127k g).
        let left = labels_in(&svg, 0.0..68.0, 30.0..262.0);
        let left: Vec<&str> = left
            .iter()
            .map(String::as_str)
            .filter(|t| *t != "m/s²")
            .collect();
        assert_eq!(left, ["1M", "100k", "10k", "1k", "100"], "{left:?}");
        let right = labels_in(&svg, 330.0..400.0, 30.0..262.0);
        let right: Vec<&str> = right
            .iter()
            .map(String::as_str)
            .filter(|t| *t != "g")
            .collect();
        assert_eq!(right, ["100k", "10k", "1k", "100", "10"], "{right:?}");
        // A short band: 2 and 5 times the decade too.
        let svg = panel_svg(vec![(150.0, 3.0), (900.0, 20.0)], true, false);
        let x = labels_in(&svg, 60.0..400.0, 262.0..285.0);
        assert_eq!(x, ["200", "400", "600", "800"], "{x:?}");
        let y = labels_in(&svg, 0.0..68.0, 30.0..262.0);
        assert_eq!(y, ["20", "10", "5"], "{y:?}");
    }
}
