//! The Cortex-M4's cycle timings (TRM) for an executed instruction: the estimate of cycles
//! from the exact instruction counts.

use super::disasm::Insn;

/// Pipeline refill after a taken branch, cycles (the M4 TRM gives 1 to 3).
pub(super) const REFILL: u32 = 2;

/// Registers in a `{r4, r5-r7, lr}` list (a D register counts as two words).
pub(super) fn register_count(operands: &str) -> u32 {
    let Some(list) = operands
        .split_once('{')
        .and_then(|(_, r)| r.split_once('}'))
        .map(|(l, _)| l)
    else {
        return 1;
    };
    list.split(',')
        .map(|r| {
            let r = r.trim();
            let words = if r.starts_with('d') { 2 } else { 1 };
            let n = match r.split_once('-') {
                Some((a, b)) => {
                    let num = |s: &str| {
                        s.trim()
                            .trim_start_matches(|c: char| c.is_ascii_alphabetic())
                            .parse::<u32>()
                            .unwrap_or(0)
                    };
                    num(b).saturating_sub(num(a)) + 1
                }
                None => 1,
            };
            n * words
        })
        .sum()
}

pub(super) const CONDITIONS: [&str; 14] = [
    "eq", "ne", "cs", "hs", "cc", "lo", "mi", "pl", "vs", "vc", "hi", "ls", "ge", "lt",
];
pub(super) const MORE_CONDITIONS: [&str; 3] = ["gt", "le", "al"];

pub(super) fn is_condition(s: &str) -> bool {
    CONDITIONS.contains(&s) || MORE_CONDITIONS.contains(&s)
}

/// Estimated Cortex-M4 cycles of one executed instruction (Cortex-M4 TRM, tables 3-1 and 7-1;
/// zero-wait-state memory, as behind the STM32F4's ART accelerator): `taken` says whether
/// the next executed instruction is not the next in memory, `after_load` whether the
/// previous one was a single load (which the next load or store pipelines with).
pub(super) fn cycles(insn: &Insn, taken: bool, after_load: bool) -> u32 {
    let full = insn.mnemonic.as_str();
    let base = full.split('.').next().unwrap_or(full);
    let ops = insn.operands.as_str();
    let writes_pc = ops.split(',').next().is_some_and(|d| d.trim() == "pc");
    let branch_like = matches!(base, "b" | "bl" | "blx" | "bx" | "cbz" | "cbnz")
        || (base.len() == 3 && base.starts_with('b') && is_condition(&base[1..]));
    if branch_like {
        return if taken { 1 + REFILL } else { 1 };
    }
    if matches!(base, "tbb" | "tbh") {
        return 2 + 1 + REFILL;
    }
    let n = register_count(ops);
    let single_load =
        base.starts_with("ldr") && !base.starts_with("ldrd") && !base.starts_with("ldrex");
    match base {
        _ if base.starts_with("pop") || base.starts_with("ldm") => {
            1 + n + if ops.contains("pc") { REFILL } else { 0 }
        }
        _ if base.starts_with("push") || base.starts_with("stm") => 1 + n,
        "vpush" | "vpop" | "vldmia" | "vldmdb" | "vstmia" | "vstmdb" | "vldm" | "vstm" => 1 + n,
        _ if base.starts_with("ldrd") || base.starts_with("strd") => 3,
        _ if single_load && writes_pc => 2 + REFILL,
        _ if single_load => {
            if after_load {
                1
            } else {
                2
            }
        }
        _ if base.starts_with("str") => {
            // Register offset: two cycles; immediate offset: one (the write buffer).
            let register_offset = ops.split_once('[').is_some_and(|(_, a)| {
                a.split(',')
                    .nth(1)
                    .is_some_and(|o| o.trim().starts_with('r'))
            });
            if register_offset {
                2
            } else {
                1
            }
        }
        "vldr" | "vstr" => {
            if ops.trim_start().starts_with('d') {
                3
            } else {
                2
            }
        }
        "sdiv" | "udiv" => 12,
        "mla" | "mls" => 2,
        "vmla" | "vmls" | "vnmla" | "vnmls" | "vfma" | "vfms" | "vfnma" | "vfnms" => 3,
        "vdiv" | "vsqrt" => 14,
        "vmov" if ops.matches(',').count() >= 2 => 2,
        _ if writes_pc => 1 + REFILL,
        _ => 1,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn insn(mnemonic: &str, operands: &str) -> Insn {
        Insn {
            size: 4,
            mnemonic: mnemonic.into(),
            operands: operands.into(),
        }
    }

    #[test]
    fn cortex_m4_timings() {
        // Cortex-M4 TRM: ALU 1, loads 2 (1 when pipelined after a load), immediate-offset
        // stores 1, LDM/STM/PUSH/POP 1 + N (+ refill when loading pc), taken branches
        // 1 + refill, MLA 2, divisions 2..12 (12 taken), VMLA 3, VDIV/VSQRT 14.
        assert_eq!(cycles(&insn("adds", "r0, r1, r2"), false, false), 1);
        assert_eq!(
            cycles(&insn("ldrsh.w", "r6, [r0, r3, lsl #1]"), false, false),
            2
        );
        assert_eq!(cycles(&insn("ldr", "r1, [r2, #4]"), false, true), 1);
        assert_eq!(cycles(&insn("str", "r1, [r2, #4]"), false, false), 1);
        assert_eq!(cycles(&insn("str.w", "r1, [r2, r3]"), false, false), 2);
        assert_eq!(
            cycles(&insn("push", "{r4, r5, r6, r7, lr}"), false, false),
            6
        );
        assert_eq!(
            cycles(&insn("pop", "{r4, r5, r6, pc}"), true, false),
            5 + REFILL
        );
        assert_eq!(
            cycles(&insn("ldmia", "r1!, {r3, r4, r5, r6}"), false, false),
            5
        );
        assert_eq!(cycles(&insn("vpush", "{d8-d9}"), false, false), 5);
        assert_eq!(
            cycles(&insn("bne.n", "75ec <f+0x38c>"), true, false),
            1 + REFILL
        );
        assert_eq!(cycles(&insn("bne.n", "75ec <f+0x38c>"), false, false), 1);
        assert_eq!(cycles(&insn("bl", "15eaa <g>"), true, false), 1 + REFILL);
        assert_eq!(cycles(&insn("mla", "r2, r5, r4, r2"), false, false), 2);
        assert_eq!(cycles(&insn("sdiv", "r0, r1, r2"), false, false), 12);
        assert_eq!(cycles(&insn("vmla.f32", "s0, s1, s2"), false, false), 3);
        assert_eq!(cycles(&insn("vsqrt.f32", "s0, s0"), false, false), 14);
        assert_eq!(cycles(&insn("vldr", "d0, [r0]"), false, false), 3);
        assert_eq!(cycles(&insn("vmov", "r0, r1, d0"), false, false), 2);
    }
}
