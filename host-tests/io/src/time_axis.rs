//! One time axis, read in order, for every reader that takes times (a CSV's time column read
//! whole or as a stream, an `.ide` file's time stamps): its first and latest time and the
//! samples taken; the head's intervals, their [`median`], and every interval checked against
//! it; the drift check ([`Drift`]); the rate. Each reader decides when a fault is an error (a
//! CSV keeps the first of each kind for the end, an `.ide` stops at it); the faults and their
//! order are the axis's.

pub use crate::error::{DriftFault, NotIncreasing, UnevenInterval};
use crate::limits::{DRIFT_BLOCK, DRIFT_LIMIT};

/// Every sample interval must lie within this range of the median interval, or the time axis
/// counts as uneven (a gap or a rate change). Jittered time stamps, as enDAQ's, stay within
/// 0.6..1.25.
pub const INTERVAL_RANGE: std::ops::RangeInclusive<f64> = 0.5..=1.5;

/// Checks that a time axis keeps its rate: the mean interval of every [`DRIFT_BLOCK`]
/// intervals against the first block's. Fed the time stamps in order (any split), so the
/// whole-file path and a stream refuse the same files at the same sample.
#[derive(Clone, Copy, Debug, Default)]
pub struct Drift {
    /// Time stamps taken, and the time at the current block's start.
    n: u64,
    block_start_s: f64,
    /// The first block's mean interval, s.
    first_dt: Option<f64>,
}

impl Drift {
    /// Takes the next time stamp `t` (s; the `n`-th from 0); a fault once a block's mean
    /// interval is more than [`DRIFT_LIMIT`] off the first block's.
    pub fn push(&mut self, t: f64) -> Result<(), DriftFault> {
        let k = self.n;
        self.n += 1;
        if k == 0 {
            self.block_start_s = t;
            return Ok(());
        }
        if k % DRIFT_BLOCK != 0 {
            return Ok(());
        }
        let mean = (t - self.block_start_s) / DRIFT_BLOCK as f64;
        self.block_start_s = t;
        let Some(first) = self.first_dt else {
            self.first_dt = Some(mean);
            return Ok(());
        };
        if (mean / first - 1.0).abs() > DRIFT_LIMIT {
            return Err(DriftFault {
                block_end: k,
                mean_dt: mean,
                first_dt: first,
            });
        }
        Ok(())
    }
}

/// The median as `select_nth_unstable(len / 2)` picks it (the upper one of an even count);
/// `None` of nothing. Reorders `values`.
pub fn median(values: &mut [f64]) -> Option<f64> {
    if values.is_empty() {
        return None;
    }
    let mid = values.len() / 2;
    Some(*values.select_nth_unstable_by(mid, f64::total_cmp).1)
}

/// An interval `dt` within [`INTERVAL_RANGE`] times the median `median`.
pub fn check_interval(dt: f64, median: f64) -> Result<(), UnevenInterval> {
    if INTERVAL_RANGE.contains(&(dt / median)) {
        Ok(())
    } else {
        Err(UnevenInterval { dt, median })
    }
}

/// What one time showed: each check's fault, if any (a reader reports them in this order:
/// time going back, an uneven interval, drift).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Faults {
    pub not_increasing: Option<NotIncreasing>,
    pub uneven: Option<UnevenInterval>,
    pub drift: Option<DriftFault>,
}

/// A time axis read in order (see the module's doc). `P` is where a time was read (a line of
/// a file, a sample's index), kept with the head's intervals until their median is known.
#[derive(Clone, Debug)]
pub struct TimeAxis {
    /// Whether the times are checked (not with `--rate`: the column gives the first time
    /// only).
    checked: bool,
    t0: Option<f64>,
    last: f64,
    n: u64,
    /// The head's intervals and where each ended, until [`TimeAxis::close_head`].
    head: Vec<(f64, u64)>,
    head_closed: bool,
    median_dt: Option<f64>,
    drift: Drift,
}

impl TimeAxis {
    /// An axis whose times are `checked` (increasing, even, steady) or only counted.
    pub fn new(checked: bool) -> Self {
        Self {
            checked,
            t0: None,
            last: 0.0,
            n: 0,
            head: Vec::new(),
            head_closed: false,
            median_dt: None,
            drift: Drift::default(),
        }
    }

    /// Takes time `t` (s) read at `at`: what the checks found. Before the head is closed its
    /// intervals are kept (checked when it closes); after, each is checked against their
    /// median.
    pub fn push(&mut self, t: f64, at: u64) -> Faults {
        let mut faults = Faults::default();
        if !self.checked {
            self.take(t);
            return faults;
        }
        faults.drift = self.drift.push(t).err();
        if self.t0.is_some() {
            let dt = t - self.last;
            if t <= self.last {
                faults.not_increasing = Some(NotIncreasing {
                    t,
                    previous: self.last,
                });
            } else if let Some(m) = self.median_dt {
                faults.uneven = check_interval(dt, m).err();
            } else if !self.head_closed {
                self.head.push((dt, at));
            }
        }
        self.take(t);
        faults
    }

    /// Takes time `t` whose interval was checked elsewhere (a parallel reader's worker): only
    /// the drift check's fault.
    pub fn push_checked(&mut self, t: f64) -> Option<DriftFault> {
        let drift = if self.checked {
            self.drift.push(t).err()
        } else {
            None
        };
        self.take(t);
        drift
    }

    /// Counts `t` as the latest time.
    fn take(&mut self, t: f64) {
        if self.t0.is_none() {
            self.t0 = Some(t);
        }
        self.last = t;
        self.n += 1;
    }

    /// Counts `k` more samples whose times were only followed ([`TimeAxis::push_checked`]
    /// took the latest).
    pub fn count(&mut self, k: u64) {
        self.n += k;
    }

    /// Ends the head: its intervals' median, and the first of them that lies far from it
    /// (where it ended, and the fault). No interval: no median.
    pub fn close_head(&mut self) -> Option<(u64, UnevenInterval)> {
        self.head_closed = true;
        let head = std::mem::take(&mut self.head);
        let mut dts: Vec<f64> = head.iter().map(|d| d.0).collect();
        let median = median(&mut dts)?;
        self.median_dt = Some(median);
        head.into_iter()
            .find_map(|(dt, at)| check_interval(dt, median).err().map(|e| (at, e)))
    }

    /// The head's median interval, once closed.
    pub fn median_dt(&self) -> Option<f64> {
        self.median_dt
    }

    /// The rate over what was taken, S/s: `(n − 1)` intervals over the span; `None` before
    /// two samples or where the span is not positive.
    pub fn rate_hz(&self) -> Option<f64> {
        let rate = 1.0 / self.mean_interval_s()?;
        (rate.is_finite() && rate > 0.0).then_some(rate)
    }

    /// The mean interval over what was taken, s: the span over `(n − 1)`; `None` before two
    /// samples.
    pub fn mean_interval_s(&self) -> Option<f64> {
        let t0 = self.t0?;
        (self.n >= 2).then(|| (self.last - t0) / (self.n - 1) as f64)
    }

    /// The first time, s (0 before any).
    pub fn t0(&self) -> f64 {
        self.t0.unwrap_or(0.0)
    }

    /// The latest time, s.
    pub fn last(&self) -> f64 {
        self.last
    }

    /// The samples taken.
    pub fn samples(&self) -> u64 {
        self.n
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_head_gives_the_median_and_later_intervals_are_held_to_it() {
        let mut axis = TimeAxis::new(true);
        for (k, t) in [0.0, 1.0, 2.0, 3.0, 4.0].into_iter().enumerate() {
            assert_eq!(axis.push(t, k as u64), Faults::default());
        }
        assert_eq!(axis.close_head(), None);
        assert_eq!(axis.median_dt(), Some(1.0));
        assert_eq!(axis.rate_hz(), Some(1.0));
        let f = axis.push(6.0, 5);
        assert_eq!(
            f.uneven,
            Some(UnevenInterval {
                dt: 2.0,
                median: 1.0
            })
        );
        let f = axis.push(5.5, 6);
        assert_eq!(
            f.not_increasing,
            Some(NotIncreasing {
                t: 5.5,
                previous: 6.0
            })
        );
        assert_eq!(axis.samples(), 7);
        // A head interval far from the median is found where it ended.
        let mut axis = TimeAxis::new(true);
        for (k, t) in [0.0, 1.0, 2.0, 5.0, 6.0, 7.0].into_iter().enumerate() {
            axis.push(t, 10 + k as u64);
        }
        assert_eq!(
            axis.close_head(),
            Some((
                13,
                UnevenInterval {
                    dt: 3.0,
                    median: 1.0
                }
            ))
        );
        // Unchecked (a rate given): only counted.
        let mut axis = TimeAxis::new(false);
        assert_eq!(axis.push(1.0, 0), Faults::default());
        assert_eq!(axis.push(0.5, 1), Faults::default());
        assert_eq!(median(&mut []), None);
        assert_eq!(median(&mut [3.0, 1.0, 2.0, 4.0]), Some(3.0));
    }

    #[test]
    fn one_rate_for_every_reader() {
        // 20 001 stamps over 0.999998703 s, where (n − 1)/span (the .ide reader's old rate) and
        // 1/(span/(n − 1)) differ in the last bit: every reader now gives the whole-file
        // CSV check's value.
        let n = 20_001u64;
        let t: Vec<f64> = (0..n)
            .map(|k| k as f64 * (0.999998703 / 20_000.0))
            .collect();
        let mut axis = TimeAxis::new(true);
        for (k, &tk) in t.iter().enumerate() {
            axis.push(tk, k as u64);
        }
        let span = t[t.len() - 1] - t[0];
        let whole = 1.0 / (span / (n - 1) as f64);
        assert_eq!(axis.rate_hz(), Some(whole));
        assert_ne!(
            whole,
            (n - 1) as f64 / span,
            "the example no longer tells them apart"
        );
        let (rate, _) = crate::channel::check_time(std::path::Path::new("t.csv"), &t, false, |k| {
            crate::At::Line(k as u64 + 2)
        })
        .unwrap();
        assert_eq!(rate, whole);
    }
}
