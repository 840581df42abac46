//! Vertical impacts against the physical generator (`impact_host::drop`, checked against SciPy
//! in `drop_peer.rs`): gravity in every contact, pads that keep or lose their dent, bounce
//! trains; each report's COR, crush time, maximum deformation, energy and peak force against
//! the generator's truth.

mod common;

use common::{impact_ok, Scratch};
use impact_core::model::{KelvinVoigt, Nonlinear, TwoPhase};
use impact_core::Model;
use impact_host::drop::{ContactTruth, Drop, Start};
use serde_json::Value;

const G: f64 = impact_core::consts::STANDARD_GRAVITY;

/// The drop rendered at `rate` as a 16-bit ADC over ±`full_scale` m/s² would record it
/// ([`impact_host::testkit::sensor::csv`]).
fn csv(drop: &Drop, rate: f64, seconds: f64, full_scale: f64) -> (String, Vec<ContactTruth>) {
    impact_host::testkit::sensor::csv(drop, rate, seconds, full_scale).expect("a valid drop")
}

fn analyse(scratch: &Scratch, name: &str, text: String, options: &[&str]) -> Value {
    let path = scratch.file(name, text);
    let mut args = vec![
        "analyze",
        path.to_str().unwrap(),
        "--json",
        "--mass",
        "0.06",
    ];
    args.extend_from_slice(options);
    serde_json::from_str(&impact_ok(&args).0).unwrap()
}

fn within(got: &Value, want: f64, rel: f64, what: &str) {
    let got = got
        .as_f64()
        .unwrap_or_else(|| panic!("{what}: {got} (want {want})"));
    assert!(
        ((got - want) / want).abs() <= rel,
        "{what}: {got} vs true {want} ({:+.2} %)",
        (got / want - 1.0) * 100.0
    );
}

/// Each contact's kinematics at `rate` against the truth, within 1 %. (Where the force
/// jumps at touch, a Kelvin–Voigt pad's `c v0` or the dented two-phase pad's damper, touch
/// lies anywhere in the interval before the jump: its middle had the crush time and `x_m`
/// up to half a sample off, ±0.8 % of `x_m` on the Kelvin–Voigt pad at 20 kS/s, and the
/// tests allowed that; the compression's law now places it, `core/src/analysis/jump.rs`.)
fn check(r: &Value, t: &ContactTruth, law: &str, what: &str, rate: f64) {
    let s = t.separation.unwrap();
    let w = |f: &str| format!("{what}: {f}");
    // First touch itself: within 0.6 of a sample (a step's middle, half a sample from where
    // it may lie), or where a foot's first samples lie within the noise, 5 µs (2.5 samples at
    // 500 kS/s: a Hertz foot's power fit 1.7 samples early; the seed's soft two-phase pad up
    // to 2 either way) or the time its mean slope takes to rise two codes of the ±2000 m/s²
    // ADC (the soft pad from 5 mm: 62 µs, where 20 kS/s puts touch 0.65 samples early).
    let code = 4000.0 / 65536.0;
    let slope = std::f64::consts::FRAC_PI_2 * t.peak_force_n / 0.06 / t.crush_time_s.unwrap();
    let start = r["start_s"].as_f64().unwrap();
    // Where the force jumps at touch and a sample is 10 µs or longer, within 0.2 of a
    // sample: the compression's law places it in the interval (its middle was up to half a
    // sample off; the Kelvin–Voigt pad from 5 mm at 20 kS/s is placed within 0.08).
    let jumps = law == "kelvin-voigt" || (law == "two-phase" && t.surface_m > 0.0);
    let tolerance = if jumps && rate <= 100e3 {
        0.2 / rate
    } else {
        (0.6 / rate).max(5e-6).max(2.0 * code / slope)
    };
    assert!(
        (start - t.touch_s).abs() <= tolerance,
        "{}: {start} s vs true {} s ({:+.2} samples)",
        w("first touch"),
        t.touch_s,
        (start - t.touch_s) * rate
    );
    within(&r["cor"], s.cor, 0.01, &w("cor"));
    within(
        &r["rebound_velocity_m_s"],
        s.rebound_m_s,
        0.01,
        &w("rebound"),
    );
    within(
        &r["crush_time_s"],
        t.crush_time_s.unwrap(),
        0.01,
        &w("crush"),
    );
    within(
        &r["max_deformation_m"],
        t.max_deformation_m.unwrap(),
        0.01,
        &w("x_m"),
    );
    within(&r["peak_force_n"], t.peak_force_n, 0.01, &w("peak force"));
    // The set after recovery within 1 % of x_m: reported for the laws whose unloading is an
    // elastic and a viscous part (linear, Kelvin–Voigt, two-phase), null (the record cannot
    // tell) or right for the others.
    let x_m = t.max_deformation_m.unwrap();
    match r["permanent_deformation_m"].as_f64() {
        Some(set) => assert!(
            (set - s.set_m).abs() <= 0.01 * x_m,
            "{}: {set} vs true {}",
            w("set"),
            s.set_m
        ),
        // (A contact of a millisecond: its restitution's points too few to tell a set from
        // none, `set-not-resolved`.)
        None => assert!(
            !matches!(
                law,
                "linear" | "kelvin-voigt" | "two-phase" | "two-phase-continuous"
            ) || t.crush_time_s.unwrap() < 1e-3,
            "{}: null ({})",
            w("set"),
            r["null_reasons"]["permanent_deformation_m"]
        ),
    }
    let x_sep = r["separation_deformation_m"].as_f64().unwrap();
    assert!(
        // (First touch's error, and separation's: both ends of the contact's feet.)
        (x_sep - s.deformation_m).abs() <= 0.02 * x_m,
        "{}: {x_sep} vs true {}",
        w("x at separation"),
        s.deformation_m
    );
    // Energy within 1 % of the impact's (½ m v0²): an elastic contact absorbs none.
    let e0 = 0.5 * 0.06 * t.approach_m_s * t.approach_m_s;
    let e = r["absorbed_energy_j"].as_f64().unwrap();
    assert!(
        (e - s.absorbed_energy_j).abs() <= 0.01 * e0,
        "{}: {e} J vs true {} J ({:+.2} % of ½ m v0²)",
        w("absorbed energy"),
        s.absorbed_energy_j,
        (e - s.absorbed_energy_j) / e0 * 100.0
    );
    within(&r["delta_v_m_s"], s.delta_v_m_s, 0.01, &w("Δv"));
}

/// A Kelvin–Voigt pad (k 1e4 N/m, c 5 N s/m): relaxes in c/k = 0.5 ms, keeps no set.
fn kelvin_voigt_pad() -> Model<f64> {
    Model::KelvinVoigt(KelvinVoigt { k: 1e4, c: 5.0 })
}

/// The seed-001 bench's two-phase pad (Table 1's x_m and x_p for 60 g at 1.3357 m/s).
fn seed_two_phase_pad() -> Model<f64> {
    Model::TwoPhase(TwoPhase {
        kc: 0.06 * (1.3357f64 / 0.0186).powi(2),
        kr: 12376.0,
        c: 2.0,
        permanent_m: Some(0.0182),
    })
}

fn seed_nonlinear() -> Model<f64> {
    Model::Nonlinear(Nonlinear {
        k: 250.0,
        c: 0.3,
        n: 1.0,
    })
}

/// One contact of the 60 g body held at rest for 50 ms and `phase` of a sample at `rate`,
/// released, falling `height_m`.
fn from_rest(law: Model<f64>, height_m: f64, rate: f64, phase: f64) -> Drop {
    Drop {
        law,
        mass_kg: 0.06,
        gravity_m_s2: G,
        start: Start::Rest {
            rest_s: 0.05 + phase / rate,
            height_m,
        },
        max_contacts: 1,
        min_rebound_m_s: 1e-3,
    }
}

fn moving(law: Model<f64>, contacts: u32) -> Drop {
    Drop {
        law,
        mass_kg: 0.06,
        gravity_m_s2: G,
        start: Start::Moving {
            touch_s: 0.0123,
            v0_m_s: 1.3357,
        },
        max_contacts: contacts,
        min_rebound_m_s: 1e-3,
    }
}

/// One vertical contact given its v0 (`--vertical`): gravity comes out of the contact.
#[test]
fn a_vertical_contact_takes_gravity_out() {
    let scratch = Scratch::new();
    for (name, law) in [
        ("nonlinear", seed_nonlinear()),
        ("kelvin-voigt", kelvin_voigt_pad()),
        ("two-phase", seed_two_phase_pad()),
    ] {
        for rate in [500_000.0, 100_000.0, 20_000.0] {
            let (text, truth) = csv(&moving(law, 1), rate, 0.2, 1000.0);
            let a = analyse(
                &scratch,
                &format!("{name}-{rate}.csv"),
                text,
                &["--v0", "1.3357", "--vertical"],
            );
            assert_eq!(a["contact_gravity_m_s2"], 9.80665);
            let impacts = a["impacts"].as_array().unwrap();
            assert_eq!(impacts.len(), 1, "{name} at {rate}");
            check(
                &impacts[0],
                &truth[0],
                name,
                &format!("{name} at {rate} S/s"),
                rate,
            );
        }
    }
}

/// A bounce train of seed 001's nonlinear law, each bounce's approach from the previous
/// rebound (`--train rebound`): gravity out of every contact, within 1 % on every bounce
/// (every law's, from the flight: `bounce_trains_of_every_law_within_one_percent`; the
/// landing on both pads: `a_bounce_lands_where_the_pad_is`).
#[test]
fn a_nonlinear_bounce_train_within_one_percent() {
    let scratch = Scratch::new();
    let (name, law) = ("nonlinear", seed_nonlinear());
    for rate in [500_000.0, 100_000.0] {
        let (text, truth) = csv(&moving(law, 6), rate, 1.5, 1000.0);
        let a = analyse(
            &scratch,
            &format!("train-{name}-{rate}.csv"),
            text,
            &["--v0", "1.3357", "--train", "rebound"],
        );
        let impacts = a["impacts"].as_array().unwrap();
        assert_eq!(
            impacts.len(),
            truth.len(),
            "{name} at {rate}: a report a contact"
        );
        for (i, (r, t)) in impacts.iter().zip(&truth).enumerate() {
            let what = format!("{name} at {rate} S/s, bounce {i}");
            within(
                &r["impact_velocity_m_s"],
                t.approach_m_s,
                0.01,
                &format!("{what}: v0"),
            );
            if t.separation.is_some() {
                check(r, t, name, &what, rate);
            }
        }
    }
}

/// Drops from rest (held at +1 g, released, falling, striking): the level the contact is
/// measured from is free fall (the sensor's zero force) whatever the rate, the foot or the
/// drop's height, and the first contact is right within 1 %, at several touch phases.
#[test]
fn drops_from_rest_are_measured_from_free_fall() {
    let scratch = Scratch::new();
    let laws = [
        (
            "linear",
            Model::Linear(impact_core::model::Linear { k: 1e4 }),
        ),
        ("hertz", Model::Hertz(impact_core::model::Hertz { k: 5e5 })),
        ("nonlinear", seed_nonlinear_stiff()),
        ("kelvin-voigt", kelvin_voigt_pad()),
        ("two-phase", seed_two_phase_pad()),
        // The seed's pad with its set from force continuity (`x_p = x_m (1 − kc/kr)`): a
        // set that follows the crush, from 91 mm or 5 mm.
        (
            "two-phase-continuous",
            Model::TwoPhase(TwoPhase {
                permanent_m: None,
                ..match seed_two_phase_pad() {
                    Model::TwoPhase(p) => p,
                    _ => unreachable!(),
                }
            }),
        ),
    ];
    for (name, law) in laws {
        for (height, rate) in [
            (0.091, 500_000.0),
            (0.091, 100_000.0),
            (0.091, 20_000.0),
            (0.005, 500_000.0),
            (0.005, 20_000.0),
        ] {
            // Not the seed's two-phase pad from 5 mm: its fixed set (18.2 mm) lies deeper than
            // that drop's crush (6.7 mm), so the pad lets go at the crush (COR 0; a 1 %
            // tolerance on 0 is none) and the body's stop coincides with the contact's end
            // (`no-stop` at 20 kS/s where the sums' stop falls just past it). The pad whose
            // set follows the crush stands in for it.
            if name == "two-phase" && height < 0.01 {
                continue;
            }
            for phase in [0.0, 0.37, 0.5, 0.71] {
                let drop = from_rest(law, height, rate, phase);
                let what = format!("{name} from {height} m at {rate} S/s, phase {phase}");
                let (text, truth) = csv(&drop, rate, 1.0, 2000.0);
                let h = height.to_string();
                let a = analyse(
                    &scratch,
                    &format!("{name}-{height}-{rate}-{phase}.csv"),
                    text,
                    // The sensor's range, as a lab gives it (no rails guessed from a flat
                    // peak: the two-phase law's is flat for many samples at 500 kS/s).
                    &["--drop-height", &h, "--range", "2000"],
                );
                let impacts = a["impacts"].as_array().unwrap();
                assert_eq!(impacts.len(), 1, "{what}: {impacts:#?}");
                let r = &impacts[0];
                assert_eq!(r["status"], "complete", "{what}");
                // No flag but `decimated` (a contact longer than the capture, kept at a
                // coarser step: the 5 mm drop on the soft pad, 32 ms).
                assert!(
                    r["flags"]
                        .as_array()
                        .unwrap()
                        .iter()
                        .all(|f| f == "decimated"),
                    "{what}: {}",
                    r["flags"]
                );
                // The level is free fall (0 here: csv() adds no offset), not rest (+1 g):
                // within 2 % of g (a soft pad's slow foot, below the noise for its first
                // strides, lifts it by up to 0.09 m/s²).
                assert!(
                    r["baseline_m_s2"].as_f64().unwrap().abs() < 0.02 * G,
                    "{what}: baseline {}",
                    r["baseline_m_s2"]
                );
                within(
                    &r["impact_velocity_m_s"],
                    truth[0].approach_m_s,
                    1e-3,
                    &what,
                );
                check(r, &truth[0], name, &what, rate);
                if name == "two-phase" && rate < 1e5 {
                    // The step at the crush placed there: the COR and the energy within
                    // 0.3 % (the step's half sample at the interval's edge was +0.88 % and
                    // −1.05 % of m v0²/2).
                    let s = truth[0].separation.unwrap();
                    within(&r["cor"], s.cor, 3e-3, &format!("{what}: cor, step placed"));
                    let e0 = 0.5 * 0.06 * truth[0].approach_m_s.powi(2);
                    let e = r["absorbed_energy_j"].as_f64().unwrap();
                    assert!(
                        (e - s.absorbed_energy_j).abs() <= 3e-3 * e0,
                        "{what}: energy {:+.3} % of m v0²/2",
                        (e - s.absorbed_energy_j) / e0 * 100.0
                    );
                }
            }
        }
    }
}

/// Seed 001's law `k x (1 + c v)` stiff enough for a drop's contact of a few ms.
fn seed_nonlinear_stiff() -> Model<f64> {
    Model::Nonlinear(Nonlinear {
        k: 1e4,
        c: 0.5,
        n: 1.0,
    })
}

/// Bounce trains on pads that recover (Kelvin–Voigt: the body leaves `x_sep = c v / k` deep
/// and lands on the surface it touched, higher) and on one that keeps its dent (the two-phase
/// pad's first contact: it lands where it left), each bounce's approach from the flight
/// (`--train flight`): the landing height is the pad's, and v0, the rebound and the COR are
/// within 1 % on every bounce (a flight taken to land where it left had a Kelvin–Voigt pad's
/// v0 up to 1.9 % high and its COR 5.2 % low by bounce 7). A first approach speed given
/// 0.3 % high moves no later bounce's landing (the rebound decides only where the two
/// landings are far apart).
#[test]
fn a_bounce_lands_where_the_pad_is() {
    let scratch = Scratch::new();
    for (name, law, v0) in [
        ("kelvin-voigt", kelvin_voigt_pad(), "1.3357"),
        ("two-phase", seed_two_phase_pad(), "1.3357"),
        ("kelvin-voigt", kelvin_voigt_pad(), "1.34"),
    ] {
        for rate in [500_000.0, 100_000.0] {
            let (text, truth) = csv(&moving(law, 8), rate, 2.0, 1000.0);
            let a = analyse(
                &scratch,
                &format!("landing-{name}-{rate}-{v0}.csv"),
                text,
                &["--v0", v0, "--train", "flight"],
            );
            let impacts = a["impacts"].as_array().unwrap();
            assert_eq!(impacts.len(), truth.len(), "{name} at {rate}");
            for (i, (r, t)) in impacts.iter().zip(&truth).enumerate() {
                let what = format!("{name} at {rate} S/s from {v0} m/s, bounce {i}");
                if i == 0 && v0 != "1.3357" {
                    continue;
                }
                within(
                    &r["impact_velocity_m_s"],
                    t.approach_m_s,
                    0.01,
                    &format!("{what}: v0"),
                );
                let s = t.separation.unwrap();
                within(&r["cor"], s.cor, 0.01, &format!("{what}: cor"));
                within(
                    &r["rebound_velocity_m_s"],
                    s.rebound_m_s,
                    0.01,
                    &format!("{what}: rebound"),
                );
                if i == 0 {
                    continue;
                }
                // The rebound's measure of the speed, landed, as well as the flight's (the
                // plain rebound was 3.8 % high on the Kelvin–Voigt pad's bounce 7).
                within(
                    &r["bounce"]["v0_rebound_m_s"],
                    t.approach_m_s,
                    0.01,
                    &format!("{what}: v0 from the rebound"),
                );
                // The truth: from the previous separation up to the pad's recovered surface.
                let p = truth[i - 1].separation.unwrap();
                let rise = p.deformation_m - p.set_m;
                // Chosen right wherever it matters: its error moves v0 by `Δh / t`, held
                // within 0.5 % (where the rebound cannot tell the pads apart, neither can
                // v0).
                let b = &r["bounce"];
                let h = b["landing_height_m"].as_f64().unwrap();
                let flight = b["flight_s"].as_f64().unwrap();
                assert!(
                    (h - rise).abs() / flight <= 0.005 * t.approach_m_s,
                    "{what}: landing {h} m vs true {rise} m"
                );
                if i == 1 && name == "two-phase" {
                    // The crushed pad: 18 mm deep where the body left, and it lands there.
                    assert_eq!(h, 0.0, "{what}");
                }
                if name == "kelvin-voigt" {
                    assert!(h > 0.0, "{what}: recovered");
                }
            }
        }
    }
}

/// A soft pad (seed 001's law at k 240 N/m, c 0.5 s/m: contacts of 55–76 ms) on which the
/// body settles after six bounces: its seventh contact never ends (the force dips to 0.04 g
/// and rises again, the body never leaves). A vertical scene's edge level lies at its noise
/// (the free-fall level is the zero force), so every bounce is found whole (COR within 1 %;
/// a fifth of the trigger cut the sixth's contact 0.65 ms short, COR +1.7 %) and the
/// settling is one impact that never separates, without COR, not three contacts with
/// flights between them.
#[test]
fn a_body_settling_on_a_soft_pad_is_one_contact_that_never_ends() {
    let scratch = Scratch::new();
    let law = Model::Nonlinear(Nonlinear {
        k: 240.0,
        c: 0.5,
        n: 1.0,
    });
    let (text, truth) = csv(&moving(law, 9), 500_000.0, 2.0, 156.9);
    assert!(truth.last().unwrap().separation.is_none());
    let a = analyse(
        &scratch,
        "settling.csv",
        text,
        &[
            "--v0",
            "1.3357",
            "--train",
            "flight",
            "--range",
            "156.9",
            "--capture-samples",
            "131072",
        ],
    );
    let impacts = a["impacts"].as_array().unwrap();
    assert_eq!(impacts.len(), truth.len(), "{impacts:#?}");
    for (i, (r, t)) in impacts.iter().zip(&truth).enumerate() {
        let what = format!("soft pad, bounce {i}");
        match t.separation {
            Some(s) => {
                within(
                    &r["impact_velocity_m_s"],
                    t.approach_m_s,
                    0.01,
                    &format!("{what}: v0"),
                );
                within(&r["cor"], s.cor, 0.01, &format!("{what}: cor"));
            }
            None => {
                assert_ne!(r["status"], "complete", "{what}: {r}");
                assert!(r["cor"].is_null(), "{what}: {r}");
            }
        }
    }
}

/// Bounce trains of every law (linear and Hertz elastic, Kelvin–Voigt, the seed's two-phase
/// pad, seed 001's law stiff and soft: contacts of 1 to 60 ms), at 500, 100 and 20 kS/s, with
/// the kinematics' speed from the flight (`--train flight`): v0, the rebound, the COR, the
/// rebound's measure of the speed, the crush time, x_m, the set, the deformation at
/// separation, the energy and the peak force within 1 % on every bounce that separates
/// ([`check`]; bounces 1 and 3 at 20 kS/s were 2.3 samples early, crush time +3 %, x_m +4.7 %, where
/// the walk back through the foot's noise after a flight set first touch). From the
/// previous rebound (`--train rebound`, a chain: each bounce's speed the previous rebound
/// brought down by the flight's time, `g t - v_r`), v0, the COR and the rebound within 1 % at
/// 500 and 100 kS/s on every pad (a Kelvin–Voigt pad's bounce 5 was 1.9 % fast when the
/// chain landed each bounce where it left). At 20 kS/s the chain adds each contact's Δv error
/// (up to 0.3 % of the speed): v0 within 1 % on every bounce, and each contact's own rebound
/// and COR within 1 % of what the true contact gives at the chain's speed (`Δv - v0`: the
/// true rebound plus the speed's error), not of the truth, which the chain's speed error
/// moves by `1/COR` and `1 + 1/COR` times its share.
#[test]
fn bounce_trains_of_every_law_within_one_percent() {
    let scratch = Scratch::new();
    let laws = [
        (
            "linear",
            Model::Linear(impact_core::model::Linear { k: 1e4 }),
        ),
        ("hertz", Model::Hertz(impact_core::model::Hertz { k: 5e5 })),
        ("kelvin-voigt", kelvin_voigt_pad()),
        ("two-phase", seed_two_phase_pad()),
        ("nonlinear-stiff", seed_nonlinear_stiff()),
        ("nonlinear", seed_nonlinear()),
    ];
    for (name, law) in laws {
        for rate in [500_000.0, 100_000.0, 20_000.0] {
            let (text, truth) = csv(&moving(law, 6), rate, 1.5, 1000.0);
            for speed in ["flight", "rebound"] {
                // The chain at 20 kS/s: the speed within 1 %, each contact's rebound and
                // COR within 1 % of the true contact's at that speed.
                let chained = speed == "rebound" && rate < 1e5;
                let a = analyse(
                    &scratch,
                    &format!("every-{name}-{rate}-{speed}.csv"),
                    text.clone(),
                    &["--v0", "1.3357", "--train", speed],
                );
                let impacts = a["impacts"].as_array().unwrap();
                assert_eq!(impacts.len(), truth.len(), "{name} at {rate} S/s, {speed}");
                for (i, (r, t)) in impacts.iter().zip(&truth).enumerate() {
                    let what = format!("{name} at {rate} S/s, {speed}, bounce {i}");
                    let Some(s) = t.separation else { continue };
                    within(
                        &r["impact_velocity_m_s"],
                        t.approach_m_s,
                        0.01,
                        &format!("{what}: v0"),
                    );
                    let v0 = r["impact_velocity_m_s"].as_f64().unwrap();
                    // The rebound `Δv - v0` at the speed used: the true rebound plus that
                    // speed's error (none but the chain's is measurably off).
                    let rebound = if chained {
                        s.rebound_m_s + t.approach_m_s - v0
                    } else {
                        s.rebound_m_s
                    };
                    let cor = if chained { rebound / v0 } else { s.cor };
                    within(&r["cor"], cor, 0.01, &format!("{what}: cor"));
                    within(
                        &r["rebound_velocity_m_s"],
                        rebound,
                        0.01,
                        &format!("{what}: rebound"),
                    );
                    if i > 0 && speed == "flight" {
                        within(
                            &r["bounce"]["v0_rebound_m_s"],
                            t.approach_m_s,
                            0.01,
                            &format!("{what}: v0 from the rebound"),
                        );
                    }
                    // Every bounce's crush time, x_m, set, energy and peak force too.
                    if speed == "flight" {
                        check(r, t, name, &what, rate);
                    }
                }
            }
        }
    }
}

/// The laws of a 1 ms contact for the 60 g body: linear, Hertz, seed 001's law and
/// Kelvin–Voigt.
fn one_millisecond_laws() -> [(&'static str, Model<f64>); 4] {
    let k = 0.06 * (std::f64::consts::PI / 1e-3f64).powi(2);
    [
        ("linear", Model::Linear(impact_core::model::Linear { k })),
        (
            "hertz",
            Model::Hertz(impact_core::model::Hertz { k: 3.0e7 }),
        ),
        (
            "nonlinear",
            Model::Nonlinear(Nonlinear { k, c: 0.3, n: 1.0 }),
        ),
        (
            "kelvin-voigt",
            Model::KelvinVoigt(KelvinVoigt { k, c: 20.0 }),
        ),
    ]
}

/// Law `name` dropped from rest 91 mm at `rate`, touch `phase` of a sample in, analysed
/// (±20 000 m/s²): its one impact and the truth.
fn one_millisecond_drop(
    scratch: &Scratch,
    name: &str,
    law: Model<f64>,
    rate: f64,
    phase: f64,
) -> (Value, ContactTruth) {
    let drop = from_rest(law, 0.091, rate, phase);
    let (text, truth) = csv(&drop, rate, 0.5, 20_000.0);
    let a = analyse(
        scratch,
        &format!("short-{name}-{rate}-{phase}.csv"),
        text,
        &["--drop-height", "0.091", "--range", "20000"],
    );
    let impacts = a["impacts"].as_array().unwrap();
    assert_eq!(
        impacts.len(),
        1,
        "{name} at {rate} S/s, phase {phase}: {impacts:#?}"
    );
    let truth = truth.into_iter().next().expect("one contact");
    (impacts[0].clone(), truth)
}

/// 1 ms contacts (linear, Hertz, seed 001's law and Kelvin–Voigt, 91 mm drops from rest) at
/// coarse rates, eight touch phases: at 100 kS/s (100 samples a contact) every field within
/// 1 % ([`check`]: Kelvin–Voigt's set null);
/// at 20 kS/s (20 samples) first touch within a tenth of a sample and the COR, crush time and
/// `x_m` within 1 % for the laws whose force starts from zero (linear, Hertz, seed 001's):
/// the onset's step past the flank level is placed from its first three samples, not in the
/// middle of the interval before it (up to ±6 % on `x_m`), and so is an onset just past the
/// edge level whose next two samples lie on its power curve (Hertz at phase 0.25: the walk
/// back to the baseline had it 0.87 samples early, `x_m` +12.6 %), and an onset whose curve
/// reaches zero just before the sample before it, which the sampling put at the baseline
/// (Hertz at phase 0.375, touch 0.009 of a sample before that sample: taken for a jump, touch
/// half a sample late, `x_m` −7.5 %), or just before a sample on the foot within the edge
/// level, which lies on one power curve with the onset's first two (seed 001's law at phase
/// 0.375: the onset's head too bent for a curve of its own, `x_m` −8.6 %).
/// At 10 and 5 kS/s (5 and 2.5 samples to the crush: a wrong guess of where in the interval
/// before the onset touch fell had moved `x_m` by −15 % and −28 %) every law, Kelvin–Voigt
/// too, is flagged `undersampled`, its crush time, deformations and fits null with that
/// reason, its COR within 5 % and 10 %.
/// Kelvin–Voigt at 20 kS/s too: where its jump is smaller than a sample's rise (phases
/// 0.125–0.375) the onset's first samples lie on a line whose zero falls in the interval
/// before it, and that line had put touch 0.7 samples early (`x_m` +11 %); now the
/// compression's law places touch there too, the line's zero standing where the law's fit
/// refutes a jump (`core/src/analysis/jump.rs`).
#[test]
fn a_one_millisecond_contact_at_coarse_rates() {
    let scratch = Scratch::new();
    for (name, law) in one_millisecond_laws() {
        for rate in [100_000.0, 20_000.0, 10_000.0, 5_000.0] {
            for phase in [0.0, 0.125, 0.25, 0.375, 0.5, 0.625, 0.75, 0.875] {
                let what = format!("1 ms {name} at {rate} S/s, phase {phase}");
                let (r, t) = &one_millisecond_drop(&scratch, name, law, rate, phase);
                // First touch within the sample interval the report states, at every rate.
                let u = r["touch_uncertainty_s"].as_f64().unwrap();
                assert_eq!(u, 1.0 / rate, "{what}");
                let start = r["start_s"].as_f64().unwrap();
                assert!(
                    (start - t.touch_s).abs() <= u,
                    "{what}: touch {start} vs {}",
                    t.touch_s
                );
                if rate >= 1e5 {
                    check(r, t, name, &what, rate);
                } else if rate < 16e3 {
                    // Fewer than 8 samples to the crush (5 at 10 kS/s): where in the interval
                    // before the onset the contact began the samples cannot tell, so no crush
                    // time, deformation or fit, each saying why; the COR (from Δv) within the
                    // issue's 5 % at 10 kS/s, 10 % at 5 kS/s.
                    // (Or, an elastic contact's Δv read past the COR's tolerance above 1 at
                    // 5 kS/s, no kinematics at all, `cor-out-of-range`.)
                    let flags = r["flags"].as_array().unwrap();
                    let cor = t.separation.unwrap().cor;
                    if rate < 1e4 && cor > 0.95 && flags.iter().any(|f| f == "cor-out-of-range") {
                        assert_eq!(r["null_reasons"]["cor"], "cor-out-of-range", "{what}");
                        assert_eq!(r["null_reasons"]["crush_time_s"], "cor-out-of-range");
                        continue;
                    }
                    assert!(
                        flags.iter().any(|f| f == "undersampled"),
                        "{what}: {flags:?}"
                    );
                    for field in [
                        "crush_time_s",
                        "max_deformation_m",
                        "separation_deformation_m",
                        "permanent_deformation_m",
                    ] {
                        assert!(r[field].is_null(), "{what}: {field} {}", r[field]);
                        assert_eq!(r["null_reasons"][field], "undersampled", "{what}: {field}");
                    }
                    // No fit either (they take `x_m` and first touch), each saying why.
                    for fit in ["two_phase", "nonlinear", "hertz"] {
                        assert!(r["fits"][fit].is_null(), "{what}: {fit} {}", r["fits"][fit]);
                        let why = &r["null_reasons"][format!("fits.{fit}")];
                        assert_eq!(why, "undersampled", "{what}: {fit}");
                    }
                    let tolerance = if rate >= 1e4 { 0.05 } else { 0.1 };
                    within(&r["cor"], cor, tolerance, &what);
                } else {
                    // First touch from the step's three samples: within a tenth of a sample.
                    let start = r["start_s"].as_f64().unwrap();
                    assert!(
                        (start - t.touch_s).abs() * rate <= 0.1,
                        "{what}: first touch {:+.3} samples",
                        (start - t.touch_s) * rate
                    );
                    assert!(
                        !r["flags"]
                            .as_array()
                            .unwrap()
                            .iter()
                            .any(|f| f == "undersampled"),
                        "{what}"
                    );
                    within(&r["cor"], t.separation.unwrap().cor, 0.01, &what);
                    within(&r["crush_time_s"], t.crush_time_s.unwrap(), 0.01, &what);
                    within(
                        &r["max_deformation_m"],
                        t.max_deformation_m.unwrap(),
                        0.01,
                        &what,
                    );
                }
            }
        }
    }
}

/// Between 16 and 25 kS/s (16 to 25 samples a 1 ms contact, 8 to 12 to the crush), ten
/// touch phases (0.95 and 0.99: touch just after a sample): every crush time and `x_m`
/// within 2 % of the truth, or null as `undersampled`; the COR within 2 % always (Δv:
/// Kelvin–Voigt at 16 kS/s phase 0.375 −1.1 %). Where
/// the onset's samples lie on a line (a ramp, or a jump after its zero onto one) or a jump's
/// middle stands, and the compression's law could not place touch (too few samples, or
/// touch before the quiet sample before the onset), the reach of touch at `v0` is stated
/// against 1 % of `x_m` (`Summary::touch_reach`): Kelvin–Voigt at 16 kS/s phases 0, 0.95
/// and 0.99 had been +11.5 % on `x_m`, seed 001's law at 25 kS/s phase 0.25 −6.6 %,
/// unflagged.
#[test]
fn between_sixteen_and_twenty_five_kilosamples_within_two_percent_or_undersampled() {
    let scratch = Scratch::new();
    let (mut held, mut null) = (0, 0);
    for (name, law) in one_millisecond_laws() {
        for rate in [25_000.0, 16_000.0] {
            for phase in [0.0, 0.125, 0.25, 0.375, 0.5, 0.625, 0.75, 0.875, 0.95, 0.99] {
                let what = format!("1 ms {name} at {rate} S/s, phase {phase}");
                let (r, t) = &one_millisecond_drop(&scratch, name, law, rate, phase);
                within(&r["cor"], t.separation.unwrap().cor, 0.02, &what);
                // (The cases that had been wrong, unflagged: null.)
                let was_wrong = matches!(
                    (name, rate as u32, phase),
                    ("kelvin-voigt", 16_000, 0.0 | 0.95 | 0.99) | ("nonlinear", 25_000, 0.25)
                );
                for (field, want) in [
                    ("crush_time_s", t.crush_time_s.unwrap()),
                    ("max_deformation_m", t.max_deformation_m.unwrap()),
                ] {
                    assert!(
                        !was_wrong || r[field].is_null(),
                        "{what}: {field} {}",
                        r[field]
                    );
                    if r[field].is_null() {
                        assert_eq!(r["null_reasons"][field], "undersampled", "{what}: {field}");
                        null += 1;
                    } else {
                        within(&r[field], want, 0.02, &what);
                        held += 1;
                    }
                }
            }
        }
    }
    // Most stand (every phase at 25 kS/s but one); the null ones say why.
    assert!(held >= 100 && null >= 10, "{held} held, {null} null");
}
