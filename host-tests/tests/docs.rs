//! The documented commands run, with their shown output checked (trycmd, the Rust CLI
//! convention): every `console` block of README.md and docs/*.md, in order, one sandbox per
//! file holding a link to the repository's `host-tests/` (its bundled recordings and
//! examples), so that a command writes its files (`-o seed.csv`, `--plot seed.svg`) there and
//! later commands of the same file read them. `...` in a shown output stands for any lines,
//! `[..]` for any text within a line. `sh` blocks are for commands that are not run here
//! (flashing a board, installing peers from the network, benchmarks of minutes whose figures
//! depend on the machine): every `impact` command in them must still parse
//! (`every_impact_command_in_the_docs_parses`).
//!
//! `TRYCMD=overwrite cargo test --profile host-test -p impact-host --test docs` writes the
//! outputs the commands give now into the documents.

use std::path::{Path, PathBuf};

mod common;
use common::Scratch;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("the workspace")
        .to_path_buf()
}

/// README.md and every `docs/*.md`.
fn documents() -> Vec<PathBuf> {
    let mut docs = vec![root().join("README.md")];
    let mut more: Vec<PathBuf> = std::fs::read_dir(root().join("docs"))
        .expect("docs/")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    more.sort();
    docs.extend(more);
    docs
}

/// The fenced blocks of `text` with their info string: `(info, body)`.
fn blocks(text: &str) -> Vec<(String, String)> {
    let mut out = Vec::new();
    let mut lines = text.lines();
    while let Some(line) = lines.next() {
        let Some(info) = line.trim_start().strip_prefix("```") else {
            continue;
        };
        let mut body = String::new();
        for l in lines.by_ref() {
            if l.trim_start().starts_with("```") {
                break;
            }
            body.push_str(l);
            body.push('\n');
        }
        out.push((info.trim().to_string(), body));
    }
    out
}

#[test]
fn every_block_names_its_language() {
    // trycmd runs a block without an info string as commands: every block says what it is.
    for doc in documents() {
        let text = std::fs::read_to_string(&doc).unwrap();
        for (info, body) in blocks(&text) {
            assert!(
                !info.is_empty(),
                "{}: a code block without a language:\n{body}",
                doc.display()
            );
        }
    }
}

#[test]
fn documented_commands_give_their_shown_output() {
    // The documents run the emulated firmware: QEMU must be there, and the firmware built
    // first (so that no command of the documents says it is building it).
    if let Err(e) = impact_host::firmware_link::qemu::tools_available() {
        assert!(
            std::env::var_os("IMPACT_REQUIRE_EMULATOR").is_none(),
            "{e} (scripts/setup.sh)"
        );
        eprintln!("skipped: {e}");
        return;
    }
    impact_host::firmware_link::qemu::build_firmware().expect("the emulator firmware builds");
    let sandboxes = Scratch::new();
    let cases = trycmd::TestCases::new();
    cases.register_bin("impact", PathBuf::from(env!("CARGO_BIN_EXE_impact")));
    // Every run says the same: no progress bar, no colour.
    cases.env("NO_COLOR", "1");
    let mut copies = Vec::new();
    for doc in documents() {
        let text = std::fs::read_to_string(&doc).unwrap();
        if !blocks(&text).iter().any(|(info, _)| info == "console") {
            continue;
        }
        let stem = doc.file_stem().unwrap().to_string_lossy().to_string();
        let dir = sandboxes.join(&stem);
        std::fs::create_dir_all(dir.join(format!("{stem}.in"))).unwrap();
        // `.out` present: trycmd copies `.in` into a fresh directory and runs there.
        std::fs::create_dir_all(dir.join(format!("{stem}.out"))).unwrap();
        std::os::unix::fs::symlink(
            root().join("host-tests"),
            dir.join(format!("{stem}.in")).join("host-tests"),
        )
        .unwrap();
        let copy = dir.join(format!("{stem}.md"));
        std::fs::copy(&doc, &copy).unwrap();
        cases.case(&copy);
        copies.push((copy, doc));
    }
    cases.run();
    if std::env::var("TRYCMD").is_ok_and(|v| v == "overwrite") {
        for (copy, doc) in &copies {
            std::fs::copy(copy, doc).unwrap();
        }
    }
}

#[test]
fn every_impact_command_in_the_docs_parses() {
    // The commands of `sh` blocks are not run: each is parsed by the tool itself
    // (`IMPACT_PARSE_ONLY`), so a renamed or removed option fails here.
    let mut checked = 0;
    for doc in documents() {
        let text = std::fs::read_to_string(&doc).unwrap();
        for (info, body) in blocks(&text) {
            if info != "sh" {
                continue;
            }
            let mut joined = String::new();
            for line in body.lines() {
                let line = line.trim();
                if let Some(cont) = line.strip_suffix('\\') {
                    joined.push_str(cont);
                    continue;
                }
                joined.push_str(line);
                let command = std::mem::take(&mut joined);
                // `cargo impact ARGS`, `impact ARGS`, `cargo run ... --bin impact -- ARGS`;
                // the command ends at a shell operator or a comment.
                let words: Vec<String> = shlex::split(
                    command
                        .split(['#', '|', '>', ';'])
                        .next()
                        .unwrap_or("")
                        .split("&&")
                        .last()
                        .unwrap_or(""),
                )
                .unwrap_or_default();
                let args: Vec<&str> = match words.iter().map(String::as_str).collect::<Vec<_>>()[..]
                {
                    ["impact", ref rest @ ..] | ["cargo", "impact", ref rest @ ..] => rest.to_vec(),
                    ["cargo", "run", ref rest @ ..] if rest.contains(&"--bin") => rest
                        .iter()
                        .position(|w| *w == "--")
                        .map(|p| rest[p + 1..].to_vec())
                        .unwrap_or_default(),
                    _ => continue,
                };
                // From the workspace's root, as the docs' paths are written (a file an
                // option reads while it is parsed, `--spec …,band-file=`, must be found).
                let out = std::process::Command::new(env!("CARGO_BIN_EXE_impact"))
                    .args(&args)
                    .current_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/.."))
                    .env("IMPACT_PARSE_ONLY", "1")
                    .output()
                    .unwrap();
                assert!(
                    out.status.success(),
                    "{}: `{command}` does not parse:\n{}",
                    doc.display(),
                    String::from_utf8_lossy(&out.stderr)
                );
                checked += 1;
            }
        }
    }
    assert!(checked > 0, "no impact command in an sh block");
}

#[test]
fn the_help_examples_are_documented_commands() {
    // Each subcommand's "Examples:" are run by the docs' tests: each must appear in a
    // `console` block.
    let mut documented = String::new();
    for doc in documents() {
        for (info, body) in blocks(&std::fs::read_to_string(&doc).unwrap()) {
            if info == "console" {
                documented.push_str(&body);
            }
        }
    }
    for sub in ["analyze", "emulate", "simulate", "synth", "log", "selftest"] {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_impact"))
            .args([sub, "--help"])
            .output()
            .unwrap();
        let help = String::from_utf8_lossy(&out.stdout).to_string();
        let examples = help
            .split("Examples:")
            .nth(1)
            .unwrap_or_else(|| panic!("impact {sub} --help has no examples"));
        for line in examples.lines().map(str::trim).filter(|l| !l.is_empty()) {
            assert!(
                documented.contains(&format!("$ {line}\n")),
                "impact {sub} --help: `{line}` is in no console block of the docs"
            );
        }
    }
}
