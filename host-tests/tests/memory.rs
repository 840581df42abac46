//! The firmware's memory budget, read off the board's ELF (`impact bench memory`), is the
//! table docs/board.md shows; the captures start zeroed (`.bss`, no image in flash), the
//! workspace is in the CCM RAM, and the emulator's memory map has the board's regions, so the
//! emulated firmware has the board's stack and room.

use std::path::{Path, PathBuf};

use impact_host::firmware_link::memory;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap()
        .to_path_buf()
}

fn target_installed() -> bool {
    std::process::Command::new("rustup")
        .args(["target", "list", "--installed"])
        .output()
        .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).contains("thumbv7em-none-eabihf"))
}

#[test]
fn the_emulators_memory_map_has_the_boards_regions() {
    let read =
        |p: &str| memory::regions(&std::fs::read_to_string(root().join(p)).unwrap()).unwrap();
    let board = read("firmware/stm32/board-memory.x");
    let emulator = read("firmware/emulator/board-memory.x");
    let sizes = |r: &[memory::Region]| -> Vec<(String, u64)> {
        r.iter().map(|r| (r.name.clone(), r.length)).collect()
    };
    assert_eq!(sizes(&board), sizes(&emulator));
    // The stack at the bottom of the data RAM, the statics right above it, in both.
    for map in [&board, &emulator] {
        let at = |n: &str| map.iter().find(|r| r.name == n).unwrap().clone();
        let (stack, ram) = (at("STACK"), at("RAM"));
        assert_eq!(stack.origin, 0x2000_0000);
        assert_eq!(ram.origin, stack.origin + stack.length);
    }
}

#[test]
fn the_boards_memory_budget_is_the_documented_one() {
    if !target_installed() {
        assert!(
            std::env::var_os("IMPACT_REQUIRE_EMULATOR").is_none(),
            "the thumbv7em-none-eabihf target is not installed (scripts/setup.sh)"
        );
        return;
    }
    let (elf, map) = memory::board_elf().unwrap();
    let b = memory::budget(&elf, &map).unwrap();
    let captures = b.find("capture_queue::SLOTS").expect("the captures");
    assert_eq!(captures.section, ".bss", "the captures start zeroed");
    assert_eq!(
        b.find("WORKSPACE").expect("the workspace").section,
        ".ccmram"
    );
    assert!(b.statics_bytes() <= b.ram_length && b.ccm_bytes <= b.ccm_length);
    let docs = std::fs::read_to_string(root().join("docs/board.md")).unwrap();
    let shown = docs
        .split_once("<!-- impact bench memory -->\n")
        .and_then(|(_, rest)| rest.split_once("<!-- end -->"))
        .map(|(table, _)| table)
        .expect("docs/board.md: the table between its markers");
    // The flash row's constants hold the dependencies' panic locations, whose paths carry
    // the build's cargo home (a `CARGO_HOME=$(mktemp -d)` one is longer than ~/.cargo): its
    // figures are held to 0.2 KiB, every other row exactly.
    let table = memory::table(&b);
    let flash = |t: &str| {
        t.lines()
            .find(|l| l.starts_with("| flash |"))
            .map(kib_figures)
    };
    let (want, got) = (flash(shown).unwrap(), flash(&table).unwrap());
    assert_eq!(want.len(), got.len(), "{shown}\n{table}");
    for (w, g) in want.iter().zip(&got) {
        assert!(
            (w - g).abs() <= 0.2,
            "docs/board.md's flash row is not what `impact bench memory` reads off the ELF:\n{shown}\n{table}"
        );
    }
    let rest = |t: &str| {
        t.lines()
            .filter(|l| !l.starts_with("| flash |"))
            .collect::<Vec<_>>()
            .join("\n")
    };
    assert_eq!(
        rest(shown),
        rest(&table),
        "docs/board.md's memory table is not what `impact bench memory` reads off the ELF"
    );
}

/// The figures before each `KiB` of a row.
fn kib_figures(row: &str) -> Vec<f64> {
    let words: Vec<&str> = row.split_whitespace().collect();
    words
        .windows(2)
        .filter(|w| w[1].starts_with("KiB"))
        .filter_map(|w| w[0].parse().ok())
        .collect()
}
