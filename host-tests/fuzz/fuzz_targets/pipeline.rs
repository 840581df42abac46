//! Arbitrary bytes through the streaming pipeline: the first bytes make a [`Scene`] (levels,
//! gain, rate, hold, longest impact, settle time, rails, filters, mass, v0, fits, bounce trains,
//! spectra, waveform frames), the rest are i16 samples
//! pushed in blocks of arbitrary sizes. Checks: no panic; the counters match the samples
//! pushed and the reports delivered; report indices count up; with a sane scene (gain and rate
//! in realistic ranges) every reported quantity is finite; and feeding the same stream one
//! sample at a time gives the same reports (block-split invariance).

#![no_main]

use impact_core::signal::cfc::Cfc;
use impact_core::signal::spectrum::SpectrumSettings;
use impact_core::Counters;
use impact_core::{
    Approach, Calibration, FitSet, ImpactReport, Monitor, Scene, Status, Train, TrainSpeed,
};
use libfuzzer_sys::fuzz_target;

/// Small buffers, so that captures fill up and rings wrap with short inputs.
type Fm = Monitor<256, 1024>;

struct Bytes<'a>(&'a [u8]);

impl Bytes<'_> {
    fn u8(&mut self) -> u8 {
        match self.0.split_first() {
            Some((&b, rest)) => {
                self.0 = rest;
                b
            }
            None => 0,
        }
    }
    fn u16(&mut self) -> u16 {
        u16::from_le_bytes([self.u8(), self.u8()])
    }
    fn f32_bits(&mut self) -> f32 {
        f32::from_bits(u32::from_le_bytes([
            self.u8(),
            self.u8(),
            self.u8(),
            self.u8(),
        ]))
    }
    /// `10^(lo + (hi - lo) * b / 255)`.
    fn log_range(&mut self, lo: f32, hi: f32) -> f32 {
        10f32.powf(lo + (hi - lo) * self.u8() as f32 / 255.0)
    }
}

fn cfc(b: u8) -> Option<Cfc> {
    match b % 6 {
        0 => Some(Cfc::Cfc60),
        1 => Some(Cfc::Cfc180),
        2 => Some(Cfc::Cfc600),
        3 => Some(Cfc::Cfc1000),
        _ => None,
    }
}

/// The scene, and whether it is sane (values in realistic ranges, so reports must be finite).
fn scene(b: &mut Bytes) -> (Scene, bool) {
    let flags = b.u8();
    let raw = flags & 0x80 != 0;
    let (gain, rate) = if raw {
        (b.f32_bits(), b.f32_bits())
    } else {
        let sign = if flags & 1 != 0 { -1.0 } else { 1.0 };
        (sign * b.log_range(-4.0, 3.0), b.log_range(1.0, 7.0))
    };
    // Levels in counts, turned into m/s² with the gain.
    let trigger_counts = 1.0 + b.u16() as f32 / 16.0;
    let edge_frac = b.u8() as f32 / 256.0;
    let hold_samples = 1 + b.u8() as u32 * 2;
    let max_samples = hold_samples + b.u16() as u32;
    let clip = (b.u16() as i16, b.u16() as i16);
    let settle_samples = hold_samples + b.u16() as u32;
    let cfc_byte = b.u8();
    let fit_byte = b.u8();
    let stage_byte = b.u8();
    let v0 = b.log_range(-2.0, 2.0);
    let g = gain.abs();
    let scene = Scene {
        calibration: Calibration {
            gain_m_s2_per_count: gain,
            sample_rate_hz: rate,
        },
        mass_kg: (fit_byte & 0x80 != 0).then_some(0.06),
        approach: match (fit_byte >> 5) & 3 {
            0 => Approach::Unknown,
            1 => Approach::Speed { v0_m_s: v0 },
            _ => Approach::DropHeight { height_m: v0 },
        },
        trigger_m_s2: trigger_counts * g,
        edge_m_s2: trigger_counts * edge_frac * g,
        hold_s: hold_samples as f32 / rate,
        max_impact_s: max_samples as f32 / rate,
        settle_s: settle_samples as f32 / rate,
        clip_counts: clip,
        cfc: cfc(cfc_byte),
        // Where no CFC is drawn, now and then a Butterworth low-pass of any order, its cut-off
        // from half the rate down to a 1700th of it.
        lowpass: (cfc_byte % 6 == 4).then_some(impact_core::signal::lowpass::Lowpass {
            order: 1 + (cfc_byte >> 3) % 8,
            cutoff_hz: rate / (2.0 + f32::from(cfc_byte / 6) * 40.0),
        }),
        trigger_cfc: cfc(cfc_byte / 6),
        fits: FitSet {
            two_phase: fit_byte & 1 != 0,
            nonlinear: fit_byte & 2 != 0,
            fit_exponent: fit_byte & 4 != 0,
            nonlinear_exponent: 1.0 + (fit_byte & 8) as f32 / 16.0,
            hertz: fit_byte & 16 != 0,
        },
        // Gravity in the contact (a drop, a train or this flag), at standard gravity.
        gravity_m_s2: impact_core::consts::STANDARD_GRAVITY as f32,
        vertical: stage_byte & 8 != 0,
        // Every impact at v0, or only one that follows no flight.
        v0_every: stage_byte & 0x10 != 0,
        // Bounce trains on either speed source, with short flights so that they chain.
        train: (stage_byte & 3 != 0).then(|| Train {
            speed: if stage_byte & 1 != 0 {
                TrainSpeed::Flight
            } else {
                TrainSpeed::Rebound
            },
            max_flight_s: max_samples as f32 * 4.0 / rate,
        }),
        // Spectra at 1/6 or 1/12 octave, to the rate / 8 or to a tenth of the rate's bands
        // (a highest band, at times below every band of a decimated capture's rate).
        spectrum: (stage_byte & 4 != 0).then(|| SpectrumSettings {
            bands_per_octave: if stage_byte & 8 != 0 { 12 } else { 6 },
            high_hz: (stage_byte & 0x10 != 0).then_some(rate / 80.0),
            ..SpectrumSettings::new()
        }),
        // A specified half-sine of the trigger's tenfold over a hold's time (a verdict per
        // impact, judged or not).
        spec: (stage_byte & 0x40 != 0).then(|| impact_core::spec::Spec {
            shape: impact_core::spec::Shape::HalfSine,
            peak_m_s2: 10.0 * trigger_counts * g,
            duration_s: hold_samples as f32 / rate,
            tolerance: impact_core::spec::Tolerance {
                band: 0.2,
                outside: 0.2,
                slack: 0.1,
                delta_v: 0.15,
                before: 0.4,
                after: 0.1,
                watch: 1.1,
            },
            band: (cfc_byte & 0x80 != 0).then_some(&BAND[..]),
        }),
        waveform_every: u16::from(stage_byte >> 4),
        // Now and then (no train: the scene refuses one) a target from a free body of
        // 1 mg to a 10 kg mount on a spring up to 2.6e6 N/m, from the bytes drawn above;
        // half of those as a state space (the same matrices, the general step; chosen by
        // the waveform's top bit, which nothing about the target draws on).
        target: (stage_byte & 0x23 == 0x20).then(|| {
            use impact_core::two_body::{SceneTarget, SpringMass, Target};
            let s = SpringMass {
                mass_kg: 1e-7 * 10f32.powi(i32::from(fit_byte >> 5) + 1),
                stiffness_n_m: f32::from(cfc_byte) * 1e4,
                damping_n_s_m: f32::from(fit_byte & 0x1f),
            };
            if stage_byte & 0x80 != 0 {
                // (Kept once per distinct target: at most 8 × 256 × 16 of them.)
                let mut t = Target::of_spring_mass(s);
                t.spring_mass = None;
                SceneTarget::StateSpace(impact_host::simulate::two_body::interned(t))
            } else {
                SceneTarget::SpringMass(s)
            }
        }),
    };
    (scene, !raw)
}

/// A user's band for the specified half-sine (`spec.band`), judged in place of IEC's.
static BAND: [impact_core::spec::BandPoint; 5] = {
    use impact_core::spec::BandPoint;
    [
        BandPoint {
            u: -0.4,
            lower: -0.2,
            upper: 0.2,
        },
        BandPoint {
            u: 0.0,
            lower: -0.2,
            upper: 0.3,
        },
        BandPoint {
            u: 0.5,
            lower: 0.7,
            upper: 1.2,
        },
        BandPoint {
            u: 1.0,
            lower: -0.2,
            upper: 0.3,
        },
        BandPoint {
            u: 1.1,
            lower: -0.2,
            upper: 0.2,
        },
    ]
};

fn finite(r: &ImpactReport) -> bool {
    let mut ok = r.start_s.is_finite()
        && r.peak_time_s.is_finite()
        && r.peak_acceleration_m_s2.is_finite()
        && r.delta_v_m_s.is_none_or(f32::is_finite)
        && r.duration_s.is_finite()
        && r.fwhm_s.is_none_or(f32::is_finite)
        && r.filtered_peak_acceleration_m_s2.is_none_or(f32::is_finite)
        && r.baseline_m_s2.is_finite()
        && r.peak_force_n.is_none_or(f32::is_finite);
    if let Some(k) = &r.kinematics {
        ok &= k.impact_velocity_m_s.is_finite()
            && k.crush_time_s.is_none_or(f32::is_finite)
            && k.max_deformation_m.is_none_or(f32::is_finite)
            && k.rebound_velocity_m_s.is_finite()
            && k.cor.is_finite()
            && k.separation_deformation_m.is_none_or(f32::is_finite)
            && k.permanent_deformation_m.is_none_or(f32::is_finite)
            && k.absorbed_energy_j.is_none_or(f32::is_finite);
    }
    if let Some(b) = &r.bounce {
        ok &= b.flight_s.is_finite()
            && b.v0_flight_m_s.is_finite()
            && b.v0_rebound_m_s.is_none_or(f32::is_finite)
            && b.landing_height_m.is_finite()
            && b.landing_height_m >= 0.0;
    }
    if let Some(s) = &r.spectrum {
        ok &= s.srs_m_s2.iter().chain(&s.pvss_m_s).all(|v| v.is_finite());
    }
    if let Some(Ok(v)) = &r.verdict {
        ok &= [v.margin, v.worst_m_s2, v.limit_m_s2, v.delta_v_m_s]
            .iter()
            .all(|x| x.is_finite())
            && v.start_s.is_finite()
            && v.worst_s.is_finite();
    }
    ok
}

/// Runs the stream in the given blocks; returns the reports (as Debug text, so that NaN
/// compares equal to NaN) and the final counters.
fn run(
    m: &mut Fm,
    samples: &[i16],
    mut next_len: impl FnMut() -> usize,
    sane: bool,
) -> (Vec<String>, Counters) {
    let mut reports = Vec::new();
    let mut incomplete = 0u64;
    let mut check = |r: &ImpactReport, reports: &mut Vec<String>| {
        assert_eq!(r.index as usize, reports.len(), "report index");
        if r.status != Status::Complete {
            incomplete += 1;
        }
        if sane {
            assert!(finite(r), "non-finite report: {r:?}");
        }
        reports.push(format!("{r:?}"));
    };
    let mut rest = samples;
    let mut pushed = 0u64;
    while !rest.is_empty() {
        let n = next_len().min(rest.len());
        let (block, tail) = rest.split_at(n);
        m.push_block(block, &mut |r| check(r, &mut reports));
        pushed += n as u64;
        rest = tail;
        let c = m.counters();
        assert_eq!(c.samples, pushed, "samples counted");
        assert_eq!(c.impacts, reports.len() as u64, "impacts counted");
    }
    m.finish(&mut |r| check(r, &mut reports));
    let c = m.counters();
    assert!(!m.in_impact(), "finish ends the impact");
    assert_eq!(c.samples, pushed, "samples counted");
    assert_eq!(c.impacts, reports.len() as u64, "impacts counted");
    assert_eq!(c.incomplete, incomplete, "incomplete counted");
    (reports, c)
}

fuzz_target!(|data: &[u8]| {
    let mut b = Bytes(data);
    let (scene, sane) = scene(&mut b);
    let mut seed = b.u8() as u32 | 1;
    // Each input sample is repeated `repeat` times (longer streams from short inputs).
    let repeat = 1 + (b.u8() % 8) as usize;
    let samples: Vec<i16> =
        b.0.chunks_exact(2)
            .flat_map(|c| std::iter::repeat_n(i16::from_le_bytes([c[0], c[1]]), repeat))
            .collect();

    let mut m = Fm::unconfigured();
    if m.configure(scene).is_err() {
        // A refused scene leaves the placeholder one; the monitor must still run.
        let _ = run(&mut m, &samples, || 97, false);
        return;
    }
    // Block lengths 0..=300 from a small LCG seeded by the input.
    let (blocks, c1) = run(
        &mut m,
        &samples,
        || {
            seed = seed.wrapping_mul(1_103_515_245).wrapping_add(12_345);
            (seed >> 16) as usize % 301
        },
        sane,
    );
    let mut one = Fm::unconfigured();
    one.configure(scene).expect("accepted once");
    let (singles, c2) = run(&mut one, &samples, || 1, sane);
    assert_eq!(c1, c2, "counters depend on the block split");
    assert_eq!(blocks, singles, "reports depend on the block split");
});
