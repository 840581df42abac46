//! What a run leaves behind when it is interrupted: nothing. The temporary files and child
//! processes (QEMU) of a run are registered here while they exist; Ctrl-C, SIGTERM and SIGHUP
//! remove the files and end the children before the tool exits with a one-line message, and a
//! closed output pipe (`impact … | head`) ends it quietly after the same cleanup. A file-size
//! limit (`ulimit -f`) makes a write fail with an error instead of killing the tool (SIGXFSZ
//! is ignored).

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

static FILES: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());
static CHILDREN: Mutex<Vec<u32>> = Mutex::new(Vec::new());

/// Unregisters its file when dropped (the file itself is the owner's to keep or remove).
#[must_use]
pub struct FileGuard(PathBuf);

impl Drop for FileGuard {
    fn drop(&mut self) {
        if let Ok(mut files) = FILES.lock() {
            files.retain(|f| *f != self.0);
        }
    }
}

/// Registers a temporary file (or an empty directory): removed if the run is interrupted
/// while the guard lives.
pub fn temporary(path: &Path) -> FileGuard {
    if let Ok(mut files) = FILES.lock() {
        files.push(path.to_path_buf());
    }
    FileGuard(path.to_path_buf())
}

/// Unregisters its child when dropped.
#[must_use]
pub struct ChildGuard(u32);

impl Drop for ChildGuard {
    fn drop(&mut self) {
        if let Ok(mut children) = CHILDREN.lock() {
            children.retain(|c| *c != self.0);
        }
    }
}

/// Registers a child process: killed if the run is interrupted while the guard lives.
pub fn child(pid: u32) -> ChildGuard {
    if let Ok(mut children) = CHILDREN.lock() {
        children.push(pid);
    }
    ChildGuard(pid)
}

/// Removes the registered files and kills the registered children.
pub fn clean_up() {
    if let Ok(children) = CHILDREN.lock() {
        for &pid in children.iter() {
            #[cfg(unix)]
            // SAFETY: sends a signal to a process this run started and has not reaped.
            unsafe {
                libc::kill(pid as libc::pid_t, libc::SIGKILL);
            }
        }
    }
    // Newest first: a directory's files before the directory.
    if let Ok(files) = FILES.lock() {
        for f in files.iter().rev() {
            let _ = std::fs::remove_file(f).or_else(|_| std::fs::remove_dir(f));
        }
    }
}

/// Installs the handlers (once, at the start of `main`).
#[cfg(unix)]
pub fn install() {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGPIPE, SIGTERM};
    // SAFETY: sets the disposition of one signal before any other thread starts.
    unsafe {
        libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
    }
    let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP, SIGPIPE])
    else {
        return;
    };
    std::thread::spawn(move || {
        if let Some(sig) = signals.forever().next() {
            clean_up();
            if sig != SIGPIPE {
                let name = match sig {
                    SIGINT => "interrupted",
                    SIGTERM => "terminated",
                    _ => "hung up",
                };
                // (Not errln!: a closed stderr must not turn this signal into SIGPIPE.)
                let _ = writeln!(
                    std::io::stderr(),
                    "{name}: temporary files removed, child processes ended"
                );
            }
            die_of(sig);
        }
    });
}

/// A write to standard output failed with `error`: a closed pipe (`impact … | head`: EPIPE
/// reached the write before the signal's handler ended the run) ends the run as the signal
/// would, quietly, by SIGPIPE, after the cleanup; any other error is returned.
pub fn closed_pipe(error: std::io::Error) -> std::io::Error {
    #[cfg(unix)]
    if error.kind() == std::io::ErrorKind::BrokenPipe {
        clean_up();
        die_of(libc::SIGPIPE);
    }
    error
}

/// Standard output could not be written (`error`, not a closed pipe): the run ends with the
/// message and status 1, after the cleanup (where `println!` would panic).
pub fn stdout_failed(error: std::io::Error) -> ! {
    let error = closed_pipe(error);
    clean_up();
    crate::errln!("error: stdout: {error}");
    std::process::exit(1)
}

/// Ends the process by `sig` with its default action, as if it had not been caught (the
/// status a shell and a parent expect of an interrupted or cut-off tool).
#[cfg(unix)]
fn die_of(sig: i32) -> ! {
    // SAFETY: restores a signal's default action and raises it in this process.
    unsafe {
        libc::signal(sig, libc::SIG_DFL);
        libc::raise(sig);
    }
    std::process::exit(128 + sig)
}

#[cfg(not(unix))]
pub fn install() {}
