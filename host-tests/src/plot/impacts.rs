//! The impacts figure of `impact analyze`, `emulate` and `log --plot`: per impact the
//! deceleration, velocity, deformation and force–deformation loop with the fitted models,
//! and with `--srs` the SRS and PVSS.

use impact_core::signal::cfc::Cfc;
use impact_core::signal::window_filter::WindowFilter;
use plotters::prelude::*;

use impact_core::spec::Spec;

use super::signal::{window, Signal};
use super::{draw_panel, write_svg, Curve, Panel, PlotError, SpecDrawn};

/// The filtered trace's colour (a CFC's or the low-pass's): dark, over the light raw one.
const CFC_TRACE: RGBColor = RGBColor(25, 45, 120);

/// A filtered trace's legend (the low-pass's setting is in the figure's title).
fn cfc_label(kind: WindowFilter) -> &'static str {
    match kind {
        WindowFilter::Cfc(Cfc::Cfc60) => "CFC 60",
        WindowFilter::Cfc(Cfc::Cfc180) => "CFC 180",
        WindowFilter::Cfc(Cfc::Cfc600) => "CFC 600",
        WindowFilter::Cfc(Cfc::Cfc1000) => "CFC 1000",
        WindowFilter::Lowpass(_) => "low-pass",
    }
}

/// The height of the figure's title band, px.
const TITLE_HEIGHT: u32 = 36;

/// Impacts the figure shows at most (a note says so when there are more).
pub const SHOWN: usize = 6;

/// Per impact (up to [`SHOWN`]), as in the seed papers' figures: deceleration, velocity and
/// deformation against time from touch, the force–deformation loop, with the fitted models
/// (two-phase, nonlinear, Hertz) simulated from the same touch over the measured curves; with
/// `--srs`, the SRS and the PVSS (log–log); with a verdict against `spec` (the scene's), its
/// band, nominal pulse, watched window and worst point on the deceleration.
pub fn impacts(
    signal: &Signal,
    spec: Option<&Spec>,
    reports: &[impact_core::ImpactReport],
    path: &std::path::Path,
) -> Result<(), PlotError> {
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
    // Only the panels an impact can fill (no empty "needs v0" panel): as many columns as the
    // fullest row needs.
    let cols = shown
        .iter()
        .map(|r| kinematics_panels(signal, spec, r).len() + if spectra { 2 } else { 0 })
        .max()
        .unwrap_or(1);
    write_svg(
        path,
        (400 * cols as u32, 330 * shown.len() as u32 + TITLE_HEIGHT),
        |root| {
            root.fill(&WHITE)?;
            let (head, body) = root.split_vertically(TITLE_HEIGHT);
            head.draw(&Text::new(
                signal.title.clone(),
                (12, 10),
                ("sans-serif", 18).into_font().style(FontStyle::Bold),
            ))?;
            draw_impacts(&body, (signal, spec), &shown, cols, spectra)
        },
    )?;
    crate::errln!("wrote {}", path.display());
    Ok(())
}

/// The impacts figure's panels on `root` (see [`impacts`]): a row per impact.
fn draw_impacts(
    root: &DrawingArea<SVGBackend, plotters::coord::Shift>,
    (signal, spec): (&Signal, Option<&Spec>),
    shown: &[&impact_core::ImpactReport],
    cols: usize,
    spectra: bool,
) -> Result<(), PlotError> {
    root.fill(&WHITE)?;
    let rows = root.split_evenly((shown.len(), cols));
    for (k, r) in shown.iter().enumerate() {
        for (j, p) in kinematics_panels(signal, spec, r).iter().enumerate() {
            draw_panel(&rows[k * cols + j], Some(r.index), p)?;
        }
        // The spectra in the last two columns of every row, one above another.
        if spectra {
            for (j, p) in spectrum_panels(r).iter().enumerate() {
                draw_panel(&rows[k * cols + cols - 2 + j], Some(r.index), p)?;
            }
        }
    }
    Ok(())
}

/// The samples of impact `r`'s window, and a sample's time in ms from the touch.
fn window_ms(
    signal: &Signal,
    r: &impact_core::ImpactReport,
) -> (std::ops::Range<usize>, impl Fn(usize) -> f64) {
    let fs = signal.rate_hz;
    let (start, len) = window(r, fs);
    let (start, len) = (start as usize, len as usize);
    let start_s = r.start_s;
    (start..start + len, move |i: usize| {
        (i as f64 / fs - start_s) * 1e3
    })
}

/// The samples the deceleration panel of impact `r` draws: its window, and the window the
/// verdict watched (`watched`, ms from the touch) and a tenth of its span either side (so
/// that its edges show) where that reaches further.
fn drawn_samples(
    signal: &Signal,
    r: &impact_core::ImpactReport,
    watched: Option<(f64, f64)>,
) -> std::ops::Range<usize> {
    let (samples, _) = window_ms(signal, r);
    let Some((from_ms, to_ms)) = watched else {
        return samples;
    };
    let margin = 0.1 * (to_ms - from_ms);
    let (from_ms, to_ms) = (from_ms - margin, to_ms + margin);
    let at = |ms: f64| ((r.start_s + ms * 1e-3) * signal.rate_hz).max(0.0);
    samples.start.min(at(from_ms).floor() as usize)..samples.end.max(at(to_ms).ceil() as usize + 1)
}

/// What an impact's window shows, measured: the deceleration above the baseline, and from
/// the touch on the velocity, deformation and the force (or deceleration) against the
/// deformation, integrated from v0 (from rest without it). Times in ms from the touch.
struct Measured {
    accel: Vec<(f64, f64)>,
    velocity: Vec<(f64, f64)>,
    deformation_mm: Vec<(f64, f64)>,
    force_loop: Vec<(f64, f64)>,
}

impl Measured {
    fn of(signal: &Signal, r: &impact_core::ImpactReport) -> Self {
        let fs = signal.rate_hz;
        let (samples, t_ms) = window_ms(signal, r);
        let base = r.baseline_m_s2 as f64;
        let accel: Vec<(f64, f64)> = samples
            .map_while(|i| Some((t_ms(i), (signal.accel_m_s2)(i as u64)? - base)))
            .collect();
        let v0 = r.kinematics.map(|k| k.impact_velocity_m_s as f64);
        // Velocity and deformation by integration from the touch.
        let (mut v, mut x) = (v0.unwrap_or(0.0), 0.0);
        let (mut velocity, mut deformation_mm, mut force_loop) =
            (Vec::new(), Vec::new(), Vec::new());
        for (t, acc) in &accel {
            if *t >= 0.0 {
                let v1 = v - acc / fs;
                x += (v + v1) / 2.0 / fs;
                v = v1;
            }
            velocity.push((*t, v));
            deformation_mm.push((*t, x * 1e3));
            if *t >= 0.0 {
                force_loop.push((x * 1e3, acc * signal.mass_kg.unwrap_or(1.0)));
            }
        }
        Self {
            accel,
            velocity,
            deformation_mm,
            force_loop,
        }
    }
}

/// The fitted models of `r` with their legends and colours.
fn fitted_models(
    r: &impact_core::ImpactReport,
) -> Vec<(&'static str, RGBColor, impact_core::model::Model<f64>)> {
    use impact_core::model::{Hertz, Model, Nonlinear, TwoPhase};
    let mut models = Vec::new();
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
    models
}

/// Each fitted model simulated from the same touch (with v0 and the mass): its a(t), v(t),
/// x(t) and F(x), over `points` samples at `fs` at most.
fn model_curves(
    r: &impact_core::ImpactReport,
    v0: Option<f64>,
    mass: Option<f64>,
    fs: f64,
    points: u64,
) -> [Vec<Curve>; 4] {
    use impact_core::solve::trajectory;
    use impact_core::{ContactLaw, Impact};
    let mut curves: [Vec<Curve>; 4] = Default::default();
    let (Some(v0), Some(m)) = (v0, mass) else {
        return curves;
    };
    let impact = Impact::new(m, v0);
    for (name, color, model) in fitted_models(r) {
        let mut s = Vec::new();
        if model.validate().is_ok()
            && trajectory::sample(&model, &impact, 1e-8, 0.0, 1.0 / fs, points, |p| s.push(p))
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
    curves
}

/// With a CFC or the low-pass, its trace over the raw one (the analysis's filter on the samples it
/// filtered) put first in `curves`; else, or where it cannot be drawn, the deceleration
/// panel's title saying so.
fn cfc_trace(
    signal: &Signal,
    r: &impact_core::ImpactReport,
    samples: std::ops::Range<usize>,
    curves: &mut Vec<Curve>,
) -> String {
    let (title, quantity) = match signal.force_kg {
        Some(_) => ("force, N", "force, N"),
        None => (
            "deceleration, m/s² (left) and g (right)",
            "deceleration, m/s², g",
        ),
    };
    let title = title.to_string();
    let Some((kind, _)) = signal.filter else {
        return title;
    };
    let (_, t_ms) = window_ms(signal, r);
    match super::filtered(signal, r) {
        Some((first, values)) => {
            let trace = samples
                .filter_map(|i| {
                    let v = values.get(usize::try_from((i as u64).checked_sub(first)?).ok()?)?;
                    Some((t_ms(i), *v))
                })
                .collect();
            curves.insert(0, (cfc_label(kind), CFC_TRACE, trace));
            title
        }
        None => format!(
            "{quantity}: {} not drawn",
            crate::report::filter::name(&kind)
        ),
    }
}

/// The deceleration panel of impact `r` (`accel`: measured over its window; `models`: the
/// fits'): with a verdict against `spec`, over the window it watched too, with its band; on a
/// force channel, in N (no g axis).
fn decel_panel<'a>(
    signal: &Signal,
    spec: Option<&Spec>,
    r: &impact_core::ImpactReport,
    mut accel: Vec<(f64, f64)>,
    mut models: Vec<Curve>,
) -> Panel<'a> {
    let spec = SpecDrawn::of(spec, r, signal.force_kg.unwrap_or(1.0));
    let samples = drawn_samples(signal, r, spec.as_ref().map(|s| s.watched));
    if spec.is_some() {
        let (_, t_ms) = window_ms(signal, r);
        let base = r.baseline_m_s2 as f64;
        accel = samples
            .clone()
            .filter_map(|i| Some((t_ms(i), (signal.accel_m_s2)(i as u64)? - base)))
            .collect();
    }
    let title = cfc_trace(signal, r, samples, &mut models);
    let raw_label = if models.first().is_some_and(|c| c.1 == CFC_TRACE) {
        "raw"
    } else {
        "measured"
    };
    // A force channel's values back in N (the mass they were divided by).
    if let Some(m) = signal.force_kg {
        for q in accel
            .iter_mut()
            .chain(models.iter_mut().flat_map(|c| c.2.iter_mut()))
        {
            q.1 *= m;
        }
    }
    Panel {
        title: title.into(),
        x_label: "time from touch, ms",
        measured: accel,
        measured_label: raw_label,
        models,
        dashed: Vec::new(),
        log: false,
        g_axis: signal.force_kg.is_none(),
        legend: true,
        spec,
    }
}

/// The four kinematic panels of impact `r`: deceleration, velocity, deformation, and force
/// against deformation, measured with the fitted models over them.
fn kinematics_panels<'a>(
    signal: &Signal,
    spec: Option<&Spec>,
    r: &impact_core::ImpactReport,
) -> Vec<Panel<'a>> {
    let Measured {
        mut accel,
        mut velocity,
        mut deformation_mm,
        mut force_loop,
    } = Measured::of(signal, r);
    let v0 = r.kinematics.map(|k| k.impact_velocity_m_s as f64);
    let points = 4 * accel.len() as u64 + 1024;
    let [c_a, c_v, c_x, c_f] = model_curves(r, v0, signal.mass_kg, signal.rate_hz, points);
    let decel = decel_panel(signal, spec, r, std::mem::take(&mut accel), c_a);
    // A Δv the report refuses (a channel that does not hold DC) is not drawn either: no
    // velocity, deformation or loop from its integral.
    let refused = r.delta_v_m_s.is_none();
    if refused {
        velocity.clear();
        deformation_mm.clear();
        force_loop.clear();
    }
    // Without v0 the integrals start from rest: said in the titles; no loop (its panel left
    // out, not drawn empty).
    let known = v0.is_some();
    let force_title = match (known, signal.mass_kg.is_some()) {
        _ if refused => "force against deformation: no Δv (see the report)",
        (false, _) => {
            force_loop.clear();
            "force against deformation: needs v0"
        }
        // (On a force channel without a mass, its force over 1 kg times 1 kg: N.)
        (true, true) => "force against deformation, N",
        (true, false) if signal.force_kg.is_some() => "force against deformation, N",
        (true, false) => "deceleration against deformation, m/s²",
    };
    let loop_drawn = known && !refused;
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
    let panel = |title, x_label, measured, models, g_axis, legend| Panel {
        title,
        x_label,
        measured,
        measured_label: "measured",
        models,
        dashed: Vec::new(),
        log: false,
        g_axis,
        legend,
        spec: None,
    };
    // A Δv refused leaves the deceleration only, its title saying why the integrals are not
    // drawn.
    if refused {
        return vec![Panel {
            title: format!("{}; Δv unknown: no velocity or deformation", decel.title).into(),
            ..decel
        }];
    }
    let mut panels = vec![
        decel,
        panel(
            vel_title.into(),
            "time from touch, ms",
            velocity,
            c_v,
            false,
            false,
        ),
        panel(
            def_title.into(),
            "time from touch, ms",
            deformation_mm,
            c_x,
            false,
            false,
        ),
    ];
    if loop_drawn {
        panels.push(panel(
            force_title.into(),
            "deformation, mm",
            force_loop,
            c_f,
            false,
            false,
        ));
    }
    panels
}

/// The SRS and PVSS panels of impact `r` (empty where it has no spectra).
fn spectrum_panels<'a>(r: &impact_core::ImpactReport) -> [Panel<'a>; 2] {
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
    [
        Panel {
            title: "SRS (maximax), m/s² (left) and g (right)".into(),
            x_label: "natural frequency, Hz",
            measured: srs,
            measured_label: "SRS",
            models: Vec::new(),
            dashed: Vec::new(),
            log: true,
            g_axis: true,
            legend: false,
            spec: None,
        },
        Panel {
            title: "pseudo-velocity shock spectrum, m/s".into(),
            x_label: "natural frequency, Hz",
            measured: pvss,
            measured_label: "PVSS",
            models: Vec::new(),
            dashed: Vec::new(),
            log: true,
            g_axis: false,
            legend: false,
            spec: None,
        },
    ]
}
