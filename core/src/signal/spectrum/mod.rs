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
//! (`skim`: 2.25 instructions a sample on the M4), marking each block with its state and a
//! [`Bound`] on both responses over it; then both responses (`tops`: 15.25 instructions a
//! sample on the M4), keeping each block's largest `|y|` without a branch, only for the
//! blocks whose bound reaches the largest `|y|` found so far (on the seed's impact 12 to 19
//! of 102 blocks a band). The result is the same, bit for
//! bit, as computing every block; only the block that holds a response's peak is run again,
//! for the samples around it.

use super::srs::{self};
use crate::error::Error;

mod band;
mod bound;
mod emphasis;
mod halfband;
mod skim;
mod tops;

use band::*;
use bound::*;
use emphasis::*;
use halfband::*;
/// The board's self-test of its hand-written recursion (`m4-bench selftest`): the first
/// length of `x` at which the spectra's first pass (each band's recursion alone, in a `VLDM`
/// loop on the M4) differs by a bit from the portable loop, from a few states and poles;
/// `None` if none does (always on the host, where both are the portable loop).
pub use skim::mismatch as skim_mismatch;
/// The board's self-test of its second hand-written loop (`m4-bench selftest`): the first
/// length of `x` at which both responses over a block (each one's largest `|y|` kept, in a
/// `VLDM` loop on the M4) differ by a bit from the portable loop, in the state or a largest
/// `|y|`, from a few filters, states and largest values so far; `None` if none does
/// (always on the host).
pub use tops::mismatch as tops_mismatch;

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
    /// Lowest band, Hz (bands are `1000 × 2^(k/n)` Hz up to the highest, at most the rate / 8).
    pub low_hz: f32,
    /// Highest band, Hz: the bands stop at the lower of it and the rate / 8; `None`, at the
    /// rate / 8. A specification's range (MIL-STD-810's SRS to 10 kHz, say) need not pay for
    /// the octaves above it: on the seed's impact at 500 kS/s the three octaves above 8 kHz
    /// are run at the full rate, half of the spectra's work. Each band below it is the same,
    /// bit for bit, as without it (`a_highest_band_keeps_the_bands_below_it`).
    pub high_hz: Option<f32>,
}

impl SpectrumSettings {
    /// 5 % damping, 1/6 octave, from 10 Hz.
    pub const fn new() -> Self {
        Self {
            damping: 0.05,
            bands_per_octave: 6,
            low_hz: 10.0,
            high_hz: None,
        }
    }

    /// The band frequencies at `rate_hz` into `out`, from the lowest band up to the lower of
    /// the highest and `rate_hz / 8`; how many (0 if the settings are invalid,
    /// more than 12 bands an octave among them, or the bands would not fit [`MAX_BANDS`]). [`srs::bands`]'s, in `f32`: each band's
    /// `2^(j/n)` as `2^q 2^(r/n)` (`j = q n + r`), one `exp2` in `f64` per band of an octave
    /// rather than per band (on the M4 `f64` is software, some 1 500 instructions an
    /// `exp2`), and `j`'s `q` and `r` counted in integers (the f64 `floor(j / n)` and
    /// `j - q n` are exact for these, so the same numbers, without a soft-float division,
    /// floor and conversion a band); the same `f32` frequencies
    /// (`the_bands_are_the_references`).
    pub fn bands(&self, rate_hz: f32, out: &mut [f32; MAX_BANDS]) -> usize {
        let per = usize::from(self.bands_per_octave);
        let (low, rate) = (self.low_hz as f64, rate_hz as f64);
        if !((1..=12).contains(&per) && low > 0.0 && rate.is_finite() && rate > 0.0) {
            return 0;
        }
        let n = per as f64;
        let first = libm::ceil(n * libm::log2(low / 1000.0) - 1e-9);
        let mut steps = [0.0f64; 12];
        for (r, step) in steps.iter_mut().enumerate().take(per) {
            *step = libm::exp2(r as f64 / n);
        }
        // The first band's `j = q n + r` (`as` saturates: a `q` beyond `i32` gives 0 or
        // infinity below, as the f64 `q as i32` did).
        let (first, per_i) = (first as i64, per as i64);
        let (mut q, mut r) = (first.div_euclid(per_i), first.rem_euclid(per_i) as usize);
        let top = srs::top_hz(rate, self.high_hz.map(f64::from));
        let mut count = 0;
        loop {
            let Some(&step) = steps.get(r) else {
                return 0;
            };
            let f = 1000.0 * libm::scalbn(step, q.clamp(i32::MIN.into(), i32::MAX.into()) as i32);
            if !(f <= top) {
                return count;
            }
            match out.get_mut(count) {
                Some(slot) => *slot = f as f32,
                // (More than fit.)
                None => return 0,
            }
            count += 1;
            r += 1;
            if r == per {
                (q, r) = (q.saturating_add(1), 0);
            }
        }
    }

    /// Checks the settings at `rate_hz`, naming the one that cannot be computed
    /// (`srs-damping`, `srs-bands`, `srs-low`, `srs-high`).
    pub fn check(&self, rate_hz: f32) -> Result<(), Error> {
        self.check_parameters()?;
        let mut freqs = [0.0; MAX_BANDS];
        if self.bands(rate_hz, &mut freqs) != 0 {
            return Ok(());
        }
        let unbounded = Self {
            high_hz: None,
            ..*self
        };
        if self.high_hz.is_some() && unbounded.bands(rate_hz, &mut freqs) != 0 {
            return Err(Error::InvalidParameter {
                name: "srs-high",
                reason: "below the first band at or above the lowest band",
            });
        }
        Err(Error::InvalidParameter {
            name: "srs-low",
            reason: "no band between it and rate / 8, or more than 96 (below rate / 8 by at most 16 octaves at 6 bands per octave, 8 at 12)",
        })
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
        if self.high_hz.is_some_and(|h| !(h > 0.0 && h.is_finite())) {
            return invalid("srs-high", "must be finite and > 0");
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
/// bands' frequencies (some 3.5 KiB), kept in the analysis's workspace instead of on the stack
/// (on the board the analysis task runs on the one stack the interrupts share).
/// `Scratch::new()` is all zeros.
///
/// The frequencies are a scene's, not an impact's: kept with the settings and rate they are
/// for, and made again only when either changes (a decimated capture's rate, another scene),
/// so an impact does not pay [`SpectrumSettings::bands`]'s `f64` (software on the M4, some
/// 33 000 instructions) again; [`Scratch::prepare`] makes them before the first impact.
pub struct Scratch {
    stats: [Rest; STAT_BLOCKS],
    marks: [Mark; STAT_BLOCKS],
    freqs: [f32; MAX_BANDS],
    /// The settings and the rate's bits `freqs` holds the bands of, and how many. All zeros
    /// (the zero settings at rate 0, no band) is a true entry: `bands` gives those none.
    freqs_for: (SpectrumSettings, u32, usize),
}

impl Scratch {
    pub const fn new() -> Self {
        Self {
            stats: [Rest::ZERO; STAT_BLOCKS],
            marks: [Mark::ZERO; STAT_BLOCKS],
            freqs: [0.0; MAX_BANDS],
            freqs_for: (
                SpectrumSettings {
                    damping: 0.0,
                    bands_per_octave: 0,
                    low_hz: 0.0,
                    high_hz: None,
                },
                0,
                0,
            ),
        }
    }

    /// Makes the band frequencies of `settings` at `rate_hz` now (a scene's configuration),
    /// so the first impact finds them made.
    pub fn prepare(&mut self, settings: &SpectrumSettings, rate_hz: f32) {
        self.bands(settings, rate_hz);
    }

    /// The band frequencies of `settings` at `rate_hz` in `freqs`, and how many: those held
    /// if they are for the same settings and rate (the same bits), else made again.
    fn bands(&mut self, settings: &SpectrumSettings, rate_hz: f32) -> usize {
        let key = (*settings, rate_hz.to_bits());
        match self.freqs_for {
            (s, r, n) if (s, r) == key => n,
            _ => {
                let n = settings.bands(rate_hz, &mut self.freqs);
                self.freqs_for = (key.0, key.1, n);
                n
            }
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
    let n = scratch.bands(settings, rate_hz);
    let Scratch {
        stats,
        marks,
        freqs,
        ..
    } = scratch;
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
mod tests;
