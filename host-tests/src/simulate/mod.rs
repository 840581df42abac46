//! `impact simulate`: one model impact from command-line parameters, as a table or JSON.

pub mod figure;
pub mod two_body;

use std::time::Instant;

use clap::{Args, ValueEnum};
use impact_core::model::{Body, Hertz, KelvinVoigt, Linear, Model, Nonlinear, TwoPhase};
use impact_core::{solve, Error, Impact, ImpactOutcome, Method, Real, Settings};
use serde::Serialize;

use crate::testkit::compare::widen;

/// The contact laws the tool knows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ModelName {
    Hertz,
    Linear,
    KelvinVoigt,
    TwoPhase,
    Nonlinear,
}

/// The solvers the tool offers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum SolverName {
    Exact,
    Rk4,
    Verlet,
    Euler,
    Adaptive,
}

impl SolverName {
    pub fn method(self) -> Method {
        match self {
            SolverName::Exact => Method::Exact,
            SolverName::Rk4 => Method::Rk4,
            SolverName::Verlet => Method::Verlet,
            SolverName::Euler => Method::Euler,
            SolverName::Adaptive => Method::Adaptive,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Precision {
    F32,
    F64,
}

/// Model parameters, shared by `simulate` and the scene options of other commands.
#[derive(Args, Clone, Debug, Default)]
#[command(next_help_heading = "Model parameters")]
pub struct ModelArgs {
    /// Stiffness: N/m (linear, kelvin-voigt), N/m^1.5 (hertz), N/m^n (nonlinear).
    #[arg(long)]
    pub stiffness: Option<f64>,
    /// Damping: N s/m (kelvin-voigt, two-phase restitution) or s/m (nonlinear).
    #[arg(long)]
    pub damping: Option<f64>,
    /// Exponent n of the nonlinear law k x^n (1 + c v) [default: 1; 1.5 = Hunt–Crossley].
    #[arg(long)]
    pub exponent: Option<f64>,
    /// Two-phase compression stiffness, N/m.
    #[arg(long)]
    pub kc: Option<f64>,
    /// Two-phase restitution stiffness, N/m.
    #[arg(long)]
    pub kr: Option<f64>,
    /// Two-phase permanent set, m [default: from force continuity].
    #[arg(long)]
    pub permanent: Option<f64>,
    /// Two-phase: measured maximum deformation, m; gives kc = m (v0 / x_m)^2 when --kc is absent.
    #[arg(long)]
    pub max_deformation: Option<f64>,
    /// Radius of body 1 at the contact, m (hertz; sizes linear and nonlinear n=1.5 too).
    #[arg(long)]
    pub radius: Option<f64>,
    /// Young's modulus of body 1, Pa.
    #[arg(long)]
    pub youngs: Option<f64>,
    /// Poisson's ratio of body 1.
    #[arg(long)]
    pub poisson: Option<f64>,
    /// Radius of body 2, m [default: flat wall].
    #[arg(long)]
    pub radius2: Option<f64>,
    /// Young's modulus of body 2, Pa [default: rigid].
    #[arg(long)]
    pub youngs2: Option<f64>,
    /// Poisson's ratio of body 2 [default: 0.3 if --youngs2 is given].
    #[arg(long)]
    pub poisson2: Option<f64>,
}

/// `impact simulate` options.
#[derive(Args, Clone, Debug)]
pub struct SimulateArgs {
    /// Contact law.
    #[arg(long, help_heading = "Model", value_enum)]
    pub model: ModelName,
    /// Mass of the impacting body, kg.
    #[arg(short = 'm', long, help_heading = "Model")]
    pub mass: f64,
    /// Approach speed at first touch, m/s.
    #[arg(long, help_heading = "Model")]
    pub v0: f64,
    #[command(flatten)]
    pub params: ModelArgs,
    /// Solver [default: exact, the most accurate; on a target, exact where a closed form
    /// exists (a free body; linear, Kelvin–Voigt, two-phase laws), else adaptive].
    #[arg(long, help_heading = "Solver", value_enum)]
    pub solver: Option<SolverName>,
    /// Relative tolerance of the adaptive solver.
    #[arg(long, help_heading = "Solver", default_value_t = 1e-10)]
    pub rtol: f64,
    /// Steps per contact time scale for fixed-step solvers.
    #[arg(long, help_heading = "Solver", default_value_t = 1000)]
    pub steps: u32,
    /// Arithmetic of the solver.
    #[arg(long, help_heading = "Solver", value_enum, default_value_t = Precision::F64)]
    pub precision: Precision,
    /// Solve the same impact N times and report the wall time per impact.
    #[arg(long, help_heading = "Solver")]
    pub repeat: Option<u32>,
    /// Print one JSON object instead of a table.
    #[arg(short = 'j', long, help_heading = "Output")]
    pub json: bool,
    #[command(flatten)]
    pub target: two_body::TargetArgs,
    /// With --plot against a wall and --model hertz: the linear spring of the same maximum
    /// deformation on the same axes (seed 000, Figs. 17–18).
    #[arg(long, help_heading = "Output", requires = "plot")]
    pub with_linear: bool,
}

/// A parameter problem, worded for the command line.
/// Why a model could not be built from the options.
#[derive(Debug, thiserror::Error)]
pub enum ModelError {
    /// An option the model needs (`option`: its name without `--`, and what else gives it).
    #[error("--{option} is required for --model {model}")]
    Missing {
        option: &'static str,
        model: &'static str,
    },
    /// A parameter out of its domain, named as its option.
    #[error("{}", crate::flags::core(*.0))]
    Core(#[from] Error),
}

/// Why `impact simulate` refused, or could not solve or draw.
#[derive(Debug, thiserror::Error)]
pub enum SimulateError {
    #[error(transparent)]
    Model(#[from] ModelError),
    /// A parameter out of its domain (or a contact not resolved), named as its option.
    #[error("{}", crate::flags::core(*.0))]
    Core(#[from] Error),
    /// The figure's trajectory could not be sampled (the core's words, its parameter by name).
    #[error(transparent)]
    Trajectory(Error),
    /// (Boxed: a target's error names its files.)
    #[error(transparent)]
    Target(Box<two_body::TargetError>),
    #[error("--with-linear: compares a Hertz contact with its linear spring; give --model hertz")]
    WithLinearNotHertz,
    #[error("--with-linear: against a wall only")]
    WithLinearTarget,
    #[error("--repeat: times the wall solvers; not with a target")]
    RepeatTarget,
    #[error("--repeat: must be at least 1")]
    RepeatZero,
    /// The figure could not be drawn (plotters' SVG backend).
    #[error(transparent)]
    Draw(#[from] plotters::drawing::DrawingAreaErrorKind<std::io::Error>),
    /// `--plot`: refused before any work, or its figure not written.
    #[error(transparent)]
    Plot(#[from] crate::plot::PlotError),
    #[error(transparent)]
    Json(#[from] serde_json::Error),
}

impl From<two_body::TargetError> for SimulateError {
    fn from(e: two_body::TargetError) -> Self {
        SimulateError::Target(Box::new(e))
    }
}

fn missing(option: &'static str, model: &'static str) -> ModelError {
    ModelError::Missing { option, model }
}

fn body(r: Option<f64>, e: Option<f64>, nu: Option<f64>, default_nu: f64) -> Body<f64> {
    Body {
        radius_m: r.unwrap_or(f64::INFINITY),
        youngs_pa: e.unwrap_or(f64::INFINITY),
        poisson: nu.unwrap_or(default_nu),
    }
}

impl ModelArgs {
    /// Hertz stiffness from --stiffness, or from the two bodies' geometry and elasticity.
    fn hertz(&self, model: &'static str) -> Result<Hertz<f64>, ModelError> {
        if let Some(k) = self.stiffness {
            return Ok(Hertz { k });
        }
        let radius = self
            .radius
            .ok_or_else(|| missing("stiffness (or --radius)", model))?;
        let youngs = self.youngs.ok_or_else(|| missing("youngs", model))?;
        let poisson = self.poisson.ok_or_else(|| missing("poisson", model))?;
        let b1 = body(Some(radius), Some(youngs), Some(poisson), 0.3);
        let b2 = body(
            self.radius2,
            self.youngs2,
            self.poisson2,
            if self.youngs2.is_some() { 0.3 } else { 0.0 },
        );
        Ok(Hertz::from_bodies(&b1, &b2)?)
    }

    /// Builds the model for `name` and the impact it will be used in.
    pub fn model(&self, name: ModelName, impact: &Impact<f64>) -> Result<Model<f64>, ModelError> {
        let model = match name {
            ModelName::Hertz => Model::Hertz(self.hertz("hertz")?),
            ModelName::Linear => match self.stiffness {
                Some(k) => Model::Linear(Linear { k }),
                None if self.radius.is_some() => {
                    let hertz = self.hertz("linear")?;
                    Model::Linear(Linear::matching_max_deformation(&hertz, impact)?)
                }
                None => {
                    return Err(missing(
                        "stiffness (or --radius/--youngs/--poisson to match Hertz)",
                        "linear",
                    ))
                }
            },
            ModelName::KelvinVoigt => Model::KelvinVoigt(KelvinVoigt {
                k: self
                    .stiffness
                    .ok_or_else(|| missing("stiffness", "kelvin-voigt"))?,
                c: self
                    .damping
                    .ok_or_else(|| missing("damping", "kelvin-voigt"))?,
            }),
            ModelName::TwoPhase => {
                let kc = match (self.kc, self.max_deformation) {
                    (Some(kc), _) => kc,
                    (None, Some(x_m)) => TwoPhase::compression_stiffness_for(impact, x_m),
                    (None, None) => return Err(missing("kc (or --max-deformation)", "two-phase")),
                };
                Model::TwoPhase(TwoPhase {
                    kc,
                    kr: self.kr.ok_or_else(|| missing("kr", "two-phase"))?,
                    c: self.damping.unwrap_or(0.0),
                    permanent_m: self.permanent,
                })
            }
            ModelName::Nonlinear => {
                let n = self.exponent.unwrap_or(1.0);
                let k = match self.stiffness {
                    Some(k) => k,
                    None if self.radius.is_some() && n == 1.5 => self.hertz("nonlinear")?.k,
                    None => return Err(missing("stiffness", "nonlinear")),
                };
                Model::Nonlinear(Nonlinear {
                    k,
                    c: self
                        .damping
                        .ok_or_else(|| missing("damping", "nonlinear"))?,
                    n,
                })
            }
        };
        Ok(model)
    }
}

/// The JSON report of `impact simulate` (exactly these fields, SI).
#[derive(Debug, Serialize)]
pub struct SimulateReport {
    pub max_deformation_m: f64,
    pub crush_time_s: f64,
    pub contact_time_s: f64,
    pub rebound_velocity_m_s: f64,
    pub cor: f64,
    pub peak_force_n: f64,
    /// Deformation at separation, where the contact force returned to zero, m (not the set a
    /// pad keeps once recovered: a Kelvin–Voigt pad's viscous part still holds it).
    pub separation_deformation_m: f64,
    pub solver: String,
    pub rhs_evaluations: u32,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub seconds_per_impact: Option<f64>,
}

/// Narrows a model to f32 (the board's arithmetic).
pub fn model_f32(m: &Model<f64>) -> Model<f32> {
    match *m {
        Model::Hertz(h) => Model::Hertz(Hertz { k: h.k as f32 }),
        Model::Linear(l) => Model::Linear(Linear { k: l.k as f32 }),
        Model::KelvinVoigt(l) => Model::KelvinVoigt(KelvinVoigt {
            k: l.k as f32,
            c: l.c as f32,
        }),
        Model::TwoPhase(l) => Model::TwoPhase(TwoPhase {
            kc: l.kc as f32,
            kr: l.kr as f32,
            c: l.c as f32,
            permanent_m: l.permanent_m.map(|x| x as f32),
        }),
        Model::Nonlinear(l) => Model::Nonlinear(Nonlinear {
            k: l.k as f32,
            c: l.c as f32,
            n: l.n as f32,
        }),
    }
}

/// Solves `repeat` times (at least once); returns the outcome and the seconds per solve.
fn timed<R: Real>(
    model: &Model<R>,
    impact: &Impact<R>,
    settings: &Settings<R>,
    repeat: u32,
) -> Result<(ImpactOutcome<f64>, f64), Error> {
    let start = Instant::now();
    let mut out = solve(model, impact, settings)?;
    for _ in 1..repeat {
        out = solve(
            std::hint::black_box(model),
            std::hint::black_box(impact),
            settings,
        )?;
    }
    Ok((
        widen(&out),
        start.elapsed().as_secs_f64() / repeat.max(1) as f64,
    ))
}

/// What `impact simulate` found: a contact with a wall or with a target.
pub enum Outcome {
    Wall(SimulateReport),
    Target(Box<two_body::TargetReport>),
}

/// Runs `impact simulate`, on the target if one is given.
pub fn run_any(args: &SimulateArgs) -> Result<Outcome, SimulateError> {
    if !args.target.given() {
        let report = run(args)?;
        if let Some(path) = &args.target.plot {
            crate::plot::check_output::<&std::path::Path>(path, &[])?;
            let impact = Impact::new(args.mass, args.v0);
            let model = args.params.model(args.model, &impact)?;
            let mut models = vec![(args.model, model)];
            if args.with_linear {
                let Model::Hertz(h) = model else {
                    return Err(SimulateError::WithLinearNotHertz);
                };
                let l = impact_core::model::Linear::matching_max_deformation(&h, &impact)?;
                models.push((ModelName::Linear, Model::Linear(l)));
            }
            figure::wall_contact(&models, &impact, path)?;
            crate::errln!("wrote {}", path.display());
        }
        return Ok(Outcome::Wall(report));
    }
    if args.with_linear {
        return Err(SimulateError::WithLinearTarget);
    }
    if args.repeat.is_some() {
        return Err(SimulateError::RepeatTarget);
    }
    let impact = Impact::new(args.mass, args.v0);
    impact.validate()?;
    let model = args.params.model(args.model, &impact)?;
    two_body::run(args, &model).map(|r| Outcome::Target(Box::new(r)))
}

/// Runs `impact simulate` against a wall.
pub fn run(args: &SimulateArgs) -> Result<SimulateReport, SimulateError> {
    let impact = Impact::new(args.mass, args.v0);
    impact.validate()?;
    let model = args.params.model(args.model, &impact)?;
    let method = args.solver.unwrap_or(SolverName::Exact).method();
    let settings = match method {
        Method::Exact => Settings::exact(),
        Method::Adaptive => Settings::adaptive(args.rtol),
        m => Settings::fixed(m, args.steps),
    };
    if args.repeat == Some(0) {
        return Err(SimulateError::RepeatZero);
    }
    let repeat = args.repeat.unwrap_or(1);
    let (outcome, seconds) = match args.precision {
        Precision::F64 => timed(&model, &impact, &settings, repeat),
        Precision::F32 => {
            let settings32 = Settings {
                method: settings.method,
                steps: settings.steps,
                rtol: settings.rtol as f32,
            };
            timed(
                &model_f32(&model),
                &Impact::new(args.mass as f32, args.v0 as f32),
                &settings32,
                repeat,
            )
        }
    }?;
    Ok(SimulateReport {
        max_deformation_m: outcome.max_deformation_m,
        crush_time_s: outcome.crush_time_s,
        contact_time_s: outcome.contact_time_s,
        rebound_velocity_m_s: outcome.rebound_velocity_m_s,
        cor: outcome.cor,
        peak_force_n: outcome.peak_force_n,
        separation_deformation_m: outcome.permanent_deformation_m,
        solver: method.name().to_string(),
        rhs_evaluations: outcome.rhs_evaluations,
        seconds_per_impact: args.repeat.map(|_| seconds),
    })
}

/// A readable table of the report.
pub fn table(r: &SimulateReport) -> String {
    let mut s = String::new();
    let rows: [(&str, f64, &str); 7] = [
        ("max deformation", r.max_deformation_m, "m"),
        ("crush time", r.crush_time_s, "s"),
        ("contact time", r.contact_time_s, "s"),
        ("rebound velocity", r.rebound_velocity_m_s, "m/s"),
        ("COR", r.cor, ""),
        ("peak force", r.peak_force_n, "N"),
        ("x at separation", r.separation_deformation_m, "m"),
    ];
    for (name, value, unit) in rows {
        s.push_str(&format!("{name:<24}{value:>22.12e} {unit}\n"));
    }
    s.push_str(&format!(
        "{:<24}{:>22} ({} force evaluations)\n",
        "solver", r.solver, r.rhs_evaluations
    ));
    if let Some(t) = r.seconds_per_impact {
        s.push_str(&format!("{:<24}{:>22.3e} s\n", "time per impact", t));
    }
    s
}
