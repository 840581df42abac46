//! `impact` under limits, for the hostile-input tests: an address-space limit set between
//! fork and exec, a time limit past which the run is killed, and what any run must satisfy
//! (no panic, no allocation failure), its output read as it comes.
#![allow(dead_code)] // not every test file needs all of it

use std::io::Read;
use std::os::unix::process::{CommandExt, ExitStatusExt};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// A finished run: its exit code or the signal that ended it, its stdout and stderr.
pub struct Run {
    pub code: Option<i32>,
    pub signal: Option<i32>,
    pub out: String,
    pub err: String,
}

/// Starts `impact ARGS` with `env` set, mapping at most `memory` bytes (`RLIMIT_AS`), stdout
/// and stderr piped.
pub fn spawn(args: &[&str], env: &[(&str, &str)], stdin: Stdio, memory: u64) -> Child {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_impact"));
    cmd.args(args)
        .envs(env.iter().copied())
        .stdin(stdin)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    // SAFETY: setrlimit is async-signal-safe; nothing else runs between fork and exec.
    unsafe {
        cmd.pre_exec(move || {
            let limit = libc::rlimit {
                rlim_cur: memory,
                rlim_max: memory,
            };
            if libc::setrlimit(libc::RLIMIT_AS, &limit) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
    cmd.spawn().expect("impact runs")
}

/// Waits for `child` (`what` names it), killing it past `time`, reading its stdout (unless
/// the caller took it) and stderr as they come; asserts no panic and no allocation failure.
pub fn wait(mut child: Child, what: &str, time: Duration) -> Run {
    let out = child.stdout.take();
    let mut err = child.stderr.take().expect("stderr piped");
    let out = std::thread::spawn(move || {
        let mut o = Vec::new();
        if let Some(mut out) = out {
            let _ = out.read_to_end(&mut o);
        }
        o
    });
    let err = std::thread::spawn(move || {
        let mut e = Vec::new();
        let _ = err.read_to_end(&mut e);
        e
    });
    let start = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if start.elapsed() > time {
            let _ = child.kill();
            panic!("{what}: still running after {time:?}");
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let run = Run {
        code: status.code(),
        signal: status.signal(),
        out: String::from_utf8_lossy(&out.join().unwrap()).into_owned(),
        err: String::from_utf8_lossy(&err.join().unwrap()).into_owned(),
    };
    assert!(
        !run.err.contains("panicked") && !run.err.contains("memory allocation"),
        "{what}: {}",
        run.err
    );
    run
}
