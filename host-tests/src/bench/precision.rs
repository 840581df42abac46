//! Work-precision benchmark: time per impact against error, per model, solver and setting.

use std::time::{Duration, Instant};

use impact_core::{solve, ContactLaw, Impact, ImpactOutcome, Method, Model, Real, Settings};
use serde::Serialize;

use plotters::prelude::*;

use crate::simulate::model_f32;
use crate::testkit::cases::{self, Case};
use crate::testkit::compare::{max_relative_error, widen};

/// One benchmark point.
#[derive(Clone, Debug, Serialize)]
pub struct Point {
    pub case: String,
    pub model: String,
    pub solver: String,
    pub precision: String,
    /// Steps per time scale (fixed-step), relative tolerance (adaptive), or 0 (exact).
    pub setting: f64,
    pub seconds_per_impact: f64,
    pub max_relative_error: f64,
    pub worst_field: String,
    pub rhs_evaluations: u32,
}

/// The solver settings swept.
pub fn settings() -> Vec<Settings<f64>> {
    let mut v = vec![Settings::exact()];
    for n in [100, 300, 1000, 3000, 10000] {
        v.push(Settings::fixed(Method::Euler, n * 10));
    }
    for n in [30, 100, 300, 1000, 3000] {
        v.push(Settings::fixed(Method::Verlet, n * 3));
    }
    for n in [25, 50, 100, 200, 400, 800, 1600] {
        v.push(Settings::fixed(Method::Rk4, n));
    }
    for rtol in [1e-4, 1e-6, 1e-8, 1e-10, 1e-12, 1e-13] {
        v.push(Settings::adaptive(rtol));
    }
    v
}

fn setting_value<R: Real>(s: &Settings<R>) -> f64 {
    match s.method {
        Method::Exact => 0.0,
        Method::Adaptive => s.rtol.to_f64(),
        _ => s.steps as f64,
    }
}

/// Times `f` for at least `budget` (and 3 calls): seconds per call.
fn time_it(budget: Duration, mut f: impl FnMut()) -> f64 {
    let mut calls = 0u64;
    let start = Instant::now();
    while calls < 3 || start.elapsed() < budget {
        f();
        calls += 1;
    }
    start.elapsed().as_secs_f64() / calls as f64
}

/// One point: solves `case` (as `model`, `impact` in the precision `R`) with `s`, compares
/// with `exact` and times it. `None` if the solver declines.
fn point<R: Real>(
    case: &Case,
    model: &Model<R>,
    impact: &Impact<R>,
    s: &Settings<R>,
    exact: &ImpactOutcome<f64>,
    budget: Duration,
) -> Option<Point> {
    let o = solve(model, impact, s).ok()?;
    let (err, field) = max_relative_error(&widen(&o), exact);
    let t = time_it(budget, || {
        let _ = std::hint::black_box(solve(
            std::hint::black_box(model),
            std::hint::black_box(impact),
            s,
        ));
    });
    Some(Point {
        case: case.name.into(),
        model: case.model.name().into(),
        solver: s.method.name().into(),
        precision: R::NAME.into(),
        setting: setting_value(s),
        seconds_per_impact: t,
        max_relative_error: err,
        worst_field: field.into(),
        rhs_evaluations: o.rhs_evaluations,
    })
}

/// Runs the sweep over `cases` in f64 (and in f32 for the board-relevant solvers).
pub fn run(cases: &[Case], budget: Duration) -> Vec<Point> {
    let mut out = Vec::new();
    for case in cases {
        let Ok(exact) = case.model.exact(&case.impact) else {
            continue;
        };
        for s in settings() {
            out.extend(point(case, &case.model, &case.impact, &s, &exact, budget));
        }
        // f32: the board's arithmetic, at the accuracy it needs.
        let model = model_f32(&case.model);
        let impact = Impact::new(case.impact.mass_kg as f32, case.impact.v0_m_s as f32);
        let s32: [Settings<f32>; 4] = [
            Settings::exact(),
            Settings::fixed(Method::Rk4, 50),
            Settings::fixed(Method::Rk4, 200),
            Settings::adaptive(1e-5),
        ];
        for s in s32 {
            out.extend(point(case, &model, &impact, &s, &exact, budget));
        }
    }
    out
}

/// The standard cases.
pub fn standard_cases() -> Vec<Case> {
    cases::standard()
}

/// CSV text of the points.
pub fn csv(points: &[Point]) -> String {
    let mut s = String::from(
        "case,model,solver,precision,setting,seconds_per_impact,max_relative_error,worst_field,rhs_evaluations\n",
    );
    for p in points {
        s.push_str(&format!(
            "{},{},{},{},{:e},{:.4e},{:.3e},{},{}\n",
            p.case,
            p.model,
            p.solver,
            p.precision,
            p.setting,
            p.seconds_per_impact,
            p.max_relative_error,
            p.worst_field,
            p.rhs_evaluations
        ));
    }
    s
}

/// A readable table of the points.
pub fn table(points: &[Point]) -> String {
    let mut s = format!(
        "{:<26} {:<9} {:<5} {:>9} {:>12} {:>10} {:>9}  {}\n",
        "case", "solver", "prec", "setting", "time/impact", "max error", "rhs evals", "worst field"
    );
    for p in points {
        s.push_str(&format!(
            "{:<26} {:<9} {:<5} {:>9.0e} {:>10.3} µs {:>10.2e} {:>9}  {}\n",
            p.case,
            p.solver,
            p.precision,
            p.setting,
            p.seconds_per_impact * 1e6,
            p.max_relative_error,
            p.rhs_evaluations,
            p.worst_field
        ));
    }
    s
}

/// Per case: the fastest f64 time-stepping run with error ≤ `target`, and the exact solver's.
pub fn summary(points: &[Point], target: f64) -> String {
    let mut s = format!(
        "fastest f64 solve with max relative error <= {target:.0e} (scipy solve_ivp: 1-8 ms):\n"
    );
    let mut names: Vec<&str> = points.iter().map(|p| p.case.as_str()).collect();
    names.dedup();
    for name in names {
        let in_case = || {
            points
                .iter()
                .filter(move |p| p.case == name && p.precision == "f64")
        };
        let stepping = in_case()
            .filter(|p| p.solver != "exact" && p.max_relative_error <= target)
            .min_by(|a, b| a.seconds_per_impact.total_cmp(&b.seconds_per_impact));
        let exact = in_case().find(|p| p.solver == "exact");
        let fmt = |p: Option<&Point>| match p {
            Some(p) => format!(
                "{:>9.2} µs ({} {:.0e}, {:.1e})",
                p.seconds_per_impact * 1e6,
                p.solver,
                p.setting,
                p.max_relative_error
            ),
            None => "none".into(),
        };
        s.push_str(&format!(
            "  {name:<26} stepping {}   exact {}\n",
            fmt(stepping),
            fmt(exact)
        ));
    }
    s
}

/// Draws time per impact (µs) against max relative error, one series per solver, one panel
/// per model case, into an SVG file.
pub fn work_precision(points: &[Point], path: &std::path::Path) -> Result<(), super::BenchError> {
    let mut cases: Vec<&str> = points.iter().map(|p| p.case.as_str()).collect();
    cases.dedup();
    let cols = 2usize;
    let rows = cases.len().div_ceil(cols).max(1);
    let mut text = String::new();
    {
        let root =
            SVGBackend::with_string(&mut text, (1100, 380 * rows as u32)).into_drawing_area();
        root.fill(&WHITE)?;
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
                )?;
            chart
                .configure_mesh()
                .x_desc("max relative error")
                .y_desc("time per impact, µs")
                .x_label_formatter(&|v| format!("{v:.0e}"))
                .y_label_formatter(&|v| format!("{v:.2}"))
                .draw()?;
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
                    .draw_series(LineSeries::new(series.clone(), color.stroke_width(2)))?
                    .label(solver)
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
                    });
                chart.draw_series(
                    series
                        .into_iter()
                        .map(|xy| Circle::new(xy, 3, color.filled())),
                )?;
            }
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.8))
                .border_style(BLACK)
                .draw()?;
        }
        root.present()?;
    }
    Ok(crate::output::write(path, text.as_bytes())?)
}
