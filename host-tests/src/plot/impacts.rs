//! The impacts figure of `impact analyze`, `emulate` and `log --plot`: per impact the
//! deceleration, velocity, deformation and force–deformation loop with the fitted models,
//! and with `--srs` the SRS and PVSS.

use impact_core::signal::cfc::Cfc;
use plotters::prelude::*;

use super::signal::{window, Signal};
use super::{draw_panel, write_svg, Curve, Panel};

/// The CFC-filtered trace's colour: dark, over the light raw one.
const CFC_TRACE: RGBColor = RGBColor(25, 45, 120);

/// A CFC trace's legend.
fn cfc_label(class: Cfc) -> &'static str {
    match class {
        Cfc::Cfc60 => "CFC 60",
        Cfc::Cfc180 => "CFC 180",
        Cfc::Cfc600 => "CFC 600",
        Cfc::Cfc1000 => "CFC 1000",
    }
}

/// The height of the figure's title band, px.
const TITLE_HEIGHT: u32 = 36;

/// Impacts the figure shows at most (a note says so when there are more).
pub const SHOWN: usize = 6;

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
        let [mut c_a, c_v, c_x, c_f] = curves;
        // With a CFC, its trace over the raw one (the analysis's filter on the samples it
        // filtered), or the title says it is not drawn.
        let mut decel_title = "deceleration, m/s² (left) and g (right)".to_string();
        if let Some((class, _)) = signal.cfc {
            match super::filtered(signal, r) {
                Some((first, values)) => {
                    let trace = (start..start + len)
                        .filter_map(|i| {
                            let v = values
                                .get(usize::try_from((i as u64).checked_sub(first)?).ok()?)?;
                            Some((t_ms(i), *v))
                        })
                        .collect();
                    c_a.insert(0, (cfc_label(class), CFC_TRACE, trace));
                }
                None => {
                    decel_title = format!("deceleration, m/s², g: CFC {} not drawn", class.class());
                }
            }
        }
        let raw_label = if c_a.first().is_some_and(|c| c.1 == CFC_TRACE) {
            "raw"
        } else {
            "measured"
        };
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
                title: &decel_title,
                x_label: "time from touch, ms",
                measured: meas,
                measured_label: raw_label,
                models: c_a,
                dashed: Vec::new(),
                log: false,
                g_axis: true,
                legend: true,
            },
            Panel {
                title: vel_title,
                x_label: "time from touch, ms",
                measured: vel,
                measured_label: "measured",
                models: c_v,
                dashed: Vec::new(),
                log: false,
                g_axis: false,
                legend: false,
            },
            Panel {
                title: def_title,
                x_label: "time from touch, ms",
                measured: def,
                measured_label: "measured",
                models: c_x,
                dashed: Vec::new(),
                log: false,
                g_axis: false,
                legend: false,
            },
            Panel {
                title: force_title,
                x_label: "deformation, mm",
                measured: loop_,
                measured_label: "measured",
                models: c_f,
                dashed: Vec::new(),
                log: false,
                g_axis: false,
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
                title: "SRS (maximax), m/s² (left) and g (right)",
                x_label: "natural frequency, Hz",
                measured: srs,
                measured_label: "SRS",
                models: Vec::new(),
                dashed: Vec::new(),
                log: true,
                g_axis: true,
                legend: false,
            });
            panels.push(Panel {
                title: "pseudo-velocity shock spectrum, m/s",
                x_label: "natural frequency, Hz",
                measured: pvss,
                measured_label: "PVSS",
                models: Vec::new(),
                dashed: Vec::new(),
                log: true,
                g_axis: false,
                legend: false,
            });
        }
        for (j, p) in panels.iter().enumerate() {
            draw_panel(&rows[k * cols + j], Some(r.index), p)?;
        }
    }
    Ok(())
}
