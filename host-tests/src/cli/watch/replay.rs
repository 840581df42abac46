//! `impact watch --replay LOG`: a finished log fed to the view at the pace it was written,
//! so a demo or a second look at a session runs as the bench did (the page's health, its
//! heartbeat ages and the latency of each impact as they were).

use std::time::{Duration, Instant};

/// The pace of a replay: each line held until as much wall-clock time has passed since the
/// run's first line as the board's clock had (over `speed`). A line without a leading time
/// (s) goes at once; a time earlier than the last (the board restarted, or a new run) starts
/// the pace again from that line.
pub struct Pace {
    speed: f64,
    /// The wall clock and the board's time at the run's first timed line.
    start: Option<(Instant, f64)>,
    last_s: f64,
}

/// The longest wait for one line, s of wall clock: a board silent for an hour is replayed
/// as a minute's silence (long enough for the page to say SILENT, then LINK… never).
const MAX_WAIT_S: f64 = 60.0;

impl Pace {
    pub fn new(speed: f64) -> Self {
        Self {
            speed,
            start: None,
            last_s: f64::NEG_INFINITY,
        }
    }

    /// Waits until `line` is due; returns how long it waited.
    pub fn wait(&mut self, line: &str) -> Duration {
        let Some(t) = board_time_s(line) else {
            return Duration::ZERO;
        };
        let now = Instant::now();
        if t < self.last_s {
            self.start = None;
        }
        self.last_s = t;
        let (wall, board) = *self.start.get_or_insert((now, t));
        let due = ((t - board) / self.speed).clamp(0.0, f64::MAX);
        let elapsed = now.duration_since(wall).as_secs_f64();
        let wait = (due - elapsed).clamp(0.0, MAX_WAIT_S);
        if wait >= MAX_WAIT_S {
            // The silence cut short: later lines keep their pace from here.
            self.start = Some((now + Duration::from_secs_f64(wait), t));
        }
        let wait = Duration::from_secs_f64(wait);
        std::thread::sleep(wait);
        wait
    }
}

/// The board's time of a log line: its leading number, s (`0.053584 INFO impact …`), if it
/// has one that is finite and not negative.
fn board_time_s(line: &str) -> Option<f64> {
    let first = line.split_ascii_whitespace().next()?;
    let t: f64 = first.parse().ok()?;
    (t.is_finite() && t >= 0.0).then_some(t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_line_waits_for_its_board_time_over_the_speed() {
        let mut p = Pace::new(10.0);
        assert_eq!(p.wait("0.5 INFO up"), Duration::ZERO);
        let t = Instant::now();
        p.wait("1.5 INFO impact seq=1");
        // 1 s of board time at 10×: 100 ms.
        let took = t.elapsed().as_secs_f64();
        assert!((0.095..0.3).contains(&took), "{took}");
        // No time, a negative or unreadable one: at once.
        for line in ["impact watch: replaced", "-1 INFO x", "nan INFO x", ""] {
            assert_eq!(p.wait(line), Duration::ZERO, "{line:?}");
        }
    }

    #[test]
    fn a_restart_paces_from_its_own_first_line() {
        let mut p = Pace::new(1.0);
        p.wait("100.0 INFO heartbeat");
        // The board restarted: its clock is back at 0.01 s; no wait for the jump back.
        assert_eq!(p.wait("0.01 INFO up"), Duration::ZERO);
        let t = Instant::now();
        p.wait("0.06 INFO scene");
        assert!(t.elapsed() >= Duration::from_millis(45));
    }
}
