//! Minimal EBML (RFC 8794) reading for `.IDE` files: element headers from a seekable stream
//! or from an in-memory body, and the scalar value decoders. No allocation is sized by a
//! declared length before that length has been checked against what is really there.

use super::IdeError;
use crate::error::{IdeUnsupported, Malformation};
use std::io::{ErrorKind, Read, Seek, SeekFrom};

/// An element's header: its ID (marker bits kept, as schemas write them), the declared body
/// size, and the absolute offsets of the header and of the body.
#[derive(Debug, Clone, Copy)]
pub struct Header {
    pub id: u32,
    pub size: u64,
    pub offset: u64,
    pub body: u64,
}

/// Length in bytes of a variable-size integer, from its first byte (0 for the invalid 0x00).
fn vint_len(first: u8) -> usize {
    if first == 0 {
        0
    } else {
        first.leading_zeros() as usize + 1
    }
}

/// Decodes an ID (1–4 bytes, marker kept) or a size (1–8 bytes, marker removed; `None` for
/// the reserved "unknown size" of all ones) from `buf`, which starts at absolute `offset`.
/// Returns the value and the bytes used.
fn vint(buf: &[u8], offset: u64, is_id: bool) -> Result<(Option<u64>, usize), IdeError> {
    let first = *buf.first().ok_or(IdeError::Truncated { offset })?;
    let len = vint_len(first);
    if len == 0 || (is_id && len > 4) {
        let what = if is_id { "element ID" } else { "element size" };
        return Err(IdeError::Malformed {
            offset,
            what: Malformation::Vint { what, byte: first },
        });
    }
    let bytes = buf.get(..len).ok_or(IdeError::Truncated { offset })?;
    let mut v = if is_id {
        first as u64
    } else {
        (first as u64) & (0xFF >> len)
    };
    for &b in &bytes[1..] {
        v = (v << 8) | b as u64;
    }
    let all_ones = !is_id && v == (1u64 << (7 * len)) - 1;
    Ok((if all_ones { None } else { Some(v) }, len))
}

/// Parses an element header at the start of `buf` (absolute `offset`): (id, size, header length).
fn header_in(buf: &[u8], offset: u64) -> Result<(u32, u64, usize), IdeError> {
    let (id, il) = vint(buf, offset, true)?;
    let (size, sl) = vint(buf.get(il..).unwrap_or(&[]), offset + il as u64, false)?;
    let id = id.unwrap_or(0) as u32; // IDs never decode to None (is_id)
    let size = size.ok_or(IdeError::Unsupported(IdeUnsupported::UnknownSize {
        id,
        offset,
    }))?;
    Ok((id, size, il + sl))
}

/// Reads the header of the element at `offset` in the stream; `Ok(None)` at a clean end of file.
pub fn read_header<R: Read + Seek>(src: &mut R, offset: u64) -> Result<Option<Header>, IdeError> {
    src.seek(SeekFrom::Start(offset))?;
    let mut buf = [0u8; 12];
    let mut got = 0;
    while got < buf.len() {
        match src.read(&mut buf[got..]) {
            Ok(0) => break,
            Ok(n) => got += n,
            Err(e) if e.kind() == ErrorKind::Interrupted => {}
            Err(e) => return Err(e.into()),
        }
    }
    if got == 0 {
        return Ok(None);
    }
    let (id, size, hl) = header_in(&buf[..got], offset)?;
    Ok(Some(Header {
        id,
        size,
        offset,
        body: offset + hl as u64,
    }))
}

/// Iterates over the child elements inside an in-memory master element body.
/// Yields (id, body, absolute offset of the child); a child overrunning its parent is an error.
pub struct Children<'a> {
    buf: &'a [u8],
    pos: usize,
    base: u64,
}

pub fn children(buf: &[u8], base: u64) -> Children<'_> {
    Children { buf, pos: 0, base }
}

impl<'a> Iterator for Children<'a> {
    type Item = Result<(u32, &'a [u8], u64), IdeError>;
    fn next(&mut self) -> Option<Self::Item> {
        let rest = self.buf.get(self.pos..).filter(|r| !r.is_empty())?;
        let offset = self.base + self.pos as u64;
        let item = header_in(rest, offset).and_then(|(id, size, hl)| {
            let end = usize::try_from(size).ok().and_then(|s| s.checked_add(hl));
            match end.and_then(|e| rest.get(hl..e)) {
                Some(body) => Ok((id, body, offset, hl + body.len())),
                None => Err(IdeError::Truncated { offset }),
            }
        });
        match item {
            Ok((id, body, offset, used)) => {
                self.pos += used;
                Some(Ok((id, body, offset)))
            }
            Err(e) => {
                self.pos = self.buf.len(); // stop after the first error
                Some(Err(e))
            }
        }
    }
}

/// Unsigned integer element (0–8 bytes, big-endian).
pub fn uint(b: &[u8], offset: u64) -> Result<u64, IdeError> {
    if b.len() > 8 {
        return Err(IdeError::Malformed {
            offset,
            what: Malformation::UintLength(b.len()),
        });
    }
    Ok(b.iter().fold(0u64, |v, &x| (v << 8) | x as u64))
}

/// Float element (0, 4 or 8 bytes, big-endian).
pub fn float(b: &[u8], offset: u64) -> Result<f64, IdeError> {
    match b.len() {
        0 => Ok(0.0),
        4 => Ok(f32::from_be_bytes([b[0], b[1], b[2], b[3]]) as f64),
        8 => Ok(f64::from_be_bytes([
            b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7],
        ])),
        n => Err(IdeError::Malformed {
            offset,
            what: Malformation::FloatLength(n),
        }),
    }
}

/// String or UTF-8 element, cut at the first NUL (as ebmlite does), invalid UTF-8 replaced.
pub fn string(b: &[u8]) -> String {
    let end = b.iter().position(|&c| c == 0).unwrap_or(b.len());
    String::from_utf8_lossy(&b[..end]).into_owned()
}
