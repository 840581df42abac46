//! The analysis as the table a person reads.

use impact_core::consts::STANDARD_GRAVITY;

use super::fmt::{human, sig};
use super::AnalysisJson;

/// A readable table.
pub fn to_table(a: &AnalysisJson) -> String {
    let mut s = format!(
        "{}{} samples at {} S/s{}{}{}{}{}\n",
        match (&a.column, &a.units) {
            // An assumed unit is marked where it is shown (the note on stderr says why).
            (Some(c), Some(u)) if a.units_assumed => {
                format!("{c} in {u} (assumed): ")
            }
            (Some(c), Some(u)) => format!("{c} in {u}: "),
            (Some(c), None) => format!("{c}: "),
            _ => String::new(),
        },
        a.samples,
        sig(a.sample_rate_hz, 6),
        if a.time_unit_assumed {
            " (time assumed in s)"
        } else {
            ""
        },
        match (&a.v0_source, a.v0_m_s, a.free_fall_s) {
            (Some(_), Some(v), Some(t)) => format!(
                "; v0 {} from {} of free fall",
                human(v, "m/s"),
                human(t, "s")
            ),
            (Some(src), Some(v), None) => format!(
                "; v0 {} ({})",
                human(v, "m/s"),
                match src.as_str() {
                    "drop-height" => "from the drop height",
                    _ => "given",
                }
            ),
            _ => String::new(),
        },
        if a.samples_lost > 0 {
            format!("; {} SAMPLES LOST", a.samples_lost)
        } else {
            String::new()
        },
        if a.analyses_skipped > 0 {
            format!("; {} analyses skipped", a.analyses_skipped)
        } else {
            String::new()
        },
        match (a.lines_dropped, a.lines_missing) {
            (0, 0) => String::new(),
            (d, m) => format!("; {d} LINES DROPPED by the board, {m} missing"),
        },
    );
    // The frame the kinematics assumed, whenever there are kinematics to assume it for.
    // (Where the sensor is: the tool cannot tell a body's reading from a target's.)
    let barrier = match &a.target {
        Some(t) => format!(
            "the sensor on the body, kinematics relative to the target ({}): Newton's COR, \
             the contact's deformation and work",
            t.short()
        ),
        None => "the sensor on the body, a rigid, fixed barrier assumed".to_string(),
    };
    if a.v0_m_s.is_some() {
        s.push_str(&match a.contact_gravity_m_s2 {
            Some(g) => format!(
                "vertical: gravity ({}) taken out of each contact; Δv is the pulse's area; \
                 {barrier}\n",
                human(g, "m/s²")
            ),
            None => format!(
                "horizontal: the reading is the deceleration (--vertical for a vertical \
                 impact given its v0); {barrier}\n"
            ),
        });
    }
    if a.resampled {
        s.push_str("time axis resampled onto an even grid (--resample)\n");
    }
    if let Some(c) = &a.clipping {
        let level = |v: Option<f64>| v.map_or("-".to_string(), |v| human(v, "m/s²"));
        s.push_str(&format!(
            "rails ({}): {} / {}; a clipped peak is a lower bound (≥)\n",
            c.from,
            level(c.low_m_s2),
            level(c.high_m_s2)
        ));
    }
    if let Some(spec) = &a.spec {
        s.push_str(&crate::report::spec::table_head(spec));
    }
    for sp in &a.spikes_removed {
        s.push_str(&format!(
            "spike removed at {:.6} s (sample {}, {} sample{}, {:.4e} m/s²); --keep-spikes keeps it\n",
            sp.time_s,
            sp.sample,
            sp.samples,
            if sp.samples == 1 { "" } else { "s" },
            sp.value_m_s2
        ));
    }
    for i in &a.impacts {
        s.push_str(&format!(
            "impact {} [{}{}{}{}{}] at {:.6} s: peak {}{} ({}){}, Δv {}, duration {}, FWHM {}\n",
            i.index,
            i.status,
            if i.clipped { ", CLIPPED" } else { "" },
            if i.flags.iter().any(|f| f == "cut-at-start") {
                ", CUT AT START"
            } else {
                ""
            },
            if i.analysis == "skipped" {
                ", analysis skipped"
            } else {
                ""
            },
            if i.decimation > 1 {
                format!(", decimated ×{}", i.decimation)
            } else {
                String::new()
            },
            i.start_s,
            if i.clipped { "≥" } else { "" },
            human(i.peak_acceleration_m_s2, "m/s²"),
            human(i.peak_acceleration_m_s2 / STANDARD_GRAVITY, "g"),
            i.peak_force_n
                .map_or(String::new(), |f| format!(", force {}", human(f, "N"))),
            i.delta_v_m_s.map_or_else(
                || format!("unknown ({})", i.null_reasons["delta_v_m_s"]),
                |v| format!("{}{}", if i.clipped { "≥" } else { "" }, human(v, "m/s"))
            ),
            human(i.duration_s, "s"),
            i.fwhm_s.map_or_else(
                || format!("unknown ({})", i.null_reasons["fwhm_s"]),
                |w| human(w, "s")
            ),
        ));
        // With a CFC or a low-pass, the filtered peak and width beside the raw ones above.
        let filtered = a.lowpass.as_ref().map_or("CFC-filtered".to_string(), |l| {
            format!("low-pass-filtered (order {}, {} Hz)", l.order, l.cutoff_hz)
        });
        if let Some(p) = i.filtered_peak_acceleration_m_s2 {
            s.push_str(&format!(
                "    {filtered}: peak {} ({}), FWHM {}\n",
                human(p, "m/s²"),
                human(p / STANDARD_GRAVITY, "g"),
                i.filtered_fwhm_s.map_or_else(
                    || format!("unknown ({})", i.null_reasons["filtered_fwhm_s"]),
                    |w| human(w, "s")
                ),
            ));
        } else if let Some(why) = i
            .null_reasons
            .get("filtered_peak_acceleration_m_s2")
            .filter(|r| *r != "no-cfc")
        {
            s.push_str(&format!("    {filtered}: unknown ({why})\n"));
        }
        // Why the kinematics are missing, unless simply because v0 was not given.
        if let Some(why) = i
            .null_reasons
            .get("cor")
            .filter(|r| *r != "no-approach-speed")
        {
            // A bounce's missing speed names the options that give it.
            let fix = if why == "approach-unknown" {
                " (a bounce: --v0 is the drop's first impact's; --train or --v0-every)"
            } else {
                ""
            };
            s.push_str(&format!("    no kinematics: {why}{fix}\n"));
        }
        if let Some(latency) = i.report_latency_s {
            s.push_str(&format!(
                "    reported {:.1} ms after the end of its hold\n",
                latency * 1e3
            ));
        }
        if let Some(x) = &i.axes {
            s.push_str(&crate::report::axes::table_line(x));
        }
        if let Some(b) = &i.bounce {
            s.push_str(&crate::report::train::table_line(b));
        }
        if let Some(sp) = &i.shock_spectrum {
            s.push_str(&crate::report::spectrum::table_line(sp));
        }
        if let Some(v) = &i.spec {
            s.push_str(&crate::report::spec::table_line(
                v.as_ref(),
                i.null_reasons.get("spec"),
                a.spec.as_ref(),
            ));
        }
        if let (Some(v0), Some(v1), Some(cor)) =
            (i.impact_velocity_m_s, i.rebound_velocity_m_s, i.cor)
        {
            // A field the kinematics left out says why (`undersampled`: the crush time and
            // the deformations).
            let or_why = |v: Option<f64>, unit: &str, field: &str| {
                v.map_or_else(
                    || {
                        let why = i.null_reasons.get(field).map_or("absent", String::as_str);
                        format!("none ({why})")
                    },
                    |v| human(v, unit),
                )
            };
            let set = match (
                i.permanent_deformation_m,
                i.null_reasons.get("permanent_deformation_m"),
            ) {
                (Some(x), _) => human(x, "m"),
                (None, Some(why)) if why == "undersampled" => format!("none ({why})"),
                (None, _) => "not resolved".to_string(),
            };
            s.push_str(&format!(
                "    v0 {}, crush time {}, x_m {}, rebound {}, COR {cor:.4}, x at separation {}, set {}{}\n",
                human(v0, "m/s"),
                or_why(i.crush_time_s, "s", "crush_time_s"),
                or_why(i.max_deformation_m, "m", "max_deformation_m"),
                human(v1, "m/s"),
                or_why(i.separation_deformation_m, "m", "separation_deformation_m"),
                set,
                i.absorbed_energy_j
                    .map_or(String::new(), |e| format!(", absorbed {}", human(e, "J")))
            ));
        }
        if let Some(t) = &i.fits.two_phase {
            s.push_str(&format!(
                "    two-phase: kc {}, kr {}, c {}, x_p {} (residual {:.2} %)\n",
                human(t.kc_n_m, "N/m"),
                human(t.kr_n_m, "N/m"),
                human(t.c_n_s_m, "N s/m"),
                human(t.permanent_deformation_m, "m"),
                100.0 * t.residual
            ));
        }
        if let Some(t) = &i.fits.nonlinear {
            s.push_str(&format!(
                "    nonlinear: k {} N/m^{:.3}, c {} (residual {:.2} %)\n",
                human(t.k, "").trim_end(),
                t.exponent,
                human(t.c_s_m, "s/m"),
                100.0 * t.residual
            ));
        }
        if let Some(t) = &i.fits.hertz {
            s.push_str(&format!(
                "    hertz: K {} N/m^1.5 (residual {:.2} %)\n",
                human(t.k, "").trim_end(),
                100.0 * t.residual
            ));
        }
    }
    s.push_str(&crate::report::train::table_lines(&a.trains));
    for d in &a.drifts {
        s.push_str(&format!(
            "no impact at {:.6} s: the signal drifted {} from its baseline over {} and did not come back, with no pulse in it (half its peak is not reached on both sides)\n",
            d.start_s,
            crate::report::fmt::human(d.excursion_m_s2.abs(), "m/s²"),
            crate::report::fmt::human(d.duration_s, "s"),
        ));
    }
    s
}
