//! The flanks of a pulse kept in bounded memory for their feet's fits
//! ([`crate::signal::power_flank`]): the rising side from the onset until the pulse is well
//! past its peak (its foot, to 30 % of the peak, is known only once the peak is, long after
//! the pre-trigger ring has let it go on a slow pulse; the capture may not be there: the
//! board has two), every `stride`-th sample; the falling side from the latest peak to the
//! separation, the mean of every `stride` samples. The strides double whenever a record
//! fills; positions decide everything, so any split of the stream keeps the same points.

use crate::signal::baseline::{Stats, STRIDE};

/// Points kept: the foot of a pulse whose peak is `n` samples after its onset keeps at least
/// `RISE_POINTS / 4` of them over its first 30 %.
pub const RISE_POINTS: usize = 128;

/// The record: positions from the onset and deviations signed so the pulse is positive.
#[derive(Clone, Copy, Debug)]
pub struct Rise {
    stride: u32,
    len: usize,
    pos: [u32; RISE_POINTS],
    d: [i32; RISE_POINTS],
    /// The onset's sample and the next two, whatever the stride (a step's three samples:
    /// [`crate::signal::power_flank::steep_zero`], or a short flank's:
    /// [`crate::signal::power_flank::head_zero`]); `None` until taken.
    head: [Option<i32>; 3],
    done: bool,
}

impl Default for Rise {
    fn default() -> Self {
        Self::new()
    }
}

impl Rise {
    pub const fn new() -> Self {
        Self {
            stride: 1,
            len: 0,
            pos: [0; RISE_POINTS],
            d: [0; RISE_POINTS],
            head: [None; 3],
            done: false,
        }
    }

    /// True once the pulse is past its peak (nothing more is taken).
    pub fn done(&self) -> bool {
        self.done
    }

    /// Where the record closes for a peak at `peak_pos` (from the onset): a quarter of the
    /// way again past it, and 16 samples more.
    pub fn closing(peak_pos: u64) -> u64 {
        peak_pos + peak_pos / 4 + 16
    }

    /// Closes the record: nothing more is taken.
    pub fn close(&mut self) {
        self.done = true;
    }

    /// Takes `n` samples from position `pos0` (from the onset): `d(k)` is sample `k`'s
    /// deviation signed so the pulse is positive. The caller closes the record at
    /// [`Self::closing`] of the peak so far, sample by sample (so any split of the stream
    /// keeps the same points).
    /// (Not inlined: the in-impact loop it follows keeps its registers.)
    #[inline(never)]
    pub fn take(&mut self, pos0: u64, n: usize, d: impl Fn(usize) -> i64) {
        if self.done {
            return;
        }
        for (at, slot) in self.head.iter_mut().enumerate() {
            if let Some(k) = (at as u64).checked_sub(pos0).filter(|&k| k < n as u64) {
                *slot = Some(d(k as usize).clamp(i32::MIN as i64, i32::MAX as i64) as i32);
            }
        }
        // The stride is a power of two: positions on it by masks (a 64-bit division is a
        // library call on the Cortex-M4).
        let mask = |stride: u32| u64::from(stride) - 1;
        let mut k = (u64::from(self.stride) - (pos0 & mask(self.stride))) & mask(self.stride);
        while k < n as u64 {
            let at = pos0 + k;
            if self.len == RISE_POINTS {
                // Keep every other point: those on the doubled stride.
                let double = self.stride.saturating_mul(2);
                let m = mask(double);
                let mut kept = 0;
                for i in 0..RISE_POINTS {
                    let (Some(&p), Some(&v)) = (self.pos.get(i), self.d.get(i)) else {
                        break;
                    };
                    if u64::from(p) & m == 0 {
                        if let (Some(tp), Some(tv)) = (self.pos.get_mut(kept), self.d.get_mut(kept))
                        {
                            *tp = p;
                            *tv = v;
                        }
                        kept += 1;
                    }
                }
                self.len = kept;
                self.stride = double;
                if at & m != 0 {
                    k += u64::from(double) - (at & m);
                    continue;
                }
            }
            if let (Some(p), Some(v)) = (self.pos.get_mut(self.len), self.d.get_mut(self.len)) {
                *p = u32::try_from(at).unwrap_or(u32::MAX);
                *v = d(k as usize).clamp(i32::MIN as i64, i32::MAX as i64) as i32;
                self.len += 1;
            }
            k += u64::from(self.stride);
        }
    }

    /// The onset's sample and the next two, once taken.
    pub fn head(&self) -> Option<[i32; 3]> {
        match self.head {
            [Some(a), Some(b), Some(c)] => Some([a, b, c]),
            _ => None,
        }
    }

    /// The points kept, in order: (position from the onset, signed deviation).
    pub fn points(&self) -> impl Iterator<Item = (u32, i32)> + '_ {
        self.pos
            .get(..self.len)
            .unwrap_or(&[])
            .iter()
            .copied()
            .zip(self.d.get(..self.len).unwrap_or(&[]).iter().copied())
    }
}

/// Buckets the falling side keeps: its foot (the last 30 %) keeps about a third of them.
pub const FALL_POINTS: usize = 64;

/// The falling side of a pulse from its peak, kept in bounded memory for its foot's fit: the
/// mean of every `stride` samples (the stride doubling, neighbours merged, whenever the record
/// fills), so a long, slow return is seen whole and with its noise averaged down.
#[derive(Clone, Copy, Debug)]
pub struct Fall {
    stride: u32,
    /// Complete buckets, and Σd over each (of `stride` samples).
    len: usize,
    sums: [i64; FALL_POINTS],
    /// The bucket being filled: Σd and samples.
    acc: i64,
    acc_n: u32,
}

impl Default for Fall {
    fn default() -> Self {
        Self::new()
    }
}

impl Fall {
    pub const fn new() -> Self {
        Self {
            stride: 1,
            len: 0,
            sums: [0; FALL_POINTS],
            acc: 0,
            acc_n: 0,
        }
    }

    /// Takes the next raw samples (contiguous, after the peak), measured as `sign (w x - s)`
    /// (the pulse positive): each bucket's sum from the samples' sum (the stride statistics,
    /// two samples an instruction on the Cortex-M4).
    #[inline(never)]
    pub fn take(&mut self, samples: &[i16], w: i64, s: i64, sign: i64) {
        let mut rest = samples;
        while !rest.is_empty() {
            let room = (self.stride - self.acc_n) as usize;
            let m = room.min(rest.len()).min(STRIDE);
            let (part, after) = rest.split_at(m);
            let st = Stats::of(part);
            self.acc += sign * (w * i64::from(st.sum) - m as i64 * s);
            self.acc_n += m as u32;
            rest = after;
            if self.acc_n < self.stride {
                continue;
            }
            if self.len == FALL_POINTS {
                // Merge neighbours: half as many buckets, twice as long.
                for j in 0..FALL_POINTS / 2 {
                    let pair = self.sums.get(2 * j).copied().unwrap_or(0)
                        + self.sums.get(2 * j + 1).copied().unwrap_or(0);
                    if let Some(slot) = self.sums.get_mut(j) {
                        *slot = pair;
                    }
                }
                self.len = FALL_POINTS / 2;
                self.stride = self.stride.saturating_mul(2);
                // The bucket being filled is now half of a doubled one.
                continue;
            }
            if let Some(slot) = self.sums.get_mut(self.len) {
                *slot = self.acc;
                self.len += 1;
            }
            self.acc = 0;
            self.acc_n = 0;
        }
    }

    /// Points kept, the bucket being filled included.
    pub fn len(&self) -> usize {
        self.len + usize::from(self.acc_n > 0)
    }

    /// Point `i`: the middle of its bucket (position from the peak) and its mean deviation.
    pub fn get(&self, i: usize) -> Option<(f32, f32)> {
        let stride = self.stride as f32;
        if i < self.len {
            let sum = *self.sums.get(i)? as f32;
            Some(((i as f32 + 0.5) * stride - 0.5, sum / stride))
        } else if i == self.len && self.acc_n > 0 {
            let n = self.acc_n as f32;
            Some((i as f32 * stride + (n - 1.0) / 2.0, self.acc as f32 / n))
        } else {
            None
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The onset's sample and the next two, however the rise is taken in pieces (from the
    /// trigger, `pulse` samples of it already in the ring) and whatever the stride.
    #[test]
    fn the_head_is_the_onset_and_the_next_two_samples() {
        let d = |k: u64| 10 * k as i64 + 7;
        for pulse in [0usize, 1, 2, 3, 5] {
            for split in 1..6 {
                let mut r = Rise::new();
                // At the trigger: positions 0..pulse from the ring.
                r.take(0, pulse, |k| d(k as u64));
                // Then the stream, `split` samples at a time, from position `pulse`.
                let mut pos = pulse as u64;
                while pos < 2000 {
                    r.take(pos, split, |k| d(pos + k as u64));
                    pos += split as u64;
                }
                assert_eq!(r.head(), Some([7, 17, 27]), "pulse {pulse}, split {split}");
            }
        }
        assert_eq!(Rise::new().head(), None);
    }

    #[test]
    fn the_fall_keeps_bucket_means_and_merges_them_when_full() {
        // A ramp 1000, 999, ... in pieces of 37: at most FALL_POINTS buckets, each the exact
        // mean of its samples, spread evenly from the peak.
        let samples: heapless::Vec<i16, 4096> = (0..4000).map(|k| 1000 - (k / 4) as i16).collect();
        let mut f = Fall::new();
        for piece in samples.chunks(37) {
            f.take(piece, 1, 0, 1);
        }
        assert!(f.len() <= FALL_POINTS + 1, "{}", f.len());
        let (p0, d0) = f.get(0).unwrap();
        let (p1, _) = f.get(1).unwrap();
        let stride = (p1 - p0) as usize;
        assert!(stride.is_power_of_two() && stride * FALL_POINTS >= 4000 / 2);
        let mean = |from: usize| {
            samples[from..from + stride]
                .iter()
                .map(|&x| x as f32)
                .sum::<f32>()
                / stride as f32
        };
        assert_eq!(d0, mean(0));
        assert_eq!(f.get(3).unwrap().1, mean(3 * stride));
        // The bucket being filled: its samples' mean at their middle.
        let last = f.len() - 1;
        let (p, d) = f.get(last).unwrap();
        let n = 4000 - last * stride;
        let tail = &samples[last * stride..];
        assert_eq!(p, last as f32 * stride as f32 + (n as f32 - 1.0) / 2.0);
        assert!((d - tail.iter().map(|&x| x as f32).sum::<f32>() / n as f32).abs() < 1e-3);
    }

    #[test]
    fn a_long_rise_is_kept_decimated_and_the_record_closes_past_the_peak() {
        let mut r = Rise::new();
        // 10 000 samples in blocks of 256 (d = position), peak at 4000.
        let mut at = 0u64;
        let close = Rise::closing(4000);
        while at < 10_000 && !r.done() {
            let n = (close + 1).saturating_sub(at).min(256);
            r.take(at, n as usize, |k| (at + k as u64) as i64);
            at += 256;
            if at > close {
                r.close();
            }
        }
        assert!(r.done());
        let pts: heapless::Vec<(u32, i32), RISE_POINTS> = r.points().collect();
        assert!(pts.len() >= RISE_POINTS / 2, "{}", pts.len());
        // Evenly spaced from the onset, each point its own position.
        let step = pts[1].0 - pts[0].0;
        assert_eq!(pts[0].0, 0);
        for (i, &(p, d)) in pts.iter().enumerate() {
            assert_eq!(p, i as u32 * step);
            assert_eq!(d, p as i32);
        }
        // Past the peak nothing is taken.
        assert!(u64::from(pts.last().unwrap().0) <= close);
    }
}
