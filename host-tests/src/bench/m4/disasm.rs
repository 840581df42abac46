//! The m4-bench ELF's code, disassembled (`arm-none-eabi-objdump`): each instruction by its
//! address, and the address ranges of the firmware's `bench_begin` and `bench_end` marks.

use std::collections::HashMap;
use std::path::Path;
use std::process::Command;

/// One decoded instruction.
#[derive(Clone, Debug)]
pub(super) struct Insn {
    pub(super) size: u32,
    pub(super) mnemonic: String,
    pub(super) operands: String,
}

/// The ELF's code: instruction per address and the marks' address ranges.
pub(super) struct Code {
    pub(super) insns: HashMap<u32, Insn>,
    pub(super) begin: (u32, u32),
    pub(super) end: (u32, u32),
}

pub(super) fn disassemble(elf: &Path) -> Result<Code, super::M4Error> {
    use super::M4Error;
    let out = Command::new("arm-none-eabi-objdump")
        .arg("-d")
        .arg(elf)
        .output()
        .map_err(M4Error::Objdump)?;
    if !out.status.success() {
        return Err(M4Error::ObjdumpFailed {
            elf: elf.to_path_buf(),
        });
    }
    let text = String::from_utf8_lossy(&out.stdout);
    let mut insns = HashMap::new();
    // The function being read, and each function's address range.
    let mut current: Option<String> = None;
    let mut ranges: HashMap<String, (u32, u32)> = HashMap::new();
    for line in text.lines() {
        // Function header: `00000458 <impact_core_vsqrt_f32>:`
        if let Some(name) = line
            .strip_suffix(">:")
            .and_then(|l| l.split_once(" <"))
            .and_then(|(a, n)| u32::from_str_radix(a.trim(), 16).ok().map(|a| (n, a)))
        {
            ranges.insert(name.0.to_string(), (name.1, name.1));
            current = Some(name.0.to_string());
            continue;
        }
        // Instruction: `     458:\teeb1 0ac0 \tvsqrt.f32\ts0, s0`
        let mut fields = line.split('\t');
        let (Some(addr), Some(raw), Some(mnemonic)) = (fields.next(), fields.next(), fields.next())
        else {
            continue;
        };
        let Some(addr) = addr
            .trim()
            .strip_suffix(':')
            .and_then(|a| u32::from_str_radix(a, 16).ok())
        else {
            continue;
        };
        let size = raw.split_whitespace().map(|h| h.len() as u32 / 2).sum();
        let operands = fields.next().unwrap_or("").to_string();
        insns.insert(
            addr,
            Insn {
                size,
                mnemonic: mnemonic.trim().to_string(),
                operands,
            },
        );
        if let Some(n) = &current {
            if let Some(r) = ranges.get_mut(n) {
                r.1 = addr + size;
            }
        }
    }
    let range = |name: &'static str| {
        ranges.get(name).copied().ok_or_else(|| M4Error::NoSymbol {
            elf: elf.to_path_buf(),
            name,
        })
    };
    Ok(Code {
        begin: range("bench_begin")?,
        end: range("bench_end")?,
        insns,
    })
}
