//! `impact analyze --srs`: each impact's shock response spectrum (SRS), pseudo-velocity shock
//! spectrum (PVSS) and enveloping half-sine as the core computes them on the board too
//! (`signal::spectrum`, f32 multirate), as JSON, CSV and a table line; and the host's f64
//! full-rate reference (`signal::srs`) the tests hold both against.

use clap::Args;
use impact_core::signal::spectrum::SpectrumSettings;
use impact_core::signal::srs::{self, Oscillator, Response};
use impact_core::ImpactReport;

use crate::analyze::Setup;
use crate::report::spectrum::ShockSpectrumJson;

/// Shock-spectrum options.
#[derive(Args, Clone, Debug, Default)]
pub struct SpectrumArgs {
    /// Add each impact's SRS (maximax absolute acceleration), PVSS and enveloping half-sine.
    #[arg(long, help_heading = "Analysis")]
    pub srs: bool,
    /// Damping ratio of the oscillators, in [0, 0.5].
    #[arg(long, help_heading = "Analysis", default_value_t = 0.05, requires = "srs", value_parser = damping)]
    pub srs_damping: f64,
    /// Bands per octave: 6 or 12 (centres 1000 × 2^(k/n) Hz).
    #[arg(long, help_heading = "Analysis", default_value_t = 6, requires = "srs", value_parser = per_octave)]
    pub srs_bands: u32,
    /// Lowest band, Hz (the highest is an eighth of the sample rate).
    #[arg(long, help_heading = "Analysis", default_value_t = 10.0, requires = "srs", value_parser = crate::parse::positive_f64)]
    pub srs_low: f64,
}

impl SpectrumArgs {
    /// The scene's spectrum settings, if asked for.
    pub fn settings(&self) -> Option<SpectrumSettings> {
        self.srs.then_some(SpectrumSettings {
            damping: self.srs_damping as f32,
            bands_per_octave: self.srs_bands as u8,
            low_hz: self.srs_low as f32,
        })
    }
}

fn per_octave(s: &str) -> Result<u32, String> {
    match s {
        "6" => Ok(6),
        "12" => Ok(12),
        _ => Err("must be 6 or 12".into()),
    }
}

fn damping(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if (0.0..=0.5).contains(&v) => Ok(v),
        Ok(_) => Err("must lie in [0, 0.5]".into()),
        Err(_) => Err("not a number".into()),
    }
}

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
    let n = srs::bands(args.srs_bands, args.srs_low, rate, &mut freqs);
    freqs.truncate(n);
    let peak = |response| -> Vec<f64> {
        freqs
            .iter()
            .map(|&f| {
                Oscillator::new(response, f, args.srs_damping, rate)
                    .map_or(0.0, |o| o.peak(accel()))
            })
            .collect()
    };
    let srs_m_s2 = peak(Response::AbsoluteAcceleration);
    let pvss_m_s = peak(Response::PseudoVelocity);
    let half = srs::enveloping_half_sine(&freqs, &pvss_m_s, args.srs_damping);
    ShockSpectrumJson {
        damping: args.srs_damping,
        bands_per_octave: args.srs_bands,
        from_sample: from,
        to_sample: to,
        frequency_hz: freqs,
        srs_m_s2,
        pvss_m_s,
        half_sine_amplitude_m_s2: half.map(|h| h.amplitude_m_s2),
        half_sine_duration_s: half.map(|h| h.duration_s),
    }
}
