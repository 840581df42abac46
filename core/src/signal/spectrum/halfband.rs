//! Halving a pulse's rate in place: a 23-tap half-band FIR, once per octave below rate / 64.

/// Half-band low-pass (windowed sinc, Kaiser β = 8, 23 taps, unit gain at 0 Hz): the centre
/// tap and the taps at odd offsets `±1, ±3, …, ±11` (even offsets are 0). Flat to 1.2e-4 up
/// to an eighth of the rate, below 8.7e-5 from three eighths on.
pub(super) const HALF_BAND_CENTRE: f32 = 0.499_976_5;
pub(super) const HALF_BAND: [f32; 6] = [
    0.308_586_44,
    -0.079_928_82,
    0.028_203_26,
    -0.008_360_258,
    0.001_578_801_5,
    -0.000_067_676_17,
];
/// A band at or below rate / this is computed at a halved rate (32 to 64 times its
/// frequency).
pub(super) const DECIMATE_BELOW: f32 = 64.0;

/// Half the FIR's span, input samples.
pub(super) const SPAN: usize = 11;

/// Halves the rate of `x[..len]` in place: `y[i] = Σ h_k x[2i - SPAN + k]` (delayed, so
/// nothing before the first sample is lost and the filter's tail is kept); returns the new
/// length `len / 2 + SPAN + 1`, if below `len` (shorter inputs are left alone and `None`
/// returned).
#[inline(never)]
pub(super) fn halve(x: &mut [f32], len: usize) -> Option<usize> {
    let len = len.min(x.len());
    let out_len = len / 2 + SPAN + 1;
    if out_len >= len {
        return None;
    }
    // The first inputs are overwritten before their last use: read them from a copy.
    let mut head = [0.0f32; 2 * SPAN];
    for (h, v) in head.iter_mut().zip(x.iter()) {
        *h = *v;
    }
    // Outputs whose 23 inputs lie past the copied head and before the end are one slice
    // each (`2 i - 2 SPAN >= 2 SPAN`, `2 i < len`). In order of `i`: output `i` overwrites
    // an input only outputs before it read.
    let inner_to = len.div_ceil(2).min(out_len);
    let inner_from = (2 * SPAN).min(inner_to);
    for i in 0..inner_from {
        let acc = edge(x, &head, len, i);
        if let Some(slot) = x.get_mut(i) {
            *slot = acc;
        }
    }
    // One at a time until a run's outputs lie before its window (`i + RUN <= 2 i - 2 SPAN`),
    // then runs of `RUN`, then the rest one at a time.
    let singles = (2 * SPAN + RUN).max(inner_from).min(inner_to);
    for i in inner_from..singles {
        inner(x, i);
    }
    let mut i = singles;
    while i + RUN <= inner_to {
        let first = 2 * i - 2 * SPAN;
        let Some((done, rest)) = x.split_at_mut_checked(first) else {
            break;
        };
        let (Some(out), Some(window)) = (
            done.get_mut(i..i + RUN)
                .and_then(|o| <&mut [f32; RUN]>::try_from(o).ok()),
            rest.get(..WINDOW)
                .and_then(|w| <&[f32; WINDOW]>::try_from(w).ok()),
        ) else {
            break;
        };
        run(window, out);
        i += RUN;
    }
    for i in i..inner_to {
        inner(x, i);
    }
    for i in inner_to..out_len {
        let acc = edge(x, &head, len, i);
        if let Some(slot) = x.get_mut(i) {
            *slot = acc;
        }
    }
    Some(out_len)
}

/// Inner output `i` of [`halve`] (its 23 inputs one slice, past the copied head and before
/// the end).
#[inline(always)]
fn inner(x: &mut [f32], i: usize) {
    let first = 2 * i - 2 * SPAN;
    let Some(w) = x
        .get(first..first + 2 * SPAN + 1)
        .and_then(|w| <&[f32; 2 * SPAN + 1]>::try_from(w).ok())
    else {
        return;
    };
    let mut acc = HALF_BAND_CENTRE * w[SPAN];
    for (k, h) in HALF_BAND.iter().enumerate() {
        acc += h * (w[SPAN - 1 - 2 * k] + w[SPAN + 1 + 2 * k]);
    }
    if let Some(slot) = x.get_mut(i) {
        *slot = acc;
    }
}

/// Outputs a [`run`] computes at a time.
const RUN: usize = 8;
/// The inputs a run reads: `2 RUN - 2 + 2 SPAN + 1`.
const WINDOW: usize = 2 * RUN + 2 * SPAN - 1;

/// `RUN` consecutive inner outputs of [`halve`] from the inputs of their windows (the first
/// output's window starts at `window[0]`, each next one two samples on): the same sums in
/// the same order as one output at a time, with each input loaded once (`window` and `out`
/// do not overlap: the compiler keeps the inputs in registers across the stores). The sum is
/// [`inner`]'s, spelt out on `window`: through a shared function over each output's 23-input
/// slice the compiler shares fewer loads (16 k instructions more on the seed's spectra).
#[inline(always)]
fn run(window: &[f32; WINDOW], out: &mut [f32; RUN]) {
    for (j, slot) in out.iter_mut().enumerate() {
        let c = 2 * j + SPAN;
        let mut acc = HALF_BAND_CENTRE * window[c];
        for (k, h) in HALF_BAND.iter().enumerate() {
            acc += h * (window[c - 1 - 2 * k] + window[c + 1 + 2 * k]);
        }
        *slot = acc;
    }
}

/// Output `i` of [`halve`] near either end: inputs before the first or past `len` are 0, the
/// first `2 SPAN` read from `head`.
pub(super) fn edge(x: &[f32], head: &[f32; 2 * SPAN], len: usize, i: usize) -> f32 {
    let centre = 2 * i as isize - SPAN as isize;
    let at = |j: isize| -> f32 {
        if j < 0 || j as usize >= len {
            0.0
        } else if (j as usize) < head.len() {
            head.get(j as usize).copied().unwrap_or(0.0)
        } else {
            x.get(j as usize).copied().unwrap_or(0.0)
        }
    };
    let mut acc = HALF_BAND_CENTRE * at(centre);
    for (k, h) in HALF_BAND.iter().enumerate() {
        let d = 2 * k as isize + 1;
        acc += h * (at(centre - d) + at(centre + d));
    }
    acc
}
