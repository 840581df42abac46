//! The captured windows' filter as the outputs name it: a CFC class or a Butterworth
//! low-pass (`--lowpass`, in the JSON as `lowpass`).

use impact_core::signal::lowpass::Lowpass;
use impact_core::signal::window_filter::WindowFilter;
use serde::Serialize;

use crate::report::fmt::shortest;

/// With `--lowpass`: the Butterworth low-pass the filtered fields
/// (`filtered_peak_acceleration_m_s2`, `filtered_fwhm_s`) come from.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct LowpassJson {
    /// Its order, 1 to 8 (one pass rolls off at 6 dB per octave per order).
    pub order: u8,
    /// One pass's −3 dB frequency, Hz (forward and backward, −6 dB).
    pub cutoff_hz: f64,
    /// Samples of signal the capture takes on either side of a contact for it to settle.
    pub padding_samples: u32,
}

impl LowpassJson {
    pub fn of(l: &Lowpass, rate_hz: f32) -> Self {
        Self {
            order: l.order,
            cutoff_hz: shortest(l.cutoff_hz),
            padding_samples: l.padding_samples(rate_hz),
        }
    }

    /// `low-pass order 4, 1000 Hz`.
    pub fn name(&self) -> String {
        lowpass_name(self.order, self.cutoff_hz)
    }
}

/// `low-pass order 4, 1000 Hz`: the setting in the digits it was given.
pub fn lowpass_name(order: u8, cutoff_hz: f64) -> String {
    format!("low-pass order {order}, {cutoff_hz} Hz")
}

/// The filter's short name (a legend, a title): `CFC 1000`, `low-pass order 4, 1000 Hz`.
pub fn name(f: &WindowFilter) -> String {
    match f {
        WindowFilter::Cfc(c) => format!("CFC {}", c.class()),
        WindowFilter::Lowpass(l) => lowpass_name(l.order, shortest(l.cutoff_hz)),
    }
}

/// What the filter is, in a sentence's words: `CFC 1000 (SAE J211, phaseless)`,
/// `Butterworth low-pass order 4, 1000 Hz (phaseless)`.
pub fn description(f: &WindowFilter) -> String {
    match f {
        WindowFilter::Cfc(_) => format!("{} (SAE J211, phaseless)", name(f)),
        WindowFilter::Lowpass(_) => format!("Butterworth {} (phaseless)", name(f)),
    }
}
