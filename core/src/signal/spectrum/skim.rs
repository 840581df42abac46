//! A band's recursion alone, `w[n] = x[n] - a1 w[n-1] - a2 w[n-2]`, over a block: the first
//! pass's work, most of the spectra's samples (each full-rate band runs it over the whole
//! window). Portable, and on the Cortex-M4 a loop of 16 samples per pass that loads 8 at a
//! time (`VLDM`) into one of two banks of registers, so each sample costs its two
//! multiply-subtracts, an eighth of a load and an eighth of the loop's count and branch: 2.25
//! instructions where the compiled loop took 3.5 (a load per sample). In cycles the gain is
//! smaller: each `VMLS` takes 3 cycles and a `VLDM` of 8 takes 9, some 7.4 cycles a sample
//! against 8.1 by the Cortex-M4's timings. The same operations in the same order as the
//! portable loop (`VMLS` rounds the product, then the difference, as the host does), so the
//! same bits (`the_skim_is_the_recursion` on the host; on the board, `m4-bench selftest`).

/// The recursion's state before a sample: `w[n-1]`, `w[n-2]` and `w[n-3]` (the last for
/// the output before it).
#[derive(Clone, Copy, Default)]
pub(super) struct State {
    pub(super) w1: f32,
    pub(super) w2: f32,
    pub(super) w3: f32,
}

/// The recursion with poles `a` over `block` from state `s`: the state after it.
#[inline]
pub(super) fn skim(a: [f32; 2], s: State, block: &[f32]) -> State {
    #[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
    {
        let (head, rest) = block.split_at(block.len() - block.len() % m4::GROUP);
        portable(a, m4::skim(a, s, head), rest)
    }
    #[cfg(not(all(target_arch = "arm", target_abi = "eabihf")))]
    {
        portable(a, s, block)
    }
}

/// The recursion sample by sample (two at a time).
pub(super) fn portable([a1, a2]: [f32; 2], s: State, block: &[f32]) -> State {
    let (mut v1, mut v2, mut v3) = (s.w1, s.w2, s.w3);
    let mut pairs = block.chunks_exact(2);
    for pair in &mut pairs {
        if let [x0, x1] = *pair {
            let wa = x0 - a1 * v1 - a2 * v2;
            let wb = x1 - a1 * wa - a2 * v1;
            (v3, v2, v1) = (v1, wa, wb);
        }
    }
    for &x in pairs.remainder() {
        let w = x - a1 * v1 - a2 * v2;
        (v3, v2, v1) = (v2, v1, w);
    }
    State {
        w1: v1,
        w2: v2,
        w3: v3,
    }
}

/// The first length of `x` (up to its own, from a few states and poles) at which [`skim`]
/// differs from [`portable`] by a bit: the board's self-test of its routine (`m4-bench
/// selftest`; on the host both are the portable loop). It does not see a routine that
/// fails to restore s16 and s17, which no caller here holds a value in.
pub fn mismatch(x: &[f32]) -> Option<usize> {
    let poles = [[-1.9f32, 0.93], [-1.999, 0.9995], [0.3, 0.2]];
    let states = [(0.0f32, 0.0f32), (0.25, -1.5), (1e30, -1e-30)];
    (0..=x.len()).find(|&len| {
        let block = x.get(..len).unwrap_or(&[]);
        poles.iter().any(|&a| {
            states.iter().any(|&(w1, w2)| {
                let s = State { w1, w2, w3: 7.0 };
                let (fast, slow) = (skim(a, s, block), portable(a, s, block));
                [fast.w1, fast.w2, fast.w3].map(f32::to_bits)
                    != [slow.w1, slow.w2, slow.w3].map(f32::to_bits)
            })
        })
    })
}

#[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
#[allow(unsafe_code)]
mod m4 {
    use super::State;

    /// Samples per pass of the routine.
    pub(super) const GROUP: usize = 16;

    extern "C" {
        /// The recursion over `groups` × 16 samples from the word-aligned `x`: `state` holds
        /// `[w1, w2, w3]`, read (the first two) and written; `a` is `[a1, a2]`.
        fn impact_core_skim_f32(
            x: *const f32,
            groups: usize,
            state: *mut [f32; 3],
            a: *const [f32; 2],
        );
    }

    /// `x.len()` a multiple of [`GROUP`] (a shorter remainder is left alone).
    #[inline]
    pub(super) fn skim(a: [f32; 2], s: State, x: &[f32]) -> State {
        let groups = x.len() / GROUP;
        if groups == 0 {
            return s;
        }
        let mut state = [s.w1, s.w2, s.w3];
        // SAFETY: `x` holds at least `groups` × 16 f32 (word-aligned, as every f32 is); the
        // routine reads them, reads `a` and `state`, writes `state` and nothing else, and
        // saves the callee-saved registers it uses (s16, s17).
        unsafe { impact_core_skim_f32(x.as_ptr(), groups, &mut state, &a) };
        let [w1, w2, w3] = state;
        State { w1, w2, w3 }
    }

    // r0 = x, r1 = groups (> 0), r2 = state, r3 = a. s16 = a1, s17 = a2; the state's w1 and
    // w2 in s15 and s14 (the last bank's last two). Each sample: w = x - a1 w1, then - a2 w2.
    core::arch::global_asm!(
        ".syntax unified",
        ".thumb",
        ".fpu fpv4-sp-d16",
        ".section .text.impact_core_skim_f32,\"ax\",%progbits",
        ".global impact_core_skim_f32",
        ".type impact_core_skim_f32,%function",
        ".thumb_func",
        "impact_core_skim_f32:",
        "vpush {{s16, s17}}",
        "vldr s16, [r3]",
        "vldr s17, [r3, #4]",
        "vldr s15, [r2]",
        "vldr s14, [r2, #4]",
        "1:",
        "vldmia r0!, {{s0-s7}}",
        "vmls.f32 s0, s16, s15",
        "vmls.f32 s0, s17, s14",
        "vmls.f32 s1, s16, s0",
        "vmls.f32 s1, s17, s15",
        "vmls.f32 s2, s16, s1",
        "vmls.f32 s2, s17, s0",
        "vmls.f32 s3, s16, s2",
        "vmls.f32 s3, s17, s1",
        "vmls.f32 s4, s16, s3",
        "vmls.f32 s4, s17, s2",
        "vmls.f32 s5, s16, s4",
        "vmls.f32 s5, s17, s3",
        "vmls.f32 s6, s16, s5",
        "vmls.f32 s6, s17, s4",
        "vmls.f32 s7, s16, s6",
        "vmls.f32 s7, s17, s5",
        "vldmia r0!, {{s8-s15}}",
        "vmls.f32 s8, s16, s7",
        "vmls.f32 s8, s17, s6",
        "vmls.f32 s9, s16, s8",
        "vmls.f32 s9, s17, s7",
        "vmls.f32 s10, s16, s9",
        "vmls.f32 s10, s17, s8",
        "vmls.f32 s11, s16, s10",
        "vmls.f32 s11, s17, s9",
        "vmls.f32 s12, s16, s11",
        "vmls.f32 s12, s17, s10",
        "vmls.f32 s13, s16, s12",
        "vmls.f32 s13, s17, s11",
        "vmls.f32 s14, s16, s13",
        "vmls.f32 s14, s17, s12",
        "vmls.f32 s15, s16, s14",
        "vmls.f32 s15, s17, s13",
        "subs r1, r1, #1",
        "bne 1b",
        "vstr s15, [r2]",
        "vstr s14, [r2, #4]",
        "vstr s13, [r2, #8]",
        "vpop {{s16, s17}}",
        "bx lr",
        ".size impact_core_skim_f32, . - impact_core_skim_f32",
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The skim is the recursion of one output at a time (a state's `w3` the sample before
    /// `w2`), bit for bit, at every length up to 70 and from any state.
    #[test]
    fn the_skim_is_the_recursion() {
        let a = [-1.9f32, 0.93];
        let x: [f32; 70] = core::array::from_fn(|k| ((k * 37 % 11) as f32 - 5.0) * 0.37);
        for len in 0..=x.len() {
            let s = State {
                w1: 0.25,
                w2: -1.5,
                w3: 3.0,
            };
            let mut w = [s.w3, s.w2, s.w1];
            for &v in &x[..len] {
                let next = v - a[0] * w[2] - a[1] * w[1];
                w = [w[1], w[2], next];
            }
            let got = skim(a, s, &x[..len]);
            assert_eq!(
                [got.w3, got.w2, got.w1].map(f32::to_bits),
                w.map(f32::to_bits),
                "{len}"
            );
        }
    }
}
