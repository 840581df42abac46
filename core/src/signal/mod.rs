//! Signal path building blocks: calibration, pre-trigger ring, exact integration, CFC and
//! Butterworth low-pass filters.

pub mod axes_zero;
pub mod baseline;
pub mod cfc;
pub mod copy;
pub mod flank;
pub mod integrate;
pub mod lowpass;
pub mod power_flank;
pub mod resultant;
pub mod ring;
pub mod spectrum;
pub mod srs;
pub mod window_filter;

/// Converts raw integer samples to physical units. SI throughout.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Calibration {
    /// Acceleration per count, m/s² (negative to invert the sensor's sign).
    pub gain_m_s2_per_count: f32,
    /// Samples per second, Hz.
    pub sample_rate_hz: f32,
}

impl Calibration {
    /// Sample period, s.
    pub fn period_s(&self) -> f32 {
        1.0 / self.sample_rate_hz
    }
}
