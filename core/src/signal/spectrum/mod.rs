//! Shock spectra as the board computes them, per impact: the ISO 18431-4 filters of
//! [`super::srs`] in `f32`, each band at the full rate or, below rate / 64, at the rate
//! halved as often as keeps it 32 to 64 times the band's frequency. The pulse is halved in
//! rate by a 23-tap half-band FIR, in place, once per octave, so the cost grows with the
//! number of bands per octave, not with the lowest band, and every filter's poles stay clear
//! of 1 where `f32` keeps the response (at the full rate a 10 Hz band at 500 kS/s would have
//! `ω T` = 1.3e-4). On a decimated signal a 5-tap pre-emphasis undoes the ramp-invariant
//! filter's linear interpolation (`sinc²`) and the peak is taken between samples (the
//! sinusoid through the three samples around it) at the instant the full-rate filter would
//! sample it: within 1.2e-4 of the full-rate f64 reference on half-sines of 1 to 5.5 ms
//! (1.5e-3 for 65 µs); content far above a low band, which reaches its absolute
//! acceleration through the damping, is lost with the decimation (0.5 % of the AFRL record's
//! SRS at 200 Hz; halving at rate / 32 instead would save a fifth of the work and lose 0.8 %).
//!
//! Each band runs in two passes over blocks of [`BLOCK`] samples: the recursion alone
//! (3.4 instructions a sample on the M4), marking each block with its state and a [`Bound`]
//! on both responses over it; then both responses, keeping each block's largest `|y|`
//! without a branch, only for the blocks whose bound reaches the largest `|y|` found so far
//! (on the seed's impact 12 to 19 of 102 blocks a band). The result is the same, bit for
//! bit, as computing every block; only the block that holds a response's peak is run again,
//! for the samples around it.

use super::srs::{self};
use crate::error::Error;

mod band;
mod bound;
mod emphasis;
mod halfband;

use band::*;
use bound::*;
use emphasis::*;
use halfband::*;

/// Most bands a spectrum holds (1/6 octave from 10 Hz to 125 kHz is 81).
pub const MAX_BANDS: usize = 96;

/// What to compute: the scene's spectrum settings.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SpectrumSettings {
    /// Damping ratio of the oscillators, in `[0, 0.5]` (5 % usually).
    pub damping: f32,
    /// Bands per octave: 6 or 12.
    pub bands_per_octave: u8,
    /// Lowest band, Hz (bands are `1000 × 2^(k/n)` Hz up to the rate / 8).
    pub low_hz: f32,
}

impl SpectrumSettings {
    /// 5 % damping, 1/6 octave, from 10 Hz.
    pub const fn new() -> Self {
        Self {
            damping: 0.05,
            bands_per_octave: 6,
            low_hz: 10.0,
        }
    }

    /// The band frequencies at `rate_hz` into `out`; how many (0 if the settings are invalid
    /// or the bands would not fit [`MAX_BANDS`]).
    pub fn bands(&self, rate_hz: f32, out: &mut [f32; MAX_BANDS]) -> usize {
        let mut f = [0.0f64; MAX_BANDS + 1];
        let n = srs::bands(
            u32::from(self.bands_per_octave),
            self.low_hz as f64,
            rate_hz as f64,
            &mut f,
        );
        if n > MAX_BANDS {
            return 0;
        }
        for (o, v) in out.iter_mut().zip(f.iter().take(n)) {
            *o = *v as f32;
        }
        n
    }

    /// Checks the settings at `rate_hz`, naming the one that cannot be computed
    /// (`srs-damping`, `srs-bands`, `srs-low`).
    pub fn check(&self, rate_hz: f32) -> Result<(), Error> {
        self.check_parameters()?;
        if self.bands(rate_hz, &mut [0.0; MAX_BANDS]) == 0 {
            return Err(Error::InvalidParameter {
                name: "srs-low",
                reason: "no band between it and rate / 8, or more than 96 (below rate / 8 by at most 16 octaves at 6 bands per octave, 8 at 12)",
            });
        }
        Ok(())
    }

    /// Damping, bands per octave and lowest band, whatever the rate.
    fn check_parameters(&self) -> Result<(), Error> {
        let invalid = |name, reason| Err(Error::InvalidParameter { name, reason });
        if !(self.damping >= 0.0 && self.damping <= 0.5) {
            return invalid("srs-damping", "must lie in [0, 0.5]");
        }
        if !matches!(self.bands_per_octave, 6 | 12) {
            return invalid("srs-bands", "must be 6 or 12");
        }
        if !(self.low_hz > 0.0 && self.low_hz.is_finite()) {
            return invalid("srs-low", "must be finite and > 0");
        }
        Ok(())
    }
}

impl Default for SpectrumSettings {
    fn default() -> Self {
        Self::new()
    }
}

/// One impact's spectra. Band `k` is at `1000 × 2^((first + k) / n)` Hz.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Spectrum {
    /// Bands held (`<= MAX_BANDS`).
    pub bands: u8,
    /// The first band's frequency, Hz.
    pub first_hz: f32,
    /// Bands per octave.
    pub bands_per_octave: u8,
    /// The oscillators' damping ratio.
    pub damping: f32,
    /// Maximax absolute acceleration, m/s², per band.
    pub srs_m_s2: [f32; MAX_BANDS],
    /// Pseudo-velocity, m/s, per band.
    pub pvss_m_s: [f32; MAX_BANDS],
    /// The enveloping half-sine: amplitude, m/s², and duration, s.
    pub half_sine: Option<(f32, f32)>,
    /// Stream indices of the window's first sample and just after its last.
    pub from_sample: u64,
    pub to_sample: u64,
}

impl Spectrum {
    /// Band `k`'s frequency, Hz, in f64: `1000 × 2^(j/n)` for the `j` of the first band.
    pub fn frequency_hz(&self, k: usize) -> f64 {
        let n = f64::from(self.bands_per_octave.max(1));
        let first = libm::round(n * libm::log2(self.first_hz as f64 / 1000.0));
        1000.0 * libm::exp2((first + k as f64) / n)
    }
}

/// What the spectra need besides the samples: each block's statistics and marks and the
/// bands' frequencies (some 5 KiB), kept in the analysis's workspace instead of on the stack
/// (on the board the analysis task runs on the one stack the interrupts share).
/// `Scratch::new()` is all zeros.
pub struct Scratch {
    stats: [Rest; STAT_BLOCKS],
    marks: [Mark; STAT_BLOCKS],
    freqs: [f32; MAX_BANDS],
}

impl Scratch {
    pub const fn new() -> Self {
        Self {
            stats: [Rest::ZERO; STAT_BLOCKS],
            marks: [Mark::ZERO; STAT_BLOCKS],
            freqs: [0.0; MAX_BANDS],
        }
    }
}

impl Default for Scratch {
    fn default() -> Self {
        Self::new()
    }
}

/// The spectra of the pulse `x[..len]` (m/s², baseline removed) sampled at `rate_hz`, which
/// it overwrites; `None` if the settings give no band at this rate.
pub fn spectrum(
    x: &mut [f32],
    len: usize,
    rate_hz: f32,
    settings: &SpectrumSettings,
    scratch: &mut Scratch,
) -> Option<Spectrum> {
    settings.check_parameters().ok()?;
    let Scratch {
        stats,
        marks,
        freqs,
    } = scratch;
    let n = settings.bands(rate_hz, freqs);
    if n == 0 {
        return None;
    }
    let mut out = Spectrum {
        bands: n as u8,
        first_hz: freqs.first().copied().unwrap_or(0.0),
        bands_per_octave: settings.bands_per_octave,
        damping: settings.damping,
        srs_m_s2: [0.0; MAX_BANDS],
        pvss_m_s: [0.0; MAX_BANDS],
        half_sine: None,
        from_sample: 0,
        to_sample: 0,
    };
    let mut len = len.min(x.len());
    let mut rate = rate_hz;
    let mut compensated: Option<(f32, core::ops::Range<usize>)> = None;
    let mut stats_rate = 0.0f32;
    // From the highest band down, halving the rate whenever a band falls to rate / 64.
    for k in (0..n).rev() {
        let f = freqs.get(k).copied().unwrap_or(0.0);
        while f <= rate / DECIMATE_BELOW {
            match halve(x, len) {
                Some(l) => {
                    len = l;
                    rate /= 2.0;
                }
                None => break,
            }
        }
        // Below the full rate: the compensated copy of this level, made once for its bands.
        if rate < rate_hz && compensated.as_ref().is_none_or(|(r, _)| *r != rate) {
            compensated = compensate(x, len).map(|range| (rate, range));
        }
        let input = match (&compensated, rate < rate_hz) {
            (Some((_, range)), true) => Input::Plain(x.get(range.clone()).unwrap_or(&[])),
            // No room for the copy: the same pre-emphasis, as the band goes.
            (None, true) => Input::Emphasised(x.get(..len).unwrap_or(&[])),
            (_, false) => Input::Plain(x.get(..len).unwrap_or(&[])),
        };
        if stats_rate != rate {
            rests(input, stats);
            stats_rate = rate;
        }
        let (s, p) = band(
            input,
            stats,
            marks,
            f,
            settings.damping,
            rate,
            rate_hz / rate,
        );
        if let (Some(a), Some(v)) = (out.srs_m_s2.get_mut(k), out.pvss_m_s.get_mut(k)) {
            (*a, *v) = (s, p);
        }
    }
    out.half_sine = srs::enveloping_half_sine_of(
        freqs
            .iter()
            .zip(&out.pvss_m_s)
            .take(n)
            .map(|(&f, &v)| (f as f64, v as f64)),
        settings.damping as f64,
    )
    .map(|h| (h.amplitude_m_s2 as f32, h.duration_s as f32))
    .filter(|(a, d)| a.is_finite() && d.is_finite());
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::signal::srs::{Oscillator, Response};

    #[test]
    fn the_half_band_filter_is_normalised_and_halving_keeps_a_constant() {
        let sum: f32 = HALF_BAND_CENTRE + 2.0 * HALF_BAND.iter().sum::<f32>();
        assert!((sum - 1.0).abs() < 1e-6, "{sum}");
        let mut x = [1.0f32; 400];
        let l = halve(&mut x, 400).unwrap();
        assert_eq!(l, 200 + SPAN + 1);
        // Away from both ends the constant passes unchanged.
        for v in &x[SPAN..195] {
            assert!((v - 1.0).abs() < 1e-5, "{v}");
        }
        // A short input is left alone.
        assert!(halve(&mut [1.0; 8], 8).is_none());
    }

    /// Halving in place gives every output as the filter over an untouched copy does (the
    /// edges' general sum), bit for bit, at every length around the edges' limits.
    #[test]
    fn halving_in_place_is_the_filter_over_a_copy() {
        let mut state = 7u32;
        for len in (0..120).chain([255, 256, 257, 1001]) {
            let x: Vec<f32> = (0..len)
                .map(|_| {
                    state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                    (state >> 8) as f32 / (1u32 << 24) as f32 - 0.5
                })
                .collect();
            let mut head = [0.0f32; 2 * SPAN];
            for (h, v) in head.iter_mut().zip(&x) {
                *h = *v;
            }
            let mut y = x.clone();
            match halve(&mut y, len) {
                Some(out) => {
                    assert_eq!(out, len / 2 + SPAN + 1);
                    for (i, v) in y.iter().take(out).enumerate() {
                        let want = halfband::edge(&x, &head, len, i);
                        assert_eq!(v.to_bits(), want.to_bits(), "{len} {i}");
                    }
                    assert_eq!(y[out..], x[out..], "{len}");
                }
                None => assert_eq!(y, x),
            }
        }
    }

    /// The pre-emphasised copy is `emphasised` at every output, bit for bit, at every length
    /// around the edges'.
    #[test]
    fn the_compensated_copy_is_the_pre_emphasis() {
        for len in 0..40usize {
            let mut x: Vec<f32> = (0..2 * len + 4).map(|k| (k as f32 * 0.37).sin()).collect();
            let src = x[..len].to_vec();
            assert_eq!(compensate(&mut x, len), Some(len..2 * len + 4));
            for n in 0..len + 4 {
                assert_eq!(x[len + n].to_bits(), emphasised(&src, n).to_bits(), "{len} {n}");
            }
            assert_eq!(x[..len], src[..]);
        }
        assert_eq!(compensate(&mut [0.0; 9], 3), None);
    }

    /// A half-sine of `amp` m/s² lasting `dur` s at `rate` with `pad` zeros before and after.
    fn half_sine(amp: f64, dur: f64, rate: f64, pad: usize) -> Vec<f64> {
        let n = (dur * rate) as usize;
        let mut v = vec![0.0; pad];
        v.extend((0..=n).map(|k| amp * libm::sin(core::f64::consts::PI * k as f64 / n as f64)));
        v.extend(core::iter::repeat_n(0.0, pad));
        v
    }

    extern crate std;
    use std::vec;
    use std::vec::Vec;

    std::thread_local! {
        /// Blocks [`band`]'s second pass computed, on this thread.
        pub(super) static EXACT: core::cell::Cell<usize> = const { core::cell::Cell::new(0) };
    }

    /// A noisy pulse: a half-sine of `amp` lasting `dur` s, a ringing tail and a step, with
    /// noise from a fixed generator.
    fn noisy(rate: f64, n: usize, seed: u64) -> Vec<f32> {
        let mut state = seed;
        let mut noise = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 40) as f32 / (1u64 << 24) as f32) - 0.5
        };
        (0..n)
            .map(|k| {
                let t = k as f64 / rate;
                let pulse = if (1e-4..2.1e-3).contains(&t) {
                    900.0 * libm::sin(core::f64::consts::PI * (t - 1e-4) / 2e-3)
                } else {
                    0.0
                };
                let ring = if t > 2.1e-3 {
                    300.0
                        * libm::exp(-(t - 2.1e-3) * 800.0)
                        * libm::sin(2.0 * core::f64::consts::PI * 3100.0 * t)
                } else {
                    0.0
                };
                let step = if t > 4e-3 { 40.0 } else { 0.0 };
                (pulse + ring + step) as f32 + 5.0 * noise()
            })
            .collect()
    }

    /// Skipping the blocks a bound keeps below the peaks found so far changes no bit of any
    /// band, plain or pre-emphasised, whatever the damping, against one pass computing every
    /// block (no marks); and it does skip.
    #[test]
    fn skipping_quiet_blocks_changes_no_bit() {
        let mut marks = [Mark::default(); STAT_BLOCKS];
        let (mut computed, mut blocks) = (0, 0);
        for (rate, n, seed) in [(2e5f32, 3000, 1), (5e5, 6000, 2), (1e5, 1500, 3)] {
            let x = noisy(rate as f64, n, seed);
            let mut freqs = [0.0f32; MAX_BANDS];
            let bands = SpectrumSettings::new().bands(rate, &mut freqs);
            for input in [Input::Plain(&x), Input::Emphasised(&x)] {
                let mut stats = [Rest::default(); STAT_BLOCKS];
                rests(input, &mut stats);
                for &f in freqs.iter().take(bands).filter(|&&f| f > rate / 64.0) {
                    for damping in [0.0, 0.05, 0.3] {
                        for (f, decimation) in [(f, 1.0), (f / 4.0, 2.0)] {
                            let fast =
                                band(input, &stats, &mut marks, f, damping, rate, decimation);
                            let all = band(input, &[], &mut [], f, damping, rate, decimation);
                            assert_eq!(fast.0.to_bits(), all.0.to_bits(), "{rate} {f} {damping}");
                            assert_eq!(fast.1.to_bits(), all.1.to_bits(), "{rate} {f} {damping}");
                            computed += EXACT.with(|q| q.replace(0));
                            blocks += input.len().div_ceil(BLOCK);
                        }
                    }
                }
            }
        }
        assert!(
            computed < blocks / 2,
            "{computed} of {blocks} blocks computed"
        );
    }

    /// Every band within 0.2 % of the f64 full-rate reference on half-sines of 65 µs to 5.5 ms
    /// (measured: 7.2e-5 at 1 ms, 1.2e-4 at 5.5 ms, 1.5e-3 at 65 µs, where the peak comes
    /// during the pulse).
    #[test]
    fn the_multirate_f32_spectra_follow_the_f64_reference() {
        for (rate, dur) in [(1e6, 1e-3), (5e5, 5.5e-3), (1e6, 65e-6)] {
            let x = half_sine(1000.0, dur, rate, 64);
            let mut buf: Vec<f32> = x.iter().map(|v| *v as f32).collect();
            let len = buf.len();
            let s = spectrum(
                &mut buf,
                len,
                rate as f32,
                &SpectrumSettings::new(),
                &mut Scratch::new(),
            )
            .unwrap();
            let mut worst: f64 = 0.0;
            let mut freqs = [0.0f64; MAX_BANDS];
            assert_eq!(srs::bands(6, 10.0, rate, &mut freqs), s.bands as usize);
            for (k, &f) in freqs.iter().enumerate().take(s.bands as usize) {
                assert!((s.frequency_hz(k) / f - 1.0).abs() < 1e-12);
                for (resp, got) in [
                    (Response::AbsoluteAcceleration, s.srs_m_s2[k]),
                    (Response::PseudoVelocity, s.pvss_m_s[k]),
                ] {
                    let want = Oscillator::<f64>::new(resp, f, 0.05, rate)
                        .unwrap()
                        .peak(x.iter().copied());
                    worst = worst.max((got as f64 / want - 1.0).abs());
                }
            }
            assert!(worst < 2e-3, "{rate} {dur}: {worst}");
        }
    }
}
