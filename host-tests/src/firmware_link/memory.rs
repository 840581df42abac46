//! The firmware's memory budget read off its ELF (`impact bench memory`): flash, the stack, the
//! statics in SRAM (the captures and the other big ones by name), the CCM RAM, and what is
//! free, against the regions of its memory map (`firmware/stm32/board-memory.x`). docs/board.md
//! shows the same table and `tests/memory.rs` holds it to this.

use std::path::{Path, PathBuf};

use object::{Object, ObjectSection, ObjectSymbol};
use serde::Serialize;

/// A memory region of the map: name, origin, length in bytes.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Region {
    pub name: String,
    pub origin: u64,
    pub length: u64,
}

/// Why a linker script's `MEMORY` regions could not be read.
#[derive(Debug, thiserror::Error)]
pub enum RegionsError {
    #[error("no MEMORY block")]
    NoMemoryBlock,
    /// An `ORIGIN` or `LENGTH` that is no number (`0x...`, `64K`, `1M`).
    #[error("{value}: not a size")]
    NotASize { value: String },
}

/// Why the firmware's memory budget could not be read.
#[derive(Debug, thiserror::Error)]
pub enum MemoryError {
    /// The ELF or the memory map could not be read.
    #[error("{}: {source}", .path.display())]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{}: {source}", .elf.display())]
    Elf { elf: PathBuf, source: object::Error },
    #[error("{}: {source}", .map.display())]
    Map { map: PathBuf, source: RegionsError },
    #[error("{}: no region {name}", .map.display())]
    NoRegion { map: PathBuf, name: &'static str },
    /// Cargo could not be started.
    #[error("cargo: {0}")]
    Cargo(std::io::Error),
    #[error("cargo fw failed ({status})")]
    BuildFailed { status: std::process::ExitStatus },
}

/// The `MEMORY` regions of a linker script (`NAME : ORIGIN = 0x..., LENGTH = 64K`).
pub fn regions(script: &str) -> Result<Vec<Region>, RegionsError> {
    let body = script
        .split_once("MEMORY")
        .and_then(|(_, rest)| rest.split_once('{'))
        .and_then(|(_, rest)| rest.split_once('}'))
        .map(|(body, _)| body)
        .ok_or(RegionsError::NoMemoryBlock)?;
    let number = |s: &str| -> Result<u64, RegionsError> {
        let s = s.trim();
        let (digits, scale) = match s.strip_suffix('K') {
            Some(d) => (d, 1024),
            None => match s.strip_suffix('M') {
                Some(d) => (d, 1024 * 1024),
                None => (s, 1),
            },
        };
        let v = match digits.strip_prefix("0x") {
            Some(hex) => u64::from_str_radix(hex, 16),
            None => digits.parse(),
        };
        v.map(|v| v * scale).map_err(|_| RegionsError::NotASize {
            value: s.to_string(),
        })
    };
    let mut out = Vec::new();
    for line in body.lines() {
        let line = line.trim();
        let Some((name, rest)) = line.split_once(':') else {
            continue;
        };
        let (mut origin, mut length) = (None, None);
        for part in rest.split(',') {
            if let Some((key, value)) = part.split_once('=') {
                match key.trim() {
                    "ORIGIN" => origin = Some(number(value)?),
                    "LENGTH" => length = Some(number(value)?),
                    _ => {}
                }
            }
        }
        if let (Some(origin), Some(length)) = (origin, length) {
            out.push(Region {
                name: name.trim().to_string(),
                origin,
                length,
            });
        }
    }
    Ok(out)
}

/// A static of note: its name, size and section.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Static {
    pub name: String,
    pub bytes: u64,
    pub section: String,
}

/// The budget.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Budget {
    /// Flash: code (vector table and `.text`), constants (`.rodata`), the `.data` image.
    pub flash_bytes: u64,
    pub flash_length: u64,
    pub code_bytes: u64,
    pub rodata_bytes: u64,
    pub data_image_bytes: u64,
    /// The stack region, bytes.
    pub stack_bytes: u64,
    /// Statics in SRAM: `.data`, `.bss`, `.uninit`, and the region they have.
    pub data_bytes: u64,
    pub bss_bytes: u64,
    pub uninit_bytes: u64,
    pub ram_length: u64,
    /// The CCM section and its region.
    pub ccm_bytes: u64,
    pub ccm_length: u64,
    /// The statics of 2 KiB or more, biggest first.
    pub big: Vec<Static>,
}

impl Budget {
    /// Bytes of statics in SRAM.
    pub fn statics_bytes(&self) -> u64 {
        self.data_bytes + self.bss_bytes + self.uninit_bytes
    }

    /// The statics named `name` (a substring of the demangled symbol).
    pub fn find(&self, name: &str) -> Option<&Static> {
        self.big.iter().find(|s| s.name.contains(name))
    }
}

/// Reads the budget of `elf`, built with the memory map `map` (a board-memory.x).
pub fn budget(elf: &Path, map: &Path) -> Result<Budget, MemoryError> {
    fn read(path: &Path) -> impl FnOnce(std::io::Error) -> MemoryError + '_ {
        move |source| MemoryError::Read {
            path: path.to_path_buf(),
            source,
        }
    }
    let bytes = std::fs::read(elf).map_err(read(elf))?;
    let file = object::File::parse(&*bytes).map_err(|source| MemoryError::Elf {
        elf: elf.to_path_buf(),
        source,
    })?;
    let script = std::fs::read_to_string(map).map_err(read(map))?;
    let regions = regions(&script).map_err(|source| MemoryError::Map {
        map: map.to_path_buf(),
        source,
    })?;
    let region = |name: &'static str| {
        regions
            .iter()
            .find(|r| r.name == name)
            .map(|r| r.length)
            .ok_or_else(|| MemoryError::NoRegion {
                map: map.to_path_buf(),
                name,
            })
    };
    let size = |name: &str| file.section_by_name(name).map_or(0, |s| s.size());
    let code = size(".vector_table") + size(".text");
    let (rodata, data) = (size(".rodata"), size(".data"));
    let section_of = |index: Option<object::SectionIndex>| -> String {
        index
            .and_then(|i| file.section_by_index(i).ok())
            .and_then(|s| s.name().ok().map(str::to_string))
            .unwrap_or_default()
    };
    let mut big: Vec<Static> = file
        .symbols()
        .filter(|s| s.kind() == object::SymbolKind::Data && s.size() >= 2048)
        .filter_map(|s| {
            let name = s.name().ok()?;
            Some(Static {
                name: demangled(name),
                bytes: s.size(),
                section: section_of(s.section_index()),
            })
        })
        .collect();
    big.sort_by(|a, b| b.bytes.cmp(&a.bytes).then(a.name.cmp(&b.name)));
    Ok(Budget {
        flash_bytes: code + rodata + data,
        flash_length: region("FLASH")?,
        code_bytes: code,
        rodata_bytes: rodata,
        data_image_bytes: data,
        stack_bytes: region("STACK")?,
        data_bytes: data,
        bss_bytes: size(".bss"),
        uninit_bytes: size(".uninit"),
        ram_length: region("RAM")?,
        ccm_bytes: size(".ccmram"),
        ccm_length: region("CCMRAM")?,
        big,
    })
}

/// `crate::path::NAME` of a Rust symbol (its hash dropped), or the symbol as it is.
fn demangled(symbol: &str) -> String {
    // Legacy mangling: _ZN<len><ident>...17h<hash>E.
    let Some(mut rest) = symbol.strip_prefix("_ZN") else {
        return symbol.to_string();
    };
    let mut parts = Vec::new();
    while let Some(end) = rest.find(|c: char| !c.is_ascii_digit()) {
        let Ok(len) = rest[..end].parse::<usize>() else {
            break;
        };
        let Some(ident) = rest.get(end..end + len) else {
            break;
        };
        if !(ident.len() == 17 && ident.starts_with('h')) {
            parts.push(
                ident
                    .replace("$LT$", "<")
                    .replace("$GT$", ">")
                    .replace("..", "::"),
            );
        }
        rest = &rest[end + len..];
    }
    parts.join("::")
}

fn kib(bytes: u64) -> String {
    let k = bytes as f64 / 1024.0;
    if (k - k.round()).abs() < 0.05 {
        format!("{:.0} KiB", k.round())
    } else {
        format!("{k:.1} KiB")
    }
}

/// The table docs/board.md shows.
pub fn table(b: &Budget) -> String {
    let named = |what: &str, name: &str| -> String {
        b.find(name)
            .map(|s| format!("{what} {} ({})", kib(s.bytes), s.section))
            .unwrap_or_default()
    };
    let others: Vec<String> = [
        named("the stream", "STREAM"),
        named("the reporter", "reporter::POOL"),
        named("its queue", "FROM_STREAM"),
        named("the sample queue", "sample_queue::SLOTS"),
        named("the RTT buffer", "logger::BUFFER"),
        named("the logger's staging", "logger::STAGING"),
    ]
    .into_iter()
    .filter(|s| !s.is_empty())
    .collect();
    let mut s = String::new();
    s.push_str("| region | used | what |\n|---|---|---|\n");
    s.push_str(&format!(
        "| flash | {} of {} | code {}, constants {}, `.data` image {} |\n",
        kib(b.flash_bytes),
        kib(b.flash_length),
        kib(b.code_bytes),
        kib(b.rodata_bytes),
        kib(b.data_image_bytes)
    ));
    s.push_str(&format!(
        "| SRAM stack | {} at 0x2000_0000 | below the statics, MPU-guarded (its lowest 32 B and the 32 KiB below SRAM): an overflow faults instead of overwriting them |\n",
        kib(b.stack_bytes)
    ));
    s.push_str(&format!(
        "| SRAM statics | {} of {} ({} free) | {}; {} |\n",
        kib(b.statics_bytes()),
        kib(b.ram_length),
        kib(b.ram_length.saturating_sub(b.statics_bytes())),
        named("2 captures", "capture_queue::SLOTS"),
        others.join(", ")
    ));
    s.push_str(&format!(
        "| CCM RAM | {} of {} | {} |\n",
        kib(b.ccm_bytes),
        kib(b.ccm_length),
        named("the analysis workspace", "WORKSPACE")
    ));
    s
}

/// The board's ELF, built (`cargo fw`) if it is missing; the workspace's memory map.
pub fn board_elf() -> Result<(PathBuf, PathBuf), MemoryError> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_default();
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .map(|d| if d.is_absolute() { d } else { root.join(d) })
        .unwrap_or_else(|| root.join("target"));
    let elf = target.join("thumbv7em-none-eabihf/release/impact-firmware");
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let status = std::process::Command::new(cargo)
        .current_dir(&root)
        .args(["fw", "--quiet"])
        .status()
        .map_err(MemoryError::Cargo)?;
    if !status.success() {
        return Err(MemoryError::BuildFailed { status });
    }
    Ok((elf, root.join("firmware/stm32/board-memory.x")))
}
