//! The rising side of a pulse, kept in bounded memory for its foot's fit at the end
//! ([`crate::signal::power_flank`]): every `stride`-th sample from the onset, the stride
//! doubling whenever the record fills, until the pulse is well past its peak. The pulse's
//! foot (to 30 % of its peak) is known only once the peak is, long after the pre-trigger
//! ring has let it go on a slow pulse; the capture may not be there (the board has two).

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
            done: false,
        }
    }

    /// True once the pulse is past its peak (nothing more is taken).
    pub fn done(&self) -> bool {
        self.done
    }

    /// Takes `n` samples from position `pos0` (from the onset): `d(k)` is sample `k`'s
    /// deviation signed so the pulse is positive. Then the record closes once the samples
    /// reach twice the peak's position (`peak_pos`) and 16 more.
    /// (Not inlined: the in-impact loop it follows keeps its registers.)
    #[inline(never)]
    pub fn take(&mut self, pos0: u64, n: usize, peak_pos: u64, d: impl Fn(usize) -> i64) {
        if self.done {
            return;
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
        if pos0 + n as u64 > peak_pos + peak_pos / 4 + 16 {
            self.done = true;
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_long_rise_is_kept_decimated_and_the_record_closes_past_the_peak() {
        let mut r = Rise::new();
        // 10 000 samples in blocks of 256 (d = position), peak at 4000.
        let mut at = 0u64;
        while at < 10_000 {
            r.take(at, 256, 4000, |k| (at + k as u64) as i64);
            at += 256;
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
        assert!(pts.last().unwrap().0 <= 2 * 4000 + 16 + 256);
    }
}
