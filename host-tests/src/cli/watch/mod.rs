//! `impact watch`: the board's log as it arrives (a pipe from probe-rs or `impact emulate
//! --realtime`, a growing file, a raw defmt stream) shown live: a local web page, or one line
//! per impact in the terminal; every line kept in the session file.

mod replay;
pub mod server;
pub mod session;
mod terminal;

use std::io::{Read, Write};
use std::net::TcpListener;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

use clap::Args;
use impact_io::table::MAX_LINE_BYTES;

use server::{now_ms, Hub};
use session::Session;

/// `impact watch` options.
#[derive(Args, Clone, Debug)]
pub struct WatchArgs {
    /// The board's decoded log (`-` or none: standard input, e.g. `cargo fw-run | impact
    /// watch`); a file is followed as it grows (`--once`: read to its end and stop).
    pub input: Option<PathBuf>,
    /// The input is the firmware's raw defmt stream, decoded against this ELF.
    #[arg(long)]
    pub elf: Option<PathBuf>,
    /// Read a file to its end, then stop following it.
    #[arg(long)]
    pub once: bool,
    /// The pulse the board judges, as `--spec` of `impact analyze`: drawn (the nominal pulse
    /// and tolerance band where each verdict placed it) until the board's scene line states
    /// its own, which is drawn then; one that differs from the board's is shown as a warning.
    #[arg(long, value_name = "SHAPE,PEAK,DURATION[,KEY=VALUE…]")]
    pub spec: Option<String>,
    /// Where the page is served (a loopback address by default: only this machine).
    #[arg(long, default_value = "127.0.0.1:8017", value_name = "ADDRESS:PORT")]
    pub listen: String,
    /// No web page: one line per impact and the board's health in the terminal.
    #[arg(long)]
    pub terminal: bool,
    /// The session file: every line read, as `impact log` reads it (default
    /// `impact-watch-<date>-<time>.log` here; never an existing file).
    #[arg(long, value_name = "FILE.log")]
    pub session: Option<PathBuf>,
    /// Replay a finished log at the pace it was written (a demo, a second look at a
    /// session): each line shown when as much wall-clock time has passed since the first
    /// as the board's clock (the line's leading time, s) had, over --speed.
    #[arg(long, value_name = "FILE.log", conflicts_with_all = ["input", "once", "elf"])]
    pub replay: Option<PathBuf>,
    /// With --replay: how many times faster than the board's clock (1 to 1000; not slower:
    /// the page's health judges a heartbeat's age by the wall clock).
    #[arg(long, value_name = "X", requires = "replay", value_parser = speed)]
    pub speed: Option<f64>,
}

/// `--speed`: a finite factor within [1, 1000].
fn speed(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(x) if (1.0..=1000.0).contains(&x) => Ok(x),
        Ok(_) => Err(
            "from 1 to 1000 times the board's pace (slower, the page would call the board \
             silent between heartbeats)"
                .into(),
        ),
        Err(_) => Err("not a number".into()),
    }
}

/// The session file's line for an input replaced (a rotation, a rewrite): the prefix and the
/// suffix around why (a replay of the session starts a new run there too).
const REPLACED_PREFIX: &str = "impact watch: ";
const REPLACED_SUFFIX: &str = "; a new run from here";

/// A new session file's default name: `impact-watch-YYYYMMDD-HHMMSS.log` (UTC).
fn default_session() -> PathBuf {
    let secs = now_ms() / 1000;
    let (days, rem) = ((secs / 86_400) as i64, secs % 86_400);
    // Days since 1970-01-01 to a civil date (Howard Hinnant's algorithm).
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    PathBuf::from(format!(
        "impact-watch-{y:04}{m:02}{d:02}-{:02}{:02}{:02}.log",
        rem / 3600,
        rem / 60 % 60,
        rem % 60
    ))
}

/// How much of a followed file's start is kept to tell a rewrite, bytes (and of the bytes
/// just read, [`TAIL`]).
const HEAD: usize = 4096;
const TAIL: usize = 256;

/// How a followed file was replaced.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Replaced {
    /// Another file at its path (another device and inode: a rotation, an atomic writer's
    /// rename).
    Rotated,
    /// The same file, shorter than what was read, or its first bytes (or the last ones
    /// read) changed.
    Rewritten,
}

impl Replaced {
    fn says(self, name: &str) -> String {
        match self {
            Replaced::Rotated => format!(
                "{name} was replaced by another file (rotated, or written anew and renamed)"
            ),
            Replaced::Rewritten => {
                format!("{name} was rewritten in place (it shrank, or bytes already read changed)")
            }
        }
    }
}

/// A file read as it grows: at its end, waits for more. The file is told by its (device,
/// inode), its size and its first bytes: at its end, every 50 ms, another file at the path
/// (a rotation) or the same one shorter or with other first bytes (a rewrite) ends the reading
/// of this one (`read` gives 0 until [`Follow::replaced`] is taken), and the reading starts
/// again from the new file's first byte. Checked before every read (a stat and two reads of
/// at most 4 KiB each, per 64 KiB read or 50 ms waited), so a replacement is not read as the
/// old file's continuation. (A rewrite that leaves the
/// first 4 KiB and the last 256 bytes read as they were, and grows, is not seen.)
struct Follow {
    path: PathBuf,
    file: std::fs::File,
    at: u64,
    follow: bool,
    /// (device, inode) of the file read.
    id: (u64, u64),
    /// Its first bytes as read (up to [`HEAD`]) and the last read (up to [`TAIL`]).
    head: Vec<u8>,
    tail: Vec<u8>,
    /// Why the file read was left for another, until the reading is started again.
    replaced: Option<Replaced>,
}

fn file_id(m: &std::fs::Metadata) -> (u64, u64) {
    use std::os::unix::fs::MetadataExt;
    (m.dev(), m.ino())
}

impl Follow {
    fn open(path: &std::path::Path, follow: bool) -> std::io::Result<Self> {
        let file = std::fs::File::open(path)?;
        let id = file_id(&file.metadata()?);
        Ok(Self {
            path: path.to_path_buf(),
            file,
            at: 0,
            follow,
            id,
            head: Vec::new(),
            tail: Vec::new(),
            replaced: None,
        })
    }

    /// Keeps what `bytes` (just read) add to the head and the tail.
    fn note(&mut self, bytes: &[u8]) {
        let room = HEAD.saturating_sub(self.head.len());
        self.head.extend_from_slice(&bytes[..room.min(bytes.len())]);
        self.tail
            .extend_from_slice(&bytes[bytes.len().saturating_sub(TAIL)..]);
        let extra = self.tail.len().saturating_sub(TAIL);
        self.tail.drain(..extra);
        self.at += bytes.len() as u64;
    }

    /// Whether the file was replaced since it was last read.
    fn changed(&self) -> std::io::Result<Option<Replaced>> {
        use std::os::unix::fs::FileExt;
        // (A path missing for a moment, between a rotation's two renames, is no change yet.)
        if let Ok(m) = std::fs::metadata(&self.path) {
            if file_id(&m) != self.id {
                return Ok(Some(Replaced::Rotated));
            }
        }
        if self.file.metadata()?.len() < self.at {
            return Ok(Some(Replaced::Rewritten));
        }
        let same = |bytes: &[u8], at: u64| -> std::io::Result<bool> {
            let mut now = vec![0; bytes.len()];
            match self.file.read_exact_at(&mut now, at) {
                Ok(()) => Ok(now == bytes),
                Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => Ok(false),
                Err(e) => Err(e),
            }
        };
        let tail_at = self.at - self.tail.len() as u64;
        if !same(&self.head, 0)? || !same(&self.tail, tail_at)? {
            return Ok(Some(Replaced::Rewritten));
        }
        Ok(None)
    }

    /// Starts reading the file at the path again from its first byte.
    fn restart(&mut self, why: Replaced) -> std::io::Result<()> {
        use std::io::Seek;
        if why == Replaced::Rotated {
            let file = std::fs::File::open(&self.path)?;
            self.id = file_id(&file.metadata()?);
            self.file = file;
        } else {
            self.file.seek(std::io::SeekFrom::Start(0))?;
        }
        (self.at, self.replaced) = (0, Some(why));
        self.head.clear();
        self.tail.clear();
        Ok(())
    }
}

impl Read for Follow {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        if self.replaced.is_some() {
            return Ok(0);
        }
        loop {
            // Checked before every read: bytes of a replacement are never read on from the
            // old file's end.
            match self.changed()? {
                Some(Replaced::Rotated) if self.follow => {
                    // What the old file got before it was replaced is read first.
                    let n = self.file.read(buf)?;
                    if n > 0 {
                        self.note(&buf[..n]);
                        return Ok(n);
                    }
                    self.restart(Replaced::Rotated)?;
                    return Ok(0);
                }
                Some(Replaced::Rewritten) if self.follow => {
                    self.restart(Replaced::Rewritten)?;
                    return Ok(0);
                }
                _ => {}
            }
            let n = self.file.read(buf)?;
            if n > 0 || !self.follow {
                self.note(&buf[..n]);
                return Ok(n);
            }
            std::thread::sleep(Duration::from_millis(50));
        }
    }
}

/// The input: standard input, or a file followed (shared with the reading loop, which asks
/// it whether the file was replaced when the reading ends).
struct Input(Option<Arc<std::sync::Mutex<Follow>>>);

impl Read for Input {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        match &self.0 {
            Some(f) => lock(f).read(buf),
            None => std::io::stdin().read(buf),
        }
    }
}

fn lock<T>(m: &std::sync::Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// Why `impact watch` could not start, or stopped.
#[derive(Debug, thiserror::Error)]
pub enum WatchError {
    /// `--spec` refused.
    #[error(transparent)]
    Spec(#[from] crate::pipeline::spec::SpecError),
    #[error(transparent)]
    Output(#[from] crate::output::OutputError),
    /// The board's log (`name`: as the tool names it) could not be opened.
    #[error("{name}: {source}")]
    Open {
        name: String,
        source: std::io::Error,
    },
    #[error(
        "--listen {address}: {source} (another `impact watch`? give another port, or :0 for any)"
    )]
    Listen {
        address: String,
        source: std::io::Error,
    },
    #[error("--session {}: {source} (a session file is never overwritten)", .path.display())]
    Session {
        path: PathBuf,
        source: std::io::Error,
    },
    /// The bound listener's own address could not be read.
    #[error(transparent)]
    Address(std::io::Error),
    /// No random token for a server on a wider address than loopback.
    #[error(
        "--listen: no random token for the page (/dev/urandom: {0}); give --listen 127.0.0.1:PORT"
    )]
    Token(std::io::Error),
    /// A line could not be kept in the session file.
    #[error("{}: {source}", .path.display())]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error(transparent)]
    Defmt(#[from] crate::firmware_link::decode::DefmtError),
    #[error(transparent)]
    ReadLine(#[from] crate::cli::log::ReadLineError),
}

/// Runs `impact watch`.
pub fn run(args: &WatchArgs) -> Result<(), WatchError> {
    let input = args
        .replay
        .clone()
        .or_else(|| args.input.clone())
        .unwrap_or_else(|| PathBuf::from("-"));
    let mut pace = args
        .replay
        .as_ref()
        .map(|_| replay::Pace::new(args.speed.unwrap_or(1.0)));
    let stdin = impact_io::channel::is_stdin(&input);
    let name = impact_io::channel::input_name(&input);
    let parsed = args
        .spec
        .as_deref()
        .map(crate::pipeline::spec::parse)
        .transpose()?;
    let spec = parsed.map(|a| (a.spec, a.standard));
    let session_path = args.session.clone().unwrap_or_else(default_session);
    let inputs = crate::output::Inputs::new()
        .with(&input)
        .with_some(args.elf.as_deref())
        .with_some(parsed.and_then(|a| a.band_file));
    crate::output::check("--session", &session_path, &inputs, None)?;
    let follow = if stdin {
        None
    } else {
        let follow = !args.once && args.replay.is_none();
        let f = Follow::open(&input, follow).map_err(|source| WatchError::Open {
            name: name.clone(),
            source,
        })?;
        Some(Arc::new(std::sync::Mutex::new(f)))
    };
    let mut source = Input(follow.clone());
    // Bound before the session file is made: a port in use is said at once.
    let listener = if args.terminal {
        None
    } else {
        let l = TcpListener::bind(&args.listen).map_err(|source| WatchError::Listen {
            address: args.listen.clone(),
            source,
        })?;
        Some(l)
    };
    let file = std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&session_path)
        .map_err(|source| WatchError::Session {
            path: session_path.clone(),
            source,
        })?;
    let log = std::cell::RefCell::new(std::io::BufWriter::new(file));
    let session = Session::new(&name, &session_path.display().to_string(), spec);
    let loopback = listener
        .as_ref()
        .and_then(|l| l.local_addr().ok())
        .is_some_and(|a| a.ip().is_loopback());
    // A server on a wider address than loopback asks for a token (in the URL it prints).
    let token = match (&listener, loopback) {
        (Some(_), false) => Some(server::new_token().map_err(WatchError::Token)?),
        _ => None,
    };
    let hub = Arc::new(Hub::new(
        session,
        session_path.clone(),
        loopback,
        token.clone(),
    ));
    let terminal = args.terminal;
    if let Some(l) = listener {
        let addr = l.local_addr().map_err(WatchError::Address)?;
        match &token {
            None => crate::errln!(
                "impact watch: http://{addr}/ (session file {})",
                session_path.display()
            ),
            Some(token) => {
                // An unspecified address (0.0.0.0) is reached by this machine's name.
                let host = if addr.ip().is_unspecified() {
                    server::machine_name().unwrap_or_else(|| "localhost".to_string())
                } else {
                    addr.ip().to_string()
                };
                let host = if host.contains(':') && !host.contains('[') {
                    format!("[{host}]")
                } else {
                    host
                };
                crate::errln!(
                    "impact watch: http://{host}:{}/?token={token} (session file {})",
                    addr.port(),
                    session_path.display()
                );
                crate::errln!(
                    "impact watch: --listen {addr} is not a loopback address: a request must \
                     carry the token of the URL above (open it once: the page keeps it), and \
                     name this machine or an address of it; anyone who has the URL sees the \
                     session (give --listen 127.0.0.1:PORT to serve this machine only)"
                );
            }
        }
        let h = hub.clone();
        std::thread::spawn(move || server::serve(l, h));
    } else {
        crate::errln!("impact watch: session file {}", session_path.display());
    }
    if stdin && std::io::IsTerminal::is_terminal(&std::io::stdin()) {
        crate::errln!(
            "impact watch: reading the board's log from standard input: pipe it in \
             (cargo fw-run | impact watch), or name a log file"
        );
    }
    // The clock: impacts that waited for their srs/spec lines shown, pages told the time, a
    // silent board said in the terminal.
    {
        let hub = hub.clone();
        std::thread::spawn(move || {
            let mut said_silent = false;
            loop {
                std::thread::sleep(Duration::from_millis(100));
                let events = hub.with(|s| s.flush(now_ms()));
                if terminal {
                    terminal::print(&events);
                    let quiet = hub.silent_for(now_ms());
                    let silent = quiet.is_some_and(|ms| ms > session::SILENT_MS);
                    if silent != said_silent {
                        // (A stream that ended is not silent; it said so.)
                        if silent || quiet.is_some() {
                            terminal::silence(quiet.filter(|_| silent));
                        }
                        said_silent = silent;
                    }
                }
                hub.tick();
            }
        });
    }
    // The session file: every line as it came.
    let keep = |line: &str| -> Result<(), WatchError> {
        let mut log = log.borrow_mut();
        writeln!(log, "{line}")
            .and_then(|()| log.flush())
            .map_err(|source| WatchError::Write {
                path: session_path.clone(),
                source,
            })
    };
    let replaying = pace.is_some();
    let mut on_line = |n: u64, line: &str| -> Result<(), WatchError> {
        if let Some(pace) = pace.as_mut() {
            pace.wait(line);
        }
        keep(line)?;
        // A session file replayed: its own marker of a replaced input starts a new run, as it
        // did live.
        let marker = line
            .strip_prefix(REPLACED_PREFIX)
            .and_then(|l| l.strip_suffix(REPLACED_SUFFIX))
            .filter(|_| replaying);
        let events = match marker {
            Some(text) => hub.with(|s| s.input_replaced(text, now_ms())),
            None => hub.with(|s| s.line(n, line, now_ms())),
        };
        if terminal {
            terminal::print(&events);
        }
        Ok(())
    };
    loop {
        match &args.elf {
            Some(elf) => {
                let skipped =
                    crate::firmware_link::decode::decode(elf, &mut source, &name, &mut on_line)?;
                if skipped > 0 {
                    crate::errln!("warning: {name}: {skipped} malformed defmt frames skipped");
                }
            }
            None => crate::cli::log::for_each_line(&mut source, &name, |n, line, cut| {
                if cut {
                    crate::errln!(
                        "warning: {name}:{n}: a line longer than {MAX_LINE_BYTES} bytes, cut"
                    );
                }
                on_line(n, line)
            })?,
        }
        // A file replaced: a new run from the new file's first line (said in the session
        // file too, as a line no reader takes for the board's).
        let Some(why) = follow.as_ref().and_then(|f| lock(f).replaced.take()) else {
            break;
        };
        let text = why.says(&name);
        keep(&format!("{REPLACED_PREFIX}{text}{REPLACED_SUFFIX}"))?;
        let events = hub.with(|s| s.input_replaced(&text, now_ms()));
        if terminal {
            terminal::print(&events);
        }
    }
    let events = hub.with(|s| s.input_ended(now_ms()));
    if terminal {
        terminal::print(&events);
        return Ok(());
    }
    crate::errln!("impact watch: {name} ended; the page stays up (Ctrl-C to stop)");
    loop {
        std::thread::park();
    }
}
