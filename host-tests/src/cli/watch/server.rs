//! `impact watch`'s web server: the page, its event stream (Server-Sent Events), the
//! session's exports. Eight GET routes on localhost (`/`, `/events`, `/state.json`,
//! `/session.json`, `/session.csv`, `/report.html`, `/receipt`, `/receipts`), each connection
//! on its own thread; a page too slow for the stream loses events (counted and shown), never
//! holds up the board's input.
//!
//! Who is served: on a loopback address, a request whose `Host` is `localhost` or a loopback
//! address (a web page elsewhere, DNS rebinding included, names its own host); on a wider
//! address, a request whose `Host` is this machine's name, `localhost` or an IP literal, and
//! that carries the session's token (the URL printed, `?token=…`, which sets it as a cookie
//! for the page's own requests). A request head must arrive whole within [`TIMEOUT`] of its
//! connection (however slowly its bytes trickle in); at most [`MAX_EXPORTS`] exports are made
//! at once, each written to the socket as it is made.

use std::collections::VecDeque;
use std::io::{BufRead, BufReader, Read, Write};
use std::net::{TcpListener, TcpStream};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::{sync_channel, Receiver, RecvTimeoutError, SyncSender, TrySendError};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::Duration;

use serde_json::Value;

use super::session::Session;

/// The page (HTML, CSS and script in one file: no network).
const PAGE: &str = include_str!("page.html");
/// Events a page may have queued before it loses the next ones.
const QUEUE: usize = 128;
/// Receipts kept (the newest) for `/receipts`.
const RECEIPTS: usize = 4096;
/// The longest request head read, bytes.
const MAX_HEAD: usize = 8192;
/// Connections served at once at most (a page holds two or three).
const MAX_CONNECTIONS: usize = 64;
/// How long a request head may take to arrive, from the connection's accept (in all, however
/// slowly its bytes come), and a write to a peer that stopped reading.
const TIMEOUT: Duration = Duration::from_secs(10);
/// Exports (`/session.json`, `/session.csv`, `/report.html`) made at once at most; another is
/// answered 503 with `Retry-After`. Each holds the session's reports read back (about 1 KiB
/// an impact) while it writes them out.
pub const MAX_EXPORTS: usize = 4;
/// The marker a stale page's queue carries in place of its snapshot: its writer builds the
/// snapshot when it comes to it (so a page that never drains costs nothing).
const RESYNC: &str = "";

/// A page's event stream.
struct Client {
    tx: SyncSender<Arc<str>>,
    dropped: Arc<AtomicU64>,
    /// Whether it lost events since its last snapshot: it is sent none until its writer has
    /// sent it a new snapshot (the tick queues the marker, [`RESYNC`], once there is room).
    stale: Arc<AtomicBool>,
    /// Whether the marker is queued.
    resync: Arc<AtomicBool>,
}

/// The session and the pages watching it.
pub struct Hub {
    session: Mutex<Session>,
    clients: Mutex<Vec<Client>>,
    /// What the pages said they drew (`/receipt?…`), with the time it arrived (Unix ms).
    receipts: Mutex<VecDeque<String>>,
    /// The session file (the whole log as it arrived), for the exports.
    session_file: PathBuf,
    /// Whether the server is bound to a loopback address (then only `Host: localhost` or a
    /// loopback address is served, so a web page elsewhere cannot read the session).
    loopback: bool,
    /// Connections open.
    connections: std::sync::atomic::AtomicUsize,
    /// Exports being made.
    exports: std::sync::atomic::AtomicUsize,
    /// On a wider address than loopback: the token a request must carry (in the URL printed,
    /// then as the cookie that sets), and this machine's name (a `Host` it may give).
    token: Option<String>,
    hostname: Option<String>,
}

/// A new session's token: 128 random bits from the system (`/dev/urandom`), as hex.
pub fn new_token() -> std::io::Result<String> {
    let mut bytes = [0u8; 16];
    std::fs::File::open("/dev/urandom")?.read_exact(&mut bytes)?;
    Ok(bytes.iter().map(|b| format!("{b:02x}")).collect())
}

/// This machine's name (`gethostname`), if it has one.
pub fn machine_name() -> Option<String> {
    let mut buf = [0u8; 256];
    // SAFETY: gethostname(2) writes at most `buf.len()` bytes into `buf`.
    let r = unsafe { libc::gethostname(buf.as_mut_ptr().cast(), buf.len()) };
    if r != 0 {
        return None;
    }
    let end = buf.iter().position(|&b| b == 0).unwrap_or(buf.len());
    let name = String::from_utf8_lossy(&buf[..end]).into_owned();
    (!name.is_empty()).then_some(name)
}

/// A lock that a panicked thread left poisoned is still the session's.
fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// Unix time, ms.
pub fn now_ms() -> u64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_millis() as u64)
}

impl Hub {
    /// The hub of `session`, its lines kept in `session_file`; `token`: the token a request
    /// must carry when the server is not on loopback.
    pub fn new(
        session: Session,
        session_file: PathBuf,
        loopback: bool,
        token: Option<String>,
    ) -> Self {
        Self {
            session: Mutex::new(session),
            clients: Mutex::new(Vec::new()),
            receipts: Mutex::new(VecDeque::new()),
            session_file,
            loopback,
            connections: std::sync::atomic::AtomicUsize::new(0),
            exports: std::sync::atomic::AtomicUsize::new(0),
            hostname: if loopback { None } else { machine_name() },
            token,
        }
    }

    /// Runs `f` on the session and sends the events it returns to every page.
    pub fn with(&self, f: impl FnOnce(&mut Session) -> Vec<Value>) -> Vec<Value> {
        let mut session = lock(&self.session);
        let events = f(&mut session);
        // Sent under the session's lock, so a page connecting meanwhile gets its snapshot
        // first and then every later event, none twice.
        let mut clients = lock(&self.clients);
        for e in &events {
            let text: Arc<str> = format!("data: {e}\n\n").into();
            clients.retain(|c| c.stale.load(Ordering::Relaxed) || send(c, text.clone()));
        }
        events
    }

    /// How long since the last heartbeat, ms (`None` before the first or after the end).
    pub fn silent_for(&self, now_ms: u64) -> Option<u64> {
        lock(&self.session).silent_for(now_ms)
    }

    /// Sends each page the clock event (with the events it lost); a page that lost events
    /// gets the marker for a new snapshot once it has room for it, then nothing until its
    /// writer has sent the snapshot: it shows the session as it is again.
    pub fn tick(&self) {
        let session = lock(&self.session);
        let now = now_ms();
        let mut clients = lock(&self.clients);
        clients.retain(|c| {
            let text: Arc<str> = if c.stale.load(Ordering::Relaxed) {
                if c.resync.load(Ordering::Relaxed) {
                    return true;
                }
                RESYNC.into()
            } else {
                let tick = session.tick(now, c.dropped.load(Ordering::Relaxed));
                format!("data: {tick}\n\n").into()
            };
            match c.tx.try_send(text.clone()) {
                Ok(()) => {
                    if text.is_empty() {
                        c.resync.store(true, Ordering::Relaxed);
                    }
                    true
                }
                Err(TrySendError::Full(_)) => true,
                Err(TrySendError::Disconnected(_)) => false,
            }
        });
    }

    /// A stale page's snapshot, made when its writer reaches the marker: under the session's
    /// lock, so the events after it are the ones sent after it.
    fn resynced(&self, stale: &AtomicBool, resync: &AtomicBool) -> String {
        let session = lock(&self.session);
        stale.store(false, Ordering::Relaxed);
        resync.store(false, Ordering::Relaxed);
        format!("data: {}\n\n", session.snapshot(now_ms()))
    }

    /// A new page's stream (the snapshot first) and its stale and marker flags.
    fn subscribe(&self) -> (Receiver<Arc<str>>, Arc<AtomicBool>, Arc<AtomicBool>) {
        let session = lock(&self.session);
        let (tx, rx) = sync_channel(QUEUE);
        let snapshot = session.snapshot(now_ms());
        let client = Client {
            tx,
            dropped: Arc::new(AtomicU64::new(0)),
            stale: Arc::new(AtomicBool::new(false)),
            resync: Arc::new(AtomicBool::new(false)),
        };
        let flags = (client.stale.clone(), client.resync.clone());
        if send(&client, format!("data: {snapshot}\n\n").into()) {
            lock(&self.clients).push(client);
        }
        (rx, flags.0, flags.1)
    }
}

/// Queues `text` for a page; false once the page is gone.
fn send(c: &Client, text: Arc<str>) -> bool {
    match c.tx.try_send(text) {
        Ok(()) => true,
        Err(TrySendError::Full(_)) => {
            c.dropped.fetch_add(1, Ordering::Relaxed);
            c.stale.store(true, Ordering::Relaxed);
            true
        }
        Err(TrySendError::Disconnected(_)) => false,
    }
}

/// Serves `hub` on `listener` until the process ends; at most [`MAX_CONNECTIONS`] at once (one
/// more is closed at once).
pub fn serve(listener: TcpListener, hub: Arc<Hub>) {
    for stream in listener.incoming() {
        let Ok(stream) = stream else {
            // Out of file descriptors, say: wait rather than spin.
            std::thread::sleep(Duration::from_millis(100));
            continue;
        };
        if hub.connections.fetch_add(1, Ordering::Relaxed) >= MAX_CONNECTIONS {
            hub.connections.fetch_sub(1, Ordering::Relaxed);
            continue;
        }
        let hub = hub.clone();
        std::thread::spawn(move || {
            let _ = connection(stream, &hub);
            hub.connections.fetch_sub(1, Ordering::Relaxed);
        });
    }
}

/// Whether `host` (a Host header: a name or address, then perhaps a port) is this machine.
fn local_host(host: &str) -> bool {
    let name = match host.strip_prefix('[') {
        Some(rest) => rest.split(']').next().unwrap_or(""),
        None => host.split(':').next().unwrap_or(""),
    };
    name.eq_ignore_ascii_case("localhost")
        || name
            .parse::<std::net::IpAddr>()
            .is_ok_and(|ip| ip.is_loopback())
}

/// Whether `host` (a Host header) names this machine as a wide server may be named: its
/// name, `localhost` or an IP literal (a DNS name another site controls is none of these).
fn own_name(host: &str, hostname: Option<&str>) -> bool {
    let name = match host.strip_prefix('[') {
        Some(rest) => rest.split(']').next().unwrap_or(""),
        None => host.split(':').next().unwrap_or(""),
    };
    let name = name.strip_suffix('.').unwrap_or(name);
    name.eq_ignore_ascii_case("localhost")
        || name.parse::<std::net::IpAddr>().is_ok()
        || hostname.is_some_and(|h| !h.is_empty() && name.eq_ignore_ascii_case(h))
}

/// Whether `a` and `b` are equal, in time that does not depend on where they differ.
fn same_secret(a: &str, b: &str) -> bool {
    a.len() == b.len() && a.bytes().zip(b.bytes()).fold(0u8, |d, (x, y)| d | (x ^ y)) == 0
}

/// A connection's reads, each given what is left of the time the request head has
/// ([`TIMEOUT`] from the accept): a head trickled in a byte at a time still ends on time.
struct Deadline<'a> {
    stream: &'a TcpStream,
    until: std::time::Instant,
}

impl Read for Deadline<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let left = self
            .until
            .saturating_duration_since(std::time::Instant::now());
        if left.is_zero() {
            return Err(std::io::ErrorKind::TimedOut.into());
        }
        self.stream.set_read_timeout(Some(left))?;
        (&mut &*self.stream).read(buf)
    }
}

/// The cookie that carries the token of the server on `port` (one per port: two sessions on
/// one machine keep theirs).
fn cookie_name(port: u16) -> String {
    format!("impact_token_{port}")
}

/// One request on `stream`.
fn connection(stream: TcpStream, hub: &Hub) -> std::io::Result<()> {
    let until = std::time::Instant::now() + TIMEOUT;
    stream.set_write_timeout(Some(TIMEOUT))?;
    stream.set_nodelay(true)?;
    let mut reader = BufReader::new(Deadline {
        stream: &stream,
        until,
    });
    let (mut head, mut line) = (Vec::new(), String::new());
    let mut size = 0;
    loop {
        line.clear();
        let n = (&mut reader).take(MAX_HEAD as u64).read_line(&mut line)?;
        size += n;
        if n == 0 || line == "\r\n" || line == "\n" || size > MAX_HEAD {
            break;
        }
        head.push(line.trim_end().to_string());
    }
    drop(reader);
    let port = stream.local_addr().map_or(0, |a| a.port());
    let mut out = stream;
    let request = head.first().cloned().unwrap_or_default();
    let mut parts = request.split(' ');
    let (method, target) = (parts.next().unwrap_or(""), parts.next().unwrap_or(""));
    let header = |name: &str| {
        head.iter().skip(1).find_map(|h| {
            let (k, v) = h.split_once(':')?;
            k.trim()
                .eq_ignore_ascii_case(name)
                .then(|| v.trim().to_string())
        })
    };
    let host = header("host").unwrap_or_default();
    let (path, query) = target.split_once('?').unwrap_or((target, ""));
    // A token given in the URL is set as a cookie for the page's own requests.
    let mut set_cookie = None;
    if hub.loopback {
        if !local_host(&host) {
            return respond(&mut out, "403 Forbidden", "text/plain", b"not this host\n");
        }
    } else {
        if !own_name(&host, hub.hostname.as_deref()) {
            return respond(
                &mut out,
                "403 Forbidden",
                "text/plain",
                b"not this host: give this machine's name or address\n",
            );
        }
        let token = hub.token.as_deref().unwrap_or_default();
        let in_url = query
            .split('&')
            .filter_map(|kv| kv.strip_prefix("token="))
            .any(|t| same_secret(t, token));
        let name = cookie_name(port);
        let in_cookie = header("cookie").is_some_and(|c| {
            c.split(';')
                .filter_map(|kv| kv.trim().strip_prefix(name.as_str())?.strip_prefix('='))
                .any(|t| same_secret(t, token))
        });
        if !(in_url || in_cookie) || token.is_empty() {
            return respond(
                &mut out,
                "403 Forbidden",
                "text/plain",
                b"a token is needed: open the URL impact watch printed (.../?token=...)\n",
            );
        }
        if in_url {
            set_cookie = Some(format!(
                "Set-Cookie: {name}={token}; Path=/; HttpOnly; SameSite=Strict\r\n"
            ));
        }
    }
    if method != "GET" {
        return respond(
            &mut out,
            "405 Method Not Allowed",
            "text/plain",
            b"GET only\n",
        );
    }
    match path {
        "/" => respond_with(
            &mut out,
            "200 OK",
            "text/html; charset=utf-8",
            PAGE.as_bytes(),
            set_cookie.as_deref().unwrap_or(""),
        ),
        "/events" => events(&mut out, hub),
        "/state.json" => {
            let s = lock(&hub.session).snapshot(now_ms()).to_string();
            respond(&mut out, "200 OK", "application/json", s.as_bytes())
        }
        "/session.json" | "/session.csv" | "/report.html" => {
            let Some(_slot) = ExportSlot::take(&hub.exports) else {
                return respond_with(
                    &mut out,
                    "503 Service Unavailable",
                    "text/plain; charset=utf-8",
                    format!("{MAX_EXPORTS} exports are being made: try again in a few seconds\n")
                        .as_bytes(),
                    "Retry-After: 2\r\n",
                );
            };
            export(&mut out, hub, path)
        }
        "/receipt" => {
            let mut r = lock(&hub.receipts);
            if r.len() == RECEIPTS {
                r.pop_front();
            }
            r.push_back(format!("arrived_unix_ms={}&{query}", now_ms()));
            drop(r);
            write!(out, "HTTP/1.1 204 No Content\r\nConnection: close\r\n\r\n")
        }
        "/receipts" => {
            let text: String = lock(&hub.receipts)
                .iter()
                .map(|r| format!("{r}\n"))
                .collect();
            respond(&mut out, "200 OK", "text/plain", text.as_bytes())
        }
        _ => respond(&mut out, "404 Not Found", "text/plain", b"not found\n"),
    }
}

fn respond(out: &mut TcpStream, status: &str, kind: &str, body: &[u8]) -> std::io::Result<()> {
    respond_with(out, status, kind, body, "")
}

/// [`respond`] with `extra` header lines (each ending `\r\n`).
fn respond_with(
    out: &mut TcpStream,
    status: &str,
    kind: &str,
    body: &[u8],
    extra: &str,
) -> std::io::Result<()> {
    write!(
        out,
        "HTTP/1.1 {status}\r\nContent-Type: {kind}\r\nContent-Length: {}\r\nCache-Control: no-store\r\n{extra}Connection: close\r\n\r\n",
        body.len()
    )?;
    out.write_all(body)?;
    out.flush()
}

/// One of the [`MAX_EXPORTS`] export slots, given back when dropped.
struct ExportSlot<'a>(&'a std::sync::atomic::AtomicUsize);

impl<'a> ExportSlot<'a> {
    fn take(exports: &'a std::sync::atomic::AtomicUsize) -> Option<Self> {
        if exports.fetch_add(1, Ordering::AcqRel) >= MAX_EXPORTS {
            exports.fetch_sub(1, Ordering::AcqRel);
            return None;
        }
        Some(Self(exports))
    }
}

impl Drop for ExportSlot<'_> {
    fn drop(&mut self) {
        self.0.fetch_sub(1, Ordering::AcqRel);
    }
}

/// `text` as a header value: printable ASCII only (anything else `?`), at most 1000 bytes.
fn header_value(text: &str) -> String {
    let mut v: String = text
        .chars()
        .map(|c| if (' '..='~').contains(&c) { c } else { '?' })
        .collect();
    v.truncate(1000);
    v
}

/// An export of the session file (`path`: `/session.json`, `/session.csv`, `/report.html`),
/// as `impact log` reads it: a bad line passed over and named (the JSON's `skipped_lines`,
/// the report's notes, the CSV's `X-Impact-Skipped-Lines` header). The JSON and the CSV are
/// written to the socket an impact at a time, never held whole.
fn export(out: &mut TcpStream, hub: &Hub, path: &str) -> std::io::Result<()> {
    let failed = |out: &mut TcpStream, e: &dyn std::fmt::Display| {
        respond(
            out,
            "500 Internal Server Error",
            "text/plain; charset=utf-8",
            format!("the session file could not be exported: {e}\n").as_bytes(),
        )
    };
    if path == "/report.html" {
        // The pulse drawn: the board's, once its scene line stated it, else `--spec`'s.
        let drawn = lock(&hub.session).spec();
        return match crate::cli::html::log_report(&hub.session_file, drawn) {
            Ok(page) => respond(out, "200 OK", "text/html; charset=utf-8", page.as_bytes()),
            Err(e) => failed(out, &e),
        };
    }
    let csv = path.ends_with("csv");
    let log = match crate::cli::log::read_log(&hub.session_file) {
        Ok(log) => log,
        Err(e) => return failed(out, &e),
    };
    let export = match crate::cli::log::Export::new(&log) {
        Ok(x) => x,
        Err(e) => return failed(out, &e),
    };
    let skipped = match log.skipped.as_slice() {
        [] => String::new(),
        all => {
            let first: Vec<String> = all.iter().take(5).map(|s| s.note()).collect();
            let more = if all.len() > 5 { "; ..." } else { "" };
            format!(
                "X-Impact-Skipped-Lines: {} skipped: {}{more}\r\n",
                all.len(),
                header_value(&first.join("; "))
            )
        }
    };
    let kind = if csv { "text/csv" } else { "application/json" };
    // No length: the body ends with the connection.
    write!(
        out,
        "HTTP/1.1 200 OK\r\nContent-Type: {kind}\r\nCache-Control: no-store\r\n{skipped}Connection: close\r\n\r\n"
    )?;
    let mut w = std::io::BufWriter::with_capacity(1 << 16, out);
    export.write(csv, &mut w)?;
    w.flush()
}

/// The event stream: the snapshot, then every event as it comes; a comment every 15 s keeps
/// an idle connection open through proxies.
fn events(out: &mut TcpStream, hub: &Hub) -> std::io::Result<()> {
    write!(
        out,
        "HTTP/1.1 200 OK\r\nContent-Type: text/event-stream\r\nCache-Control: no-store\r\nConnection: keep-alive\r\n\r\nretry: 1000\n\n"
    )?;
    out.flush()?;
    let (rx, stale, resync) = hub.subscribe();
    loop {
        match rx.recv_timeout(Duration::from_secs(15)) {
            Ok(text) => {
                let mut pending = Some(text);
                // Whatever else is queued goes out in the same flush.
                while let Some(text) = pending.take().or_else(|| rx.try_recv().ok()) {
                    if text.is_empty() {
                        out.write_all(hub.resynced(&stale, &resync).as_bytes())?;
                    } else {
                        out.write_all(text.as_bytes())?;
                    }
                }
                out.flush()?;
            }
            Err(RecvTimeoutError::Timeout) => {
                out.write_all(b": idle\n\n")?;
                out.flush()?;
            }
            Err(RecvTimeoutError::Disconnected) => return Ok(()),
        }
    }
}
