//! The firmware's light-gate speed computation (hardware-free part), on the host.

use impact_firmware::light_gate::{speed_m_s, GateError};

#[test]
fn speed_from_two_beam_cuts() {
    // Seed bench: 10 mm apart at 1.3357 m/s is 7486.7 µs.
    let v = speed_m_s(1_000_000, 1_007_487, 0.010).unwrap();
    assert!((v - 1.3357).abs() < 1e-3, "{v}");
    assert_eq!(speed_m_s(5, 5 + 10_000, 0.01), Ok(1.0));
}

#[test]
fn bad_readings_are_refused_not_guessed() {
    assert_eq!(speed_m_s(100, 50, 0.01), Err(GateError::Order));
    assert_eq!(speed_m_s(100, 100, 0.01), Err(GateError::Order));
    assert_eq!(speed_m_s(0, 10_000_000, 0.01), Err(GateError::Implausible)); // 1 mm/s
    assert_eq!(speed_m_s(0, 10, 0.01), Err(GateError::Implausible)); // 1000 m/s
    assert_eq!(speed_m_s(0, 10_000, f32::NAN), Err(GateError::Spacing));
    assert_eq!(speed_m_s(0, 10_000, -0.01), Err(GateError::Spacing));
}

#[test]
fn cuts_pair_into_passages_with_their_direction() {
    use impact_firmware::light_gate::{Beam, Pairing, Passage, PAIRING_WINDOW_US};
    let mut g = Pairing::new();
    // Toward the barrier: first then second beam.
    assert_eq!(g.cut(Beam::First, 1_000, 0.01), None);
    assert_eq!(
        g.cut(Beam::Second, 11_000, 0.01),
        Some(Ok(Passage::Toward(1.0)))
    );
    // The rebound: second then first.
    assert_eq!(g.cut(Beam::Second, 50_000, 0.01), None);
    assert_eq!(
        g.cut(Beam::First, 70_000, 0.01),
        Some(Ok(Passage::Away(0.5)))
    );
    // A repeated cut of one beam replaces the pending one; a late second cut starts anew.
    assert_eq!(g.cut(Beam::First, 100_000, 0.01), None);
    assert_eq!(g.cut(Beam::First, 105_000, 0.01), None);
    assert_eq!(
        g.cut(Beam::Second, 115_000, 0.01),
        Some(Ok(Passage::Toward(1.0)))
    );
    assert_eq!(g.cut(Beam::First, 200_000, 0.01), None);
    assert_eq!(g.cut(Beam::Second, 200_001 + PAIRING_WINDOW_US, 0.01), None);
    // Same instant: not a speed.
    assert_eq!(
        g.cut(Beam::First, 200_001 + PAIRING_WINDOW_US, 0.01),
        Some(Err(GateError::Order))
    );
}

/// A receiver's output bouncing as the body's edge crosses the beam: a burst of edges closer
/// than `DEBOUNCE_US` is one cut, at its first edge (the burst before took the last edge
/// for the first beam, a speed too high, and could fill the four-cut queue); cuts of a real
/// passage at the fastest speed believed stay apart, also across the clock's wrap.
#[test]
fn a_bouncing_beam_is_one_cut_at_its_first_edge() {
    use impact_firmware::light_gate::{new_cut, DEBOUNCE_US};
    let accepted = |edges: &[u32]| -> Vec<u32> {
        let mut last = None;
        let mut out = Vec::new();
        for &t in edges {
            if new_cut(last, t) {
                out.push(t);
            }
            last = Some(t);
        }
        out
    };
    assert_eq!(accepted(&[1000, 1003, 1010, 1045, 1090, 1120]), vec![1000]);
    assert_eq!(accepted(&[1000, 1003, 2000, 2004]), vec![1000, 2000]);
    // 100 m/s through 10 mm: 100 µs between the beams' cuts; one beam's rebound re-cut.
    assert_eq!(
        accepted(&[5000, 5000 + DEBOUNCE_US]),
        vec![5000, 5000 + DEBOUNCE_US]
    );
    let wrap = u32::MAX - 10;
    assert_eq!(
        accepted(&[wrap, wrap.wrapping_add(20), wrap.wrapping_add(500)]),
        vec![wrap, wrap.wrapping_add(500)]
    );
}
