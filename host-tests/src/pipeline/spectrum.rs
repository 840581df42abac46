//! `impact analyze --srs`: each impact's shock response spectrum (SRS), pseudo-velocity shock
//! spectrum (PVSS) and enveloping half-sine as the core computes them on the board too
//! (`signal::spectrum`, f32 multirate), as JSON, CSV and a table line; and the host's f64
//! full-rate reference (`signal::srs`) the tests hold both against.

use impact_core::signal::srs::{self, Oscillator, Response};
use impact_core::ImpactReport;

use crate::pipeline::options::SpectrumArgs;
use crate::pipeline::Setup;
use crate::report::spectrum::ShockSpectrumJson;

/// Samples before the report's onset included in the window (the pulse's foot): the same
/// as the board's.
const LEAD_SAMPLES: u64 = impact_core::analysis::SPECTRUM_LEAD;

/// Most bands: 12 per octave from 1 mHz to 100 MHz.
const MAX_BANDS: usize = 12 * 37;

/// The f64 full-rate reference spectra of one impact (the tests' check on the board's): its
/// onset less [`LEAD_SAMPLES`] to the end of its hold, the counts less the report's baseline.
pub fn reference_spectrum(
    setup: &Setup,
    r: &ImpactReport,
    args: &SpectrumArgs,
) -> ShockSpectrumJson {
    let counts = &setup.prepared.counts;
    let gain = setup.scene.calibration.gain_m_s2_per_count as f64;
    let baseline = r.baseline_m_s2 as f64;
    let rate = setup.rate_hz;
    let from = r
        .start_sample
        .saturating_sub(LEAD_SAMPLES)
        .min(counts.len() as u64);
    let to = r.end_sample.clamp(from, counts.len() as u64);
    let window = &counts[from as usize..to as usize];
    let accel = || window.iter().map(|&c| c as f64 * gain - baseline);
    let mut freqs = vec![0.0; MAX_BANDS];
    // The bands' limits as the core's settings hold them (`f32`), so a limit within `f32`'s
    // rounding of a band centre gives both the same bands.
    let n = srs::bands(
        args.bands_per_octave(),
        f64::from(args.low_hz() as f32),
        args.srs_high.map(|h| f64::from(h as f32)),
        rate,
        &mut freqs,
    );
    freqs.truncate(n);
    let peak = |response| -> Vec<f64> {
        freqs
            .iter()
            .map(|&f| {
                Oscillator::new(response, f, args.damping(), rate).map_or(0.0, |o| o.peak(accel()))
            })
            .collect()
    };
    let srs_m_s2 = peak(Response::AbsoluteAcceleration);
    let pvss_m_s = peak(Response::PseudoVelocity);
    let half = srs::enveloping_half_sine(&freqs, &pvss_m_s, args.damping());
    ShockSpectrumJson {
        damping: args.damping(),
        bands_per_octave: args.bands_per_octave(),
        from_sample: from,
        to_sample: to,
        frequency_hz: freqs,
        srs_m_s2,
        pvss_m_s,
        half_sine_amplitude_m_s2: half.map(|h| h.amplitude_m_s2),
        half_sine_duration_s: half.map(|h| h.duration_s),
    }
}
