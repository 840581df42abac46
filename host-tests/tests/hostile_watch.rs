//! `impact watch` and `impact log` under hostile input (issue #45, round four): a followed log
//! rewritten in place or replaced by a rename, a line cut by the link, implausible lines and
//! scenes, concurrent exports of a long session, a wide `--listen`, request heads trickled in.
//! Each case failed on the binary before its fix.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::sync::mpsc::{channel, Receiver};
use std::time::{Duration, Instant};

mod common;
use common::board_log::{heartbeat, impact_line, summary, SCENE};
use common::Scratch;

/// A running `impact watch` (killed when dropped) and what its first stderr line says.
struct Watch {
    child: Child,
    /// `host:port` as printed, and the port.
    port: u16,
    /// The URL's token (a wide `--listen`), if any.
    token: Option<String>,
    /// Its stdout lines (terminal mode) and its stderr lines after the first.
    stdout: Option<Receiver<String>>,
    stderr: Receiver<String>,
}

impl Drop for Watch {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Lines of `r` through a channel, so that a stall fails a test instead of hanging it.
fn lines_of(r: impl Read + Send + 'static) -> Receiver<String> {
    let (tx, rx) = channel();
    std::thread::spawn(move || {
        for line in BufReader::new(r).lines().map_while(Result::ok) {
            if tx.send(line).is_err() {
                break;
            }
        }
    });
    rx
}

impl Watch {
    /// `impact watch ARGS…` with `input` on its standard input (then closed), if given.
    fn start(args: &[&str], input: Option<String>) -> Self {
        let mut child = Command::new(env!("CARGO_BIN_EXE_impact"))
            .arg("watch")
            .args(args)
            .stdin(if input.is_some() {
                Stdio::piped()
            } else {
                Stdio::null()
            })
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        if let Some(text) = input {
            let mut stdin = child.stdin.take().unwrap();
            std::thread::spawn(move || stdin.write_all(text.as_bytes()));
        }
        let stderr = lines_of(child.stderr.take().unwrap());
        let stdout = Some(lines_of(child.stdout.take().unwrap()));
        let terminal = args.contains(&"--terminal");
        let (mut port, mut token) = (0, None);
        if !terminal {
            let first = stderr.recv_timeout(Duration::from_secs(10)).unwrap();
            let url = first
                .split("http://")
                .nth(1)
                .unwrap_or_else(|| panic!("{first}"));
            let url = url.split_whitespace().next().unwrap();
            let hostport = url.split('/').next().unwrap();
            port = hostport.rsplit(':').next().unwrap().parse().unwrap();
            token = url.split("token=").nth(1).map(str::to_string);
        }
        Self {
            child,
            port,
            token,
            stdout,
            stderr,
        }
    }

    /// GET `path` on 127.0.0.1 with `Host: host` (none: the address) and `headers`: the
    /// status code, the head and the body.
    fn request(&self, path: &str, host: Option<&str>, headers: &str) -> (u16, String, String) {
        request(self.port, path, host, headers)
    }

    fn get(&self, path: &str) -> (u16, String) {
        let (status, _, body) = self.request(path, None, "");
        (status, body)
    }

    fn state(&self) -> serde_json::Value {
        serde_json::from_str(&self.get("/state.json").1).unwrap()
    }

    /// Waits (at most 15 s) until the session has read `lines` lines.
    fn wait_lines(&self, lines: u64) {
        let t = Instant::now();
        loop {
            let tick = self.get("/state.json").1;
            let s: serde_json::Value = serde_json::from_str(&tick).unwrap_or_default();
            // (The snapshot has no line count: the health's impacts and the trend tell.)
            let seen = s["trend"].as_array().map_or(0, Vec::len) as u64;
            if seen >= lines {
                return;
            }
            assert!(t.elapsed() < Duration::from_secs(15), "{seen} of {lines}");
            std::thread::sleep(Duration::from_millis(50));
        }
    }

    /// The tool's peak resident memory, MiB.
    fn peak_mib(&self) -> f64 {
        let status = std::fs::read_to_string(format!("/proc/{}/status", self.child.id())).unwrap();
        let kib: f64 = status
            .lines()
            .find_map(|l| l.strip_prefix("VmHWM:"))
            .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
            .unwrap();
        kib / 1024.0
    }
}

/// GET `path` on 127.0.0.1:`port` with `Host: host` (none: the address) and `headers`: the
/// status code, the head and the body.
fn request(port: u16, path: &str, host: Option<&str>, headers: &str) -> (u16, String, String) {
    let addr = format!("127.0.0.1:{port}");
    let mut s = TcpStream::connect(&addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(15))).unwrap();
    write!(
        s,
        "GET {path} HTTP/1.1\r\nHost: {}\r\n{headers}Connection: close\r\n\r\n",
        host.unwrap_or(&addr)
    )
    .unwrap();
    let mut bytes = Vec::new();
    let _ = s.read_to_end(&mut bytes);
    let text = String::from_utf8_lossy(&bytes).into_owned();
    let (head, body) = text.split_once("\r\n\r\n").unwrap_or((&text, ""));
    let status = head
        .split(' ')
        .nth(1)
        .and_then(|c| c.parse().ok())
        .unwrap_or(0);
    (status, head.to_string(), body.to_string())
}

/// Stdout lines of a terminal watch until `done` holds for the lines so far (at most 15 s).
fn read_until(w: &Watch, seen: &mut Vec<String>, done: impl Fn(&[String]) -> bool) {
    let t = Instant::now();
    let rx = w.stdout.as_ref().unwrap();
    while !done(seen) {
        let left = Duration::from_secs(15).saturating_sub(t.elapsed());
        match rx.recv_timeout(left) {
            Ok(line) => seen.push(line),
            Err(_) => panic!("not within 15 s: {seen:#?}"),
        }
    }
}

/// A board's log: its first line `first`, the scene, `n` impacts of peak `peak` m/s², a
/// heartbeat.
fn board(first: &str, n: u64, peak: &str) -> String {
    let mut text = format!("{first}\n{SCENE}\n");
    for i in 0..n {
        text += &impact_line(i, i, Some(("peak_acceleration_m_s2", peak)));
        text.push('\n');
    }
    text + &heartbeat(n, 40_000 * n, n) + "\n"
}

/// Impacts printed by a terminal watch: (run, index, peak text).
fn impacts(lines: &[String]) -> Vec<(u32, u32, String)> {
    lines
        .iter()
        .filter_map(|l| {
            let mut w = l.split_whitespace();
            (w.next()? == "run").then_some(())?;
            let run = w.next()?.parse().ok()?;
            (w.next()? == "impact").then_some(())?;
            let index = w.next()?.parse().ok()?;
            let peak = l.split("peak ").nth(1)?.split(' ').next()?.to_string();
            Some((run, index, peak))
        })
        .collect()
}

fn follow(scratch: &Scratch, log: &Path, session: &str) -> Watch {
    Watch::start(
        &[
            "--terminal",
            "--session",
            scratch.join_str(session).as_str(),
            log.to_str().unwrap(),
        ],
        None,
    )
}

/// A followed log rewritten in place (the same inode) with longer content: a new run from the
/// new content's first line, said; the old run's impacts are not mixed into it.
#[test]
fn a_log_rewritten_in_place_with_longer_content_starts_a_new_run() {
    let scratch = Scratch::new();
    let log = scratch.join("board.log");
    std::fs::write(&log, board("0.000000 INFO  boot one", 3, "100.0")).unwrap();
    let w = follow(&scratch, &log, "rewrite-session.log");
    let mut seen = Vec::new();
    read_until(&w, &mut seen, |l| impacts(l).len() == 3);
    // Over the old bytes from the start, never shorter (no truncation in between).
    let new = board("0.000000 INFO  boot two", 5, "200.0");
    let mut f = std::fs::OpenOptions::new().write(true).open(&log).unwrap();
    f.write_all(new.as_bytes()).unwrap();
    drop(f);
    read_until(&w, &mut seen, |l| impacts(l).len() >= 8);
    let got = impacts(&seen);
    let second: Vec<_> = got[3..]
        .iter()
        .map(|(r, i, p)| (*r, *i, p.as_str()))
        .collect();
    // 200 m/s² is 20.39 g; the old file's 10.2 g never in the new run.
    assert_eq!(
        second,
        (0..5).map(|i| (2, i, "20.39")).collect::<Vec<_>>(),
        "{seen:#?}"
    );
    let notice = w
        .stderr
        .recv_timeout(Duration::from_secs(5))
        .unwrap_or_default();
    assert!(
        seen.iter().any(|l| l.contains("rewritten")) || notice.contains("rewritten"),
        "no notice: {seen:#?} {notice}"
    );
    // The session file has the new file's first lines.
    let session = std::fs::read_to_string(scratch.join("rewrite-session.log")).unwrap();
    assert!(session.contains("boot two"), "{session}");
}

/// A followed log replaced by a rename (a rotation, any atomic writer): the new file is read
/// from its start as a new run, said.
#[test]
fn a_log_replaced_by_rename_starts_a_new_run() {
    let scratch = Scratch::new();
    let log = scratch.join("board.log");
    std::fs::write(&log, board("0.000000 INFO  boot one", 2, "100.0")).unwrap();
    let w = follow(&scratch, &log, "rename-session.log");
    let mut seen = Vec::new();
    read_until(&w, &mut seen, |l| impacts(l).len() == 2);
    let tmp = scratch.join("board.log.tmp");
    std::fs::write(&tmp, board("0.000000 INFO  boot two", 2, "200.0")).unwrap();
    std::fs::rename(&tmp, &log).unwrap();
    read_until(&w, &mut seen, |l| impacts(l).len() >= 4);
    let got = impacts(&seen);
    assert_eq!(
        (got[2].0, got[2].1, got[2].2.as_str()),
        (2, 0, "20.39"),
        "{seen:#?}"
    );
    assert!(
        seen.iter().any(|l| l.contains("replaced")),
        "no notice: {seen:#?}"
    );
    let session = std::fs::read_to_string(scratch.join("rename-session.log")).unwrap();
    assert!(session.contains("boot two"), "{session}");
}

/// One impact line cut by the link: the page, every export and `impact log` skip it and name
/// it (line 4) instead of refusing the session.
#[test]
fn a_cut_line_is_skipped_and_named_by_every_export_and_impact_log() {
    let scratch = Scratch::new();
    let cut = impact_line(2, 2, None);
    let lines = [
        SCENE.to_string(),
        impact_line(0, 0, None),
        impact_line(1, 1, None),
        cut[..cut.len() / 2].to_string(),
        impact_line(3, 3, None),
        heartbeat(4, 200_000, 4),
    ];
    let session = scratch.join_str("cut-session.log");
    let w = Watch::start(
        &["-", "--listen", "127.0.0.1:0", "--session", &session],
        Some(lines.join("\n") + "\n"),
    );
    w.wait_lines(3);
    let (status, json) = w.get("/session.json");
    assert_eq!(status, 200, "{json}");
    let j: serde_json::Value = serde_json::from_str(&json).unwrap();
    let indices: Vec<u64> = j["impacts"]
        .as_array()
        .unwrap()
        .iter()
        .map(|i| i["index"].as_u64().unwrap())
        .collect();
    assert_eq!(indices, [0, 1, 3]);
    assert_eq!(j["skipped_lines"][0]["line"], 4, "{json}");
    assert!(
        j["skipped_lines"][0]["reason"]
            .as_str()
            .unwrap()
            .contains("missing"),
        "{json}"
    );
    let (status, head, csv) = w.request("/session.csv", None, "");
    assert_eq!(status, 200, "{csv}");
    assert_eq!(csv.lines().count(), 4, "{csv}");
    assert!(head.contains("line 4"), "{head}");
    let (status, html) = w.get("/report.html");
    assert_eq!(status, 200, "{html}");
    assert!(html.contains("line 4: "), "the report names the line");
    // `impact log` of the session file: the same three impacts, the line named.
    let (code, out, err) = common::impact(&["log", &session]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("line 4: ") && err.contains("skipped"), "{err}");
    let j: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(j["impacts"].as_array().unwrap().len(), 3);
}

/// A `duration_s=1e30` line (which `impact log` refuses) stays out of the live statistics;
/// an impact ending at sample 1e15 is refused too, and `/report.html` answers at once.
#[test]
fn implausible_lines_stay_out_of_the_live_statistics_and_the_report() {
    let scratch = Scratch::new();
    let lines = [
        SCENE.to_string(),
        impact_line(0, 0, None),
        impact_line(1, 1, Some(("duration_s", "1e30"))),
        impact_line(2, 2, Some(("end_sample", "1000000000000000"))),
        impact_line(3, 3, None),
        heartbeat(4, 200_000, 4),
    ];
    let session = scratch.join_str("implausible-session.log");
    let w = Watch::start(
        &["-", "--listen", "127.0.0.1:0", "--session", &session],
        Some(lines.join("\n") + "\n"),
    );
    w.wait_lines(2);
    std::thread::sleep(Duration::from_millis(400));
    let s = w.state();
    let duration = &s["stats"]["metrics"][2];
    assert_eq!(duration["name"], "duration_s");
    assert_eq!(duration["n"], 2, "{duration}");
    assert!(duration["max"].as_f64().unwrap() < 1.0, "{duration}");
    assert_eq!(s["trend"].as_array().unwrap().len(), 2, "{s}");
    let t = Instant::now();
    let (status, html) = w.get("/report.html");
    assert_eq!(status, 200, "{html}");
    assert!(t.elapsed() < Duration::from_secs(5), "{:?}", t.elapsed());
    assert!(html.contains("line 3: ") && html.contains("line 4: "));
}

/// A scene whose rate no board samples at (1e-38 Hz voided every plausibility check) is
/// refused naming its line and the bounds; the checks then use the heartbeat's rate.
#[test]
fn an_implausible_scene_rate_is_refused_and_the_checks_do_not_use_it() {
    let scratch = Scratch::new();
    let scene = SCENE.replace("rate_hz=500000.0", "rate_hz=1e-38");
    let log = [
        scene,
        impact_line(0, 0, None),
        impact_line(1, 1, Some(("duration_s", "1e30"))),
        heartbeat(2, 100_000, 2),
    ];
    let path = scratch.text("rate.log", &(log.join("\n") + "\n"));
    let (code, out, err) = common::impact(&["log", &path]);
    assert!(
        err.contains("line 1: ") && err.contains("rate_hz=1e-38") && err.contains("1 Hz"),
        "{err}"
    );
    assert!(err.contains("line 3: duration_s=1e30"), "{err}");
    assert_eq!(code, 0, "{err}");
    let j: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(j["impacts"].as_array().unwrap().len(), 1, "{out}");
    assert!(
        j["impacts"][0]["duration_s"].as_f64().unwrap() < 1.0,
        "{out}"
    );
    assert_eq!(j["skipped_lines"][1]["line"], 3, "{out}");
    assert!(!out.contains("NaN") && !out.contains("inf,"), "{out}");
}

/// A `wave` line declaring 4 294 967 295 samples is refused at once, naming what a window
/// holds; it is never blamed on the link.
#[test]
fn a_wave_line_declaring_four_billion_samples_is_refused_at_once() {
    let scratch = Scratch::new();
    let scene = SCENE.replace("wave_every=0", "wave_every=1");
    let log = [
        scene,
        "0.1 INFO  wave seq=0 index=0 first_sample=5000 samples=4294967295 every=1 \
         frames=67108864 base_sum=0 base_n=1"
            .to_string(),
        format!(
            "0.1 INFO  wave_frame seq=1 index=0 frame=0 counts=[{}]",
            vec!["1"; 64].join(", ")
        ),
        impact_line(2, 0, None),
        summary(3, 100_000, 1),
    ];
    let path = scratch.text("wave.log", &(log.join("\n") + "\n"));
    let export = scratch.join_str("w.csv");
    let t = Instant::now();
    let (code, _, err) = common::impact(&["log", &path, "--export", &export]);
    assert!(t.elapsed() < Duration::from_secs(2), "{:?}", t.elapsed());
    assert!(
        err.contains("line 2: ") && err.contains("samples=4294967295"),
        "{err}"
    );
    assert!(!err.contains("link dropped"), "{err}");
    assert!(code == 0 || code == 1, "{err}");
}

/// A session of `n` impacts (a heartbeat every 100, the summary).
fn long_log(n: u64) -> String {
    let mut text = String::with_capacity(n as usize * 1600);
    text += SCENE;
    text.push('\n');
    let mut seq = 0;
    for i in 0..n {
        text += &impact_line(seq, i, None);
        text.push('\n');
        seq += 1;
        if (i + 1) % 100 == 0 {
            text += &heartbeat(seq, 40_000 * (i + 1), i + 1);
            text.push('\n');
            seq += 1;
        }
    }
    text + &summary(seq, 40_000 * n, n) + "\n"
}

/// 16 clients export a 10 000-impact session at once: a few are served at a time (the others
/// told to come back), each written as it is made: the tool's peak memory stays bounded.
#[test]
fn sixteen_concurrent_exports_of_a_long_session_stay_in_bounded_memory() {
    let scratch = Scratch::new();
    let log = scratch.text("long.log", &long_log(10_000));
    let session = scratch.join_str("long-session.log");
    let w = Watch::start(
        &[
            &log,
            "--once",
            "--listen",
            "127.0.0.1:0",
            "--session",
            &session,
        ],
        None,
    );
    // The input read (its end said on stderr).
    let t = Instant::now();
    loop {
        let line = w.stderr.recv_timeout(Duration::from_secs(15)).unwrap();
        if line.contains("ended") {
            break;
        }
        assert!(t.elapsed() < Duration::from_secs(15));
    }
    let before = w.peak_mib();
    let port = w.port;
    let clients: Vec<_> = (0..16)
        .map(|k| {
            std::thread::spawn(move || {
                let path = if k % 2 == 0 {
                    "/session.json"
                } else {
                    "/session.csv"
                };
                request(port, path, None, "")
            })
        })
        .collect();
    let answers: Vec<_> = clients.into_iter().map(|c| c.join().unwrap()).collect();
    let peak = w.peak_mib();
    let served = answers.iter().filter(|a| a.0 == 200).count();
    let busy = answers.iter().filter(|a| a.0 == 503).count();
    assert_eq!(
        served + busy,
        16,
        "{:?}",
        answers.iter().map(|a| a.0).collect::<Vec<_>>()
    );
    assert!(served >= 4, "{served} served");
    for (status, head, body) in &answers {
        if *status == 503 {
            assert!(head.contains("Retry-After: "), "{head}");
        } else if head.contains("application/json") {
            let j: serde_json::Value = serde_json::from_str(body).unwrap();
            assert_eq!(j["impacts"].as_array().unwrap().len(), 10_000);
        } else {
            assert_eq!(body.lines().count(), 10_001);
        }
    }
    eprintln!("peak {peak:.0} MiB (before the exports {before:.0} MiB)");
    assert!(
        peak < 100.0,
        "peak {peak:.0} MiB (before the exports {before:.0} MiB)"
    );
}

/// A wide `--listen` keeps the Host check for its own names and asks for the token the URL
/// it prints carries (then a cookie, for the page's own requests); loopback needs none.
#[test]
fn a_wide_listen_keeps_the_host_check_and_asks_for_the_token() {
    let scratch = Scratch::new();
    let session = scratch.join_str("wide-session.log");
    let w = Watch::start(
        &["-", "--listen", "0.0.0.0:0", "--session", &session],
        Some(SCENE.to_string() + "\n"),
    );
    let port = w.port;
    // DNS rebinding: another name for this address.
    let (status, _, _) = w.request("/state.json", Some(&format!("attacker.example:{port}")), "");
    assert_eq!(status, 403);
    // An IP literal, without the token.
    let (status, _, _) = w.request("/state.json", None, "");
    assert_eq!(status, 403);
    let token = w.token.clone().expect("a token in the printed URL");
    assert!(token.len() >= 32, "{token}");
    let (status, head, page) = w.request(&format!("/?token={token}"), None, "");
    assert_eq!(status, 200);
    assert!(page.contains("<html"));
    let cookie = head
        .lines()
        .find_map(|l| l.strip_prefix("Set-Cookie: "))
        .expect("a cookie")
        .split(';')
        .next()
        .unwrap()
        .to_string();
    assert!(
        head.contains("HttpOnly") && head.contains("SameSite=Strict"),
        "{head}"
    );
    let (status, _, _) = w.request("/state.json", None, &format!("Cookie: {cookie}\r\n"));
    assert_eq!(status, 200);
    let (status, _, _) = w.request(
        "/state.json",
        Some(&format!("localhost:{port}")),
        &format!("Cookie: {cookie}\r\n"),
    );
    assert_eq!(status, 200);
    // The right cookie under a foreign name is still refused.
    let (status, _, _) = w.request(
        "/state.json",
        Some(&format!("attacker.example:{port}")),
        &format!("Cookie: {cookie}\r\n"),
    );
    assert_eq!(status, 403);
    let (status, _, _) = w.request("/state.json", None, "Cookie: impact_token=wrong\r\n");
    assert_eq!(status, 403);
}

/// 70 connections sending their request head a byte every 2 s: each is closed 10 s after it
/// was accepted, so the page answers again.
#[test]
fn request_heads_trickled_in_are_cut_at_their_deadline() {
    let scratch = Scratch::new();
    let session = scratch.join_str("trickle-session.log");
    let w = Watch::start(
        &["-", "--listen", "127.0.0.1:0", "--session", &session],
        Some(SCENE.to_string() + "\n"),
    );
    assert_eq!(w.get("/state.json").0, 200);
    let addr = format!("127.0.0.1:{}", w.port);
    let mut slow: Vec<TcpStream> = (0..70)
        .map(|_| TcpStream::connect(&addr).unwrap())
        .collect();
    let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let trickle = {
        let stop = stop.clone();
        std::thread::spawn(move || {
            let head = b"GET /state.json HTTP/1.1\r\nX-Slow: aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa";
            for k in 0.. {
                for s in &mut slow {
                    let _ = s.write_all(&[head[k % head.len()]]);
                }
                for _ in 0..20 {
                    if stop.load(std::sync::atomic::Ordering::Relaxed) {
                        return;
                    }
                    std::thread::sleep(Duration::from_millis(100));
                }
            }
        })
    };
    let t = Instant::now();
    std::thread::sleep(Duration::from_millis(500));
    let answered = loop {
        let mut s = TcpStream::connect(&addr).unwrap();
        s.set_read_timeout(Some(Duration::from_secs(2))).unwrap();
        let _ = write!(s, "GET /state.json HTTP/1.1\r\nHost: {addr}\r\n\r\n");
        let mut text = String::new();
        let _ = s.read_to_string(&mut text);
        if text.starts_with("HTTP/1.1 200") {
            break Some(t.elapsed());
        }
        if t.elapsed() > Duration::from_secs(16) {
            break None;
        }
        std::thread::sleep(Duration::from_millis(250));
    };
    stop.store(true, std::sync::atomic::Ordering::Relaxed);
    trickle.join().unwrap();
    let answered = answered.expect("the page never answered while the heads trickled in");
    assert!(answered < Duration::from_secs(13), "{answered:?}");
}
