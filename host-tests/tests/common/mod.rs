//! Shared by the command-line test files: run the `impact` binary.

use std::process::Command;

/// Runs `impact ARGS`: (exit code, stdout, stderr).
pub fn impact(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_impact"))
        .args(args)
        .output()
        .expect("runs");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Runs `impact ARGS`, which must succeed: (stdout, stderr).
#[allow(dead_code)] // not every test file needs it
pub fn impact_ok(args: &[&str]) -> (String, String) {
    let (code, out, err) = impact(args);
    assert_eq!(code, 0, "impact {}: exit {code}\n{err}", args.join(" "));
    (out, err)
}

/// `impact synth` of a two-phase impact (seed-001 bench body; kc 1e4, kr 5e4, damping 5): one
/// 55.6 g impact at 10 ms, the hostile-input issue's `T2`.
#[allow(dead_code)] // not every test file needs it
pub const SYNTH_T2: [&str; 13] = [
    "synth",
    "--law",
    "two-phase",
    "--mass",
    "0.06",
    "--v0",
    "1.3357",
    "--kc",
    "1e4",
    "--kr",
    "5e4",
    "--damping",
    "5",
];

/// The CSV of [`SYNTH_T2`].
#[allow(dead_code)] // not every test file needs it
pub fn synth_t2() -> String {
    impact_ok(&SYNTH_T2).0
}
