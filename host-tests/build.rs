//! The git commit the `impact` tool is built from, for `impact report`'s provenance: the
//! environment variable `IMPACT_GIT_COMMIT` when the build sets it (`.ci/run`, which builds a
//! `git archive` copy), else `git rev-parse HEAD` of the repository this crate is in, else
//! `unknown` (a copy without `.git`, no git installed); and whether the tool's own sources
//! differ from that commit (`IMPACT_GIT_DIRTY`, `1` or empty: a report says "with changes not
//! committed"). Never a build failure.

use std::path::{Path, PathBuf};
use std::process::Command;

/// `git ARGS` in `dir`: its output, trimmed, if it ran and succeeded.
fn git(dir: &Path, args: &[&str]) -> Option<String> {
    let out = Command::new("git")
        .args(args)
        .current_dir(dir)
        .output()
        .ok()?;
    let text = String::from_utf8(out.stdout).ok()?;
    let text = text.trim();
    (out.status.success() && !text.is_empty()).then(|| text.to_string())
}

/// A full commit hash (40 or 64 hex digits).
fn is_commit(s: &str) -> bool {
    matches!(s.len(), 40 | 64) && s.bytes().all(|b| b.is_ascii_hexdigit())
}

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-env-changed=IMPACT_GIT_COMMIT");
    let dir = PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").unwrap_or_default());
    let given = std::env::var("IMPACT_GIT_COMMIT")
        .ok()
        .filter(|c| is_commit(c));
    // Only this workspace's own repository: a copy unpacked inside another repository's
    // tree must not take that one's commit.
    let workspace = dir.parent().and_then(|w| w.canonicalize().ok());
    let own = git(&dir, &["rev-parse", "--show-toplevel"])
        .and_then(|t| Path::new(&t).canonicalize().ok())
        .is_some_and(|t| Some(t) == workspace);
    let found = own
        .then(|| git(&dir, &["rev-parse", "HEAD"]))
        .flatten()
        .filter(|c| is_commit(c));
    // The tool's own sources changed since that commit (tracked files only: the crates the
    // tool is built from, the firmware it links for its self-test and bench scene, and the
    // lock file); a commit given from outside is taken as clean.
    let dirty = found.is_some()
        && given.is_none()
        && git(
            &dir,
            &[
                "status",
                "--porcelain",
                "--untracked-files=no",
                "--",
                "../core",
                "../firmware",
                ".",
                "../Cargo.toml",
                "../Cargo.lock",
            ],
        )
        .is_some();
    let commit = given.or(found).unwrap_or_else(|| "unknown".to_string());
    println!("cargo:rustc-env=IMPACT_GIT_COMMIT={commit}");
    println!(
        "cargo:rustc-env=IMPACT_GIT_DIRTY={}",
        if dirty { "1" } else { "" }
    );
    if !own {
        return;
    }
    // Run again when a source of the tool changes, so that the mark follows the tree.
    for source in [
        "../core/src",
        "../firmware/src",
        "../firmware/Cargo.toml",
        "src",
        "io/src",
        "assets",
        "Cargo.toml",
        "../Cargo.lock",
    ] {
        println!("cargo:rerun-if-changed={source}");
    }
    // Built again when HEAD moves: HEAD, the branch it names, the packed refs, and HEAD's log
    // (written on every commit, checkout and reset, whether the branch's ref is loose or
    // packed); only files that exist: cargo reruns a script on every build for a missing one.
    let mut watched = vec![
        "HEAD".to_string(),
        "packed-refs".to_string(),
        "logs/HEAD".to_string(),
    ];
    watched.extend(git(&dir, &["symbolic-ref", "-q", "HEAD"]));
    for name in watched {
        let path = git(
            &dir,
            &["rev-parse", "--path-format=absolute", "--git-path", &name],
        );
        if let Some(p) = path.filter(|p| Path::new(p).exists()) {
            println!("cargo:rerun-if-changed={p}");
        }
    }
}
