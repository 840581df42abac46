//! Every model and solver against the exact results of `docs/oracles.md`.

use impact_core::model::{Body, Hertz, KelvinVoigt, Linear, Model, Nonlinear, TwoPhase};
use impact_core::{solve, ContactLaw, Error, Impact, ImpactOutcome, Method, Settings};
use impact_host::simulate::model_f32;
use impact_host::testkit::cases::{self, Case};
use impact_host::testkit::compare::{max_relative_error, widen};

fn rel(got: f64, want: f64) -> f64 {
    ((got - want) / want).abs()
}

#[track_caller]
fn close(got: f64, want: f64, tol: f64, what: &str) {
    assert!(
        rel(got, want) <= tol,
        "{what}: got {got:.15e}, want {want:.15e} (rel {:.2e} > {tol:.0e})",
        rel(got, want)
    );
}

fn exact(case: &Case) -> ImpactOutcome<f64> {
    case.model.exact(&case.impact).expect("exact solution")
}

// ---------------------------------------------------------------- exact vs oracle values

#[test]
fn hertz_sphere_on_rigid_wall_matches_the_worked_case() {
    let m = cases::sphere_mass_kg();
    close(m, 8.41936702144e-3, 1e-11, "mass");
    let hertz = Hertz::from_bodies(&cases::steel_sphere(), &Body::rigid_wall()).unwrap();
    close(hertz.k, 2.3351468792e10, 1e-10, "K");
    let o = hertz.exact(&Impact::new(m, 2.0)).unwrap();
    close(o.max_deformation_m, 2.00619940589e-5, 1e-10, "x_m");
    close(o.contact_time_s, 2.95239846308e-5, 1e-10, "t_c");
    close(o.crush_time_s, 2.95239846308e-5 / 2.0, 1e-10, "t_m");
    close(o.peak_force_n, 2098.33753233, 1e-10, "F_peak");
    assert_eq!(
        (o.cor, o.rebound_velocity_m_s, o.permanent_deformation_m),
        (1.0, 2.0, 0.0)
    );
    // Energy: all kinetic energy is stored at x_m.
    close(
        hertz.energy(o.max_deformation_m),
        0.5 * m * 4.0,
        1e-13,
        "U(x_m)",
    );
}

#[test]
fn hertz_sphere_on_steel_wall_matches_the_worked_case() {
    let m = cases::sphere_mass_kg();
    let wall = Body {
        radius_m: f64::INFINITY,
        ..cases::steel_sphere()
    };
    let hertz = Hertz::from_bodies(&cases::steel_sphere(), &wall).unwrap();
    close(hertz.k, 1.1675734396e10, 1e-10, "K");
    let o = hertz.exact(&Impact::new(m, 2.0)).unwrap();
    close(o.max_deformation_m, 2.64719598666e-5, 1e-10, "x_m");
    close(o.contact_time_s, 3.89571312779e-5, 1e-10, "t_c");
    close(o.peak_force_n, 1590.24247994, 1e-10, "F_peak");
}

#[test]
fn hertz_of_two_equal_spheres_halves_the_radius() {
    let s = cases::steel_sphere();
    let two = Hertz::from_bodies(&s, &s).unwrap();
    let wall = Hertz::from_bodies(
        &s,
        &Body {
            radius_m: f64::INFINITY,
            ..s
        },
    )
    .unwrap();
    close(two.k, wall.k * 0.5f64.sqrt(), 1e-15, "K(R/2)");
}

#[test]
fn hertz_rejects_two_flat_or_two_rigid_bodies_naming_the_parameter() {
    let wall = Body::<f64>::rigid_wall();
    let err = Hertz::from_bodies(
        &Body {
            radius_m: f64::INFINITY,
            ..cases::steel_sphere()
        },
        &wall,
    )
    .unwrap_err();
    assert!(
        matches!(err, Error::InvalidParameter { name: "radius", .. }),
        "{err:?}"
    );
    let err = Hertz::from_bodies(
        &Body {
            poisson: 0.7,
            ..cases::steel_sphere()
        },
        &wall,
    )
    .unwrap_err();
    assert!(
        matches!(
            err,
            Error::InvalidParameter {
                name: "poisson",
                ..
            }
        ),
        "{err:?}"
    );
}

#[test]
fn linear_stand_in_matching_x_m_and_how_far_it_really_is_from_hertz() {
    let sphere = Impact::new(cases::sphere_mass_kg(), 2.0);
    let hertz = Hertz::from_bodies(&cases::steel_sphere(), &Body::rigid_wall()).unwrap();
    let lin = Linear::matching_max_deformation(&hertz, &sphere).unwrap();
    close(lin.k, 8.36741363264e7, 1e-10, "k");
    let l = lin.exact(&sphere).unwrap();
    let h = hertz.exact(&sphere).unwrap();
    close(l.contact_time_s, 3.15133065759e-5, 1e-10, "t_c");
    close(l.peak_force_n, 1678.67002586, 1e-10, "F_peak");
    close(
        l.max_deformation_m,
        h.max_deformation_m,
        1e-14,
        "x_m matched",
    );
    // Seed 000 claims 5-10 %: contact time is +6.7 %, but peak force is -20 %.
    let dt = l.contact_time_s / h.contact_time_s - 1.0;
    let df = l.peak_force_n / h.peak_force_n - 1.0;
    assert!((dt - 0.0674).abs() < 5e-4, "contact time differs by {dt}");
    assert!((df + 0.2000).abs() < 5e-4, "peak force differs by {df}");
}

#[test]
fn kelvin_voigt_matches_the_check_values() {
    let o = KelvinVoigt { k: 100.0, c: 4.0 }
        .exact(&Impact::new(1.0, 1.0))
        .unwrap();
    close(o.contact_time_s, 0.279535444073, 1e-11, "t_c");
    close(o.cor, 0.571740027585, 1e-11, "COR");
    assert!(o.permanent_deformation_m > 0.0);
}

#[test]
fn kelvin_voigt_is_continuous_through_critical_damping() {
    let i = Impact::new(1.0, 1.0);
    let at = KelvinVoigt { k: 100.0, c: 20.0 }.exact(&i).unwrap();
    for c in [20.0 * (1.0 - 1e-9), 20.0 * (1.0 + 1e-9)] {
        let near = KelvinVoigt { k: 100.0, c }.exact(&i).unwrap();
        let (err, field) = max_relative_error(&near, &at);
        assert!(err < 1e-8, "{c}: {field} off by {err}");
    }
    // Critical damping: t_m = 1/w, COR = e^-2.
    close(at.crush_time_s, 0.1, 1e-15, "t_m");
    close(at.cor, (-2.0f64).exp(), 1e-15, "COR");
}

#[test]
fn two_phase_reproduces_table_1_crush_time_from_first_principles() {
    // Seed 001 Table 1: the Kelvin-Voigt model's crush time is 21.84 ms for x_m = 1.858 cm.
    let bench = Impact::new(cases::BENCH_MASS_KG, cases::BENCH_V0_M_S);
    let x_m_table = 0.01858;
    let kc = TwoPhase::compression_stiffness_for(&bench, x_m_table);
    let law = TwoPhase {
        kc,
        kr: 10.0 * kc,
        c: 0.0,
        permanent_m: Some(0.01816),
    };
    let o = law.exact(&bench).unwrap();
    close(o.max_deformation_m, x_m_table, 1e-14, "x_m");
    // pi/2 x_m / v0 = 21.850 ms: the table's 21.84 ms, within its rounding (0.05 %).
    assert!(
        (o.crush_time_s - 21.84e-3).abs() < 0.011e-3,
        "t_m = {} ms",
        o.crush_time_s * 1e3
    );
    // The oracle's x_m = 18.6 mm case.
    let kc = cases::bench_kc();
    close(kc, 309.416318071, 1e-11, "kc");
    let o = TwoPhase {
        kc,
        kr: kc,
        c: 0.0,
        permanent_m: None,
    }
    .exact(&bench)
    .unwrap();
    close(o.crush_time_s, 21.8737827943e-3, 1e-10, "t_m");
    close(o.peak_force_n, 1.3357 * (0.06 * kc).sqrt(), 1e-14, "F_peak");
}

#[test]
fn two_phase_restitution_closed_forms() {
    let bench = Impact::new(cases::BENCH_MASS_KG, cases::BENCH_V0_M_S);
    let kc = cases::bench_kc();
    // Undamped restitution from y0 = x_m - x_p: v' = y0 w_r, quarter period, x_p left.
    let kr = 100.0 * kc;
    let o = TwoPhase {
        kc,
        kr,
        c: 0.0,
        permanent_m: Some(cases::BENCH_X_P),
    }
    .exact(&bench)
    .unwrap();
    let wr = (kr / 0.06).sqrt();
    close(o.rebound_velocity_m_s, (0.0186 - 0.0182) * wr, 1e-12, "v'");
    close(
        o.contact_time_s - o.crush_time_s,
        std::f64::consts::FRAC_PI_2 / wr,
        1e-12,
        "t_r",
    );
    close(o.permanent_deformation_m, 0.0182, 1e-12, "x_p");
    // Force continuity: x_p = x_m (1 - kc/kr) and the peak force is continuous.
    let o = TwoPhase {
        kc,
        kr,
        c: 1.0,
        permanent_m: None,
    }
    .exact(&bench)
    .unwrap();
    close(o.peak_force_n, kc * 0.0186, 1e-12, "F_peak");
    assert!(o.permanent_deformation_m > 0.0186 * (1.0 - kc / kr));
    // A set at or beyond x_m: the body stops dead.
    let o = TwoPhase {
        kc,
        kr,
        c: 0.0,
        permanent_m: Some(0.02),
    }
    .exact(&bench)
    .unwrap();
    assert_eq!(
        (o.cor, o.rebound_velocity_m_s, o.contact_time_s),
        (0.0, 0.0, o.crush_time_s)
    );
}

#[test]
fn nonlinear_matches_the_worked_table() {
    let bench = Impact::new(0.06, 1.3357);
    let k = 309.416318071;
    // c, x_m, t_m, t_c, v', COR, F_peak
    let table = [
        (
            0.1,
            0.0178309481975,
            0.0212940752829,
            0.0437774577626,
            1.2264125041,
            0.918179609265,
            5.56199706389,
        ),
        (
            0.5,
            0.0155721587573,
            0.0195403524554,
            0.0443192118632,
            0.920301577666,
            0.689003202565,
            5.48157139021,
        ),
        (
            1.0,
            0.0137485404611,
            0.0180575488801,
            0.0455401661433,
            0.692769885454,
            0.518656798274,
            5.84770070148,
        ),
        (
            10.0,
            0.0064396753566,
            0.0110964828877,
            0.0785860227812,
            0.0999991645866,
            0.0748664854283,
            12.2071690265,
        ),
    ];
    for (c, x_m, t_m, t_c, v1, cor, f) in table {
        let o = Nonlinear { k, c, n: 1.0 }.exact(&bench).unwrap();
        let what = |s: &str| format!("c = {c}: {s}");
        close(o.max_deformation_m, x_m, 1e-10, &what("x_m"));
        close(o.crush_time_s, t_m, 1e-10, &what("t_m"));
        close(o.contact_time_s, t_c, 1e-10, &what("t_c"));
        close(o.rebound_velocity_m_s, v1, 1e-10, &what("v'"));
        close(o.cor, cor, 1e-10, &what("COR"));
        close(o.peak_force_n, f, 1e-10, &what("F_peak"));
        assert_eq!(o.permanent_deformation_m, 0.0);
    }
}

#[test]
fn nonlinear_cor_depends_on_c_v0_alone() {
    for (p, cor) in [
        (0.1f64, 0.937476f64),
        (0.3, 0.832870),
        (1.0, 0.593624),
        (3.0, 0.306897),
    ] {
        for (m, k, n, v0) in [
            (0.06f64, 309.4f64, 1.0f64, 1.3357f64),
            (2.0, 1e7, 1.5, 0.2),
            (1e-3, 5.0, 2.0, 30.0),
        ] {
            let o = Nonlinear { k, c: p / v0, n }
                .exact(&Impact::new(m, v0))
                .unwrap();
            assert!(
                (o.cor - cor).abs() < 6e-7,
                "p = {p}, n = {n}: COR {}",
                o.cor
            );
            // The exit condition p (1 + e) = ln((1 + p) / (1 - p e)) to machine precision.
            let e = o.cor;
            let lhs = p * (1.0 + e);
            let rhs = ((1.0 + p) / (1.0 - p * e)).ln();
            assert!((lhs - rhs).abs() < 4e-15 * lhs, "p = {p}: {lhs} vs {rhs}");
        }
    }
    // Small p: e ≈ 1 - 2p/3.
    let o = Nonlinear::<f64> {
        k: 1.0,
        c: 1e-6,
        n: 1.0,
    }
    .exact(&Impact::new(1.0, 1.0))
    .unwrap();
    assert!((o.cor - (1.0 - 2e-6 / 3.0)).abs() < 1e-12, "{}", o.cor);
}

#[test]
fn nonlinear_without_damping_is_the_elastic_power_law() {
    let i = Impact::new(cases::sphere_mass_kg(), 2.0);
    let hertz = Hertz::from_bodies(&cases::steel_sphere(), &Body::rigid_wall()).unwrap();
    let hc = Nonlinear {
        k: hertz.k,
        c: 0.0,
        n: 1.5,
    }
    .exact(&i)
    .unwrap();
    assert_eq!(hc, hertz.exact(&i).unwrap());
    // And with a whisker of damping, the quadrature path agrees with the closed form.
    let tiny = Nonlinear {
        k: hertz.k,
        c: 1e-9,
        n: 1.5,
    }
    .exact(&i)
    .unwrap();
    let (err, field) = max_relative_error(&tiny, &hc);
    assert!(err < 1e-8, "{field}: {err}");
}

#[test]
fn nonlinear_extreme_damping_stays_finite_and_exact() {
    // c v0 = 1000: v' is within e^-994 of 1/c, and the exit takes long.
    let i = Impact::new(0.06, 1.0);
    let o = Nonlinear::<f64> {
        k: 300.0,
        c: 1000.0,
        n: 1.0,
    }
    .exact(&i)
    .unwrap();
    assert_eq!(o.rebound_velocity_m_s, 1e-3);
    assert!(o.contact_time_s.is_finite() && o.contact_time_s > o.crush_time_s);
    let lhs_xm = o.max_deformation_m.powi(2) / 2.0;
    let rhs_xm = 0.06 / (1e6 * 300.0) * (1000.0 - 1001f64.ln());
    close(lhs_xm, rhs_xm, 1e-13, "x_m energy relation");
}

// ---------------------------------------------------------------- solvers vs exact

fn all_cases() -> Vec<Case> {
    let mut v = cases::standard();
    let bench = Impact::new(cases::BENCH_MASS_KG, cases::BENCH_V0_M_S);
    v.push(Case {
        name: "two-phase-continuity",
        model: Model::TwoPhase(TwoPhase {
            kc: cases::bench_kc(),
            kr: 5.0 * cases::bench_kc(),
            c: 0.5,
            permanent_m: None,
        }),
        impact: bench,
    });
    v.push(Case {
        name: "nonlinear-heavy-c10",
        model: Model::Nonlinear(Nonlinear {
            k: cases::bench_kc(),
            c: 10.0,
            n: 1.0,
        }),
        impact: bench,
    });
    v
}

#[test]
fn adaptive_at_its_tightest_tolerance_is_within_1e9_of_exact() {
    for case in all_cases() {
        let o = solve(&case.model, &case.impact, &Settings::adaptive(1e-13)).unwrap();
        let (err, field) = max_relative_error(&o, &exact(&case));
        assert!(err <= 1e-9, "{}: {field} off by {err:.2e}", case.name);
        assert!(o.rhs_evaluations > 0);
    }
}

#[test]
fn adaptive_error_follows_the_tolerance() {
    for case in all_cases() {
        for rtol in [1e-6, 1e-8, 1e-10] {
            let o = solve(&case.model, &case.impact, &Settings::adaptive(rtol)).unwrap();
            let (err, field) = max_relative_error(&o, &exact(&case));
            assert!(
                err <= 20.0 * rtol,
                "{} rtol {rtol:e}: {field} off by {err:.2e}",
                case.name
            );
        }
    }
}

#[test]
fn rk4_reaches_1e9_and_converges_at_fourth_order() {
    for case in all_cases() {
        let ex = exact(&case);
        let err = |n| {
            max_relative_error(
                &solve(&case.model, &case.impact, &Settings::fixed(Method::Rk4, n)).unwrap(),
                &ex,
            )
            .0
        };
        let fine = err(2000);
        assert!(fine <= 1e-9, "{}: {fine:.2e} at 2000 steps", case.name);
        // Hertz-type laws have x^1.5 at the ends of the contact: at least order 2.5 there.
        let smooth = !matches!(case.model, Model::Hertz(_))
            && !matches!(case.model, Model::Nonlinear(Nonlinear { n, .. }) if n != 1.0);
        let (e1, e2) = (err(100), err(200));
        let order = (e1 / e2).log2();
        let want = if smooth { 3.6 } else { 2.4 };
        assert!(
            order >= want,
            "{}: observed order {order:.2} ({e1:.2e} -> {e2:.2e})",
            case.name
        );
    }
}

#[test]
fn verlet_and_euler_converge_at_their_orders() {
    for case in all_cases() {
        let ex = exact(&case);
        for (method, want) in [(Method::Verlet, 1.8), (Method::Euler, 0.9)] {
            let err = |n| {
                max_relative_error(
                    &solve(&case.model, &case.impact, &Settings::fixed(method, n)).unwrap(),
                    &ex,
                )
                .0
            };
            let (e1, e2) = (err(400), err(800));
            let order = (e1 / e2).log2();
            assert!(
                order >= want,
                "{} {method:?}: order {order:.2} ({e1:.2e} -> {e2:.2e})",
                case.name
            );
            assert!(
                e2 < 1e-2 / (want * want),
                "{} {method:?}: {e2:.2e}",
                case.name
            );
        }
    }
}

#[test]
fn too_few_steps_for_a_stiff_damper_is_reported_not_wrong() {
    // zeta = 50: the damping time m/c is 1/1000 of the time scale's elastic part.
    let law = KelvinVoigt {
        k: 100.0,
        c: 1000.0,
    };
    let i = Impact::new(1.0, 1.0);
    let ex = law.exact(&i).unwrap();
    for method in [Method::Euler, Method::Verlet, Method::Rk4] {
        match solve(&law, &i, &Settings::fixed(method, 2)) {
            Err(Error::Unresolved(_)) => {}
            Ok(o) => {
                let (err, field) = max_relative_error(&o, &ex);
                assert!(
                    err < 0.5,
                    "{method:?} returned a wrong answer silently: {field} off by {err}"
                );
            }
            Err(e) => panic!("{method:?}: unexpected {e:?}"),
        }
    }
}

// ---------------------------------------------------------------- f32 paths

#[test]
fn f32_paths_are_within_1e5_of_exact() {
    for case in all_cases() {
        let ex = exact(&case);
        let model = model_f32(&case.model);
        let impact = Impact::new(case.impact.mass_kg as f32, case.impact.v0_m_s as f32);
        let runs: [(&str, Settings<f32>); 5] = [
            ("exact", Settings::exact()),
            ("adaptive 1e-6", Settings::adaptive(1e-6)),
            ("rk4 200", Settings::fixed(Method::Rk4, 200)),
            ("verlet 2000", Settings::fixed(Method::Verlet, 2000)),
            ("rk4 20000", Settings::fixed(Method::Rk4, 20000)),
        ];
        for (what, settings) in runs {
            let o = solve(&model, &impact, &settings).unwrap();
            let (err, field) = max_relative_error(&widen(&o), &ex);
            let tol = if what.starts_with("verlet") {
                1e-4
            } else {
                1e-5
            };
            assert!(err <= tol, "{} {what}: {field} off by {err:.2e}", case.name);
        }
    }
}
