//! `impact simulate --plot`: the wall contact of each model drawn (force against deformation
//! and time, deformation against time).

use plotters::prelude::*;

use crate::plot::{draw_panel, Curve, Panel};

/// `impact simulate --plot` against a wall: each model's deformation, velocity and force
/// against time and its force against deformation (seed 000's Figs. 17–18 when a Hertz
/// contact and its linear spring are drawn together).
pub fn wall_contact(
    models: &[(crate::simulate::ModelName, impact_core::Model<f64>)],
    impact: &impact_core::Impact<f64>,
    path: &std::path::Path,
) -> Result<(), crate::simulate::SimulateError> {
    use crate::simulate::ModelName;
    use crate::simulate::SimulateError;
    use impact_core::solve::trajectory;
    use impact_core::ContactLaw;
    const COLOURS: [RGBColor; 3] = [
        RGBColor(40, 90, 200),
        RGBColor(200, 60, 40),
        RGBColor(40, 140, 60),
    ];
    let mut curves: [Vec<Curve>; 4] = Default::default();
    for ((name, model), colour) in models.iter().zip(COLOURS) {
        let label = match name {
            ModelName::Hertz => "Hertz",
            ModelName::Linear => "linear",
            ModelName::KelvinVoigt => "Kelvin–Voigt",
            ModelName::TwoPhase => "two-phase",
            ModelName::Nonlinear => "nonlinear",
        };
        let mut s = Vec::new();
        // 400 points per time scale (a contact lasts a few).
        let scale = model.time_scale(impact);
        let dt = (scale / 400.0).max(f64::MIN_POSITIVE);
        trajectory::sample(model, impact, 1e-10, 0.0, dt, 20_000, |p| s.push(p))
            .map_err(SimulateError::Trajectory)?;
        let map = |f: &dyn Fn(&trajectory::Sample<f64>) -> (f64, f64)| {
            s.iter().map(f).collect::<Vec<_>>()
        };
        curves[0].push((label, colour, map(&|p| (p.t_s * 1e3, p.x_m * 1e3))));
        curves[1].push((label, colour, map(&|p| (p.t_s * 1e3, p.v_m_s))));
        curves[2].push((label, colour, map(&|p| (p.t_s * 1e3, p.force_n))));
        curves[3].push((label, colour, map(&|p| (p.x_m * 1e3, p.force_n))));
    }
    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, (1600, 360)).into_drawing_area();
        root.fill(&WHITE)?;
        let areas = root.split_evenly((1, 4));
        let titles = [
            ("deformation x(t), mm", "time from touch, ms"),
            ("velocity v(t), m/s", "time from touch, ms"),
            ("contact force F(t), N", "time from touch, ms"),
            ("force against deformation F(x), N", "deformation, mm"),
        ];
        for (j, (c, (title, x_label))) in curves.into_iter().zip(titles).enumerate() {
            let p = Panel {
                title: title.into(),
                x_label,
                measured: Vec::new(),
                measured_label: "",
                models: c,
                dashed: Vec::new(),
                log: false,
                g_axis: false,
                legend: j == 0,
                spec: None,
            };
            draw_panel(&areas[j], None, &p)?;
        }
        root.present()?;
    }
    Ok(crate::plot::write_figure(path, &text)?)
}
