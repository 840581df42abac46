//! The impactor on a target with its own dynamics (seed 000, section 3.2): every solver against
//! closed forms, an independent fine-step integration written here, energy balance, the wall
//! limit and bad input.

use impact_core::model::{Hertz, KelvinVoigt, Linear, Model, Nonlinear, TwoPhase};
use impact_core::two_body::free::after;
use impact_core::two_body::{self, Target, TargetOutcome, MAX_STATES};
use impact_core::{ContactLaw, Error, Impact, Settings};

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

/// A steel ball (seed 000's worked case scale): 8.4 g at 1 m/s on Hertz K = 1e10 N/m^1.5.
fn hertz() -> Hertz<f64> {
    Hertz { k: 1.0e10 }
}

fn on<L: ContactLaw<f64>>(
    law: &L,
    m1: f64,
    v0: f64,
    t: &Target<f64>,
    s: Settings<f64>,
) -> TargetOutcome<f64> {
    two_body::solve(law, &Impact::new(m1, v0), t, &s).expect("solved")
}

/// An independent reference: classic RK4 on `(x1, u1, y, w)` of an impactor on a spring–mass
/// target at `steps` steps per `t_scale`, separation by bisection on a partial RK4 step.
/// Returns (contact time, impactor velocity, target velocity, max deformation, peak force).
fn reference(
    force: impl Fn(f64, f64) -> f64,
    m1: f64,
    v0: f64,
    (m2, k2, c2): (f64, f64, f64),
    h: f64,
) -> (f64, f64, f64, f64, f64) {
    let f = |s: [f64; 4]| {
        let d = s[0] - s[2];
        let r = s[1] - s[3];
        let fc = force(d, r);
        [s[1], -fc / m1, s[3], (fc - k2 * s[2] - c2 * s[3]) / m2]
    };
    let rk4 = |s: [f64; 4], h: f64| {
        let add = |a: [f64; 4], b: [f64; 4], k: f64| {
            [
                a[0] + k * b[0],
                a[1] + k * b[1],
                a[2] + k * b[2],
                a[3] + k * b[3],
            ]
        };
        let k1 = f(s);
        let k2 = f(add(s, k1, h / 2.0));
        let k3 = f(add(s, k2, h / 2.0));
        let k4 = f(add(s, k3, h));
        let mut out = s;
        for i in 0..4 {
            out[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
        out
    };
    let fo = |s: [f64; 4]| force(s[0] - s[2], s[1] - s[3]);
    let mut s = [0.0, v0, 0.0, 0.0];
    let mut t = 0.0;
    let (mut xm, mut fm) = (0.0f64, fo(s));
    let mut past_max = false;
    loop {
        let s1 = rk4(s, h);
        let r1 = s1[1] - s1[3];
        if r1 < 0.0 {
            past_max = true;
        }
        // Maxima of deformation and force, refined on partial steps.
        let golden = |g: &dyn Fn([f64; 4]) -> f64| {
            let (mut a, mut b) = (0.0, h);
            for _ in 0..100 {
                let m1 = a + (b - a) * 0.382;
                let m2 = a + (b - a) * 0.618;
                if g(rk4(s, m1)) < g(rk4(s, m2)) {
                    a = m1
                } else {
                    b = m2
                }
            }
            g(rk4(s, 0.5 * (a + b)))
        };
        xm = xm.max(golden(&|q| q[0] - q[2]));
        fm = fm.max(golden(&|q| fo(q)));
        if past_max && fo(s1) <= 0.0 {
            let (mut a, mut b) = (0.0, h);
            for _ in 0..200 {
                let m = 0.5 * (a + b);
                if fo(rk4(s, m)) > 0.0 {
                    a = m
                } else {
                    b = m
                }
            }
            let e = rk4(s, a);
            return (t + a, e[1], e[3], xm, fm);
        }
        s = s1;
        t += h;
    }
}

// ------------------------------------------------------------------------ two free bodies

#[test]
fn two_free_hertz_bodies_exchange_momentum_as_the_closed_form_says() {
    let v0 = 1.0;
    for (m1, m2) in [(8.4e-3, 8.4e-3), (8.4e-3, 0.1), (0.1, 8.4e-3), (1.0, 3.0)] {
        let target = Target::spring_mass(m2, 0.0, 0.0).unwrap();
        let mu = m1 * m2 / (m1 + m2);
        let wall = hertz().exact(&Impact::new(mu, v0)).unwrap();
        for (s, tol) in [
            (Settings::exact(), 1e-12),
            (Settings::adaptive(1e-12), 1e-9),
        ] {
            let out = on(&hertz(), m1, v0, &target, s);
            let what = format!("m1 {m1} m2 {m2} {:?}", s.method);
            // v1' = (m1 - m2)/(m1 + m2) v0 (positive toward the target), v2' = 2 m1/(m1 + m2) v0.
            let u1 = -out.rebound_velocity_m_s;
            let want_u1 = (m1 - m2) / (m1 + m2) * v0;
            assert!(
                (u1 - want_u1).abs() <= tol * v0,
                "{what}: u1 {u1} want {want_u1}"
            );
            close(
                out.target_velocity_m_s,
                2.0 * m1 / (m1 + m2) * v0,
                tol,
                &what,
            );
            close(out.cor, 1.0, tol, &what);
            // The relative motion is the wall problem of the reduced mass.
            close(out.contact_time_s, wall.contact_time_s, tol, &what);
            close(out.max_deformation_m, wall.max_deformation_m, tol, &what);
            close(out.peak_force_n, wall.peak_force_n, tol, &what);
            close(
                out.target_energy_j.unwrap(),
                0.5 * m2 * out.target_velocity_m_s.powi(2),
                1e-12,
                &what,
            );
        }
    }
}

// ----------------------------------------------- linear laws on a spring–mass: closed forms

#[test]
fn linear_law_on_a_spring_mass_matches_the_modal_closed_form() {
    // Undamped 2-DOF: M q'' + K q = 0, q = (x1, y), K = [[k, -k], [-k, k + k2]]; modes from the
    // 2x2 eigenproblem, written out here independently of the solvers' matrix exponential.
    let (m1, m2, k, k2, v0): (f64, f64, f64, f64, f64) = (0.06, 0.2, 2.0e5, 5.0e4, 1.3357);
    let (a, b, d) = (k / m1, -k / m1, (k + k2) / m2);
    let c = -k / m2;
    // Eigenvalues of [[a, b], [c, d]] (= M^-1 K).
    let tr = a + d;
    let det = a * d - b * c;
    let disc = (tr * tr / 4.0 - det).sqrt();
    let lam = [tr / 2.0 - disc, tr / 2.0 + disc];
    // Mode shapes (1, r) with (a - lam) + b r = 0.
    let r: Vec<f64> = lam.iter().map(|l| (l - a) / b).collect();
    let w: Vec<f64> = lam.iter().map(|l| l.sqrt()).collect();
    // q(0) = 0, q'(0) = (v0, 0) = s1 w1 (1, r1) + s2 w2 (1, r2).
    let s2 = v0 * -r[0] / (w[1] * (r[1] - r[0]));
    let s1 = (v0 - s2 * w[1]) / w[0];
    let delta = |t: f64| {
        let x1 = s1 * (w[0] * t).sin() + s2 * (w[1] * t).sin();
        let y = s1 * r[0] * (w[0] * t).sin() + s2 * r[1] * (w[1] * t).sin();
        (x1, y, x1 - y)
    };
    let vel = |t: f64| {
        let u1 = s1 * w[0] * (w[0] * t).cos() + s2 * w[1] * (w[1] * t).cos();
        let wt = s1 * r[0] * w[0] * (w[0] * t).cos() + s2 * r[1] * w[1] * (w[1] * t).cos();
        (u1, wt)
    };
    // Separation: the first zero of δ after its maximum, by bisection on a fine bracket.
    let mut t = 1e-7;
    while delta(t).2 > 0.0 {
        t += 1e-7;
    }
    let (mut lo, mut hi) = (t - 1e-7, t);
    for _ in 0..200 {
        let m = 0.5 * (lo + hi);
        if delta(m).2 > 0.0 {
            lo = m
        } else {
            hi = m
        }
    }
    let tc = 0.5 * (lo + hi);
    let (u1, wt) = vel(tc);
    let target = Target::spring_mass(m2, k2, 0.0).unwrap();
    let law = Linear { k };
    for (s, tol) in [
        (Settings::exact(), 1e-10),
        (Settings::adaptive(1e-12), 1e-9),
    ] {
        let out = on(&law, m1, v0, &target, s);
        let what = format!("{:?}", s.method);
        close(out.contact_time_s, tc, tol, &what);
        close(-out.rebound_velocity_m_s, u1, tol, &what);
        close(out.target_velocity_m_s, wt, tol, &what);
        close(out.target_displacement_m, delta(tc).1, tol, &what);
        close(out.cor, (wt - u1) / v0, tol, &what);
    }
}

#[test]
fn affine_laws_on_a_damped_spring_mass_match_an_independent_integration() {
    let (m1, v0) = (0.06, 1.3357);
    let mount = (0.2, 5.0e4, 20.0);
    let target = Target::spring_mass(mount.0, mount.1, mount.2).unwrap();
    let kv = KelvinVoigt { k: 2.0e5, c: 8.0 };
    let reference_kv = reference(|d, r| kv.k * d + kv.c * r, m1, v0, mount, 2e-8);
    let linear = Linear { k: 2.0e5 };
    let reference_lin = reference(|d, _| linear.k * d, m1, v0, mount, 2e-8);
    for (law, want) in [
        (Model::KelvinVoigt(kv), reference_kv),
        (Model::Linear(linear), reference_lin),
    ] {
        for s in [Settings::exact(), Settings::adaptive(1e-12)] {
            let out = on(&law, m1, v0, &target, s);
            let what = format!("{} {:?}", law.name(), s.method);
            close(out.contact_time_s, want.0, 1e-9, &what);
            close(-out.rebound_velocity_m_s, want.1, 1e-9, &what);
            close(out.target_velocity_m_s, want.2, 1e-9, &what);
            close(out.max_deformation_m, want.3, 1e-9, &what);
            close(out.peak_force_n, want.4, 1e-9, &what);
        }
    }
}

/// Kelvin–Voigt (ζ = 0.2 on the impactor's mass) on a target 1000× lighter than the impactor:
/// `(k, c, m2)` of the stability sweep at `m1 = v0 = 1`.
fn kelvin_voigt_on_a_feather(f: f64, zeta: f64) -> (KelvinVoigt<f64>, Target<f64>) {
    let pi = std::f64::consts::PI;
    let k = (pi / 1e-3f64).powi(2);
    let law = KelvinVoigt {
        k,
        c: 0.4 * k.sqrt(),
    };
    let m2 = 1e-3;
    let k2 = m2 * (f * pi / 1e-3).powi(2);
    let c2 = 2.0 * zeta * (k2 * m2).sqrt();
    (law, Target::spring_mass(m2, k2, c2).unwrap())
}

#[test]
// The reference's digits as the 50-digit computation printed them.
#[allow(clippy::excessive_precision)]
fn kelvin_voigt_carrying_a_light_target_on_its_mount_matches_the_modal_solution() {
    // The overdamped contact takes the feather along and the two swing on its mount for
    // 0.31 s, 1e5 of the contact's own time scale: the largest deformation is at the top of
    // that swing, where δ' is 1e-5 of v0. Reference: the modal solution of the linear system
    // in 50-digit arithmetic (mpmath), events refined on it.
    let (law, target) = kelvin_voigt_on_a_feather(0.1, 0.3);
    let (tc, tm, xm) = (
        0.31449168638228163,
        0.1554632125784393,
        9.9047811372633108e-7,
    );
    let (rebound, w) = (0.96985428673333789, -0.96984459775917649);
    for rtol in [1e-6, 1e-10] {
        let out = on(&law, 1.0, 1.0, &target, Settings::adaptive(rtol));
        let what = format!("adaptive {rtol:e}");
        close(out.contact_time_s, tc, 100.0 * rtol, &what);
        close(out.crush_time_s, tm, 100.0 * rtol, &what);
        close(out.max_deformation_m, xm, 100.0 * rtol, &what);
        assert!(
            (out.rebound_velocity_m_s - rebound).abs() <= 100.0 * rtol,
            "{what}"
        );
        assert!(
            (out.target_velocity_m_s - w).abs() <= 100.0 * rtol,
            "{what}"
        );
    }
}

#[test]
fn kelvin_voigt_separation_from_a_free_light_target_is_where_the_closed_form_puts_it() {
    // Separation is where k δ + c δ' returns to zero, with δ' = u1 - w 170× smaller than v0.
    let (law, target) = kelvin_voigt_on_a_feather(0.0, 0.0);
    let exact = on(&law, 1.0, 1.0, &target, Settings::exact());
    for rtol in [1e-6, 1e-10] {
        let out = on(&law, 1.0, 1.0, &target, Settings::adaptive(rtol));
        let what = format!("adaptive {rtol:e}");
        close(
            out.contact_time_s,
            exact.contact_time_s,
            100.0 * rtol,
            &what,
        );
        close(out.crush_time_s, exact.crush_time_s, 100.0 * rtol, &what);
    }
}

#[test]
fn hertz_on_a_damped_spring_mass_matches_an_independent_integration() {
    let (m1, v0) = (8.4e-3, 1.0);
    let mount = (0.02, 1.0e6, 5.0);
    let target = Target::spring_mass(mount.0, mount.1, mount.2).unwrap();
    let k = hertz().k;
    let want = reference(|d, _| k * d.max(0.0).powf(1.5), m1, v0, mount, 2e-9);
    for rtol in [1e-10, 1e-12] {
        let out = on(&hertz(), m1, v0, &target, Settings::adaptive(rtol));
        let what = format!("rtol {rtol}");
        close(out.contact_time_s, want.0, 1e-8, &what);
        close(-out.rebound_velocity_m_s, want.1, 1e-8, &what);
        close(out.target_velocity_m_s, want.2, 1e-8, &what);
        close(out.max_deformation_m, want.3, 1e-8, &what);
        close(out.peak_force_n, want.4, 1e-8, &what);
    }
    // Hertz has no closed form on a sprung target: the exact solver says so.
    let err =
        two_body::solve(&hertz(), &Impact::new(m1, v0), &target, &Settings::exact()).unwrap_err();
    assert!(
        matches!(err, Error::InvalidParameter { name: "solver", .. }),
        "{err:?}"
    );
}

#[test]
fn two_phase_on_a_spring_mass_agrees_between_exact_and_adaptive() {
    let law = TwoPhase {
        kc: 1.0e4,
        kr: 5.0e4,
        c: 5.0,
        permanent_m: None,
    };
    let target = Target::spring_mass(0.5, 2.0e4, 3.0).unwrap();
    let a = on(&law, 0.06, 1.3357, &target, Settings::exact());
    let b = on(&law, 0.06, 1.3357, &target, Settings::adaptive(1e-12));
    for (x, y, what) in [
        (a.contact_time_s, b.contact_time_s, "contact time"),
        (a.crush_time_s, b.crush_time_s, "crush time"),
        (a.max_deformation_m, b.max_deformation_m, "x_m"),
        (a.permanent_deformation_m, b.permanent_deformation_m, "x_p"),
        (a.rebound_velocity_m_s, b.rebound_velocity_m_s, "rebound"),
        (
            a.target_velocity_m_s,
            b.target_velocity_m_s,
            "target velocity",
        ),
        (a.peak_force_n, b.peak_force_n, "peak force"),
    ] {
        close(x, y, 1e-9, what);
    }
}

// --------------------------------------------------------------------------- energy balance

#[test]
fn energy_is_kept_by_the_impactor_the_contact_and_the_target() {
    let (m1, v0) = (0.06, 1.3357);
    let e0 = 0.5 * m1 * v0 * v0;
    let target = Target::spring_mass(0.3, 4.0e4, 12.0).unwrap();
    let laws = [
        Model::KelvinVoigt(KelvinVoigt { k: 2.0e5, c: 8.0 }),
        Model::Hertz(Hertz { k: 5.0e8 }),
        Model::Nonlinear(Nonlinear {
            k: 2.0e5,
            c: 0.3,
            n: 1.0,
        }),
        Model::TwoPhase(TwoPhase {
            kc: 1.0e4,
            kr: 5.0e4,
            c: 5.0,
            permanent_m: None,
        }),
    ];
    for law in laws {
        let out = on(&law, m1, v0, &target, Settings::adaptive(1e-13));
        let e1 = 0.5 * m1 * out.rebound_velocity_m_s.powi(2);
        let (wc, wt) = (out.contact_work_j.unwrap(), out.target_work_j.unwrap());
        let balance = (e0 - e1 - wc - wt).abs() / e0;
        assert!(
            balance < 1e-9,
            "{}: impactor + contact + target off by {balance:.1e}",
            law.name()
        );
        let kept = out.target_energy_j.unwrap() + out.target_dissipated_j.unwrap();
        let target_balance = (wt - kept).abs() / e0;
        assert!(
            target_balance < 1e-9,
            "{}: target work vs energy + damper {target_balance:.1e}",
            law.name()
        );
        // The elastic part of each law returns what it stored: only damping is lost.
        assert!(wc > 0.0 && wc < e0, "{}", law.name());
    }
    // An elastic law on an undamped target loses nothing in the contact.
    let out = on(
        &Hertz { k: 5.0e8 },
        m1,
        v0,
        &Target::spring_mass(0.3, 4.0e4, 0.0).unwrap(),
        Settings::adaptive(1e-13),
    );
    assert!(out.contact_work_j.unwrap().abs() < 1e-9 * e0);
}

// ----------------------------------------------------------------------- after separation

#[test]
fn a_heavy_impactor_on_a_light_sprung_target_hits_it_again() {
    let target = Target::spring_mass(0.01, 1.0e4, 0.0).unwrap();
    for s in [Settings::exact(), Settings::adaptive(1e-10)] {
        let out = on(&Linear { k: 1.0e6 }, 1.0, 1.0, &target, s);
        // The impactor keeps moving on; the ringing target comes back into it.
        assert!(out.rebound_velocity_m_s < 0.0);
        let free = after(&target, &out).unwrap();
        let t = free.recontact_s.expect("recontact");
        assert!(
            t > out.contact_time_s
                && t < out.contact_time_s + 2.0 * std::f64::consts::PI * (0.01f64 / 1.0e4).sqrt()
        );
        // Ring-down of the undamped mount at its natural frequency.
        close(
            free.ring_frequency_hz.unwrap(),
            (1.0e4f64 / 0.01).sqrt() / (2.0 * std::f64::consts::PI),
            1e-12,
            "ring",
        );
    }
    // The seed's assumption holds for a light impactor on a heavy target: a single hit.
    let heavy = Target::spring_mass(1.0, 1.0e4, 0.0).unwrap();
    let out = on(&Linear { k: 1.0e6 }, 0.01, 1.0, &heavy, Settings::exact());
    let free = after(&heavy, &out).unwrap();
    assert_eq!(free.recontact_s, None);
    assert!(free.checked_until_s > out.contact_time_s);
    assert!(free.ring_amplitude_m > 0.0);
    // Two free bodies part for good.
    let free_body = Target::spring_mass(0.05, 0.0, 0.0).unwrap();
    let out = on(&hertz(), 8.4e-3, 1.0, &free_body, Settings::exact());
    assert_eq!(after(&free_body, &out).unwrap().recontact_s, None);
}

// ------------------------------------------------------------------------- the wall limit

#[test]
fn a_target_too_heavy_or_too_stiff_to_move_is_the_wall() {
    let (m1, v0) = (0.06, 1.3357);
    let laws = [
        Model::Hertz(Hertz { k: 5.0e8 }),
        Model::Linear(Linear { k: 2.0e5 }),
        Model::KelvinVoigt(KelvinVoigt { k: 2.0e5, c: 8.0 }),
        Model::TwoPhase(TwoPhase {
            kc: 1.0e4,
            kr: 5.0e4,
            c: 5.0,
            permanent_m: None,
        }),
        Model::Nonlinear(Nonlinear {
            k: 2.0e5,
            c: 0.3,
            n: 1.0,
        }),
    ];
    for law in laws {
        let wall = law.exact(&Impact::new(m1, v0)).unwrap();
        let mut runs = vec![(
            Target::spring_mass(1e15, 0.0, 0.0).unwrap(),
            Settings::exact(),
            "m2 -> inf, exact",
        )];
        runs.push((
            Target::spring_mass(1e15, 1e3, 1.0).unwrap(),
            Settings::adaptive(1e-13),
            "m2 -> inf, adaptive",
        ));
        if law.affine(impact_core::model::Phase::Compression).is_some() {
            runs.push((
                Target::spring_mass(100.0, 1e18, 0.0).unwrap(),
                Settings::exact(),
                "k2 -> inf, exact",
            ));
        }
        for (target, s, how) in runs {
            let out = on(&law, m1, v0, &target, s);
            let what = format!("{} {how}", law.name());
            close(out.contact_time_s, wall.contact_time_s, 1e-9, &what);
            close(out.max_deformation_m, wall.max_deformation_m, 1e-9, &what);
            close(out.crush_time_s, wall.crush_time_s, 1e-9, &what);
            close(out.peak_force_n, wall.peak_force_n, 1e-9, &what);
            close(
                out.rebound_velocity_m_s,
                wall.rebound_velocity_m_s,
                1e-9,
                &what,
            );
            close(out.cor, wall.cor, 1e-9, &what);
            if wall.permanent_deformation_m > 0.0 {
                close(
                    out.permanent_deformation_m,
                    wall.permanent_deformation_m,
                    1e-9,
                    &what,
                );
            }
        }
    }
}

#[test]
fn f32_paths_agree_with_f64_within_1e_5() {
    let (m1, v0) = (0.06f64, 1.3357f64);
    type Mount = (f64, f64, f64);
    let cases: [(Model<f64>, Mount, Settings<f64>); 3] = [
        (
            Model::Hertz(Hertz { k: 5.0e8 }),
            (0.05, 0.0, 0.0),
            Settings::exact(),
        ),
        (
            Model::KelvinVoigt(KelvinVoigt { k: 2.0e5, c: 8.0 }),
            (0.3, 4.0e4, 12.0),
            Settings::adaptive(1e-6),
        ),
        (
            Model::Hertz(Hertz { k: 5.0e8 }),
            (0.3, 4.0e4, 12.0),
            Settings::adaptive(1e-6),
        ),
    ];
    for (law, (m2, k2, c2), s) in cases {
        let want = on(
            &law,
            m1,
            v0,
            &Target::spring_mass(m2, k2, c2).unwrap(),
            if s.rtol > 0.0 {
                Settings::adaptive(1e-12)
            } else {
                s
            },
        );
        let law32 = impact_host::simulate::model_f32(&law);
        let t32 = Target::spring_mass(m2 as f32, k2 as f32, c2 as f32).unwrap();
        let s32 = Settings {
            method: s.method,
            steps: s.steps,
            rtol: s.rtol as f32,
        };
        let got = two_body::solve(&law32, &Impact::new(m1 as f32, v0 as f32), &t32, &s32).unwrap();
        let what = format!("{} {:?} f32", law.name(), s.method);
        // The closed form on a sprung target is f64 only, and says so.
        if k2 > 0.0 && law.affine(impact_core::model::Phase::Compression).is_some() {
            let exact32 = two_body::solve(
                &law32,
                &Impact::new(m1 as f32, v0 as f32),
                &t32,
                &Settings::exact(),
            );
            assert!(
                matches!(
                    exact32,
                    Err(Error::InvalidParameter {
                        name: "precision",
                        ..
                    })
                ),
                "{exact32:?}"
            );
        }
        close(got.contact_time_s as f64, want.contact_time_s, 1e-5, &what);
        close(
            got.max_deformation_m as f64,
            want.max_deformation_m,
            1e-5,
            &what,
        );
        close(got.peak_force_n as f64, want.peak_force_n, 1e-5, &what);
        close(
            got.target_velocity_m_s as f64,
            want.target_velocity_m_s,
            1e-5,
            &what,
        );
        close(got.cor as f64, want.cor, 1e-5, &what);
    }
}

// ------------------------------------------------------------------------------ bad input

#[test]
fn a_target_that_cannot_be_pushed_is_an_error_naming_the_option() {
    for (m, k, c, name) in [
        (0.0, 1.0, 0.0, "target-mass"),
        (-1.0, 1.0, 0.0, "target-mass"),
        (f64::NAN, 1.0, 0.0, "target-mass"),
        (f64::INFINITY, 1.0, 0.0, "target-mass"),
        (1.0, -1.0, 0.0, "target-stiffness"),
        (1.0, f64::NAN, 0.0, "target-stiffness"),
        (1.0, 1.0, -1.0, "target-damping"),
    ] {
        match Target::spring_mass(m, k, c) {
            Err(Error::InvalidParameter { name: n, .. }) => assert_eq!(n, name),
            other => panic!("{m} {k} {c}: {other:?}"),
        }
    }
    let z = [[0.0; MAX_STATES]; MAX_STATES];
    let mut a = z;
    a[0][1] = 1.0;
    a[1][0] = -1e4;
    let mut b = [0.0; MAX_STATES];
    b[1] = 2.0;
    let mut c = [[0.0; MAX_STATES]; 2];
    c[0][0] = 1.0;
    c[1][1] = 1.0;
    assert!(Target::state_space(2, a, b, c, [0.0, 0.0]).is_ok());
    let mut unstable = a;
    unstable[1][1] = 1e-3; // negative damping
    let mut nan = a;
    nan[1][0] = f64::NAN;
    let mut pull = b;
    pull[1] = -2.0;
    let mut wrong_c = c;
    wrong_c[1][1] = 2.0;
    for (a, b, c, d, why) in [
        (unstable, b, c, [0.0, 0.0], "unstable"),
        (nan, b, c, [0.0, 0.0], "finite"),
        (a, pull, c, [0.0, 0.0], "mass"),
        (a, b, wrong_c, [0.0, 0.0], "derivative"),
        (a, b, c, [0.0, 1.0], "algebraic"),
    ] {
        match Target::state_space(2, a, b, c, d) {
            Err(Error::InvalidParameter {
                name: "target",
                reason,
            }) => {
                assert!(reason.contains(why), "{why}: {reason}")
            }
            other => panic!("{why}: {other:?}"),
        }
    }
    // Fixed-step solvers are not offered for targets: an error, not a wall.
    let t = Target::spring_mass(1.0, 1.0, 0.0).unwrap();
    let err = two_body::solve(
        &Linear { k: 1e5 },
        &Impact::new(0.1, 1.0),
        &t,
        &Settings::fixed(impact_core::Method::Rk4, 100),
    );
    assert!(matches!(
        err,
        Err(Error::InvalidParameter { name: "solver", .. })
    ));
}

#[test]
fn a_state_space_spring_mass_is_the_spring_mass() {
    let (m2, k2, c2) = (0.3, 4.0e4, 12.0);
    let sm = Target::spring_mass(m2, k2, c2).unwrap();
    let ss = Target::state_space(sm.n, sm.a, sm.b, sm.c, [0.0, 0.0]).unwrap();
    let law = Hertz { k: 5.0e8 };
    let a = on(&law, 0.06, 1.3357, &sm, Settings::adaptive(1e-12));
    let b = on(&law, 0.06, 1.3357, &ss, Settings::adaptive(1e-12));
    close(b.contact_time_s, a.contact_time_s, 1e-10, "contact time");
    close(
        b.target_velocity_m_s,
        a.target_velocity_m_s,
        1e-10,
        "target velocity",
    );
    assert!(b.target_energy_j.is_none() && b.target_work_j.is_some());
    let fa = after(&sm, &a).unwrap();
    let fb = after(&ss, &b).unwrap();
    close(
        fb.ring_frequency_hz.unwrap(),
        fa.ring_frequency_hz.unwrap(),
        0.01,
        "ring frequency",
    );
    close(
        fb.ring_amplitude_m,
        fa.ring_amplitude_m,
        0.02,
        "ring amplitude",
    );
}

/// A light target on a soft mount (15.9 Hz) thrown off by a steel ball: the state-space form
/// of the spring–mass scans its free response over its own slowest period (it was scanned for
/// 100 contact times, 1.2 ms, and reported no recontact and no ringing).
#[test]
fn a_state_space_mount_rings_and_is_hit_again_as_its_spring_mass_twin() {
    let sm = Target::spring_mass(0.001, 10.0, 0.0).unwrap();
    let ss = Target::state_space(sm.n, sm.a, sm.b, sm.c, [0.0, 0.0]).unwrap();
    let law = Hertz { k: 1.0e10 };
    let a = on(&law, 8.419e-3, 2.0, &sm, Settings::adaptive(1e-12));
    let b = on(&law, 8.419e-3, 2.0, &ss, Settings::adaptive(1e-12));
    let fa = after(&sm, &a).unwrap();
    let fb = after(&ss, &b).unwrap();
    let ra = fa.recontact_s.expect("the spring–mass is hit again");
    let rb = fb.recontact_s.expect("its state-space twin is hit again");
    close(rb, ra, 1e-6, "recontact");
    assert!(fb.checked_until_s >= rb, "{fb:?}");
    close(
        fb.ring_frequency_hz.expect("the mount rings"),
        (10.0f64 / 0.001).sqrt() / (2.0 * std::f64::consts::PI),
        0.01,
        "ring frequency",
    );
    close(
        fb.ring_amplitude_m,
        fa.ring_amplitude_m,
        0.003,
        "ring amplitude",
    );
}
