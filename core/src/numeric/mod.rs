//! Numerical building blocks with no physics in them: bracketed roots and minima, quadrature,
//! the fits' `e^y` in f32.

pub mod dopri;
pub mod exp;
pub mod quad;
pub mod roots;

/// The greater of `x` and `y` as libm's `fmaxf` gives it (IEEE 754-2008 `maxNum`: a NaN is
/// passed over; of two equal values, `x`), inline: the Cortex-M4's FPU has no `VMAXNM`, so
/// `f32::max` is a call there (≈ 15 instructions where this is 3).
#[inline(always)]
pub fn fmax(x: f32, y: f32) -> f32 {
    if x.is_nan() || x < y {
        y
    } else {
        x
    }
}

/// The lesser of `x` and `y` as libm's `fminf` gives it (`minNum`: a NaN is passed over; of
/// two equal values, `y`), inline ([`fmax`]).
#[inline(always)]
pub fn fmin(x: f32, y: f32) -> f32 {
    if y.is_nan() || x < y {
        x
    } else {
        y
    }
}

#[cfg(test)]
mod tests {
    use super::{fmax, fmin};

    /// The same bits as `f32::max`/`f32::min` (libm's `fmaxf`/`fminf` on the board) on
    /// every pair of special and ordinary values, signed zeros and NaNs included.
    #[test]
    fn fmax_and_fmin_are_f32s_max_and_min() {
        let v = [
            f32::NAN,
            f32::NEG_INFINITY,
            -1.5,
            -0.0,
            0.0,
            1e-45,
            2.0,
            f32::MAX,
            f32::INFINITY,
        ];
        for x in v {
            for y in v {
                let same =
                    |a: f32, b: f32| a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan());
                assert!(same(fmax(x, y), libm::fmaxf(x, y)), "max {x} {y}");
                assert!(same(fmin(x, y), libm::fminf(x, y)), "min {x} {y}");
                if x != 0.0 || y != 0.0 {
                    assert!(same(fmax(x, y), x.max(y)), "max {x} {y}");
                    assert!(same(fmin(x, y), x.min(y)), "min {x} {y}");
                }
            }
        }
    }
}
