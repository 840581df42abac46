//! Bounce scenes: closed-form flights, one solved contact per bounce.

use impact_core::consts::STANDARD_GRAVITY;
use impact_core::model::{KelvinVoigt, Linear, Nonlinear};
use impact_core::solve::bounce::Bounces;
use impact_core::{ContactLaw, Impact, Settings};

#[test]
fn kelvin_voigt_bounces_decay_geometrically_and_flights_are_closed_form() {
    let law = KelvinVoigt { k: 1e5, c: 20.0 };
    let (m, h, g) = (0.1, 1.0, STANDARD_GRAVITY);
    let cor = law.exact(&Impact::new(m, 1.0)).unwrap().cor; // KV: COR independent of v0
    let bounces: Vec<_> = Bounces::new(&law, Settings::exact(), m, h, g, 0.05, 1000)
        .unwrap()
        .collect::<Result<_, _>>()
        .unwrap();
    let v_first = (2.0 * g * h).sqrt();
    let expected = 1 + ((0.05f64 / v_first).ln() / cor.ln()).floor() as usize;
    assert_eq!(bounces.len(), expected);
    let mut t = (2.0 * h / g).sqrt();
    let mut v = v_first;
    for b in &bounces {
        assert!(
            (b.touch_time_s - t).abs() < 1e-12 * t.max(1.0),
            "bounce {}: {} vs {t}",
            b.index,
            b.touch_time_s
        );
        assert!((b.impact_velocity_m_s - v).abs() < 1e-12 * v);
        let v1 = v * cor;
        assert!((b.outcome.rebound_velocity_m_s - v1).abs() < 1e-12 * v);
        assert!((b.apex_height_m - v1 * v1 / (2.0 * g)).abs() < 1e-12);
        t += b.outcome.contact_time_s + 2.0 * v1 / g;
        v = v1;
    }
    assert!(bounces.last().unwrap().outcome.rebound_velocity_m_s < 0.05);
}

#[test]
fn the_cost_grows_with_contacts_not_flight_time() {
    // Same contacts, 100x longer flights (100x the drop height... and lower gravity).
    let law = Nonlinear {
        k: 1e4,
        c: 0.3,
        n: 1.0,
    };
    let settings = Settings::adaptive(1e-8);
    let evals = |h: f64, g: f64| -> (usize, u32) {
        let b: Vec<_> = Bounces::new(&law, settings, 0.05, h, g, 0.1, 50)
            .unwrap()
            .collect::<Result<_, _>>()
            .unwrap();
        (b.len(), b.iter().map(|b| b.outcome.rhs_evaluations).sum())
    };
    let (n1, e1) = evals(1.0, 9.81);
    let (n2, e2) = evals(100.0, 0.0981); // same impact speed, 100x the flight times
    assert_eq!(n1, n2);
    assert_eq!(e1, e2);
}

#[test]
fn an_elastic_law_stops_at_the_contact_cap_and_errors_end_the_sequence() {
    let law = Linear { k: 1e6 };
    let all: Vec<_> = Bounces::new(&law, Settings::exact(), 0.1, 0.5, 9.81, 1e-3, 7)
        .unwrap()
        .collect();
    assert_eq!(all.len(), 7);
    assert!(all.iter().all(|b| b.as_ref().unwrap().outcome.cor == 1.0));
    // A bad law: the first item is the error, then the iterator ends.
    let bad = Linear { k: -1.0 };
    let items: Vec<_> = Bounces::new(&bad, Settings::exact(), 0.1, 0.5, 9.81, 1e-3, 7)
        .unwrap()
        .collect();
    assert_eq!(items.len(), 1);
    assert!(items[0].is_err());
    assert!(Bounces::new(&law, Settings::exact(), 0.1, -1.0, 9.81, 1e-3, 7).is_err());
}
