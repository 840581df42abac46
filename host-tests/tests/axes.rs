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

/// A 50 g, 6 ms half-sine along z (on 1 g of gravity) with `cross` of it along x and noise
/// on y, at 50 kS/s: the CSV's path.
fn shock_with_cross_axis(scratch: &Scratch, name: &str, cross: f64) -> String {
    shock(scratch, name, 50.0, cross, f64::INFINITY)
}

/// As [`shock_with_cross_axis`], the pulse `peak` g, the x axis clipped flat at `rail` g.
fn shock(scratch: &Scratch, name: &str, peak: f64, cross: f64, rail: f64) -> String {
    let rate = 50_000.0;
    let d = 0.006;
    let mut csv = String::from("time_s,x_g,y_g,z_g\n");
    for k in 0..10_000u32 {
        let t = f64::from(k) / rate - 0.05;
        let pulse = if (0.0..d).contains(&t) {
            peak * (std::f64::consts::PI * t / d).sin()
        } else {
            0.0
        };
        let noise = |s: u32| {
            0.02 * (((k.wrapping_add(s).wrapping_mul(2_654_435_761) >> 16) % 1000) as f64 / 500.0
                - 1.0)
        };
        csv.push_str(&format!(
            "{:.6},{:.5},{:.5},{:.5}\n",
            t + 0.05,
            (cross * pulse + noise(1)).min(rail),
            noise(2),
            1.0 + pulse + noise(3)
        ));
    }
    scratch.text(&format!("{name}.csv"), &csv)
}

/// The transverse-motion check (IEC 60068-2-27's 30 % of the nominal peak): a cross axis at
/// 20 % passes, at 40 % fails the pulse (exit status 3) though the resultant meets the band;
/// the limit and the main axis can be given; a main axis not among the axes is refused.
#[test]
fn a_cross_axis_beyond_the_transverse_limit_fails_the_pulse() {
    let scratch = Scratch::new();
    let run = |file: &str, more: &[&str]| {
        let mut a = vec![
            "analyze",
            file,
            "--axes",
            "x_g,y_g,z_g",
            "--spec",
            "half-sine,50g,6ms",
        ];
        a.extend_from_slice(more);
        common::impact(&a)
    };
    let json = |file: &str, more: &[&str]| -> (i32, Value) {
        let mut m = more.to_vec();
        m.push("--json");
        let (code, out, err) = run(file, &m);
        let j: Value = serde_json::from_str(&out).unwrap_or_else(|e| panic!("{e}: {err}"));
        (code, j["impacts"][0]["spec"].clone())
    };
    let low = shock_with_cross_axis(&scratch, "low", 0.2);
    let (code, v) = json(&low, &[]);
    assert_eq!(code, 0, "{v}");
    let t = &v["transverse"];
    assert_eq!(t["main_axis"], "z_g");
    assert_eq!(t["main_axis_from"], "largest-peak");
    assert_eq!(t["limit_fraction"], 0.3);
    assert_eq!(t["pass"], true);
    let x = t["cross_axes"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["column"] == "x_g")
        .unwrap();
    let share = x["fraction_of_nominal_peak"].as_f64().unwrap();
    assert!((share - 0.2).abs() < 0.005, "{share}");

    let high = shock_with_cross_axis(&scratch, "high", 0.4);
    let (code, v) = json(&high, &[]);
    assert_eq!(code, 3, "{v}");
    assert_eq!(v["pass"], false);
    assert_eq!(v["band_pass"], true, "the resultant meets the band: {v}");
    assert_eq!(v["transverse"]["pass"], false);
    let (_, table, _) = run(&high, &[]);
    assert!(table.contains("x_g 40.0 % EXCEEDED"), "{table}");
    assert!(table.contains("spec: FAIL"), "{table}");
    // A looser limit passes it; naming x the main axis makes z the cross axis, beyond.
    assert_eq!(json(&high, &["--transverse-limit", "0.5"]).0, 0);
    let (code, v) = json(&low, &["--main-axis", "x_g"]);
    assert_eq!(code, 3);
    assert_eq!(v["transverse"]["main_axis"], "x_g");
    assert_eq!(v["transverse"]["main_axis_from"], "main-axis");
    // The main axis by its header where --axes gives indices.
    let (code, out, err) = common::impact(&[
        "analyze",
        &low,
        "--axes",
        "1,2,3",
        "--spec",
        "half-sine,50g,6ms",
        "--main-axis",
        "z_g",
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    let j: Value = serde_json::from_str(&out).unwrap();
    assert_eq!(j["impacts"][0]["spec"]["transverse"]["main_axis"], "z_g");
    assert_eq!(
        j["impacts"][0]["spec"]["transverse"]["main_axis_from"],
        "main-axis"
    );
    let (code, _, err) = run(&low, &["--main-axis", "w_g"]);
    assert_ne!(code, 0);
    assert!(err.contains("--main-axis w_g: not one of --axes"), "{err}");
    // A cross axis clipped within the limit (flat at 8 g, 16 % of 50 g): a pulse that met
    // its band is not judged (its cross axis may lie beyond); one that failed it still fails.
    let clipped = shock(&scratch, "clipped", 50.0, 0.3, 8.0);
    let (code, v) = json(&clipped, &[]);
    assert_eq!((code, v.clone()), (0, Value::Null));
    let (_, out, _) = run(&clipped, &["--json"]);
    let j: Value = serde_json::from_str(&out).unwrap();
    assert_eq!(
        j["impacts"][0]["null_reasons"]["spec"],
        "transverse-clipped"
    );
    let failing = shock(&scratch, "failing", 65.0, 0.3, 8.0);
    let (code, v) = json(&failing, &[]);
    assert_eq!(code, 3, "{v}");
    assert_eq!(v["band_pass"], false);
    assert!(v.get("transverse").is_none(), "{v}");
    // The limit needs a pulse to be a fraction of.
    let (code, _, err) = common::impact(&[
        "analyze",
        &low,
        "--axes",
        "x_g,y_g,z_g",
        "--transverse-limit",
        "0.3",
    ]);
    assert_eq!(code, 2, "{err}");
}

/// Each axis zeroed before the magnitude (SAE J211, ISO 6487): a 12.6 g, 10 ms half-sine
/// along x, along −z, along +z and at 45° in the xz plane, with gravity's 1 g on z (a sled, a
/// drop table) or on y, and noise on every axis, peaks at 12.6 g and gives its Δv's
/// magnitude within 1 % (the magnitudes' difference, `|f| − |f₀|`, gave x 7.6 % low and −z
/// 16 % low).
#[test]
fn each_axis_is_zeroed_before_the_magnitude_whatever_the_gravity() {
    let scratch = Scratch::new();
    let (rate, d, peak_g) = (20_000.0, 0.010, 12.6);
    let s45 = std::f64::consts::FRAC_1_SQRT_2;
    for (dir, gravity, what) in [
        ([1.0, 0.0, 0.0], [0.0, 0.0, 1.0], "x, gravity on z"),
        ([0.0, 0.0, -1.0], [0.0, 0.0, 1.0], "-z, gravity on z"),
        ([0.0, 0.0, 1.0], [0.0, 0.0, 1.0], "+z, gravity on z"),
        ([s45, 0.0, s45], [0.0, 0.0, 1.0], "45° in xz, gravity on z"),
        ([1.0, 0.0, 0.0], [0.0, -1.0, 0.0], "x, gravity on -y"),
    ] {
        let mut csv = String::from("time_s,x_g,y_g,z_g\n");
        for k in 0..8_000u32 {
            let t = f64::from(k) / rate - 0.2;
            let p = if (0.0..d).contains(&t) {
                peak_g * (std::f64::consts::PI * t / d).sin()
            } else {
                0.0
            };
            let noise = |axis: u32| {
                let h = (k.wrapping_add(axis * 7919)).wrapping_mul(2_654_435_761) >> 16;
                0.005 * ((h % 1000) as f64 / 500.0 - 1.0)
            };
            let v: Vec<String> = (0..3)
                .map(|i| format!("{:.6}", gravity[i] + dir[i] * p + noise(i as u32)))
                .collect();
            csv.push_str(&format!("{:.6},{}\n", f64::from(k) / rate, v.join(",")));
        }
        let f = scratch.file(&format!("{what}.csv"), &csv);
        let (out, _) = impact_ok(&[
            "analyze",
            f.to_str().unwrap(),
            "--axes",
            "x_g,y_g,z_g",
            "--json",
        ]);
        let j: Value = serde_json::from_str(&out).unwrap();
        let impacts = j["impacts"].as_array().unwrap();
        assert_eq!(impacts.len(), 1, "{what}: {out}");
        let i = &impacts[0];
        let g = impact_core::consts::STANDARD_GRAVITY;
        let peak = i["peak_acceleration_m_s2"].as_f64().unwrap() / g;
        assert!(
            (peak / peak_g - 1.0).abs() <= 0.01,
            "{what}: peak {peak} g, true {peak_g} g"
        );
        let dv = i["axes"]["delta_v_magnitude_m_s"].as_f64().unwrap();
        let want = 2.0 / std::f64::consts::PI * peak_g * g * d;
        assert!(
            (dv / want - 1.0).abs() <= 0.01,
            "{what}: |Δv| {dv}, true {want}"
        );
    }
}
