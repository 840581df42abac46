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
         | shock spectra (SRS, PVSS, half-sine; 1/6 octave) | {} |\n\
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
        u("spec_instructions"),
        u("spec_band_instructions"),
        fits(b),
        100.0 * f("headroom_at_500k"),
        100.0 * f("headroom_at_adc_top_rate"),
    )
}

#[test]
fn the_docs_m4_figures_are_the_stored_baselines() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/..");
    let baseline: Value = serde_json::from_str(
        &std::fs::read_to_string(format!("{root}/host-tests/bench/m4-baseline.json")).unwrap(),
    )
    .unwrap();
    let docs = std::fs::read_to_string(format!("{root}/docs/benchmarks.md")).unwrap();
    let start = "<!-- host-tests/bench/m4-baseline.json -->\n";
    let from = docs
        .find(start)
        .expect("the baseline's block in docs/benchmarks.md")
        + start.len();
    let to = from + docs[from..].find("\n<!-- end -->").unwrap();
    let want = table(&baseline);
    assert_eq!(
        &docs[from..to],
        want,
        "docs/benchmarks.md's M4 figures are not the baseline's; put:\n{want}"
    );
}
