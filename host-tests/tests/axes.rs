//! `--axes`: a pulse split over two axes at a known angle (and a quiet third) gives the
//! single-axis pulse's peak as the resultant's, and each axis its share of the peak and Δv.

mod common;

use common::{impact_ok, synth_t2, Scratch};
use serde_json::Value;

#[test]
fn a_pulse_split_over_axes_gives_each_its_share() {
    let one = synth_t2();
    let (c, s) = (0.6f64, 0.8f64);
    let mut three = String::from("time_s,x_g,y_g,z_g\n");
    for line in one.lines().skip(1) {
        let (t, a) = line.split_once(',').unwrap();
        let a: f64 = a.parse().unwrap();
        three.push_str(&format!("{t},{:.9e},{:.9e},0\n", a * c, a * s));
    }
    let scratch = Scratch::new();
    let (f1, f3) = (
        scratch.file("one.csv", &one),
        scratch.file("three.csv", &three),
    );
    let json = |args: &[&str]| -> Value {
        let mut a = vec!["analyze"];
        a.extend_from_slice(args);
        a.push("--json");
        serde_json::from_str(&impact_ok(&a).0).unwrap()
    };
    let single = json(&[f1.to_str().unwrap()]);
    let axes = json(&[f3.to_str().unwrap(), "--axes", "x_g,y_g,z_g"]);
    let (i1, i3) = (&single["impacts"][0], &axes["impacts"][0]);
    assert_eq!(axes["impacts"].as_array().unwrap().len(), 1);
    let peak = i1["peak_acceleration_m_s2"].as_f64().unwrap();
    let dv = i1["delta_v_m_s"].as_f64().unwrap();
    let x = &i3["axes"];
    let close = |got: f64, want: f64, what: &str| {
        assert!(
            (got - want).abs() < 0.01 * want.abs() + 0.5,
            "{what}: {got} vs {want}"
        )
    };
    // The synthetic pulse sits on an offset: the resultant's peak is the offset plus the pulse
    // in the same direction, so compare each axis (baseline removed) instead.
    let ax = &x["axes"];
    close(
        ax[0]["peak_acceleration_m_s2"].as_f64().unwrap(),
        c * peak,
        "x peak",
    );
    close(
        ax[1]["peak_acceleration_m_s2"].as_f64().unwrap(),
        s * peak,
        "y peak",
    );
    assert!(ax[2]["peak_acceleration_m_s2"].as_f64().unwrap().abs() < 1e-9);
    let close_dv = |got: f64, want: f64, what: &str| {
        assert!(
            (got - want).abs() < 0.01 * want.abs(),
            "{what}: {got} vs {want}"
        )
    };
    close_dv(ax[0]["delta_v_m_s"].as_f64().unwrap(), c * dv, "x Δv");
    close_dv(ax[1]["delta_v_m_s"].as_f64().unwrap(), s * dv, "y Δv");
    close_dv(x["delta_v_magnitude_m_s"].as_f64().unwrap(), dv, "|Δv|");
    assert!(i3["delta_v_m_s"].is_null());
    assert_eq!(i3["null_reasons"]["delta_v_m_s"], "resultant");
    // An approach speed does not apply to a resultant.
    let (code, _, err) = common::impact(&[
        "analyze",
        f3.to_str().unwrap(),
        "--axes",
        "x_g,y_g",
        "--v0",
        "1",
    ]);
    assert_eq!(code, 2, "{err}");
    // One axis is no resultant; a repeated one is refused.
    for bad in ["x_g", "x_g,x_g"] {
        let (code, _, err) = common::impact(&["analyze", f3.to_str().unwrap(), "--axes", bad]);
        assert_ne!(code, 0);
        assert!(err.contains("--axes"), "{err}");
    }
}
