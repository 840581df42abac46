//! SVG plots: the work-precision diagram (time per impact against error).

use plotters::prelude::*;

use crate::precision::Point;

/// Checks that `path` can take an SVG before any work is done: its directory exists and it is
/// none of the `inputs` (an analysis never overwrites its recording).
pub fn check_output(path: &std::path::Path, inputs: &[&std::path::Path]) -> Result<(), String> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => std::path::Path::new("."),
    };
    if !dir.is_dir() {
        return Err(format!(
            "--plot {}: directory {} does not exist",
            path.display(),
            dir.display()
        ));
    }
    if let Ok(out) = path.canonicalize() {
        for input in inputs {
            if input.canonicalize().is_ok_and(|i| i == out) {
                return Err(format!(
                    "--plot {}: is an input file; it would be overwritten",
                    path.display()
                ));
            }
        }
    }
    Ok(())
}

/// Draws time per impact (µs) against max relative error, one series per solver, one panel
/// per model case, into an SVG file.
pub fn work_precision(points: &[Point], path: &std::path::Path) -> Result<(), String> {
    let mut cases: Vec<&str> = points.iter().map(|p| p.case.as_str()).collect();
    cases.dedup();
    let cols = 2usize;
    let rows = cases.len().div_ceil(cols).max(1);
    let root = SVGBackend::new(path, (1100, 380 * rows as u32)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let panels = root.split_evenly((rows, cols));
    let solvers = [
        ("euler", RGBColor(200, 80, 40)),
        ("verlet", RGBColor(40, 140, 60)),
        ("rk4", RGBColor(40, 80, 200)),
        ("adaptive", RGBColor(150, 40, 170)),
        ("exact", RGBColor(0, 0, 0)),
    ];
    for (panel, case) in panels.iter().zip(&cases) {
        let pts: Vec<&Point> = points
            .iter()
            .filter(|p| p.case == *case && p.precision == "f64")
            .collect();
        let err = |p: &Point| p.max_relative_error.max(1e-17);
        let (mut tmin, mut tmax) = (f64::MAX, f64::MIN);
        for p in &pts {
            tmin = tmin.min(p.seconds_per_impact * 1e6);
            tmax = tmax.max(p.seconds_per_impact * 1e6);
        }
        let mut chart = ChartBuilder::on(panel)
            .caption(*case, ("sans-serif", 18))
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(
                (1e-17f64..1.0f64).log_scale(),
                ((tmin * 0.5)..(tmax * 2.0)).log_scale(),
            )
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .x_desc("max relative error")
            .y_desc("time per impact, µs")
            .x_label_formatter(&|v| format!("{v:.0e}"))
            .y_label_formatter(&|v| format!("{v:.2}"))
            .draw()
            .map_err(|e| e.to_string())?;
        for (solver, color) in solvers {
            let series: Vec<(f64, f64)> = pts
                .iter()
                .filter(|p| p.solver == solver)
                .map(|p| (err(p), p.seconds_per_impact * 1e6))
                .collect();
            if series.is_empty() {
                continue;
            }
            chart
                .draw_series(LineSeries::new(series.clone(), color.stroke_width(2)))
                .map_err(|e| e.to_string())?
                .label(solver)
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
                });
            chart
                .draw_series(
                    series
                        .into_iter()
                        .map(|xy| Circle::new(xy, 3, color.filled())),
                )
                .map_err(|e| e.to_string())?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()
            .map_err(|e| e.to_string())?;
    }
    root.present().map_err(|e| e.to_string())
}

/// A named, coloured series of (time, value) points.
type Curve = (&'static str, RGBColor, Vec<(f64, f64)>);

/// Acceleration, velocity and deformation of each impact (up to six), as in the seed
/// paper's figures, with the fitted models' accelerations over the measured one.
pub fn impacts(
    setup: &crate::analyze::Setup,
    reports: &[impact_core::ImpactReport],
    path: &std::path::Path,
) -> Result<(), String> {
    use impact_core::model::{Model, Nonlinear, TwoPhase};
    use impact_core::solve::trajectory;
    use impact_core::{ContactLaw, Impact};
    let shown: Vec<_> = reports.iter().take(6).collect();
    if shown.is_empty() {
        return Err("--plot: no impact to draw".into());
    }
    let root = SVGBackend::new(path, (1200, 330 * shown.len() as u32)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let rows = root.split_evenly((shown.len(), 3));
    let fs = setup.rate_hz;
    let a = &setup.prepared.accel_m_s2;
    for (k, r) in shown.iter().enumerate() {
        let start = ((r.start_s * fs).floor() as usize).saturating_sub(2);
        let len = ((r.duration_s as f64 * fs).ceil() as usize + 4).max(4);
        let end = (start + len).min(a.len());
        let base = r.baseline_m_s2 as f64;
        let t_ms = |i: usize| (i as f64 / fs - r.start_s) * 1e3;
        let meas: Vec<(f64, f64)> = (start..end).map(|i| (t_ms(i), a[i] - base)).collect();
        let v0 = r.kinematics.map(|k| k.impact_velocity_m_s as f64);
        // Velocity and deformation by integration from the touch.
        let (mut v, mut x) = (v0.unwrap_or(0.0), 0.0);
        let mut vel = Vec::new();
        let mut def = Vec::new();
        for (t, acc) in &meas {
            if *t >= 0.0 {
                let v1 = v - acc / fs;
                x += (v + v1) / 2.0 / fs;
                v = v1;
            }
            vel.push((*t, v));
            def.push((*t, x * 1e3));
        }
        // Fitted models, simulated from the same touch.
        let mut fitted: Vec<Curve> = Vec::new();
        if let (Some(v0), Some(m)) = (v0, setup.scene.mass_kg) {
            let impact = Impact::new(m as f64, v0);
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
            // A model's curve over a few times the measured window at most.
            let points = 4 * meas.len() as u64 + 1024;
            for (name, color, model) in models {
                let mut series = Vec::new();
                if model.validate().is_ok()
                    && trajectory::sample(&model, &impact, 1e-8, 0.0, 1.0 / fs, points, |s| {
                        series.push((s.t_s * 1e3, s.force_n / m as f64))
                    })
                    .is_ok()
                {
                    fitted.push((name, color, series));
                }
            }
        }
        let panels = [
            ("deceleration, m/s²", &meas, true),
            ("velocity, m/s", &vel, false),
            ("deformation, mm", &def, false),
        ];
        for (j, (label, series, with_fits)) in panels.into_iter().enumerate() {
            let area = &rows[k * 3 + j];
            let (mut lo, mut hi) = series
                .iter()
                .fold((f64::MAX, f64::MIN), |(l, h), p| (l.min(p.1), h.max(p.1)));
            if with_fits {
                for (_, _, s) in &fitted {
                    for p in s {
                        lo = lo.min(p.1);
                        hi = hi.max(p.1);
                    }
                }
            }
            let pad = (hi - lo).abs().max(1e-12) * 0.08;
            let (t0, t1) = (
                series.first().map_or(0.0, |p| p.0),
                series.last().map_or(1.0, |p| p.0),
            );
            let mut chart = ChartBuilder::on(area)
                .caption(format!("impact {} — {label}", r.index), ("sans-serif", 15))
                .margin(8)
                .x_label_area_size(30)
                .y_label_area_size(55)
                .build_cartesian_2d(t0..t1.max(t0 + 1e-9), (lo - pad)..(hi + pad))
                .map_err(|e| e.to_string())?;
            chart
                .configure_mesh()
                .x_desc("time from touch, ms")
                .draw()
                .map_err(|e| e.to_string())?;
            chart
                .draw_series(LineSeries::new(
                    series.iter().copied(),
                    BLUE.stroke_width(1),
                ))
                .map_err(|e| e.to_string())?
                .label("measured")
                .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], BLUE));
            if with_fits {
                for (name, color, s) in &fitted {
                    let c = *color;
                    chart
                        .draw_series(LineSeries::new(s.iter().copied(), c.stroke_width(2)))
                        .map_err(|e| e.to_string())?
                        .label(*name)
                        .legend(move |(x, y)| {
                            PathElement::new(vec![(x, y), (x + 18, y)], c.stroke_width(2))
                        });
                }
                chart
                    .configure_series_labels()
                    .background_style(WHITE.mix(0.8))
                    .border_style(BLACK)
                    .draw()
                    .map_err(|e| e.to_string())?;
            }
        }
    }
    root.present().map_err(|e| e.to_string())
}
