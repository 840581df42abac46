//! Order statistics (the median) of a stream of any length, in fixed memory, to 0.2 % of the
//! value.
//!
//! Each value falls in one of 2^20 bins by the top 20 bits of its order-preserving bit
//! pattern: the sign, the 11 exponent bits and 8 mantissa bits. A bin spans 1/256 of its
//! values' magnitude, and a bin stands for its middle, so a statistic taken from the
//! histogram is within 0.2 % of the exact one (bins near zero: within 1e-300). It is the
//! same number however the values were split into blocks or whether they were held in
//! memory, which is what lets a recording read in passes give the whole-file reports.

/// Bits of the order key that pick the bin.
const KEY_BITS: u32 = 20;

/// Counts per bin of a stream of `f64` values (8 MiB, zeroed lazily by the allocator).
pub struct OrderHistogram {
    counts: Vec<u64>,
    n: u64,
}

impl Default for OrderHistogram {
    fn default() -> Self {
        Self::new()
    }
}

impl OrderHistogram {
    pub fn new() -> Self {
        Self {
            counts: vec![0; 1 << KEY_BITS],
            n: 0,
        }
    }

    /// Values added so far.
    pub fn len(&self) -> u64 {
        self.n
    }

    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    #[inline]
    pub fn add(&mut self, v: f64) {
        // The key is below 2^KEY_BITS, the table's length.
        if let Some(c) = self.counts.get_mut(key(v)) {
            *c += 1;
        }
        self.n += 1;
    }

    /// Adds each value.
    pub fn add_all(&mut self, values: impl Iterator<Item = f64>) {
        let counts = &mut self.counts[..1 << KEY_BITS];
        let mut n = 0u64;
        for v in values {
            // The key is below 2^KEY_BITS, the slice's length.
            counts[key(v) & ((1 << KEY_BITS) - 1)] += 1;
            n += 1;
        }
        self.n += n;
    }

    /// The `k`-th smallest value (from 0), to the bins' resolution; `None` if `k` is not
    /// below the count.
    pub fn select(&self, k: u64) -> Option<f64> {
        if k >= self.n {
            return None;
        }
        let mut below = 0u64;
        for (bin, &c) in self.counts.iter().enumerate() {
            below += c;
            if below > k {
                return Some(value_of(bin));
            }
        }
        None
    }

    /// The median as `select_nth_unstable(len / 2)` picks it (the upper one of an even
    /// count), to the bins' resolution.
    pub fn median(&self) -> Option<f64> {
        self.select(self.n / 2)
    }
}

/// The bin of `v`: the top bits of its bit pattern ordered as the values are (negative
/// values' bits inverted, positive ones' sign bit set).
#[inline]
fn key(v: f64) -> usize {
    let b = v.to_bits();
    let ordered = if b >> 63 == 1 { !b } else { b | 1 << 63 };
    (ordered >> (64 - KEY_BITS)) as usize
}

/// The value a bin stands for: its middle in bit pattern (0 for the two bins at zero).
fn value_of(bin: usize) -> f64 {
    let ordered = ((bin as u64) << (64 - KEY_BITS)) | 1 << (63 - KEY_BITS);
    let b = if ordered >> 63 == 1 {
        ordered & !(1 << 63)
    } else {
        !ordered
    };
    if bin == key(0.0) || bin == key(-0.0) {
        return 0.0;
    }
    f64::from_bits(b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bins_keep_the_order_and_stand_within_a_fifth_of_a_percent() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let mut last = None;
        let mut values: Vec<f64> = (0..20_000)
            .map(|_| {
                let u = (next() >> 11) as f64 / (1u64 << 53) as f64;
                let e = (next() % 80) as i32 - 40;
                (u - 0.5) * 2f64.powi(e)
            })
            .collect();
        values.extend([0.0, -0.0, 1e-310, -1e-310, f64::MAX, -f64::MAX]);
        values.sort_by(f64::total_cmp);
        for &v in &values {
            let k = key(v);
            if let Some(l) = last {
                assert!(k >= l, "{v}: bin {k} before {l}");
            }
            last = Some(k);
            let r = value_of(k);
            if v.abs() > 1e-300 {
                assert!(((r - v) / v).abs() <= 1.0 / 512.0, "{v} stands as {r}");
            } else {
                assert!(r.abs() < 1e-300);
            }
        }
    }

    #[test]
    fn the_median_is_the_exact_one_to_its_bin() {
        let x: Vec<f64> = (0..1001)
            .map(|i| ((i * 7919) % 1001) as f64 * 0.37 - 50.0)
            .collect();
        let mut h = OrderHistogram::new();
        x.iter().for_each(|&v| h.add(v));
        let mut sorted = x.clone();
        sorted.sort_by(f64::total_cmp);
        for k in [0, 1, 500, 999, 1000] {
            let got = h.select(k as u64).unwrap();
            let want = sorted[k];
            assert!(
                (got - want).abs() <= want.abs() / 512.0,
                "{k}: {got} vs {want}"
            );
        }
        assert_eq!(h.select(1001), None);
        assert_eq!(OrderHistogram::new().median(), None);
        let mut zeros = OrderHistogram::new();
        (0..9).for_each(|_| zeros.add(0.0));
        assert_eq!(zeros.median(), Some(0.0));
    }
}
