//! What a verdict reads: the acceleration by stream index, and, where the record keeps it
//! in one piece, a run of it at once (the one pass over the watched window, some 4 000
//! samples of the seed's 3 ms pulse at 500 kS/s, without an index's checks at each sample).

/// The acceleration a verdict judges, m/s² in the pulse's direction.
pub trait Record {
    /// Sample `i` (a stream index); `None` outside what the record holds.
    fn at(&self, i: u64) -> Option<f32>;

    /// Samples `from..from + out.len()` into `out`, each [`Record::at`]'s value, if the
    /// record holds every one and can give them at once; `false` (the default) leaves them
    /// to be read one by one.
    fn run(&self, from: u64, out: &mut [f32]) -> bool {
        let _ = (from, out);
        false
    }
}

/// A reader by index alone.
impl<F: Fn(u64) -> Option<f32>> Record for F {
    fn at(&self, i: u64) -> Option<f32> {
        self(i)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spec::verdict::{judge_in, tests::spec, SCRATCH};
    use crate::spec::Shape;
    extern crate std;
    use std::vec;
    use std::vec::Vec;

    /// Samples from stream index `offset` on, giving a run at once where it holds it.
    struct Slice<'a> {
        x: &'a [f32],
        offset: u64,
    }

    impl Record for Slice<'_> {
        fn at(&self, i: u64) -> Option<f32> {
            let k = usize::try_from(i.checked_sub(self.offset)?).ok()?;
            self.x.get(k).copied()
        }

        fn run(&self, from: u64, out: &mut [f32]) -> bool {
            let k = from.checked_sub(self.offset).map(|k| k as usize);
            match k.and_then(|k| self.x.get(k..k + out.len())) {
                Some(src) => {
                    out.copy_from_slice(src);
                    true
                }
                None => false,
            }
        }
    }

    /// A record read in one run (the workspace holding the window) gives the verdict, or
    /// the missing side, that reading it sample by sample gives: a half-sine that passes, one
    /// too high, one with a glitch, one with a NaN, and records that end before the window
    /// does or start after it.
    #[test]
    fn a_record_read_in_one_run_judges_as_one_read_by_sample() {
        let spec = spec(Shape::HalfSine);
        let (rate, start, n) = (50_000.0f32, 2000usize, 550usize);
        let mut runs = 0;
        for (peak, glitch, from, len) in [
            (500.0f32, None, 0u64, 10_000usize),
            (650.0, None, 0, 10_000),
            (500.0, Some((2800, 150.0)), 0, 10_000),
            (500.0, Some((2300, f32::NAN)), 0, 10_000),
            (500.0, None, 0, 2900),
            (500.0, None, 1900, 8000),
        ] {
            let mut x: Vec<f32> = (0..10_000)
                .map(|i| peak * spec.shape.at((i as f32 - start as f32) / n as f32))
                .collect();
            if let Some((at, v)) = glitch {
                x[at] = v;
            }
            let x = &x[from as usize..(from as usize + len).min(10_000)];
            let peak_index = (start + n / 2) as u64;
            let mut scratch = vec![0.0f32; SCRATCH + 10_000];
            let whole = judge_in(
                Slice { x, offset: from },
                rate,
                &spec,
                peak_index,
                &mut scratch,
            );
            let by_sample = |i: u64| Slice { x, offset: from }.at(i);
            let one_by_one = judge_in(by_sample, rate, &spec, peak_index, &mut scratch);
            assert_eq!(whole, one_by_one, "{peak} {glitch:?} {from} {len}");
            runs += usize::from(whole.is_ok());
        }
        assert_eq!(runs, 3);
    }
}
