//! The parallel fast path of a CSV file's or stream's data rows: 1 MiB chunks cut at line ends,
//! parsed on worker threads and handed on in order. It takes plain rows only (numbers and
//! delimiters with white space around them, no quotes, no blank lines, the table's number of
//! fields); at the first line it cannot take plainly it stops, and the sequential reader
//! ([`crate::table::Rows::resume`]) goes on from that line, so every error and edge case
//! reads as in one pass.

use std::collections::BTreeMap;
use std::io::Read;
use std::sync::mpsc::{sync_channel, Receiver};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;

use crate::table::{is_reading, read_number, MAX_LINE_BYTES};
use crate::tape::Tape;

/// Bytes a chunk holds (up to the last line end in them).
const CHUNK: usize = 1 << 20;

/// Rows the sequential reader takes (after a line the fast path could not take, and at the
/// start of a whole table) before the fast path goes on.
pub const SEQUENTIAL_ROWS: usize = 4096;

/// Which fields a row has and which of them are wanted; the time column's unit (s) and the
/// head's median interval, which every interval is checked against.
#[derive(Clone, Copy, Debug)]
pub struct Layout {
    pub columns: usize,
    pub channel: usize,
    pub time: Option<usize>,
    pub delimiter: u8,
    pub decimal_comma: bool,
    pub time_unit_s: f64,
    /// Check that each row's time follows the previous one's...
    pub increasing: bool,
    /// ...by this median interval within [`crate::channel::INTERVAL_RANGE`] (if given).
    pub median_dt: Option<f64>,
    /// Keep every field of every row too ([`Parsed::fields`]), for a whole table.
    pub all: bool,
}

impl Layout {
    /// Field `k`'s value `x`: into `row` (channel value, time) if wanted, and onto `fields`
    /// when every field is kept.
    #[inline]
    fn keep(&self, k: usize, x: f64, row: &mut (f64, f64), fields: &mut Vec<f64>) {
        if k == self.channel {
            row.0 = x;
        }
        if Some(k) == self.time {
            row.1 = x;
        }
        if self.all {
            fields.push(x);
        }
    }
}

/// One chunk's rows, in order, one a line (a chunk with a blank line stops there).
pub struct Parsed {
    /// The chunk's first line and byte.
    pub line: u64,
    pub byte: u64,
    /// Per row: the channel's value and the time column's (0 without one).
    pub rows: Vec<(f64, f64)>,
    /// With [`Layout::all`]: every row's fields, one row after the other.
    pub fields: Vec<f64>,
    /// Where plain rows stopped, if they did: the file's byte and the line to resume at.
    pub stop: Option<(u64, u64)>,
}

/// A chunk for a worker: its order, the file's byte it starts at, its bytes (`None`: a line
/// longer than the sequential reader accepts, or a read error, starts here).
struct Job {
    seq: u64,
    byte: u64,
    bytes: Option<Vec<u8>>,
}

/// The chunks of a file from a byte and line on, parsed ahead by worker threads (a few
/// chunks in flight, so memory stays bounded).
pub struct FastRows {
    results: Option<Receiver<(u64, Parsed)>>,
    pending: BTreeMap<u64, Parsed>,
    next: u64,
    /// The next chunk's first line.
    line: u64,
    threads: Vec<JoinHandle<()>>,
    tape: Option<Arc<Tape>>,
}

impl FastRows {
    /// Starts reading `input`, at byte `byte` of the file or stream (the start of line
    /// `line`); `progress` gets the fraction of `size` read. With a stream's `tape`, each
    /// chunk's start is released as it is handed on (the sequential reader may resume there
    /// or later, never before).
    pub fn start(
        mut input: Box<dyn Read + Send>,
        (byte, line): (u64, u64),
        layout: Layout,
        progress: Option<(crate::progress::Progress, u64)>,
        tape: Option<Arc<Tape>>,
    ) -> Self {
        let workers = std::thread::available_parallelism().map_or(2, |n| n.get().clamp(1, 4));
        let (job_tx, job_rx) = sync_channel::<Job>(2 * workers);
        let (result_tx, result_rx) = sync_channel::<(u64, Parsed)>(2 * workers);
        let jobs = Arc::new(Mutex::new(job_rx));
        let mut threads = Vec::new();
        for _ in 0..workers {
            let (jobs, results) = (Arc::clone(&jobs), result_tx.clone());
            threads.push(std::thread::spawn(move || loop {
                let job = match jobs.lock() {
                    Ok(rx) => rx.recv(),
                    Err(_) => return,
                };
                let Ok(job) = job else { return };
                let seq = job.seq;
                if results.send((seq, parse(job, &layout))).is_err() {
                    return;
                }
            }));
        }
        threads.push(std::thread::spawn(move || {
            let (mut byte, mut seq) = (byte, 0u64);
            let mut carry = Vec::new();
            let mut next_progress = 0u64;
            loop {
                let mut buf = std::mem::take(&mut carry);
                buf.reserve(CHUNK);
                // Appended without zeroing the room first.
                let n = loop {
                    match (&mut input).take(CHUNK as u64).read_to_end(&mut buf) {
                        Ok(n) => break Some(n),
                        Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
                        // The sequential reader meets the error again and reports it.
                        Err(_) => break None,
                    }
                };
                let job = |bytes| Job { seq, byte, bytes };
                let Some(n) = n else {
                    let _ = job_tx.send(job(None));
                    return;
                };
                let eof = n == 0;
                let cut = match buf.iter().rposition(|&b| b == b'\n') {
                    Some(p) => p + 1,
                    None if eof => buf.len(),
                    None if buf.len() > MAX_LINE_BYTES => {
                        let _ = job_tx.send(job(None));
                        return;
                    }
                    None => {
                        carry = buf;
                        continue;
                    }
                };
                if cut == 0 {
                    return;
                }
                carry = buf.split_off(cut);
                if job_tx.send(job(Some(buf))).is_err() {
                    return;
                }
                (byte, seq) = (byte + cut as u64, seq + 1);
                if let Some((p, size)) = &progress {
                    if byte >= next_progress {
                        p.report(byte as f64 / (*size).max(1) as f64);
                        next_progress = byte + (size / 20).max(1);
                    }
                }
                if eof && carry.is_empty() {
                    return;
                }
            }
        }));
        Self {
            results: Some(result_rx),
            pending: BTreeMap::new(),
            next: 0,
            line,
            threads,
            tape,
        }
    }

    /// The next chunk, in order; `None` at the end of the file.
    pub fn next_chunk(&mut self) -> Option<Parsed> {
        loop {
            if let Some(mut p) = self.pending.remove(&self.next) {
                // Workers number lines from their chunk's start.
                p.line = self.line;
                if let Some((_, line)) = &mut p.stop {
                    *line += self.line;
                }
                self.line += p.rows.len() as u64;
                self.next += 1;
                if let Some(tape) = &self.tape {
                    tape.release(p.byte);
                }
                return Some(p);
            }
            let (seq, parsed) = self.results.as_ref()?.recv().ok()?;
            self.pending.insert(seq, parsed);
        }
    }
}

impl Drop for FastRows {
    fn drop(&mut self) {
        // Closing the results ends the workers' sends, and with them the reader's. A stream's
        // reader may be waiting on the stream for its next chunk: it is left to end when that
        // read returns, so a hand-over to the sequential reader (which goes on with the bytes
        // the tape holds) does not wait for more of the stream. A file's is joined.
        self.results = None;
        self.pending.clear();
        if self.tape.is_some() {
            self.threads.clear();
        }
        for t in self.threads.drain(..) {
            let _ = t.join();
        }
    }
}

/// A chunk's plain rows, up to the first line that is not one or whose time does not follow
/// the previous row's by about the median interval (the chunk's first row is left to the
/// caller, which knows the row before it).
fn parse(job: Job, layout: &Layout) -> Parsed {
    let Some(bytes) = job.bytes else {
        return Parsed {
            line: 0,
            byte: job.byte,
            rows: Vec::new(),
            fields: Vec::new(),
            stop: Some((job.byte, 0)),
        };
    };
    // The one-pass scanner, where the delimiter cannot be part of a number.
    let scan =
        !layout.decimal_comma && !matches!(layout.delimiter, b'0'..=b'9' | b'.' | b'+' | b'-');
    let mut rows = Vec::with_capacity(bytes.len() / 16);
    let mut fields = Vec::new();
    let (mut at, mut line) = (0usize, 0u64);
    let mut last_t: Option<f64> = None;
    while at < bytes.len() {
        let kept = fields.len();
        let (row, next) = match scan
            .then(|| scan_row(&bytes, at, layout, &mut fields))
            .flatten()
        {
            Some((row, next)) => (Some(row), next),
            None => {
                fields.truncate(kept);
                let end = bytes[at..]
                    .iter()
                    .position(|&b| b == b'\n')
                    .map_or(bytes.len(), |p| at + p);
                (plain_row(&bytes[at..end], layout, &mut fields), end + 1)
            }
        };
        match row.filter(|&(_, t)| follows(t, &mut last_t, layout)) {
            Some(row) => rows.push(row),
            None => {
                fields.truncate(kept);
                return Parsed {
                    line: 0,
                    byte: job.byte,
                    rows,
                    fields,
                    stop: Some((job.byte + at as u64, line)),
                };
            }
        }
        (at, line) = (next, line + 1);
    }
    Parsed {
        line: 0,
        byte: job.byte,
        rows,
        fields,
        stop: None,
    }
}

/// Whether a row's time `time` follows the chunk's previous one (`last`) as the sequential
/// checks want it to; keeps it in `last`.
fn follows(time: f64, last: &mut Option<f64>, layout: &Layout) -> bool {
    if layout.time.is_none() || !layout.increasing {
        return true;
    }
    let t = time * layout.time_unit_s;
    let ok = last.is_none_or(|l| {
        t > l
            && layout
                .median_dt
                .is_none_or(|m| crate::time_axis::check_interval(t - l, m).is_ok())
    });
    *last = Some(t);
    ok
}

/// One plain row from `bytes[at..]` in one pass: fields of digits with at most one point and
/// 15 digits (an optional sign), delimiters between them, `\n` or `\r\n` (or the chunk's
/// end) after them. The row's channel value and time, and where the next row starts; `None`
/// for anything else ([`plain_row`] decides).
#[inline]
fn scan_row(
    bytes: &[u8],
    at: usize,
    layout: &Layout,
    fields: &mut Vec<f64>,
) -> Option<((f64, f64), usize)> {
    let mut row = (0.0, 0.0);
    let (mut p, mut k) = (at, 0usize);
    loop {
        let negative = match bytes.get(p) {
            Some(b'-') => {
                p += 1;
                true
            }
            Some(b'+') => {
                p += 1;
                false
            }
            _ => false,
        };
        // Digits, a point, digits: each run in a loop of its own.
        let mut m = 0u64;
        let whole = p;
        while let Some(&b) = bytes.get(p).filter(|b| b.is_ascii_digit()) {
            m = m.wrapping_mul(10).wrapping_add(u64::from(b - b'0'));
            p += 1;
        }
        let mut count = p - whole;
        let mut fraction = 0;
        if bytes.get(p) == Some(&b'.') {
            p += 1;
            let from = p;
            while let Some(&b) = bytes.get(p).filter(|b| b.is_ascii_digit()) {
                m = m.wrapping_mul(10).wrapping_add(u64::from(b - b'0'));
                p += 1;
            }
            fraction = p - from;
            count += fraction;
        }
        let end = bytes.get(p).copied();
        if count == 0 || count > 15 {
            return None;
        }
        let x = m as f64 / EXACT_TENS.get(fraction).copied()?;
        layout.keep(k, if negative { -x } else { x }, &mut row, fields);
        k += 1;
        match end {
            Some(d) if d == layout.delimiter => p += 1,
            Some(b'\n') => {
                p += 1;
                break;
            }
            Some(b'\r') if bytes.get(p + 1) == Some(&b'\n') => {
                p += 2;
                break;
            }
            None => break,
            Some(_) => return None,
        }
    }
    (k == layout.columns).then_some((row, p))
}

/// The channel's value and the time (0 without a time column) of a plain row: every field a
/// number the sequential reader accepts, as many as the table's rows have, no quote. Fields
/// split as the sequential reader splits them ([`crate::table::Rows::next_row`]): where tabs
/// delimit or no delimiter splits the line, white space inside a field separates fields and
/// an empty last field is none (an empty first one is left to the sequential reader, which
/// refuses it under a header that names that column).
fn plain_row(text: &[u8], layout: &Layout, fields: &mut Vec<f64>) -> Option<(f64, f64)> {
    let (mut row, mut count) = ((0.0, 0.0), 0usize);
    let mut scratch = Vec::new();
    let n = text.split(|&b| b == layout.delimiter).count();
    let split = layout.delimiter == b'\t' || n == 1;
    for (i, field) in text.split(|&b| b == layout.delimiter).enumerate() {
        let field = field.trim_ascii();
        if field.first() == Some(&b'"') {
            return None;
        }
        if split && n > 1 && field.is_empty() {
            if i + 1 == n {
                continue;
            }
            return None;
        }
        let inside = split && field.iter().any(|&b| b == b' ' || b == b'\t');
        let parts = field
            .split(|&b| inside && (b == b' ' || b == b'\t'))
            .filter(|p| !inside || !p.is_empty());
        for part in parts {
            let x = read_number(part, layout.decimal_comma, &mut scratch)?;
            if !is_reading(x) {
                return None;
            }
            layout.keep(count, x, &mut row, fields);
            count += 1;
        }
    }
    (count == layout.columns).then_some(row)
}

/// Powers of ten that `f64` holds exactly.
const EXACT_TENS: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

#[cfg(test)]
mod tests {
    use super::*;

    /// Two comma-separated columns, the value in the second (`time`: the time column),
    /// nothing checked.
    fn two_columns(time: Option<usize>) -> Layout {
        Layout {
            columns: 2,
            channel: 1,
            time,
            delimiter: b',',
            decimal_comma: false,
            time_unit_s: 1.0,
            increasing: false,
            median_dt: None,
            all: false,
        }
    }

    /// A stream that gives what is sent to it, waiting for more until the sender is gone.
    struct Channel(std::sync::mpsc::Receiver<Vec<u8>>, Vec<u8>);

    impl Read for Channel {
        fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
            if self.1.is_empty() {
                match self.0.recv() {
                    Ok(v) => self.1 = v,
                    Err(_) => return Ok(0),
                }
            }
            let n = buf.len().min(self.1.len());
            buf[..n].copy_from_slice(&self.1[..n]);
            self.1.drain(..n);
            Ok(n)
        }
    }

    #[test]
    fn a_stop_on_a_stream_does_not_wait_for_more_of_it() {
        // A chunk and a bit of a stream, a quoted row in the first chunk; the stream then
        // waits for more.
        let (send, sent) = std::sync::mpsc::channel();
        let tape = Tape::new(Box::new(Channel(sent, Vec::new())));
        let mut text = "0,1\n".repeat(1000);
        let stop_byte = text.len() as u64;
        text.push_str("\"1\",2\n");
        text.push_str(&"2,3\n".repeat(CHUNK / 4));
        send.send(text.into_bytes()).unwrap();
        let layout = two_columns(None);
        let input = Box::new(tape.reader_at(0).unwrap());
        let mut fast = FastRows::start(input, (0, 1), layout, None, Some(Arc::clone(&tape)));
        let chunk = fast.next_chunk().unwrap();
        assert_eq!(chunk.rows.len(), 1000);
        assert_eq!(chunk.stop, Some((stop_byte, 1001)));
        // The reader waits on the stream for its next chunk: dropping it does not.
        let (done, dropped) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            drop(fast);
            let _ = done.send(());
        });
        dropped
            .recv_timeout(std::time::Duration::from_secs(10))
            .expect("the hand-over waited for more of the stream");
        // The sequential reader takes the stream from the quoted row.
        let mut row = [0u8; 6];
        tape.reader_at(stop_byte)
            .unwrap()
            .read_exact(&mut row)
            .unwrap();
        assert_eq!(&row, b"\"1\",2\n");
        drop(send);
    }

    #[test]
    fn plain_decimals_read_as_the_general_parser_reads_them() {
        let mut fields: Vec<String> = [
            "0",
            "-0",
            "-0.0",
            "+1.5",
            "7.",
            ".25",
            "-.5",
            "123456789012345",
            "0.000000000000001",
            "99999.9999999999",
            "1.7976931348623157",
            "3.14159265358979",
            "0.1",
            "0.3",
            "-2.675",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        for _ in 0..200_000 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let digits = (state % 15 + 1) as usize;
            let mantissa = state >> 8;
            let s = format!("{mantissa}");
            let s = &s[..digits.min(s.len())];
            let at = (state >> 4) as usize % (s.len() + 1);
            let sign = if state & 1 == 1 { "-" } else { "" };
            fields.push(format!("{sign}{}.{}", &s[..at], &s[at..]));
        }
        let layout = two_columns(Some(0));
        let mut out = Vec::new();
        let mut taken = 0;
        for pair in fields.chunks(2) {
            let text = format!("{},{}\n", pair[0], pair[pair.len() - 1]);
            let general = plain_row(text.trim_end().as_bytes(), &layout, &mut out);
            if let Some((row, next)) = scan_row(text.as_bytes(), 0, &layout, &mut out) {
                assert_eq!(Some(row), general, "{text}");
                assert_eq!(next, text.len());
                taken += 1;
            }
        }
        assert!(taken > 90_000);
        // What it leaves to the general reader.
        for f in [
            "1e5,1",
            ",1",
            "-,1",
            ".,1",
            "1.2.3,1",
            "nan,1",
            "1234567890123456,1",
            " 1,1",
            "1,2,3",
            "1",
            "1;2",
            "1,2 ",
        ] {
            assert_eq!(scan_row(f.as_bytes(), 0, &layout, &mut out), None, "{f}");
        }
        // `\r\n` and a chunk's last line without a line end.
        assert_eq!(
            scan_row(b"1,2\r\n3,4", 0, &layout, &mut out),
            Some(((2.0, 1.0), 5))
        );
        assert_eq!(
            scan_row(b"1,2\r\n3,4", 5, &layout, &mut out),
            Some(((4.0, 3.0), 8))
        );
    }
}
