//! Numbers as a person reads them (the table) and settings in their own precision.

pub use impact_io::channel::sig;

/// An f32 setting as the f64 its decimal digits name (`0.05`, not `0.05000000074505806`).
pub fn shortest(x: f32) -> f64 {
    x.to_string().parse().unwrap_or(f64::from(x))
}

/// A quantity as a person reads it: four significant digits, times and lengths with a prefix
/// that keeps the number in [1, 1000) (`5.521 ms`, `3.275 mm`), other units plain between
/// 1e-3 and 1e5 and in exponent form beyond (`1.071e5 m/s²`).
pub fn human(v: f64, unit: &str) -> String {
    let digits = |x: f64| {
        if x == 0.0 || !x.is_finite() {
            return format!("{x}");
        }
        let decimals = (3 - x.abs().log10().floor() as i32).clamp(0, 6) as usize;
        format!("{x:.decimals$}")
    };
    let prefixed = |prefixes: &[(f64, &str)]| {
        let (scale, p) = prefixes
            .iter()
            .copied()
            .find(|(scale, _)| v.abs() * scale >= 1.0)
            .unwrap_or(*prefixes.last().unwrap());
        format!("{} {p}", digits(v * scale))
    };
    match unit {
        "s" if v.abs() < 1000.0 => prefixed(&[(1.0, "s"), (1e3, "ms"), (1e6, "µs"), (1e9, "ns")]),
        "m" if v.abs() < 1000.0 => prefixed(&[(1.0, "m"), (1e3, "mm"), (1e6, "µm"), (1e9, "nm")]),
        _ if v == 0.0 || (1e-3..1e5).contains(&v.abs()) => format!("{} {unit}", digits(v)),
        _ => format!("{v:.3e} {unit}"),
    }
}

/// A number as a CSV cell, in the digits it holds: an f32 field (the core's) in the shortest
/// digits that give it back (`7.569964`, not `7.5699639320373535e0`), any other in an f64's;
/// plain between 1e-4 and 1e7, in exponent form beyond (`1.5e-7`).
pub fn number(v: f64) -> String {
    let f = v as f32;
    let plain = v == 0.0 || (1e-4..1e7).contains(&v.abs());
    match (f64::from(f) == v, plain) {
        (true, true) => format!("{f}"),
        (true, false) => format!("{f:e}"),
        (false, true) => format!("{v}"),
        (false, false) => format!("{v:e}"),
    }
}

#[cfg(test)]
mod tests {
    use super::{human, number};

    #[test]
    fn quantities_read_as_a_person_reads_them() {
        assert_eq!(human(96.873, "m/s²"), "96.87 m/s²");
        assert_eq!(human(9.878, "g"), "9.878 g");
        assert_eq!(human(0.0055215, "s"), "5.522 ms");
        assert_eq!(human(3.2748e-3, "m"), "3.275 mm");
        assert_eq!(human(2.5e-7, "s"), "250.0 ns");
        assert_eq!(human(1.0714e5, "m/s²"), "1.071e5 m/s²");
        assert_eq!(human(-1.5, "m/s"), "-1.500 m/s");
        assert_eq!(human(0.0, "J"), "0 J");
    }

    #[test]
    fn numbers_keep_the_digits_they_hold() {
        assert_eq!(number(f64::from(7.569964f32)), "7.569964");
        assert_eq!(number(f64::from(1.5e-7f32)), "1.5e-7");
        assert_eq!(number(f64::from(30579.8f32)), "30579.8");
        assert_eq!(number(0.005002401375770569), "0.005002401375770569");
        assert_eq!(number(0.0), "0");
        // The digits read back to the same f32.
        for x in [0.1f32, 1.0 / 3.0, 9.80665, 2.0e-5, 123456.79, 3.4e38] {
            assert_eq!(number(f64::from(x)).parse::<f32>().unwrap(), x);
        }
    }
}
