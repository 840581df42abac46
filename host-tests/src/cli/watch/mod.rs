//! `impact watch`: the board's log as it arrives (a pipe from probe-rs or `impact emulate
//! --realtime`, a growing file, a raw defmt stream) shown live: a local web page, or one line
//! per impact in the terminal; every line kept in the session file.

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
}

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

/// A file read as it grows: at its end, waits for more (a file cut shorter, a log started
/// again, is read from its start).
struct Follow {
    file: std::fs::File,
    at: u64,
    follow: bool,
}

impl Read for Follow {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        loop {
            let n = self.file.read(buf)?;
            if n > 0 || !self.follow {
                self.at += n as u64;
                return Ok(n);
            }
            std::thread::sleep(Duration::from_millis(50));
            if self.file.metadata()?.len() < self.at {
                use std::io::Seek;
                self.at = self.file.seek(std::io::SeekFrom::Start(0))?;
            }
        }
    }
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
    let input = args.input.clone().unwrap_or_else(|| PathBuf::from("-"));
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
    let source: Box<dyn Read + Send> = if stdin {
        Box::new(std::io::stdin())
    } else {
        let file = std::fs::File::open(&input).map_err(|source| WatchError::Open {
            name: name.clone(),
            source,
        })?;
        Box::new(Follow {
            file,
            at: 0,
            follow: !args.once,
        })
    };
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
    let mut log = std::io::BufWriter::new(file);
    let session = Session::new(&name, &session_path.display().to_string(), spec);
    let loopback = listener
        .as_ref()
        .and_then(|l| l.local_addr().ok())
        .is_some_and(|a| a.ip().is_loopback());
    let hub = Arc::new(Hub::new(session, session_path.clone(), loopback));
    let terminal = args.terminal;
    if let Some(l) = listener {
        let addr = l.local_addr().map_err(WatchError::Address)?;
        crate::errln!(
            "impact watch: http://{addr}/ (session file {})",
            session_path.display()
        );
        if !loopback {
            crate::errln!(
                "impact watch: --listen {addr} is not a loopback address: anyone who can reach \
                 it sees the session"
            );
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
    let mut on_line = |n: u64, line: &str| -> Result<(), WatchError> {
        writeln!(log, "{line}")
            .and_then(|()| log.flush())
            .map_err(|source| WatchError::Write {
                path: session_path.clone(),
                source,
            })?;
        let events = hub.with(|s| s.line(n, line, now_ms()));
        if terminal {
            terminal::print(&events);
        }
        Ok(())
    };
    match &args.elf {
        Some(elf) => {
            let skipped = crate::firmware_link::decode::decode(elf, source, &name, &mut on_line)?;
            if skipped > 0 {
                crate::errln!("warning: {name}: {skipped} malformed defmt frames skipped");
            }
        }
        None => crate::cli::log::for_each_line(source, &name, |n, line, cut| {
            if cut {
                crate::errln!(
                    "warning: {name}:{n}: a line longer than {MAX_LINE_BYTES} bytes, cut"
                );
            }
            on_line(n, line)
        })?,
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
