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
