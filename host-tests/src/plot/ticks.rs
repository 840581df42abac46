//! Tick labels: numbers in engineering form.

/// A tick's label in engineering form: four significant digits at most, no trailing zeros,
/// an SI prefix from 10^4 up and below 10^-3 (`100k`, `1.5M`, `250µ`; not `100000.0`).
pub(crate) fn tick(v: f64) -> String {
    let a = v.abs();
    if a <= 1e-12 || !a.is_finite() {
        return "0".into();
    }
    let (scale, prefix) = match a {
        a if a >= 1e9 => (1e-9, "G"),
        a if a >= 1e6 => (1e-6, "M"),
        a if a >= 1e4 => (1e-3, "k"),
        a if a >= 1e-3 => (1.0, ""),
        a if a >= 1e-6 => (1e6, "µ"),
        _ => (1e9, "n"),
    };
    let x = v * scale;
    let decimals = (3 - x.abs().log10().floor() as i32).clamp(0, 6) as usize;
    let s = format!("{x:.decimals$}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        &s
    };
    format!("{s}{prefix}")
}

#[cfg(test)]
mod tests {
    use super::tick;

    #[test]
    fn ticks_read_as_engineering_numbers() {
        for (v, want) in [
            (0.0, "0"),
            (100_000.0, "100k"),
            (12_500.0, "12.5k"),
            (1.5e6, "1.5M"),
            (20.0, "20"),
            (-0.5, "-0.5"),
            (0.0015, "0.0015"),
            (2.5e-4, "250µ"),
            (1234.0, "1234"),
        ] {
            assert_eq!(tick(v), want, "{v}");
        }
    }
}
