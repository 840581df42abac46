//! `Walk::run` held to the loop it replaced (one sample at a time, every check on every
//! sample), and the bands to their definitions.

use super::*;
extern crate std;
use std::vec::Vec;

impl Walk {
    /// The loop `run` replaced (one sample at a time, every check on every sample): the
    /// reference `run` must equal.
    fn run_one_by_one(&mut self, samples: &[i16], deviation: Deviation, l: &Levels) {
        let n = samples.len();
        let edge = l.edge;
        let start = l.start;
        let mut k = 0;
        'scan: while k < n {
            let (mut sign, mut trigger, mut lo, mut hi) = l.marks(
                self.peak_abs,
                self.peak_positive,
                self.returned,
                self.separation.is_none(),
            );
            while let Some(&x) = samples.get(k) {
                let d = deviation.of(x);
                let abs = d.unsigned_abs();
                if abs <= edge {
                    break;
                }
                let e = d.wrapping_mul(sign);
                if e > hi || e < lo {
                    if self.returned && e > trigger {
                        // Back at the baseline, then a new hit the same way beyond the
                        // trigger: the next impact starts with this sample.
                        self.ended = Some(End::NextHit);
                        self.used = k;
                        break 'scan;
                    }
                    if abs > self.peak_abs {
                        self.peak(k, d, abs, l);
                    } else if self.separation.is_none() && e < 0 {
                        // Across the whole band between two samples (a sign flip): the
                        // signal came back between them.
                        self.separation = Some(start + k as u64);
                        self.separation_c = self.total_c + self.sum;
                    }
                    (sign, trigger, lo, hi) = l.marks(
                        self.peak_abs,
                        self.peak_positive,
                        self.returned,
                        self.separation.is_none(),
                    );
                }
                if self.quiet > 0 {
                    self.last_quiet_k = Some(k);
                    self.quiet = 0;
                }
                self.sum += d as i64;
                self.sum2 = self.sum2.wrapping_add(self.sum);
                k += 1;
            }
            // Quiet: the first quiet sample after the peak is the separation.
            if k < n && self.separation.is_none() {
                self.separation = Some(start + k as u64);
                self.separation_c = self.total_c + self.sum;
            }
            while let Some(&x) = samples.get(k) {
                let d = deviation.of(x);
                if d.unsigned_abs() > edge {
                    break;
                }
                self.quiet += 1;
                self.sum += d as i64;
                self.sum2 = self.sum2.wrapping_add(self.sum);
                if self.quiet >= l.first_mark {
                    self.returned |= self.quiet >= l.min_gap;
                    if self.quiet >= l.hold && start + k as u64 > l.trigger_index {
                        self.ended = Some(End::Quiet);
                        self.used = k + 1;
                        break 'scan;
                    }
                }
                k += 1;
            }
        }
    }

    /// Every field, comparable.
    fn state(&self) -> impl PartialEq + core::fmt::Debug {
        let end = self.ended.as_ref().map(|e| match e {
            End::Quiet => 0,
            End::NextHit => 1,
            End::Settled(_) => 2,
        });
        (
            (
                self.peak_abs,
                self.peak_positive,
                self.new_peak,
                self.peak_at,
            ),
            (
                self.rise_closes,
                self.separation,
                self.separation_c,
                self.total_c,
            ),
            (self.quiet, self.returned, self.last_quiet_k),
            (self.sum, self.sum2, self.used, end),
        )
    }
}

/// `run` against the loop it replaced on random calls: samples around the edge and the
/// trigger levels (runs of loud and quiet ones, peaks, sign flips, new hits), every
/// entry state (quiet counts past the gap or the hold, returned or not, a separation or
/// none, a peak from none to the largest), hold and gap from 0 up, the trigger before,
/// inside or after the call, extreme edges and deviations: the same state after.
#[test]
fn run_is_the_loop_it_replaced() {
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    for case in 0..20_000 {
        let pick = |r: u64, options: &[i64]| options[(r % options.len() as u64) as usize];
        let (w, s) = if case % 50 == 0 {
            (i32::MAX, 0)
        } else {
            (1 + (next() % 8) as i32, (next() % 2001) as i32 - 1000)
        };
        let deviation = Deviation::new(i64::from(s), i64::from(w));
        let edge = pick(
            next(),
            &[0, 1, 30, 200, 5000, i32::MAX as i64, u32::MAX as i64],
        ) as u32;
        let hold = pick(next(), &[0, 1, 2, 3, 8, 40]) as u32;
        let min_gap = pick(next(), &[0, 1, 2, 5, (hold / 8).max(2) as i64]) as u32;
        let start = next() % 1000;
        let n = (next() % 300) as usize;
        let trigger_index = match next() % 4 {
            0 => start.saturating_sub(5),
            1 => start + (next() % (n as u64 + 1)),
            2 => start + n as u64 + 10,
            _ => u64::MAX,
        };
        let levels = Levels {
            edge,
            d_hi: pick(next(), &[0, 100, 2000, i32::MAX as i64]) as i32,
            d_lo: pick(next(), &[0, -100, -2000, i32::MIN as i64]) as i32,
            first_mark: min_gap.min(hold),
            min_gap,
            hold,
            trigger_index,
            onset: start.saturating_sub(next() % 500),
            start,
        };
        let scale = pick(next(), &[50, 400, 3000, 40000]);
        let mut x = 0i64;
        let samples: Vec<i16> = (0..n)
            .map(|_| {
                x = match next() % 10 {
                    0 => (next() % (2 * scale as u64 + 1)) as i64 - scale,
                    1 => 0,
                    2 => -x,
                    _ => x + (next() % 61) as i64 - 30,
                };
                x.clamp(i16::MIN.into(), i16::MAX.into()) as i16
            })
            .collect();
        let entry = Walk {
            peak_abs: pick(next(), &[0, 50, 3000, u32::MAX as i64]) as u32,
            peak_positive: next() % 2 == 0,
            new_peak: None,
            peak_at: start.saturating_sub(next() % 100),
            rise_closes: None,
            separation: (next() % 2 == 0).then_some(start.saturating_sub(3)),
            separation_c: 7,
            total_c: (next() % 10_000) as i64 - 5000,
            quiet: pick(next(), &[0, 0, 1, 3, 9, 50]) as u32,
            returned: next() % 2 == 0,
            last_quiet_k: None,
            sum: 0,
            sum2: 0,
            used: n,
            ended: None,
        };
        let (mut a, mut b) = (entry.clone_state(), entry);
        a.run(&samples, deviation, &levels);
        b.run_one_by_one(&samples, deviation, &levels);
        assert_eq!(a.state(), b.state(), "case {case}");
    }
}

/// The bands hold exactly the `d` their definitions do, at the extremes too: `lo <= d *
/// sign <= hi && d * sign > edge` (the product wrapping, as the loop's), `|d| <= edge`.
#[test]
fn the_bands_are_their_definitions() {
    let ds = [
        i32::MIN,
        i32::MIN + 1,
        -(1 << 29),
        -1001,
        -1000,
        -999,
        -1,
        0,
        1,
        999,
        1000,
        1001,
        1 << 29,
        i32::MAX - 1,
        i32::MAX,
    ];
    let bounds = [
        i32::MIN,
        -(1 << 30),
        -1000,
        -1,
        0,
        1,
        1000,
        1 << 30,
        i32::MAX,
    ];
    let edges = [
        0,
        1,
        999,
        1000,
        i32::MAX as u32 - 1,
        i32::MAX as u32,
        u32::MAX,
    ];
    for sign in [1, -1] {
        for &lo in &bounds {
            for &hi in &bounds {
                for &edge in &edges {
                    let band = Band::loud(sign, lo, hi, edge);
                    for &d in &ds {
                        let e = d.wrapping_mul(sign);
                        let want = lo <= e && e <= hi && e.unsigned_abs() > edge && e > 0;
                        let got = band.is_some_and(|b| b.holds(d));
                        assert_eq!(got, want, "{sign} {lo} {hi} {edge} {d}");
                    }
                }
            }
        }
    }
    for &edge in &edges {
        let band = Band::quiet(edge);
        for &d in &ds {
            assert_eq!(band.is_some_and(|b| b.holds(d)), d.unsigned_abs() <= edge);
        }
    }
}

impl Walk {
    fn clone_state(&self) -> Walk {
        Walk {
            peak_abs: self.peak_abs,
            peak_positive: self.peak_positive,
            new_peak: self.new_peak,
            peak_at: self.peak_at,
            rise_closes: self.rise_closes,
            separation: self.separation,
            separation_c: self.separation_c,
            total_c: self.total_c,
            quiet: self.quiet,
            returned: self.returned,
            last_quiet_k: self.last_quiet_k,
            sum: self.sum,
            sum2: self.sum2,
            used: self.used,
            ended: None,
        }
    }
}
