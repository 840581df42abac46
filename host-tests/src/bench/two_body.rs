//! Targets in the benchmarks: the work-precision sweep (time against error) and the
//! stability sweep (every law and solver over targets from a feather to a wall).

use std::time::{Duration, Instant};

use impact_core::model::{Hertz, KelvinVoigt, Linear, Model, TwoPhase};
use impact_core::two_body::{self, Target, TargetOutcome};
use impact_core::{ContactLaw, Error, Impact, Method, Settings};

use crate::bench::precision::Point;
use crate::bench::stability::{stated_bound_on_target, Row};
use crate::simulate::model_f32;
use crate::simulate::two_body::{narrow, widen};

/// The fields compared: contact time, crush time, deformation, force, both velocities.
fn fields(o: &TargetOutcome<f64>) -> [(&'static str, f64); 6] {
    [
        ("contact_time_s", o.contact_time_s),
        ("crush_time_s", o.crush_time_s),
        ("max_deformation_m", o.max_deformation_m),
        ("peak_force_n", o.peak_force_n),
        ("rebound_velocity_m_s", o.rebound_velocity_m_s),
        ("target_velocity_m_s", o.target_velocity_m_s),
    ]
}

/// Largest relative error over the fields (velocities relative to the approach speed, which
/// they may cross zero beside).
fn error(o: &TargetOutcome<f64>, reference: &TargetOutcome<f64>, v0: f64) -> (f64, &'static str) {
    let mut worst = (0.0, "");
    for ((name, got), (_, want)) in fields(o).iter().zip(fields(reference)) {
        let scale = if name.ends_with("_m_s") {
            v0
        } else {
            want.abs()
        };
        let e = ((got - want) / scale).abs();
        let e = if e.is_nan() { f64::INFINITY } else { e };
        if e > worst.0 {
            worst = (e, name);
        }
    }
    worst
}

/// The reference: the closed form where there is one, else Dormand–Prince at 1e-13.
fn reference(
    model: &Model<f64>,
    impact: &Impact<f64>,
    t: &Target<f64>,
) -> Option<TargetOutcome<f64>> {
    two_body::solve(model, impact, t, &Settings::exact())
        .or_else(|_| two_body::solve(model, impact, t, &Settings::adaptive(1e-13)))
        .ok()
}

/// A named law, impact and target.
pub type Case = (&'static str, Model<f64>, Impact<f64>, Target<f64>);

/// `(name, law, impact, target)`: the seed-001 bench body on a damped mount, the seed-000
/// steel ball on a free twin and on a sprung plate.
pub fn cases() -> Vec<Case> {
    let bench = Impact::new(0.06, 1.3357);
    let ball = Impact::new(8.4e-3, 1.0);
    let mount = Target::spring_mass(0.3, 4.0e4, 12.0).expect("valid mount");
    vec![
        (
            "linear-on-mount",
            Model::Linear(Linear { k: 2.0e5 }),
            bench,
            mount,
        ),
        (
            "two-phase-on-mount",
            Model::TwoPhase(TwoPhase {
                kc: 1.0e4,
                kr: 5.0e4,
                c: 5.0,
                permanent_m: None,
            }),
            bench,
            mount,
        ),
        (
            "hertz-on-mount",
            Model::Hertz(Hertz { k: 5.0e8 }),
            bench,
            mount,
        ),
        (
            "hertz-two-balls",
            Model::Hertz(Hertz { k: 1.0e10 }),
            ball,
            Target::spring_mass(8.4e-3, 0.0, 0.0).expect("valid ball"),
        ),
        (
            "hertz-on-plate",
            Model::Hertz(Hertz { k: 1.0e10 }),
            ball,
            Target::spring_mass(0.05, 1.0e7, 2.0).expect("valid plate"),
        ),
    ]
}

fn seconds(budget: Duration, mut f: impl FnMut()) -> f64 {
    let start = Instant::now();
    let mut calls = 0u32;
    while calls < 3 || start.elapsed() < budget {
        f();
        calls += 1;
    }
    start.elapsed().as_secs_f64() / calls as f64
}

/// Work-precision points for the target cases (exact where a closed form exists, adaptive at
/// each tolerance; f32 exact and adaptive 1e-5).
pub fn precision(budget: Duration) -> Vec<Point> {
    let mut out = Vec::new();
    for (name, model, impact, t) in cases() {
        let Some(reference) = reference(&model, &impact, &t) else {
            continue;
        };
        let mut settings = vec![Settings::exact()];
        for rtol in [1e-4, 1e-6, 1e-8, 1e-10, 1e-12] {
            settings.push(Settings::adaptive(rtol));
        }
        for s in &settings {
            let Ok(o) = two_body::solve(&model, &impact, &t, s) else {
                continue;
            };
            // The closed form against Dormand–Prince at 1e-13 (not against itself).
            let (err, field) = match (
                s.method,
                two_body::solve(&model, &impact, &t, &Settings::adaptive(1e-13)),
            ) {
                (Method::Exact, Ok(tight)) => error(&o, &tight, impact.v0_m_s),
                _ => error(&o, &reference, impact.v0_m_s),
            };
            let secs = seconds(budget, || {
                let _ = std::hint::black_box(two_body::solve(
                    std::hint::black_box(&model),
                    &impact,
                    &t,
                    s,
                ));
            });
            out.push(point(
                name,
                &model,
                s.method,
                "f64",
                s.rtol,
                secs,
                err,
                field,
                o.rhs_evaluations,
            ));
        }
        let (m32, i32_, t32) = (
            model_f32(&model),
            Impact::new(impact.mass_kg as f32, impact.v0_m_s as f32),
            narrow(&t),
        );
        for s in [Settings::<f32>::exact(), Settings::adaptive(1e-5)] {
            let Ok(o) = two_body::solve(&m32, &i32_, &t32, &s) else {
                continue;
            };
            let (err, field) = error(&widen(&o), &reference, impact.v0_m_s);
            let secs = seconds(budget, || {
                let _ = std::hint::black_box(two_body::solve(
                    std::hint::black_box(&m32),
                    &i32_,
                    &t32,
                    &s,
                ));
            });
            out.push(point(
                name,
                &model,
                s.method,
                "f32",
                s.rtol as f64,
                secs,
                err,
                field,
                o.rhs_evaluations,
            ));
        }
    }
    out
}

#[allow(clippy::too_many_arguments)]
fn point(
    case: &str,
    model: &Model<f64>,
    method: Method,
    precision: &str,
    rtol: f64,
    secs: f64,
    err: f64,
    field: &str,
    evals: u32,
) -> Point {
    Point {
        case: case.into(),
        model: model.name().into(),
        solver: method.name().into(),
        precision: precision.into(),
        setting: if method == Method::Adaptive {
            rtol
        } else {
            0.0
        },
        seconds_per_impact: secs,
        max_relative_error: err,
        worst_field: field.into(),
        rhs_evaluations: evals,
    }
}

/// The stability sweep over targets: impactor mass and speed over six and five decades, target
/// mass from 1e-3 to 1e9 of the impactor's, mount frequency from none (a free body) to 100×
/// the contact's, undamped and ζ = 0.3; every law with a closed form on the target is also
/// solved adaptively and compared with it, Hertz adaptively against 1e-13.
pub fn stability(full: bool) -> Vec<Row> {
    let masses: &[f64] = if full {
        &[1e-4, 1e-2, 1.0, 1e2]
    } else {
        &[1e-3, 1.0]
    };
    let speeds: &[f64] = if full {
        &[1e-3, 1e-1, 1.0, 1e2]
    } else {
        &[1e-2, 10.0]
    };
    let ratios: &[f64] = if full {
        &[1e-3, 1e-1, 1.0, 1e3, 1e9]
    } else {
        &[1e-2, 1.0, 1e9]
    };
    let freq: &[f64] = &[0.0, 0.1, 1.0, 100.0];
    let mut rows: Vec<Row> = Vec::new();
    let solvers: Vec<Settings<f64>> = vec![
        Settings::exact(),
        Settings::adaptive(1e-6),
        Settings::adaptive(1e-10),
    ];
    for &m1 in masses {
        for &v0 in speeds {
            let impact = Impact::new(m1, v0);
            // Laws sized so the contact lasts ~1 ms at this mass.
            let k_lin = m1 * (std::f64::consts::PI / 1e-3f64).powi(2);
            let laws = [
                Model::Linear(Linear { k: k_lin }),
                Model::KelvinVoigt(KelvinVoigt {
                    k: k_lin,
                    c: 0.2 * 2.0 * (k_lin * m1).sqrt(),
                }),
                Model::TwoPhase(TwoPhase {
                    kc: k_lin,
                    kr: 4.0 * k_lin,
                    c: 0.1 * (k_lin * m1).sqrt(),
                    permanent_m: None,
                }),
                Model::Hertz(Hertz {
                    k: k_lin / (v0 * 1e-3 / std::f64::consts::PI).sqrt(),
                }),
            ];
            for law in laws {
                for &ratio in ratios {
                    let m2 = m1 * ratio;
                    for &f in freq {
                        for zeta in [0.0, 0.3] {
                            let k2 = m2 * (f * std::f64::consts::PI / 1e-3).powi(2);
                            let c2 = if k2 > 0.0 {
                                2.0 * zeta * (k2 * m2).sqrt()
                            } else {
                                0.0
                            };
                            let Ok(t) = Target::spring_mass(m2, k2, c2) else {
                                continue;
                            };
                            let Some(reference) = reference(&law, &impact, &t) else {
                                continue;
                            };
                            let desc =
                                format!("m1 {m1:e} v0 {v0:e} m2/m1 {ratio:e} f {f} zeta {zeta}");
                            for s in &solvers {
                                let mut record = |precision: &str, f32: bool, result: Result<TargetOutcome<f64>, Error>| {
                                    let label = match s.method {
                                        Method::Exact => "exact".to_string(),
                                        _ => format!("adaptive {:.0e}", s.rtol),
                                    };
                                    let name = format!("{}+target", law.name());
                                    Row::find_or_add(
                                        &mut rows,
                                        &name,
                                        &label,
                                        precision,
                                        stated_bound_on_target(s.method, f32, s.rtol),
                                    )
                                    .tally(result.ok().map(|o| error(&o, &reference, v0)), &desc);
                                };
                                let has_exact = t.is_free_body()
                                    || law.affine(impact_core::model::Phase::Compression).is_some();
                                if s.method == Method::Exact && !has_exact {
                                    continue;
                                }
                                record("f64", false, two_body::solve(&law, &impact, &t, s));
                                if s.method == Method::Exact || s.rtol >= 1e-6 {
                                    let s32 = Settings {
                                        method: s.method,
                                        steps: s.steps,
                                        rtol: s.rtol as f32,
                                    };
                                    let r32 = two_body::solve(
                                        &model_f32(&law),
                                        &Impact::new(m1 as f32, v0 as f32),
                                        &narrow(&t),
                                        &s32,
                                    )
                                    .map(|o| widen(&o));
                                    record("f32", true, r32);
                                }
                            }
                        }
                    }
                }
            }
        }
    }
    rows
}
