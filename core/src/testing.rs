//! What the unit tests share (test builds only).

/// Uniform noise in `[-0.5, 0.5)` from a fixed generator (a 64-bit LCG, Knuth's MMIX
/// constants): the same sequence for the same `seed` on every machine.
pub(crate) fn uniform(seed: u64) -> impl FnMut() -> f32 {
    let mut state = seed;
    move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((state >> 40) as f32 / (1u64 << 24) as f32) - 0.5
    }
}
