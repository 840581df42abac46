//! Numerical stability sweep: every model × solver × precision over parameters spanning many
//! orders of magnitude; each result is finite and within the solver's stated bound, or the
//! solver says it could not resolve the contact.

use impact_core::model::{KelvinVoigt, Linear, Model, Nonlinear, TwoPhase};
use impact_core::{solve, ContactLaw, Impact, Method, Settings};
use serde::Serialize;

use crate::simulate::model_f32;
use crate::testkit::compare::{max_relative_error, widen};

/// The bound each solver states, relative to the exact result (largest over the fields).
pub fn stated_bound(method: Method, f32: bool, rtol: f64) -> f64 {
    match (method, f32) {
        (Method::Exact, false) => 1e-9,
        (Method::Exact, true) => 1e-4,
        (Method::Adaptive, false) => 100.0 * rtol,
        (Method::Adaptive, true) => 100.0 * rtol.max(1e-6),
        // Fixed steps accepted only at h * max_rate <= 0.5: that bounds the error too.
        (Method::Rk4, _) => 1e-2,
        (Method::Verlet, _) => 5e-2,
        (Method::Euler, _) => 0.5,
    }
}

/// The bound a solver states on a target with its own dynamics: the wall's, but for the
/// adaptive solver in f32, 3e-4. A light target carried along on a soft damped mount makes
/// the crush time a flat maximum tens of thousands of contact time scales in: its condition
/// number reaches ~500 (Kelvin–Voigt, a target 1000× lighter, measured), so one f32 rounding
/// of the force (6e-8) moves it by 3e-5, and the roundings of a whole solve by up to 1.8e-4
/// (16 copies of the case that agree to 2e-13 in f64), while every other field stays within
/// 1e-7. f64 keeps the wall's bound.
pub fn stated_bound_on_target(method: Method, f32: bool, rtol: f64) -> f64 {
    match (method, f32) {
        (Method::Adaptive, true) => 3e-4f64.max(stated_bound(method, f32, rtol)),
        _ => stated_bound(method, f32, rtol),
    }
}

/// Resolved results outside their bound, and non-finite ones, over `rows`.
pub fn failures(rows: &[Row]) -> u32 {
    rows.iter().map(|r| r.out_of_bound + r.non_finite).sum()
}

/// One row of the table: a model, a solver and a precision over the whole grid.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Row {
    pub model: String,
    pub solver: String,
    pub precision: String,
    pub cases: u32,
    pub resolved: u32,
    pub unresolved: u32,
    /// Resolved but outside the stated bound (must be 0).
    pub out_of_bound: u32,
    /// Not finite (must be 0).
    pub non_finite: u32,
    pub max_error: f64,
    pub bound: f64,
    /// Worst case, for the record.
    pub worst: String,
}

impl Row {
    /// The row for `model`, `solver` and `precision` in `rows`, added (with `bound`) if new.
    pub fn find_or_add<'a>(
        rows: &'a mut Vec<Row>,
        model: &str,
        solver: &str,
        precision: &str,
        bound: f64,
    ) -> &'a mut Row {
        match rows
            .iter()
            .position(|r| r.model == model && r.solver == solver && r.precision == precision)
        {
            Some(i) => &mut rows[i],
            None => {
                rows.push(Row {
                    model: model.into(),
                    solver: solver.into(),
                    precision: precision.into(),
                    bound,
                    ..Row::default()
                });
                rows.last_mut().expect("just pushed")
            }
        }
    }

    /// Counts one case: `None` if the solver declined, else its largest relative error and the
    /// field it is in; `desc` names the case for the worst one.
    pub fn tally(&mut self, error: Option<(f64, &str)>, desc: &str) {
        self.cases += 1;
        let Some((err, field)) = error else {
            self.unresolved += 1;
            return;
        };
        if !err.is_finite() {
            self.non_finite += 1;
            return;
        }
        self.resolved += 1;
        if err > self.bound {
            self.out_of_bound += 1;
        }
        if err > self.max_error {
            self.max_error = err;
            self.worst = format!("{desc}: {field}");
        }
    }
}

/// Grid of impacts and laws: `(description, model, impact)`.
pub fn grid(full: bool) -> Vec<(String, Model<f64>, Impact<f64>)> {
    let ratios: &[f64] = if full {
        &[1.0, 1e3, 1e6, 1e9, 1e12, 1e14]
    } else {
        &[1.0, 1e6, 1e14]
    };
    let speeds: &[f64] = if full {
        &[1e-6, 1e-3, 1.0, 1e3]
    } else {
        &[1e-6, 1.0, 1e3]
    };
    let zetas: &[f64] = if full {
        &[0.0, 0.1, 1.0, 10.0]
    } else {
        &[0.0, 1.0, 10.0]
    };
    let ps: &[f64] = if full {
        &[0.0, 0.1, 1.0, 10.0, 1e3]
    } else {
        &[0.0, 1.0, 1e3]
    };
    let ns: &[f64] = &[1.0, 1.5, 2.0];
    let mut out = Vec::new();
    for &r in ratios {
        for &v0 in speeds {
            let impact = Impact::new(1.0, v0);
            out.push((
                format!("linear k/m={r:e} v0={v0:e}"),
                Model::Linear(Linear { k: r }),
                impact,
            ));
            for &z in zetas {
                let c = 2.0 * z * r.sqrt();
                out.push((
                    format!("kelvin-voigt k/m={r:e} zeta={z} v0={v0:e}"),
                    Model::KelvinVoigt(KelvinVoigt { k: r, c }),
                    impact,
                ));
                out.push((
                    format!("two-phase kc/m={r:e} kr=4kc zeta={z} v0={v0:e}"),
                    Model::TwoPhase(TwoPhase {
                        kc: r,
                        kr: 4.0 * r,
                        c: 2.0 * z * (4.0 * r).sqrt(),
                        permanent_m: None,
                    }),
                    impact,
                ));
            }
            for &p in ps {
                for &n in ns {
                    out.push((
                        format!("nonlinear k/m={r:e} n={n} c*v0={p} v0={v0:e}"),
                        Model::Nonlinear(Nonlinear { k: r, c: p / v0, n }),
                        impact,
                    ));
                }
            }
        }
    }
    out
}

/// The solver settings swept.
pub fn settings(full: bool) -> Vec<Settings<f64>> {
    let mut v = vec![
        Settings::exact(),
        Settings::adaptive(1e-8),
        Settings::adaptive(1e-12),
    ];
    let steps: &[u32] = if full {
        &[4, 64, 1024, 100_000]
    } else {
        &[4, 256]
    };
    for &n in steps {
        for m in [Method::Euler, Method::Verlet, Method::Rk4] {
            v.push(Settings::fixed(m, n));
        }
    }
    v
}

/// Runs the sweep.
pub fn run(full: bool) -> Vec<Row> {
    let grid = grid(full);
    let mut rows: Vec<Row> = Vec::new();
    for s in settings(full) {
        for f32 in [false, true] {
            if f32 && s.method == Method::Adaptive && s.rtol < 1e-6 {
                continue;
            }
            for (desc, model, impact) in &grid {
                let Ok(exact) = model.exact(impact) else {
                    continue;
                };
                let result = if f32 {
                    let s32 = Settings {
                        method: s.method,
                        steps: s.steps,
                        rtol: s.rtol as f32,
                    };
                    solve(
                        &model_f32(model),
                        &Impact::new(impact.mass_kg as f32, impact.v0_m_s as f32),
                        &s32,
                    )
                    .map(|o| widen(&o))
                } else {
                    solve(model, impact, &s)
                };
                let key = (
                    model.name(),
                    s.method.name(),
                    if f32 { "f32" } else { "f64" },
                );
                let label = match s.method {
                    Method::Exact => key.1.to_string(),
                    Method::Adaptive => format!("adaptive {:.0e}", s.rtol),
                    _ => format!("{} {}", key.1, s.steps),
                };
                let row = Row::find_or_add(
                    &mut rows,
                    key.0,
                    &label,
                    key.2,
                    stated_bound(s.method, f32, s.rtol),
                );
                row.tally(result.ok().map(|o| max_relative_error(&o, &exact)), desc);
            }
        }
    }
    rows
}

/// The table as text.
pub fn table(rows: &[Row]) -> String {
    let mut s = format!(
        "{:<13} {:<16} {:<5} {:>6} {:>9} {:>10} {:>6} {:>10} {:>9}  worst case\n",
        "model", "solver", "prec", "cases", "resolved", "unresolved", "out", "max error", "bound"
    );
    for r in rows {
        s.push_str(&format!(
            "{:<13} {:<16} {:<5} {:>6} {:>9} {:>10} {:>6} {:>10.2e} {:>9.0e}  {}\n",
            r.model,
            r.solver,
            r.precision,
            r.cases,
            r.resolved,
            r.unresolved,
            r.out_of_bound + r.non_finite,
            r.max_error,
            r.bound,
            r.worst
        ));
    }
    s
}
