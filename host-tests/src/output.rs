//! The one output rule: a file the tool writes is never one of its inputs, and it appears
//! whole or not at all.
//!
//! Every output (a figure, a log, a defmt stream, an exported window, a synthesised
//! recording) is checked against the command's inputs before any work: the same file, a hard
//! or symbolic link to it, or the file standard input is read from is refused. It is then
//! written to a temporary file beside it, renamed into place once complete: a reader never
//! sees half a file, two writers cannot interleave (the last rename wins), and an error or an
//! interrupt leaves nothing behind (the temporary file is registered with
//! [`crate::interrupt`], which removes it on Ctrl-C). The finished file keeps the target's
//! permission bits (a new one gets 0666 less the umask; its owner is this user); a read-only
//! target, a device or FIFO, or an unwritable folder is refused before any work, never
//! replaced.

use std::io::Write;
use std::path::{Path, PathBuf};

/// The files a command reads: the recording, a scene, a free-fall recording, a target, an
/// ELF, a log; `-` is standard input.
#[derive(Clone, Debug, Default)]
pub struct Inputs {
    paths: Vec<PathBuf>,
}

impl Inputs {
    pub fn new() -> Self {
        Self::default()
    }

    /// One more input (`-` for standard input).
    pub fn with(mut self, path: &Path) -> Self {
        self.paths.push(path.to_path_buf());
        self
    }

    /// One more input if there is one.
    pub fn with_some(self, path: Option<&Path>) -> Self {
        match path {
            Some(p) => self.with(p),
            None => self,
        }
    }
}

/// The file's identity (device and inode), following symbolic links; `None` if it does not
/// exist.
#[cfg(unix)]
fn identity(path: &Path) -> Option<(u64, u64)> {
    use std::os::unix::fs::MetadataExt;
    std::fs::metadata(path).ok().map(|m| (m.dev(), m.ino()))
}

/// Standard input's file (a redirection `< FILE`), if it is one.
#[cfg(unix)]
fn stdin_identity() -> Option<(u64, u64)> {
    use std::os::unix::fs::MetadataExt;
    use std::os::unix::io::AsFd;
    let fd = std::io::stdin().as_fd().try_clone_to_owned().ok()?;
    let file = std::fs::File::from(fd);
    file.metadata().ok().map(|m| (m.dev(), m.ino()))
}

#[cfg(not(unix))]
fn identity(path: &Path) -> Option<(u64, u64)> {
    let _ = path.canonicalize().ok()?;
    None
}

#[cfg(not(unix))]
fn stdin_identity() -> Option<(u64, u64)> {
    None
}

/// Why an output cannot be written: refused before any work ([`check`]), or its write
/// failed ([`write_with`]). `option` is the option that named it (`--plot`).
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    #[error("{option} {}: directory {} does not exist", .path.display(), .dir.display())]
    NoDirectory {
        option: String,
        path: PathBuf,
        dir: PathBuf,
    },
    #[error("{option} {}: is a directory", .path.display())]
    IsDirectory { option: String, path: PathBuf },
    /// One of the command's inputs (`-`: the file read on standard input).
    #[error(
        "{option} {}: is {}; it would be overwritten (write to another file)",
        .path.display(),
        input_named(.input)
    )]
    IsAnInput {
        option: String,
        path: PathBuf,
        input: PathBuf,
    },
    #[error("{option} {}: links to an input; it would be overwritten", .path.display())]
    LinksToAnInput { option: String, path: PathBuf },
    /// An existing file this user may not write (a 0444 report kept as the signed copy,
    /// another user's file): it is not replaced behind the permission's back.
    #[error(
        "{option} {}: the file exists and is read-only; it is not replaced (make it writable \
         for you, or write to another file)",
        .path.display()
    )]
    ReadOnly { option: String, path: PathBuf },
    /// An existing path that is no regular file (a device such as `/dev/null`, a FIFO, a
    /// socket): renaming a file over it would replace the device.
    #[error(
        "{option} {}: is not a regular file (a device, a FIFO or a socket); outputs are files \
         (write to a file, or leave the option out)",
        .path.display()
    )]
    NotAFile { option: String, path: PathBuf },
    /// The folder the output goes in, where this user may not create files.
    #[error("{option} {}: folder {} is not writable (write to another folder)", .path.display(), .dir.display())]
    FolderReadOnly {
        option: String,
        path: PathBuf,
        dir: PathBuf,
    },
    #[error(
        "{option} {}: the output is {}: name the file .{ext}",
        .path.display(),
        .ext.to_uppercase()
    )]
    Extension {
        option: String,
        path: PathBuf,
        ext: String,
    },
    /// The write itself (a full disk, a file-size limit); nothing was left behind.
    #[error("{}: {source}", .path.display())]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
}

/// An input as a refusal names it.
fn input_named(input: &Path) -> String {
    if input.as_os_str() == "-" {
        "the input file read on standard input".to_string()
    } else {
        format!("the input file {}", input.display())
    }
}

/// Checks, before any work, that `path` (the value of `option`) can take an output: its
/// directory exists, it is no directory itself, and it is none of the `inputs` (the same file,
/// a link to one, standard input's file). `extension`, if given, is the one the output must
/// have (`svg`).
pub fn check(
    option: &str,
    path: &Path,
    inputs: &Inputs,
    extension: Option<&str>,
) -> Result<(), OutputError> {
    let (option, owned) = (option.to_string(), path.to_path_buf());
    let dir = directory(path);
    if !dir.is_dir() {
        return Err(OutputError::NoDirectory {
            option,
            path: owned,
            dir: dir.to_path_buf(),
        });
    }
    if path.is_dir() {
        return Err(OutputError::IsDirectory {
            option,
            path: owned,
        });
    }
    if let Some(e) = unwritable(&option, path) {
        return Err(e);
    }
    if let Some(out) = identity(path) {
        for input in &inputs.paths {
            let same = if input.as_os_str() == "-" {
                stdin_identity() == Some(out)
            } else {
                identity(input) == Some(out)
            };
            if same {
                return Err(OutputError::IsAnInput {
                    option,
                    path: owned,
                    input: input.clone(),
                });
            }
        }
    }
    // Without a file yet, its name may still be an input's (not created yet) only by a
    // dangling link: the comparison by name covers it.
    if identity(path).is_none() {
        if let Ok(target) = std::fs::read_link(path) {
            let target = dir.join(target);
            if inputs.paths.contains(&target) {
                return Err(OutputError::LinksToAnInput {
                    option,
                    path: owned,
                });
            }
        }
    }
    if let Some(ext) = extension {
        let ok = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case(ext));
        if !ok {
            return Err(OutputError::Extension {
                option,
                path: owned,
                ext: ext.to_string(),
            });
        }
    }
    Ok(())
}

/// Why `path` cannot take an output written beside it and renamed over it, if it cannot:
/// an existing path that is no regular file, an existing file that is read-only (no write bit
/// at all, `chmod a-w`, the mark of a kept copy, which `rm` also asks about, even for root; or
/// one this user may not write), or a folder this user may not create the file in.
fn unwritable(option: &str, path: &Path) -> Option<OutputError> {
    let (option, owned) = (option.to_string(), path.to_path_buf());
    if let Ok(meta) = std::fs::metadata(path) {
        if !meta.is_file() && !meta.is_dir() {
            return Some(OutputError::NotAFile {
                option,
                path: owned,
            });
        }
        if meta.is_file() && (no_write_bit(&meta) || !may_write(path)) {
            return Some(OutputError::ReadOnly {
                option,
                path: owned,
            });
        }
    }
    let dir = directory(path);
    if dir.is_dir() && !may_write(dir) {
        return Some(OutputError::FolderReadOnly {
            option,
            path: owned,
            dir: dir.to_path_buf(),
        });
    }
    None
}

#[cfg(unix)]
fn no_write_bit(meta: &std::fs::Metadata) -> bool {
    use std::os::unix::fs::PermissionsExt;
    meta.permissions().mode() & 0o222 == 0
}

#[cfg(not(unix))]
fn no_write_bit(meta: &std::fs::Metadata) -> bool {
    meta.permissions().readonly()
}

/// `access(2)`'s `W_OK` for this process: the bits as they apply to this user, a read-only
/// mount.
#[cfg(unix)]
fn may_write(path: &Path) -> bool {
    use std::os::unix::ffi::OsStrExt;
    let Ok(c) = std::ffi::CString::new(path.as_os_str().as_bytes()) else {
        return true;
    };
    // SAFETY: `c` is a NUL-terminated path that outlives the call; access only reads it.
    unsafe { libc::access(c.as_ptr(), libc::W_OK) == 0 }
}

#[cfg(not(unix))]
fn may_write(_: &Path) -> bool {
    true
}

/// The mode an existing target keeps (its permission bits, not setuid, setgid or sticky: the
/// new file is this user's), if it exists.
#[cfg(unix)]
fn kept_mode(path: &Path) -> Option<u32> {
    use std::os::unix::fs::PermissionsExt;
    std::fs::metadata(path)
        .ok()
        .filter(|m| m.is_file())
        .map(|m| m.permissions().mode() & 0o777)
}

/// The directory `path` is in (`.` for a bare name).
fn directory(path: &Path) -> &Path {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// Writes `bytes` to `path`, whole or not at all (see the module).
pub fn write(path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
    write_with(path, |w| w.write_all(bytes))
}

/// Writes `path` through `fill`, whole or not at all: into a temporary file beside it,
/// renamed into place once `fill` and the flush succeed; on an error (a full disk, a file
/// size limit) the temporary file is removed and the error names `path`. An existing file
/// keeps its mode; one this user may not write is refused ([`OutputError::ReadOnly`]).
pub fn write_with(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<(), OutputError> {
    let failed = |source: std::io::Error| OutputError::Write {
        path: path.to_path_buf(),
        source,
    };
    if let Some(e) = unwritable("output", path) {
        return Err(e);
    }
    let name = path
        .file_name()
        .map_or_else(|| "output".into(), |n| n.to_string_lossy().into_owned());
    let prefix = format!(".{name}.");
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix).suffix(".part");
    // A new file's mode as any tool's: 0666 less the umask, which the kernel applies.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let tmp = builder.tempfile_in(directory(path)).map_err(failed)?;
    let guard = crate::interrupt::temporary(tmp.path());
    {
        let mut w = std::io::BufWriter::new(tmp.as_file());
        fill(&mut w).map_err(failed)?;
        w.flush().map_err(failed)?;
    }
    // An existing target's own mode (a 0600 figure stays 0600).
    #[cfg(unix)]
    if let Some(mode) = kept_mode(path) {
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::Permissions::from_mode(mode);
        std::fs::set_permissions(tmp.path(), mode).map_err(failed)?;
    }
    tmp.persist(path).map_err(|e| failed(e.error))?;
    drop(guard);
    Ok(())
}

/// Standard output, locked: a write that finds the pipe closed ends the run as SIGPIPE would
/// ([`crate::interrupt::closed_pipe`], found by its `io::ErrorKind`); any other error is
/// returned to the caller.
pub fn stdout() -> Stdout {
    Stdout(std::io::stdout().lock())
}

/// See [`stdout`].
pub struct Stdout(std::io::StdoutLock<'static>);

impl Write for Stdout {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.0.write(buf).map_err(crate::interrupt::closed_pipe)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.0.flush().map_err(crate::interrupt::closed_pipe)
    }
}

/// `print!` through [`stdout`]: a closed pipe ends the run as SIGPIPE would; another write
/// error ends it with a message ([`crate::interrupt::stdout_failed`]), where `print!` panics.
#[macro_export]
macro_rules! out {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        if let Err(e) = write!($crate::output::stdout(), $($arg)*) {
            $crate::interrupt::stdout_failed(e);
        }
    }};
}

/// `eprintln!` that a closed standard error never panics on: a closed pipe (`impact … 2>&1 |
/// head`) ends the run as SIGPIPE would ([`crate::interrupt::closed_pipe`]); another error is
/// dropped (standard error is where it would be said).
#[macro_export]
macro_rules! errln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        if let Err(e) = writeln!(std::io::stderr(), $($arg)*) {
            let _ = $crate::interrupt::closed_pipe(e);
        }
    }};
}

/// `eprint!` as [`errln!`](crate::errln!) writes it.
#[macro_export]
macro_rules! err {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        if let Err(e) = write!(std::io::stderr(), $($arg)*) {
            let _ = $crate::interrupt::closed_pipe(e);
        }
    }};
}

/// `println!` through [`stdout`], as [`out!`](crate::out!).
#[macro_export]
macro_rules! outln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        if let Err(e) = writeln!($crate::output::stdout(), $($arg)*) {
            $crate::interrupt::stdout_failed(e);
        }
    }};
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir() -> PathBuf {
        let d = std::env::temp_dir().join(format!("impact-output-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn input_path(inputs: &Inputs) -> PathBuf {
        inputs.paths[0].clone()
    }

    #[test]
    fn an_input_a_link_to_it_or_its_hard_link_is_refused() {
        let d = dir();
        let input = d.join("in.csv");
        std::fs::write(&input, "a\n").unwrap();
        let inputs = Inputs::new().with(&input);
        assert!(check("--plot", &input, &inputs, None).is_err());
        let hard = d.join("hard.svg");
        let _ = std::fs::remove_file(&hard);
        std::fs::hard_link(&input, &hard).unwrap();
        let e = check("--plot", &hard, &inputs, Some("svg")).unwrap_err();
        assert!(
            matches!(&e, OutputError::IsAnInput { input, .. } if *input == input_path(&inputs)),
            "{e:?}"
        );
        assert!(e.to_string().contains("would be overwritten"), "{e}");
        #[cfg(unix)]
        {
            let soft = d.join("soft.svg");
            let _ = std::fs::remove_file(&soft);
            std::os::unix::fs::symlink(&input, &soft).unwrap();
            assert!(check("--plot", &soft, &inputs, Some("svg")).is_err());
        }
        assert!(check("--plot", &d.join("new.svg"), &inputs, Some("svg")).is_ok());
        assert!(matches!(
            check("--plot", &d.join("new.png"), &inputs, Some("svg")),
            Err(OutputError::Extension { .. })
        ));
        assert!(matches!(
            check("--plot", &d.join("nowhere/x.svg"), &inputs, None),
            Err(OutputError::NoDirectory { .. })
        ));
    }

    #[test]
    fn a_write_is_whole_or_leaves_nothing() {
        let d = dir();
        let out = d.join("whole.txt");
        write(&out, b"complete\n").unwrap();
        assert_eq!(std::fs::read(&out).unwrap(), b"complete\n");
        // A failing writer: the old file stays, no temporary file is left.
        let e = write_with(&out, |w| {
            w.write_all(b"half")?;
            Err(std::io::Error::other("disk full"))
        })
        .unwrap_err();
        assert!(
            matches!(&e, OutputError::Write { path, .. } if *path == out),
            "{e:?}"
        );
        assert!(e.to_string().contains("whole.txt") && e.to_string().contains("disk full"));
        assert_eq!(std::fs::read(&out).unwrap(), b"complete\n");
        let left: Vec<_> = std::fs::read_dir(&d)
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().ends_with(".part"))
            .collect();
        assert!(left.is_empty(), "{left:?}");
    }
}
