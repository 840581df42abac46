//! An impact's pulse as an inline SVG for the HTML report: the measured acceleration in g
//! above its baseline (min/max per column), with a specification's nominal pulse and band
//! where its verdict placed them and the verdict's worst point circled (as the live view's
//! page circles it: red where the band fails there).

use impact_core::consts::STANDARD_GRAVITY;
use impact_core::spec::Spec;

pub use crate::plot::band::{band, window, BandPoint};

use crate::html;
use crate::html::Html;
use crate::plot::ticks::{linear_ticks, AxisFormat};
use crate::report::fmt::human;

/// The largest number of impacts drawn (each figure is a few kB; the table has them all).
pub const MAX_FIGURES: usize = 200;

/// A pixel column of a pulse: time (s) and the least and greatest acceleration there (m/s²).
pub type Column = (f64, f64, f64);

/// A pulse drawn: `(t_s, a_m_s2)` min/max pairs per pixel column over the window from
/// `from_s`, the title, the CFC-filtered trace's, and the specification's nominal pulse and
/// band placed at `start_s`.
pub struct Pulse<'a> {
    pub title: String,
    pub columns: Vec<Column>,
    /// The CFC-filtered signal's columns, likewise, and its legend (`CFC 1000`).
    pub filtered: Option<(String, Vec<Column>)>,
    pub spec: Option<(&'a Spec, f64)>,
    /// The verdict's worst point, drawn as a circle.
    pub worst: Option<Worst>,
    /// The recording's time of stream time 0, s: the axis's origin said on its clock.
    pub t0_s: f64,
    /// A force channel: the mass its values in N were divided by (the figure draws N, with
    /// no g axis); none for an acceleration.
    pub force_kg: Option<f64>,
}

/// A verdict's worst point: its time (s from the stream's start), its acceleration above the
/// baseline in the pulse's direction (m/s², as the figure draws the signal), and whether it
/// lies beyond the band (the band fails there).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Worst {
    pub t_s: f64,
    pub a_m_s2: f64,
    pub beyond: bool,
}

impl Worst {
    /// Its colour: red beyond the band, amber within it (the live view's).
    fn colour(self) -> &'static str {
        if self.beyond {
            "#d62728"
        } else {
            "#e3a82b"
        }
    }
}

/// A tick's label: as few digits as the step needs.
fn label(v: f64, step: f64) -> String {
    let decimals = (-step.log10().floor()).max(0.0) as usize;
    format!("{v:.decimals$}")
}

/// The pulse as an inline SVG: acceleration in g (left; m/s² on the right) against time in ms
/// from the nominal pulse's start (without a specification, the window's start), said on the
/// recording's clock, the measured signal as a min/max band per column, the band and
/// the nominal pulse dashed.
pub fn svg(p: &Pulse) -> Html {
    const W: f64 = 530.0;
    const H: f64 = 300.0;
    const L: f64 = 54.0;
    const R: f64 = 56.0;
    const T: f64 = 30.0;
    const B: f64 = 42.0;
    let Some(&(t_first, _, _)) = p.columns.first() else {
        return Html::new();
    };
    let t_last = p.columns.last().map_or(t_first, |c| c.0);
    let g = STANDARD_GRAVITY;
    // The band and the nominal pulse, in (t, lo, hi, nominal) over the window.
    let band = match p.spec {
        Some((spec, start)) => band(spec, start, t_first, t_last),
        None => Vec::new(),
    };
    let (mut y_lo, mut y_hi) = p
        .columns
        .iter()
        .chain(p.filtered.iter().flat_map(|f| f.1.iter()))
        .fold((0.0f64, 0.0f64), |(lo, hi), c| (lo.min(c.1), hi.max(c.2)));
    for b in &band {
        y_lo = y_lo.min(b.1);
        y_hi = y_hi.max(b.2);
    }
    // The worst point, where the window shows it.
    let worst = p
        .worst
        .filter(|w| (t_first..=t_last).contains(&w.t_s) && w.a_m_s2.is_finite());
    if let Some(w) = worst {
        y_lo = y_lo.min(w.a_m_s2);
        y_hi = y_hi.max(w.a_m_s2);
    }
    let pad = 0.05 * (y_hi - y_lo).max(1e-9);
    let (y_lo, mut y_hi) = (y_lo - pad, y_hi + pad);
    let x = |t: f64| L + (t - t_first) / (t_last - t_first).max(1e-12) * (W - L - R);
    // The legend: in the upper right corner, or the left, whichever the curves leave free;
    // else the right, with the range raised until they pass below it.
    let entries = 1
        + usize::from(p.filtered.is_some())
        + usize::from(!band.is_empty())
        + usize::from(worst.is_some());
    let legend_px = 14.0 * entries as f64 + 8.0;
    let highest = |from_px: f64, to_px: f64| {
        let within = |t: f64| (from_px..=to_px).contains(&x(t));
        p.columns
            .iter()
            .chain(p.filtered.iter().flat_map(|f| f.1.iter()))
            .filter(|c| within(c.0))
            .map(|c| c.2)
            .chain(band.iter().filter(|b| within(b.0)).map(|b| b.2))
            .fold(f64::NEG_INFINITY, f64::max)
    };
    let free = |top: f64| (y_hi - top) / (y_hi - y_lo) * (H - T - B) > legend_px;
    let (right, left) = (W - R - 168.0, L + 4.0);
    let right_top = highest(right, W - R);
    let legend_x = if free(right_top) {
        right
    } else if free(highest(left, left + 168.0)) {
        left
    } else {
        let f = legend_px / (H - T - B);
        y_hi = (right_top - f * y_lo) / (1.0 - f);
        right
    };
    let y = |a: f64| T + (y_hi - a) / (y_hi - y_lo) * (H - T - B);
    let mut s = Html::new();
    html!(
        s,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{}\" height=\"{}\" viewBox=\"0 0 {} {}\" font-family=\"sans-serif\" font-size=\"11\"><title>{}</title><rect width=\"{}\" height=\"{}\" fill=\"white\"/>",
        W, H, W, H, p.title, W, H
    );
    html!(s, "<text x=\"{}\" y=\"16\" text-anchor=\"middle\" font-size=\"12\" font-weight=\"bold\">{}</text>", W / 2.0, p.title);
    // Grid and ticks: time in ms from the origin (the nominal pulse's start, where the
    // verdict's times are told from; else the window's start), acceleration in g.
    let origin = p.spec.map_or(t_first, |(_, start)| start);
    let xt = linear_ticks((t_first - origin) * 1e3, (t_last - origin) * 1e3, 6);
    let xstep = xt.get(1).zip(xt.first()).map_or(1.0, |(b, a)| b - a);
    for v in &xt {
        let px = x(origin + v * 1e-3);
        html!(s, "<line x1=\"{:.1}\" y1=\"{}\" x2=\"{:.1}\" y2=\"{}\" stroke=\"#eee\"/><text x=\"{:.1}\" y=\"{}\" text-anchor=\"middle\">{}</text>", px, T, px, H - B, px, H - B + 14.0, label(*v, xstep));
    }
    // The left axis in g (a force channel: in N, the values times the mass they were
    // divided by).
    let per = p.force_kg.map_or(1.0 / g, |m| m);
    let yt = linear_ticks(y_lo * per, y_hi * per, 6);
    let ystep = yt.get(1).zip(yt.first()).map_or(1.0, |(b, a)| b - a);
    for v in &yt {
        let py = y(v / per);
        html!(s, "<line x1=\"{}\" y1=\"{:.1}\" x2=\"{}\" y2=\"{:.1}\" stroke=\"#eee\"/><text x=\"{}\" y=\"{:.1}\" text-anchor=\"end\">{}</text>", L, py, W - R, py, L - 4.0, py + 4.0, label(*v, ystep));
    }
    // The same range in m/s² on the right (none for a force).
    let yt = if p.force_kg.is_some() {
        Vec::new()
    } else {
        linear_ticks(y_lo, y_hi, 6)
    };
    let format = AxisFormat::of(&yt);
    for v in &yt {
        let py = y(*v);
        html!(s, "<line x1=\"{}\" y1=\"{:.1}\" x2=\"{}\" y2=\"{:.1}\" stroke=\"#999\"/><text x=\"{}\" y=\"{:.1}\">{}</text>", W - R, py, W - R + 4.0, py, W - R + 6.0, py + 4.0, format.label(*v));
    }
    html!(
        s,
        "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"#999\"/>",
        L,
        T,
        W - L - R,
        H - T - B
    );
    html!(
        s,
        "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">{} t = {:.6} s on the recording's clock (ms)</text>",
        (L + W - R) / 2.0,
        H - 8.0,
        if p.spec.is_some() {
            "time from the nominal pulse's start,"
        } else {
            "time from"
        },
        p.t0_s + origin
    );
    if p.force_kg.is_some() {
        html!(s, "<text transform=\"translate(14 {}) rotate(-90)\" text-anchor=\"middle\">force (N)</text>", (T + H - B) / 2.0);
    } else {
        html!(s, "<text transform=\"translate(14 {}) rotate(-90)\" text-anchor=\"middle\">acceleration (g)</text>", (T + H - B) / 2.0);
        html!(s, "<text transform=\"translate({} {}) rotate(90)\" text-anchor=\"middle\">acceleration (m/s²)</text>", W - 12.0, (T + H - B) / 2.0);
    }
    // The band (shaded between its limits) and the nominal pulse (dashed).
    if !band.is_empty() {
        let mut d = Html::new();
        for (k, b) in band.iter().enumerate() {
            html!(
                d,
                "{}{:.1},{:.1}",
                if k == 0 { "M" } else { " L" },
                x(b.0),
                y(b.2)
            );
        }
        for b in band.iter().rev() {
            html!(d, " L{:.1},{:.1}", x(b.0), y(b.1));
        }
        html!(s, "<path d=\"{} Z\" fill=\"#4a90d9\" fill-opacity=\"0.15\" stroke=\"#4a90d9\" stroke-width=\"0.8\"/>", d);
        let mut pts = Html::new();
        for (k, b) in band.iter().enumerate() {
            html!(
                pts,
                "{}{:.1},{:.1}",
                if k == 0 { "" } else { " " },
                x(b.0),
                y(b.3)
            );
        }
        html!(
            s,
            "<polyline points=\"{}\" fill=\"none\" stroke=\"#4a90d9\" stroke-dasharray=\"5 3\"/>",
            pts
        );
    }
    // The measured signal, and the filtered one: each column's extremes joined.
    let path = |columns: &[Column]| {
        let mut d = Html::new();
        for (k, c) in columns.iter().enumerate() {
            html!(
                d,
                "{}{:.1},{:.1} L{:.1},{:.1}",
                if k == 0 { "M" } else { " L" },
                x(c.0),
                y(c.1),
                x(c.0),
                y(c.2)
            );
        }
        d
    };
    html!(
        s,
        "<path d=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"1.2\"/>",
        path(&p.columns),
        RAW
    );
    if let Some((_, f)) = &p.filtered {
        html!(
            s,
            "<path d=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"1.8\"/>",
            path(f),
            FILTERED
        );
    }
    if let Some(w) = worst {
        html!(
            s,
            "<circle class=\"worst\" cx=\"{:.1}\" cy=\"{:.1}\" r=\"6\" fill=\"none\" stroke=\"{}\" stroke-width=\"2\"/>",
            x(w.t_s),
            y(w.a_m_s2),
            w.colour()
        );
    }
    // The legend, on white: each entry's stroke (markup) and its text.
    let mut raw_stroke = Html::new();
    html!(raw_stroke, "stroke=\"{}\" stroke-width=\"1.5\"", RAW);
    let mut entries = vec![(raw_stroke, "measured")];
    if let Some((label, _)) = &p.filtered {
        entries[0].1 = "raw";
        let mut filtered_stroke = Html::new();
        html!(
            filtered_stroke,
            "stroke=\"{}\" stroke-width=\"1.8\"",
            FILTERED
        );
        entries.push((filtered_stroke, label.as_str()));
    }
    if !band.is_empty() {
        let mut dashed = Html::new();
        dashed.raw("stroke=\"#4a90d9\" stroke-dasharray=\"5 3\"");
        entries.push((dashed, "nominal, tolerance band"));
    }
    html!(
        s,
        "<g transform=\"translate({} {})\"><rect x=\"-4\" y=\"-8\" width=\"162\" height=\"{}\" fill=\"white\" fill-opacity=\"0.85\" stroke=\"#ccc\"/>",
        legend_x + 4.0,
        T + 11.0,
        14 * (entries.len() + usize::from(worst.is_some())) + 2
    );
    for (k, (stroke, text)) in entries.iter().enumerate() {
        let y = 14 * k;
        html!(
            s,
            "<line x1=\"0\" y1=\"{}\" x2=\"18\" y2=\"{}\" {}/><text x=\"22\" y=\"{}\">{}</text>",
            y,
            y,
            stroke,
            y + 4,
            text
        );
    }
    if let Some(w) = worst {
        let y = 14 * entries.len();
        html!(
            s,
            "<circle cx=\"9\" cy=\"{}\" r=\"4.5\" fill=\"none\" stroke=\"{}\" stroke-width=\"2\"/><text x=\"22\" y=\"{}\">{}</text>",
            y,
            w.colour(),
            y + 4,
            if w.beyond {
                "worst point: fails"
            } else {
                "worst point: within"
            }
        );
    }
    s.raw("</g></svg>");
    s
}

/// The raw signal's colour.
const RAW: &str = "#c0392b";

/// The CFC-filtered signal's colour: dark, over the raw one.
const FILTERED: &str = "#192d78";

/// Columns a pulse is drawn in (each its samples' least and greatest value).
const COLUMNS: u64 = 400;

/// Impact `r` of the recording `signal` reads drawn (`spec`: the scene's): above its baseline, in the direction of its peak;
/// with a verdict, over the window it watched with the nominal pulse and band where it was
/// placed, else from a quarter of its duration before it to a quarter after. `held`: the
/// samples the signal holds, when it is a board's window (no other sample is read: what a
/// figure loops over is bounded by what the log holds, whatever the report's times say).
pub fn pulse_svg(
    signal: &crate::plot::Signal,
    spec: Option<&Spec>,
    r: &impact_core::ImpactReport,
    title: String,
    held: Option<std::ops::Range<u64>>,
) -> Html {
    let rate = signal.rate_hz;
    let (from_s, to_s, placed) = window(spec, r);
    let sign = if r.peak_acceleration_m_s2 < 0.0 {
        -1.0
    } else {
        1.0
    };
    let base = f64::from(r.baseline_m_s2);
    let i0 = (from_s * rate).floor().max(0.0) as u64;
    let i1 = ((to_s * rate).ceil().max(0.0) as u64).max(i0 + 1);
    let n = i1 - i0;
    let cols = COLUMNS.min(n);
    // Each column's least and greatest value of `a` (m/s² above the baseline, by sample), in
    // the direction of the peak.
    let columns = |a: &dyn Fn(u64) -> Option<f64>| -> Vec<Column> {
        (0..cols)
            .filter_map(|c| {
                let (from, to) = (i0 + c * n / cols, i0 + (c + 1) * n / cols);
                let mut samples = from..to.max(from + 1);
                if let Some(h) = &held {
                    samples = samples.start.max(h.start)..samples.end.min(h.end);
                }
                let (lo, hi) = samples
                    .filter_map(a)
                    .map(|v| sign * v)
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                        (lo.min(v), hi.max(v))
                    });
                (lo <= hi).then_some((from as f64 / rate, lo, hi))
            })
            .collect()
    };
    let raw = columns(&|i| Some((signal.accel_m_s2)(i)? - base));
    // The peaks in g, or a force channel's in N.
    let g = |a: f32| match signal.force_kg {
        Some(m) => human(f64::from(a) * m, "N"),
        None => human(f64::from(a) / STANDARD_GRAVITY, "g"),
    };
    let mut peak = format!("peak {}", g(r.peak_acceleration_m_s2));
    let mut filtered = None;
    if let Some((kind, _)) = signal.filter {
        let name = crate::report::filter::name(&kind);
        match (
            crate::plot::filtered(signal, r),
            r.filtered_peak_acceleration_m_s2,
        ) {
            (Some((first, values)), Some(f)) => {
                let trace = columns(&|i| {
                    values
                        .get(usize::try_from(i.checked_sub(first)?).ok()?)
                        .copied()
                });
                peak = format!("{peak} raw, {} {name}", g(f));
                filtered = Some((name, trace));
            }
            _ => peak = format!("{peak} raw ({name}: not drawn)"),
        }
    }
    // The verdict's worst point (its time and value are the stream's, above the baseline in
    // the pulse's direction: as the figure draws the signal).
    let worst = match (&placed, &r.verdict) {
        (Some(_), Some(Ok(v))) => Some(Worst {
            t_s: v.worst_s,
            a_m_s2: f64::from(v.worst_m_s2),
            beyond: !v.band_pass,
        }),
        _ => None,
    };
    svg(&Pulse {
        title: format!("{title}: {peak}"),
        columns: raw,
        filtered,
        spec: placed,
        worst,
        t0_s: signal.t0_s,
        force_kg: signal.force_kg,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_are_round_numbers_covering_the_range() {
        assert_eq!(linear_ticks(0.0, 10.0, 5), [0.0, 2.0, 4.0, 6.0, 8.0, 10.0]);
        assert_eq!(linear_ticks(-3.0, 12.0, 6), [0.0, 5.0, 10.0]);
        assert_eq!(
            linear_ticks(-3.0, 12.0, 10),
            [-2.0, 0.0, 2.0, 4.0, 6.0, 8.0, 10.0, 12.0]
        );
        assert_eq!(label(0.25, 0.05), "0.25");
        assert_eq!(label(12000.0, 2000.0), "12000");
    }

    #[test]
    fn a_force_is_drawn_in_newtons_with_no_g_axis() {
        // 70 m/s² of a force divided by 0.5 kg: 35 N.
        let s = svg(&Pulse {
            title: "hammer".into(),
            columns: (0..100).map(|k| (f64::from(k) * 1e-5, 0.0, 70.0)).collect(),
            filtered: None,
            spec: None,
            worst: None,
            t0_s: 0.0,
            force_kg: Some(0.5),
        })
        .into_string();
        assert!(s.contains(">force (N)</text>"), "{s}");
        assert!(!s.contains("acceleration"), "{s}");
        assert!(s.contains(">30</text>") && !s.contains(">70</text>"), "{s}");
    }

    #[test]
    fn the_pulse_is_in_g_with_m_s2_on_the_right() {
        // A 10 g step: g ticks 0–10 on the left, m/s² 0–100 on the right.
        let g = STANDARD_GRAVITY;
        let s = svg(&Pulse {
            title: "step".into(),
            columns: (0..100)
                .map(|k| (f64::from(k) * 1e-5, 0.0, 10.0 * g))
                .collect(),
            filtered: None,
            spec: None,
            worst: None,
            t0_s: 0.0,
            force_kg: None,
        });
        for want in [
            ">acceleration (g)</text>",
            ">acceleration (m/s²)</text>",
            ">10</text>",
            ">100</text>",
        ] {
            assert!(s.as_str().contains(want), "{want} missing");
        }
    }
}
