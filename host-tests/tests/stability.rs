//! The stability sweep's bounds (the full table: `impact bench stability --full`).

use impact_host::bench::stability;

#[test]
fn every_result_is_finite_and_within_its_bound_or_reported_unresolved() {
    let rows = stability::run(false);
    assert!(rows.len() > 50);
    for r in &rows {
        assert_eq!(r.non_finite, 0, "{r:?}");
        assert_eq!(r.out_of_bound, 0, "{r:?}");
        assert_eq!(r.cases, r.resolved + r.unresolved, "{r:?}");
    }
    // The exact and adaptive solvers resolve everything; fixed steps refuse 4 steps per
    // contact and resolve the well-scaled cases at 256.
    for r in rows
        .iter()
        .filter(|r| r.solver == "exact" || r.solver.starts_with("adaptive"))
    {
        assert_eq!(r.unresolved, 0, "{r:?}");
    }
    for r in rows.iter().filter(|r| r.solver.ends_with(" 4")) {
        assert_eq!(r.resolved, 0, "{r:?}");
    }
    for r in rows.iter().filter(|r| r.solver.ends_with(" 256")) {
        assert!(r.resolved * 2 >= r.cases, "{r:?}");
    }
}

#[test]
fn targets_from_a_feather_to_a_wall_stay_within_their_bounds() {
    let rows = impact_host::bench::two_body::stability(false);
    assert!(rows.len() >= 16);
    for r in &rows {
        assert_eq!(r.non_finite, 0, "{r:?}");
        assert_eq!(r.out_of_bound, 0, "{r:?}");
        assert_eq!(r.cases, r.resolved + r.unresolved, "{r:?}");
        // Every solver offered resolves every target; the closed form on a sprung target is
        // f64 only (it refuses f32, counted unresolved).
        if !(r.solver == "exact" && r.precision == "f32") {
            assert_eq!(r.unresolved, 0, "{r:?}");
        }
    }
}
