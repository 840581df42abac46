//! `read`: a recording's channel as the tool reads it (the same readers, options and unit
//! rules as `impact analyze`), its samples handed to NumPy without a copy, and an enDAQ
//! `.IDE`'s own recorder and channels.

use impact_io::ide::IdeFile;
use numpy::{IntoPyArray, PyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::ReadError;

/// The recording `argv[0]` read with `impact analyze`'s reading options (`--column`,
/// `--axes`, `--rate`, `--units`…): its samples in the file's units, their times, rate,
/// channel and units, the factor to m/s², what the tool assumed, and the file's own metadata.
#[pyfunction]
pub fn read<'py>(py: Python<'py>, argv: Vec<String>) -> PyResult<Bound<'py, PyDict>> {
    let cmd = super::analyze::parse(argv)?;
    let args = cmd.args;
    let (read, notes) = py.detach(|| {
        super::analyze::with_notes(|| -> PyResult<_> {
            let ch = impact_io::read_recording(
                &args.file,
                &args.read_options(impact_io::progress::Progress::none()),
            )
            .map_err(|e| {
                ReadError::new_err(impact_host::read_errors::ReadFailure::from(e).to_string())
            })?;
            let file = impact_host::pipeline::scene_file(&args)
                .map_err(|e| crate::UsageError::new_err(e.to_string()))?;
            let column = ch
                .axes
                .first()
                .map_or(ch.name.as_str(), |(n, _)| n.as_str());
            let (mass, scale, units, assumed) =
                impact_host::pipeline::mass_and_scale(&args, &file, column)
                    .map_err(|e| crate::UsageError::new_err(e.to_string()))?;
            // A force reads as an acceleration only over a known mass.
            let known = units != impact_host::pipeline::Units::N || mass.is_some();
            let mut assumptions: Vec<String> = assumed.iter().map(|a| a.text()).collect();
            if let Some(t) = &ch.time_unit_assumed {
                assumptions.push(impact_host::pipeline::assumed_time_unit(t).text());
            }
            let metadata = ide_metadata(&args.file);
            Ok((ch, units, known.then_some(scale), assumptions, metadata))
        })
    });
    let read = read?;
    let (ch, units, to_m_s2, assumptions, metadata) = read;
    let d = PyDict::new(py);
    d.set_item("column", &ch.name)?;
    d.set_item("units", units.name())?;
    d.set_item("to_m_s2", to_m_s2)?;
    d.set_item("rate_hz", ch.rate_hz)?;
    d.set_item("jitter", ch.jitter)?;
    d.set_item("resampled", ch.resampled)?;
    d.set_item("assumptions", assumptions)?;
    d.set_item("notes", notes)?;
    d.set_item("metadata_json", metadata)?;
    let axes: Vec<(String, Bound<'py, PyArray1<f64>>)> = ch
        .axes
        .into_iter()
        .map(|(name, v)| (name, v.into_pyarray(py)))
        .collect();
    d.set_item("axes", axes)?;
    d.set_item("samples", ch.values.into_pyarray(py))?;
    d.set_item("time_s", ch.time_s.into_pyarray(py))?;
    Ok(d)
}

/// An `.IDE` recording's own account as JSON text: its recorder, sensors, factory
/// calibration, session start and channels (each subchannel with its sensor); none for another
/// format, or a header that cannot be read (the read itself says why).
fn ide_metadata(path: &std::path::Path) -> Option<String> {
    if !impact_io::ide::is_ide(path) {
        return None;
    }
    let file = IdeFile::open(path).ok()?;
    let info = file.info();
    let r = &info.recorder;
    let channels: Vec<serde_json::Value> = info
        .channels
        .iter()
        .map(|c| {
            serde_json::json!({
                "id": c.id,
                "name": c.name,
                "subchannels": c.subchannels.iter().map(|s| serde_json::json!({
                    "id": s.id, "name": s.name, "label": s.label, "units": s.units,
                    "sensor": file.sensor_of(c.id, s.id).map(|x| &x.name),
                })).collect::<Vec<_>>(),
            })
        })
        .collect();
    let json = serde_json::json!({
        "recorder": {
            "product_name": r.product_name,
            "part_number": r.part_number,
            "serial": r.serial,
            "user_name": r.user_name,
            "hardware_revision": r.hardware_revision,
            "firmware": r.firmware,
            "manufactured_unix_s": r.manufactured_unix_s,
        },
        "sensors": info.sensors.iter().map(|x| serde_json::json!({
            "id": x.id, "name": x.name, "serial": x.serial,
        })).collect::<Vec<_>>(),
        "calibration": {
            "date_unix_s": info.calibration.date_unix_s,
            "expiry_unix_s": info.calibration.expiry_unix_s,
            "serial": info.calibration.serial,
        },
        "utc_start_s": info.utc_start,
        "channels": channels,
    });
    Some(json.to_string())
}
