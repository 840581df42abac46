//! The verdict first: a banner (how many pulses pass; each failing one named with what it
//! failed, and where), then each judged pulse against the nominal one: peak, duration and the
//! judged Δv with their errors, the criterion it failed and the time where it failed.

use impact_core::consts::STANDARD_GRAVITY;

use super::super::series::{self, EntryJson};
use crate::html;
use crate::html::Html;
use crate::report::fmt::human;
use crate::report::spec::{Criterion, SpecJson, VerdictJson};
use crate::report::ImpactJson;

/// The most failing pulses the banner names (the verdicts' table has every one).
pub const MAX_NAMED: usize = 50;

/// What the banner says of the run as a whole.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Overall {
    /// Every pulse judged, and every one passed.
    Pass,
    /// A judged pulse failed.
    Fail,
    /// None failed, but not every pulse (or recording) could be judged.
    Incomplete,
    /// No specification given.
    NotJudged,
}

/// The counts behind the banner.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Tally {
    pub pulses: usize,
    pub judged: usize,
    pub passed: usize,
    pub not_judged: usize,
    /// Recordings that could not be analysed.
    pub recordings_failed: usize,
    /// Recordings analysed in which no pulse was found (nothing of theirs judged).
    pub recordings_without_pulse: usize,
}

impl Tally {
    fn of(results: &[EntryJson]) -> Self {
        let mut t = Tally {
            recordings_failed: results.iter().filter(|e| e.error.is_some()).count(),
            recordings_without_pulse: results.iter().filter(|e| without_pulse(e)).count(),
            ..Tally::default()
        };
        for (_, i) in series::impacts(results) {
            t.pulses += 1;
            match &i.spec {
                Some(Some(v)) => {
                    t.judged += 1;
                    t.passed += usize::from(v.pass);
                }
                Some(None) => t.not_judged += 1,
                None => {}
            }
        }
        t
    }

    fn overall(self, spec: bool) -> Overall {
        if !spec {
            Overall::NotJudged
        } else if self.passed < self.judged {
            Overall::Fail
        } else if self.judged > 0
            && self.not_judged == 0
            && self.recordings_failed == 0
            && self.recordings_without_pulse == 0
        {
            Overall::Pass
        } else {
            Overall::Incomplete
        }
    }
}

/// Whether `e` was analysed and no pulse found in it (nothing of its judged).
fn without_pulse(e: &EntryJson) -> bool {
    e.analysis.as_ref().is_some_and(|a| a.impacts.is_empty())
}

/// The specification the results were judged against (every recording's is the same).
pub fn spec_of(results: &[EntryJson]) -> Option<&SpecJson> {
    results
        .iter()
        .find_map(|e| e.analysis.as_ref()?.spec.as_ref())
}

/// The recordings' files as a table shows them: relative to the folder they all lie in
/// (that folder, and each full path in the inputs' table), so that a row's file is its name
/// where they share a folder, not a path wrapped over lines; and that folder (empty: none
/// shared).
pub fn short_files(files: &[&str]) -> (String, Vec<String>) {
    let parent = |f: &str| {
        std::path::Path::new(f)
            .parent()
            .map(std::path::Path::to_path_buf)
            .unwrap_or_default()
    };
    let mut common = files.first().map(|f| parent(f)).unwrap_or_default();
    for f in files {
        while !std::path::Path::new(f).starts_with(&common) {
            if !common.pop() {
                break;
            }
        }
    }
    let short = files
        .iter()
        .map(|f| {
            std::path::Path::new(f)
                .strip_prefix(&common)
                .ok()
                .filter(|r| !r.as_os_str().is_empty())
                .map_or_else(|| f.to_string(), |r| r.display().to_string())
        })
        .collect();
    (common.display().to_string(), short)
}

/// A pulse's name: its file's name, channel and index.
fn name(e: &EntryJson, i: &ImpactJson) -> String {
    let file = std::path::Path::new(&e.file)
        .file_name()
        .map_or_else(|| e.file.clone(), |n| n.to_string_lossy().into_owned());
    match &e.direction {
        Some(d) => format!("{file} [{}] impact {} (direction {d})", e.channel, i.index),
        None => format!("{file} [{}] impact {}", e.channel, i.index),
    }
}

/// A number as the page writes it (`—` for one that is not finite, which no page shows).
fn q(v: f64, unit: &str) -> String {
    if v.is_finite() {
        human(v, unit).trim_end().to_string()
    } else {
        "—".to_string()
    }
}

/// `measured` over `nominal`, as a signed percentage error.
fn error_pct(measured: f64, nominal: f64) -> String {
    let e = 100.0 * (measured / nominal - 1.0);
    // (A error that rounds to zero is written +0.0 %, never -0.0 %.)
    let e = if e.abs() < 0.05 { 0.0 } else { e };
    if e.is_finite() {
        format!("{e:+.1} %")
    } else {
        "—".to_string()
    }
}

/// What a failed criterion was and where: the band's worst point (value, limit, time `t` on
/// the recording's clock and from the nominal pulse's start), or Δv's error and the window it
/// was integrated over.
pub fn why(c: Criterion, v: &VerdictJson, s: &SpecJson) -> String {
    let g = |a: f64| q(a / STANDARD_GRAVITY, "g");
    match c {
        Criterion::BandUpper | Criterion::BandLower => format!(
            "{}: {} at t = {} ({} after the nominal start), limit {}, beyond by {:.1} % of the peak",
            c.words(),
            g(v.worst_m_s2),
            clock(v.worst_time_s),
            q(v.worst_time_s - v.nominal_start_s, "s"),
            g(v.limit_m_s2),
            100.0 * v.margin,
        ),
        Criterion::DeltaV => format!(
            "{}: {} is {} of the nominal {} (tolerance ±{:.0} %), integrated from t = {} to {}",
            c.words(),
            q(v.delta_v_m_s, "m/s"),
            error_pct(v.delta_v_m_s, s.nominal_delta_v_m_s),
            q(s.nominal_delta_v_m_s, "m/s"),
            100.0 * s.delta_v_tolerance,
            clock(v.nominal_start_s - s.before * s.duration_s),
            clock(v.nominal_start_s + (1.0 + s.after) * s.duration_s),
        ),
        Criterion::Transverse => transverse_why(c, v, g),
    }
}

/// A failed transverse check: the worst cross axis's peak, when, and its share of the
/// nominal peak against the limit.
fn transverse_why(c: Criterion, v: &VerdictJson, g: impl Fn(f64) -> String) -> String {
    let Some(t) = &v.transverse else {
        return c.words().to_string();
    };
    match t.worst() {
        Some(x) => format!(
            "{} at t = {} ({}): {}",
            c.words(),
            clock(x.peak_time_s),
            g(x.peak_acceleration_m_s2),
            t.worst_words()
        ),
        None => c.words().to_string(),
    }
}

/// A time on the recording's clock, to the microsecond (a time 14.6 s into a recording
/// keeps its sample: four significant digits would not).
fn clock(t: f64) -> String {
    format!("{t:.6} s")
}

/// [`why`] in a table's cell: the limit, the time and the values; Δv's tolerance and window
/// (its error is in the row).
fn why_short(c: Criterion, v: &VerdictJson, s: &SpecJson) -> String {
    let g = |a: f64| q(a / STANDARD_GRAVITY, "g");
    match c {
        Criterion::BandUpper | Criterion::BandLower => format!(
            "{} limit at t = {}: {} against {} (beyond by {:.1} % of the peak)",
            if c == Criterion::BandUpper {
                "upper"
            } else {
                "lower"
            },
            clock(v.worst_time_s),
            g(v.worst_m_s2),
            g(v.limit_m_s2),
            100.0 * v.margin,
        ),
        Criterion::DeltaV => format!(
            "Δv outside ±{:.0} % (t = {} to {})",
            100.0 * s.delta_v_tolerance,
            clock(v.nominal_start_s - s.before * s.duration_s),
            clock(v.nominal_start_s + (1.0 + s.after) * s.duration_s),
        ),
        Criterion::Transverse => v.transverse.as_ref().map_or(String::new(), |t| {
            format!(
                "transverse at t = {}: {}",
                t.worst().map_or(String::new(), |x| clock(x.peak_time_s)),
                t.worst_words()
            )
        }),
    }
}

/// The banner: the run's verdict, the counts, and each failing pulse named (at most
/// [`MAX_NAMED`]) with what it failed, linked to its row of the verdicts' table.
pub fn banner(h: &mut Html, results: &[EntryJson]) {
    let spec = spec_of(results);
    let t = Tally::of(results);
    let overall = t.overall(spec.is_some());
    let (class, word) = match overall {
        Overall::Pass => ("banner banner-pass", "PASS"),
        Overall::Fail => ("banner banner-fail", "FAIL"),
        Overall::Incomplete => ("banner banner-incomplete", "INCOMPLETE"),
        Overall::NotJudged => ("banner", "NOT JUDGED"),
    };
    html!(
        h,
        "<div class=\"{}\" id=\"verdict\"><p class=\"headline\"><b>{}</b>: ",
        class,
        word
    );
    match spec {
        Some(_) => html!(
            h,
            "{} of {} pulse{} pass",
            t.passed,
            t.pulses,
            if t.pulses == 1 { "" } else { "s" }
        ),
        None => {
            h.raw("no specification given (<code>--spec</code>): the pulses are not judged");
        }
    }
    if t.not_judged > 0 {
        html!(h, "; {} not judged", t.not_judged);
    }
    if t.recordings_failed > 0 {
        html!(
            h,
            "; {} recording{} could not be analysed",
            t.recordings_failed,
            if t.recordings_failed == 1 { "" } else { "s" }
        );
    }
    if t.recordings_without_pulse > 0 {
        html!(
            h,
            "; {} recording{} without a pulse",
            t.recordings_without_pulse,
            if t.recordings_without_pulse == 1 {
                ""
            } else {
                "s"
            }
        );
    }
    h.raw("</p>\n");
    if spec.is_some() && t.recordings_without_pulse > 0 {
        h.raw("<ul class=\"failing\">\n");
        for e in results.iter().filter(|e| without_pulse(e)) {
            html!(
                h,
                "<li>{} [{}]: no pulse found, nothing judged</li>\n",
                e.file,
                e.channel
            );
        }
        h.raw("</ul>\n");
    }
    if let Some(s) = spec {
        let failing: Vec<(usize, &EntryJson, &ImpactJson, &VerdictJson)> = series::impacts(results)
            .enumerate()
            .filter_map(|(k, (e, i))| match &i.spec {
                Some(Some(v)) if !v.pass => Some((k, e, i, v)),
                _ => None,
            })
            .collect();
        if !failing.is_empty() {
            h.raw("<ul class=\"failing\">\n");
            for (k, e, i, v) in failing.iter().take(MAX_NAMED) {
                let what: Vec<String> = v.failed().iter().map(|&c| why(c, v, s)).collect();
                html!(
                    h,
                    "<li><a href=\"#pulse-{}\">{}</a>: {}</li>\n",
                    k,
                    name(e, i),
                    what.join("; ")
                );
            }
            if failing.len() > MAX_NAMED {
                html!(
                    h,
                    "<li>and {} more failing pulses (each in the verdicts' table)</li>\n",
                    failing.len() - MAX_NAMED
                );
            }
            h.raw("</ul>\n");
        }
    }
    for e in results.iter().filter(|e| e.error.is_some()) {
        if let Some(err) = &e.error {
            html!(
                h,
                "<p>FAILED {}</p>\n",
                series::failure(e, err.of_recording())
            );
        }
    }
    h.raw("</div>\n");
}

/// Each pulse against the nominal one: the peak, the duration and the judged Δv, nominal,
/// measured and the error; what it failed and where (nothing without a specification).
pub fn verdicts_table(h: &mut Html, results: &[EntryJson]) {
    let Some(s) = spec_of(results) else {
        return;
    };
    h.raw("<h2>Verdicts</h2>\n");
    html!(
        h,
        "<p>Against {}. The peak is the measured signal's above its baseline, as a magnitude (a pulse recorded negative has its sign reversed here); the duration the stream's (first touch to the contact's end; ≥ and no error where the contact had not ended); Δv the verdict's, integrated over −{}D…+{}D around the nominal pulse placed where it fits best. The band's worst point is circled on each pulse's figure.</p>\n",
        crate::report::spec::table_head(s)
            .trim_end()
            .trim_start_matches("spec: "),
        s.before,
        s.after
    );
    h.raw("<table class=\"verdicts\"><tr><th class=\"l\" rowspan=\"2\">pulse</th><th class=\"l\" rowspan=\"2\">verdict</th><th colspan=\"3\">peak (g)</th><th colspan=\"3\">duration</th><th colspan=\"3\">Δv (m/s)</th><th class=\"l\" rowspan=\"2\">failed: the band's limit or Δv, and where</th></tr>\n");
    h.raw("<tr><th>nominal</th><th>measured</th><th>error</th><th>nominal</th><th>measured</th><th>error</th><th>nominal</th><th>judged</th><th>error</th></tr>\n");
    let g = STANDARD_GRAVITY;
    for (k, (e, i)) in series::impacts(results).enumerate() {
        let peak = i.peak_acceleration_m_s2.abs();
        html!(
            h,
            "<tr id=\"pulse-{}\"><td class=\"l\">{}</td>",
            k,
            name(e, i)
        );
        let verdict = match &i.spec {
            Some(Some(v)) => Some(v),
            _ => None,
        };
        match verdict {
            Some(v) if v.pass => {
                h.raw("<td class=\"l pass\">PASS</td>");
            }
            Some(_) => {
                h.raw("<td class=\"l fail\">FAIL</td>");
            }
            None => {
                h.raw("<td class=\"l\">not judged</td>");
            }
        }
        // A contact that had not ended (cut by the recording's end or a gap, or still under
        // way) has a duration that is only a lower bound: no error is made of it.
        let ended = i.status == "complete";
        html!(
            h,
            "<td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}{}</td><td>{}</td>",
            q(s.peak_m_s2 / g, ""),
            q(peak / g, ""),
            error_pct(peak, s.peak_m_s2),
            q(s.duration_s, "s"),
            if ended { "" } else { "≥ " },
            q(i.duration_s, "s"),
            if ended {
                error_pct(i.duration_s, s.duration_s)
            } else {
                format!("— ({})", i.status)
            },
        );
        match verdict {
            Some(v) => {
                html!(
                    h,
                    "<td>{}</td><td>{}</td>",
                    q(s.nominal_delta_v_m_s, ""),
                    q(v.delta_v_m_s, "")
                );
                let error = error_pct(v.delta_v_m_s, s.nominal_delta_v_m_s);
                if v.delta_v_pass {
                    html!(h, "<td>{}</td>", error);
                } else {
                    html!(h, "<td class=\"fail\">{}</td>", error);
                }
                let what: Vec<String> = v.failed().iter().map(|&c| why_short(c, v, s)).collect();
                html!(
                    h,
                    "<td class=\"l\">{}</td></tr>\n",
                    if what.is_empty() {
                        "—".to_string()
                    } else {
                        what.join("; ")
                    }
                );
            }
            None => {
                let reason = match &i.spec {
                    Some(None) => crate::report::spec::not_judged(
                        i.null_reasons.get("spec").map_or("", String::as_str),
                    ),
                    _ => String::new(),
                };
                html!(
                    h,
                    "<td>{}</td><td>—</td><td>—</td><td class=\"l\">{}</td></tr>\n",
                    q(s.nominal_delta_v_m_s, ""),
                    reason
                );
            }
        }
    }
    h.raw("</table>\n");
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn files_are_shown_relative_to_their_shared_folder() {
        let (folder, short) = short_files(&["/d/runs/a.csv", "/d/runs/b/c.csv", "/d/runs/a.csv"]);
        assert_eq!(folder, "/d/runs");
        assert_eq!(short, ["a.csv", "b/c.csv", "a.csv"]);
        let (folder, short) = short_files(&["x.csv", "/abs/y.csv"]);
        assert_eq!(folder, "");
        assert_eq!(short, ["x.csv", "/abs/y.csv"]);
    }
}
