//! Copying runs of raw samples: `copy_from_slice`, with a word-wise `LDM`/`STM` loop on the
//! Cortex-M4 (the generic `memcpy` there moves one word per five instructions).

/// Copies `src` into the start of `dst` (as many samples as both hold).
#[inline]
pub fn copy_samples(dst: &mut [i16], src: &[i16]) {
    let n = dst.len().min(src.len());
    let (dst, src) = (&mut dst[..n], &src[..n]);
    #[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
    {
        words::copy(dst, src)
    }
    #[cfg(not(all(target_arch = "arm", target_abi = "eabihf")))]
    {
        dst.copy_from_slice(src)
    }
}

#[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
#[allow(unsafe_code)]
mod words {
    extern "C" {
        /// Copies `words` 32-bit words from word-aligned `src` to word-aligned `dst`.
        fn impact_core_copy_words(dst: *mut i16, src: *const i16, words: usize);
        /// As `impact_core_copy_words` from a `src` on a half-word boundary (the M4's
        /// single-word loads accept any alignment; `LDM` does not).
        fn impact_core_copy_words_from_halfword(dst: *mut i16, src: *const i16, words: usize);
    }

    /// Equal lengths (others copy nothing). Word-wise once `dst` is on a word boundary.
    #[inline]
    pub fn copy(dst: &mut [i16], src: &[i16]) {
        if dst.len() != src.len() {
            return;
        }
        let phase = |p: usize| (p / 2) & 1;
        let (d, s) = (dst.as_ptr() as usize, src.as_ptr() as usize);
        if dst.len() < 8 {
            // No `memcpy` call for an empty run.
            if !dst.is_empty() {
                dst.copy_from_slice(src);
            }
            return;
        }
        let aligned = phase(d) == phase(s);
        let head = phase(d);
        let (dst_head, dst) = dst.split_at_mut(head);
        let (src_head, src) = src.split_at(head);
        // Single samples by hand: a `memcpy` call would cost more than the sample.
        for (d, s) in dst_head.iter_mut().zip(src_head) {
            *d = *s;
        }
        let words = dst.len() / 2;
        let (dst_mid, dst_tail) = dst.split_at_mut(2 * words);
        let (src_mid, src_tail) = src.split_at(2 * words);
        // SAFETY: `dst_mid` is word-aligned (head skipped), `src_mid` is too when `aligned`
        // (else the routine loads it word by word, unaligned); both hold `words` words and do
        // not overlap (a `&mut` and a `&` slice); the routines touch nothing else.
        unsafe {
            if aligned {
                impact_core_copy_words(dst_mid.as_mut_ptr(), src_mid.as_ptr(), words)
            } else {
                impact_core_copy_words_from_halfword(dst_mid.as_mut_ptr(), src_mid.as_ptr(), words)
            }
        };
        for (d, s) in dst_tail.iter_mut().zip(src_tail) {
            *d = *s;
        }
    }

    // r0 = dst, r1 = src, r2 = words: four words per LDM/STM pair, then one at a time.
    core::arch::global_asm!(
        ".syntax unified",
        ".thumb",
        ".section .text.impact_core_copy_words,\"ax\",%progbits",
        ".global impact_core_copy_words",
        ".type impact_core_copy_words,%function",
        ".thumb_func",
        "impact_core_copy_words:",
        "push {{r4, r5, r6, lr}}",
        "subs r2, r2, #4",
        "blo 2f",
        "1:",
        "ldmia r1!, {{r3, r4, r5, r6}}",
        "stmia r0!, {{r3, r4, r5, r6}}",
        "subs r2, r2, #4",
        "bhs 1b",
        "2:",
        "adds r2, r2, #4",
        "beq 4f",
        "3:",
        "ldr r3, [r1], #4",
        "str r3, [r0], #4",
        "subs r2, r2, #1",
        "bne 3b",
        "4:",
        "pop {{r4, r5, r6, pc}}",
        ".size impact_core_copy_words, . - impact_core_copy_words",
    );

    // r0 = dst (word-aligned), r1 = src (half-word aligned), r2 = words: four single
    // (unaligned) loads and one STM, then one at a time.
    core::arch::global_asm!(
        ".syntax unified",
        ".thumb",
        ".section .text.impact_core_copy_words_from_halfword,\"ax\",%progbits",
        ".global impact_core_copy_words_from_halfword",
        ".type impact_core_copy_words_from_halfword,%function",
        ".thumb_func",
        "impact_core_copy_words_from_halfword:",
        "push {{r4, r5, r6, lr}}",
        "subs r2, r2, #4",
        "blo 2f",
        "1:",
        "ldr r3, [r1], #4",
        "ldr r4, [r1], #4",
        "ldr r5, [r1], #4",
        "ldr r6, [r1], #4",
        "stmia r0!, {{r3, r4, r5, r6}}",
        "subs r2, r2, #4",
        "bhs 1b",
        "2:",
        "adds r2, r2, #4",
        "beq 4f",
        "3:",
        "ldr r3, [r1], #4",
        "str r3, [r0], #4",
        "subs r2, r2, #1",
        "bne 3b",
        "4:",
        "pop {{r4, r5, r6, pc}}",
        ".size impact_core_copy_words_from_halfword, . - impact_core_copy_words_from_halfword",
    );
}
