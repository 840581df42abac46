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

#[test]
fn the_capture_counter_becomes_one_time_line_across_its_wraps() {
    use impact_firmware::light_gate::{in_capture_order, CaptureClock, HALF_WRAP_US};
    let mut c = CaptureClock::new();
    // The first capture starts the line at the coarse clock.
    assert_eq!(c.extend(4_294_960_000, 5_000_000), 5_000_000);
    // 7486 µs later, across the counter's wrap: exact, whatever the coarse clock's jitter.
    assert_eq!(
        c.extend(4_294_960_000u32.wrapping_add(7_486), 5_007_700),
        5_007_486
    );
    // A minute later, and many wraps' worth of captures a minute apart: still on the counts.
    let mut raw = 4_294_960_000u32.wrapping_add(7_486);
    let mut t = 5_007_486u64;
    for k in 1..200u64 {
        raw = raw.wrapping_add(60_000_000);
        t += 60_000_000;
        assert_eq!(c.extend(raw, t + 3_000 + k), t, "capture {k}");
    }
    // After more than half a wrap of silence the counts cannot tell: the coarse clock again,
    // and the counts from there.
    let late = t + HALF_WRAP_US + 10_000;
    assert_eq!(c.extend(raw.wrapping_add(12_345), late), late);
    assert_eq!(
        c.extend(raw.wrapping_add(22_345), late + 10_050),
        late + 10_000
    );
    // A capture read after a later one of the other beam (its interrupt came late) is placed
    // before it, not a wrap ahead; the next is placed from it.
    let mut c = CaptureClock::new();
    assert_eq!(c.extend(1_000_000, 9_000_000), 9_000_000);
    assert_eq!(c.extend(1_000_500, 9_000_600), 9_000_500);
    assert_eq!(c.extend(1_000_450, 9_000_610), 9_000_450);
    assert_eq!(c.extend(1_010_450, 9_010_500), 9_010_450);
    // Two captures read in one interrupt are ordered by their counts, across the wrap too.
    assert_eq!(in_capture_order((10, 'a'), (5, 'b')), [(5, 'b'), (10, 'a')]);
    assert_eq!(
        in_capture_order((3, 'a'), (u32::MAX - 2, 'b')),
        [(u32::MAX - 2, 'b'), (3, 'a')]
    );
    assert_eq!(in_capture_order((7, 'a'), (7, 'b')), [(7, 'a'), (7, 'b')]);
}
