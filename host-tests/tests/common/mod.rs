//! Shared by the command-line test files: run the `impact` binary.

use std::process::Command;

pub mod board_log;
pub mod browser;
#[cfg(unix)]
pub mod limited;

/// Runs `impact ARGS`: (exit code, stdout, stderr).
pub fn impact(args: &[&str]) -> (i32, String, String) {
    run(Command::new(env!("CARGO_BIN_EXE_impact")).args(args))
}

/// Runs `impact ARGS` in `dir`: (exit code, stdout, stderr).
#[allow(dead_code)] // not every test file needs it
pub fn impact_in(dir: &std::path::Path, args: &[&str]) -> (i32, String, String) {
    run(Command::new(env!("CARGO_BIN_EXE_impact"))
        .current_dir(dir)
        .args(args))
}

fn run(cmd: &mut Command) -> (i32, String, String) {
    let out = cmd.output().expect("runs");
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

/// Runs `impact ARGS`, which must finish: exit status 0, or 3 when a judged impact failed
/// its specification (then stderr ends saying so): (stdout, stderr).
#[allow(dead_code)] // not every test file needs it
pub fn impact_judged(args: &[&str]) -> (String, String) {
    let (code, out, err) = impact(args);
    match code {
        0 => assert!(!err.contains("failed the specification"), "{err}"),
        3 => assert!(
            err.contains("failed the specification (exit status 3)"),
            "{err}"
        ),
        _ => panic!("impact {}: exit {code}\n{err}", args.join(" ")),
    }
    (out, err)
}

/// `impact synth` of a two-phase impact (seed-001 bench body; kc 1e4, kr 5e4, damping 5): one
/// 55.6 g impact at 10 ms, the hostile-input issue's `T2`.
#[allow(dead_code)] // not every test file needs it
pub const SYNTH_T2: [&str; 13] = [
    "synth",
    "--model",
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

/// `period` samples of little-endian i16 codes: `offset` with ±1 count of noise, and a 2 ms
/// (1000-sample) half-sine of 1000 counts starting half way.
#[allow(dead_code)] // not every test file needs it
pub fn impact_period(period: usize, offset: i32) -> Vec<u8> {
    let mut pattern = vec![0u8; period * 2];
    for (k, b) in pattern.chunks_exact_mut(2).enumerate() {
        let noise = ((k as u32).wrapping_mul(2_654_435_761) >> 30) as i32 - 1;
        let j = k as i64 - (period / 2) as i64;
        let pulse = if (0..1000).contains(&j) {
            (1000.0 * (std::f64::consts::PI * j as f64 / 1000.0).sin()).round() as i32
        } else {
            0
        };
        b.copy_from_slice(&((offset + noise + pulse) as i16).to_le_bytes());
    }
    pattern
}

/// The peak memory, MiB, a child run with IMPACT_PEAK_MEMORY set printed on stderr.
#[allow(dead_code)] // not every test file needs it
pub fn peak_memory_mib(stderr: &str) -> f64 {
    stderr
        .lines()
        .find_map(|l| l.strip_prefix("peak memory: "))
        .and_then(|v| v.trim_end_matches("kB").trim().parse::<f64>().ok())
        .expect("peak memory printed")
        / 1024.0
}

/// A refusal: a one-line error naming `want` (exit 1), or clap's usage error (exit 2), which
/// starts with `error:` and names `want` with the accepted values, the usage and a hint.
#[allow(dead_code)] // not every test file needs it
pub fn assert_refused(code: Option<i32>, err: &str, want: &str, what: &str) {
    assert!(matches!(code, Some(1 | 2)), "{what}: exit {code:?}\n{err}");
    if code == Some(1) {
        assert_eq!(err.trim().lines().count(), 1, "{what}: {err}");
    }
    assert!(err.starts_with("error: "), "{what}: {err}");
    assert!(err.contains(want), "{what}: wanted {want:?} in {err}");
    assert!(!err.contains("panicked"), "{what}: {err}");
}

/// A refusal of a file: [`assert_refused`], on one line whatever the exit code (a usage
/// error included), and naming the file (its name, where the message shows its path).
#[allow(dead_code)] // not every test file needs it
pub fn assert_refused_file(
    code: Option<i32>,
    err: &str,
    want: &str,
    file: &std::path::Path,
    what: &str,
) {
    assert_refused(code, err, want, what);
    assert_eq!(err.trim().lines().count(), 1, "{what}: {err}");
    let name = file
        .file_name()
        .and_then(|n| n.to_str())
        .expect("a file name");
    assert!(
        err.contains(name),
        "{what}: wanted the file {name:?} in {err}"
    );
}

/// A figure's title (its first text) and the figure without it.
#[allow(dead_code)] // not every test file needs it
pub fn untitled(svg: &str) -> (String, String) {
    let i = svg.find("<text").expect("a title");
    let j = i + svg[i..].find("</text>").expect("its end") + "</text>".len();
    (svg[i..j].to_string(), format!("{}{}", &svg[..i], &svg[j..]))
}

/// `impact synth` (its arguments, from `synth`) of a soft bounce train of seed 001's nonlinear
/// law: the seed bench's 60 g body at a first approach of 1.3357 m/s on a soft barrier
/// (k 240, c 0.5), ±16 g at 500 kS/s, `bounces` contacts of 55 ms and more (each outlasting
/// the board's capture, 30.2 ms) over `duration` s.
#[allow(dead_code)] // not every test file needs it
pub fn soft_train_args<'a>(bounces: &'a str, duration: &'a str) -> [&'a str; 17] {
    [
        "synth",
        "--model",
        "nonlinear",
        "--mass",
        "0.06",
        "--v0",
        "1.3357",
        "--stiffness",
        "240",
        "--damping",
        "0.5",
        "--bounces",
        bounces,
        "--full-scale",
        "156.9",
        "--duration",
        duration,
    ]
}

/// A scratch folder for a test's files, removed when it drops (also when the test fails).
#[allow(dead_code)] // not every test file needs it
pub struct Scratch(tempfile::TempDir);

#[allow(dead_code)] // not every test file needs it
impl Scratch {
    /// A new, empty folder (under TMPDIR).
    pub fn new() -> Self {
        Self(
            tempfile::Builder::new()
                .prefix("impact-test-")
                .tempdir()
                .expect("a temporary folder"),
        )
    }

    /// The folder.
    pub fn path(&self) -> &std::path::Path {
        self.0.path()
    }

    /// `name` in the folder (not written).
    pub fn join(&self, name: &str) -> std::path::PathBuf {
        self.0.path().join(name)
    }

    /// `name` in the folder (not written), as a string: a command-line argument.
    pub fn join_str(&self, name: &str) -> String {
        self.join(name).to_str().expect("a UTF-8 path").to_string()
    }

    /// `name` in the folder, written with `bytes`.
    pub fn file(&self, name: &str, bytes: impl AsRef<[u8]>) -> std::path::PathBuf {
        let path = self.join(name);
        std::fs::write(&path, bytes).expect("a scratch file written");
        path
    }

    /// `name` in the folder, written with `text`: its path as a string (a command-line
    /// argument).
    pub fn text(&self, name: &str, text: &str) -> String {
        let path = self.join_str(name);
        std::fs::write(&path, text).expect("a scratch file written");
        path
    }
}
