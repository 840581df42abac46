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
    state: Mutex<State>,
}

struct State {
    source: Box<dyn Read + Send>,
    /// The stream's bytes from `start` on, up to the bytes read, in blocks of [`BLOCK`]
    /// (all full but the last): each block's room (zeroed once) and the bytes in it.
    blocks: VecDeque<(Box<[u8]>, usize)>,
    start: u64,
    held: u64,
    /// No reader goes back before this byte.
    released: u64,
    /// The stream's error, given again to any reader that reaches the byte it failed at.
    failed: Option<(io::ErrorKind, String)>,
}

/// Bytes a block holds, and the most read from the stream at a time (a pipe gives at most
/// its buffer, 64 KiB).
const BLOCK: usize = 1 << 16;

impl Tape {
    pub fn new(source: Box<dyn Read + Send>) -> Arc<Self> {
        Arc::new(Self {
            state: Mutex::new(State {
                source,
                blocks: VecDeque::new(),
                start: 0,
                held: 0,
                released: 0,
                failed: None,
            }),
        })
    }

    /// A reader from the stream's byte `byte` on; an error if that byte was released.
    pub fn reader_at(self: &Arc<Self>, byte: u64) -> io::Result<TapeReader> {
        self.lock()?.check(byte)?;
        Ok(TapeReader {
            tape: Arc::clone(self),
            at: byte,
        })
    }

    /// No reader will go back before `byte` any more: the blocks before it are dropped.
    pub fn release(&self, byte: u64) {
        let Ok(mut s) = self.state.lock() else { return };
        s.released = s.released.max(byte);
        while s.blocks.len() > 1 && s.start + BLOCK as u64 <= s.released {
            s.blocks.pop_front();
            s.start += BLOCK as u64;
            s.held -= BLOCK as u64;
        }
    }

    fn lock(&self) -> io::Result<std::sync::MutexGuard<'_, State>> {
        self.state
            .lock()
            .map_err(|_| io::Error::other("a reader of the stream panicked"))
    }
}

impl State {
    fn check(&self, byte: u64) -> io::Result<()> {
        if byte < self.released {
            return Err(io::Error::other(format!(
                "byte {byte} of the stream is no longer held (from {} on)",
                self.released
            )));
        }
        Ok(())
    }

    /// Reads more of the stream onto the last block (a new one if it is full); the bytes
    /// read, 0 at its end.
    fn fill(&mut self) -> io::Result<usize> {
        if let Some((kind, message)) = &self.failed {
            return Err(io::Error::new(*kind, message.clone()));
        }
        if self.blocks.back().is_none_or(|&(_, len)| len == BLOCK) {
            self.blocks
                .push_back((vec![0; BLOCK].into_boxed_slice(), 0));
        }
        let Self { source, blocks, .. } = self;
        let Some((block, len)) = blocks.back_mut() else {
            return Ok(0);
        };
        let n = loop {
            match source.read(&mut block[*len..]) {
                Ok(n) => break n.min(BLOCK - *len),
                Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
                Err(e) => {
                    self.failed = Some((e.kind(), e.to_string()));
                    return Err(e);
                }
            }
        };
        *len += n;
        self.held += n as u64;
        Ok(n)
    }
}

/// One reader's place on a [`Tape`].
pub struct TapeReader {
    tape: Arc<Tape>,
    at: u64,
}

impl Read for TapeReader {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        if buf.is_empty() {
            return Ok(0);
        }
        let mut s = self.tape.lock()?;
        s.check(self.at)?;
        if self.at == s.start + s.held && s.fill()? == 0 {
            return Ok(0);
        }
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
        Ok(n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A source that gives `data` a few bytes at a time, then an error if `fail`.
    struct Dribble {
        data: Vec<u8>,
        at: usize,
        fail: bool,
    }

    impl Read for Dribble {
        fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
            if self.at == self.data.len() && self.fail {
                return Err(io::Error::other("the pipe broke"));
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
        };
        (Tape::new(Box::new(source)), data)
    }

    #[test]
    fn readers_replay_from_any_byte_not_released() {
        let (t, data) = tape(40 * BLOCK + 123, false);
        const B: u64 = BLOCK as u64;
        let mut first = Vec::new();
        t.reader_at(0).unwrap().read_to_end(&mut first).unwrap();
        assert_eq!(first, data);
        // A second reader replays from the middle; the bytes before a release are gone.
        let mut again = Vec::new();
        t.reader_at(1000).unwrap().read_to_end(&mut again).unwrap();
        assert_eq!(again, data[1000..]);
        t.release(2 * B + 5);
        assert!(t.reader_at(2 * B + 4).is_err());
        let mut tail = Vec::new();
        let mut r = t.reader_at(2 * B + 5).unwrap();
        r.read_to_end(&mut tail).unwrap();
        assert_eq!(tail, data[2 * BLOCK + 5..]);
        // A reader left behind a release fails rather than read the wrong bytes.
        let mut behind = t.reader_at(2 * B + 5).unwrap();
        t.release(3 * B);
        // Only the blocks from the release on are held.
        assert_eq!(t.state.lock().unwrap().held, 37 * B + 123);
        assert!(behind.read(&mut [0; 8]).is_err());
    }

    #[test]
    fn the_stream_error_is_given_again_where_it_happened() {
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
}
