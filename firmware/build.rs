//! Puts the target's memory map on the linker search path, chosen by cargo feature
//! (embassy-stm32's `memory-x` feature is off). cortex-m-rt's `link.x` includes the
//! workspace root's `memory.x`, which includes `board-memory.x` from that path:
//!
//! * `stm32` (default): `firmware/stm32/board-memory.x` (STM32F407VG flash and SRAM);
//! * `emulator`: `firmware/emulator/board-memory.x` (QEMU `mps2-an386`: the board's
//!   regions and sizes at the MPS2's addresses);
//! * `m4-bench` (implies `emulator`): `firmware/m4-bench/board-memory.x`, the emulator's map
//!   with all 4 MiB of data RAM for statics (the bench holds a whole recording in RAM);
//! * `panic-check` alone (neither of the above): the M4 bench's map, for the `panic-check`
//!   binary (`src/bin/panic_check.rs`), which never runs: it only has to link, and its one
//!   `Monitor` holds the analysis workspace the board keeps in CCM RAM beside the stream and
//!   the capture, more than the board's SRAM.
//!
//! The `-Tlink.x` / `-Tdefmt.x` / `--nmagic` link arguments come from the workspace's
//! `.cargo/config.toml` (`[target.thumbv7em-none-eabihf] rustflags`) and only from there;
//! they are deliberately not repeated here, since passing `-Tlink.x` twice makes the link
//! fail. (A `RUSTFLAGS` environment variable replaces those rustflags: don't set it.)

use std::env;
use std::path::PathBuf;

fn main() {
    let manifest_dir = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").unwrap_or_default());

    let emulator = env::var_os("CARGO_FEATURE_EMULATOR").is_some();
    let panic_check = env::var_os("CARGO_FEATURE_PANIC_CHECK").is_some();
    // The panic check alone links against the board's map.
    let stm32 = env::var_os("CARGO_FEATURE_STM32").is_some() || (panic_check && !emulator);
    // Both or neither: src/main.rs stops the build with a clear message; add no search path
    // here so that the linker does not pick one layout silently.
    if emulator == stm32 {
        println!("cargo:rerun-if-changed=build.rs");
        return;
    }

    if let Some(workspace_root) = manifest_dir.parent() {
        println!(
            "cargo:rerun-if-changed={}",
            workspace_root.join("memory.x").display()
        );
    }

    let m4_bench = env::var_os("CARGO_FEATURE_M4_BENCH").is_some();
    let memory_dir = manifest_dir.join(if m4_bench || (panic_check && !emulator) {
        "m4-bench"
    } else if emulator {
        "emulator"
    } else {
        "stm32"
    });
    let memory_x = memory_dir.join("board-memory.x");

    println!("cargo:rustc-link-search={}", memory_dir.display());
    println!("cargo:rerun-if-changed={}", memory_x.display());
    println!("cargo:rerun-if-changed=build.rs");
}
