//! Screening a recorded channel before it is quantised: isolated glitches (removed and
//! listed) and clipped stretches (the sensor's rails, from its range or from flat tops).
//!
//! A recording is scaled to i16 counts by its own extremes, and the default trigger level
//! follows its range, so one glitch far above everything else would set both and hide the
//! real impacts. And a sensor driven past its range reads a flat top that must not pass for a
//! peak.

pub mod rails;
pub mod spikes;

pub use rails::{flat_tops, from_range, FlatTops, RAIL_FRACTION};
pub use spikes::{apply, fill, Removal, SpikeScan, TooManyGlitches, MAX_GLITCHES};

#[cfg(test)]
mod tests {
    use super::spikes::{isolated, SPIKE_RATIO};
    use super::*;
    use crate::report::{Clipping, Spike};

    /// A half-sine pulse on a baseline with ±0.01 of deterministic dither, rounded to 0.01.
    fn pulse(n: usize, at: usize, width: usize, peak: f64) -> Vec<f64> {
        (0..n)
            .map(|i| {
                let v = if i >= at && i < at + width {
                    peak * (std::f64::consts::PI * (i - at) as f64 / width as f64).sin()
                } else {
                    0.0
                };
                let dither = 0.01 * ((i * 7919 % 3) as f64 - 1.0);
                (v * 100.0).round() / 100.0 + dither
            })
            .collect()
    }

    /// Finds isolated spikes in `x` and replaces each by the straight line between its
    /// neighbours ([`SpikeScan`] over the whole slice, `median` the recording's).
    fn remove_spikes(x: &mut [f64], median: f64) -> Result<Vec<Spike>, TooManyGlitches> {
        let mut scan = SpikeScan::default();
        scan.push(x);
        Ok(apply(&scan.finish(median)?, x, 0.0, 1.0))
    }

    fn median(x: &[f64]) -> f64 {
        impact_io::time_axis::median(&mut x.to_vec()).unwrap_or(f64::NAN)
    }

    fn remove(x: &mut [f64]) -> Vec<Spike> {
        let m = median(x);
        remove_spikes(x, m).unwrap()
    }

    /// The rules written over a whole slice, as they were before they were streamed.
    fn spikes_in_one_go(x: &mut [f64], median: f64) -> Vec<Spike> {
        let n = x.len();
        let mut candidates: Vec<(usize, usize)> = Vec::new();
        let mut i = 2;
        while i + 3 < n {
            match (1..=2).find(|&len| isolated(&x[i - 2..i + len + 2], len)) {
                Some(len) => {
                    candidates.push((i, len));
                    i += len + 1;
                }
                None => i += 1,
            }
        }
        let mut in_candidate = vec![false; n];
        for &(i, len) in &candidates {
            in_candidate[i..i + len].fill(true);
        }
        let rest = x
            .iter()
            .zip(&in_candidate)
            .filter(|(_, &c)| !c)
            .fold(0.0f64, |m, (v, _)| m.max((v - median).abs()));
        let mut spikes = Vec::new();
        for (i, len) in candidates {
            let extreme = x[i..i + len]
                .iter()
                .copied()
                .max_by(|a, b| (a - median).abs().total_cmp(&(b - median).abs()))
                .unwrap();
            if (extreme - median).abs() < SPIKE_RATIO * rest {
                continue;
            }
            let (a, b) = (x[i - 1], x[i + len]);
            for j in 0..len {
                x[i + j] = a + (b - a) * (j + 1) as f64 / (len + 1) as f64;
            }
            spikes.push(Spike {
                sample: i as u64,
                time_s: 0.0,
                samples: len as u32,
                value_m_s2: extreme,
            });
        }
        spikes
    }

    fn flat_tops_in_one_go(x: &[f64]) -> Option<Clipping> {
        let q = x
            .windows(2)
            .map(|w| (w[1] - w[0]).abs())
            .filter(|d| *d > 0.0)
            .fold(f64::INFINITY, f64::min);
        if !q.is_finite() {
            return None;
        }
        let max = x.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let min = x.iter().copied().fold(f64::INFINITY, f64::min);
        let run_at = |level: f64| {
            let mut i = 0;
            while i < x.len() {
                if x[i] != level {
                    i += 1;
                    continue;
                }
                let start = i;
                while i < x.len() && x[i] == level {
                    i += 1;
                }
                let len = i - start;
                if len < 3 {
                    continue;
                }
                let slope_at = |a: Option<usize>, b: Option<usize>| {
                    let one = a.map_or(0.0, |a| (x[a] - level).abs());
                    let two = b.map_or(0.0, |b| (x[b] - level).abs() / 2.0);
                    one.max(two)
                };
                let entry = slope_at(start.checked_sub(1), start.checked_sub(2));
                let exit = slope_at(
                    (i < x.len()).then_some(i),
                    (i + 1 < x.len()).then_some(i + 1),
                );
                let slope = entry.max(exit);
                if slope >= 2.0 * q && slope >= 16.0 * q / len as f64 {
                    return true;
                }
            }
            false
        };
        let high = run_at(max).then_some(max);
        let low = run_at(min).then_some(min);
        (high.is_some() || low.is_some()).then(|| Clipping {
            low_m_s2: low,
            high_m_s2: high,
            from: "flat-top".into(),
        })
    }

    /// Signals with glitches, clipped runs of each length, steps at block edges.
    fn hostile(seed: u64, n: usize) -> Vec<f64> {
        let mut state = seed | 1;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let mut x: Vec<f64> = (0..n).map(|_| ((next() % 7) as f64 - 3.0) * 0.01).collect();
        for _ in 0..n / 50 {
            let at = (next() as usize) % n;
            match next() % 6 {
                0 => x[at] = ((next() % 2000) as f64 - 1000.0) * 10.0,
                1 => {
                    let len = 1 + (next() % 12) as usize;
                    let level = if next() % 2 == 0 { 2.0 } else { -2.0 };
                    for v in x.iter_mut().skip(at).take(len) {
                        *v = level;
                    }
                }
                2 => {
                    let v = ((next() % 200) as f64 - 100.0) * 1e3;
                    x[at] = v;
                    if at + 1 < n {
                        x[at + 1] = v * 0.7;
                    }
                }
                3 => {
                    let w = 2 + (next() % 30) as usize;
                    for k in 0..w.min(n - at) {
                        x[at + k] += 1.5 * (std::f64::consts::PI * k as f64 / w as f64).sin();
                    }
                }
                // Signed zeros, and readings near the end of f64's range (steps overflow).
                4 => x[at] = if next() % 2 == 0 { 0.0 } else { -0.0 },
                5 if seed % 3 == 0 => x[at] = if next() % 2 == 0 { 1e308 } else { -1e308 },
                _ => {}
            }
        }
        x
    }

    #[test]
    fn streamed_in_any_blocks_the_screen_finds_what_the_whole_slice_rules_find() {
        for seed in 1..40u64 {
            let n = 20 + (seed as usize * 997) % 5000;
            let x = hostile(seed, n);
            let m = median(&x);
            let mut want = x.clone();
            let want_spikes = spikes_in_one_go(&mut want, m);
            for block in [1, 2, 3, 5, 64, 4096, n] {
                let mut scan = SpikeScan::default();
                let mut flat = FlatTops::default();
                for b in x.chunks(block) {
                    scan.push(b);
                    flat.push(b);
                }
                let removals = scan.finish(m).unwrap();
                let got: Vec<Spike> = removals.iter().map(|r| r.spike.clone()).collect();
                assert_eq!(got, want_spikes, "seed {seed}, blocks of {block}");
                let mut y = x.clone();
                for r in &removals {
                    for j in 0..r.spike.samples as usize {
                        y[r.spike.sample as usize + j] = r.value(j);
                    }
                }
                assert_eq!(y, want, "seed {seed}, blocks of {block}");
                assert_eq!(
                    flat.finish(),
                    flat_tops_in_one_go(&x),
                    "seed {seed}, {block}"
                );
            }
        }
    }

    #[test]
    fn the_glitch_limit_does_not_depend_on_the_blocks() {
        // Many glitches early that a real impact later dwarfs: none is a spike, however the
        // recording is cut.
        let n = 3 * (MAX_GLITCHES + 100) + 5000;
        let mut x: Vec<f64> = (0..n).map(|i| (i % 3) as f64 * 0.01).collect();
        for k in 0..MAX_GLITCHES + 100 {
            x[3 * k + 10] = 1000.0;
        }
        for k in 0..1000 {
            x[n - 2000 + k] += 500.0 * (std::f64::consts::PI * k as f64 / 1000.0).sin();
        }
        let m = median(&x);
        let whole = remove_spikes(&mut x.clone(), m).unwrap();
        assert!(whole.is_empty());
        for block in [7, 4096, 65536] {
            let mut scan = SpikeScan::default();
            x.chunks(block).for_each(|b| scan.push(b));
            assert!(scan.finish(m).unwrap().is_empty(), "blocks of {block}");
        }
    }

    #[test]
    fn too_many_glitches_are_refused_not_dropped() {
        let mut x = vec![0.0; 10 * (MAX_GLITCHES + 10)];
        for k in 0..MAX_GLITCHES + 5 {
            x[10 * k + 5] = 1e6 + k as f64;
        }
        let e = remove_spikes(&mut x.clone(), 0.0).unwrap_err();
        assert_eq!(e, TooManyGlitches);
        assert!(e.to_string().contains("--keep-spikes"), "{e}");
    }

    #[test]
    fn a_glitch_far_above_the_recording_is_removed_and_listed() {
        let mut x = pulse(2000, 500, 50, 50.0);
        let clean = x.clone();
        x[1500] = 1e4;
        let spikes = remove(&mut x);
        assert_eq!(spikes.len(), 1);
        assert_eq!(spikes[0].sample, 1500);
        assert_eq!(spikes[0].value_m_s2, 1e4);
        assert!((x[1500] - clean[1500]).abs() < 0.05);
        assert_eq!(&x[..1500], &clean[..1500]);
    }

    #[test]
    fn a_two_sample_glitch_is_removed() {
        let mut x = pulse(2000, 500, 50, 50.0);
        x[1500] = -3e3;
        x[1501] = -2e3;
        let spikes = remove(&mut x);
        assert_eq!(spikes.len(), 1);
        assert_eq!((spikes[0].sample, spikes[0].samples), (1500, 2));
        assert_eq!(spikes[0].value_m_s2, -3e3);
    }

    #[test]
    fn a_real_short_pulse_stays() {
        // A two-sample pulse that does not dwarf the rest of the recording.
        let mut x = pulse(2000, 500, 50, 50.0);
        x[1500] = 200.0;
        x[1501] = 150.0;
        let before = x.clone();
        assert!(remove(&mut x).is_empty());
        assert_eq!(x, before);
        // A smooth pulse is never a spike, however large.
        let mut y = pulse(2000, 500, 5, 1e6);
        let before = y.clone();
        assert!(remove(&mut y).is_empty());
        assert_eq!(y, before);
    }

    #[test]
    fn a_clipped_half_sine_is_a_flat_top_and_a_smooth_one_is_not() {
        let x = pulse(4000, 1000, 1000, 40.0);
        assert_eq!(flat_tops(&x), None);
        let clipped: Vec<f64> = x.iter().map(|v| v.min(16.0)).collect();
        let c = flat_tops(&clipped).expect("flat top");
        assert_eq!(c.high_m_s2, Some(16.0));
        assert_eq!(c.low_m_s2, None);
        // Three samples at a steep edge are enough.
        let mut short = pulse(4000, 1000, 8, 40.0);
        let top = 36.0;
        short[1003..1006].fill(top);
        assert!(flat_tops(&short).is_some_and(|c| c.high_m_s2 == Some(top)));
    }

    #[test]
    fn range_levels_are_just_inside_full_scale() {
        let c = from_range(16.0 * 9.80665);
        assert!(c.high_m_s2.unwrap() < 16.0 * 9.80665);
        assert!(c.high_m_s2.unwrap() > 15.8 * 9.80665);
        assert_eq!(c.low_m_s2, c.high_m_s2.map(|v| -v));
    }
}
