//! The M4 figures `docs/benchmarks.md` shows are the stored baseline's
//! (`host-tests/bench/m4-baseline.json`, written by `impact bench m4 --json`, held by
//! `impact bench m4 --check` in CI): refreshing the baseline without the docs fails here.

use serde_json::Value;

/// `n` with a space between thousands (`111 896`), as the docs write counts.
fn grouped(n: u64) -> String {
    let s = n.to_string();
    let mut out = String::new();
    for (i, c) in s.chars().enumerate() {
        if i > 0 && (s.len() - i) % 3 == 0 {
            out.push(' ');
        }
        out.push(c);
    }
    out
}

/// One row per fit the bench times (each the analysis with that fit, less the report's).
fn fits(b: &Value) -> String {
    b["fits"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| {
            format!(
                "| fit {} | {} |\n",
                f["fit"].as_str().unwrap(),
                grouped(f["instructions"].as_u64().unwrap())
            )
        })
        .collect()
}

/// The docs' table, from the baseline.
fn table(b: &Value) -> String {
    let f = |k: &str| b[k].as_f64().unwrap_or_else(|| panic!("{k} missing"));
    let u = |k: &str| grouped(f(k).round() as u64);
    format!(
        "| path | instructions / sample | estimated cycles / sample | target |\n\
         |---|---|---|---|\n\
         | idle (baseline, trigger check, pre-trigger ring) | **{:.2}** | {:.1} | ≤ 10 |\n\
         | inside an impact (capture, exact sums, peak, separation, next hit, level watch, end detection, ring, the rise's record, the kinematics' online sums) | **{:.1}** | {:.1} | ≤ 40 |\n\
         | the whole emulator firmware, idle (source, queue, tasks, executor, replay) | **{:.1}** | | |\n\
         \n\
         | per impact | instructions |\n\
         |---|---|\n\
         | trigger (onset, flanks, pre-trigger replay, the online sums' start) | {} |\n\
         | report without fits ({} samples) | {} |\n\
         | the board's whole analysis (report and the three fits, n fitted) | {} |\n\
         | shock spectra (SRS, PVSS, half-sine; 1/6 octave from 10 Hz to the rate / 8) | {} |\n\
         | the same to 10 kHz (`--srs-high 10000`, MIL-STD-810's range) | {} |\n\
         | verdict against a specified pulse (3 ms half-sine, IEC 60068-2-27) | {} |\n\
         | the same verdict against a user's band of 64 rows | {} |\n\
         {}\n\
         Headroom of the in-impact path on the STM32F407 at 168 MHz: {:.0} % at 500 kS/s, \
         {:.0} % at the ADC's top rate of 2.4 MS/s.",
        f("idle_instructions_per_sample"),
        f("idle_cycles_per_sample"),
        f("impact_instructions_per_sample"),
        f("impact_cycles_per_sample"),
        f("firmware_idle_instructions_per_sample"),
        u("trigger_instructions"),
        u("impact_samples"),
        u("report_instructions"),
        u("analysis_instructions"),
        u("spectrum_instructions"),
        u("spectrum_10khz_instructions"),
        u("spec_instructions"),
        u("spec_band_instructions"),
        fits(b),
        100.0 * f("headroom_at_500k"),
        100.0 * f("headroom_at_adc_top_rate"),
    )
}

#[test]
fn the_docs_m4_figures_are_the_stored_baselines() {
    let baseline = read_json("host-tests/bench/m4-baseline.json");
    assert_block(
        "docs/benchmarks.md",
        "<!-- host-tests/bench/m4-baseline.json -->\n",
        &table(&baseline),
        "docs/benchmarks.md's M4 figures are not the baseline's",
    );
}

/// The repository's file `path` (from its root), as JSON.
fn read_json(path: &str) -> Value {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/..");
    serde_json::from_str(&std::fs::read_to_string(format!("{root}/{path}")).unwrap()).unwrap()
}

/// The stored `impact bench realtime --clock-shift n --json` run.
fn stored_run(n: u32) -> Value {
    read_json(&format!("host-tests/bench/realtime-shift{n}.json"))
}

/// That the text between `start` and the next `<!-- end -->` of the repository's file `doc`
/// is `want`; else `what` and the text to put.
fn assert_block(doc: &str, start: &str, want: &str, what: &str) {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/..");
    let text = std::fs::read_to_string(format!("{root}/{doc}")).unwrap();
    let from = text
        .find(start)
        .unwrap_or_else(|| panic!("the stored block {start:?} in {doc}"))
        + start.len();
    let to = from + text[from..].find("\n<!-- end -->").unwrap();
    assert_eq!(&text[from..to], want, "{what}; put:\n{want}");
}

/// The case of a run named from `name` whose analysis is `work` (`fits`, `stream`,
/// `everything`).
fn case<'a>(run: &'a Value, name: &str, work: &str) -> &'a Value {
    run.as_array()
        .unwrap()
        .iter()
        .find(|c| c["case"].as_str().unwrap().starts_with(name) && c["work"] == work)
        .unwrap_or_else(|| panic!("{name} {work} missing"))
}

/// The spacings a case's trains were tried at, s.
fn spacings(c: &Value) -> impl Iterator<Item = f64> + '_ {
    (c["runs"].as_array().unwrap().iter()).map(|r| r["spacing_s"].as_f64().unwrap())
}

/// A latency in ms as the README writes it: one decimal below 100 ms, none above; a dash
/// where the bench measured none.
fn latency_ms(v: &Value) -> String {
    match v.as_f64().map(|s| s * 1e3) {
        // (Rounded before the format is chosen: 99.96 ms is 100 ms.)
        Some(ms) if (ms * 10.0).round() >= 1000.0 => format!("{ms:.0} ms"),
        Some(ms) => format!("{ms:.1} ms"),
        None => "—".into(),
    }
}

/// A spacing in ms as the docs write it (`80`, `1.25`).
fn spacing_ms(s: f64) -> String {
    let t = format!("{:.2}", s * 1e3);
    t.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// The board's run at clock shift 3 as docs/board.md tabulates it: each case's latency at
/// the widest spacing, and the highest rates tried with every impact analysed and with
/// nothing lost, each with its spacing.
fn shift3_table(run: &Value) -> String {
    let mut t = String::from(
        "| case | analysis | report latency at the widest spacing: median / max | highest rate tried with every impact analysed | highest rate tried with nothing lost |\n|---|---|---|---|---|\n",
    );
    let rate = |hz: &Value| match hz.as_f64() {
        Some(hz) => format!("{} /s ({} ms apart)", per_s(hz), spacing_ms(1.0 / hz)),
        None => "none".into(),
    };
    for c in run.as_array().unwrap() {
        let work = match c["work"].as_str().unwrap() {
            "fits" => "all three fits, n fitted",
            "stream" => "none",
            "everything" => "fits, spectra, verdict",
            other => panic!("{other}"),
        };
        let n = &c["nominal"];
        t.push_str(&format!(
            "| {} | {work} | {} / {} ({} ms apart) | {} | {} |\n",
            c["case"].as_str().unwrap(),
            latency_ms(&n["latency_median_s"]).trim_end_matches(" ms"),
            latency_ms(&n["latency_max_s"]),
            spacing_ms(n["spacing_s"].as_f64().unwrap()),
            rate(&c["max_rate_fully_analysed_hz"]),
            rate(&c["max_rate_lossless_hz"]),
        ));
    }
    t.pop();
    t
}

/// A rate per second with at most one decimal (`12.5`, `25`).
fn per_s(hz: f64) -> String {
    let tenths = (hz * 10.0).round();
    if tenths % 10.0 == 0.0 {
        format!("{:.0}", tenths / 10.0)
    } else {
        format!("{:.1}", tenths / 10.0)
    }
}

/// The README's real-time table, from `impact bench realtime --json` at clock shifts 2, 3
/// and 4 (`runs[s]` the shift's cases).
fn realtime_table(runs: &[Value; 3]) -> String {
    let row = |name: &str, work: &str| -> String {
        runs.iter()
            .map(|r| latency_ms(&case(r, name, work)["nominal"]["latency_median_s"]))
            .collect::<Vec<_>>()
            .join(" | ")
    };
    let rates: Vec<String> = runs
        .iter()
        .map(|r| {
            let c = case(r, "seed bench", "everything");
            c["max_rate_fully_analysed_hz"]
                .as_f64()
                .map_or("none".into(), |hz| format!("{} /s", per_s(hz)))
        })
        .collect();
    let everything = case(&runs[1], "seed bench", "everything");
    let widest = spacings(everything).fold(0.0, f64::max);
    let closest = spacings(everything).fold(f64::INFINITY, f64::min);
    format!(
        "| report latency (median) | twice as fast (2) | the board (3) | half as fast (4) |\n\
         |---|---|---|---|\n\
         | seed bench, 500 kS/s, all fits | {} |\n\
         | AFRL-like pulses, 1 MS/s, all fits | {} |\n\
         | seed bench, everything on (fits, shock spectra, a verdict against a 10 g, 3 ms half-sine) | {} |\n\
         | highest impact rate with everything on, every impact analysed at a pace the board keeps (seed bench, trains of ten; rates tried: {} to {} /s) | {} |",
        row("seed bench", "fits"),
        row("AFRL-like", "fits"),
        row("seed bench", "everything"),
        per_s(1.0 / widest),
        per_s(1.0 / closest),
        rates.join(" | "),
    )
}

#[test]
fn the_readmes_real_time_figures_are_the_stored_runs() {
    assert_block(
        "README.md",
        "<!-- host-tests/bench/realtime-shift{2,3,4}.json -->\n",
        &realtime_table(&[stored_run(2), stored_run(3), stored_run(4)]),
        "README.md's real-time figures are not the stored runs'",
    );
}

/// docs/board.md's table of the same runs: each case's latency and the highest rate with
/// every impact analysed (below the widest spacing's rate where none was).
fn board_table(runs: &[Value; 3]) -> String {
    let cell = |run: &Value, name: &str, work: &str| -> String {
        let c = case(run, name, work);
        let rate = match c["max_rate_fully_analysed_hz"].as_f64() {
            Some(hz) => format!("{} /s", per_s(hz)),
            None => format!("below {} /s", per_s(1.0 / spacings(c).fold(0.0, f64::max))),
        };
        format!("{}, {rate}", latency_ms(&c["nominal"]["latency_median_s"]))
    };
    let row = |label: &str, name: &str, work: &str| -> String {
        let cells: Vec<String> = runs.iter().map(|r| cell(r, name, work)).collect();
        format!("| {label} | {} |\n", cells.join(" | "))
    };
    let mut t = String::from(
        "| case | `--clock-shift 2` | `3` (the board) | `4` (half as fast) |\n|---|---|---|---|\n",
    );
    t.push_str(&row(
        "seed bench, fits: latency median, rate with every impact analysed",
        "seed bench",
        "fits",
    ));
    t.push_str(&row("seed bench, no fits", "seed bench", "stream"));
    t.push_str(&row(
        "seed bench, fits, spectra, verdict",
        "seed bench",
        "everything",
    ));
    t.push_str(&row("AFRL-like, fits", "AFRL-like", "fits"));
    t.push_str(&row("AFRL-like, no fits", "AFRL-like", "stream"));
    t.pop();
    t
}

#[test]
fn the_boards_real_time_table_is_the_stored_runs() {
    for (start, want) in [
        (
            "<!-- host-tests/bench/realtime-shift3.json -->\n",
            shift3_table(&stored_run(3)),
        ),
        (
            "<!-- host-tests/bench/realtime-shift{2,3,4}.json -->\n",
            board_table(&[stored_run(2), stored_run(3), stored_run(4)]),
        ),
    ] {
        assert_block(
            "docs/board.md",
            start,
            &want,
            "docs/board.md's real-time table is not the stored runs'",
        );
    }
}

/// docs/accuracy.md's prose figures of the spectra's cost are the baseline's, to 0.1 M: the
/// default bands' and those to 10 kHz.
#[test]
fn the_accuracy_docs_spectra_costs_are_the_stored_baseline() {
    let b = read_json("host-tests/bench/m4-baseline.json");
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/..");
    let text = std::fs::read_to_string(format!("{root}/docs/accuracy.md")).unwrap();
    let m = |k: &str| b[k].as_f64().unwrap_or_else(|| panic!("{k} missing")) / 1e6;
    for want in [
        format!(
            "**{:.1} M instructions** for the seed impact's",
            m("spectrum_instructions")
        ),
        format!(
            "**{:.1} M instructions** (the table",
            m("spectrum_10khz_instructions")
        ),
    ] {
        assert!(text.contains(&want), "docs/accuracy.md should say {want:?}");
    }
}
