//! The M4 report as a table, its check against the stored baseline and the targets.

use super::*;

/// The report as a table.
pub fn table(r: &M4Report) -> String {
    let mut s = String::new();
    s.push_str(&format!(
        "Cortex-M4F (QEMU mps2-an386, exact instruction counts), board scene, {}-sample blocks\n",
        r.block
    ));
    s.push_str(&format!(
        "  idle        {:6.2} instructions/sample (target <= {IDLE_TARGET}), ~{:.1} cycles\n",
        r.idle_instructions_per_sample, r.idle_cycles_per_sample
    ));
    s.push_str(&format!(
        "  in impact   {:6.2} instructions/sample (target <= {IMPACT_TARGET}), ~{:.1} cycles\n",
        r.impact_instructions_per_sample, r.impact_cycles_per_sample
    ));
    s.push_str(&format!(
        "  whole emulator firmware, idle: {:.2} instructions/sample (tasks, channel, executor, replay source)\n",
        r.firmware_idle_instructions_per_sample
    ));
    s.push_str(&format!(
        "  worst ~{:.1} cycles/sample: headroom {:.1} % at 500 kS/s (336 cycles), {:.1} % at 2.4 MS/s (70 cycles)\n",
        r.estimated_cycles_per_sample,
        100.0 * r.headroom_at_500k,
        100.0 * r.headroom_at_adc_top_rate
    ));
    s.push_str(&format!(
        "  per impact: trigger {} instructions, report (no fit) {} instructions ({} samples)\n",
        r.trigger_instructions, r.report_instructions, r.impact_samples
    ));
    for f in &r.fits {
        s.push_str(&format!(
            "  fit {:<38} {:>12} instructions ({:.1} ms at 168 MHz, 1 instruction/cycle)\n",
            f.fit,
            f.instructions,
            f.instructions as f64 / BOARD_CLOCK_HZ * 1e3
        ));
    }
    s.push_str(&format!(
        "  the board's whole analysis of one impact (report + fits, n fitted): {} instructions ({:.1} ms at 125 M instructions/s)\n",
        r.analysis_instructions,
        r.analysis_instructions as f64 / 125e6 * 1e3
    ));
    s.push_str(&format!(
        "  shock spectra of the impact (SRS, PVSS, half-sine; 1/6 octave from 10 Hz): {} instructions ({:.1} ms at 125 M instructions/s)\n",
        r.spectrum_instructions,
        r.spectrum_instructions as f64 / 125e6 * 1e3,
    ));
    s.push_str(&format!(
        "  the same spectra up to 10 kHz (--srs-high 10000, MIL-STD-810's range): {} instructions ({:.1} ms at 125 M instructions/s)\n",
        r.spectrum_10khz_instructions,
        r.spectrum_10khz_instructions as f64 / 125e6 * 1e3,
    ));
    s.push_str(&format!(
        "  verdict against a specified pulse (3 ms half-sine, IEC 60068-2-27): {} instructions ({:.1} ms at 125 M instructions/s)\n",
        r.spec_instructions,
        r.spec_instructions as f64 / 125e6 * 1e3,
    ));
    s.push_str(&format!(
        "  the same verdict against a user's band of 64 rows: {} instructions ({:.1} ms at 125 M instructions/s)\n",
        r.spec_band_instructions,
        r.spec_band_instructions as f64 / 125e6 * 1e3,
    ));
    for (name, now, target) in targets(r) {
        s.push_str(&format!(
            "  target: {name:<40} {now:>10} <= {target:>9}: {}\n",
            if now <= target { "met" } else { "MISSED" }
        ));
    }
    s.push_str("\nOne impact in f32 at <= 1e-4 relative error (cheapest setting on the ladder):\n");
    s.push_str("  case                       method     setting       error   instructions  same bits as host\n");
    for v in &r.solves {
        s.push_str(&format!(
            "  {:<26} {:<9} {:>8}  {:>10.1e}  {:>13}  {}\n",
            v.case,
            v.method,
            if v.method == "adaptive" {
                format!("{:.0e}", v.setting)
            } else {
                format!("{}", v.setting)
            },
            v.error,
            v.instructions,
            if v.same_bits_as_host { "yes" } else { "NO" }
        ));
    }
    s.push_str(
        "\nMaths back-ends (f32): instructions per call on the M4, largest relative error:\n",
    );
    for m in &r.maths {
        s.push_str(&format!(
            "  {:<7} {:<10} {:>8.1}  {:>9.1e}\n",
            m.op, m.backend, m.instructions_per_call, m.max_relative_error
        ));
    }
    s
}

/// One way a run's counts fail against the baseline or the targets.
#[derive(Clone, Debug, PartialEq)]
pub enum Regression {
    /// A count grew by more than 10 %.
    Grew { name: String, now: f64, then: f64 },
    /// A solve the M4 and the host give different bits for.
    Disagree { case: String, method: String },
    /// A per-impact count over its absolute target.
    OverTarget {
        name: &'static str,
        now: u64,
        target: u64,
    },
    /// The in-impact path's instructions a sample over its absolute target.
    OverSampleTarget {
        name: &'static str,
        now: f64,
        target: f64,
    },
}

impl std::fmt::Display for Regression {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Regression::Grew { name, now, then } => write!(f, "{name}: {now:.2} against {then:.2}"),
            Regression::Disagree { case, method } => {
                write!(f, "solve {case} {method}: the M4 and the host disagree")
            }
            Regression::OverTarget { name, now, target } => {
                write!(f, "{name}: {now} instructions, over its target of {target}")
            }
            Regression::OverSampleTarget { name, now, target } => {
                write!(
                    f,
                    "{name}: {now:.2} instructions a sample, over its target of {target}"
                )
            }
        }
    }
}

/// The counts regressed: the comparison's table and what failed, a line each.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("M4 instruction counts regressed by more than 10 %:\n{table}{}", lines(.failed))]
pub struct Regressed {
    pub table: String,
    pub failed: Vec<Regression>,
}

fn lines(failed: &[Regression]) -> String {
    failed
        .iter()
        .map(Regression::to_string)
        .collect::<Vec<_>>()
        .join("\n")
}

/// Compares `r` with a stored baseline: every instruction count may grow by 10 % at most.
/// The comparison's table, or what regressed.
pub fn check(r: &M4Report, baseline: &M4Report) -> Result<String, Regressed> {
    let mut rows: Vec<(String, f64, f64)> = vec![
        (
            "idle instructions/sample".into(),
            r.idle_instructions_per_sample,
            baseline.idle_instructions_per_sample,
        ),
        (
            "in-impact instructions/sample".into(),
            r.impact_instructions_per_sample,
            baseline.impact_instructions_per_sample,
        ),
        (
            "firmware idle instructions/sample".into(),
            r.firmware_idle_instructions_per_sample,
            baseline.firmware_idle_instructions_per_sample,
        ),
        (
            "trigger instructions".into(),
            r.trigger_instructions as f64,
            baseline.trigger_instructions as f64,
        ),
        (
            "report instructions".into(),
            r.report_instructions as f64,
            baseline.report_instructions as f64,
        ),
        (
            "whole analysis instructions".into(),
            r.analysis_instructions as f64,
            baseline.analysis_instructions as f64,
        ),
        (
            "shock spectra instructions".into(),
            r.spectrum_instructions as f64,
            baseline.spectrum_instructions as f64,
        ),
        (
            "shock spectra to 10 kHz instructions".into(),
            r.spectrum_10khz_instructions as f64,
            baseline.spectrum_10khz_instructions as f64,
        ),
        (
            "spec verdict instructions".into(),
            r.spec_instructions as f64,
            baseline.spec_instructions as f64,
        ),
        (
            "spec verdict, user's band, instructions".into(),
            r.spec_band_instructions as f64,
            baseline.spec_band_instructions as f64,
        ),
    ];
    for f in &r.fits {
        if let Some(b) = baseline.fits.iter().find(|b| b.fit == f.fit) {
            rows.push((
                format!("fit {}", f.fit),
                f.instructions as f64,
                b.instructions as f64,
            ));
        }
    }
    for v in &r.solves {
        if let Some(b) = baseline
            .solves
            .iter()
            .find(|b| b.case == v.case && b.method == v.method && b.setting == v.setting)
        {
            rows.push((
                format!("solve {} {}", v.case, v.method),
                v.instructions as f64,
                b.instructions as f64,
            ));
        }
    }
    let mut text = String::new();
    let mut failed = Vec::new();
    for (name, now, then) in rows {
        let ratio = if then > 0.0 { now / then } else { 1.0 };
        text.push_str(&format!(
            "  {name:<44} {now:>14.2} vs {then:>14.2} ({:+.1} %)\n",
            100.0 * (ratio - 1.0)
        ));
        if ratio > 1.10 {
            failed.push(Regression::Grew { name, now, then });
        }
    }
    for v in r.solves.iter().filter(|v| !v.same_bits_as_host) {
        failed.push(Regression::Disagree {
            case: v.case.clone(),
            method: v.method.clone(),
        });
    }
    for (name, now, target) in targets(r) {
        if now > target {
            failed.push(Regression::OverTarget { name, now, target });
        }
    }
    // #44's per-sample target for the in-impact path (a count that is not a number fails).
    let (now, target) = (r.impact_instructions_per_sample, IMPACT_TARGET);
    if now.partial_cmp(&target).is_none_or(|o| o.is_gt()) {
        failed.push(Regression::OverSampleTarget {
            name: "in impact",
            now,
            target,
        });
    }
    if failed.is_empty() {
        Ok(text)
    } else {
        Err(Regressed {
            table: text,
            failed,
        })
    }
}

/// The per-impact targets with what was measured: (name, instructions, target).
fn targets(r: &M4Report) -> Vec<(&'static str, u64, u64)> {
    let fit = |name: &str| {
        r.fits
            .iter()
            .find(|f| f.fit == name)
            .map_or(0, |f| f.instructions)
    };
    vec![
        ("report without fits", r.report_instructions, REPORT_TARGET),
        (
            "two-phase + nonlinear (n fixed) + hertz",
            fit("two-phase + nonlinear (n fixed) + hertz"),
            THREE_FITS_TARGET,
        ),
        (
            "nonlinear (n fitted)",
            fit("nonlinear (n fitted)"),
            EXPONENT_FIT_TARGET,
        ),
        (
            "the board's whole analysis",
            r.analysis_instructions,
            ANALYSIS_TARGET,
        ),
        (
            "shock spectra (1/6 octave)",
            r.spectrum_instructions,
            SPECTRUM_TARGET,
        ),
        (
            "a verdict against a specified pulse",
            r.spec_instructions,
            SPEC_TARGET,
        ),
        (
            "a verdict against a user's band",
            r.spec_band_instructions,
            SPEC_TARGET,
        ),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn report(idle: f64, solve_instructions: u64, same: bool) -> M4Report {
        M4Report {
            block: 256,
            idle_instructions_per_sample: idle,
            impact_instructions_per_sample: 40.0,
            idle_cycles_per_sample: 0.0,
            impact_cycles_per_sample: 0.0,
            estimated_cycles_per_sample: 0.0,
            headroom_at_500k: 0.0,
            headroom_at_adc_top_rate: 0.0,
            trigger_instructions: 1000,
            report_instructions: 1000,
            impact_samples: 100,
            analysis_instructions: 2000,
            spectrum_instructions: 3000,
            spectrum_10khz_instructions: 2000,
            spec_instructions: 3000,
            spec_band_instructions: 3000,
            fits: vec![],
            solves: vec![SolveCost {
                case: "c".into(),
                method: "rk4".into(),
                setting: 16.0,
                error: 1e-5,
                instructions: solve_instructions,
                same_bits_as_host: same,
            }],
            maths: vec![],
            instructions_per_tick: 40.0,
            firmware_idle_instructions_per_sample: 20.0,
        }
    }

    #[test]
    fn baseline_check_fails_on_a_regression_beyond_ten_percent() {
        let base = report(10.0, 1000, true);
        assert!(check(&report(10.9, 1099, true), &base).is_ok());
        assert!(check(&report(11.1, 1000, true), &base).is_err());
        assert!(check(&report(10.0, 1101, true), &base).is_err());
        assert!(check(&report(10.0, 1000, false), &base).is_err());
        // Getting faster is never a failure.
        assert!(check(&report(5.0, 10, true), &base).is_ok());
    }

    #[test]
    fn baseline_check_fails_over_an_absolute_target() {
        let base = report(10.0, 1000, true);
        let mut r = report(10.0, 1000, true);
        r.fits.push(FitCost {
            fit: "nonlinear (n fitted)".into(),
            instructions: EXPONENT_FIT_TARGET + 1,
        });
        let e = check(&r, &base).unwrap_err();
        assert!(
            matches!(e.failed[..], [Regression::OverTarget { .. }]),
            "{e}"
        );
        r.fits[0].instructions = EXPONENT_FIT_TARGET;
        assert!(check(&r, &base).is_ok());
        r.analysis_instructions = ANALYSIS_TARGET + 1;
        assert!(check(&r, &base).is_err());
        r.analysis_instructions = ANALYSIS_TARGET;
        r.spectrum_instructions = SPECTRUM_TARGET + 1;
        assert!(check(&r, &base).is_err());
        r.spectrum_instructions = SPECTRUM_TARGET;
        // The in-impact path over #44's 40 a sample, though within 10 % of the baseline's.
        assert_eq!(base.impact_instructions_per_sample, IMPACT_TARGET);
        let over = |r: &M4Report| {
            check(r, &base).err().is_some_and(|e| {
                e.failed
                    .iter()
                    .any(|f| matches!(f, Regression::OverSampleTarget { .. }))
            })
        };
        assert!(!over(&r));
        r.impact_instructions_per_sample = IMPACT_TARGET + 0.5;
        assert!(over(&r));
    }
}
