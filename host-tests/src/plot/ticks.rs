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

/// The SI prefixes a label takes: the factor that scales a value to it, the prefix, and the
/// least magnitude that takes it (`k` from 10^4, none from 10^-3: no `m`, which would read as
/// metres).
const PREFIXES: [(f64, &str, f64); 6] = [
    (1e-9, "G", 1e9),
    (1e-6, "M", 1e6),
    (1e-3, "k", 1e4),
    (1.0, "", 1e-3),
    (1e6, "µ", 1e-6),
    (1e9, "n", 0.0),
];

/// The labels plotters puts on a linear axis at most (its default, which the panels set).
pub(crate) const LABELS: usize = 11;

/// One format for every label of an axis, chosen from all of them: never `-500µ` next to
/// `-0.001`, nor `0.5` next to `1`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum AxisFormat {
    /// Every label scaled by `factor` and written with `decimals` decimals and `prefix`
    /// (`-1000µ, -500µ, 0, 500µ`; `0.5, 1.0, 1.5`); zero is `0`.
    Fixed {
        factor: f64,
        prefix: &'static str,
        decimals: usize,
    },
    /// A log axis's decades from 1 up, in engineering form: `1, 10, 100, 1k, 10k, 100k, 1M`.
    Engineering,
    /// A log axis's decades from 10^-3 to 10^3, as decimals: `0.001, 0.01, 0.1, 1, 10`.
    Decimal,
    /// A log axis's decades reaching below 10^-3, or from below 1 to 10^4 and more, as powers
    /// of ten: `10⁻⁶, 10⁻⁵ … 10²`.
    Powers,
}

impl AxisFormat {
    /// The format of a linear axis over `lo..hi`: the labels plotters puts there ([`LABELS`]).
    pub(crate) fn linear(lo: f64, hi: f64) -> Self {
        use plotters::coord::ranged1d::{BoldPoints, Ranged};
        if !(lo.is_finite() && hi.is_finite()) {
            return Self::of(&[]);
        }
        let axis = plotters::coord::types::RangedCoordf64::from(lo..hi);
        Self::of(&axis.key_points(BoldPoints(LABELS)))
    }

    /// The one format for `ticks`: the prefix the largest takes (the next smaller one where
    /// that needs more than 3 decimals and the largest stays under 10^4 in it: `500µ`, not
    /// `0.0005`), and the fewest decimals that write every tick exactly (to a thousandth of
    /// their least gap: their step).
    pub(crate) fn of(ticks: &[f64]) -> Self {
        let ticks: Vec<f64> = ticks.iter().copied().filter(|v| v.is_finite()).collect();
        let largest = ticks.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let step = ticks
            .windows(2)
            .map(|w| (w[1] - w[0]).abs())
            .filter(|d| *d > 0.0)
            .fold(f64::INFINITY, f64::min);
        let step = if step.is_finite() { step } else { largest };
        if largest <= 0.0 || !largest.is_finite() {
            return AxisFormat::Fixed {
                factor: 1.0,
                prefix: "",
                decimals: 0,
            };
        }
        let decimals = |factor: f64| {
            let slack = step * factor * 1e-3;
            (0..9)
                .find(|&d| {
                    let p = 10f64.powi(d);
                    ticks
                        .iter()
                        .all(|v| ((v * factor * p).round() / p - v * factor).abs() <= slack)
                })
                .unwrap_or(9) as usize
        };
        let mut k = PREFIXES
            .iter()
            .position(|p| largest >= p.2)
            .unwrap_or(PREFIXES.len() - 1);
        if decimals(PREFIXES[k].0) > 3
            && k + 1 < PREFIXES.len()
            && largest * PREFIXES[k + 1].0 < 1e4
        {
            k += 1;
        }
        let (factor, prefix, _) = PREFIXES[k];
        AxisFormat::Fixed {
            factor,
            prefix,
            decimals: decimals(factor),
        }
    }

    /// The format of a log axis labelled at `ticks` ([`log_ticks`]): its decades as
    /// [`AxisFormat::Engineering`], [`AxisFormat::Decimal`] or [`AxisFormat::Powers`] by their
    /// range; other round numbers (a range under two decades) as a linear axis's.
    pub(crate) fn log(ticks: &[f64]) -> Self {
        let decade = |v: &f64| *v > 0.0 && (v.log10() - v.log10().round()).abs() < 1e-9;
        if ticks.is_empty() || !ticks.iter().all(decade) {
            return Self::of(ticks);
        }
        let (lo, hi) = ticks.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), v| {
            (lo.min(*v), hi.max(*v))
        });
        if lo >= 1.0 - 1e-9 {
            AxisFormat::Engineering
        } else if lo >= 1e-3 * (1.0 - 1e-9) && hi < 1e4 {
            AxisFormat::Decimal
        } else {
            AxisFormat::Powers
        }
    }

    /// `v`'s label in this format.
    pub(crate) fn label(&self, v: f64) -> String {
        match *self {
            AxisFormat::Fixed {
                factor,
                prefix,
                decimals,
            } => {
                let x = v * factor;
                if !x.is_finite() || x.abs() < 0.5 * 10f64.powi(-(decimals as i32)) {
                    return "0".into();
                }
                format!("{x:.decimals$}{prefix}")
            }
            AxisFormat::Engineering => log_tick(v),
            AxisFormat::Decimal => tick(v),
            AxisFormat::Powers => power_of_ten(v),
        }
    }
}

/// `v` as a power of ten, the exponent in superscript (`10⁻⁴`, `10⁰`, `10³`).
fn power_of_ten(v: f64) -> String {
    const DIGITS: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];
    let e = v.abs().log10().round() as i64;
    let mut s = String::from(if v < 0.0 { "-10" } else { "10" });
    if e < 0 {
        s.push('⁻');
    }
    for d in e.unsigned_abs().to_string().bytes() {
        s.push(DIGITS[usize::from(d - b'0')]);
    }
    s
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
pub(crate) mod tests {
    use super::{log_tick, log_ticks, tick, AxisFormat};

    /// Whether `labels` (one axis's) share one format: every one but `0` with the same
    /// suffix (SI prefix, or a power of ten's superscript exponent) and the same number of
    /// decimals; a log axis's decades in engineering form (`1, 10, 100, 1k, 10k`) pass too.
    pub(crate) fn one_format(labels: &[String]) -> bool {
        let numbers: Vec<&str> = labels
            .iter()
            .map(String::as_str)
            .filter(|l| *l != "0")
            .collect();
        let split = |l: &str| {
            let body = l.trim_start_matches('-');
            let digits = body
                .find(|c: char| !(c.is_ascii_digit() || c == '.'))
                .unwrap_or(body.len());
            let (number, suffix) = body.split_at(digits);
            let decimals = number.find('.').map_or(0, |d| number.len() - d - 1);
            (decimals, suffix.to_string(), number.to_string())
        };
        let all_same = numbers
            .windows(2)
            .all(|w| (split(w[0]).0, split(w[0]).1) == (split(w[1]).0, split(w[1]).1));
        // Powers of ten: `10` and a superscript exponent each.
        let powers = numbers.iter().all(|l| {
            l.trim_start_matches('-').starts_with("10")
                && l.chars().any(|c| "⁰¹²³⁴⁵⁶⁷⁸⁹".contains(c))
        });
        // Decades in engineering form: 1, 10 or 100 and no decimals, `k`, `M` or `G` or none.
        let decades = numbers.iter().all(|l| {
            let (decimals, suffix, number) = split(l);
            decimals == 0
                && ["1", "10", "100"].contains(&number.as_str())
                && ["", "k", "M", "G"].contains(&suffix.as_str())
        });
        all_same || powers || decades
    }

    /// `ticks` labelled in their one format.
    fn labels(ticks: &[f64]) -> Vec<String> {
        let f = AxisFormat::of(ticks);
        ticks.iter().map(|v| f.label(*v)).collect()
    }

    #[test]
    fn an_axis_labels_its_ticks_in_one_format() {
        // One prefix, one number of decimals, chosen from every tick (one by one, `tick`
        // wrote -0.001 next to -500µ, 1 next to 0.5, 5000 next to 10k).
        for (ticks, want) in [
            (
                &[-0.001, -0.0005, 0.0, 0.0005][..],
                &["-1000µ", "-500µ", "0", "500µ"][..],
            ),
            (&[0.0, 0.5, 1.0, 1.5], &["0", "0.5", "1.0", "1.5"]),
            (
                &[0.0, 5000.0, 10_000.0, 15_000.0],
                &["0", "5k", "10k", "15k"],
            ),
            (&[0.1, 0.15, 0.2], &["0.10", "0.15", "0.20"]),
            (&[-0.02, -0.01, 0.0, 0.01], &["-0.02", "-0.01", "0", "0.01"]),
            (
                &[0.0, 0.005, 0.01, 0.015],
                &["0", "0.005", "0.010", "0.015"],
            ),
            (&[1e6, 1.5e6, 2e6], &["1.0M", "1.5M", "2.0M"]),
            (&[0.5, 0.5001, 0.5002], &["0.5000", "0.5001", "0.5002"]),
            // Plotters' ticks carry float noise: 0.1 + 0.2, and a zero that is none.
            (
                &[-0.1, 5.551115123125783e-17, 0.1, 0.30000000000000004],
                &["-0.1", "0", "0.1", "0.3"],
            ),
            (&[], &[]),
            (&[0.0], &["0"]),
            (&[7.0], &["7"]),
        ] {
            let got = labels(ticks);
            assert_eq!(got, want, "{ticks:?}");
            assert!(one_format(&got), "{got:?}");
        }
        // The checker itself refuses a mixture.
        for mixed in [
            &["-0.001", "-500µ", "0"][..],
            &["0", "0.5", "1", "1.5"],
            &["5000", "10k"],
            &["0.0001", "10⁻³"],
        ] {
            let mixed: Vec<String> = mixed.iter().map(|s| s.to_string()).collect();
            assert!(!one_format(&mixed), "{mixed:?}");
        }
    }

    #[test]
    fn plotters_linear_ticks_get_one_format() {
        // Ranges whose ticks `tick` wrote in two formats.
        for (lo, hi) in [
            (-0.0031, 0.0002),
            (-0.0124, 0.0008),
            (-0.08, 0.42),
            (-3.0, 74.0),
            (0.0, 15_300.0),
            (-1.2e-7, 3.3e-7),
            (0.98, 1.0031),
        ] {
            use plotters::coord::ranged1d::{BoldPoints, Ranged};
            let axis = plotters::coord::types::RangedCoordf64::from(lo..hi);
            let ticks = axis.key_points(BoldPoints(super::LABELS));
            let f = AxisFormat::linear(lo, hi);
            let got: Vec<String> = ticks.iter().map(|v| f.label(*v)).collect();
            assert!(got.len() >= 3 && one_format(&got), "{lo}..{hi}: {got:?}");
            // Each label reads back as its tick, to a hundredth of the step.
            let step = ticks[1] - ticks[0];
            for (t, l) in ticks.iter().zip(&got) {
                let (number, factor) = [('n', 1e-9), ('µ', 1e-6), ('k', 1e3)]
                    .into_iter()
                    .find_map(|(p, f)| Some((l.strip_suffix(p)?, f)))
                    .unwrap_or((l.as_str(), 1.0));
                let v: f64 = number.parse().unwrap();
                assert!((v * factor - t).abs() < step / 100.0, "{l} for {t}");
            }
        }
    }

    #[test]
    fn a_log_axis_numbers_its_decades_in_one_notation() {
        let names = |ticks: &[f64]| -> Vec<String> {
            let f = AxisFormat::log(ticks);
            ticks.iter().map(|v| f.label(*v)).collect()
        };
        assert_eq!(
            names(&[10.0, 100.0, 1e3, 1e4, 1e5]),
            ["10", "100", "1k", "10k", "100k"]
        );
        assert_eq!(
            names(&[0.001, 0.01, 0.1, 1.0, 10.0]),
            ["0.001", "0.01", "0.1", "1", "10"]
        );
        // Below 10^-3 (`tick` wrote 100µ next to 0.001): powers of ten.
        assert_eq!(
            names(&[1e-5, 1e-4, 1e-3, 1e-2]),
            ["10⁻⁵", "10⁻⁴", "10⁻³", "10⁻²"]
        );
        assert_eq!(names(&[0.1, 10.0, 1e3, 1e5]), ["10⁻¹", "10¹", "10³", "10⁵"]);
        // Round numbers within two decades: one format as on a linear axis.
        assert_eq!(names(&[2.5, 3.0, 3.5, 4.0]), ["2.5", "3.0", "3.5", "4.0"]);
        assert_eq!(names(&[5.0, 10.0, 20.0]), ["5", "10", "20"]);
        assert_eq!(names(&[2e-4, 5e-4, 1e-3]), ["200µ", "500µ", "1000µ"]);
        for ticks in [
            &[1e-5, 1e-4, 1e-3][..],
            &[1.0, 10.0, 100.0, 1e3, 1e4, 1e5, 1e6],
        ] {
            assert!(one_format(&names(ticks)), "{ticks:?}");
        }
    }

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
