//! Running baseline (sensor offset) learned only from quiet stretches of the signal.
//!
//! The stream is cut into strides of `STRIDE` samples at fixed stream positions. A stride whose
//! samples all lie within the edge level of the current baseline, and whose mean lies within
//! its own noise of it, is quiet, and its sum enters a window of the last `K` quiet strides;
//! a stride with any excursion is left out. So a slow pulse's rising flank cannot drag the
//! baseline along (and hide itself from the trigger), nor can a slow ramp below the edge level
//! before an impact (a drop tower's table settling, a sensor warming): the baseline stays the
//! sensor's zero. It is the exact rational `sum / count` of raw counts.

/// Samples per stride.
pub const STRIDE: usize = 64;

/// Sum, minimum and maximum of a run of samples: one pass, vectorised by the compiler on the
/// host and written with the Cortex-M4's SIMD instructions (two samples per `SMLAD`,
/// `SSUB16`+`SEL`) on the board.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Stats {
    pub len: usize,
    pub sum: i32,
    pub min: i16,
    pub max: i16,
}

impl Stats {
    /// Of at most [`STRIDE`] samples (the sum cannot overflow).
    #[inline]
    pub fn of(samples: &[i16]) -> Self {
        #[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
        {
            dsp::stats(samples)
        }
        #[cfg(not(all(target_arch = "arm", target_abi = "eabihf")))]
        {
            Self::of_portable(samples)
        }
    }

    /// True if every sample lies within `lo..=hi` (raw counts).
    #[inline]
    pub fn within(&self, lo: i32, hi: i32) -> bool {
        (self.max as i32) <= hi && (self.min as i32) >= lo
    }

    /// [`Self::of`] in plain Rust (the reference for the Cortex-M4 version).
    #[inline]
    pub fn of_portable(samples: &[i16]) -> Self {
        let mut s = Self {
            len: samples.len(),
            sum: 0,
            min: i16::MAX,
            max: i16::MIN,
        };
        for &x in samples {
            s.sum += x as i32;
            s.min = s.min.min(x);
            s.max = s.max.max(x);
        }
        s
    }
}

/// [`Stats::of`] with the Cortex-M4's DSP extension, two samples per 32-bit word.
#[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
#[allow(unsafe_code)]
mod dsp {
    use super::Stats;

    extern "C" {
        /// `pairs` words from the word-aligned `words`: writes the sum of the 2 × `pairs`
        /// samples, the lane-wise minimum and the lane-wise maximum (two i16 each) to `out`.
        fn impact_core_stats_i16(words: *const i16, pairs: usize, out: *mut [u32; 3]);
    }

    #[inline]
    pub fn stats(samples: &[i16]) -> Stats {
        // A first sample off a word boundary and an odd last one go the portable way.
        let head = (samples.as_ptr() as usize / 2) & 1;
        let head = head.min(samples.len());
        let (first, rest) = samples.split_at(head);
        let pairs = rest.len() / 2;
        let (middle, tail) = rest.split_at(2 * pairs);
        let mut out = [0u32, 0x7FFF_7FFF, 0x8000_8000];
        if pairs > 0 {
            // SAFETY: `middle` is word-aligned (the head took the odd half-word) and holds
            // exactly `pairs` words; the routine reads them and writes `out`, nothing else.
            unsafe { impact_core_stats_i16(middle.as_ptr(), pairs, &mut out) };
        }
        let edges = Stats::of_portable(first);
        let last = Stats::of_portable(tail);
        let lanes = |w: u32| (w as u16 as i16, (w >> 16) as u16 as i16);
        let (min_lo, min_hi) = lanes(out[1]);
        let (max_lo, max_hi) = lanes(out[2]);
        Stats {
            len: samples.len(),
            sum: (out[0] as i32) + edges.sum + last.sum,
            min: min_lo.min(min_hi).min(edges.min).min(last.min),
            max: max_lo.max(max_hi).max(edges.max).max(last.max),
        }
    }

    // r0 = words, r1 = pairs (> 0), r2 = out. Per word: SMLAD adds both halves to the sum;
    // SSUB16 sets the GE flags of the lanes where x >= min (resp. max) and SEL picks lane-wise.
    core::arch::global_asm!(
        ".syntax unified",
        ".thumb",
        ".section .text.impact_core_stats_i16,\"ax\",%progbits",
        ".global impact_core_stats_i16",
        ".type impact_core_stats_i16,%function",
        ".thumb_func",
        "impact_core_stats_i16:",
        "push {{r4, r5, r6, r7, lr}}",
        "movs r3, #0",
        "movw r12, #0x7fff",
        "movt r12, #0x7fff",
        "mov.w r4, #0x80008000",
        "mov.w r5, #0x00010001",
        // Two words per pass while at least two are left.
        "subs r1, r1, #2",
        "blo 2f",
        "1:",
        "ldrd r6, r7, [r0], #8",
        "smlad r3, r6, r5, r3",
        "ssub16 lr, r6, r12",
        "sel r12, r12, r6",
        "ssub16 lr, r6, r4",
        "sel r4, r6, r4",
        "smlad r3, r7, r5, r3",
        "ssub16 lr, r7, r12",
        "sel r12, r12, r7",
        "ssub16 lr, r7, r4",
        "sel r4, r7, r4",
        "subs r1, r1, #2",
        "bhs 1b",
        "2:",
        // r1 is -1 if one word is left, -2 if none.
        "adds r1, r1, #1",
        "bne 3f",
        "ldr r6, [r0]",
        "smlad r3, r6, r5, r3",
        "ssub16 lr, r6, r12",
        "sel r12, r12, r6",
        "ssub16 lr, r6, r4",
        "sel r4, r6, r4",
        "3:",
        "str r3, [r2]",
        "str r12, [r2, #4]",
        "str r4, [r2, #8]",
        "pop {{r4, r5, r6, r7, pc}}",
        ".size impact_core_stats_i16, . - impact_core_stats_i16",
    );
}

/// The last `K` quiet strides' sums.
pub struct Baseline<const K: usize> {
    sums: [i32; K],
    head: usize,
    len: usize,
    total: i64,
    /// `total / (len * STRIDE)` (0 before arming), kept with the window.
    mean: f32,
    // The stride being accumulated.
    acc: i32,
    min: i16,
    max: i16,
    filled: usize,
    /// Strides completed since the window's newest that did not enter it (moving, or
    /// loud).
    rejected: u32,
}

impl<const K: usize> Default for Baseline<K> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const K: usize> Baseline<K> {
    pub const fn new() -> Self {
        Self {
            sums: [0; K],
            head: 0,
            len: 0,
            total: 0,
            mean: 0.0,
            acc: 0,
            min: i16::MAX,
            max: i16::MIN,
            filled: 0,
            rejected: 0,
        }
    }

    /// True once one stride has been learned.
    pub fn is_armed(&self) -> bool {
        self.len > 0
    }

    /// The baseline as `(sum, count)` of raw counts.
    pub fn rational(&self) -> (i64, i64) {
        (self.total, (self.len * STRIDE) as i64)
    }

    /// The baseline in counts (0 before arming).
    #[inline]
    pub fn mean(&self) -> f32 {
        self.mean
    }

    /// `total / (len * STRIDE)`, for the window just changed.
    fn window_mean(&self) -> f32 {
        if self.len == 0 {
            0.0
        } else {
            // The FPU converts i32 (a baseline of up to 2^16 samples of i16 fits); i64 is a
            // soft-float call on the Cortex-M4, kept for larger windows.
            let total = match i32::try_from(self.total) {
                Ok(t) => t as f32,
                Err(_) => self.total as f64 as f32,
            };
            total / (self.len * STRIDE) as f32
        }
    }

    /// Learned from a short stretch that the signal never came back to: fewer than
    /// [`Self::SHORT`] strides in the window, and at least as many completed since its newest
    /// without entering it. A record that starts on a moving signal (a ramp into its first
    /// pulse) learns its first strides there, then rejects every stride after them as moving:
    /// its zero is not the sensor's. (The stream asks it of the record's first baseline
    /// only.)
    pub fn unconfirmed(&self) -> bool {
        self.len < Self::SHORT && self.rejected >= Self::SHORT as u32
    }

    /// Strides (512 samples) a window must hold, or the signal must stay off it, for
    /// [`Self::unconfirmed`].
    pub const SHORT: usize = 8;

    /// Samples still missing to complete the current stride.
    pub fn to_stride_end(&self) -> usize {
        STRIDE - self.filled
    }

    /// Adds samples (at most [`Self::to_stride_end`] of them); when a stride completes, it
    /// enters the window if every sample was within `edge` counts of the baseline and its mean
    /// within a tenth of its own span (about four standard errors of a mean of 64 noisy
    /// samples; at least one count) of it, or, while nothing is learned yet, if its samples
    /// span at most `4 edge` (so a pulse in the first stride cannot become the baseline).
    /// Returns true when a stride completed.
    #[inline]
    pub fn add(&mut self, samples: &[i16], edge: f32) -> bool {
        let stats = Stats::of(samples);
        self.add_stats(&stats, edge)
    }

    /// As [`Self::add`], with the samples' statistics already computed.
    #[inline]
    pub fn add_stats(&mut self, s: &Stats, edge: f32) -> bool {
        self.acc += s.sum;
        self.min = self.min.min(s.min);
        self.max = self.max.max(s.max);
        self.filled += s.len;
        if self.filled < STRIDE {
            return false;
        }
        let (acc, lo, hi) = (self.acc, self.min, self.max);
        let mean = self.mean();
        let span = hi as f32 - lo as f32;
        let quiet = if self.len == 0 {
            span <= 4.0 * edge
        } else {
            // The mean of a stride of noise is within ~4 standard errors (σ / 8) of the
            // baseline; the span of 64 noisy samples is ~5 σ.
            // (`f32::max` is a library call on the M4.)
            let band = span / 10.0;
            let band = if band > 1.0 { band } else { 1.0 };
            let stride_mean = acc as f32 / self.filled as f32;
            lo as f32 >= mean - edge
                && hi as f32 <= mean + edge
                && libm::fabsf(stride_mean - mean) <= band
        };
        if quiet {
            self.push(acc);
        } else {
            self.rejected = self.rejected.saturating_add(1);
        }
        self.acc = 0;
        self.min = i16::MAX;
        self.max = i16::MIN;
        self.filled = 0;
        true
    }

    /// Forgets the partial stride (the stream continues elsewhere, e.g. after an impact).
    pub fn restart_stride(&mut self) {
        self.acc = 0;
        self.min = i16::MAX;
        self.max = i16::MIN;
        self.filled = 0;
    }

    /// Forgets everything.
    pub fn clear(&mut self) {
        *self = Self::new();
    }

    /// Starts again from the level `sum / n` (raw counts, `n` a multiple of [`STRIDE`], at most
    /// `K` strides): the level the signal moved to. The window holds it exactly, as `n / STRIDE`
    /// strides.
    pub fn restart_at(&mut self, sum: i64, n: i64) {
        *self = Self::new();
        let k = (n / STRIDE as i64).clamp(1, K as i64);
        let each = sum.checked_div(k).unwrap_or(0);
        // The remainder goes one count to a stride, so the strides add up to `sum`.
        let mut extra = sum - each * k;
        for _ in 0..k {
            let part = each + extra.signum();
            extra -= extra.signum();
            self.push(part.clamp(i32::MIN as i64, i32::MAX as i64) as i32);
        }
    }

    /// A stride's sum into the window.
    fn push(&mut self, acc: i32) {
        self.rejected = 0;
        if self.len == K {
            self.total -= self.sums[self.head % K] as i64;
        } else {
            self.len += 1;
        }
        self.sums[self.head % K] = acc;
        self.total += acc as i64;
        self.head = (self.head + 1) % K;
        self.mean = self.window_mean();
    }
}

/// A raw sample with one impact's frozen baseline removed, `d = W x - S` (the baseline is the
/// rational `S / W` counts), in i32: exact, since `W <= 4096` and `|x| <= 2^15` keep `|S|`
/// below 2^27 and `|d|` below 2^28 (the wrapping operations never wrap); i32 because the FPU
/// converts it while i64 arithmetic and conversions are longer or soft-float calls on the
/// Cortex-M4.
#[derive(Clone, Copy, Debug)]
pub struct Deviation {
    w: i32,
    s: i32,
}

impl Deviation {
    /// For the baseline `base_sum / base_n` (`base_n <= 4096`, as the stream's baseline).
    pub const fn new(base_sum: i64, base_n: i64) -> Self {
        Self {
            w: base_n as i32,
            s: base_sum as i32,
        }
    }

    /// The deviation from a level `counts` above the baseline (`S + W counts`, its product
    /// rounded to an integer: within `1 / (2 W)` of a count, `1/8192` of a count or less for
    /// the stream's baseline). The scene keeps `|counts| <= 2^15` (gravity within the
    /// sensor's range), so `|d|` stays below 2^29.
    pub fn above(self, counts: f64) -> Self {
        let shift = libm::round(self.w as f64 * counts);
        Self {
            w: self.w,
            // Saturating conversion: never wraps, whatever the input.
            s: (self.s as f64 + shift) as i32,
        }
    }

    #[inline]
    pub fn of(self, x: i16) -> i32 {
        (x as i32).wrapping_mul(self.w).wrapping_sub(self.s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn learns_quiet_strides_and_ignores_excursions() {
        let mut b = Baseline::<4>::new();
        // A first stride with a pulse in it is not learned.
        let mut pulse = [100i16; STRIDE];
        pulse[3] = 500;
        assert!(b.add(&pulse, 5.0));
        assert!(!b.is_armed());
        assert!(b.add(&[100; STRIDE], 5.0));
        assert_eq!(b.rational(), (100 * STRIDE as i64, STRIDE as i64));
        // A stride with an excursion beyond the edge is left out.
        let mut loud = [100i16; STRIDE];
        loud[10] = 120;
        assert!(b.add(&loud, 5.0));
        assert_eq!(b.rational(), (100 * STRIDE as i64, STRIDE as i64));
        // Quiet but offset by 1 (within the stride mean's band of one count): enters, in two
        // pieces.
        assert!(!b.add(&[101; 10], 5.0));
        assert!(b.add(&[101; STRIDE - 10], 5.0));
        assert_eq!(b.rational(), (201 * STRIDE as i64, 2 * STRIDE as i64));
        assert_eq!(b.mean(), 100.5);
        // Flat but 3 counts off: its mean is beyond its own noise, so it is not the zero.
        assert!(b.add(&[103; STRIDE], 5.0));
        assert_eq!(b.rational(), (201 * STRIDE as i64, 2 * STRIDE as i64));
    }

    #[test]
    fn restarting_at_a_level_keeps_it_exactly() {
        let mut b = Baseline::<64>::new();
        b.add(&[5; STRIDE], 2.0);
        // 3 strides summing to 1000 * 192 + 7 counts: their mean, exactly.
        b.restart_at(1000 * 192 + 7, 3 * STRIDE as i64);
        assert_eq!(b.rational(), (1000 * 192 + 7, 3 * STRIDE as i64));
        b.restart_at(-64 * 3, STRIDE as i64);
        assert_eq!(b.rational(), (-192, STRIDE as i64));
        assert_eq!(b.mean(), -3.0);
    }

    #[test]
    fn a_slow_ramp_below_the_edge_level_is_not_learned() {
        // Noise of ±10 counts around 0; then strides whose mean creeps up by 3 counts each
        // (well inside the edge level of 50): the baseline stays at the sensor's zero.
        let noisy = |offset: i16| -> [i16; STRIDE] {
            core::array::from_fn(|i| offset + [-10, -3, 4, 10, 0, -6, 7, 2][i % 8])
        };
        let mut b = Baseline::<64>::new();
        for _ in 0..32 {
            b.add(&noisy(0), 50.0);
        }
        let zero = b.mean();
        for k in 1..=10 {
            b.add(&noisy(3 * k), 50.0);
        }
        assert!((b.mean() - zero).abs() < 0.5, "{} {zero}", b.mean());
        // A stride of plain noise still enters.
        let (_, n) = b.rational();
        b.add(&noisy(1), 50.0);
        assert_eq!(b.rational().1, n + STRIDE as i64);
    }
}
