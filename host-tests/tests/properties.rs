//! Property tests of the core: physics invariants of the solvers, and the pipeline's
//! indifference to how a stream is cut and to what the stream contains.

use impact_core::model::{Hertz, KelvinVoigt, Linear, Model, Nonlinear, TwoPhase};
use impact_core::{
    solve, Calibration, ContactLaw, FitSet, Impact, ImpactReport, Method, Monitor, Scene, Settings,
};
use proptest::prelude::*;

fn log_uniform(lo: f64, hi: f64) -> impl Strategy<Value = f64> {
    (lo.ln()..hi.ln()).prop_map(f64::exp)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Elastic laws give back all the energy, whatever the solver.
    #[test]
    fn elastic_laws_conserve_energy(k in log_uniform(1e2, 1e12), m in log_uniform(1e-3, 1e2), v0 in log_uniform(1e-3, 1e2), n in 1.0f64..2.0) {
        let law = Nonlinear { k, c: 0.0, n };
        let impact = Impact::new(m, v0);
        for settings in [Settings::exact(), Settings::adaptive(1e-10), Settings::fixed(Method::Rk4, 400)] {
            let o = solve(&law, &impact, &settings).unwrap();
            prop_assert!((o.cor - 1.0).abs() < 1e-6, "{settings:?}: COR {}", o.cor);
            // All kinetic energy is stored at x_m: k x_m^(n+1) / (n+1) = m v0^2 / 2.
            let stored = k * o.max_deformation_m.powf(n + 1.0) / (n + 1.0);
            prop_assert!((stored / (0.5 * m * v0 * v0) - 1.0).abs() < 1e-6, "{settings:?}: {stored}");
        }
    }

    /// Damped laws: 0 <= COR <= 1, finite fields, separation after the maximum.
    #[test]
    fn cor_is_a_fraction_and_the_report_is_ordered(k in log_uniform(1e1, 1e8), m in log_uniform(1e-3, 1e1), v0 in log_uniform(1e-2, 1e1), zeta in 0.0f64..3.0, p in 0.0f64..5.0) {
        let impact = Impact::new(m, v0);
        let c_kv = 2.0 * zeta * (k * m).sqrt();
        let laws = [
            Model::KelvinVoigt(KelvinVoigt { k, c: c_kv }),
            Model::TwoPhase(TwoPhase { kc: k, kr: 4.0 * k, c: c_kv, permanent_m: None }),
            Model::Nonlinear(Nonlinear { k, c: p / v0, n: 1.0 }),
        ];
        for law in laws {
            for s in [Settings::exact(), Settings::adaptive(1e-8)] {
                let o = solve(&law, &impact, &s).unwrap();
                prop_assert!((0.0..=1.0 + 1e-9).contains(&o.cor), "COR {}", o.cor);
                prop_assert!(o.crush_time_s > 0.0 && o.contact_time_s >= o.crush_time_s);
                prop_assert!(o.peak_force_n > 0.0 && o.max_deformation_m > 0.0);
                prop_assert!(o.permanent_deformation_m >= 0.0 && o.permanent_deformation_m <= o.max_deformation_m * (1.0 + 1e-9));
            }
        }
    }

    /// More damping, lower COR.
    #[test]
    fn more_damping_lowers_the_cor(k in log_uniform(1e1, 1e6), m in log_uniform(1e-2, 1.0), v0 in log_uniform(1e-2, 1e1), c1 in 0.0f64..1.0, extra in 0.01f64..1.0) {
        let impact = Impact::new(m, v0);
        let cor = |c: f64| Nonlinear { k, c: c / v0, n: 1.5 }.exact(&impact).unwrap().cor;
        prop_assert!(cor(c1 + extra) < cor(c1));
        let ckv = |z: f64| 2.0 * z * (k * m).sqrt();
        let cor_kv = |z: f64| KelvinVoigt { k, c: ckv(z) }.exact(&impact).unwrap().cor;
        prop_assert!(cor_kv(c1 + extra) < cor_kv(c1));
    }

    /// The linear stand-in matched on x_m always has the same x_m and a longer contact.
    #[test]
    fn linear_stand_in_matches_x_m(k in log_uniform(1e6, 1e12), m in log_uniform(1e-4, 1.0), v0 in log_uniform(1e-2, 1e1)) {
        let impact = Impact::new(m, v0);
        let h = Hertz { k };
        let l = Linear::matching_max_deformation(&h, &impact).unwrap();
        let (ho, lo) = (h.exact(&impact).unwrap(), l.exact(&impact).unwrap());
        prop_assert!((lo.max_deformation_m / ho.max_deformation_m - 1.0).abs() < 1e-12);
        prop_assert!((lo.contact_time_s / ho.contact_time_s - 1.0 - 0.0674).abs() < 1e-3);
    }
}

fn scene() -> Scene {
    let mut s = Scene::new(
        Calibration {
            gain_m_s2_per_count: 0.5,
            sample_rate_hz: 100_000.0,
        },
        20.0,
    );
    s.edge_m_s2 = 4.0;
    s.hold_s = 1e-3;
    s.mass_kg = Some(0.1);
    s.approach = impact_core::Approach::Speed { v0_m_s: 1.0 };
    s.fits = FitSet::all();
    s
}

fn feed(samples: &[i16], cuts: &[usize], scene: Scene) -> Vec<ImpactReport> {
    let mut m = Box::new(Monitor::<256, 4096>::new(scene).unwrap());
    let mut out = Vec::new();
    let mut rest = samples;
    let mut i = 0;
    while !rest.is_empty() {
        let n = cuts
            .get(i)
            .copied()
            .unwrap_or(usize::MAX)
            .clamp(1, rest.len());
        let (a, b) = rest.split_at(n);
        m.push_block(a, &mut |r: &ImpactReport| out.push(*r));
        rest = b;
        i += 1;
    }
    m.finish(&mut |r: &ImpactReport| out.push(*r));
    out
}

/// Noise with a few pulses of random height, width and position.
fn stream() -> impl Strategy<Value = Vec<i16>> {
    (
        prop::collection::vec((100usize..3000, 5usize..400, -400i32..400), 1..5),
        any::<u64>(),
    )
        .prop_map(|(pulses, seed)| {
            let mut s = seed | 1;
            let mut out = Vec::new();
            for (gap, width, height) in pulses {
                for _ in 0..gap {
                    s ^= s << 13;
                    s ^= s >> 7;
                    s ^= s << 17;
                    out.push(1000 + (s % 3) as i16 - 1);
                }
                for k in 0..width {
                    let shape = (std::f64::consts::PI * k as f64 / width as f64).sin();
                    out.push(1000 + (height as f64 * shape) as i16);
                }
            }
            out.extend(std::iter::repeat_n(1000, 500));
            out
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// Any split of the same stream into blocks gives the same reports.
    #[test]
    fn block_split_never_changes_the_reports(samples in stream(), cuts in prop::collection::vec(1usize..700, 0..200)) {
        let whole = feed(&samples, &[usize::MAX], scene());
        let split = feed(&samples, &cuts, scene());
        prop_assert_eq!(whole, split);
    }

    /// Arbitrary samples and scene levels: never a panic, every report finite or absent.
    #[test]
    fn arbitrary_streams_never_panic(samples in prop::collection::vec(any::<i16>(), 0..6000), trigger in log_uniform(1e-3, 1e6), gain in log_uniform(1e-6, 1e3), block in 1usize..600) {
        let mut s = scene();
        s.calibration.gain_m_s2_per_count = gain as f32;
        s.trigger_m_s2 = trigger as f32;
        s.edge_m_s2 = (trigger / 4.0) as f32;
        let mut m = Box::new(Monitor::<256, 4096>::new(s).unwrap());
        let mut out = Vec::new();
        for b in samples.chunks(block) {
            m.push_block(b, &mut |r: &ImpactReport| out.push(*r));
        }
        m.finish(&mut |r: &ImpactReport| out.push(*r));
        prop_assert_eq!(m.counters().samples, samples.len() as u64);
        prop_assert_eq!(m.counters().impacts, out.len() as u64);
        for r in &out {
            prop_assert!(r.start_s.is_finite() && r.delta_v_m_s.is_none_or(f32::is_finite) && r.peak_acceleration_m_s2.is_finite());
        }
    }
}

/// A row of a user's band with any f32 bits at all, or one in a plausible range.
fn band_row() -> impl Strategy<Value = impact_core::spec::BandPoint> {
    let value = prop_oneof![
        4 => -3.0f32..3.0,
        1 => any::<f32>(),
        1 => Just(f32::NAN),
    ];
    (value.clone(), value.clone(), value)
        .prop_map(|(u, lower, upper)| impact_core::spec::BandPoint { u, lower, upper })
}

/// A half-sine spec of `peak` m/s² over 11 ms with IEC's tolerances and the user's `rows`.
fn band_spec(peak: f64, rows: Vec<impact_core::spec::BandPoint>) -> impact_core::spec::Spec {
    use impact_core::spec::{Shape, Spec};
    Spec {
        shape: Shape::HalfSine,
        peak_m_s2: peak as f32,
        duration_s: 0.011,
        tolerance: impact_host::standards::STANDARDS[0].tolerance,
        band: Some(Box::leak(rows.into_boxed_slice())),
    }
}

/// The half-sine of `spec` itself at 50 kS/s, starting at sample 15 000 (held to 40 000).
fn nominal_pulse(spec: &impact_core::spec::Spec) -> impl Fn(u64) -> Option<f32> + '_ {
    move |i| (i < 40_000).then(|| spec.peak_m_s2 * spec.shape.at((i as f32 - 15_000.0) / 550.0))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// A user's band of any rows (any bits, sorted or not) never panics: refused, or every
    /// look-up finite and ordered, and the verdict of a pulse against it finite.
    #[test]
    fn any_users_band_is_refused_or_finite(mut rows in prop::collection::vec(band_row(), 0..70), sort in any::<bool>(), peak in log_uniform(1.0, 1e4), us in prop::collection::vec(-20.0f32..20.0, 8)) {
        use impact_core::spec::verdict;
        if sort {
            rows.sort_by(|a, b| a.u.total_cmp(&b.u));
        }
        let spec = band_spec(peak, rows);
        if spec.validate().is_err() {
            return Ok(());
        }
        for &u in &us {
            let (lo, hi) = spec.band_at(u);
            prop_assert!(lo.is_finite() && hi.is_finite() && lo <= hi, "{u}: {lo} {hi}");
        }
        match verdict::judge(nominal_pulse(&spec), 50_000.0, &spec, 15_275) {
            Ok(v) => prop_assert!(v.margin.is_finite() && v.delta_v_m_s.is_finite(), "{v:?}"),
            Err(e) => prop_assert!(
                matches!(
                    e,
                    verdict::Missing::Window
                        | verdict::Missing::WindowBefore
                        | verdict::Missing::WindowAfter
                ),
                "{e:?}"
            ),
        }
    }

    /// Any band around the nominal pulse (rows every 0.1 D from −0.4 D to 1.5 D, each limit
    /// 0.2 to 3 peaks from the nominal: its chords within 0.012 of the sine) is valid, and the
    /// nominal pulse itself passes it.
    #[test]
    fn the_nominal_pulse_passes_any_band_around_it(widths in prop::collection::vec((0.2f32..3.0, 0.2f32..3.0), 20), peak in log_uniform(1.0, 1e4)) {
        use impact_core::spec::{verdict, BandPoint, Shape};
        let rows: Vec<BandPoint> = widths
            .iter()
            .enumerate()
            .map(|(k, &(below, above))| {
                let u = -0.4 + 0.1 * k as f32;
                let at = Shape::HalfSine.at(u);
                BandPoint { u, lower: at - below, upper: at + above }
            })
            .collect();
        let spec = band_spec(peak, rows);
        prop_assert!(spec.validate().is_ok(), "{:?}", spec.validate());
        let v = verdict::judge(nominal_pulse(&spec), 50_000.0, &spec, 15_275).unwrap();
        prop_assert!(v.band_pass, "{v:?}");
        let narrowest = widths.iter().map(|&(a, b)| a.min(b)).fold(f32::INFINITY, f32::min);
        // The first placement that passes is kept (up to a coarse bucket, 0.03 D, from the
        // best): the margin is the narrowest width less the sine's slope over that (π × 0.03)
        // and the chords'.
        prop_assert!(v.margin <= -(narrowest.min(0.2) - 0.11), "{v:?}: narrowest {narrowest}");
    }
}
