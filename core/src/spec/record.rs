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
