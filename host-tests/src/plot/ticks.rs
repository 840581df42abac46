//! Tick labels: numbers in engineering form; a log axis's ticks (its decades numbered).

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

/// A log axis's label: [`tick`], with `k` from 10^3 (`1k`, `2k`, `10k`).
pub(crate) fn log_tick(v: f64) -> String {
    if (1e3..1e4).contains(&v.abs()) {
        format!("{}k", tick(v / 1e3))
    } else {
        tick(v)
    }
}

/// A log axis's ticks over `lo..hi` (both > 0) drawn `length_px` long, labels at least
/// `spacing_px` apart: `(labelled, light)`. The decades are labelled (1, 10, 100, 1k …), every
/// second (or n-th) one where they would crowd; with fewer than two decades in the range, 2
/// and 5 times them too when that makes three labels or more, else round numbers (1, 2 or 5
/// × 10^k apart: 80, 100, 120 …). The light ticks are the multiples 1–9 of each decade.
pub(crate) fn log_ticks(lo: f64, hi: f64, length_px: f64, spacing_px: f64) -> (Vec<f64>, Vec<f64>) {
    if !(lo > 0.0 && hi > lo && lo.is_finite() && hi.is_finite()) {
        return (Vec::new(), Vec::new());
    }
    let px_per_decade = length_px / (hi / lo).log10();
    // The multiples `mult` of each decade from lo's to hi's that lie in the range.
    let within = |mult: &[f64]| -> Vec<f64> {
        let (k0, k1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
        (k0..=k1)
            .flat_map(|k| mult.iter().map(move |m| m * 10f64.powi(k)))
            // A hair of slack: 10^k computed is not always the literal.
            .filter(|v| *v >= lo * (1.0 - 1e-9) && *v <= hi * (1.0 + 1e-9))
            .collect()
    };
    let all = within(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]);
    let decades = within(&[1.0]);
    let labelled = if decades.len() >= 2 {
        decades
    } else {
        let multiples = within(&[1.0, 2.0, 5.0]);
        if multiples.len() >= 3 {
            multiples
        } else {
            linear_ticks(lo, hi, 6)
                .into_iter()
                .filter(|v| *v >= lo && *v <= hi)
                .collect()
        }
    };
    // Every n-th label (from one at a multiple of n) until they stand apart.
    let apart = |v: &[f64]| {
        v.windows(2)
            .all(|w| (w[1] / w[0]).log10() * px_per_decade >= spacing_px)
    };
    let mut shown = labelled.clone();
    for n in 2..=labelled.len().max(2) {
        if apart(&shown) {
            break;
        }
        // Decades by their exponent (1, 100, 10k …); round numbers by their place.
        let decade = |v: f64| (v.log10().round() as i64).rem_euclid(n as i64) == 0;
        shown = if labelled.iter().all(|v| v.log10().fract().abs() < 1e-9) {
            labelled.iter().copied().filter(|v| decade(*v)).collect()
        } else {
            labelled.iter().copied().step_by(n).collect()
        };
    }
    let light = all.into_iter().filter(|v| !shown.contains(v)).collect();
    (shown, light)
}

/// Ticks at 1, 2 or 5 × 10^k covering `[lo, hi]`, about `n` of them.
pub(crate) fn linear_ticks(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    let span = (hi - lo).abs().max(f64::MIN_POSITIVE);
    let raw = span / n as f64;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * mag);
    let mut t = (lo / step).ceil() * step;
    let mut out = Vec::new();
    while t <= hi + step * 1e-9 && out.len() < 50 {
        out.push(if t.abs() < step * 1e-9 { 0.0 } else { t });
        t += step;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::{log_tick, log_ticks, tick};

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

    #[test]
    fn log_axes_number_their_decades_and_never_crowd() {
        // Compared to 1e-12 (10^k computed is not always the literal).
        let same = |got: &[f64], want: &[f64]| {
            got.len() == want.len()
                && got
                    .iter()
                    .zip(want)
                    .all(|(g, w)| (g / w - 1.0).abs() < 1e-12)
        };
        // Four decades over 250 px: each decade labelled, the multiples light.
        let (labelled, light) = log_ticks(8.0, 125_000.0, 250.0, 18.0);
        assert!(same(&labelled, &[10.0, 100.0, 1000.0, 10_000.0, 100_000.0]));
        assert!(light.contains(&20.0) && light.contains(&90_000.0) && !light.contains(&7.0));
        let names: Vec<String> = labelled.iter().map(|v| log_tick(*v)).collect();
        assert_eq!(names, ["10", "100", "1k", "10k", "100k"]);
        // Under two decades in the range: 2 and 5 times them too.
        let (labelled, _) = log_ticks(0.8, 8.5, 250.0, 18.0);
        assert!(same(&labelled, &[1.0, 2.0, 5.0]), "{labelled:?}");
        let (labelled, _) = log_ticks(0.04, 8.5, 250.0, 18.0);
        assert!(same(&labelled, &[0.1, 1.0]), "{labelled:?}");
        // No decade in it, or 2 and 5 times one too few: round numbers.
        let (labelled, _) = log_ticks(150.0, 700.0, 250.0, 18.0);
        assert!(
            same(&labelled, &[200.0, 300.0, 400.0, 500.0, 600.0, 700.0]),
            "{labelled:?}"
        );
        let (labelled, _) = log_ticks(72.0, 181.0, 250.0, 18.0);
        assert!(
            same(&labelled, &[80.0, 100.0, 120.0, 140.0, 160.0, 180.0]),
            "{labelled:?}"
        );
        let (labelled, _) = log_ticks(2.1, 4.5, 250.0, 18.0);
        assert!(same(&labelled, &[2.5, 3.0, 3.5, 4.0, 4.5]), "{labelled:?}");
        let (labelled, _) = log_ticks(1.05, 1.64, 250.0, 18.0);
        assert!(
            same(&labelled, &[1.1, 1.2, 1.3, 1.4, 1.5, 1.6]),
            "{labelled:?}"
        );
        // Crowded round numbers: every second one.
        let (labelled, _) = log_ticks(150.0, 700.0, 100.0, 18.0);
        assert!(same(&labelled, &[200.0, 400.0, 600.0]), "{labelled:?}");
        let (labelled, _) = log_ticks(30.0, 800.0, 250.0, 18.0);
        assert!(
            same(&labelled, &[50.0, 100.0, 200.0, 500.0]),
            "{labelled:?}"
        );
        // Twelve decades in 100 px: every third one, at least 18 px apart.
        let (labelled, _) = log_ticks(1e-6, 1e6, 100.0, 18.0);
        assert!(
            same(&labelled, &[1e-6, 1e-3, 1.0, 1e3, 1e6]),
            "{labelled:?}"
        );
        // Nothing to tick on a range that is none.
        assert_eq!(log_ticks(0.0, 1.0, 100.0, 18.0), (vec![], vec![]));
        assert_eq!(log_tick(2000.0), "2k");
        assert_eq!(log_tick(0.05), "0.05");
    }
}
