//! The physical drop generator (`impact_host::drop`), the oracle of the drop and bounce-train
//! tests, against an independent integrator before any test trusts it: SciPy's DOP853 with
//! its own event location, stored by `scripts/peer_drop.py` in `scripts/peer_drop.csv`.
//! Every contact's quantities and every stored sample agree to 1e-6 relative.

use std::collections::BTreeMap;

use impact_core::model::{Hertz, KelvinVoigt, Linear, Nonlinear, TwoPhase};
use impact_core::Model;
use impact_host::drop::{Drop, Rendered, Start};

const G: f64 = impact_core::consts::STANDARD_GRAVITY;

/// The cases of `scripts/peer_drop.py`'s `CASES`, spelled again: (name, drop, rate, samples).
fn cases() -> Vec<(&'static str, Drop, f64, usize)> {
    let drop = |law, m: f64, g: f64, start, contacts| Drop {
        law,
        mass_kg: m,
        gravity_m_s2: g,
        start,
        max_contacts: contacts,
        min_rebound_m_s: 1e-6,
    };
    let seed_height = 1.3357f64.powi(2) / (2.0 * G);
    let hertz_k = 4.0 / 3.0 * (200e9 / (2.0 * (1.0 - 0.3f64.powi(2)))) * 6.35e-3f64.sqrt();
    vec![
        (
            "nonlinear-train",
            drop(
                Model::Nonlinear(Nonlinear {
                    k: 250.0,
                    c: 0.3,
                    n: 1.0,
                }),
                0.06,
                G,
                Start::Rest {
                    rest_s: 0.02,
                    height_m: seed_height,
                },
                8,
            ),
            20_000.0,
            30_000,
        ),
        (
            "kv-rest",
            drop(
                Model::KelvinVoigt(KelvinVoigt { k: 1e4, c: 5.0 }),
                0.06,
                G,
                Start::Rest {
                    rest_s: 0.05,
                    height_m: 0.091,
                },
                6,
            ),
            100_000.0,
            100_000,
        ),
        (
            "two-phase-seed",
            drop(
                Model::TwoPhase(TwoPhase {
                    kc: 0.06 * (1.3357f64 / 0.0186).powi(2),
                    kr: 12376.0,
                    c: 2.0,
                    permanent_m: Some(0.0182),
                }),
                0.06,
                G,
                Start::Rest {
                    rest_s: 0.01,
                    height_m: seed_height,
                },
                4,
            ),
            50_000.0,
            40_000,
        ),
        (
            "two-phase-continuous",
            drop(
                Model::TwoPhase(TwoPhase {
                    kc: 2e4,
                    kr: 8e4,
                    c: 0.0,
                    permanent_m: None,
                }),
                0.1,
                G,
                Start::Rest {
                    rest_s: 0.0,
                    height_m: 0.05,
                },
                5,
            ),
            100_000.0,
            60_000,
        ),
        (
            "hertz-steel",
            drop(
                Model::Hertz(Hertz { k: hertz_k }),
                8.419e-3,
                G,
                Start::Rest {
                    rest_s: 0.001,
                    height_m: 0.02,
                },
                3,
            ),
            1_000_000.0,
            150_000,
        ),
        (
            "linear-horizontal",
            drop(
                Model::Linear(Linear { k: 5e4 }),
                0.2,
                0.0,
                Start::Moving {
                    touch_s: 0.003,
                    v0_m_s: 2.0,
                },
                1,
            ),
            200_000.0,
            4_000,
        ),
    ]
}

/// The peer's rows: case -> (index, quantity) -> value.
fn peer() -> BTreeMap<String, BTreeMap<(usize, String), f64>> {
    let text = include_str!("../../scripts/peer_drop.csv");
    let mut out: BTreeMap<String, BTreeMap<(usize, String), f64>> = BTreeMap::new();
    for line in text.lines().filter(|l| !l.starts_with('#')).skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let [case, index, quantity, value] = f[..] else {
            panic!("bad peer line {line}");
        };
        out.entry(case.to_string()).or_default().insert(
            (index.parse().unwrap(), quantity.to_string()),
            value.parse().unwrap(),
        );
    }
    out
}

/// The generator's value of a contact quantity the peer names.
fn ours(r: &Rendered, index: usize, quantity: &str) -> Option<f64> {
    if quantity == "accel_m_s2" {
        return r.accel_m_s2.get(index).copied();
    }
    let c = r.contacts.get(index)?;
    let s = c.separation;
    Some(match quantity {
        "touch_s" => c.touch_s,
        "approach_m_s" => c.approach_m_s,
        "peak_force_n" => c.peak_force_n,
        "crush_time_s" => c.crush_time_s?,
        "max_deformation_m" => c.max_deformation_m?,
        "contact_time_s" => s?.contact_time_s,
        "rebound_m_s" => s?.rebound_m_s,
        "separation_deformation_m" => s?.deformation_m,
        "set_m" => s?.set_m,
        other => panic!("unknown peer quantity {other}"),
    })
}

#[test]
fn the_generator_matches_scipy_to_one_part_in_a_million() {
    let peer = peer();
    let cases = cases();
    assert_eq!(
        peer.keys().collect::<Vec<_>>(),
        {
            let mut names: Vec<_> = cases.iter().map(|c| c.0).collect();
            names.sort();
            names
        },
        "the cases here and in scripts/peer_drop.py differ"
    );
    for (name, drop, rate, n) in cases {
        let r = drop.render(rate, n).unwrap();
        let rows = &peer[name];
        let peak_a = r.accel_m_s2.iter().fold(0.0f64, |a, &b| a.max(b.abs()));
        let mut compared = 0;
        let mut worst = 0.0f64;
        for ((index, quantity), &want) in rows {
            let got = ours(&r, *index, quantity)
                .unwrap_or_else(|| panic!("{name} {index} {quantity}: the generator has none"));
            // Deformations near zero (a set of 0, a separation at the surface) against the
            // contact's largest; samples against the case's largest.
            let scale = match quantity.as_str() {
                "separation_deformation_m" | "set_m" | "max_deformation_m" => rows
                    .get(&(*index, "max_deformation_m".to_string()))
                    .copied()
                    .unwrap_or(want),
                "accel_m_s2" => peak_a,
                _ => want,
            };
            assert!(
                (got - want).abs() <= 1e-6 * scale.abs(),
                "{name} {index} {quantity}: {got} vs SciPy {want} ({:.2e} relative)",
                (got - want).abs() / scale.abs()
            );
            compared += 1;
            worst = worst.max((got - want).abs() / scale.abs());
        }
        println!("{name}: {compared} values, worst {worst:.1e} relative");
        // Every contact the peer found, and no more.
        let peer_contacts = rows.keys().filter(|(_, q)| q == "touch_s").count();
        assert_eq!(r.contacts.len(), peer_contacts, "{name}: contacts");
        assert!(compared > 100, "{name}: only {compared} values compared");
    }
}
