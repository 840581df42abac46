//! The maths back-ends' error on the host: each `m4-bench` maths case against its f64
//! reference.

/// A maths function compared: name, f64 reference, input range, the back-ends that offer it.
pub(super) type MathCase = (
    &'static str,
    fn(f64) -> f64,
    (f32, f32),
    &'static [&'static str],
);

/// The maths functions the models use, compared across back-ends.
pub(super) fn maths() -> Vec<MathCase> {
    vec![
        (
            "sqrt",
            f64::sqrt,
            (1e-4, 1e3),
            &["libm", "micromath", "vsqrt"],
        ),
        ("exp", f64::exp, (-10.0, 10.0), &["libm", "micromath"]),
        ("ln", f64::ln, (1e-4, 1e3), &["libm", "micromath"]),
        (
            "pow1.5",
            |x| x.powf(1.5),
            (1e-4, 1e3),
            &["libm", "micromath", "vsqrt"],
        ),
        ("sin", f64::sin, (-3.0, 3.0), &["libm", "micromath"]),
        ("cos", f64::cos, (-3.0, 3.0), &["libm", "micromath"]),
        ("asin", f64::asin, (-0.999, 0.999), &["libm", "micromath"]),
        ("acos", f64::acos, (-0.999, 0.999), &["libm", "micromath"]),
    ]
}

/// The host's copy of a back-end function (the same code as on the M4: f32 arithmetic is
/// IEEE on both).
pub(super) fn host_math(op: &str, backend: &str) -> Option<fn(f32) -> f32> {
    use micromath::F32Ext;
    Some(match (op, backend) {
        ("sqrt", "libm" | "vsqrt") => libm::sqrtf,
        ("sqrt", "micromath") => |x| F32Ext::sqrt(x),
        ("exp", "libm") => libm::expf,
        ("exp", "micromath") => |x| F32Ext::exp(x),
        ("ln", "libm") => libm::logf,
        ("ln", "micromath") => |x| F32Ext::ln(x),
        ("pow1.5", "libm") => |x| libm::powf(x, 1.5),
        ("pow1.5", "vsqrt") => |x| x * libm::sqrtf(x),
        ("pow1.5", "micromath") => |x| F32Ext::powf(x, 1.5),
        ("sin", "libm") => libm::sinf,
        ("sin", "micromath") => |x| F32Ext::sin(x),
        ("cos", "libm") => libm::cosf,
        ("cos", "micromath") => |x| F32Ext::cos(x),
        ("asin", "libm") => libm::asinf,
        ("asin", "micromath") => |x| F32Ext::asin(x),
        ("acos", "libm") => libm::acosf,
        ("acos", "micromath") => |x| F32Ext::acos(x),
        _ => return None,
    })
}

/// Largest relative error of `f` against `reference` over 2^16 points of `range` (relative
/// to max(|exact|, 1e-3) so that zeros of sin and cos do not dominate).
pub(super) fn math_error(f: fn(f32) -> f32, reference: fn(f64) -> f64, range: (f32, f32)) -> f64 {
    let n = 1 << 16;
    (0..=n)
        .map(|k| {
            let x = range.0 + (range.1 - range.0) * (k as f32 / n as f32);
            let exact = reference(x as f64);
            ((f(x) as f64 - exact) / exact.abs().max(1e-3)).abs()
        })
        .fold(0.0, f64::max)
}
