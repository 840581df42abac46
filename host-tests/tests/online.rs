//! The kinematics the stream integrates online (`core/src/stream/online.rs`) against the pass
//! over a capture that holds the whole contact: the board's capture (15 104 samples) and a
//! host-sized one give the same bits for every impact, however long its contact (#41).

use impact_core::signal::Calibration;
use impact_core::{Approach, ImpactReport, Monitor, Scene};

/// A pulse of `len` samples: a half-sine of `peak` counts, its rise softened (a foot) by
/// `foot` (0: none), on a baseline of 2000 counts; 0.2 s of quiet before and after it.
fn pulse(len: usize, peak: f64, foot: f64, rate: f64) -> Vec<i16> {
    let quiet = (0.2 * rate) as usize;
    let mut x = vec![2000i16; quiet];
    for j in 0..len {
        let t = j as f64 / len as f64;
        let s = (std::f64::consts::PI * t).sin();
        let shape = if foot > 0.0 {
            s.powf(1.0 + foot * (1.0 - t))
        } else {
            s
        };
        // A little deterministic noise (a few counts), as a real channel has.
        let noise = ((j * 7919) % 5) as f64 - 2.0;
        x.push((2000.0 + peak * shape + noise * 0.6).round() as i16);
    }
    x.extend(std::iter::repeat_n(2000i16, quiet));
    x
}

fn scene(rate: f64, v0: f32, vertical: bool) -> Scene {
    let mut s = Scene::new(
        Calibration {
            gain_m_s2_per_count: 0.05,
            sample_rate_hz: rate as f32,
        },
        2.0,
    );
    s.edge_m_s2 = 0.5;
    s.hold_s = 2e-3;
    s.mass_kg = Some(0.06);
    s.approach = Approach::Speed { v0_m_s: v0 };
    s.vertical = vertical;
    s
}

/// The reports of `samples` through a monitor whose capture holds `CAP` samples.
fn run<const CAP: usize>(samples: &[i16], scene: Scene) -> Vec<ImpactReport> {
    let samples = samples.to_vec();
    std::thread::Builder::new()
        .stack_size(256 << 20)
        .spawn(move || {
            let mut m: Box<Monitor<4096, CAP>> = Box::new(Monitor::unconfigured());
            m.configure(scene).unwrap();
            let mut out = Vec::new();
            for block in samples.chunks(256) {
                m.push_block(block, &mut |r| out.push(*r));
            }
            m.finish(&mut |r| out.push(*r));
            out
        })
        .unwrap()
        .join()
        .unwrap()
}

#[test]
fn every_contact_has_the_same_kinematics_with_the_boards_capture_and_a_whole_one() {
    let rate = 500_000.0;
    let mut checked = 0;
    for (len, peak, foot, vertical) in [
        (2_000usize, 3000.0, 0.0, false),
        (12_000, 800.0, 0.0, false),
        (25_000, 400.0, 0.0, false),
        (25_000, 1200.0, 1.5, true),
        (40_000, 900.0, 0.8, true),
    ] {
        let x = pulse(len, peak, foot, rate);
        // The pulse's Δv, m/s (less g T in a vertical contact); an approach of 60 % of it.
        let t = len as f64 / rate;
        let area = x.iter().map(|&c| (c - 2000) as f64).sum::<f64>() * 0.05 / rate;
        let dv = area - if vertical { 9.80665 * t } else { 0.0 };
        let sc = scene(rate, (0.6 * dv) as f32, vertical);
        let board = run::<15_104>(&x, sc);
        let whole = run::<65_536>(&x, sc);
        assert_eq!(board.len(), 1, "{len}");
        assert_eq!(whole.len(), 1, "{len}");
        let (b, w) = (&board[0], &whole[0]);
        let k = w
            .kinematics
            .unwrap_or_else(|| panic!("{len}: host: {:?}", w.flags));
        assert_eq!(
            b.kinematics.map(|k| (
                k.crush_time_s.to_bits(),
                k.max_deformation_m.to_bits(),
                k.cor.to_bits(),
                k.separation_deformation_m.to_bits()
            )),
            Some((
                k.crush_time_s.to_bits(),
                k.max_deformation_m.to_bits(),
                k.cor.to_bits(),
                k.separation_deformation_m.to_bits()
            )),
            "{len} {foot}: board {:?} {:?}, whole {:?}",
            b.status,
            b.flags,
            k
        );
        checked += 1;
    }
    assert_eq!(checked, 5);
}
