//! The report's series direction by direction (`--direction`, `--meta direction=`): each
//! direction's recordings, impacts and verdicts, then its statistics.

use crate::html;
use crate::html::Html;
use crate::report::statistics::DirectionGroup;

/// The directions' table and each direction's statistics (nothing without directions).
pub fn by_direction(h: &mut Html, groups: &[DirectionGroup]) {
    if groups.is_empty() {
        return;
    }
    h.raw("<h2>By direction</h2>\n<table class=\"directions\"><tr><th class=\"l\">direction</th><th>recordings</th><th>impacts</th><th>verdicts</th></tr>\n");
    for g in groups {
        let verdicts = g.summary.spec.as_ref().map_or("—".to_string(), |r| {
            format!(
                "{} of {} pass{}",
                r.passed,
                r.judged,
                if r.not_judged > 0 {
                    format!(", {} not judged", r.not_judged)
                } else {
                    String::new()
                }
            )
        });
        html!(
            h,
            "<tr><td class=\"l\">{}</td><td>{}</td><td>{}</td><td>{}</td></tr>\n",
            g.shown(),
            g.recordings,
            g.summary.impacts,
            verdicts
        );
    }
    h.raw("</table>\n");
    for g in groups.iter().filter(|g| !g.summary.statistics.is_empty()) {
        html!(h, "<h3>Statistics of direction {}</h3>\n", g.shown());
        super::statistics_table(h, &g.summary.statistics);
    }
}
