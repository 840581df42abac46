//! A stream that cannot be read twice (standard input, a pipe) read once and replayed from
//! any byte not yet released, so the CSV readers can hand it over between them (the parallel
//! one and the sequential one) at a line, as they do a file they open again and seek.
//!
//! Memory: the bytes from the last release on, which the readers bound (the parallel reader's
//! chunks in flight, the sequential reader's buffers).

use std::collections::VecDeque;
use std::io::{self, Read};
use std::sync::{Arc, Mutex};

/// The stream and the bytes read from it that are not yet released.
pub struct Tape {
    /// The stream and a buffer to read it into: locked only to read more of it, so a reader
    /// waiting on the stream keeps no other from the bytes held (or from releasing them).
    source: Mutex<(Stream, Box<[u8]>)>,
    state: Mutex<State>,
}

type Stream = Box<dyn Read + Send>;

struct State {
    /// The stream's bytes from `start` on, up to the bytes read, in blocks of [`BLOCK`]
    /// (all full but the last): each block's room (zeroed once) and the bytes in it.
    blocks: VecDeque<(Box<[u8]>, usize)>,
    start: u64,
    held: u64,
    /// No reader goes back before this byte.
    released: u64,
    /// The stream's error, given again to any reader that reaches the byte it failed at.
    failed: Option<(io::ErrorKind, String)>,
    /// Whether the stream has ended (it is not read again: a terminal would wait).
    ended: bool,
    /// Released blocks, to read into again.
    spare: Vec<Box<[u8]>>,
}

/// Bytes a block holds, and the most read from the stream at a time (a pipe gives at most
/// its buffer, 64 KiB).
const BLOCK: usize = 1 << 16;

impl Tape {
    pub fn new(source: Box<dyn Read + Send>) -> Arc<Self> {
        Arc::new(Self {
            source: Mutex::new((source, vec![0; BLOCK].into_boxed_slice())),
            state: Mutex::new(State {
                blocks: VecDeque::new(),
                start: 0,
                held: 0,
                released: 0,
                failed: None,
                ended: false,
                spare: Vec::new(),
            }),
        })
    }

    /// A reader from the stream's byte `byte` on; an error if that byte was released.
    pub fn reader_at(self: &Arc<Self>, byte: u64) -> io::Result<TapeReader> {
        lock(&self.state)?.check(byte)?;
        Ok(TapeReader {
            tape: Arc::clone(self),
            at: byte,
            trail: None,
        })
    }

    /// The bytes held (read and not yet dropped).
    pub fn held(&self) -> u64 {
        self.state.lock().map_or(0, |s| s.held)
    }

    /// No reader will go back before `byte` any more: the blocks before it are dropped.
    pub fn release(&self, byte: u64) {
        let Ok(mut s) = self.state.lock() else { return };
        s.released = s.released.max(byte);
        while s.blocks.len() > 1 && s.start + BLOCK as u64 <= s.released {
            if let Some((block, _)) = s.blocks.pop_front() {
                if s.spare.len() < 4 {
                    s.spare.push(block);
                }
            }
            s.start += BLOCK as u64;
            s.held -= BLOCK as u64;
        }
    }

    /// Reads more of the stream onto the blocks unless it has been read past `at` meanwhile;
    /// false at its end.
    fn fill(&self, at: u64) -> io::Result<bool> {
        let mut source = lock(&self.source)?;
        {
            let s = lock(&self.state)?;
            if at < s.start + s.held {
                return Ok(true);
            }
            if let Some((kind, message)) = &s.failed {
                return Err(io::Error::new(*kind, message.clone()));
            }
            if s.ended {
                return Ok(false);
            }
        }
        let (stream, buf) = &mut *source;
        let read = loop {
            match stream.read(buf) {
                Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
                r => break r,
            }
        };
        let mut s = lock(&self.state)?;
        let n = match read {
            Ok(n) => n.min(buf.len()),
            Err(e) => {
                s.failed = Some((e.kind(), e.to_string()));
                return Err(e);
            }
        };
        // Onto the last block while it has room; the rest (all of it, when reads come a
        // block at a time) becomes the next block as it is, and a spare block is read into
        // next.
        let mut into_last = 0;
        if let Some((block, len)) = s.blocks.back_mut() {
            into_last = n.min(BLOCK - *len);
            block[*len..*len + into_last].copy_from_slice(&buf[..into_last]);
            *len += into_last;
        }
        let rest = n - into_last;
        if rest > 0 {
            buf.copy_within(into_last..n, 0);
            let fresh = s
                .spare
                .pop()
                .unwrap_or_else(|| vec![0; BLOCK].into_boxed_slice());
            s.blocks.push_back((std::mem::replace(buf, fresh), rest));
        }
        s.held += n as u64;
        s.ended |= n == 0;
        Ok(n > 0)
    }
}

/// Why a reader of the tape cannot read (inside the `io::Error` it gets).
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum TapeFault {
    #[error("a reader of the stream panicked")]
    Poisoned,
    /// The byte asked for was released (the tape holds it from `held_from` on).
    #[error("byte {byte} of the stream is no longer held (from {held_from} on)")]
    Released { byte: u64, held_from: u64 },
}

fn lock<T>(m: &Mutex<T>) -> io::Result<std::sync::MutexGuard<'_, T>> {
    m.lock().map_err(|_| io::Error::other(TapeFault::Poisoned))
}

impl State {
    fn check(&self, byte: u64) -> io::Result<()> {
        if byte < self.released {
            return Err(io::Error::other(TapeFault::Released {
                byte,
                held_from: self.released,
            }));
        }
        Ok(())
    }
}

/// One reader's place on a [`Tape`].
pub struct TapeReader {
    tape: Arc<Tape>,
    at: u64,
    /// Release the tape this far behind the place as it reads.
    trail: Option<u64>,
}

impl TapeReader {
    /// The reader releasing the tape `trail` bytes behind its place as it reads (for a
    /// reader that never hands over further back than that).
    pub fn releasing_behind(self, trail: u64) -> Self {
        Self {
            trail: Some(trail),
            ..self
        }
    }
}

impl Read for TapeReader {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        if buf.is_empty() {
            return Ok(0);
        }
        let end = {
            let s = lock(&self.tape.state)?;
            s.check(self.at)?;
            s.start + s.held
        };
        if self.at == end && !self.tape.fill(self.at)? {
            return Ok(0);
        }
        let s = lock(&self.tape.state)?;
        s.check(self.at)?;
        // Every block but the last is full.
        let offset = self.at - s.start;
        let (k, from) = (
            (offset / BLOCK as u64) as usize,
            (offset % BLOCK as u64) as usize,
        );
        let Some((block, len)) = s.blocks.get(k) else {
            return Ok(0);
        };
        let n = buf.len().min(len.saturating_sub(from));
        buf[..n].copy_from_slice(&block[from..from + n]);
        self.at += n as u64;
        drop(s);
        if let Some(trail) = self.trail {
            self.tape.release(self.at.saturating_sub(trail));
        }
        Ok(n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::mpsc::{channel, Receiver, Sender};
    use std::time::Duration;

    const B: u64 = BLOCK as u64;

    /// A source that gives `data` a few bytes at a time, then an error once if `fail`, then
    /// its end, and an error if read again past its end.
    struct Dribble {
        data: Vec<u8>,
        at: usize,
        fail: bool,
        ended: bool,
    }

    impl Read for Dribble {
        fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
            if self.at == self.data.len() {
                if std::mem::take(&mut self.fail) {
                    return Err(io::Error::other("the pipe broke"));
                }
                if self.ended {
                    return Err(io::Error::other("read again past its end"));
                }
                self.ended = true;
                return Ok(0);
            }
            let n = buf.len().min(7).min(self.data.len() - self.at);
            buf[..n].copy_from_slice(&self.data[self.at..self.at + n]);
            self.at += n;
            Ok(n)
        }
    }

    fn tape(n: usize, fail: bool) -> (Arc<Tape>, Vec<u8>) {
        let data: Vec<u8> = (0..n).map(|k| (k * 31 % 251) as u8).collect();
        let source = Dribble {
            data: data.clone(),
            at: 0,
            fail,
            ended: false,
        };
        (Tape::new(Box::new(source)), data)
    }

    fn read_from(t: &Arc<Tape>, byte: u64) -> io::Result<Vec<u8>> {
        let mut got = Vec::new();
        t.reader_at(byte)?.read_to_end(&mut got)?;
        Ok(got)
    }

    #[test]
    fn readers_replay_from_any_byte_not_released() {
        let (t, data) = tape(40 * BLOCK + 123, false);
        assert_eq!(read_from(&t, 0).unwrap(), data);
        // A second reader replays from the middle (and meets the end without reading the
        // stream past it again); the bytes before a release are gone.
        assert_eq!(read_from(&t, 1000).unwrap(), data[1000..]);
        t.release(2 * B + 5);
        assert!(t.reader_at(2 * B + 4).is_err());
        assert_eq!(read_from(&t, 2 * B + 5).unwrap(), data[2 * BLOCK + 5..]);
        // A reader left behind a release fails rather than read the wrong bytes.
        let mut behind = t.reader_at(2 * B + 5).unwrap();
        t.release(3 * B);
        // Only the blocks from the release on are held.
        assert_eq!(t.held(), 37 * B + 123);
        assert!(behind.read(&mut [0; 8]).is_err());
    }

    #[test]
    fn the_stream_error_is_given_again_where_it_happened() {
        // The stream fails once (then would end): every reader meets the same error there.
        let (t, data) = tape(100, true);
        let mut got = Vec::new();
        let e = t.reader_at(0).unwrap().read_to_end(&mut got).unwrap_err();
        assert_eq!(e.to_string(), "the pipe broke");
        assert_eq!(got, data);
        let mut again = Vec::new();
        let e = t
            .reader_at(50)
            .unwrap()
            .read_to_end(&mut again)
            .unwrap_err();
        assert_eq!(e.to_string(), "the pipe broke");
        assert_eq!(again, data[50..]);
    }

    /// A source that gives what is sent to it, saying when it starts to wait for it.
    struct Channel {
        sent: Receiver<Vec<u8>>,
        waiting: Sender<()>,
        left: Vec<u8>,
    }

    impl Read for Channel {
        fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
            if self.left.is_empty() {
                let _ = self.waiting.send(());
                match self.sent.recv() {
                    Ok(v) => self.left = v,
                    Err(_) => return Ok(0),
                }
            }
            let n = buf.len().min(self.left.len());
            buf[..n].copy_from_slice(&self.left[..n]);
            self.left.drain(..n);
            Ok(n)
        }
    }

    fn channel_tape() -> (Arc<Tape>, Sender<Vec<u8>>, Receiver<()>) {
        let (send, sent) = channel();
        let (waiting, waits) = channel();
        let source = Channel {
            sent,
            waiting,
            left: Vec::new(),
        };
        (Tape::new(Box::new(source)), send, waits)
    }

    #[test]
    fn a_reader_waiting_on_the_stream_keeps_no_one_from_the_bytes_held() {
        let (t, send, waits) = channel_tape();
        send.send(vec![1; 100]).unwrap();
        let mut buf = [0; 100];
        t.reader_at(0).unwrap().read_exact(&mut buf).unwrap();
        waits.recv().unwrap();
        // A reader at the end waits on the stream...
        let mut last = t.reader_at(100).unwrap();
        let waiting = std::thread::spawn(move || {
            let mut b = [0; 10];
            let n = last.read(&mut b).unwrap();
            (n, b)
        });
        waits.recv_timeout(Duration::from_secs(10)).unwrap();
        // ...while another replays the bytes held, and releases them.
        let (done, replayed) = channel();
        let other = Arc::clone(&t);
        std::thread::spawn(move || {
            let mut again = [0; 100];
            let r = other
                .reader_at(0)
                .and_then(|mut r| r.read_exact(&mut again));
            other.release(50);
            let _ = done.send(r.map(|_| again));
        });
        let again = replayed
            .recv_timeout(Duration::from_secs(10))
            .expect("the replay waited on the stream");
        assert_eq!(again.unwrap(), [1; 100]);
        send.send(vec![2; 10]).unwrap();
        assert_eq!(waiting.join().unwrap(), (10, [2; 10]));
    }

    #[test]
    fn released_blocks_are_read_into_again_and_a_trailing_reader_releases() {
        let (t, send, _waits) = channel_tape();
        let data: Vec<u8> = (0..20 * BLOCK).map(|k| (k * 7 % 253) as u8).collect();
        // In pieces that straddle the blocks.
        for piece in data[..10 * BLOCK].chunks(BLOCK / 3 + 5) {
            send.send(piece.to_vec()).unwrap();
        }
        let mut r = t.reader_at(0).unwrap().releasing_behind(2 * B);
        let mut got = vec![0; 10 * BLOCK];
        r.read_exact(&mut got).unwrap();
        assert_eq!(got, data[..10 * BLOCK]);
        // It held only the blocks within its trail (and the one being filled).
        assert!(t.held() <= 4 * B, "{}", t.held());
        // The blocks released are read into again: the later bytes come back right.
        for piece in data[10 * BLOCK..].chunks(BLOCK) {
            send.send(piece.to_vec()).unwrap();
        }
        drop(send);
        let mut rest = Vec::new();
        r.read_to_end(&mut rest).unwrap();
        assert_eq!(rest, data[10 * BLOCK..]);
        assert!(t.reader_at(8 * B).is_err());
        assert_eq!(read_from(&t, 20 * B - 10).unwrap(), data[20 * BLOCK - 10..]);
    }
}
