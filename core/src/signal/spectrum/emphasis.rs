//! On a decimated signal: the pre-emphasis that undoes the ramp-invariant filter's linear
//! interpolation (`sinc²`), and the peak taken between samples.

use super::*;

/// The pre-emphasis that undoes the ramp-invariant filter's linear interpolation of a
/// decimated signal: `sinc²(x)`, `x = π f T`, inverted to `x⁶` by
/// `1 + 2a (1 - cos 2x) + 2b (1 - cos 4x)`, `a = 23/180`, `b = -1/90` (0.01 % at `f T = 1/8`).
pub(super) const EMPHASIS: [f32; 3] = [1.0 + 23.0 / 90.0 - 1.0 / 45.0, -23.0 / 180.0, 1.0 / 90.0];

/// The pre-emphasis of one output from its five inputs, `w[2]` the centre.
#[inline(always)]
fn five([w0, w1, w2, w3, w4]: [f32; 5]) -> f32 {
    EMPHASIS[0] * w2 + EMPHASIS[1] * (w1 + w3) + EMPHASIS[2] * (w0 + w4)
}

/// Output `n` of the pre-emphasis over `x[..len]`: input `n - 2` (outputs run from two
/// samples before the first input to two after the last, `len + 4` of them).
#[inline]
pub(super) fn emphasised(x: &[f32], n: usize) -> f32 {
    // Inside: the five inputs are one slice.
    if let Some(w) = n
        .checked_sub(4)
        .and_then(|a| x.get(a..a + 5))
        .and_then(|w| <&[f32; 5]>::try_from(w).ok())
    {
        return five(*w);
    }
    let at = |j: isize| {
        if j < 0 {
            0.0
        } else {
            x.get(j as usize).copied().unwrap_or(0.0)
        }
    };
    let c = n as isize - 2;
    five([at(c - 2), at(c - 1), at(c), at(c + 1), at(c + 2)])
}

/// The pre-emphasis of `x[..len]` into `x[len..2 len + 4]`; the range written, or `None`
/// without room.
#[inline(never)]
pub(super) fn compensate(x: &mut [f32], len: usize) -> Option<core::ops::Range<usize>> {
    let (src, dst) = x.split_at_mut(len.min(x.len()));
    let dst = dst.get_mut(..src.len() + 4)?;
    // Inside (outputs 4 to len - 1), runs of `RUN` outputs from their `RUN + 4` inputs (each
    // loaded once, not five times), then five inputs at a time; the edges as `emphasised`
    // takes them (the same operations).
    let inside = dst.get_mut(4..src.len()).unwrap_or(&mut []);
    let mut runs = inside.chunks_exact_mut(RUN);
    let mut from = 0;
    for out in &mut runs {
        if let (Ok(out), Some(Ok(window))) = (
            <&mut [f32; RUN]>::try_from(out),
            src.get(from..from + RUN + 4)
                .map(<&[f32; RUN + 4]>::try_from),
        ) {
            run(window, out);
        }
        from += RUN;
    }
    for (slot, w) in runs
        .into_remainder()
        .iter_mut()
        .zip(src.get(from..).unwrap_or(&[]).windows(5))
    {
        if let Ok(&w) = <&[f32; 5]>::try_from(w) {
            *slot = five(w);
        }
    }
    let outputs = dst.len();
    for n in (0..4.min(outputs)).chain(src.len().max(4)..outputs) {
        if let Some(slot) = dst.get_mut(n) {
            *slot = emphasised(src, n);
        }
    }
    Some(len..2 * len + 4)
}

/// Outputs a [`run`] computes at a time.
const RUN: usize = 8;

/// `RUN` consecutive inside outputs of [`compensate`] from their inputs (the same
/// operations as one at a time; `window` and `out` do not overlap, so each input is loaded
/// once).
#[inline(always)]
fn run(window: &[f32; RUN + 4], out: &mut [f32; RUN]) {
    for (j, slot) in out.iter_mut().enumerate() {
        let w = |k: usize| window.get(j + k).copied().unwrap_or(0.0);
        *slot = five([w(0), w(1), w(2), w(3), w(4)]);
    }
}

/// The peak between samples of one response from its largest sampled value `at` and the
/// outputs `before` and `after` it, as the full-rate filter would sample it (`decimation`
/// full-rate samples to one here): never below the sampled peak, nor above it by more
/// than 9 %.
pub(super) fn between(before: f32, at: f32, after: f32, decimation: f32) -> f32 {
    let best = at.abs();
    // |y| near its peak: the signs such that the largest is positive.
    let sign = if at < 0.0 { -1.0 } else { 1.0 };
    let (before, at, after) = (sign * before, sign * at, sign * after);
    // The sinusoid `A cos(φ m + ψ)` through the three samples (its frequency from them too):
    // exact for any oscillation, where the sampled peak of one at 8 samples a period is up
    // to 7.6 % low.
    let cos = (before + after) / (2.0 * at);
    if cos.is_finite() && cos > 0.0 && cos < 1.0 {
        let sin = crate::real::fpu_sqrt(1.0 - cos * cos);
        let slope = (after - before) / (2.0 * sin);
        let amplitude = crate::real::fpu_sqrt(at * at + slope * slope);
        // Its crest `crest` samples from the largest; the full-rate filter samples the
        // sinusoid at multiples of `1 / decimation` from there.
        let phi = libm::atan2f(sin, cos);
        let crest = libm::atanf(slope / at) / phi;
        let miss = crest - libm::roundf(crest * decimation) / decimation;
        let sampled = amplitude * srs::sin_cos(phi * miss).1;
        if sampled.is_finite() {
            return sampled.max(best).min(best * 1.09);
        }
    }
    best
}
