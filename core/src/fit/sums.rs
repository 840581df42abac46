//! Sums of many f32 terms to nearly f64 accuracy at the price of f32 additions: each block of
//! [`BLOCK`] terms is summed in f32 (relative error at most `BLOCK · 2^-24`), the block sums in
//! f64 (a soft-float addition on the Cortex-M4, once per block).

/// Terms per f32 block.
const BLOCK: u32 = 64;

/// `N` running sums.
pub struct Sums<const N: usize> {
    total: [f64; N],
    block: [f32; N],
    count: u32,
}

impl<const N: usize> Sums<N> {
    pub fn new() -> Self {
        Self {
            total: [0.0; N],
            block: [0.0; N],
            count: 0,
        }
    }

    /// Adds one term to each sum.
    #[inline]
    pub fn add(&mut self, terms: [f32; N]) {
        for (b, t) in self.block.iter_mut().zip(terms) {
            *b += t;
        }
        self.count += 1;
        if self.count == BLOCK {
            self.flush();
        }
    }

    fn flush(&mut self) {
        for (t, b) in self.total.iter_mut().zip(self.block.iter_mut()) {
            *t += *b as f64;
            *b = 0.0;
        }
        self.count = 0;
    }

    /// The sums.
    pub fn get(mut self) -> [f64; N] {
        self.flush();
        self.total
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_long_sum_keeps_f64_accuracy_where_plain_f32_drifts() {
        let mut s = Sums::<1>::new();
        let mut plain = 0.0f32;
        let mut exact = 0.0f64;
        for k in 0..100_000 {
            let t = 1.0 + (k % 7) as f32 * 1e-3;
            s.add([t]);
            plain += t;
            exact += t as f64;
        }
        let [sum] = s.get();
        assert!((sum / exact - 1.0).abs() < 1e-6, "{sum} {exact}");
        assert!(
            (plain as f64 / exact - 1.0).abs() > 1e-4,
            "f32 alone would drift"
        );
    }
}
