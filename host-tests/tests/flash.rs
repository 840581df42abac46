//! What a user flashes is the monitor: `cargo fw-run` at the root and `cargo run --release`
//! inside `firmware/` build the `impact-firmware` binary for the board (not a helper binary)
//! and hand it to probe-rs for the STM32F407. A stand-in `probe-rs` on the `PATH` records how
//! it is called and answers as the real one does without a board; where the real probe-rs is
//! installed, it is run too and must stop at "no probe found".
#![cfg(unix)]

use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};
use std::process::Command;

mod common;
use common::Scratch;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("the workspace")
        .to_path_buf()
}

/// Whether the firmware can be built here (the Cortex-M4F target installed).
fn target_installed() -> bool {
    Command::new("rustup")
        .args(["target", "list", "--installed"])
        .output()
        .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).contains("thumbv7em-none-eabihf"))
}

/// Runs `cargo ARGS` in `dir` with `path` first on the PATH: (status, stderr).
fn cargo(dir: &Path, args: &[&str], path: Option<&Path>) -> (bool, String) {
    let mut cmd = Command::new(std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into()));
    cmd.current_dir(dir).args(args);
    if let Some(p) = path {
        let old = std::env::var_os("PATH").unwrap_or_default();
        let mut paths = vec![p.to_path_buf()];
        paths.extend(std::env::split_paths(&old));
        cmd.env("PATH", std::env::join_paths(paths).unwrap());
    }
    let out = cmd.output().expect("cargo runs");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// The entry point of a 32-bit little-endian ELF.
fn elf_entry(path: &Path) -> u32 {
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(&bytes[..4], b"\x7fELF", "{}: not an ELF", path.display());
    u32::from_le_bytes(bytes[24..28].try_into().unwrap())
}

#[test]
fn fw_run_flashes_the_monitor_through_probe_rs() {
    if !target_installed() {
        assert!(
            std::env::var_os("IMPACT_REQUIRE_EMULATOR").is_none(),
            "the thumbv7em-none-eabihf target is not installed (scripts/setup.sh)"
        );
        eprintln!("skipped: the thumbv7em-none-eabihf target is not installed");
        return;
    }
    let scratch = Scratch::new();
    let dir = scratch.path();
    let calls = scratch.join("calls");
    let stand_in = scratch.file(
        "probe-rs",
        format!(
            "#!/bin/sh\necho \"$@\" >> {}\necho 'Error: No connected probes were found.' >&2\nexit 1\n",
            calls.display()
        ),
    );
    std::fs::set_permissions(&stand_in, std::fs::Permissions::from_mode(0o755)).unwrap();

    for (where_, args) in [
        (root(), vec!["fw-run"]),
        (root().join("firmware"), vec!["run", "--release"]),
    ] {
        let _ = std::fs::remove_file(&calls);
        let (ok, err) = cargo(&where_, &args, Some(dir));
        assert!(!ok, "{args:?} succeeded without a board");
        assert!(
            err.contains("No connected probes were found"),
            "{args:?} did not reach the probe: {err}"
        );
        let called = std::fs::read_to_string(&calls).unwrap();
        let words: Vec<&str> = called.split_whitespace().collect();
        // The firmware's own fault handler and restart run under the probe as without it.
        assert_eq!(
            words[..5],
            [
                "run",
                "--chip",
                "STM32F407VGTx",
                "--no-catch-reset",
                "--no-catch-hardfault"
            ],
            "{args:?}: probe-rs called as {called}"
        );
        let elf = Path::new(words[5]);
        assert!(
            elf.ends_with("thumbv7em-none-eabihf/release/impact-firmware"),
            "{args:?}: flashed {}",
            elf.display()
        );
        // The board build: its reset handler is in the STM32F407's flash (the emulator's
        // would be in QEMU's code RAM at 0).
        let entry = elf_entry(&where_.join(elf));
        assert!(
            (0x0800_0000..0x0810_0000).contains(&entry),
            "{args:?}: entry {entry:#x} is not in the STM32F407's flash"
        );
    }

    // The real probe-rs, where it is installed: it stops where no board is.
    let real = Command::new("probe-rs").arg("--version").output();
    if real.is_ok_and(|o| o.status.success()) {
        let (ok, err) = cargo(&root(), &["fw-run"], None);
        assert!(!ok);
        assert!(
            err.to_lowercase().contains("no connected probes")
                || err.to_lowercase().contains("no probe"),
            "{err}"
        );
    } else {
        eprintln!("probe-rs is not installed: only the stand-in was run");
    }
}
