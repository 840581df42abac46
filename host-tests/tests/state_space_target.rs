//! A body striking a linear target given in state-space form (`--target FILE`, as `impact
//! simulate --target` takes it), analysed against the strike generator's truth
//! (`impact_host::drop::mounted`, its own RK4 on the same state space): a fixture of two
//! masses, the contact's kinematics within 1 % at several touch phases; a spring–mass
//! written as a state space measured as `--target-mass` measures it; and what the tool
//! refuses.

mod common;

use common::{impact_ok, Scratch};
use impact_core::model::{Hertz, KelvinVoigt, Nonlinear, TwoPhase};
use impact_core::two_body::{Target, MAX_STATES};
use impact_core::Model;
use impact_host::drop::mounted::{Mount, Strike, StrikeTruth};
use serde_json::Value;

/// A fixture of two masses: the struck plate `m2` (0.3 kg) on a spring `k2` (4e4 N/m) and
/// damper `c2` (12 N s/m) to a base `m3` (1 kg) on `k3` (1e6 N/m) and `c3` (60 N s/m) to
/// ground. States `(y2, w2, y3, w3)`; the contact point is the plate.
fn two_masses() -> Target<f64> {
    plate_on_base(1.0, 1e6, 60.0)
}

/// The plate of [`two_masses`] on a base of `m3`, `k3`, `c3`.
fn plate_on_base(m3: f64, k3: f64, c3: f64) -> Target<f64> {
    let (m2, k2, c2) = (0.3, 4e4, 12.0);
    let mut a = [[0.0; MAX_STATES]; MAX_STATES];
    a[0][1] = 1.0;
    a[1] = [-k2 / m2, -c2 / m2, k2 / m2, c2 / m2, 0.0, 0.0];
    a[2][3] = 1.0;
    a[3] = [k2 / m3, c2 / m3, -(k2 + k3) / m3, -(c2 + c3) / m3, 0.0, 0.0];
    let mut b = [0.0; MAX_STATES];
    b[1] = 1.0 / m2;
    let mut c = [[0.0; MAX_STATES]; 2];
    c[0][0] = 1.0;
    c[1][1] = 1.0;
    Target::state_space(4, a, b, c, [0.0, 0.0]).expect("a valid target")
}

/// The fixtures' plate alone, as `--target-mass` takes a spring–mass to ground.
const PLATE_ALONE: [&str; 6] = [
    "--target-mass",
    "0.3",
    "--target-stiffness",
    "40000",
    "--target-damping",
    "12",
];

/// `t` as the JSON file `--target` reads.
fn json_of(t: &Target<f64>) -> String {
    let n = t.n;
    let row = |r: &[f64]| r.iter().take(n).copied().collect::<Vec<f64>>();
    serde_json::json!({
        "a": t.a.iter().take(n).map(|r| row(r)).collect::<Vec<_>>(),
        "b": row(&t.b),
        "c": [row(&t.c[0]), row(&t.c[1])],
        "d": [0.0, 0.0],
    })
    .to_string()
}

/// A 60 g body at 1.3357 m/s with `law`, touching at `touch_s`.
fn strike(law: Model<f64>, touch_s: f64) -> Strike {
    Strike {
        law,
        mass_kg: 0.06,
        v0_m_s: 1.3357,
        touch_s,
        // (Not used: the strikes here are rendered on a state space.)
        mount: Mount {
            mass_kg: 1.0,
            stiffness_n_m: 0.0,
            damping_n_s_m: 0.0,
        },
        gravity_m_s2: 0.0,
    }
}

/// The body's reading `accel` at `rate` (16-bit over twice its peak) analysed with `--v0`
/// and `extra`: the JSON.
fn analyse(scratch: &Scratch, accel: &[f64], rate: f64, extra: &[&str]) -> Value {
    let peak = accel.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let text = impact_host::testkit::sensor::csv_of(accel, rate, 2.0 * peak);
    let path = scratch.file("strike.csv", text);
    let mut args = vec![
        "analyze",
        path.to_str().unwrap(),
        "--json",
        "--mass",
        "0.06",
        "--v0",
        "1.3357",
    ];
    args.extend_from_slice(extra);
    let (out, _) = impact_ok(&args);
    serde_json::from_str(&out).unwrap()
}

/// The contact's COR, x_m, crush time and work against the truth (the work against a tenth
/// of the body's energy where it is smaller), relative.
fn errors(r: &Value, t: &StrikeTruth) -> [f64; 4] {
    let off = |got: &Value, want: f64| (got.as_f64().unwrap_or(f64::NAN) - want) / want;
    let e0 = 0.5 * 0.06 * 1.3357f64.powi(2);
    [
        off(&r["cor"], t.cor),
        off(&r["max_deformation_m"], t.max_deformation_m),
        off(&r["crush_time_s"], t.crush_time_s),
        (r["absorbed_energy_j"].as_f64().unwrap_or(f64::NAN) - t.contact_work_j)
            / t.contact_work_j.abs().max(0.1 * e0),
    ]
}

#[test]
fn the_contact_on_a_two_mass_fixture_within_one_percent() {
    let scratch = Scratch::new();
    let target = two_masses();
    let file = scratch.file("fixture.json", json_of(&target));
    let file = file.to_str().unwrap();
    let rate = 500e3;
    let laws = [
        ("hertz", Model::Hertz(Hertz { k: 1e9 })),
        (
            "two-phase",
            Model::TwoPhase(TwoPhase {
                kc: 0.06 * (1.3357f64 / 0.0186).powi(2),
                kr: 12376.0,
                c: 2.0,
                permanent_m: Some(0.0182),
            }),
        ),
        (
            "kelvin-voigt",
            Model::KelvinVoigt(KelvinVoigt { k: 1e5, c: 5.0 }),
        ),
    ];
    for (name, law) in laws {
        for phase in [0.0, 0.5] {
            let s = strike(law, 0.0123 + phase / rate);
            let n = ((s.touch_s + 0.08) * rate) as usize;
            let (accel, truth) = s.render_on(Some(&target), rate, n).unwrap();
            let json = analyse(&scratch, &accel, rate, &["--target", file]);
            let what = format!("{name}, phase {phase}");
            let r = &json["impacts"][0];
            assert_eq!(json["impacts"].as_array().unwrap().len(), 1, "{what}");
            assert!(r["flags"].as_array().unwrap().is_empty(), "{what}: {r}");
            let errs = errors(r, &truth);
            eprintln!("{what}: {errs:.5?} (truth cor {:.4})", truth.cor);
            for (field, e) in ["cor", "x_m", "crush", "work"].iter().zip(errs) {
                assert!(e.abs() <= 0.01, "{what}: {field} {:+.2} %", e * 100.0);
            }
            // The steel-like contact's own reading would be far off: the target matters.
            // And the generator agrees with the core's two-body solver (`impact simulate`).
            if name == "hertz" {
                let (out, _) = impact_ok(&[
                    "simulate",
                    "--model",
                    "hertz",
                    "--mass",
                    "0.06",
                    "--v0",
                    "1.3357",
                    "--stiffness",
                    "1e9",
                    "--target",
                    file,
                    "--json",
                ]);
                let sim: Value = serde_json::from_str(&out).unwrap();
                for (field, want) in [
                    ("cor", truth.cor),
                    ("max_deformation_m", truth.max_deformation_m),
                    ("crush_time_s", truth.crush_time_s),
                ] {
                    let got = sim[field].as_f64().unwrap();
                    assert!((got / want - 1.0).abs() < 1e-4, "{field}: {got} {want}");
                }
                assert!(
                    (truth.body_cor - truth.cor).abs() > 0.05,
                    "{what}: {truth:?}"
                );
            }
            // What the target was, and what the kinematics are against it, said.
            let ss = &json["target"]["state_space"];
            assert_eq!(ss["a"].as_array().unwrap().len(), 4, "{what}");
            let m = json["target"]["contact_mass_kg"].as_f64().unwrap();
            assert!((m - 0.3).abs() < 1e-6, "{what}: {m}");
            assert!(json["target"].get("mass_kg").is_none(), "{what}");
            let said = json["assumptions"][0].as_str().unwrap();
            assert!(
                said.starts_with(
                    "the kinematics are the contact's against the target given (a linear state \
                     space of 4 states, contact-point mass 0.3 kg"
                ),
                "{what}: {said}"
            );
        }
    }
}

/// On a light, soft base (0.1 kg on 2e4 N/m, 71 Hz) a 7 ms contact moves the base: the plate
/// alone (`--target-mass`, its spring to ground) reads a COR 22 % low, the state space within
/// 1 % of the truth.
#[test]
fn a_soft_base_matters_and_the_state_space_measures_it() {
    let scratch = Scratch::new();
    let target = plate_on_base(0.1, 2e4, 5.0);
    let file = scratch.file("soft.json", json_of(&target));
    let rate = 500e3;
    let law = Model::Nonlinear(Nonlinear {
        k: 2e5,
        c: 0.3,
        n: 1.5,
    });
    let s = strike(law, 0.0123);
    let n = ((s.touch_s + 0.08) * rate) as usize;
    let (accel, truth) = s.render_on(Some(&target), rate, n).unwrap();
    let json = analyse(
        &scratch,
        &accel,
        rate,
        &["--target", file.to_str().unwrap()],
    );
    let errs = errors(&json["impacts"][0], &truth);
    eprintln!("soft base: {errs:.5?} (truth cor {:.4})", truth.cor);
    assert!(errs.iter().all(|e| e.abs() <= 0.01), "{errs:?}");
    let plate = analyse(&scratch, &accel, rate, &PLATE_ALONE);
    let plate_cor = plate["impacts"][0]["cor"].as_f64().unwrap();
    assert!(
        (plate_cor / truth.cor - 1.0).abs() > 0.1,
        "the plate alone {plate_cor} vs {}",
        truth.cor
    );
}

#[test]
fn a_spring_mass_as_a_state_space_is_measured_as_target_mass_measures_it() {
    let scratch = Scratch::new();
    let (m2, k2, c2) = (0.3, 4e4, 12.0);
    // States (1000 y, w): not the spring–mass's own matrices.
    let mut a = [[0.0; MAX_STATES]; MAX_STATES];
    a[0][1] = 1000.0;
    a[1][0] = -k2 / m2 / 1000.0;
    a[1][1] = -c2 / m2;
    let mut b = [0.0; MAX_STATES];
    b[1] = 1.0 / m2;
    let mut c = [[0.0; MAX_STATES]; 2];
    c[0][0] = 1e-3;
    c[1][1] = 1.0;
    let space = Target::state_space(2, a, b, c, [0.0, 0.0]).unwrap();
    let file = scratch.file("mount.json", json_of(&space));
    let rate = 500e3;
    let mut s = strike(Model::Hertz(Hertz { k: 1e9 }), 0.0123);
    s.mount = Mount {
        mass_kg: m2,
        stiffness_n_m: k2,
        damping_n_s_m: c2,
    };
    let n = ((s.touch_s + 0.08) * rate) as usize;
    // The generator's two paths agree.
    let (accel, truth) = s.render(rate, n).unwrap();
    let (accel_ss, truth_ss) = s.render_on(Some(&space), rate, n).unwrap();
    let worst = accel
        .iter()
        .zip(&accel_ss)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(worst < 1e-6 * truth.peak_force_n / 0.06, "{worst}");
    assert!(
        (truth.cor - truth_ss.cor).abs() < 1e-9,
        "{truth:?} {truth_ss:?}"
    );
    // And the analysis's.
    let by_mass = analyse(&scratch, &accel, rate, &PLATE_ALONE);
    let by_space = analyse(
        &scratch,
        &accel,
        rate,
        &["--target", file.to_str().unwrap()],
    );
    // (Each against its own scale: the COR's 1, x_m for deformations, the body's energy.)
    let x_m = truth.max_deformation_m;
    for (field, scale) in [
        ("cor", 1.0),
        ("max_deformation_m", x_m),
        ("crush_time_s", truth.crush_time_s),
        ("absorbed_energy_j", 0.5 * 0.06 * 1.3357f64.powi(2)),
        ("separation_deformation_m", x_m),
    ] {
        let (p, q) = (
            by_mass["impacts"][0][field].as_f64().unwrap(),
            by_space["impacts"][0][field].as_f64().unwrap(),
        );
        assert!((p - q).abs() <= 1e-4 * scale, "{field}: {p} {q}");
    }
    let errs = errors(&by_space["impacts"][0], &truth);
    assert!(errs.iter().all(|e| e.abs() <= 0.01), "{errs:?}");
}

#[test]
fn a_state_space_target_the_tool_cannot_use_is_refused_naming_it() {
    let scratch = Scratch::new();
    let csv = scratch.file("flat.csv", "time_s,accel_g\n0,0\n0.001,0\n");
    let csv = csv.to_str().unwrap();
    let good = scratch.file("good.json", json_of(&two_masses()));
    let good = good.to_str().unwrap();
    // Unstable: a spring to ground of negative stiffness.
    let unstable = scratch.file(
        "unstable.json",
        r#"{"a": [[0, 1], [1000, 0]], "b": [0, 1], "c": [[1, 0], [0, 1]]}"#,
    );
    let unstable = unstable.to_str().unwrap();
    for (args, code, want) in [
        (
            vec!["analyze", csv, "--mass", "0.06", "--target", unstable],
            1,
            "unstable.json: A is unstable",
        ),
        (
            vec!["analyze", csv, "--target", good],
            1,
            "--target: needs the body's mass",
        ),
        (
            vec!["analyze", csv, "--target", good, "--target-mass", "0.3"],
            2,
            "cannot be used with",
        ),
    ] {
        let (got, _, err) = common::impact(&args);
        assert_eq!(got, code, "{args:?}: {err}");
        assert!(err.contains(want), "{args:?}: {err}");
    }
    // The command line's state space over a scene file's spring–mass.
    let scene = scratch.file("scene.json", r#"{"mass": 0.06, "target_mass": 0.3}"#);
    let (out, _) = impact_ok(&[
        "analyze",
        csv,
        "--json",
        "--scene",
        scene.to_str().unwrap(),
        "--target",
        good,
    ]);
    let json: Value = serde_json::from_str(&out).unwrap();
    assert_eq!(
        json["target"]["state_space"]["a"].as_array().unwrap().len(),
        4
    );
    assert!(json["target"].get("mass_kg").is_none(), "{json}");
    // The target file is an input: no output over it (a report's either).
    let (got, _, err) = common::impact(&["report", csv, "--target", good, "--html", good]);
    assert_eq!(got, 1, "{err}");
    assert!(err.contains("it would be overwritten"), "{err}");
    let (got, _, err) = common::impact(&[
        "synth",
        "--model",
        "hertz",
        "--mass",
        "0.06",
        "--v0",
        "1.3357",
        "--stiffness",
        "1e9",
        "--target",
        good,
        "--output",
        good,
    ]);
    assert_eq!(got, 1, "{err}");
    assert!(std::fs::read_to_string(good).unwrap().starts_with("{\"a\""));
}

/// A scene file takes the state space as `--target` does: by the name of its file (relative
/// to the scene file's folder, not to where the tool runs) or written in it, with the same
/// numbers; `--target` overrides it; a spring–mass beside it, a malformed one and an output
/// over its file are refused, naming the scene file's key.
#[test]
fn a_scene_files_state_space_is_the_options() {
    let scratch = Scratch::new();
    let target = two_masses();
    let s = strike(Model::Hertz(Hertz { k: 1e9 }), 0.0123);
    let rate = 500e3;
    let n = ((s.touch_s + 0.08) * rate) as usize;
    let (accel, _) = s.render_on(Some(&target), rate, n).unwrap();
    let sub = scratch.path().join("bench");
    std::fs::create_dir(&sub).unwrap();
    std::fs::write(sub.join("fixture.json"), json_of(&target)).unwrap();
    let fixture = sub.join("fixture.json");
    let fixture = fixture.to_str().unwrap();
    let by_option = analyse(&scratch, &accel, rate, &["--target", fixture]);
    let named = sub.join("named.json");
    std::fs::write(&named, r#"{"target": "fixture.json"}"#).unwrap();
    let inline = sub.join("inline.json");
    let object: Value = serde_json::from_str(&json_of(&target)).unwrap();
    std::fs::write(&inline, serde_json::json!({ "target": object }).to_string()).unwrap();
    // (Another target: the plate on a soft base.)
    let plate = scratch.file("plate.json", json_of(&plate_on_base(0.1, 2e4, 5.0)));
    for (scene, extra) in [
        (&named, vec![]),
        (&inline, vec![]),
        (&named, vec!["--target", fixture]),
    ] {
        let mut args = vec!["--scene", scene.to_str().unwrap()];
        args.extend(extra);
        let by_scene = analyse(&scratch, &accel, rate, &args);
        assert_eq!(by_scene["target"], by_option["target"], "{args:?}");
        assert_eq!(by_scene["impacts"], by_option["impacts"], "{args:?}");
        assert_eq!(
            by_scene["assumptions"], by_option["assumptions"],
            "{args:?}"
        );
    }
    // The command line's over the scene file's: a different target, different numbers.
    let over = analyse(
        &scratch,
        &accel,
        rate,
        &[
            "--scene",
            named.to_str().unwrap(),
            "--target",
            plate.to_str().unwrap(),
        ],
    );
    assert_ne!(over["impacts"][0]["cor"], by_option["impacts"][0]["cor"]);
    let csv = scratch.join_str("strike.csv");
    let refused = |scene: &str, extra: &[&str], want: &str| {
        let path = sub.join("refused.json");
        std::fs::write(&path, scene).unwrap();
        let mut args = vec!["analyze", &csv, "--mass", "0.06", "--scene"];
        let path = path.to_str().unwrap().to_string();
        args.push(&path);
        args.extend_from_slice(extra);
        let (got, _, err) = common::impact(&args);
        assert_eq!(got, 1, "{scene} {extra:?}: {err}");
        assert!(err.contains(want), "{scene} {extra:?}: {err}");
    };
    refused(
        r#"{"target": "fixture.json", "target_mass": 0.3}"#,
        &[],
        "refused.json: target: a state-space target, and a spring–mass too",
    );
    // A spring without its mass is not a target to override it with.
    refused(
        r#"{"target": "fixture.json"}"#,
        &["--target-stiffness", "100"],
        "--target-stiffness: needs the target's mass",
    );
    refused(
        r#"{"target": {"a": [[0, 1], [-1, 0]], "b": [0, 1, 2], "c": [[1, 0], [0, 1]]}}"#,
        &[],
        "refused.json: target: B has 3 entries, not 2",
    );
    // (Named relative to the scene file's folder.)
    refused(
        r#"{"target": "missing.json"}"#,
        &[],
        &format!(
            "refused.json: target {}",
            sub.join("missing.json").display()
        ),
    );
    // The core's refusals of the target named as the scene file's key.
    refused(
        r#"{"target": "fixture.json"}"#,
        &["--train", "flight"],
        "refused.json: target: ",
    );
    refused(
        r#"{"target": 3}"#,
        &[],
        "refused.json: target must be the name of",
    );
    // Wrong in the file even where the command line overrides it.
    refused(
        r#"{"target": ""}"#,
        &["--target", fixture],
        "refused.json: target must be the name of",
    );
    // The file the scene file names is an input: no output over it.
    let (got, _, err) = common::impact(&[
        "report",
        &csv,
        "--scene",
        named.to_str().unwrap(),
        "--html",
        fixture,
    ]);
    assert_eq!(got, 1, "{err}");
    assert!(err.contains("it would be overwritten"), "{err}");
    assert!(std::fs::read_to_string(fixture)
        .unwrap()
        .starts_with("{\"a\""));
    // `--target-mass` over the scene file's state space: a spring–mass, its file not read.
    let spring = analyse(
        &scratch,
        &accel,
        rate,
        &["--scene", named.to_str().unwrap(), "--target-mass", "0.3"],
    );
    assert_eq!(
        spring["target"]["mass_kg"].as_f64(),
        Some(0.3),
        "{}",
        spring["target"]
    );
}
