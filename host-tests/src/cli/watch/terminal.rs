//! `impact watch --terminal`: the live view as text (for an SSH session): one line per impact,
//! the board's health when a loss counter moves (and every ten heartbeats), silence said.

use std::io::Write;
use std::sync::Mutex;

use serde_json::Value;

/// The last health line's loss counters, and heartbeats since it was printed.
static LAST_HEALTH: Mutex<Option<(Vec<u64>, u32)>> = Mutex::new(None);

/// A number with four significant digits, or an em dash when unknown.
fn n(v: &Value, scale: f64) -> String {
    v.as_f64()
        .map_or("—".into(), |x| crate::report::fmt::sig(x * scale, 4))
}

/// Prints `events` as text on stdout (warnings on stderr).
pub fn print(events: &[Value]) {
    let mut out = crate::output::stdout();
    for e in events {
        let line = match e["type"].as_str() {
            Some("impact") => Some(impact(e)),
            Some("health") => health(e),
            Some("run") if e["replaced"].is_string() => {
                Some(format!("── {} ──", e["replaced"].as_str().unwrap_or("")))
            }
            Some("run") if e["run"].as_u64() > Some(1) => {
                Some(format!("── the board restarted: run {} ──", e["run"]))
            }
            Some("end") => Some(format!(
                "── the stream ended: {} ──",
                e["result"].as_str().unwrap_or("?")
            )),
            Some("warning") => {
                crate::errln!("warning: {}", e["text"].as_str().unwrap_or(""));
                None
            }
            // The board's scene line states the pulse it judges.
            Some("spec") => {
                if let Some(d) = e["differs"].as_str() {
                    crate::errln!("warning: {d}");
                }
                Some(match (e["text"].as_str(), e["from"].as_str()) {
                    (Some(t), Some("board")) => format!("the board judges {t}"),
                    (Some(t), _) => format!("the board judges no pulse; drawn: --spec {t}"),
                    (None, _) => "the board judges no pulse".to_string(),
                })
            }
            _ => None,
        };
        if let Some(l) = line {
            // A closed pipe ends the tool through its signal handling.
            if let Err(e) = writeln!(out, "{l}") {
                crate::interrupt::stdout_failed(e);
            }
        }
    }
    if let Err(e) = out.flush() {
        crate::interrupt::stdout_failed(e);
    }
}

/// One impact's line: run and index, board time, peak, Δv, duration, COR, verdict, latency,
/// flags.
fn impact(e: &Value) -> String {
    let verdict = match &e["verdict"] {
        Value::Null => String::new(),
        v => match v["pass"].as_bool() {
            Some(true) => "  PASS".into(),
            Some(false) => format!(
                "  FAIL (worst {} g, limit {} g)",
                n(&v["worst_g"], 1.0),
                n(&v["limit_g"], 1.0)
            ),
            None => format!("  not judged ({})", v["reason"].as_str().unwrap_or("?")),
        },
    };
    let latency = e["report_latency_s"].as_f64().map_or(String::new(), |l| {
        format!("  latency {} ms", crate::report::fmt::sig(l * 1e3, 3))
    });
    let flags: Vec<&str> = e["flags"]
        .as_array()
        .map(|a| a.iter().filter_map(Value::as_str).collect())
        .unwrap_or_default();
    format!(
        "run {} impact {:>4}  t {} s  peak {} g  Δv {} m/s  duration {} ms  COR {}{verdict}{latency}{}",
        e["run"],
        e["index"].as_u64().unwrap_or_default(),
        n(&e["start_s"], 1.0),
        n(&e["peak_g"], 1.0),
        n(&e["delta_v_m_s"], 1.0),
        n(&e["duration_s"], 1e3),
        n(&e["cor"], 1.0),
        if flags.is_empty() {
            String::new()
        } else {
            format!("  [{}]", flags.join(", "))
        }
    )
}

/// The health line, when a loss counter moved or ten heartbeats passed since the last one.
fn health(e: &Value) -> Option<String> {
    let keys = [
        "samples_lost",
        "gaps",
        "lines_dropped",
        "analyses_skipped",
        "reports_dropped",
    ];
    let counters: Vec<u64> = keys.iter().map(|k| e[k].as_u64().unwrap_or(0)).collect();
    let mut last = LAST_HEALTH
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    let due = match last.as_mut() {
        Some((c, beats)) if *c == counters && *beats < 9 => {
            *beats += 1;
            false
        }
        _ => true,
    };
    if !due {
        return None;
    }
    *last = Some((counters, 0));
    let stack = match (
        e["stack_peak_bytes"].as_u64(),
        e["stack_size_bytes"].as_u64(),
    ) {
        (Some(p), Some(s)) if s > 0 => format!(
            ", stack {p} of {s} B ({:.0} %)",
            100.0 * p as f64 / s as f64
        ),
        _ => String::new(),
    };
    Some(format!(
        "board {} s: {} impact{}, samples lost {}, gaps {}, lines dropped {}, analyses skipped {}, reports dropped {}{stack}, busy {} %",
        n(&e["board_time_s"], 1.0),
        e["impacts"],
        if e["impacts"] == 1 { "" } else { "s" },
        e["samples_lost"],
        e["gaps"],
        e["lines_dropped"],
        e["analyses_skipped"],
        e["reports_dropped"],
        n(&e["busy_share"], 100.0),
    ))
}

/// Says that the board went silent (`Some(ms)` since its last heartbeat) or came back.
pub fn silence(quiet_ms: Option<u64>) {
    match quiet_ms {
        Some(ms) => crate::outln!(
            "── no heartbeat for {} s: the board is silent or its link is lost ──",
            crate::report::fmt::sig(ms as f64 / 1e3, 2)
        ),
        None => crate::outln!("── heartbeats again ──"),
    }
}
