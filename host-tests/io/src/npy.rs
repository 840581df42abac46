//! `.npy` arrays (`impact analyze FILE.npy --rate HZ`): numpy's format, read by `npyz`; a 1-D
//! array is the channel, a 2-D one (rows are samples, C or Fortran order) gives its channel
//! by `--column` (0-based). Little- or big-endian integers and floats.

use std::io::BufReader;
use std::path::Path;

use crate::channel::{check_rate, evenly_sampled, numbered_column};
use crate::channel::{Channel, ColumnRef, ReadOptions};
use crate::error::{NpyFault, Numbered, ReadError, ReadErrorKind};

/// True for a `.npy` file name (any case).
pub fn is_npy(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("npy"))
}

/// An array's elements as f64, in storage order, read as they are asked for (an error names
/// the element).
pub type Elements = Box<dyn Iterator<Item = Result<f64, NpyFault>> + Send>;

/// An .npy file opened: its elements (in storage order, whatever the numeric dtype), shape
/// and order.
pub fn open_elements(path: &Path) -> Result<(Elements, Vec<u64>, npyz::Order), ReadError> {
    fn boxed<T: npyz::Deserialize + Into<f64> + 'static>(
        r: npyz::NpyReader<T, BufReader<std::fs::File>>,
    ) -> Elements
    where
        npyz::NpyReader<T, BufReader<std::fs::File>>: Send,
    {
        Box::new(r.enumerate().map(|(element, v)| {
            v.map(Into::into)
                .map_err(|error| NpyFault::Element { element, error })
        }))
    }
    let mut f = std::fs::File::open(path).map_err(|e| ReadError::new(path, e))?;
    check_header(&mut f).map_err(|e| ReadError::new(path, e))?;
    let file = npyz::NpyFile::new(BufReader::new(f))
        .map_err(|e| ReadError::new(path, NpyFault::Header(e)))?;
    let shape = file.shape().to_vec();
    let order = file.order();
    let dtype = file.dtype();
    let file = match file.try_data::<f64>() {
        Ok(r) => return Ok((boxed(r), shape, order)),
        Err(f) => f,
    };
    let file = match file.try_data::<f32>() {
        Ok(r) => return Ok((boxed(r), shape, order)),
        Err(f) => f,
    };
    let file = match file.try_data::<i32>() {
        Ok(r) => return Ok((boxed(r), shape, order)),
        Err(f) => f,
    };
    let file = match file.try_data::<i16>() {
        Ok(r) => return Ok((boxed(r), shape, order)),
        Err(f) => f,
    };
    let file = match file.try_data::<u16>() {
        Ok(r) => return Ok((boxed(r), shape, order)),
        Err(f) => f,
    };
    let file = match file.try_data::<i8>() {
        Ok(r) => return Ok((boxed(r), shape, order)),
        Err(f) => f,
    };
    match file.try_data::<u8>() {
        Ok(r) => Ok((boxed(r), shape, order)),
        Err(_) => Err(ReadError::new(path, NpyFault::Dtype(dtype))),
    }
}

/// The largest header read, bytes: numpy's own reader refuses longer ones (`max_header_size`,
/// numpy 1.24 on) unless told to trust the file.
const MAX_HEADER: u64 = 10_000;

/// The deepest brackets a numeric array's header holds: its dict, and the shape tuple in it.
const MAX_NESTING: usize = 2;

/// Checks the header before `npyz` reads it, which allocates the length the prefix declares
/// (a 4 GiB one aborted the tool) and parses nested brackets in time doubling per level (20
/// levels in 130 bytes: a hang): the length against the file and numpy's limit, the nesting
/// against a numeric array's. Leaves `f` at its start. (A file too short for a prefix, or
/// with another magic or version, is left to `npyz` to refuse.)
fn check_header(f: &mut std::fs::File) -> Result<(), ReadErrorKind> {
    use std::io::{Read, Seek, SeekFrom};
    let len = f.metadata()?.len();
    let mut prefix = [0u8; 12];
    let mut got = 0;
    while got < prefix.len() {
        match f.read(&mut prefix[got..])? {
            0 => break,
            n => got += n,
        }
    }
    let declared = match (&prefix[..6] == b"\x93NUMPY", prefix[6], got) {
        (true, 1, 10..) => Some((u64::from(u16::from_le_bytes([prefix[8], prefix[9]])), 10)),
        (true, 2 | 3, 12) => Some((
            u64::from(u32::from_le_bytes([
                prefix[8], prefix[9], prefix[10], prefix[11],
            ])),
            12,
        )),
        _ => None,
    };
    if let Some((declared, start)) = declared {
        let available = len.saturating_sub(start);
        if declared > MAX_HEADER || declared > available {
            return Err(NpyFault::HeaderSize {
                declared,
                available,
                limit: MAX_HEADER,
            }
            .into());
        }
        f.seek(SeekFrom::Start(start))?;
        let mut header = Vec::new();
        f.by_ref().take(declared).read_to_end(&mut header)?;
        let depth = nesting(&header);
        if depth > MAX_NESTING {
            return Err(NpyFault::HeaderNesting { depth }.into());
        }
    }
    f.seek(SeekFrom::Start(0))?;
    Ok(())
}

/// The deepest nesting of `( [ {` in a header's text, outside its quoted strings (a
/// backslash inside one escapes the next byte, as Python reads it; a triple quote reads as
/// quotes that open and close, which can only count more brackets, never fewer).
fn nesting(header: &[u8]) -> usize {
    let (mut depth, mut deepest, mut quote) = (0usize, 0usize, None);
    let mut escaped = false;
    for &b in header {
        match (quote, b) {
            (Some(_), _) if escaped => escaped = false,
            (Some(_), b'\\') => escaped = true,
            (Some(q), _) if b == q => quote = None,
            (Some(_), _) => {}
            (None, b'\'' | b'"') => quote = Some(b),
            (None, b'(' | b'[' | b'{') => {
                depth += 1;
                deepest = deepest.max(depth);
            }
            (None, b')' | b']' | b'}') => depth = depth.saturating_sub(1),
            _ => {}
        }
    }
    deepest
}

/// Samples, channels and the chosen channel of an array of `shape`: 1-D, or 2-D samples ×
/// channels.
pub fn layout(
    shape: &[u64],
    column: Option<&ColumnRef>,
) -> Result<(u64, u64, usize), ReadErrorKind> {
    let (rows, cols) = match *shape {
        [n] => (n, 1),
        [n, c] => (n, c),
        _ => return Err(NpyFault::Shape(shape.to_vec()).into()),
    };
    let column = numbered_column(column, cols as usize, Numbered::ArrayColumns)?;
    Ok((rows, cols, column))
}

/// Reads the channel `opts.column` of a 1-D or 2-D array at `opts.rate_hz`.
pub fn read_npy(path: &Path, opts: &ReadOptions) -> Result<Channel, ReadError> {
    let err = |kind: ReadErrorKind| ReadError::new(path, kind);
    let Some(rate_hz) = opts.rate_hz else {
        return Err(err(ReadErrorKind::NpyNoTime));
    };
    check_rate(rate_hz).map_err(err)?;
    if opts.time_column.is_some() || opts.resample || !opts.axes.is_empty() {
        return Err(err(ReadErrorKind::NpyOptions));
    }
    let (elements, shape, order) = open_elements(path)?;
    let (rows, cols, column) = layout(&shape, opts.column.as_ref()).map_err(err)?;
    let (rows, cols) = (rows as usize, cols as usize);
    let all: Vec<f64> = elements
        .map(|e| e.map_err(|e| err(e.into())))
        .collect::<Result<_, _>>()?;
    if all.len() != rows * cols {
        return Err(err(NpyFault::ElementCount {
            elements: all.len(),
            shape,
        }
        .into()));
    }
    let at = |i: usize| match order {
        npyz::Order::C => all.get(i * cols + column),
        npyz::Order::Fortran => all.get(column * rows + i),
    };
    let mut values = Vec::with_capacity(rows);
    for i in 0..rows {
        match at(i).copied() {
            Some(v) if v.is_finite() => values.push(v),
            Some(value) => {
                return Err(err(NpyFault::NotFinite {
                    row: i as u64,
                    value,
                }
                .into()))
            }
            None => return Err(err(NpyFault::RowMissing { row: i }.into())),
        }
    }
    evenly_sampled(format!("column {column}"), values, rate_hz)
        .map_err(|e| err(NpyFault::Samples(e).into()))
}
