//! The figures as a user sees them: the CFC trace drawn is the analysis's own filter, the
//! g axis, the log axes' decades, the PNG.

use std::path::PathBuf;

use impact_host::pipeline::{self, AnalyzeArgs};
use impact_io::channel::ColumnRef;

mod common;
use common::{impact_ok, Scratch};

fn data(rel: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("data")
        .join(rel)
}

/// The analysis's CFC-filtered peak, as the report has it: the trace drawn reaches it (to the
/// rounding of its f32 input) in the impact's window, read in passes and whole.
#[test]
fn the_cfc_trace_drawn_is_the_analysis_s_filter() {
    let mut compared = 0;
    for (rel, column) in [
        ("afrl-drop-tower/series1_test1_full_100ms.csv", 1),
        ("afrl-drop-tower/accel_5.csv", 3),
        ("endaq-high-drop/High-Drop_2000g-PE_13.4-15.0s.csv", 1),
        ("impack-water-entry/4mps_sphere_1_100g-PR_9.9-10.6s.csv", 1),
        ("pyfrf-impact-hammer/measurement_1.csv", 1),
    ] {
        for class in [60, 180, 600, 1000] {
            // Read in passes (the figure's windows kept) and whole.
            for whole in [false, true] {
                let args = AnalyzeArgs {
                    file: data(rel),
                    column: Some(ColumnRef::Index(column)),
                    cfc: Some(class),
                    plot: Some(PathBuf::from("unused.svg")),
                    ..Default::default()
                };
                let analysed = if whole {
                    pipeline::setup(&args, impact_io::progress::Progress::none()).and_then(
                        |setup| {
                            let reports = pipeline::run(
                                &setup.prepared.counts,
                                &setup.scene,
                                setup.capture_len,
                            )?;
                            Ok((setup, reports))
                        },
                    )
                } else {
                    pipeline::analyze(&args, impact_io::progress::Progress::none())
                };
                // (A rate too low for the class is refused as a whole.)
                let Ok((setup, reports)) = analysed else {
                    continue;
                };
                let signal = setup.plot_signal();
                for r in reports.iter().take(impact_host::plot::SHOWN) {
                    let Some(want) = r.filtered_peak_acceleration_m_s2 else {
                        assert!(impact_host::plot::filtered(&signal, r).is_none());
                        continue;
                    };
                    let (first, trace) = impact_host::plot::filtered(&signal, r)
                        .unwrap_or_else(|| panic!("{rel} CFC {class}: no trace"));
                    // The trace's peak over the impact's window (from its onset: the window
                    // starts a little before, where the filtered signal is smaller).
                    let from = usize::try_from(r.start_sample - first).unwrap();
                    let to = usize::try_from(r.end_sample - first).unwrap();
                    let got = trace[from..to]
                        .iter()
                        .copied()
                        .max_by(|a, b| a.abs().total_cmp(&b.abs()))
                        .unwrap();
                    let err = (got - f64::from(want)).abs() / f64::from(want).abs();
                    assert!(
                        err < 2e-5,
                        "{rel} CFC {class} (whole: {whole}) impact {}: drawn {got}, reported {want}",
                        r.index
                    );
                    compared += 1;
                }
            }
        }
    }
    assert!(compared >= 20, "{compared}");
}

#[test]
fn with_a_cfc_the_figures_draw_the_raw_and_the_filtered_signal_and_say_so() {
    let scratch = Scratch::new();
    let d = scratch.path();
    let f = data("afrl-drop-tower/accel_5.csv");
    let svg = d.join("cfc.svg");
    impact_ok(&[
        "analyze",
        f.to_str().unwrap(),
        "--column",
        "1",
        "--cfc",
        "1000",
        "--plot",
        svg.to_str().unwrap(),
    ]);
    let drawn = std::fs::read_to_string(&svg).unwrap();
    for want in [
        "raw signal above its baseline, m/s²; CFC 1000 (SAE J211, phaseless) over the deceleration",
        ">\nraw\n</text>",
        ">\nCFC 1000\n</text>",
    ] {
        assert!(drawn.contains(want), "{want} missing from the figure");
    }
    // Without a CFC: the measured signal alone.
    impact_ok(&[
        "analyze",
        f.to_str().unwrap(),
        "--column",
        "1",
        "--plot",
        svg.to_str().unwrap(),
    ]);
    let drawn = std::fs::read_to_string(&svg).unwrap();
    assert!(!drawn.contains("CFC") && drawn.contains(">\nmeasured\n</text>"));
    // The report's pulses: both peaks in the title, both traces in the legend.
    let html = d.join("cfc.html");
    impact_ok(&[
        "report",
        f.to_str().unwrap(),
        "--channels",
        "1,2",
        "--units",
        "kgn",
        "--cfc",
        "1000",
        "--html",
        html.to_str().unwrap(),
    ]);
    let page = std::fs::read_to_string(&html).unwrap();
    assert_eq!(page.matches("g CFC 1000</text>").count(), 2, "the titles");
    assert_eq!(page.matches(">CFC 1000</text>").count(), 2, "the legends");
    assert_eq!(page.matches(">raw</text>").count(), 2);
}

/// A PNG's size and its RGBA pixels.
fn decode(bytes: &[u8]) -> ((u32, u32), Vec<u8>) {
    let mut reader = png::Decoder::new(std::io::Cursor::new(bytes))
        .read_info()
        .unwrap();
    let mut pixels = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut pixels).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgba);
    pixels.truncate(info.buffer_size());
    ((info.width, info.height), pixels)
}

/// The share of the pixels in rows `rows` that are dark (text, axes, curves).
fn dark(size: (u32, u32), pixels: &[u8], rows: std::ops::Range<u32>) -> f64 {
    let w = size.0 as usize;
    let px = |k: usize| &pixels[4 * k..4 * k + 4];
    let n = rows.clone().count() * w;
    let dark = rows
        .flat_map(|y| (0..w).map(move |x| y as usize * w + x))
        .filter(|&k| px(k)[..3].iter().all(|&c| c < 100) && px(k)[3] > 200)
        .count();
    dark as f64 / n as f64
}

#[test]
fn plot_png_is_the_figure_rasterised_the_same_on_any_machine() {
    let scratch = Scratch::new();
    let d = scratch.path();
    let f = data("afrl-drop-tower/series1_test1_full_100ms.csv");
    let draw = |name: &str| {
        let out = d.join(name);
        let (_, err) = impact_ok(&[
            "analyze",
            f.to_str().unwrap(),
            "--column",
            "1",
            "--srs",
            "--plot",
            out.to_str().unwrap(),
        ]);
        assert!(err.contains(&format!("wrote {}", out.display())), "{err}");
        std::fs::read(&out).unwrap()
    };
    let png = draw("figure.png");
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n", "the PNG signature");
    // The SVG's size: five panels of 400 px across (without v0 no force-deformation loop:
    // the panels the impact can fill, none drawn empty), one impact of 330 px and the
    // title's 36.
    let svg = String::from_utf8(draw("figure.svg")).unwrap();
    assert!(
        svg.starts_with("<svg width=\"2000\" height=\"366\""),
        "{}",
        &svg[..80]
    );
    assert!(!svg.contains("needs v0"), "an empty panel");
    let (size, pixels) = decode(&png);
    assert_eq!(size, (2000, 366));
    // Not blank: opaque, a white background, and dark pixels where the title's text is (the
    // embedded font drew it) and over the panels (axes, labels).
    assert!(pixels.chunks(4).all(|p| p[3] == 255), "transparent pixels");
    let title = dark(size, &pixels, 8..30);
    let panels = dark(size, &pixels, 40..366);
    assert!(
        title > 0.005 && panels > 0.005,
        "title {title}, panels {panels}"
    );
    assert!(
        title < 0.5 && panels < 0.5,
        "title {title}, panels {panels}"
    );
    // The same bytes every time (no system font, no clock in the file).
    assert_eq!(draw("again.png"), png);
    // The extension chooses, whatever its case; other names are refused, naming the two.
    assert_eq!(&draw("upper.PNG")[..8], b"\x89PNG\r\n\x1a\n");
    let (code, _, err) = common::impact(&[
        "analyze",
        f.to_str().unwrap(),
        "--plot",
        d.join("figure.jpg").to_str().unwrap(),
    ]);
    assert_eq!(code, 1);
    assert!(err.contains(".svg or .png"), "{err}");
    assert!(!d.join("figure.jpg").exists());
    // The output rules hold for a PNG: never over an input (a link to one included).
    let input = d.join("input.png");
    std::fs::copy(&f, &input).unwrap();
    let (code, _, err) = common::impact(&[
        "analyze",
        input.to_str().unwrap(),
        "--column",
        "1",
        "--plot",
        input.to_str().unwrap(),
    ]);
    assert_eq!(code, 1);
    assert!(err.contains("would be overwritten"), "{err}");
    assert_eq!(std::fs::read(&input).unwrap(), std::fs::read(&f).unwrap());
}

/// An SVG's `<text>` elements: `(x, y, text)`.
fn texts(svg: &str) -> Vec<(f64, f64, String)> {
    svg.split("<text")
        .skip(1)
        .filter_map(|t| {
            let text = t[t.find('>')? + 1..t.find("</text>")?].trim().to_string();
            Some((attr(t, "x")?, attr(t, "y")?, text))
        })
        .collect()
}

/// Attribute `name` of the element starting `element`, as a number.
fn attr(element: &str, name: &str) -> Option<f64> {
    let key = format!(" {name}=\"");
    let rest = &element[element.find(&key)? + key.len()..];
    rest[..rest.find('"')?].parse().ok()
}

/// A 10 g, 3 ms half-sine (a linear contact of 1 kg at 100 kS/s) in `scratch`.
fn half_sine(scratch: &Scratch) -> String {
    let file = scratch.join_str("half-sine.csv");
    impact_ok(&[
        "synth",
        "--model",
        "linear",
        "--mass",
        "1",
        "--stiffness",
        "1.0966e6",
        "--v0",
        "0.0937",
        "--rate",
        "100000",
        "--full-scale",
        "400",
        "--output",
        &file,
    ]);
    file
}

/// With `--spec`, the deceleration panel draws the tolerance band and the nominal pulse, shades
/// the window the verdict watched and circles its worst point, each where the verdict put it
/// (read back through the panel's own tick labels), with legend entries; without, none of it.
#[test]
fn a_spec_run_draws_its_band_and_the_window_it_watched() {
    let scratch = Scratch::new();
    let file = half_sine(&scratch);
    let svg = scratch.join_str("spec.svg");
    let spec = "half-sine,10g,3ms";
    let (json, _) = impact_ok(&["analyze", &file, "--spec", spec, "--json"]);
    impact_ok(&["analyze", &file, "--spec", spec, "--plot", &svg]);
    let drawn = std::fs::read_to_string(&svg).unwrap();
    let j: serde_json::Value = serde_json::from_str(&json).unwrap();
    let i = &j["impacts"][0];
    let num = |v: &serde_json::Value| v.as_f64().unwrap();
    let (start, placed) = (num(&i["start_s"]), num(&i["spec"]["nominal_start_s"]));
    let d = num(&j["spec"]["duration_s"]);
    let (before, watch) = (num(&j["spec"]["before"]), num(&j["spec"]["watch"]));
    // ms from the touch to px, from the first panel's time labels (under it, left of 400 px).
    let t = texts(&drawn);
    let ticks: Vec<(f64, f64)> = t
        .iter()
        .filter(|(x, y, _)| *x < 400.0 && (330.0..345.0).contains(y))
        .filter_map(|(x, _, s)| Some((s.parse::<f64>().ok()?, *x)))
        .collect();
    assert!(ticks.len() >= 4, "{ticks:?}");
    let (a, b) = (ticks[0], ticks[ticks.len() - 1]);
    let px = |ms: f64| a.1 + (ms - a.0) / (b.0 - a.0) * (b.1 - a.1);
    let ms = |s: f64| (s - start) * 1e3;
    // The watched window: a shaded rectangle from before·D ahead of the placed pulse to
    // watch·D past its end.
    let rect = drawn
        .split("<rect")
        .find(|r| r.contains("fill=\"#787878\""))
        .expect("no watched window drawn");
    let (x, w) = (attr(rect, "x").unwrap(), attr(rect, "width").unwrap());
    let (from, to) = (
        px(ms(placed - before * d)),
        px(ms(placed + (1.0 + watch) * d)),
    );
    assert!((x - from).abs() <= 2.0, "{x} against {from}");
    assert!((x + w - to).abs() <= 2.0, "{} against {to}", x + w);
    // The band, shaded, and the nominal pulse, dashed (many short dark green strokes).
    assert!(drawn.contains("<polygon opacity=\"0.18\" fill=\"#2E8B57\""));
    assert!(
        drawn
            .matches("stroke=\"#145A32\" stroke-width=\"2\"")
            .count()
            > 20
    );
    // The worst point, at its time, on the curve's scale (0 m/s² where the left axis says 0).
    let circle = drawn
        .split("<circle")
        .find(|c| c.contains("r=\"6\""))
        .expect("no worst point drawn");
    let worst = num(&i["spec"]["worst_time_s"]);
    assert!((attr(circle, "cx").unwrap() - px(ms(worst))).abs() <= 2.0);
    let zero = t
        .iter()
        .find(|(x, y, s)| *x < 68.0 && *y > 60.0 && s == "0")
        .unwrap();
    let value_px = attr(circle, "cy").unwrap() - (zero.1 - 4.0);
    assert!(value_px.abs() <= 6.0, "{value_px}");
    for entry in [
        "watched window",
        "tolerance band",
        "nominal pulse",
        "worst point: within",
    ] {
        assert!(
            t.iter().any(|(_, _, s)| s == entry),
            "{entry} not in the legend"
        );
    }
    // Without --spec, none of it.
    impact_ok(&["analyze", &file, "--plot", &svg]);
    let drawn = std::fs::read_to_string(&svg).unwrap();
    for absent in [
        "#787878",
        "<polygon",
        "watched window",
        "tolerance band",
        "worst point",
    ] {
        assert!(!drawn.contains(absent), "{absent} drawn without --spec");
    }
}

/// A force channel (the impact hammer's `force_n`) is drawn as force: its panel titled and
/// scaled in N (the peak force the report gives, not that force over the mass), no g axis,
/// no m/s² anywhere in the deceleration's place.
#[test]
fn a_force_channel_is_drawn_in_newtons_without_a_g_axis() {
    let scratch = Scratch::new();
    let f = data("pyfrf-impact-hammer/measurement_1.csv");
    let svg = scratch.join_str("force.svg");
    for mass in [None, Some("0.5")] {
        let mut args = vec!["analyze", f.to_str().unwrap(), "--plot", &svg];
        args.extend(mass.map(|m| ["--mass", m]).iter().flatten());
        impact_ok(&args);
        let drawn = std::fs::read_to_string(&svg).unwrap();
        let t = texts(&drawn);
        assert!(
            t.iter().any(|(_, _, s)| s == "impact 0 — force, N"),
            "{mass:?}: no force panel"
        );
        assert!(
            t[0].2.contains("raw signal above its baseline, N"),
            "{}",
            t[0].2
        );
        for (_, _, s) in &t {
            assert!(!s.contains("m/s²") && s != "g", "{mass:?}: {s:?} drawn");
        }
        // The force axis (left of the first panel) reaches the peak of 68.6 N, not 137 m/s²
        // (68.6 N over 0.5 kg).
        let top = t
            .iter()
            .filter(|(x, y, _)| *x < 68.0 && *y > 60.0)
            .filter_map(|(_, _, s)| s.parse::<f64>().ok())
            .fold(f64::MIN, f64::max);
        assert!((68.6..100.0).contains(&top), "{mass:?}: {top}");
    }
}
