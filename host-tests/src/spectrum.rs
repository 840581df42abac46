//! `impact analyze --srs`: each impact's shock response spectrum (SRS), pseudo-velocity shock
//! spectrum (PVSS) and enveloping half-sine as the core computes them on the board too
//! (`signal::spectrum`, f32 multirate), as JSON, CSV and a table line; and the host's f64
//! full-rate reference (`signal::srs`) the tests hold both against.

use clap::Args;
use impact_core::report::Spectrum;
use impact_core::signal::spectrum::SpectrumSettings;
use impact_core::signal::srs::{self, Oscillator, Response};
use impact_core::ImpactReport;
use serde::Serialize;

use crate::analyze::{human, Setup};

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
    #[arg(long, help_heading = "Analysis", default_value_t = 10.0, requires = "srs", value_parser = crate::analyze::positive_f64)]
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

/// A core spectrum as JSON.
pub fn spectrum_json(s: &Spectrum) -> ShockSpectrumJson {
    let n = usize::from(s.bands);
    let f = |v: &f32| *v as f64;
    ShockSpectrumJson {
        damping: crate::analyze::shortest(s.damping),
        bands_per_octave: u32::from(s.bands_per_octave),
        from_sample: s.from_sample,
        to_sample: s.to_sample,
        frequency_hz: (0..n).map(|k| s.frequency_hz(k)).collect(),
        srs_m_s2: s.srs_m_s2[..n].iter().map(f).collect(),
        pvss_m_s: s.pvss_m_s[..n].iter().map(f).collect(),
        half_sine_amplitude_m_s2: s.half_sine.map(|h| h.0 as f64),
        half_sine_duration_s: s.half_sine.map(|h| h.1 as f64),
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

/// One impact's spectra.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct ShockSpectrumJson {
    pub damping: f64,
    pub bands_per_octave: u32,
    /// First and one-past-last sample the spectra were computed over (the residual after it
    /// included).
    pub from_sample: u64,
    pub to_sample: u64,
    pub frequency_hz: Vec<f64>,
    /// Largest |absolute acceleration| of each oscillator, m/s².
    pub srs_m_s2: Vec<f64>,
    /// Largest ω × |relative displacement|, m/s.
    pub pvss_m_s: Vec<f64>,
    /// Gaberson's half-sine whose PVSS envelopes this one (enDAQ's `enveloping_half_sine`).
    pub half_sine_amplitude_m_s2: Option<f64>,
    pub half_sine_duration_s: Option<f64>,
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

/// The SRS's largest value and its band, if any.
pub fn srs_peak(s: &ShockSpectrumJson) -> Option<(f64, f64)> {
    s.srs_m_s2
        .iter()
        .zip(&s.frequency_hz)
        .map(|(&a, &f)| (a, f))
        .fold(None, |best, (a, f)| match best {
            Some((b, _)) if b >= a => best,
            _ => Some((a, f)),
        })
}

/// The CSV columns `impact analyze --csv --srs` adds.
pub const CSV_HEADER: &str =
    "srs_peak_m_s2,srs_peak_frequency_hz,half_sine_amplitude_m_s2,half_sine_duration_s";

/// An impact's cells under [`CSV_HEADER`] (empty without spectra).
pub fn csv_cells(s: Option<&ShockSpectrumJson>) -> String {
    let o = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v:e}"));
    let peak = s.and_then(srs_peak);
    [
        o(peak.map(|p| p.0)),
        o(peak.map(|p| p.1)),
        o(s.and_then(|s| s.half_sine_amplitude_m_s2)),
        o(s.and_then(|s| s.half_sine_duration_s)),
    ]
    .join(",")
}

/// The table's line for an impact's spectra.
pub fn table_line(s: &ShockSpectrumJson) -> String {
    let g = impact_core::consts::STANDARD_GRAVITY;
    let peak = srs_peak(s).map_or("none".to_string(), |(a, f)| {
        format!(
            "{} ({}) at {}",
            human(a, "m/s²"),
            human(a / g, "g"),
            human(f, "Hz")
        )
    });
    let half = match (s.half_sine_amplitude_m_s2, s.half_sine_duration_s) {
        (Some(a), Some(t)) => format!(
            "{} ({}) for {}",
            human(a, "m/s²"),
            human(a / g, "g"),
            human(t, "s")
        ),
        _ => "none".to_string(),
    };
    format!(
        "    SRS ({:.0} % damping, 1/{} octave, {} bands): peak {peak}; enveloping half-sine {half}\n",
        s.damping * 100.0,
        s.bands_per_octave,
        s.frequency_hz.len()
    )
}
