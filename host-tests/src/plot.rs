//! SVG plots: the work-precision diagram (time per impact against error).

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

/// What the impact figure draws from: the signal the pipeline analysed (the counts times
/// the gain, so that `impact analyze` and `impact log` on the board's waveforms draw the
/// same), at the scene's rate.
pub struct Signal<'a> {
    /// Sample rate, Hz (the scene's, an `f32`).
    pub rate_hz: f64,
    /// The body's mass, kg, if known.
    pub mass_kg: Option<f64>,
    /// Acceleration of stream sample `i`, m/s² (`None` where it is not known).
    pub accel_m_s2: Box<dyn Fn(u64) -> Option<f64> + 'a>,
    /// The figure's title: what was drawn (file, channel, filter).
    pub title: String,
}

/// A tick's label in engineering form: four significant digits at most, no trailing zeros,
/// an SI prefix from 10^4 up and below 10^-3 (`100k`, `1.5M`, `250µ`; not `100000.0`).
pub(crate) fn tick(v: f64) -> String {
    let a = v.abs();
    if a <= 1e-12 || !a.is_finite() {
        return "0".into();
    }
    let (scale, prefix) = match a {
        a if a >= 1e9 => (1e-9, "G"),
        a if a >= 1e6 => (1e-6, "M"),
        a if a >= 1e4 => (1e-3, "k"),
        a if a >= 1e-3 => (1.0, ""),
        a if a >= 1e-6 => (1e6, "µ"),
        _ => (1e9, "n"),
    };
    let x = v * scale;
    let decimals = (3 - x.abs().log10().floor() as i32).clamp(0, 6) as usize;
    let s = format!("{x:.decimals$}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        &s
    };
    format!("{s}{prefix}")
}

/// The height of the figure's title band, px.
const TITLE_HEIGHT: u32 = 36;

/// Impacts the figure shows at most (a note says so when there are more).
pub const SHOWN: usize = 6;

/// The samples the figure draws of impact `r` at `rate_hz`: from two before first touch to
/// four past separation, `(first, count)`.
pub fn window(r: &impact_core::ImpactReport, rate_hz: f64) -> (u64, u64) {
    let start = ((r.start_s * rate_hz).floor().max(0.0) as u64).saturating_sub(2);
    let len = ((f64::from(r.duration_s) * rate_hz).ceil().max(0.0) as u64 + 4).max(4);
    (start, len)
}

/// Per impact (up to [`SHOWN`]), as in the seed papers' figures: deceleration, velocity and
/// deformation against time from touch, the force–deformation loop, with the fitted models
/// (two-phase, nonlinear, Hertz) simulated from the same touch over the measured curves; with
/// `--srs`, the SRS and the PVSS (log–log).
pub fn impacts(
    signal: &Signal,
    reports: &[impact_core::ImpactReport],
    path: &std::path::Path,
) -> Result<(), String> {
    let shown: Vec<_> = reports.iter().take(SHOWN).collect();
    if shown.is_empty() {
        crate::note(&format!(
            "--plot {}: no impact to draw, no figure written",
            path.display()
        ));
        return Ok(());
    }
    let spectra = shown.iter().any(|r| r.spectrum.is_some());
    if reports.len() > shown.len() {
        crate::note(&format!(
            "--plot: the figure shows the first {} of {} impacts",
            shown.len(),
            reports.len()
        ));
    }
    let cols = if spectra { 6 } else { 4 };
    write_svg(
        path,
        (400 * cols as u32, 330 * shown.len() as u32 + TITLE_HEIGHT),
        |root| {
            root.fill(&WHITE).map_err(|e| e.to_string())?;
            let (head, body) = root.split_vertically(TITLE_HEIGHT);
            head.draw(&Text::new(
                signal.title.clone(),
                (12, 10),
                ("sans-serif", 18).into_font().style(FontStyle::Bold),
            ))
            .map_err(|e| e.to_string())?;
            draw_impacts(&body, signal, &shown, cols, spectra)
        },
    )?;
    eprintln!("wrote {}", path.display());
    Ok(())
}

/// The impacts figure's panels on `root` (see [`impacts`]).
fn draw_impacts(
    root: &DrawingArea<SVGBackend, plotters::coord::Shift>,
    signal: &Signal,
    shown: &[&impact_core::ImpactReport],
    cols: usize,
    spectra: bool,
) -> Result<(), String> {
    use impact_core::model::{Hertz, Model, Nonlinear, TwoPhase};
    use impact_core::solve::trajectory;
    use impact_core::{ContactLaw, Impact};
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let rows = root.split_evenly((shown.len(), cols));
    let fs = signal.rate_hz;
    let mass = signal.mass_kg;
    for (k, r) in shown.iter().enumerate() {
        let (start, len) = window(r, fs);
        let (start, len) = (start as usize, len as usize);
        let base = r.baseline_m_s2 as f64;
        let t_ms = |i: usize| (i as f64 / fs - r.start_s) * 1e3;
        let meas: Vec<(f64, f64)> = (start..start + len)
            .map_while(|i| Some((t_ms(i), (signal.accel_m_s2)(i as u64)? - base)))
            .collect();
        let v0 = r.kinematics.map(|k| k.impact_velocity_m_s as f64);
        // Velocity and deformation by integration from the touch.
        let (mut v, mut x) = (v0.unwrap_or(0.0), 0.0);
        let (mut vel, mut def, mut loop_) = (Vec::new(), Vec::new(), Vec::new());
        for (t, acc) in &meas {
            if *t >= 0.0 {
                let v1 = v - acc / fs;
                x += (v + v1) / 2.0 / fs;
                v = v1;
            }
            vel.push((*t, v));
            def.push((*t, x * 1e3));
            if *t >= 0.0 {
                loop_.push((x * 1e3, acc * mass.unwrap_or(1.0)));
            }
        }
        // Fitted models, simulated from the same touch.
        let mut models: Vec<(&'static str, RGBColor, Model<f64>)> = Vec::new();
        if let Some(f) = r.fits.two_phase {
            models.push((
                "two-phase fit",
                RGBColor(200, 60, 40),
                Model::TwoPhase(TwoPhase {
                    kc: f.kc_n_m as f64,
                    kr: f.kr_n_m as f64,
                    c: (f.c_n_s_m as f64).max(0.0),
                    permanent_m: Some((f.permanent_m as f64).max(0.0)),
                }),
            ));
        }
        if let Some(f) = r.fits.nonlinear {
            models.push((
                "nonlinear fit",
                RGBColor(40, 140, 60),
                Model::Nonlinear(Nonlinear {
                    k: f.k as f64,
                    c: (f.c_s_m as f64).max(0.0),
                    n: f.n as f64,
                }),
            ));
        }
        if let Some(f) = r.fits.hertz {
            models.push((
                "Hertz fit",
                RGBColor(150, 60, 170),
                Model::Hertz(Hertz { k: f.k as f64 }),
            ));
        }
        // Each model's a(t), v(t), x(t) and F(x), over a few times the window at most.
        let mut curves: [Vec<Curve>; 4] = Default::default();
        if let (Some(v0), Some(m)) = (v0, mass) {
            let impact = Impact::new(m, v0);
            let points = 4 * meas.len() as u64 + 1024;
            for (name, color, model) in models {
                let mut s = Vec::new();
                if model.validate().is_ok()
                    && trajectory::sample(&model, &impact, 1e-8, 0.0, 1.0 / fs, points, |p| {
                        s.push(p)
                    })
                    .is_ok()
                {
                    let map = |f: &dyn Fn(&trajectory::Sample<f64>) -> (f64, f64)| {
                        s.iter().map(f).collect::<Vec<_>>()
                    };
                    curves[0].push((name, color, map(&|p| (p.t_s * 1e3, p.force_n / m))));
                    curves[1].push((name, color, map(&|p| (p.t_s * 1e3, p.v_m_s))));
                    curves[2].push((name, color, map(&|p| (p.t_s * 1e3, p.x_m * 1e3))));
                    curves[3].push((name, color, map(&|p| (p.x_m * 1e3, p.force_n))));
                }
            }
        }
        let [c_a, c_v, c_x, c_f] = curves;
        // A Δv the report refuses (a channel that does not hold DC) is not drawn either: no
        // velocity, deformation or loop from its integral.
        let refused = r.delta_v_m_s.is_none();
        if refused {
            vel.clear();
            def.clear();
            loop_.clear();
        }
        // Without v0 the integrals start from rest: said in the titles; no loop.
        let known = v0.is_some();
        let force_title = match (known, mass.is_some()) {
            _ if refused => "force against deformation: no Δv (see the report)",
            (false, _) => {
                loop_.clear();
                "force against deformation: needs v0"
            }
            (true, true) => "force against deformation, N",
            (true, false) => "deceleration against deformation, m/s²",
        };
        let (vel_title, def_title) = if refused {
            (
                "velocity: no Δv (see the report)",
                "deformation: no Δv (see the report)",
            )
        } else if known {
            ("velocity, m/s", "deformation, mm")
        } else {
            (
                "velocity change from touch, m/s (no v0)",
                "displacement from touch, mm (no v0)",
            )
        };
        let mut panels = vec![
            Panel {
                title: "deceleration, m/s²",
                x_label: "time from touch, ms",
                measured: meas,
                measured_label: "measured",
                models: c_a,
                log: false,
                legend: true,
            },
            Panel {
                title: vel_title,
                x_label: "time from touch, ms",
                measured: vel,
                measured_label: "measured",
                models: c_v,
                log: false,
                legend: false,
            },
            Panel {
                title: def_title,
                x_label: "time from touch, ms",
                measured: def,
                measured_label: "measured",
                models: c_x,
                log: false,
                legend: false,
            },
            Panel {
                title: force_title,
                x_label: "deformation, mm",
                measured: loop_,
                measured_label: "measured",
                models: c_f,
                log: false,
                legend: false,
            },
        ];
        if spectra {
            let (srs, pvss) = match &r.spectrum {
                Some(sp) => {
                    let n = usize::from(sp.bands);
                    let f = |i: usize| sp.frequency_hz(i);
                    (
                        (0..n).map(|i| (f(i), sp.srs_m_s2[i] as f64)).collect(),
                        (0..n).map(|i| (f(i), sp.pvss_m_s[i] as f64)).collect(),
                    )
                }
                None => (Vec::new(), Vec::new()),
            };
            panels.push(Panel {
                title: "SRS (maximax), m/s²",
                x_label: "natural frequency, Hz",
                measured: srs,
                measured_label: "SRS",
                models: Vec::new(),
                log: true,
                legend: false,
            });
            panels.push(Panel {
                title: "pseudo-velocity shock spectrum, m/s",
                x_label: "natural frequency, Hz",
                measured: pvss,
                measured_label: "PVSS",
                models: Vec::new(),
                log: true,
                legend: false,
            });
        }
        for (j, p) in panels.iter().enumerate() {
            draw_panel(&rows[k * cols + j], Some(r.index), p)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::tick;

    #[test]
    fn ticks_read_as_engineering_numbers() {
        for (v, want) in [
            (0.0, "0"),
            (100_000.0, "100k"),
            (12_500.0, "12.5k"),
            (1.5e6, "1.5M"),
            (20.0, "20"),
            (-0.5, "-0.5"),
            (0.0015, "0.0015"),
            (2.5e-4, "250µ"),
            (1234.0, "1234"),
        ] {
            assert_eq!(tick(v), want, "{v}");
        }
    }
}
