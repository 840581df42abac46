//! Where a sensor really rails, and where it only rests: a pulse driven past a phone's ±16 g
//! range (its readings at 156.86 m/s², their neighbours up to 1 % lower) is clipped with the
//! range declared; a clean flat top is found without it; and a noise-free recording resting
//! at 1 g, its minimum, is not taken for a rail (its rest level was, and every pulse was
//! marked clipped).

mod common;

use common::{impact_ok, Scratch};

/// A 5 ms half-sine of `peak` (in the file's unit) over a rest of `rest`, at 10 kS/s from
/// 0.2 s of 0.5 s, each reading passed through `rail`.
fn recording(header: &str, rest: f64, peak: f64, rail: impl Fn(usize, f64) -> f64) -> String {
    let mut text = format!("time_s,{header}\n");
    for k in 0..5000usize {
        let t = k as f64 / 1e4;
        let tt = t - 0.2;
        let pulse = if (0.0..0.005).contains(&tt) {
            peak * (std::f64::consts::PI * tt / 0.005).sin()
        } else {
            0.0
        };
        text.push_str(&format!("{t:.4},{:.4}\n", rail(k, rest + pulse)));
    }
    text
}

fn first_impact(file: &std::path::Path, more: &[&str]) -> serde_json::Value {
    let mut args = vec!["analyze", file.to_str().unwrap(), "--json"];
    args.extend_from_slice(more);
    let (out, err) = impact_ok(&args);
    let j: serde_json::Value = serde_json::from_str(&out).unwrap_or_else(|e| panic!("{e}{err}"));
    j["impacts"][0].clone()
}

#[test]
fn a_rail_with_noise_is_clipped_and_a_rest_level_is_not() {
    let scratch = Scratch::new();
    // Resting at exactly 1 g, a clean 20 g pulse: its rest level is the minimum and flat.
    let rest = scratch.file("rest.csv", recording("accel_g", 1.0, 20.0, |_, v| v));
    let i = first_impact(&rest, &[]);
    assert_eq!(i["clipped"], false, "{i}");
    // A phone's ±16 g: readings past 156.858 m/s² rail there, with noise up to 1 % below.
    let phone = |k: usize, v: f64| {
        if v > 156.858 {
            156.858 - 1.5 * ((k * 7919 % 100) as f64 / 100.0)
        } else {
            v
        }
    };
    let railed = scratch.file("phone.csv", recording("accel_m_s2", 9.81, 300.0, phone));
    let i = first_impact(&railed, &["--range", "16g"]);
    assert_eq!(i["clipped"], true, "{i}");
    assert!(i["flags"].to_string().contains("clipped"), "{i}");
    // A clean flat top (an ADC's code held): found from its shape alone.
    let flat = scratch.file(
        "flat.csv",
        recording("accel_g", 0.0, 30.0, |_, v| v.min(20.0)),
    );
    let i = first_impact(&flat, &[]);
    assert_eq!(i["clipped"], true, "{i}");
}
