//! The spectra's tests: the multirate `f32` spectra against the `f64` reference, the
//! skipped blocks changing no bit, and each piece against its definition.

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
        // (Stale samples past `len`, as the workspace holds: read as zeros.)
        let mut y = x.clone();
        y.extend(core::iter::repeat_n(7.0, 40));
        match halve(&mut y, len) {
            Some(out) => {
                assert_eq!(out, len / 2 + SPAN + 1);
                for (i, v) in y.iter().take(out).enumerate() {
                    let want = halfband::edge(&x, &head, len, i);
                    assert_eq!(v.to_bits(), want.to_bits(), "{len} {i}");
                }
                assert_eq!(y[out..len], x[out..], "{len}");
                // And the edges' sum is the filter's: a constant in, the constant out
                // away from both ends.
                if len > 200 {
                    let ones = vec![1.0f32; len];
                    let want = halfband::edge(&ones, &[1.0; 2 * SPAN], len, len / 4);
                    assert!((want - 1.0).abs() < 1e-5, "{want}");
                }
            }
            None => assert_eq!(y[..len], x[..]),
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
            assert_eq!(
                x[len + n].to_bits(),
                emphasised(&src, n).to_bits(),
                "{len} {n}"
            );
        }
        assert_eq!(x[..len], src[..]);
    }
    assert_eq!(compensate(&mut [0.0; 9], 3), None);
}

/// The bands in `f32` are [`srs::bands`]'s, cast, for every lowest band, highest band and
/// rate: the same frequencies, as many, and none where they would not fit.
#[test]
fn the_bands_are_the_references() {
    let mut checked = 0;
    let highs = [
        None,
        Some(5.0f32),
        Some(1000.0),
        Some(8000.0),
        Some(1e4),
        Some(1e9),
    ];
    for (per, high) in [6u8, 12].into_iter().flat_map(|p| highs.map(|h| (p, h))) {
        for low in [
            1e-3f32, 0.7, 1.0, 10.0, 11.2, 33.0, 100.0, 999.0, 1000.0, 5e4,
        ] {
            for rate in [1e3f32, 2e4, 1e5, 5e5, 1e6, 2.4e6, 1e8] {
                let s = SpectrumSettings {
                    damping: 0.05,
                    bands_per_octave: per,
                    low_hz: low,
                    high_hz: high,
                };
                let mut f = [0.0f64; MAX_BANDS + 1];
                let (low64, high64) = (low as f64, high.map(f64::from));
                let want = srs::bands(u32::from(per), low64, high64, rate as f64, &mut f);
                let mut got = [0.0f32; MAX_BANDS];
                let n = s.bands(rate, &mut got);
                let case = (per, low, high, rate);
                if want > MAX_BANDS {
                    assert_eq!(n, 0, "{case:?}");
                    continue;
                }
                assert_eq!(n, want, "{case:?}");
                for k in 0..n {
                    assert_eq!(got[k].to_bits(), (f[k] as f32).to_bits(), "{case:?} {k}");
                    // None above the highest band.
                    assert!(high.is_none_or(|h| got[k] <= h), "{case:?} {k}");
                    checked += 1;
                }
            }
        }
    }
    assert!(checked > 8000, "{checked}");
    // Every band a lowest band and rate can reach (the frequency depends on its index `j`
    // alone), as `srs::bands` computes it.
    for per in [6i32, 12] {
        let n = f64::from(per);
        for j in -2000i32..2000 {
            let want = (1000.0 * libm::exp2(f64::from(j) / n)) as f32;
            let q = libm::floor(f64::from(j) / n);
            let r = (f64::from(j) - q * n) as i32;
            let got = (1000.0 * libm::scalbn(libm::exp2(f64::from(r) / n), q as i32)) as f32;
            assert_eq!(got.to_bits(), want.to_bits(), "{per} {j}");
        }
    }
    // What cannot be had gives no band, never a panic.
    for (per, low, rate) in [
        (13u8, 10.0f32, 5e5f32),
        (0, 10.0, 5e5),
        (6, f32::NAN, 5e5),
        (6, f32::INFINITY, 5e5),
        (6, 1e-40, 5e5),
        (6, -1.0, 5e5),
        (6, 10.0, f32::INFINITY),
        (6, 10.0, 0.0),
    ] {
        let s = SpectrumSettings {
            damping: 0.05,
            bands_per_octave: per,
            low_hz: low,
            high_hz: None,
        };
        assert_eq!(
            s.bands(rate, &mut [0.0; MAX_BANDS]),
            0,
            "{per} {low} {rate}"
        );
    }
}

/// The impulse response's norm in closed form is at least the filter's own over a block
/// and one sample more (run in f64), and within 0.2 % of the latter, for every band and
/// damping the spectra use.
#[test]
fn the_impulse_norm_bounds_the_filters_own() {
    use crate::signal::srs::Oscillator;
    // Every rate a band runs at, 8 to 64 samples a period (the bands at the full rate and
    // the halved levels alike), finely; the bound's own limit, 140; every damping by 0.01.
    let periods = (0..=192)
        .map(|k| 8.0 * 2f32.powf(k as f32 / 64.0))
        .chain([140.0]);
    let mut checked = 0;
    for per_period in periods {
        let (f, rate) = (1000.0f32, 1000.0 * per_period);
        for damping in (0..=50).map(|k| k as f32 / 100.0) {
            let Some(pair) = Oscillator::<f32>::pair(f, damping, rate) else {
                continue;
            };
            for o in pair {
                let [a1, a2] = o.a.map(f64::from);
                let [b0, b1, b2] = o.b.map(f64::from);
                let (mut w1, mut w2) = (0.0f64, 0.0f64);
                let mut sums = [0.0f64; 2];
                for k in 0..=BLOCK {
                    let w = f64::from(u8::from(k == 0)) - a1 * w1 - a2 * w2;
                    let y = b0 * w + b1 * w1 + b2 * w2;
                    if k < BLOCK {
                        sums[0] += y * y;
                    }
                    sums[1] += y * y;
                    (w2, w1) = (w1, w);
                }
                // (The closed form holds one sample more than the block.)
                let [block, more] = sums.map(f64::sqrt);
                let got = f64::from(bound::impulse_norm(o.a, o.b));
                assert!(
                    got >= block && got >= more && got <= more * 1.002,
                    "{per_period} samples a period, ζ {damping}: {got} against {block}, {more}"
                );
                checked += 1;
            }
        }
    }
    assert!(checked > 19_000, "{checked}");
    // Beyond the limit there is no bound to take it.
    let [acc, pv] = Oscillator::<f32>::pair(1000.0, 0.05, 1000.0 * 200.0).unwrap();
    assert!(Bound::new(acc.a, [acc.b, pv.b]).is_none());
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
    let mut noise = crate::testing::uniform(seed);
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
                        let fast = band(input, &stats, &mut marks, f, damping, rate, decimation);
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
        assert_eq!(
            srs::bands(6, 10.0, None, rate, &mut freqs),
            s.bands as usize
        );
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

/// One scratch kept over impacts of other rates and settings (a decimated capture, another
/// scene) gives each the spectra a fresh scratch gives it, to the bit: its bands are made
/// again whenever the rate or the settings change.
#[test]
fn a_scratch_kept_over_rates_and_settings_gives_a_fresh_ones_spectra() {
    let twelve = SpectrumSettings {
        bands_per_octave: 12,
        low_hz: 1000.0,
        ..SpectrumSettings::new()
    };
    let from_100 = SpectrumSettings {
        low_hz: 100.0,
        ..SpectrumSettings::new()
    };
    let six_from_1000 = SpectrumSettings {
        bands_per_octave: 6,
        ..twelve
    };
    let to_10k = SpectrumSettings {
        high_hz: Some(1e4),
        ..SpectrumSettings::new()
    };
    // Each change alone: the rate, the lowest band, the bands an octave, the highest band.
    let cases = [
        (1e6, to_10k),
        (1e6, SpectrumSettings::new()),
        (1e6, to_10k),
        (1e6, SpectrumSettings::new()),
        (1e6, from_100),
        (5e5, from_100),
        (5e5, SpectrumSettings::new()),
        (1e6, SpectrumSettings::new()),
        (1e6, twelve),
        (1e6, six_from_1000),
        (1e6, from_100),
        (2.5e5, from_100),
    ];
    let x = half_sine(1000.0, 1e-3, 1e6, 64);
    let run = |rate: f64, settings: &SpectrumSettings, scratch: &mut Scratch| {
        let mut buf: Vec<f32> = x.iter().map(|v| *v as f32).collect();
        let len = buf.len();
        spectrum(&mut buf, len, rate as f32, settings, scratch).unwrap()
    };
    let mut kept = Scratch::new();
    kept.prepare(&SpectrumSettings::new(), 1e6);
    for (rate, settings) in &cases {
        let (got, want) = (
            run(*rate, settings, &mut kept),
            run(*rate, settings, &mut Scratch::new()),
        );
        assert_eq!(got.bands, want.bands, "{rate} {settings:?}");
        assert_eq!(got.first_hz.to_bits(), want.first_hz.to_bits());
        assert_eq!(
            got.half_sine.map(|(a, d)| (a.to_bits(), d.to_bits())),
            want.half_sine.map(|(a, d)| (a.to_bits(), d.to_bits()))
        );
        for k in 0..usize::from(want.bands) {
            assert_eq!(got.srs_m_s2[k].to_bits(), want.srs_m_s2[k].to_bits());
            assert_eq!(got.pvss_m_s[k].to_bits(), want.pvss_m_s[k].to_bits());
        }
    }
}

/// A highest band drops the bands above it and changes none below, to the bit (each band's
/// rate and input are the same: the halvings follow the band, not the top), at rates where
/// the highest band is at the full rate, decimated, or above the rate / 8; and a highest
/// band below the lowest is refused by name, as one that is not a positive number.
#[test]
fn a_highest_band_keeps_the_bands_below_it() {
    let x = half_sine(1000.0, 3e-3, 5e5, 64);
    for rate in [5e5f32, 1e5, 2e4] {
        let run = |high_hz| {
            let mut buf: Vec<f32> = x.iter().map(|v| *v as f32).collect();
            let len = buf.len();
            let settings = SpectrumSettings {
                high_hz,
                ..SpectrumSettings::new()
            };
            spectrum(&mut buf, len, rate, &settings, &mut Scratch::new()).unwrap()
        };
        let all = run(None);
        for high in [20.0f32, 1000.0, 1e4, 8000.0, 1e9] {
            let some = run(Some(high));
            let top = all.frequency_hz(usize::from(some.bands) - 1);
            assert!(top <= f64::from(high) * 1.000_001, "{rate} {high}");
            let above = usize::from(some.bands);
            assert!(
                above == usize::from(all.bands) || all.frequency_hz(above) > f64::from(high),
                "{rate} {high}: a band at or below the highest was dropped"
            );
            assert_eq!(some.first_hz.to_bits(), all.first_hz.to_bits());
            for k in 0..above {
                assert_eq!(
                    some.srs_m_s2[k].to_bits(),
                    all.srs_m_s2[k].to_bits(),
                    "{rate} {high} {k}"
                );
                assert_eq!(
                    some.pvss_m_s[k].to_bits(),
                    all.pvss_m_s[k].to_bits(),
                    "{rate} {high} {k}"
                );
            }
        }
    }
    let named = |high_hz| match (SpectrumSettings {
        high_hz: Some(high_hz),
        ..SpectrumSettings::new()
    })
    .check(5e5)
    {
        Err(Error::InvalidParameter { name, .. }) => name,
        other => panic!("{high_hz}: {other:?}"),
    };
    for bad in [5.0f32, 0.0, -1.0, f32::NAN, f32::INFINITY] {
        assert_eq!(named(bad), "srs-high", "{bad}");
    }
    let fine = SpectrumSettings {
        high_hz: Some(1e4),
        ..SpectrumSettings::new()
    };
    assert_eq!(fine.check(5e5), Ok(()));
}
