//! Both responses of a band over a block, keeping each one's largest `|y|`: the second
//! pass's work (the blocks whose bound reaches the peak so far; on the seed's impact some
//! 15 of 102 at each full-rate band). Portable, and on the Cortex-M4 a loop of 16 samples
//! per pass that loads 8 at a time (`VLDM`) into one of two banks of registers and keeps
//! the largest `|y|` in core registers: both outputs go over in one `VMOV`, and each is
//! compared as its bits shifted left by one (the sign dropped) with a shifted `CMP` and a
//! conditional `LSL`. Each sample costs its two multiply-subtracts, six multiply(-add)s,
//! the move and two compare-and-keeps: 15.25 instructions with the loads and the loop's
//! count, where the compiled loop took some 19 (an absolute value, a `VCMP` and a `VMRS`
//! for each response). The same operations in the same order as the portable loop, so the
//! same bits (`the_tops_are_the_responses` on the host; on the board, `m4-bench selftest`).
//!
//! The largest `|y|` is kept as a key: `|y|`'s bits shifted left by one, compared as
//! integers. For every number, infinities included, that orders as `|y|` does, and a key
//! is kept only when it is larger, so the first of equal largest values stays, as a float
//! comparison keeps it; a NaN, which a float comparison would pass over, ranks above
//! everything (on the board the input is ADC codes, whose responses are finite).

use super::skim::State;

/// Both oscillators' constants: the poles `[a1, a2]` and the numerators.
#[derive(Clone, Copy)]
pub(super) struct Filter {
    pub(super) a: [f32; 2],
    pub(super) num: [[f32; 3]; 2],
}

/// A response's largest `|y|` as a key: `|y|`'s bits, shifted left by one.
pub(super) fn key(y: f32) -> u32 {
    y.to_bits() << 1
}

/// The `|y|` of a [`key`].
pub(super) fn value(key: u32) -> f32 {
    f32::from_bits(key >> 1)
}

/// Both responses over `block` from `s`, keeping in `tops` each one's largest [`key`]: the
/// state after it.
#[inline]
pub(super) fn tops(f: &Filter, s: State, tops: &mut [u32; 2], block: &[f32]) -> State {
    #[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
    {
        let (head, rest) = block.split_at(block.len() - block.len() % m4::GROUP);
        let s = m4::tops(f, s, tops, head);
        portable(f, s, tops, rest)
    }
    #[cfg(not(all(target_arch = "arm", target_abi = "eabihf")))]
    {
        portable(f, s, tops, block)
    }
}

/// One sample: the recursion, both outputs, each kept if its key is the largest so far.
#[inline(always)]
pub(super) fn step(f: &Filter, s: &mut State, tops: &mut [u32; 2], x: f32) -> [f32; 2] {
    let [a1, a2] = f.a;
    let [[b0, b1, b2], [c0, c1, c2]] = f.num;
    let w = x - a1 * s.w1 - a2 * s.w2;
    let ya = b0 * w + b1 * s.w1 + b2 * s.w2;
    let yp = c0 * w + c1 * s.w1 + c2 * s.w2;
    (s.w3, s.w2, s.w1) = (s.w2, s.w1, w);
    let [ta, tp] = tops;
    // Integer comparisons: no branch, no `VMRS`.
    if key(ya) > *ta {
        *ta = key(ya);
    }
    if key(yp) > *tp {
        *tp = key(yp);
    }
    [ya, yp]
}

/// Both responses sample by sample.
pub(super) fn portable(f: &Filter, mut s: State, tops: &mut [u32; 2], block: &[f32]) -> State {
    for &x in block {
        step(f, &mut s, tops, x);
    }
    s
}

/// The first length of `x` (up to its own, from a few states, filters and kept keys) at
/// which [`tops`] differs from [`portable`] by a bit in the state or the keys, or
/// `x.len() + 1` if they differ over a block of special values (±0, subnormals, the largest
/// finite, ±∞, NaN): the board's self-test of its routine (`m4-bench selftest`; on the host
/// both are the portable loop).
pub fn mismatch(x: &[f32]) -> Option<usize> {
    let filters = [
        Filter {
            a: [-1.9, 0.93],
            num: [[0.01, 0.02, 0.015], [0.5, -0.25, -0.125]],
        },
        Filter {
            a: [-1.999, 0.9995],
            num: [[1e-3, 2e-3, -1e-3], [3.0, 0.0, -3.0]],
        },
        Filter {
            a: [0.3, 0.2],
            num: [[-1.0, 0.5, 0.25], [0.125, 0.75, -0.5]],
        },
    ];
    let starts = [
        (0.0f32, 0.0f32, [0u32, 0]),
        (0.25, -1.5, [key(0.5), key(3.0)]),
    ];
    let differ = |block: &[f32]| {
        filters.iter().any(|f| {
            starts.iter().any(|&(w1, w2, kept)| {
                let s = State { w1, w2, w3: 7.0 };
                let (mut fast_tops, mut slow_tops) = (kept, kept);
                let fast = tops(f, s, &mut fast_tops, block);
                let slow = portable(f, s, &mut slow_tops, block);
                fast_tops != slow_tops
                    || [fast.w1, fast.w2, fast.w3].map(f32::to_bits)
                        != [slow.w1, slow.w2, slow.w3].map(f32::to_bits)
            })
        })
    };
    let special: [f32; 32] = core::array::from_fn(|k| match k % 8 {
        0 => 0.0,
        1 => -0.0,
        2 => 1e-40,
        3 => -1e-40,
        4 => f32::MAX,
        5 if k < 16 => f32::INFINITY,
        5 => f32::NEG_INFINITY,
        6 if k > 24 => f32::NAN,
        _ => k as f32 - 16.0,
    });
    (0..=x.len())
        .find(|&len| differ(x.get(..len).unwrap_or(&[])))
        .or_else(|| differ(&special).then_some(x.len() + 1))
}

#[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
#[allow(unsafe_code)]
mod m4 {
    use super::{Filter, State};

    /// Samples per pass of the routine.
    pub(super) const GROUP: usize = 16;

    /// What the routine reads and writes: the state `[w1, w2, w3]` and the two keys.
    #[repr(C)]
    struct Io {
        w: [f32; 3],
        tops: [u32; 2],
    }

    extern "C" {
        /// Both responses over `groups` × 16 samples from the word-aligned `x`: `io` holds
        /// the state (its first two read, all three written) and the keys (read and
        /// written); `k` is `[a1, a2, b0, b1, b2, c0, c1, c2]`.
        fn impact_core_tops_f32(x: *const f32, groups: usize, io: *mut Io, k: *const [f32; 8]);
    }

    /// `x.len()` a multiple of [`GROUP`] (a shorter remainder is left alone).
    #[inline]
    pub(super) fn tops(f: &Filter, s: State, tops: &mut [u32; 2], x: &[f32]) -> State {
        let groups = x.len() / GROUP;
        if groups == 0 {
            return s;
        }
        let [a1, a2] = f.a;
        let [[b0, b1, b2], [c0, c1, c2]] = f.num;
        let k = [a1, a2, b0, b1, b2, c0, c1, c2];
        let mut io = Io {
            w: [s.w1, s.w2, s.w3],
            tops: *tops,
        };
        // SAFETY: `x` holds at least `groups` × 16 f32 (word-aligned, as every f32 is); the
        // routine reads them and `k`, reads and writes `io` and nothing else, and saves the
        // callee-saved registers it uses (r4 to r7, s16 to s25).
        unsafe { impact_core_tops_f32(x.as_ptr(), groups, &mut io, &k) };
        *tops = io.tops;
        let [w1, w2, w3] = io.w;
        State { w1, w2, w3 }
    }

    // r0 = x, r1 = groups (> 0), r2 = io, r3 = k. s16, s17 = a1, a2; s18 to s20 = b0 to b2;
    // s21 to s23 = c0 to c2; the outputs in s24, s25; the keys in r6, r7. The state's w1 and
    // w2 in s15 and s14 (the last bank's last two). A sample `x` whose two before are `p`, `q`:
    // w = x - a1 p, then - a2 q; ya = b0 w + b1 p + b2 q; yp likewise; then each output's
    // bits, shifted left by one, kept if larger than its key (`CMP` with the shifted
    // operand, `LSL` if lower).
    core::arch::global_asm!(
        ".syntax unified",
        ".thumb",
        ".fpu fpv4-sp-d16",
        ".section .text.impact_core_tops_f32,\"ax\",%progbits",
        ".global impact_core_tops_f32",
        ".type impact_core_tops_f32,%function",
        ".macro impact_core_tops_step x, p, q",
        "vmls.f32 \\x, s16, \\p",
        "vmls.f32 \\x, s17, \\q",
        "vmul.f32 s24, s18, \\x",
        "vmla.f32 s24, s19, \\p",
        "vmla.f32 s24, s20, \\q",
        "vmul.f32 s25, s21, \\x",
        "vmla.f32 s25, s22, \\p",
        "vmla.f32 s25, s23, \\q",
        "vmov r4, r5, s24, s25",
        "cmp.w r6, r4, lsl #1",
        "it lo",
        "lsllo r6, r4, #1",
        "cmp.w r7, r5, lsl #1",
        "it lo",
        "lsllo r7, r5, #1",
        ".endm",
        ".thumb_func",
        "impact_core_tops_f32:",
        "push {{r4, r5, r6, r7}}",
        "vpush {{s16-s25}}",
        "vldmia r3, {{s16-s23}}",
        "vldr s15, [r2]",
        "vldr s14, [r2, #4]",
        "ldr r6, [r2, #12]",
        "ldr r7, [r2, #16]",
        "1:",
        "vldmia r0!, {{s0-s7}}",
        "impact_core_tops_step s0, s15, s14",
        "impact_core_tops_step s1, s0, s15",
        "impact_core_tops_step s2, s1, s0",
        "impact_core_tops_step s3, s2, s1",
        "impact_core_tops_step s4, s3, s2",
        "impact_core_tops_step s5, s4, s3",
        "impact_core_tops_step s6, s5, s4",
        "impact_core_tops_step s7, s6, s5",
        "vldmia r0!, {{s8-s15}}",
        "impact_core_tops_step s8, s7, s6",
        "impact_core_tops_step s9, s8, s7",
        "impact_core_tops_step s10, s9, s8",
        "impact_core_tops_step s11, s10, s9",
        "impact_core_tops_step s12, s11, s10",
        "impact_core_tops_step s13, s12, s11",
        "impact_core_tops_step s14, s13, s12",
        "impact_core_tops_step s15, s14, s13",
        "subs r1, r1, #1",
        "bne 1b",
        "vstr s15, [r2]",
        "vstr s14, [r2, #4]",
        "vstr s13, [r2, #8]",
        "str r6, [r2, #12]",
        "str r7, [r2, #16]",
        "vpop {{s16-s25}}",
        "pop {{r4, r5, r6, r7}}",
        "bx lr",
        ".purgem impact_core_tops_step",
        ".size impact_core_tops_f32, . - impact_core_tops_f32",
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Both responses kept as keys are each response's largest `|y|`, one output at a
    /// time, bit for bit, at every length up to 70 and from any state; the first of equal
    /// largest values; a key is never taken for a smaller value.
    #[test]
    fn the_tops_are_the_responses() {
        let f = Filter {
            a: [-1.9, 0.93],
            num: [[0.01, 0.02, 0.015], [0.5, -0.25, -0.125]],
        };
        let x: [f32; 70] = core::array::from_fn(|k| ((k * 37 % 11) as f32 - 5.0) * 0.37);
        for len in 0..=x.len() {
            let s = State {
                w1: 0.25,
                w2: -1.5,
                w3: 3.0,
            };
            let (mut w1, mut w2) = (s.w1, s.w2);
            let mut top = [0.0f32; 2];
            for &v in &x[..len] {
                let w = v - f.a[0] * w1 - f.a[1] * w2;
                for (t, [b0, b1, b2]) in top.iter_mut().zip(f.num) {
                    let y: f32 = b0 * w + b1 * w1 + b2 * w2;
                    if y.abs() > *t {
                        *t = y.abs();
                    }
                }
                (w2, w1) = (w1, w);
            }
            let mut kept = [0u32; 2];
            let end = tops(&f, s, &mut kept, &x[..len]);
            assert_eq!(
                kept.map(value).map(f32::to_bits),
                top.map(f32::to_bits),
                "{len}"
            );
            assert_eq!(
                [end.w1, end.w2].map(f32::to_bits),
                [w1, w2].map(f32::to_bits)
            );
            assert_eq!(mismatch(&x[..len]), None);
        }
        // The key orders as |y| does, signs and infinities included.
        let ordered = [0.0f32, 1e-40, 1e-3, 1.0, 3.5, f32::MAX, f32::INFINITY];
        for pair in ordered.windows(2) {
            assert!(key(pair[0]) < key(pair[1]) && key(-pair[0]) < key(pair[1]));
            assert_eq!(key(-pair[1]), key(pair[1]));
        }
        assert_eq!(value(key(-2.5)), 2.5);
    }
}
