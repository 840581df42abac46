//! `impact simulate` on a target with its own dynamics: the options, the report and its plot.

use std::path::{Path, PathBuf};

use clap::Args;
use impact_core::model::Model;
use impact_core::two_body::free::{after, target_at, FreeResponse};
use impact_core::two_body::{self, Sample, Target, TargetOutcome, MAX_STATES};
use impact_core::{ContactLaw, Impact, Method, Settings};
use plotters::prelude::*;
use serde::{Deserialize, Serialize};

use super::{model_f32, Precision, SimulateArgs, SimulateError};

/// The target the impactor hits instead of a wall (seed 000, section 3.2).
#[derive(Args, Clone, Debug, Default)]
pub struct TargetArgs {
    /// Target mass m2, kg: a body on a spring and damper to ground (free without them).
    #[arg(long, help_heading = "Target", conflicts_with = "target")]
    pub target_mass: Option<f64>,
    /// Target spring to ground k2, N/m [default: 0, a free body].
    #[arg(long, help_heading = "Target", requires = "target_mass")]
    pub target_stiffness: Option<f64>,
    /// Target damper to ground c2, N s/m [default: 0].
    #[arg(long, help_heading = "Target", requires = "target_mass")]
    pub target_damping: Option<f64>,
    /// A linear target in state-space form, JSON `{"a": [[..]], "b": [..], "c": [[..], [..]],
    /// "d": [0, 0]}`: input the contact force (N), outputs the contact point's displacement (m)
    /// and velocity (m/s), at most 6 states.
    #[arg(long, help_heading = "Target")]
    pub target: Option<PathBuf>,
    /// Draw into this SVG or PNG (by its extension): against a wall the deformation, velocity and force against time and
    /// the force against deformation; on a target the impactor's and target's displacement,
    /// velocity and the contact force over the contact and the ring-down.
    #[arg(short = 'p', long, help_heading = "Output", value_name = "FILE")]
    pub plot: Option<PathBuf>,
}

impl TargetArgs {
    /// True if a target was given.
    pub fn given(&self) -> bool {
        self.target_mass.is_some() || self.target.is_some()
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct StateSpaceFile {
    a: Vec<Vec<f64>>,
    b: Vec<f64>,
    c: Vec<Vec<f64>>,
    #[serde(default)]
    d: Option<Vec<f64>>,
}

/// Where a state-space target came from, as its errors name it.
#[derive(Clone, Debug, PartialEq)]
pub enum TargetAt {
    /// `--target FILE`.
    Option(PathBuf),
    /// A scene file's `target`: written in it (no file), or a file it names.
    Scene {
        scene: PathBuf,
        file: Option<PathBuf>,
    },
}

impl std::fmt::Display for TargetAt {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            TargetAt::Option(p) => write!(f, "--target {}", p.display()),
            TargetAt::Scene { scene, file: None } => write!(f, "{}: target", scene.display()),
            TargetAt::Scene {
                scene,
                file: Some(p),
            } => write!(f, "{}: target {}", scene.display(), p.display()),
        }
    }
}

/// Why the target could not be built (`--target FILE`, a scene file's `target`,
/// `--target-mass`).
#[derive(Debug, thiserror::Error)]
pub enum TargetError {
    /// The file could not be read (a secondary input: `-` is a file there).
    #[error("--target {}", crate::read_errors::input_file_message(.0))]
    Read(impact_io::ReadError),
    /// The file a scene file's `target` names could not be read.
    #[error("{}: target {}", .scene.display(), crate::read_errors::input_file_message(.error))]
    SceneRead {
        scene: PathBuf,
        error: Box<impact_io::ReadError>,
    },
    #[error("{at}: {source}")]
    Json {
        at: TargetAt,
        source: serde_json::Error,
    },
    #[error("{at}: A must have 1 to {MAX_STATES} rows, not {n}")]
    Rows { at: TargetAt, n: usize },
    #[error("{at}: A row {row} has {len} entries, not {n}")]
    Row {
        at: TargetAt,
        row: usize,
        len: usize,
        n: usize,
    },
    #[error("{at}: B has {len} entries, not {n}")]
    B { at: TargetAt, len: usize, n: usize },
    #[error("{at}: C must be two rows (displacement, velocity) of {n} entries")]
    C { at: TargetAt, n: usize },
    #[error("{at}: D must have 2 entries, not {len}")]
    D { at: TargetAt, len: usize },
    /// The file's system refused by the core (its reason, without the parameter's name).
    #[error("{at}: {}", reason(.error))]
    Invalid {
        at: TargetAt,
        error: impact_core::Error,
    },
    /// A scene file's `target` neither a file's name nor a state space.
    #[error("{}: target must be the name of a state-space target's file or the state space itself ({{\"a\": .., \"b\": .., \"c\": ..}})", .scene.display())]
    SceneKind { scene: PathBuf },
    /// `--target-mass` and its spring refused by the core, named as its option.
    #[error("{}", crate::flags::core(*.0))]
    SpringMass(impact_core::Error),
    #[error("no target given (--target-mass or --target)")]
    NotGiven,
}

pub(crate) fn read_state_space(path: &Path) -> Result<Target<f64>, TargetError> {
    let bytes = impact_io::read_limited(path, 1 << 20, "target file").map_err(TargetError::Read)?;
    state_space_json(&bytes, TargetAt::Option(path.to_path_buf()))
}

/// A scene file's `target` (`scene` the scene file's path): the name of a file, relative to
/// the scene file's folder, or the state space's object itself.
pub(crate) fn scene_state_space(
    scene: &Path,
    value: &serde_json::Value,
) -> Result<Target<f64>, TargetError> {
    let kind = || TargetError::SceneKind {
        scene: scene.to_path_buf(),
    };
    match value {
        serde_json::Value::String(_) => {
            let path = scene_target_path(scene, value).ok_or_else(kind)?;
            let bytes =
                impact_io::read_limited(&path, 1 << 20, "target file").map_err(|error| {
                    TargetError::SceneRead {
                        scene: scene.to_path_buf(),
                        error: Box::new(error),
                    }
                })?;
            let at = TargetAt::Scene {
                scene: scene.to_path_buf(),
                file: Some(path),
            };
            state_space_json(&bytes, at)
        }
        serde_json::Value::Object(_) => {
            let at = TargetAt::Scene {
                scene: scene.to_path_buf(),
                file: None,
            };
            match StateSpaceFile::deserialize(value) {
                Ok(f) => state_space(f, &at),
                Err(source) => Err(TargetError::Json { at, source }),
            }
        }
        _ => Err(kind()),
    }
}

/// The file a scene file's `target` names, relative to the scene file's folder (`None`
/// unless the value is a string that is not empty).
pub(crate) fn scene_target_path(scene: &Path, value: &serde_json::Value) -> Option<PathBuf> {
    let name = Path::new(value.as_str().filter(|n| !n.is_empty())?);
    Some(match scene.parent() {
        Some(dir) if name.is_relative() => dir.join(name),
        _ => name.to_path_buf(),
    })
}

/// The state space of a target file's JSON.
fn state_space_json(bytes: &[u8], at: TargetAt) -> Result<Target<f64>, TargetError> {
    match serde_json::from_slice(bytes) {
        Ok(f) => state_space(f, &at),
        Err(source) => Err(TargetError::Json { at, source }),
    }
}

/// The state space a file or a scene file's object holds, checked as the core checks it.
fn state_space(f: StateSpaceFile, at: &TargetAt) -> Result<Target<f64>, TargetError> {
    let p = || at.clone();
    let n = f.a.len();
    if n == 0 || n > MAX_STATES {
        return Err(TargetError::Rows { at: p(), n });
    }
    let mut a = [[0.0; MAX_STATES]; MAX_STATES];
    for (i, row) in f.a.iter().enumerate() {
        if row.len() != n {
            return Err(TargetError::Row {
                at: p(),
                row: i,
                len: row.len(),
                n,
            });
        }
        a[i][..n].copy_from_slice(row);
    }
    if f.b.len() != n {
        return Err(TargetError::B {
            at: p(),
            len: f.b.len(),
            n,
        });
    }
    let mut b = [0.0; MAX_STATES];
    b[..n].copy_from_slice(&f.b);
    if f.c.len() != 2 || f.c.iter().any(|r| r.len() != n) {
        return Err(TargetError::C { at: p(), n });
    }
    let mut c = [[0.0; MAX_STATES]; 2];
    for (i, row) in f.c.iter().enumerate() {
        c[i][..n].copy_from_slice(row);
    }
    let d = match f.d.as_deref() {
        None => [0.0, 0.0],
        Some([x, y]) => [*x, *y],
        Some(other) => {
            return Err(TargetError::D {
                at: p(),
                len: other.len(),
            })
        }
    };
    Target::state_space(n, a, b, c, d).map_err(|error| TargetError::Invalid { at: p(), error })
}

/// The error's reason without its `--name:` prefix.
fn reason(e: &impact_core::Error) -> String {
    match e {
        impact_core::Error::InvalidParameter { reason, .. } => reason.to_string(),
        other => other.to_string(),
    }
}

/// Builds the target from the options.
pub fn build(args: &TargetArgs) -> Result<Target<f64>, TargetError> {
    match (&args.target, args.target_mass) {
        (Some(path), _) => read_state_space(path),
        (None, Some(m2)) => Target::spring_mass(
            m2,
            args.target_stiffness.unwrap_or(0.0),
            args.target_damping.unwrap_or(0.0),
        )
        .map_err(TargetError::SpringMass),
        (None, None) => Err(TargetError::NotGiven),
    }
}

/// The JSON report of `impact simulate` with a target (SI; null fields say why in
/// `null_reasons`).
#[derive(Debug, Serialize)]
pub struct TargetReport {
    pub contact_time_s: f64,
    pub crush_time_s: f64,
    pub max_deformation_m: f64,
    /// Deformation at separation, m (not the set a pad keeps once recovered).
    pub separation_deformation_m: f64,
    pub peak_force_n: f64,
    /// The impactor's, positive away from the target.
    pub rebound_velocity_m_s: f64,
    /// The contact point's at separation, positive in the impact direction.
    pub target_velocity_m_s: f64,
    pub target_displacement_m: f64,
    /// Relative separation speed over approach speed.
    pub cor: f64,
    pub target_energy_j: Option<f64>,
    pub target_work_j: Option<f64>,
    pub contact_work_j: Option<f64>,
    pub target_dissipated_j: Option<f64>,
    pub recontact: bool,
    pub recontact_time_s: Option<f64>,
    pub recontact_checked_until_s: f64,
    pub ring_amplitude_m: f64,
    pub ring_frequency_hz: Option<f64>,
    pub solver: String,
    pub rhs_evaluations: u32,
    pub null_reasons: std::collections::BTreeMap<&'static str, &'static str>,
}

/// `t` kept for the process, as a scene's target borrows it
/// ([`impact_core::two_body::SceneTarget::StateSpace`]; the board keeps its one in a static):
/// once per distinct target, so however many scenes are built from the same few files,
/// memory stays bounded by the targets given.
pub fn interned(t: Target<f32>) -> &'static Target<f32> {
    use std::collections::HashMap;
    use std::sync::Mutex;
    static KEPT: Mutex<Option<HashMap<Vec<u32>, &'static Target<f32>>>> = Mutex::new(None);
    // Keyed by the bits of every number (the order, A, B, C, the spring–mass's).
    let key: Vec<u32> = std::iter::once(t.n as u32)
        .chain(t.a.iter().flatten().map(|v| v.to_bits()))
        .chain(t.b.iter().map(|v| v.to_bits()))
        .chain(t.c.iter().flatten().map(|v| v.to_bits()))
        .chain(
            t.spring_mass
                .iter()
                .flat_map(|s| [s.mass_kg, s.stiffness_n_m, s.damping_n_s_m].map(f32::to_bits)),
        )
        .collect();
    let mut kept = KEPT.lock().unwrap_or_else(|e| e.into_inner());
    kept.get_or_insert_with(HashMap::new)
        .entry(key)
        .or_insert_with(|| Box::leak(Box::new(t)))
}

#[allow(clippy::needless_range_loop)]
pub fn narrow(t: &Target<f64>) -> Target<f32> {
    let mut a = [[0.0f32; MAX_STATES]; MAX_STATES];
    let mut b = [0.0f32; MAX_STATES];
    let mut c = [[0.0f32; MAX_STATES]; 2];
    for i in 0..MAX_STATES {
        for j in 0..MAX_STATES {
            a[i][j] = t.a[i][j] as f32;
        }
        b[i] = t.b[i] as f32;
        c[0][i] = t.c[0][i] as f32;
        c[1][i] = t.c[1][i] as f32;
    }
    Target {
        n: t.n,
        a,
        b,
        c,
        spring_mass: t.spring_mass.map(|s| two_body::SpringMass {
            mass_kg: s.mass_kg as f32,
            stiffness_n_m: s.stiffness_n_m as f32,
            damping_n_s_m: s.damping_n_s_m as f32,
        }),
    }
}

pub fn widen(o: &TargetOutcome<f32>) -> TargetOutcome<f64> {
    let mut z = [0.0; MAX_STATES];
    for (w, n) in z.iter_mut().zip(&o.target_state) {
        *w = *n as f64;
    }
    let f = |x: f32| x as f64;
    TargetOutcome {
        max_deformation_m: f(o.max_deformation_m),
        crush_time_s: f(o.crush_time_s),
        contact_time_s: f(o.contact_time_s),
        peak_force_n: f(o.peak_force_n),
        permanent_deformation_m: f(o.permanent_deformation_m),
        rebound_velocity_m_s: f(o.rebound_velocity_m_s),
        impactor_displacement_m: f(o.impactor_displacement_m),
        target_displacement_m: f(o.target_displacement_m),
        target_velocity_m_s: f(o.target_velocity_m_s),
        cor: f(o.cor),
        target_state: z,
        target_energy_j: o.target_energy_j.map(f),
        target_work_j: o.target_work_j.map(f),
        contact_work_j: o.contact_work_j.map(f),
        target_dissipated_j: o.target_dissipated_j.map(f),
        rhs_evaluations: o.rhs_evaluations,
    }
}

/// Runs `impact simulate` with a target.
pub fn run(args: &SimulateArgs, model: &Model<f64>) -> Result<TargetReport, SimulateError> {
    if let Some(path) = &args.target.plot {
        // Before the target file is read: a figure never writes over it.
        let inputs: Vec<_> = args.target.target.iter().map(|p| p.as_path()).collect();
        crate::plot::check_output(path, &inputs)?;
    }
    let t = build(&args.target)?;
    let impact = Impact::new(args.mass, args.v0);
    let closed_form = t.is_free_body()
        || model
            .affine(impact_core::model::Phase::Compression)
            .is_some();
    let method = match args.solver {
        Some(s) => s.method(),
        None if closed_form => Method::Exact,
        None => Method::Adaptive,
    };
    let settings = match method {
        Method::Exact => Settings::exact(),
        Method::Adaptive => Settings::adaptive(args.rtol),
        m => Settings::fixed(m, args.steps),
    };
    let outcome = match args.precision {
        Precision::F64 => two_body::solve(model, &impact, &t, &settings),
        Precision::F32 => {
            let s32 = Settings {
                method: settings.method,
                steps: settings.steps,
                rtol: settings.rtol as f32,
            };
            let impact32 = Impact::new(args.mass as f32, args.v0 as f32);
            two_body::solve(&model_f32(model), &impact32, &narrow(&t), &s32).map(|o| widen(&o))
        }
    }?;
    let free = after(&t, &outcome)?;
    if let Some(path) = &args.target.plot {
        plot(model, &impact, &t, &outcome, &free, path)?;
    }
    Ok(report(&t, &outcome, &free, method))
}

fn report(
    t: &Target<f64>,
    o: &TargetOutcome<f64>,
    free: &FreeResponse<f64>,
    method: Method,
) -> TargetReport {
    let mut null_reasons = std::collections::BTreeMap::new();
    if o.target_energy_j.is_none() {
        null_reasons.insert(
            "target_energy_j",
            "state-space-target: no mass or stiffness to define its energy (target_work_j is what the contact gave it)",
        );
    }
    let damped = t.spring_mass.is_some_and(|s| s.damping_n_s_m > 0.0);
    for (field, value) in [
        ("target_work_j", o.target_work_j),
        ("contact_work_j", o.contact_work_j),
        ("target_dissipated_j", o.target_dissipated_j),
    ] {
        if value.is_none() {
            let why = if t.spring_mass.is_none() && field == "target_dissipated_j" {
                "state-space-target: its dissipation is not defined without a damper"
            } else if damped || t.spring_mass.is_none() {
                "exact-solver: the closed form gives states, not energy integrals (use --solver adaptive)"
            } else {
                "not-computed"
            };
            null_reasons.insert(field, why);
        }
    }
    if free.recontact_s.is_none() {
        null_reasons.insert(
            "recontact_time_s",
            "no-recontact within recontact_checked_until_s",
        );
    }
    if free.ring_frequency_hz.is_none() {
        null_reasons.insert(
            "ring_frequency_hz",
            "no-ringing: a free body, an over-damped mount or fewer than three turning points",
        );
    }
    TargetReport {
        contact_time_s: o.contact_time_s,
        crush_time_s: o.crush_time_s,
        max_deformation_m: o.max_deformation_m,
        separation_deformation_m: o.permanent_deformation_m,
        peak_force_n: o.peak_force_n,
        rebound_velocity_m_s: o.rebound_velocity_m_s,
        target_velocity_m_s: o.target_velocity_m_s,
        target_displacement_m: o.target_displacement_m,
        cor: o.cor,
        target_energy_j: o.target_energy_j,
        target_work_j: o.target_work_j,
        contact_work_j: o.contact_work_j,
        target_dissipated_j: o.target_dissipated_j,
        recontact: free.recontact_s.is_some(),
        recontact_time_s: free.recontact_s,
        recontact_checked_until_s: free.checked_until_s,
        ring_amplitude_m: free.ring_amplitude_m,
        ring_frequency_hz: free.ring_frequency_hz,
        solver: method.name().to_string(),
        rhs_evaluations: o.rhs_evaluations,
        null_reasons,
    }
}

/// A readable table of the report.
pub fn table(r: &TargetReport) -> String {
    let mut s = String::new();
    let mut row = |name: &str, value: Option<f64>, unit: &str| {
        let v = value.map_or("—".to_string(), |v| format!("{v:.9e}"));
        s.push_str(&format!("{name:<26}{v:>18} {unit}\n"));
    };
    row("contact time", Some(r.contact_time_s), "s");
    row("crush time", Some(r.crush_time_s), "s");
    row("max deformation", Some(r.max_deformation_m), "m");
    row("x at separation", Some(r.separation_deformation_m), "m");
    row("peak force", Some(r.peak_force_n), "N");
    row(
        "rebound velocity",
        Some(r.rebound_velocity_m_s),
        "m/s (impactor, away)",
    );
    row(
        "target velocity",
        Some(r.target_velocity_m_s),
        "m/s (at separation)",
    );
    row("COR (relative)", Some(r.cor), "");
    row("target energy", r.target_energy_j, "J");
    row("work on target", r.target_work_j, "J");
    row("work into contact", r.contact_work_j, "J");
    row("target damper", r.target_dissipated_j, "J");
    row("ring amplitude", Some(r.ring_amplitude_m), "m");
    row("ring frequency", r.ring_frequency_hz, "Hz");
    match r.recontact_time_s {
        Some(t) => s.push_str(&format!(
            "{:<26}{:>18} at {t:.6e} s: the seed's single-hit assumption fails\n",
            "recontact", "yes"
        )),
        None => s.push_str(&format!(
            "{:<26}{:>18} (checked to {:.3e} s)\n",
            "recontact", "no", r.recontact_checked_until_s
        )),
    }
    s.push_str(&format!(
        "{:<26}{:>18} ({} evaluations)\n",
        "solver", r.solver, r.rhs_evaluations
    ));
    s
}

/// Draws the contact (Dormand–Prince at 1e-10, whatever solver gave the figures) and the
/// ring-down (the target's exact free response, the impactor coasting).
fn plot(
    model: &Model<f64>,
    impact: &Impact<f64>,
    t: &Target<f64>,
    o: &TargetOutcome<f64>,
    free: &FreeResponse<f64>,
    path: &Path,
) -> Result<(), SimulateError> {
    let mut samples: Vec<Sample<f64>> = Vec::new();
    two_body::trajectory(model, impact, t, 1e-10, &mut |s| samples.push(s))?;
    let tc = o.contact_time_s;
    let period = free.ring_frequency_hz.map_or(tc, |f| 1.0 / f);
    let end = free
        .recontact_s
        .map_or(tc + (4.0 * tc).max(3.0 * period), |r| r + 0.5 * tc)
        .min(free.checked_until_s.max(2.0 * tc));
    let n = 600;
    for k in 1..=n {
        let tau = (end - tc) * k as f64 / n as f64;
        if let Some((y, w)) = target_at(t, o, tau) {
            samples.push(Sample {
                t_s: tc + tau,
                impactor_m: o.impactor_displacement_m - o.rebound_velocity_m_s * tau,
                impactor_m_s: -o.rebound_velocity_m_s,
                target_m: y,
                target_m_s: w,
                force_n: 0.0,
            });
        }
    }
    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, (1300, 900)).into_drawing_area();
        root.fill(&WHITE)?;
        let panels = root.split_evenly((3, 2));
        let ms = |s: &Sample<f64>| s.t_s * 1e3;
        let impactor = RGBColor(200, 60, 30);
        let target_c = RGBColor(30, 90, 200);
        type Pick = fn(&Sample<f64>) -> f64;
        let series: [(&str, Pick, Option<Pick>); 3] = [
            (
                "displacement, mm (impact direction +)",
                |s| s.impactor_m * 1e3,
                Some(|s| s.target_m * 1e3),
            ),
            ("velocity, m/s", |s| s.impactor_m_s, Some(|s| s.target_m_s)),
            ("contact force, N", |s| s.force_n, None),
        ];
        // Left: the contact and a little after; right: the whole ring-down.
        let spans = [(0.0, (1.5 * tc).min(end)), (0.0, end)];
        for (index, panel) in panels.iter().enumerate() {
            let (ylabel, first, second) = series[index / 2];
            let (t0, t1) = spans[index % 2];
            let shown: Vec<&Sample<f64>> = samples
                .iter()
                .filter(|s| s.t_s <= t1 * (1.0 + 1e-12))
                .collect();
            let (mut lo, mut hi) = (f64::MAX, f64::MIN);
            for s in &shown {
                for v in [Some(first(s)), second.map(|g| g(s))].into_iter().flatten() {
                    lo = lo.min(v);
                    hi = hi.max(v);
                }
            }
            let pad = 0.05 * (hi - lo).max(1e-12);
            let title = match index {
                0 => format!(
                    "{} on a target: the contact, {:.4} ms, COR {:.4}",
                    model.name(),
                    tc * 1e3,
                    o.cor
                ),
                1 => match free.recontact_s {
                    Some(r) => format!("after separation: recontact at {:.4} ms", r * 1e3),
                    None => format!(
                        "after separation: the target rings{}, no recontact",
                        free.ring_frequency_hz
                            .map_or(String::new(), |f| format!(" at {f:.4} Hz"))
                    ),
                },
                _ => String::new(),
            };
            let mut chart = ChartBuilder::on(panel)
                .caption(title, ("sans-serif", 17))
                .margin(10)
                .x_label_area_size(40)
                .y_label_area_size(70)
                .build_cartesian_2d(t0 * 1e3..t1 * 1e3, (lo - pad)..(hi + pad))?;
            chart
                .configure_mesh()
                .x_desc("time from first touch, ms")
                .y_desc(ylabel)
                .draw()?;
            let name1 = if second.is_some() {
                "impactor"
            } else {
                "contact force"
            };
            chart
                .draw_series(LineSeries::new(
                    shown.iter().map(|s| (ms(s), first(s))),
                    impactor.stroke_width(2),
                ))?
                .label(name1)
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], impactor.stroke_width(2))
                });
            if let Some(g) = second {
                chart
                    .draw_series(LineSeries::new(
                        shown.iter().map(|s| (ms(s), g(s))),
                        target_c.stroke_width(2),
                    ))?
                    .label("target (contact point)")
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 20, y)], target_c.stroke_width(2))
                    });
            }
            let sep = vec![(tc * 1e3, lo - pad), (tc * 1e3, hi + pad)];
            chart
                .draw_series(std::iter::once(PathElement::new(sep, BLACK.mix(0.4))))?
                .label("separation")
                .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.mix(0.4)));
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.8))
                .border_style(BLACK)
                .position(SeriesLabelPosition::UpperRight)
                .draw()?;
        }
        root.present()?;
    }
    Ok(crate::plot::write_figure(path, &text)?)
}
