//! The captured windows' phaseless filter: an SAE J211 class ([`super::cfc`]) or a lab's own
//! Butterworth low-pass ([`super::lowpass`]). Either runs where the other would: on
//! everything a capture holds, with its padding of signal taken around the contact.

use super::cfc::{Biquad, Cfc};
use super::lowpass::{Butterworth, Lowpass};

/// The filter a scene asks for on its captured windows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum WindowFilter {
    Cfc(Cfc),
    Lowpass(Lowpass),
}

impl WindowFilter {
    /// Samples of signal the filter needs on each side of a pulse to settle.
    pub fn padding_samples(&self, sample_rate_hz: f32) -> u32 {
        match self {
            WindowFilter::Cfc(c) => c.padding_samples(sample_rate_hz),
            WindowFilter::Lowpass(l) => l.padding_samples(sample_rate_hz),
        }
    }

    /// Its coefficients at `sample_rate_hz`; `None` if it cannot run at this rate.
    pub fn design(&self, sample_rate_hz: f64) -> Option<Designed> {
        match self {
            WindowFilter::Cfc(c) => Biquad::cfc(*c, sample_rate_hz).map(Designed::Cfc),
            WindowFilter::Lowpass(l) => l.design(sample_rate_hz).map(Designed::Lowpass),
        }
    }
}

/// A [`WindowFilter`] designed for a rate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Designed {
    Cfc(Biquad),
    Lowpass(Butterworth),
}

impl Designed {
    /// Phaseless filtering of `f32` data, `f64` inside.
    pub fn phaseless_f32(&self, data: &mut [f32]) {
        match self {
            Designed::Cfc(b) => b.phaseless_f32(data),
            Designed::Lowpass(b) => b.phaseless_f32(data),
        }
    }

    /// Phaseless filtering of `f64` data.
    pub fn phaseless(&self, data: &mut [f64]) {
        match self {
            Designed::Cfc(b) => b.phaseless(data),
            Designed::Lowpass(b) => b.phaseless(data),
        }
    }
}
