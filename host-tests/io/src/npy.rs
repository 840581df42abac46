//! `.npy` arrays (`impact analyze FILE.npy --rate HZ`): numpy's format, read by `npyz`; a 1-D
//! array is the channel, a 2-D one (rows are samples, C or Fortran order) gives its channel
//! by `--column` (0-based). Little- or big-endian integers and floats.

use std::io::BufReader;
use std::path::Path;

use crate::channel::{evenly_sampled, numbered_column, Channel, ColumnRef, ReadOptions};
use crate::channel::{one_line, RecordingError};
use crate::limits::RATE_HZ;

/// True for a `.npy` file name (any case).
pub fn is_npy(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("npy"))
}

/// An array's elements as f64, in storage order, read as they are asked for.
pub type Elements = Box<dyn Iterator<Item = Result<f64, String>> + Send>;

/// An .npy file opened: its elements (in storage order, whatever the numeric dtype), shape
/// and order.
pub fn open_elements(path: &Path) -> Result<(Elements, Vec<u64>, npyz::Order), String> {
    fn boxed<T: npyz::Deserialize + Into<f64> + 'static>(
        r: npyz::NpyReader<T, BufReader<std::fs::File>>,
    ) -> Elements
    where
        npyz::NpyReader<T, BufReader<std::fs::File>>: Send,
    {
        Box::new(r.enumerate().map(|(k, v)| {
            v.map(Into::into)
                .map_err(|e| format!("element {k}: {}", one_line(e)))
        }))
    }
    let f = std::fs::File::open(path).map_err(|e| e.to_string())?;
    let file =
        npyz::NpyFile::new(BufReader::new(f)).map_err(|e| format!("npy: {}", one_line(e)))?;
    let shape = file.shape().to_vec();
    let order = file.order();
    let dtype = file.dtype().descr();
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
        Err(_) => Err(format!(
            "npy: dtype {dtype}: not one of float64, float32, int32, int16, uint16, int8, uint8"
        )),
    }
}

/// Samples, channels and the chosen channel of an array of `shape`: 1-D, or 2-D samples ×
/// channels.
pub fn layout(shape: &[u64], column: Option<&ColumnRef>) -> Result<(u64, u64, usize), String> {
    let (rows, cols) = match *shape {
        [n] => (n, 1),
        [n, c] => (n, c),
        _ => {
            return Err(format!(
                "npy: shape {shape:?}; a 1-D array or 2-D (samples × channels)"
            ))
        }
    };
    let column = numbered_column(column, cols as usize, "the array's columns")?;
    Ok((rows, cols, column))
}

/// Reads the channel `opts.column` of a 1-D or 2-D array at `opts.rate_hz`.
pub fn read_npy(path: &Path, opts: &ReadOptions) -> Result<Channel, RecordingError> {
    let err = |message: String| RecordingError {
        file: path.to_path_buf(),
        line: None,
        message,
    };
    let Some(rate_hz) = opts.rate_hz else {
        return Err(err("an .npy array holds no time: give --rate".into()));
    };
    RATE_HZ.check_named("--rate", rate_hz).map_err(err)?;
    if opts.time_column.is_some() || opts.resample || !opts.axes.is_empty() {
        return Err(err(
            "an .npy array takes --rate and --column only (no --time-column, --resample, --axes)"
                .into(),
        ));
    }
    let (elements, shape, order) = open_elements(path).map_err(err)?;
    let (rows, cols, column) = layout(&shape, opts.column.as_ref()).map_err(err)?;
    let (rows, cols) = (rows as usize, cols as usize);
    let all: Vec<f64> = elements
        .map(|e| e.map_err(|e| err(format!("npy: {}", one_line(e)))))
        .collect::<Result<_, _>>()?;
    if all.len() != rows * cols {
        return Err(err(format!(
            "npy: {} elements for shape {shape:?}",
            all.len()
        )));
    }
    let at = |i: usize| match order {
        npyz::Order::C => all.get(i * cols + column),
        npyz::Order::Fortran => all.get(column * rows + i),
    };
    let mut values = Vec::with_capacity(rows);
    for i in 0..rows {
        match at(i).copied() {
            Some(v) if v.is_finite() => values.push(v),
            Some(v) => return Err(err(format!("npy: row {i}: {v} is not finite"))),
            None => return Err(err(format!("npy: row {i} missing"))),
        }
    }
    evenly_sampled(format!("column {column}"), values, rate_hz)
        .map_err(|e| err(format!("npy: {e}")))
}
