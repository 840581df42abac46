//! `e^y` in f32 for the fits' inner loops: an f32 polynomial on the Cortex-M4's FPU (the FPU
//! has no exponential of its own), ~40 instructions inline, within `8.4e-8 + |t| 2^-24` of
//! the exact value relative (`t = y log2 e`; 3e-7 and less where `e^y > 0.02`).
//!
//! `e^y = 2^t`, split as `2^i · 2^f` (`i = floor t`, `f` in `[0, 1)`): `2^f` by a degree-6
//! polynomial (Horner; fitted for relative error, within 8.4e-8 of `2^f` over `[0, 1)`
//! evaluated in f32, each step a multiply-add rounded twice, as the host rounds it too),
//! `2^i` put straight into the exponent bits. The rounding of `t` adds `|t| · 2^-24`
//! relative (1.2e-7 at `t = -2`; 2e-6 at `t = -33`, where `e^y` is below 1e-10 and counts for
//! nothing in a fit's sums). Below `2^-126` the result is 0 (no subnormals); above `2^128`,
//! infinity; NaN stays NaN.
//!
//! Against `libm::expf` (within an ulp, 55 instructions a call on the M4, `impact bench m4`'s
//! maths table): the nonlinear fit's exponent search takes `x^n = e^(n ln x)` at every point
//! for every exponent it tries (about ten tries of up to 512 points), most of its cost; this
//! one brings the board's three fits from 2.70 M to 2.40 M instructions.

/// `log2 e`.
const LOG2_E: f32 = core::f32::consts::LOG2_E;

/// `2^f` on `[0, 1)`, lowest power first. (Fitted for the least largest relative error:
/// the linear one is not `ln 2`, though close.)
#[allow(clippy::approx_constant)]
const P: [f32; 7] = [
    1.0,
    0.693_147,
    0.240_229_83,
    0.055_483_34,
    0.009_678_841,
    0.001_243_969,
    0.000_217_022_46,
];

/// `e^y` (see the module's accuracy).
#[inline]
pub fn exp(y: f32) -> f32 {
    let t = y * LOG2_E;
    // The usual case tested first: two comparisons (NaN fails both) where three were.
    if !(-126.0..128.0).contains(&t) {
        return if t.is_nan() {
            t
        } else if t < 0.0 {
            0.0
        } else {
            f32::INFINITY
        };
    }
    // floor(t) in [-126, 127]: `as` truncates towards zero.
    let mut i = t as i32;
    if (i as f32) > t {
        i -= 1;
    }
    let f = t - i as f32;
    let mut p = P[6];
    for &c in P[..6].iter().rev() {
        p = p * f + c;
    }
    // 2^i for i in [-126, 127]: a normal number's exponent bits.
    let scale = f32::from_bits(((i + 127) as u32) << 23);
    p * scale
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn within_its_bound_where_a_fit_reads_it_and_zero_infinity_nan_at_the_ends() {
        // Dense over the range a fit uses (n ln X with X in (0, 1], n in [1, 2.5]) and a
        // little beyond.
        let mut worst = 0.0f64;
        let mut y = -20.0f32;
        while y <= 5.0 {
            let want = libm::exp(y as f64);
            let got = exp(y) as f64;
            let t = (y as f64 * core::f64::consts::LOG2_E).abs();
            // The polynomial's 8.4e-8 and the result's rounding (2 f32::EPSILON, with room),
            // plus the rounding of t.
            let tolerance = 2.0 * f32::EPSILON as f64 + t * f32::EPSILON as f64 / 2.0;
            let rel = (got / want - 1.0).abs();
            assert!(rel <= tolerance, "e^{y}: {got} vs {want} ({rel:e})");
            worst = worst.max(rel / tolerance);
            y += 1.0e-3;
        }
        // (The bound is reached to 0.7 of it: a correctly rounded exp would not come near.)
        assert!(worst > 0.5, "the bound is not vacuous: {worst}");
        assert_eq!(exp(0.0), 1.0);
        assert_eq!(exp(f32::NEG_INFINITY), 0.0);
        assert_eq!(exp(-200.0), 0.0);
        assert_eq!(exp(200.0), f32::INFINITY);
        assert!(exp(f32::NAN).is_nan());
        // A negative t just off an integer: the split's floor (a truncation would be 5e-4
        // off there, which the sweep above catches too).
        assert!((exp(-0.7) as f64 / libm::exp(-0.7) - 1.0).abs() < 3e-7);
    }
}
