//! Pre-trigger ring of raw samples: the history an impact's capture starts from.
//!
//! A plain power-of-two ring (index masking, no division, no panics) rather than
//! `heapless::HistoryBuffer`, whose `% N` write index costs a division per sample on the
//! Cortex-M4 for sizes the compiler cannot see are powers of two.

/// The last `N` raw samples (`N` a power of two).
pub struct Ring<const N: usize> {
    buf: [i16; N],
    /// Index of the next write.
    head: usize,
    /// Number of valid samples, up to `N`.
    len: usize,
}

impl<const N: usize> Default for Ring<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> Ring<N> {
    const MASK: usize = N - 1;
    /// Fails to compile unless `N` is a power of two.
    const CHECK: () = assert!(N.is_power_of_two(), "ring size must be a power of two");

    pub const fn new() -> Self {
        #[allow(clippy::let_unit_value)]
        let _ = Self::CHECK;
        Self {
            buf: [0; N],
            head: 0,
            len: 0,
        }
    }

    /// Appends a block, evicting the oldest samples once full (two straight copies).
    #[inline]
    pub fn extend(&mut self, block: &[i16]) {
        // Only the last N samples of a long block can stay.
        let block = block.get(block.len().saturating_sub(N)..).unwrap_or(&[]);
        let head = self.head & Self::MASK;
        let first = block.len().min(N - head);
        let to_end = block.get(..first).unwrap_or(&[]);
        let wrapped = block.get(first..).unwrap_or(&[]);
        if let Some(dst) = self.buf.get_mut(head..) {
            super::copy::copy_samples(dst, to_end);
        }
        if !wrapped.is_empty() {
            super::copy::copy_samples(&mut self.buf, wrapped);
        }
        self.head = (head + block.len()) & Self::MASK;
        self.len = (self.len + block.len()).min(N);
    }

    /// Number of samples held.
    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// True once `N` samples have been seen.
    pub fn is_full(&self) -> bool {
        self.len == N
    }

    /// The `i`-th most recent sample (`0` = newest), if held.
    #[inline]
    pub fn back(&self, i: usize) -> Option<i16> {
        if i < self.len {
            Some(self.buf[(self.head.wrapping_sub(1 + i)) & Self::MASK])
        } else {
            None
        }
    }

    /// The newest `n` samples (as many as are held), oldest first, as two contiguous runs.
    pub fn last(&self, n: usize) -> (&[i16], &[i16]) {
        let n = n.min(self.len);
        let head = self.head & Self::MASK;
        if n <= head {
            (self.buf.get(head - n..head).unwrap_or(&[]), &[])
        } else {
            let wrapped = n - head;
            (
                self.buf.get(N - wrapped..).unwrap_or(&[]),
                self.buf.get(..head).unwrap_or(&[]),
            )
        }
    }

    /// The samples oldest first.
    pub fn iter_oldest_first(&self) -> impl Iterator<Item = i16> + '_ {
        (0..self.len).rev().filter_map(move |i| self.back(i))
    }

    /// Empties the ring for a replay of its history: the samples, oldest first, stay readable
    /// with [`Self::replayed`] at positions `0..n` (`n` is returned) while the ring fills
    /// again from position 0, so a replay that reads each sample before it writes it back
    /// sees them intact. No copy of the history is made (no `N`-sample buffer on the stack).
    pub fn take_history(&mut self) -> usize {
        let n = self.len;
        if n == N {
            // Full: the oldest sample is at `head`; rotate it to the front.
            self.buf.rotate_left(self.head & Self::MASK);
        }
        // Not full: written from position 0 since the last clear, so already in order.
        self.clear();
        n
    }

    /// The history's samples at positions `from..from + out.len()` (see
    /// [`Self::take_history`]) into `out`.
    pub fn replayed(&self, from: usize, out: &mut [i16]) {
        if let Some(src) = self.buf.get(from..from + out.len()) {
            out.copy_from_slice(src);
        }
    }

    /// Forgets everything.
    pub fn clear(&mut self) {
        self.head = 0;
        self.len = 0;
    }
}

/// Splits the two runs `first`, `second` (one sequence) at position `at`: the runs before it
/// and the runs from it on.
pub fn split_runs<'a>(
    first: &'a [i16],
    second: &'a [i16],
    at: usize,
) -> ([&'a [i16]; 2], [&'a [i16]; 2]) {
    let (a0, a1) = first.split_at(at.min(first.len()));
    let rest = at.saturating_sub(first.len());
    let (b0, b1) = second.split_at(rest.min(second.len()));
    ([a0, b0], [a1, b1])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_block_longer_than_the_ring_keeps_its_tail() {
        let mut r = Ring::<4>::new();
        r.extend(&[9]);
        r.extend(&[1, 2, 3, 4, 5, 6]);
        assert!(r.iter_oldest_first().eq([3, 4, 5, 6]));
        r.extend(&[7, 8, 9]);
        assert!(r.iter_oldest_first().eq([6, 7, 8, 9]));
    }

    #[test]
    fn the_history_replays_in_place() {
        for pushed in [3usize, 4, 6, 9] {
            let mut r = Ring::<4>::new();
            for x in 0..pushed as i16 {
                r.extend(&[x]);
            }
            let expected: [i16; 4] = core::array::from_fn(|i| r.back(3 - i).unwrap_or(-1));
            let n = r.take_history();
            assert_eq!((n, r.len()), (pushed.min(4), 0));
            // Read one, write it back: the rest stays intact.
            let mut got = [0i16; 4];
            for k in 0..n {
                r.replayed(k, &mut got[k..k + 1]);
                r.extend(&got[k..k + 1]);
            }
            let want = &expected[4 - n..];
            assert_eq!(&got[..n], want, "{pushed}");
            assert!(r.iter_oldest_first().eq(want.iter().copied()));
        }
    }

    #[test]
    fn the_last_samples_come_in_two_runs() {
        let mut r = Ring::<4>::new();
        r.extend(&[1, 2, 3]);
        assert_eq!(r.last(2), (&[2, 3][..], &[][..]));
        assert_eq!(r.last(9), (&[1, 2, 3][..], &[][..]));
        r.extend(&[4, 5, 6]);
        let (a, b) = r.last(4);
        assert_eq!([a, b].concat(), [3, 4, 5, 6]);
        let (a, b) = r.last(3);
        assert_eq!([a, b].concat(), [4, 5, 6]);
        assert_eq!(r.last(0), (&[][..], &[][..]));
    }

    #[test]
    fn keeps_the_newest() {
        let mut r = Ring::<4>::new();
        r.extend(&[1, 2, 3]);
        assert_eq!(
            (r.len(), r.back(0), r.back(2), r.back(3)),
            (3, Some(3), Some(1), None)
        );
        r.extend(&[4, 5, -6]);
        assert_eq!(r.len(), 4);
        let v: [i16; 4] = core::array::from_fn(|i| r.back(3 - i).unwrap());
        assert_eq!(v, [3, 4, 5, -6]);
        assert!(r.iter_oldest_first().eq([3, 4, 5, -6]));
    }
}
