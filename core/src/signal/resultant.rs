//! The resultant of a three-axis sensor's axes in counts, `sqrt(x² + y² + z²)` rounded by
//! exact integer arithmetic: the same value on the board, in the emulator and on the host.

/// `sqrt(x² + y² + z²)` in counts, rounded to the nearest integer (a tie cannot occur: the
/// square of a half-integer is not an integer). Never negative; saturates at `i16::MAX`
/// (only reached beyond 18 918 counts per axis).
pub fn resultant_counts(x: i16, y: i16, z: i16) -> i16 {
    let sq = |v: i16| u64::from(v.unsigned_abs()) * u64::from(v.unsigned_abs());
    // At most 3 · 32768² = 3 · 2³⁰ < 2³²: always fits a u32.
    let n = sq(x) + sq(y) + sq(z);
    let n = u32::try_from(n).unwrap_or(u32::MAX);
    let r = isqrt(n);
    // Round: up when n lies beyond r² + r (the midpoint (r + ½)² = r² + r + ¼).
    let r = if n - r * r > r { r + 1 } else { r };
    i16::try_from(r).unwrap_or(i16::MAX)
}

/// `floor(sqrt(n))`, digit by digit (16 steps of shifts and compares, no division).
fn isqrt(n: u32) -> u32 {
    let (mut rem, mut root) = (n, 0u32);
    let mut bit = 1u32 << 30;
    while bit > rem {
        bit >>= 2;
    }
    while bit != 0 {
        if rem >= root + bit {
            rem -= root + bit;
            root = (root >> 1) + bit;
        } else {
            root >>= 1;
        }
        bit >>= 2;
    }
    root
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rounds_to_the_nearest_count_over_the_whole_range() {
        for (x, y, z) in [
            (0, 0, 0),
            (3, 4, 0),
            (1, 1, 1),
            (-4096, -4096, -4096),
            (4095, -17, 2000),
            (i16::MIN, i16::MIN, i16::MIN),
            (i16::MAX, 0, 0),
            (-1, 0, 0),
        ] {
            let exact = ((x as f64).powi(2) + (y as f64).powi(2) + (z as f64).powi(2)).sqrt();
            let want = exact.round().min(i16::MAX as f64) as i16;
            assert_eq!(resultant_counts(x, y, z), want, "({x}, {y}, {z})");
        }
        let mut seed = 1u32;
        for _ in 0..100_000 {
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            let (x, y, z) = (
                seed as i16 >> 3,
                (seed >> 16) as i16 >> 3,
                (seed >> 7) as i16 >> 3,
            );
            let exact = ((x as f64).powi(2) + (y as f64).powi(2) + (z as f64).powi(2)).sqrt();
            assert_eq!(resultant_counts(x, y, z), exact.round() as i16);
        }
    }
}
