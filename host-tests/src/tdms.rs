//! NI TDMS files (`impact analyze FILE.tdms`), read by the `tdms-rs` crate: one channel, named
//! `group/channel` or `channel` (or a 0-based index over the file's channels in order), at the
//! rate of its waveform properties (`wf_increment`) or `--rate`. Numeric channels of any
//! integer or float type; DAQmx raw (scaled) data is what the crate reads, and it is not
//! checked against NI's own files here.

use std::path::Path;

use tdms_rs::{DataType, PropertyValue, TdmsChannel, TdmsFile};

use crate::recording::{Channel, ReadOptions};
use crate::table::{ColumnRef, RecordingError};

/// True for a `.tdms` file name (any case).
pub fn is_tdms(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("tdms"))
}

/// Every value of `ch` as f64.
fn values(ch: &TdmsChannel) -> Result<Vec<f64>, String> {
    fn read<T: tdms_rs::api::reader::Pod + Default + Into<f64>>(
        ch: &TdmsChannel,
    ) -> Result<Vec<f64>, String> {
        let mut out = vec![T::default(); ch.len()];
        ch.read(0..ch.len(), &mut out).map_err(|e| e.to_string())?;
        Ok(out.into_iter().map(Into::into).collect())
    }
    match ch.dtype() {
        DataType::Double => read::<f64>(ch),
        DataType::Float => read::<f32>(ch),
        DataType::I8 => read::<i8>(ch),
        DataType::I16 => read::<i16>(ch),
        DataType::I32 => read::<i32>(ch),
        DataType::U8 => read::<u8>(ch),
        DataType::U16 => read::<u16>(ch),
        DataType::U32 => read::<u32>(ch),
        other => Err(format!("channel type {other:?} is not a number this reads")),
    }
}

/// Reads the channel `opts.column` [default: the first one].
pub fn read_tdms(path: &Path, opts: &ReadOptions) -> Result<Channel, RecordingError> {
    let err = |message: String| RecordingError {
        file: path.to_path_buf(),
        line: None,
        message,
    };
    if opts.time_column.is_some() || opts.resample || !opts.axes.is_empty() {
        return Err(err(
            "a TDMS file takes --column (group/channel) and --rate only".into(),
        ));
    }
    let file = TdmsFile::open(path).map_err(|e| err(format!("TDMS: {e}")))?;
    let all: Vec<(String, TdmsChannel)> = file
        .groups()
        .flat_map(|g| {
            let group = g.name().to_string();
            g.channels()
                .map(move |c| (format!("{group}/{}", c.name()), c))
                .collect::<Vec<_>>()
        })
        .collect();
    let names = || {
        all.iter()
            .map(|(n, _)| n.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    };
    let found = match &opts.column {
        None => all.first(),
        Some(ColumnRef::Index(i)) => all.get(*i),
        Some(ColumnRef::Name(n)) => all
            .iter()
            .find(|(full, c)| full == n || c.name() == n.as_str()),
    };
    let Some((name, ch)) = found else {
        return Err(err(format!(
            "no such channel{}; the file has: {}",
            opts.column.as_ref().map_or(String::new(), |c| match c {
                ColumnRef::Index(i) => format!(" {i}"),
                ColumnRef::Name(n) => format!(" {n}"),
            }),
            names()
        )));
    };
    let increment = match ch.property("wf_increment") {
        Some(PropertyValue::Double(d)) if d.is_finite() && *d > 0.0 => Some(*d),
        _ => None,
    };
    let rate_hz = match (opts.rate_hz, increment) {
        (Some(r), _) => r,
        (None, Some(dt)) => 1.0 / dt,
        (None, None) => {
            return Err(err(format!(
                "{name} has no wf_increment property: give --rate"
            )))
        }
    };
    if !(rate_hz.is_finite() && rate_hz > 0.0 && rate_hz <= 1e9) {
        return Err(err(format!("rate {rate_hz} Hz is not in (0, 1e9]")));
    }
    let values = values(ch).map_err(|e| err(format!("TDMS {name}: {e}")))?;
    if let Some(k) = values.iter().position(|v| !v.is_finite()) {
        return Err(err(format!("TDMS {name}: value {k} is not finite")));
    }
    if values.len() < 2 {
        return Err(err(format!(
            "TDMS {name}: {} values; at least 2",
            values.len()
        )));
    }
    let time_s = (0..values.len()).map(|k| k as f64 / rate_hz).collect();
    Ok(Channel {
        name: name.clone(),
        values,
        time_s,
        rate_hz,
        jitter: 0.0,
        resampled: false,
        axes: Vec::new(),
    })
}
