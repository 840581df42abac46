//! Shock spectra (`--srs`) in the report: the JSON, its CSV columns and its table line.

use impact_core::report::Spectrum;
use serde::Serialize;

use super::fmt::human;

/// A core spectrum as JSON.
pub fn spectrum_json(s: &Spectrum) -> ShockSpectrumJson {
    let n = usize::from(s.bands);
    let f = |v: &f32| *v as f64;
    ShockSpectrumJson {
        damping: crate::report::fmt::shortest(s.damping),
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

/// One impact's spectra.
#[derive(Clone, Debug, Serialize, serde::Deserialize, PartialEq)]
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
pub const CSV_COLUMNS: [&str; 4] = [
    "srs_peak_m_s2",
    "srs_peak_frequency_hz",
    "half_sine_amplitude_m_s2",
    "half_sine_duration_s",
];

/// An impact's cells under [`CSV_COLUMNS`] (empty without spectra).
pub fn csv_cells(s: Option<&ShockSpectrumJson>) -> [String; 4] {
    let o = |v: Option<f64>| v.map_or(String::new(), crate::report::fmt::number);
    let peak = s.and_then(srs_peak);
    [
        o(peak.map(|p| p.0)),
        o(peak.map(|p| p.1)),
        o(s.and_then(|s| s.half_sine_amplitude_m_s2)),
        o(s.and_then(|s| s.half_sine_duration_s)),
    ]
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
