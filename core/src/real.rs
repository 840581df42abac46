//! The floating-point abstraction: every model and solver is generic over [`Real`] (`f32`, `f64`).
//!
//! Transcendental functions come from `libm` (the portable, correctly-rounded-or-close back-end
//! used across the embedded ecosystem). `f32` is the board's type (single-precision FPU on the
//! Cortex-M4F); `f64` is the host's reference type.

use core::fmt::Debug;
use core::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

/// A real number type the models and solvers can run on.
pub trait Real:
    Copy
    + Debug
    + Default
    + PartialEq
    + PartialOrd
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + SubAssign
    + MulAssign
    + 'static
{
    const ZERO: Self;
    const ONE: Self;
    const TWO: Self;
    const HALF: Self;
    const PI: Self;
    /// Machine epsilon (spacing of the type at 1.0).
    const EPSILON: Self;
    /// Largest finite value.
    const MAX: Self;
    /// Name used in reports: `"f32"` or `"f64"`.
    const NAME: &'static str;

    /// Converts from `f64`, rounding to nearest.
    fn from_f64(x: f64) -> Self;
    /// Widens (or copies) to `f64`.
    fn to_f64(self) -> f64;
    /// Converts a count exactly where the type can hold it.
    fn from_u32(n: u32) -> Self;

    fn abs(self) -> Self;
    fn sqrt(self) -> Self;
    fn cbrt(self) -> Self;
    fn powf(self, e: Self) -> Self;
    fn exp(self) -> Self;
    fn exp_m1(self) -> Self;
    fn ln(self) -> Self;
    fn ln_1p(self) -> Self;
    fn sin(self) -> Self;
    fn cos(self) -> Self;
    fn asin(self) -> Self;
    fn acos(self) -> Self;
    fn asinh(self) -> Self;
    fn sinh(self) -> Self;
    fn cosh(self) -> Self;
    fn tanh(self) -> Self;
    fn tgamma(self) -> Self;
    fn atan(self) -> Self;
    fn atan2(self, x: Self) -> Self;
    fn floor(self) -> Self;
    fn is_finite(self) -> bool;

    /// True for NaN.
    #[inline]
    #[allow(clippy::eq_op)]
    fn is_nan(self) -> bool {
        self != self
    }
    #[inline]
    fn max(self, o: Self) -> Self {
        if self >= o {
            self
        } else {
            o
        }
    }
    #[inline]
    fn min(self, o: Self) -> Self {
        if self <= o {
            self
        } else {
            o
        }
    }
    /// `x |x|^(e-1)`: the odd extension of `x^e` (smooth through zero for `e >= 1`).
    #[inline]
    fn signed_pow(self, e: Self) -> Self {
        let p = pow(self.abs(), e);
        if self < Self::ZERO {
            -p
        } else {
            p
        }
    }
}

macro_rules! impl_real {
    ($t:ty, $name:literal, $sqrt:path, $cbrt:path, $pow:path, $exp:path, $expm1:path, $ln:path,
     $ln1p:path, $sin:path, $cos:path, $asin:path, $acos:path, $asinh:path, $sinh:path, $cosh:path,
     $tanh:path, $tgamma:path, $atan:path, $atan2:path, $floor:path) => {
        impl Real for $t {
            const ZERO: Self = 0.0;
            const ONE: Self = 1.0;
            const TWO: Self = 2.0;
            const HALF: Self = 0.5;
            const PI: Self = core::f64::consts::PI as $t;
            const EPSILON: Self = <$t>::EPSILON;
            const MAX: Self = <$t>::MAX;
            const NAME: &'static str = $name;

            #[inline]
            fn from_f64(x: f64) -> Self {
                x as $t
            }
            #[inline]
            fn to_f64(self) -> f64 {
                self as f64
            }
            #[inline]
            fn from_u32(n: u32) -> Self {
                n as $t
            }
            #[inline]
            fn abs(self) -> Self {
                <$t>::abs(self)
            }
            #[inline]
            fn sqrt(self) -> Self {
                $sqrt(self)
            }
            #[inline]
            fn cbrt(self) -> Self {
                $cbrt(self)
            }
            #[inline]
            fn powf(self, e: Self) -> Self {
                $pow(self, e)
            }
            #[inline]
            fn exp(self) -> Self {
                $exp(self)
            }
            #[inline]
            fn exp_m1(self) -> Self {
                $expm1(self)
            }
            #[inline]
            fn ln(self) -> Self {
                $ln(self)
            }
            #[inline]
            fn ln_1p(self) -> Self {
                $ln1p(self)
            }
            #[inline]
            fn sin(self) -> Self {
                $sin(self)
            }
            #[inline]
            fn cos(self) -> Self {
                $cos(self)
            }
            #[inline]
            fn asin(self) -> Self {
                $asin(self)
            }
            #[inline]
            fn acos(self) -> Self {
                $acos(self)
            }
            #[inline]
            fn asinh(self) -> Self {
                $asinh(self)
            }
            #[inline]
            fn sinh(self) -> Self {
                $sinh(self)
            }
            #[inline]
            fn cosh(self) -> Self {
                $cosh(self)
            }
            #[inline]
            fn tanh(self) -> Self {
                $tanh(self)
            }
            #[inline]
            fn tgamma(self) -> Self {
                $tgamma(self)
            }
            #[inline]
            fn atan(self) -> Self {
                $atan(self)
            }
            #[inline]
            fn atan2(self, x: Self) -> Self {
                $atan2(self, x)
            }
            #[inline]
            fn floor(self) -> Self {
                $floor(self)
            }
            #[inline]
            fn is_finite(self) -> bool {
                <$t>::is_finite(self)
            }
        }
    };
}

impl_real!(
    f32,
    "f32",
    // The FPU's vsqrt on the Cortex-M4F: 3 instructions + 14 cycles against libm's 48
    // instructions, the same bits (both correctly rounded); `impact bench m4` measures both.
    fpu_sqrt,
    libm::cbrtf,
    libm::powf,
    libm::expf,
    libm::expm1f,
    libm::logf,
    libm::log1pf,
    libm::sinf,
    libm::cosf,
    libm::asinf,
    libm::acosf,
    libm::asinhf,
    libm::sinhf,
    libm::coshf,
    libm::tanhf,
    libm::tgammaf,
    libm::atanf,
    libm::atan2f,
    libm::floorf
);
impl_real!(
    f64,
    "f64",
    libm::sqrt,
    libm::cbrt,
    libm::pow,
    libm::exp,
    libm::expm1,
    libm::log,
    libm::log1p,
    libm::sin,
    libm::cos,
    libm::asin,
    libm::acos,
    libm::asinh,
    libm::sinh,
    libm::cosh,
    libm::tanh,
    libm::tgamma,
    libm::atan,
    libm::atan2,
    libm::floor
);

/// `x^e` with the exponents the contact laws use most (1/2, 1, 3/2, 2, 3) done by multiply and
/// `sqrt`: several times cheaper than `powf`, and exact where `powf` would round. `x >= 0`.
#[inline]
pub fn pow<R: Real>(x: R, e: R) -> R {
    if e == R::ONE {
        x
    } else if e == R::HALF {
        x.sqrt()
    } else if e == R::from_f64(1.5) {
        x * x.sqrt()
    } else if e == R::TWO {
        x * x
    } else if e == R::from_f64(3.0) {
        x * x * x
    } else if x == R::ZERO {
        x
    } else {
        x.powf(e)
    }
}

/// Square root by the FPU's `vsqrt.f32` on the Cortex-M4F (14 cycles); `libm::sqrtf`
/// elsewhere. Both are IEEE correctly rounded, so both give the same bits for every input.
///
/// The instruction sits in a two-instruction function written in `global_asm!`: Rust's
/// inline `asm!` refuses single-precision registers on `thumbv7em-none-eabihf` (its `vfp2`
/// feature implies double precision, which the M4F lacks), and the hard-float ABI passes the
/// argument and the result in `s0`.
#[inline]
#[allow(unsafe_code)]
pub fn fpu_sqrt(x: f32) -> f32 {
    #[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
    {
        extern "C" {
            fn impact_core_vsqrt_f32(x: f32) -> f32;
        }
        // SAFETY: the function below reads s0, writes s0 and returns; it touches no memory.
        unsafe { impact_core_vsqrt_f32(x) }
    }
    #[cfg(not(all(target_arch = "arm", target_abi = "eabihf")))]
    {
        libm::sqrtf(x)
    }
}

#[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
#[allow(unsafe_code)]
mod vsqrt {
    core::arch::global_asm!(
        ".syntax unified",
        ".thumb",
        ".fpu fpv4-sp-d16",
        ".section .text.impact_core_vsqrt_f32,\"ax\",%progbits",
        ".global impact_core_vsqrt_f32",
        ".type impact_core_vsqrt_f32,%function",
        ".thumb_func",
        "impact_core_vsqrt_f32:",
        "vsqrt.f32 s0, s0",
        "bx lr",
        ".size impact_core_vsqrt_f32, . - impact_core_vsqrt_f32",
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pow_fast_paths_agree_with_powf() {
        for x in [0.0f64, 1e-300, 0.3, 2.0, 7.5e8] {
            for e in [0.5, 1.0, 1.5, 2.0, 3.0, 0.4, 2.7] {
                let want = if x == 0.0 { 0.0 } else { libm::pow(x, e) };
                let got = pow(x, e);
                assert!(
                    (got - want).abs() <= 4.0 * f64::EPSILON * want,
                    "{x}^{e}: {got} vs {want}"
                );
            }
        }
    }

    #[test]
    fn signed_pow_is_odd_and_exact_at_zero() {
        assert_eq!(0.0f64.signed_pow(1.5), 0.0);
        assert_eq!((-4.0f64).signed_pow(1.5), -8.0);
        assert_eq!(4.0f64.signed_pow(1.5), 8.0);
    }
}
