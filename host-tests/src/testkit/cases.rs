//! The reference impact cases: the seeds' and oracles' worked examples, one or more per model.

use impact_core::model::{Body, Hertz, KelvinVoigt, Linear, Model, Nonlinear, TwoPhase};
use impact_core::Impact;

/// A named model and impact.
#[derive(Clone, Copy, Debug)]
pub struct Case {
    pub name: &'static str,
    pub model: Model<f64>,
    pub impact: Impact<f64>,
}

/// 1/2-inch steel sphere (seed 000): radius m, Young's modulus Pa, Poisson, density kg/m³.
pub const SPHERE_RADIUS_M: f64 = 6.35e-3;
pub const STEEL_YOUNGS_PA: f64 = 200e9;
pub const STEEL_POISSON: f64 = 0.3;
pub const STEEL_DENSITY: f64 = 7850.0;

/// Mass of the 1/2-inch steel sphere, kg.
pub fn sphere_mass_kg() -> f64 {
    4.0 / 3.0 * core::f64::consts::PI * SPHERE_RADIUS_M.powi(3) * STEEL_DENSITY
}

pub fn steel_sphere() -> Body<f64> {
    Body {
        radius_m: SPHERE_RADIUS_M,
        youngs_pa: STEEL_YOUNGS_PA,
        poisson: STEEL_POISSON,
    }
}

/// Seed 001 bench: 60 g body at 1.3357 m/s.
pub const BENCH_MASS_KG: f64 = 0.06;
pub const BENCH_V0_M_S: f64 = 1.3357;
/// Seed 001 measured maximum and permanent deformation, m.
pub const BENCH_X_M: f64 = 0.0186;
pub const BENCH_X_P: f64 = 0.0182;

/// Seed 001 compression stiffness from `x_m`: `kc = m (v0 / x_m)^2`, N/m.
pub fn bench_kc() -> f64 {
    BENCH_MASS_KG * (BENCH_V0_M_S / BENCH_X_M).powi(2)
}

/// The standard set used by the oracle tests and the work-precision benchmark.
pub fn standard() -> Vec<Case> {
    let sphere = Impact::new(sphere_mass_kg(), 2.0);
    let bench = Impact::new(BENCH_MASS_KG, BENCH_V0_M_S);
    let hertz = Hertz::from_bodies(&steel_sphere(), &Body::rigid_wall()).expect("valid sphere");
    let linear = Linear::matching_max_deformation(&hertz, &sphere).expect("valid");
    let kc = bench_kc();
    vec![
        Case {
            name: "hertz-sphere-wall",
            model: Model::Hertz(hertz),
            impact: sphere,
        },
        Case {
            name: "linear-matched",
            model: Model::Linear(linear),
            impact: sphere,
        },
        Case {
            name: "kelvin-voigt-zeta0.2",
            model: Model::KelvinVoigt(KelvinVoigt { k: 100.0, c: 4.0 }),
            impact: Impact::new(1.0, 1.0),
        },
        Case {
            name: "kelvin-voigt-overdamped",
            model: Model::KelvinVoigt(KelvinVoigt { k: 100.0, c: 30.0 }),
            impact: Impact::new(1.0, 1.0),
        },
        Case {
            name: "two-phase-bench",
            model: Model::TwoPhase(TwoPhase {
                kc,
                kr: 40.0 * kc,
                c: 2.0,
                permanent_m: Some(BENCH_X_P),
            }),
            impact: bench,
        },
        Case {
            name: "nonlinear-bench-c1",
            model: Model::Nonlinear(Nonlinear {
                k: kc,
                c: 1.0,
                n: 1.0,
            }),
            impact: bench,
        },
        Case {
            name: "hunt-crossley-sphere",
            model: Model::Nonlinear(Nonlinear {
                k: hertz.k,
                c: 0.2,
                n: 1.5,
            }),
            impact: sphere,
        },
    ]
}
