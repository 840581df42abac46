//! SAE J211-1 / ISO 6487 channel-frequency-class (CFC) filters.
//!
//! A second-order Butterworth section with the J211 pre-warping, run forward then backward
//! (phaseless) on a captured window; the single forward pass is the causal option for live
//! triggering. Coefficients and state are `f64`: at high sample rates the `f32` coefficients
//! of the low classes lose their DC gain (CFC 60 at 500 kS/s: ~5 %), so the filter does not
//! use them. `f64` is soft-float on the Cortex-M4 but deterministic, so board and host agree
//! bit for bit; it runs once per captured impact, not per idle sample.

/// The four J211 classes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Cfc {
    Cfc60,
    Cfc180,
    Cfc600,
    Cfc1000,
}

impl Cfc {
    /// The class number (60, 180, 600, 1000).
    pub fn class(self) -> u32 {
        match self {
            Cfc::Cfc60 => 60,
            Cfc::Cfc180 => 180,
            Cfc::Cfc600 => 600,
            Cfc::Cfc1000 => 1000,
        }
    }

    /// Samples of signal the phaseless filter needs on each side of a pulse to settle: one
    /// period of its -3 dB frequency (1.667 × the class, SAE J211), rounded up.
    pub fn padding_samples(self, sample_rate_hz: f32) -> u32 {
        let n = libm::ceilf(sample_rate_hz / (1.667 * self.class() as f32));
        if n >= u32::MAX as f32 {
            u32::MAX
        } else if n >= 1.0 {
            n as u32
        } else {
            1
        }
    }

    /// The class from its number.
    pub fn from_class(class: u32) -> Option<Self> {
        match class {
            60 => Some(Cfc::Cfc60),
            180 => Some(Cfc::Cfc180),
            600 => Some(Cfc::Cfc600),
            1000 => Some(Cfc::Cfc1000),
            _ => None,
        }
    }
}

/// Second-order section `y[n] = a0 x[n] + a1 x[n-1] + a2 x[n-2] + b1 y[n-1] + b2 y[n-2]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Biquad {
    pub a0: f64,
    pub a1: f64,
    pub a2: f64,
    pub b1: f64,
    pub b2: f64,
}

impl Biquad {
    /// J211 coefficients for `class` at `sample_rate_hz`: `wd = 2 pi CFC 2.0775`,
    /// `wa = tan(wd T / 2)`. `None` unless the rate is finite and above 4 times the class's
    /// design frequency (the pre-warped section needs `wd T / 2 < pi / 2`).
    pub fn cfc(class: Cfc, sample_rate_hz: f64) -> Option<Self> {
        let t = 1.0 / sample_rate_hz;
        let wd = 2.0 * core::f64::consts::PI * class.class() as f64 * 2.0775;
        let half = wd * t / 2.0;
        if !(sample_rate_hz.is_finite() && half > 0.0 && half < 1.2) {
            return None;
        }
        let wa = libm::tan(half);
        let sqrt2 = core::f64::consts::SQRT_2;
        let d = 1.0 + sqrt2 * wa + wa * wa;
        let a0 = wa * wa / d;
        Some(Self {
            a0,
            a1: 2.0 * a0,
            a2: a0,
            b1: -2.0 * (wa * wa - 1.0) / d,
            b2: (-1.0 + sqrt2 * wa - wa * wa) / d,
        })
    }

    /// Filters `data` in place, forward. The state starts at rest on the first sample (no
    /// start-up step).
    pub fn forward(&self, data: &mut [f64]) {
        let Some(&first) = data.first() else { return };
        let (mut x1, mut x2, mut y1, mut y2) = (first, first, first, first);
        for v in data.iter_mut() {
            let x = *v;
            let y = self.a0 * x + self.a1 * x1 + self.a2 * x2 + self.b1 * y1 + self.b2 * y2;
            x2 = x1;
            x1 = x;
            y2 = y1;
            y1 = y;
            *v = y;
        }
    }

    /// Phaseless filtering: forward, then backward over the result.
    pub fn phaseless(&self, data: &mut [f64]) {
        self.forward(data);
        data.reverse();
        self.forward(data);
        data.reverse();
    }

    /// Phaseless filtering of `f32` data with `f64` coefficients and state (the samples are
    /// rounded to `f32` only between and after the passes).
    pub fn phaseless_f32(&self, data: &mut [f32]) {
        let pass = |data: &mut [f32], reverse: bool| {
            let first = if reverse { data.last() } else { data.first() };
            let Some(&first) = first else { return };
            let first = first as f64;
            let (mut x1, mut x2, mut y1, mut y2) = (first, first, first, first);
            let mut step = |v: &mut f32| {
                let x = *v as f64;
                let y = self.a0 * x + self.a1 * x1 + self.a2 * x2 + self.b1 * y1 + self.b2 * y2;
                x2 = x1;
                x1 = x;
                y2 = y1;
                y1 = y;
                *v = y as f32;
            };
            if reverse {
                data.iter_mut().rev().for_each(&mut step);
            } else {
                data.iter_mut().for_each(&mut step);
            }
        };
        pass(data, false);
        pass(data, true);
    }

    /// Gain of one pass at frequency `f_hz`.
    pub fn gain(&self, f_hz: f64, sample_rate_hz: f64) -> f64 {
        let w = 2.0 * core::f64::consts::PI * f_hz / sample_rate_hz;
        let (c1, s1) = (libm::cos(w), libm::sin(w));
        let (c2, s2) = (libm::cos(2.0 * w), libm::sin(2.0 * w));
        let nr = self.a0 + self.a1 * c1 + self.a2 * c2;
        let ni = -(self.a1 * s1 + self.a2 * s2);
        let dr = 1.0 - self.b1 * c1 - self.b2 * c2;
        let di = self.b1 * s1 + self.b2 * s2;
        libm::sqrt((nr * nr + ni * ni) / (dr * dr + di * di))
    }
}

/// The forward (causal) pass as a running filter, one sample at a time: the live trigger's
/// option. `f64` state, so even CFC 60 at high rates keeps its DC gain.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Causal {
    b: Biquad,
    x1: f64,
    x2: f64,
    y1: f64,
    y2: f64,
}

impl Causal {
    /// A filter at rest at `level`.
    pub fn new(b: Biquad, level: f64) -> Self {
        Self {
            b,
            x1: level,
            x2: level,
            y1: level,
            y2: level,
        }
    }

    /// Puts the filter at rest at `level` (no start-up step).
    pub fn reset(&mut self, level: f64) {
        *self = Self::new(self.b, level);
    }

    /// Filters one sample.
    #[inline]
    pub fn step(&mut self, x: f64) -> f64 {
        let b = &self.b;
        let y = b.a0 * x + b.a1 * self.x1 + b.a2 * self.x2 + b.b1 * self.y1 + b.b2 * self.y2;
        self.x2 = self.x1;
        self.x1 = x;
        self.y2 = self.y1;
        self.y1 = y;
        y
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn double_pass_is_3_db_down_at_five_thirds_of_the_class() {
        for class in [Cfc::Cfc60, Cfc::Cfc180, Cfc::Cfc600, Cfc::Cfc1000] {
            for fs in [10_000.0, 100_000.0, 500_000.0, 1_000_000.0] {
                // J211 expects sampling well above the class (here at least 100x).
                if fs < 100.0 * class.class() as f64 {
                    continue;
                }
                let b = Biquad::cfc(class, fs).unwrap();
                let f3 = 5.0 / 3.0 * class.class() as f64;
                let g = b.gain(f3, fs);
                let db = 20.0 * libm::log10(g * g);
                assert!(
                    (db + 3.0).abs() < 0.05,
                    "{class:?} at {fs}: {db} dB at {f3} Hz"
                );
                // f64 keeps the DC gain to ~1e-9 even for CFC 60 at 1 MS/s.
                assert!(
                    (b.gain(0.0, fs) - 1.0).abs() < 1e-8,
                    "DC gain {}",
                    b.gain(0.0, fs)
                );
            }
        }
    }

    #[test]
    fn f32_coefficients_would_lose_dc_gain_at_high_rates() {
        // Why the filter is f64: CFC 60 at 500 kS/s.
        let b = Biquad::cfc(Cfc::Cfc60, 500_000.0).unwrap();
        let dc32 = (4.0 * (b.a0 as f32)) / (1.0 - b.b1 as f32 - b.b2 as f32);
        assert!((dc32 - 1.0).abs() > 0.01, "f32 DC gain {dc32}");
    }

    #[test]
    fn phaseless_filtering_keeps_a_constant_and_centres_a_symmetric_pulse() {
        let b = Biquad::cfc(Cfc::Cfc1000, 100_000.0).unwrap();
        let mut flat = [3.0f64; 64];
        b.phaseless(&mut flat);
        assert!(flat.iter().all(|v| (v - 3.0).abs() < 1e-12));
        let mut pulse = [0.0f64; 201];
        for (i, v) in pulse.iter_mut().enumerate() {
            let t = (i as f64 - 100.0) / 20.0;
            *v = libm::exp(-t * t);
        }
        b.phaseless(&mut pulse);
        let peak = (0..pulse.len())
            .max_by(|&a, &c| pulse[a].total_cmp(&pulse[c]))
            .unwrap();
        assert_eq!(peak, 100);
    }

    #[test]
    fn causal_pass_equals_the_forward_pass() {
        let b = Biquad::cfc(Cfc::Cfc600, 100_000.0).unwrap();
        let mut data: [f64; 50] = core::array::from_fn(|i| if i > 10 { 5.0 } else { 1.0 });
        let mut c = Causal::new(b, data[0]);
        let stepped: [f64; 50] = core::array::from_fn(|i| c.step(data[i]));
        b.forward(&mut data);
        assert_eq!(stepped, data);
    }

    #[test]
    fn rejects_rates_too_low_for_the_class() {
        assert!(Biquad::cfc(Cfc::Cfc1000, 5_000.0).is_none());
        assert!(Biquad::cfc(Cfc::Cfc60, f64::NAN).is_none());
    }
}
