//! A Butterworth low-pass of a chosen order and cut-off, run forward then backward
//! (phaseless) on a captured window: a lab's own filter beside SAE J211's classes (`cfc`).
//!
//! Designed as SciPy's `butter(order, cutoff, fs=rate, output='sos')`: the analogue
//! Butterworth poles at the cut-off pre-warped (`K = tan(pi cutoff / rate)`), mapped by the
//! bilinear transform, in second-order sections (one first-order section for an odd order)
//! with their zeros at Nyquist. Each section has unit gain at 0 Hz (SciPy puts the whole gain
//! into its first section: the same filter, another rounding). The cut-off is one pass's
//! −3 dB point, as SciPy's; forward and backward it is −6 dB there.
//!
//! Run as `cfc.rs` runs its section: `f64` coefficients and state (soft-float on the
//! Cortex-M4, so board and host agree bit for bit; once per captured impact), each pass
//! starting at rest on its first value. That is SciPy's `sosfiltfilt(sos, x, padtype=None)`
//! (`sosfilt_zi` times the first value); its default odd padding differs only near the ends,
//! where the capture holds real signal as padding ([`Lowpass::padding_samples`]).

use super::cfc::Biquad;
use crate::error::Error;

/// Orders the filter takes: 1 to 8 (one pass rolls off at `6 order` dB per octave).
pub const MIN_ORDER: u8 = 1;
pub const MAX_ORDER: u8 = 8;

/// Sections of the highest order.
pub const MAX_SECTIONS: usize = MAX_ORDER.div_ceil(2) as usize;

/// The lowest cut-off is the sample rate over this: below it the `f64` sections' gain at
/// 0 Hz drifts further from 1 (the rounding of `1 - b1 - b2` against `K^2`; measured in the
/// tests).
pub const MAX_RATE_OVER_CUTOFF: f64 = 1e5;

/// The setting: order and cut-off (Hz, one pass's −3 dB point).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Lowpass {
    pub order: u8,
    pub cutoff_hz: f32,
}

impl Lowpass {
    /// A low-pass of `order` (1 to 8) at `cutoff_hz` (finite and > 0); the rate is checked
    /// by [`Lowpass::check`].
    pub fn new(order: u8, cutoff_hz: f32) -> Result<Self, Error> {
        let l = Self { order, cutoff_hz };
        l.check_own()?;
        Ok(l)
    }

    fn check_own(&self) -> Result<(), Error> {
        if !(MIN_ORDER..=MAX_ORDER).contains(&self.order) {
            return Err(Error::InvalidParameter {
                name: "lowpass",
                reason: "the order must be 1 to 8",
            });
        }
        if !(self.cutoff_hz.is_finite() && self.cutoff_hz > 0.0) {
            return Err(Error::InvalidParameter {
                name: "lowpass",
                reason: "the cut-off must be finite and > 0 Hz",
            });
        }
        Ok(())
    }

    /// The setting at `rate_hz`: its order, and a cut-off below Nyquist and at least the rate
    /// over [`MAX_RATE_OVER_CUTOFF`].
    pub fn check(&self, rate_hz: f32) -> Result<(), Error> {
        self.check_own()?;
        let (fc, fs) = (f64::from(self.cutoff_hz), f64::from(rate_hz));
        if !(fc < fs / 2.0) {
            return Err(Error::InvalidParameter {
                name: "lowpass",
                reason: "the cut-off must be below the Nyquist frequency (half the sample rate)",
            });
        }
        if !(fc * MAX_RATE_OVER_CUTOFF >= fs) {
            return Err(Error::InvalidParameter {
                name: "lowpass",
                reason: "the cut-off must be at least 1e-5 of the sample rate",
            });
        }
        Ok(())
    }

    /// The sections at `rate_hz` (`None` where [`Lowpass::check`] refuses the setting).
    pub fn design(&self, rate_hz: f64) -> Option<Butterworth> {
        if self.check(rate_hz as f32).is_err() {
            return None;
        }
        Butterworth::new(self.order, f64::from(self.cutoff_hz), rate_hz)
    }

    /// Samples of signal the phaseless filter needs on each side of a pulse to settle: until
    /// the envelope of its slowest pole (damping `sin(pi / (2 order))`) is down to
    /// `exp(-pi sqrt 2)` (1.2 %), `rate / cutoff` times [`PADDING_PERIODS`], rounded up: for
    /// order 2, one period of the cut-off (as the CFC's padding is one period of its −3 dB
    /// frequency); for order 8, 3.6 periods.
    pub fn padding_samples(&self, sample_rate_hz: f32) -> u32 {
        let periods = PADDING_PERIODS
            .get(usize::from(self.order.clamp(MIN_ORDER, MAX_ORDER) - 1))
            .copied()
            .unwrap_or(1.0);
        let n = libm::ceil(f64::from(sample_rate_hz) / f64::from(self.cutoff_hz) * periods);
        if n >= f64::from(u32::MAX) {
            u32::MAX
        } else if n >= 1.0 {
            n as u32
        } else {
            1
        }
    }
}

/// Periods of the cut-off the padding spans, by order (1 to 8): `1 / (sqrt 2 sin(pi / (2
/// order)))`, held as numbers so that order 2's is exactly 1 (the tests check the formula).
pub const PADDING_PERIODS: [f64; MAX_ORDER as usize] = [
    0.7071067811865475,
    1.0,
    core::f64::consts::SQRT_2,
    1.8477590650225735,
    2.2882456112707374,
    2.732050807568877,
    3.1777090299529647,
    3.6245097854115516,
];

/// The designed filter: up to [`MAX_SECTIONS`] sections in cascade (the first-order one of an
/// odd order first, then the pairs from the most damped to the least, as SciPy orders them).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Butterworth {
    sections: [Biquad; MAX_SECTIONS],
    len: usize,
}

impl Butterworth {
    /// The sections of `order` (1 to 8) at `cutoff_hz` for `rate_hz`; `None` unless
    /// `0 < cutoff < rate / 2` and both are finite.
    pub fn new(order: u8, cutoff_hz: f64, rate_hz: f64) -> Option<Self> {
        let designable = (MIN_ORDER..=MAX_ORDER).contains(&order)
            && cutoff_hz > 0.0
            && rate_hz.is_finite()
            && cutoff_hz < rate_hz / 2.0;
        if !designable {
            return None;
        }
        let k = libm::tan(core::f64::consts::PI * cutoff_hz / rate_hz);
        if !(k.is_finite() && k > 0.0) {
            return None;
        }
        let idle = Biquad {
            a0: 1.0,
            a1: 0.0,
            a2: 0.0,
            b1: 0.0,
            b2: 0.0,
        };
        let mut sections = [idle; MAX_SECTIONS];
        let mut len = 0;
        let mut push = |b: Biquad| {
            if let Some(slot) = sections.get_mut(len) {
                *slot = b;
                len += 1;
            }
        };
        if order % 2 == 1 {
            // The real pole: `1 / (s + 1)`.
            let d = 1.0 + k;
            push(Biquad {
                a0: k / d,
                a1: k / d,
                a2: 0.0,
                b1: (1.0 - k) / d,
                b2: 0.0,
            });
        }
        // Each pair `1 / (s^2 + 2 zeta s + 1)`, `2 zeta = 2 sin(pi (2 i + 1) / (2 order))`,
        // the most damped first.
        for i in (0..order / 2).rev() {
            let two_zeta = 2.0
                * libm::sin(
                    core::f64::consts::PI * f64::from(2 * i + 1) / (2.0 * f64::from(order)),
                );
            let k2 = k * k;
            let d = 1.0 + two_zeta * k + k2;
            let a0 = k2 / d;
            push(Biquad {
                a0,
                a1: 2.0 * a0,
                a2: a0,
                b1: 2.0 * (1.0 - k2) / d,
                b2: -(1.0 - two_zeta * k + k2) / d,
            });
        }
        Some(Self { sections, len })
    }

    /// The sections, in the order they run.
    pub fn sections(&self) -> &[Biquad] {
        self.sections.get(..self.len).unwrap_or(&[])
    }

    /// One pass over `len` values, read and written by index through `get` and `set` (in
    /// the order `at` gives), every section at rest on the first value.
    fn pass(&self, len: usize, at: impl Fn(usize) -> usize, io: &mut impl Io) {
        if len == 0 {
            return;
        }
        let first = io.get(at(0));
        // Each section's `(x1, x2, y1, y2)`, at rest on the first value (every section's
        // gain at 0 Hz is 1, so every section's input is that value too).
        let mut state = [[first; 4]; MAX_SECTIONS];
        for n in 0..len {
            let i = at(n);
            let mut v = io.get(i);
            for (b, s) in self.sections().iter().zip(state.iter_mut()) {
                let [x1, x2, y1, y2] = *s;
                let y = b.a0 * v + b.a1 * x1 + b.a2 * x2 + b.b1 * y1 + b.b2 * y2;
                *s = [v, x1, y, y1];
                v = y;
            }
            io.set(i, v);
        }
    }

    /// Phaseless filtering in place: forward, then backward over the result.
    pub fn phaseless(&self, data: &mut [f64]) {
        let n = data.len();
        let mut io = F64(data);
        self.pass(n, |i| i, &mut io);
        self.pass(n, |i| n - 1 - i, &mut io);
    }

    /// Phaseless filtering of `f32` data with `f64` coefficients and state (the values are
    /// rounded to `f32` only between and after the passes), as [`Biquad::phaseless_f32`].
    pub fn phaseless_f32(&self, data: &mut [f32]) {
        let n = data.len();
        let mut io = F32(data);
        self.pass(n, |i| i, &mut io);
        self.pass(n, |i| n - 1 - i, &mut io);
    }

    /// Gain of one pass at frequency `f_hz`.
    pub fn gain(&self, f_hz: f64, sample_rate_hz: f64) -> f64 {
        self.sections()
            .iter()
            .map(|b| b.gain(f_hz, sample_rate_hz))
            .product()
    }
}

/// Values a pass reads and writes as `f64`.
trait Io {
    fn get(&self, i: usize) -> f64;
    fn set(&mut self, i: usize, v: f64);
}

struct F64<'a>(&'a mut [f64]);
struct F32<'a>(&'a mut [f32]);

impl Io for F64<'_> {
    fn get(&self, i: usize) -> f64 {
        self.0.get(i).copied().unwrap_or(0.0)
    }
    fn set(&mut self, i: usize, v: f64) {
        if let Some(slot) = self.0.get_mut(i) {
            *slot = v;
        }
    }
}

impl Io for F32<'_> {
    fn get(&self, i: usize) -> f64 {
        self.0.get(i).map_or(0.0, |&v| f64::from(v))
    }
    fn set(&mut self, i: usize, v: f64) {
        if let Some(slot) = self.0.get_mut(i) {
            *slot = v as f32;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_pass_is_3_db_down_at_the_cutoff_and_1_at_dc() {
        for order in MIN_ORDER..=MAX_ORDER {
            for (fc, fs) in [(1000.0, 1e6), (100.0, 1e4), (2000.0, 1e4), (20.0, 1e6)] {
                let b = Butterworth::new(order, fc, fs).unwrap();
                assert_eq!(b.sections().len(), usize::from(order).div_ceil(2));
                let db = 20.0 * libm::log10(b.gain(fc, fs));
                assert!(
                    (db + 3.0103).abs() < 1e-3,
                    "order {order}, {fc} of {fs}: {db} dB"
                );
                let dc = b.gain(0.0, fs);
                // (Rounding against `K^2`: 1e-8 at 2e-5 of the rate.)
                assert!((dc - 1.0).abs() < 1e-7, "order {order}: DC gain {dc}");
                // An octave above (below Nyquist), 6 order dB further down, at least.
                let above = 20.0 * libm::log10(b.gain(2.0 * fc, fs));
                assert!(above < db - 3.0 * f64::from(order), "{above} dB");
            }
        }
    }

    #[test]
    fn order_2_is_the_cfc_section_without_its_corner_correction() {
        // CFC 1000's section is this one at 2.0775 kHz (J211's design frequency).
        let cfc = Biquad::cfc(crate::signal::cfc::Cfc::Cfc1000, 1e6).unwrap();
        let b = Butterworth::new(2, 2077.5, 1e6).unwrap();
        let s = b.sections()[0];
        for (x, y) in [
            (s.a0, cfc.a0),
            (s.a1, cfc.a1),
            (s.a2, cfc.a2),
            (s.b1, cfc.b1),
            (s.b2, cfc.b2),
        ] {
            assert!((x - y).abs() <= 1e-15 * y.abs().max(1e-3), "{x} vs {y}");
        }
    }

    #[test]
    fn keeps_a_constant_and_centres_a_symmetric_pulse() {
        for order in [1, 2, 3, 4, 8] {
            let b = Butterworth::new(order, 5000.0, 100_000.0).unwrap();
            let mut flat = [3.0f64; 64];
            b.phaseless(&mut flat);
            assert!(flat.iter().all(|v| (v - 3.0).abs() < 1e-12), "{flat:?}");
            let mut pulse = [0.0f64; 1001];
            for (i, v) in pulse.iter_mut().enumerate() {
                let t = (i as f64 - 500.0) / 5.0;
                *v = libm::exp(-t * t);
            }
            b.phaseless(&mut pulse);
            let peak = (0..pulse.len())
                .max_by(|&a, &c| pulse[a].total_cmp(&pulse[c]))
                .unwrap();
            assert_eq!(peak, 500, "order {order}");
            // Symmetric about the peak (phaseless), far from the ends.
            for d in 1..200 {
                let (l, r) = (pulse[500 - d], pulse[500 + d]);
                assert!((l - r).abs() < 1e-9, "order {order}: {l} vs {r}");
            }
        }
    }

    #[test]
    fn the_f32_run_is_the_f64_run_rounded() {
        let b = Butterworth::new(4, 1000.0, 1e6).unwrap();
        let x: [f64; 3000] = core::array::from_fn(|i| {
            let t = i as f64 * 1e-6;
            if (1e-3..1.1e-3).contains(&t) {
                libm::sin(core::f64::consts::PI * (t - 1e-3) / 1e-4)
            } else {
                0.0
            }
        });
        let mut a = x;
        let mut b32: [f32; 3000] = core::array::from_fn(|i| x[i] as f32);
        b.phaseless(&mut a);
        b.phaseless_f32(&mut b32);
        for (p, q) in a.iter().zip(&b32) {
            assert!((p - f64::from(*q)).abs() < 1e-6, "{p} vs {q}");
        }
    }

    #[test]
    fn the_lowest_cutoff_keeps_its_dc_gain() {
        for order in MIN_ORDER..=MAX_ORDER {
            let fs = 1e6;
            let b = Butterworth::new(order, fs / MAX_RATE_OVER_CUTOFF, fs).unwrap();
            // The sections' own gain at 0 Hz, from their coefficients as a pass sums them.
            let dc: f64 = (b.sections().iter())
                .map(|s| (s.a0 + s.a1 + s.a2) / (1.0 - s.b1 - s.b2))
                .product();
            assert!((dc - 1.0).abs() < 1e-6, "order {order}: DC gain {dc}");
            let mut flat = [1.0f64; 1000];
            b.phaseless(&mut flat);
            assert!(flat.iter().all(|v| (v - 1.0).abs() < 1e-6), "order {order}");
        }
    }

    #[test]
    fn refuses_what_it_cannot_design() {
        assert!(Lowpass::new(0, 1000.0).is_err());
        assert!(Lowpass::new(9, 1000.0).is_err());
        assert!(Lowpass::new(4, 0.0).is_err());
        assert!(Lowpass::new(4, f32::NAN).is_err());
        assert!(Lowpass::new(4, f32::INFINITY).is_err());
        let l = Lowpass::new(4, 500_000.0).unwrap();
        assert!(l.check(1e6).is_err(), "at Nyquist");
        assert!(l.design(1e6).is_none());
        assert!(Lowpass::new(4, 499_999.0).unwrap().check(1e6).is_ok());
        assert!(
            Lowpass::new(4, 9.0).unwrap().check(1e6).is_err(),
            "below 1e-5"
        );
        assert!(Lowpass::new(4, 10.0).unwrap().check(1e6).is_ok());
        assert!(Butterworth::new(2, 1000.0, f64::NAN).is_none());
        assert!(Butterworth::new(2, 1000.0, 2000.0).is_none());
    }

    #[test]
    fn padding_is_one_cutoff_period_at_order_2_and_longer_above() {
        let at = |order| Lowpass::new(order, 1000.0).unwrap().padding_samples(1e6);
        assert_eq!(at(2), 1000);
        assert_eq!(at(1), 708);
        assert_eq!(at(8), 3625);
        for (n, p) in (1..).zip(PADDING_PERIODS) {
            let f = 1.0
                / (core::f64::consts::SQRT_2 * libm::sin(core::f64::consts::PI / (2.0 * n as f64)));
            assert!((p - f).abs() < 1e-15, "order {n}: {p} vs {f}");
        }
        assert_eq!(
            Lowpass::new(8, 1e-30).unwrap().padding_samples(1e8),
            u32::MAX
        );
    }
}
