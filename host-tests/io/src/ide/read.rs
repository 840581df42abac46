//! An enDAQ `.ide` recording as the analysis reads it: the subchannel asked for (`--column
//! 8.1`, or its name), or two or three subchannels of one channel (`--axes 32.0,32.1,32.2`),
//! in its calibrated units, on the recorder's time stamps.

use std::io::Read;
use std::path::Path;
use std::sync::mpsc;

use super::{IdeError, IdeFile};
use crate::channel::{check_time, Channel, ColumnRef, ReadOptions};
use crate::error::{At, ReadError, ReadErrorKind};
use crate::recording::resample;
use crate::units::Units;

/// True for a `.ide` file name (any case), or a file that starts with an EBML header whose
/// DocType is `mide`.
pub fn is_ide(path: &Path) -> bool {
    if path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("ide"))
    {
        return true;
    }
    let mut head = [0u8; 64];
    // Only a regular file is sniffed (a pipe's bytes would be gone).
    let n = match std::fs::metadata(path) {
        Ok(m) if m.is_file() => std::fs::File::open(path)
            .and_then(|mut f| f.read(&mut head))
            .unwrap_or(0),
        _ => 0,
    };
    head[..n].starts_with(&[0x1A, 0x45, 0xDF, 0xA3]) && head[..n].windows(4).any(|w| w == b"mide")
}

/// The subchannels to read: one channel's, in their order, with their names (`8.1 Z (2000g)
/// [g]`).
pub struct Pick {
    pub channel: u64,
    pub subs: Vec<u64>,
    pub names: Vec<String>,
}

/// The units of a subchannel's calibrated values, or why it is no acceleration or force.
fn units_of(units: &str, name: &str) -> Result<Units, ReadErrorKind> {
    match units.trim() {
        "g" | "G" => Ok(Units::G),
        "m/s²" | "m/s^2" | "m/s2" | "m/s/s" => Ok(Units::MS2),
        "N" | "n" => Ok(Units::N),
        other => Err(ReadErrorKind::IdeNotAcceleration {
            subchannel: name.to_string(),
            units: other.to_string(),
        }),
    }
}

/// Resolves `--column` (or `--axes`) among the file's subchannels: `CH.SUB`, a subchannel's
/// name (any case), or a 0-based index over all subchannels in file order; by default the
/// first acceleration subchannel (a note names it when there are others).
pub fn pick<R: std::io::Read + std::io::Seek>(
    file: &IdeFile<R>,
    column: Option<&ColumnRef>,
    axes: &[ColumnRef],
) -> Result<Pick, ReadErrorKind> {
    let all: Vec<(u64, u64, String, String)> = file
        .channels()
        .iter()
        .filter(|c| c.unsupported.is_none())
        .flat_map(|c| {
            c.subchannels.iter().map(move |s| {
                (
                    c.id,
                    s.id,
                    format!("{}.{} {} [{}]", c.id, s.id, s.name, s.units),
                    s.units.clone(),
                )
            })
        })
        .collect();
    let listing = || -> Vec<String> { all.iter().map(|(_, _, n, _)| n.clone()).collect() };
    let find = |c: &ColumnRef| -> Result<usize, ReadErrorKind> {
        let found = match c {
            ColumnRef::Index(i) => (*i < all.len()).then_some(*i),
            ColumnRef::Name(n) => all.iter().position(|(ch, sub, name, _)| {
                *n == format!("{ch}.{sub}")
                    || name
                        .split_once(' ')
                        .is_some_and(|(_, rest)| rest.to_lowercase().starts_with(&n.to_lowercase()))
            }),
        };
        found.ok_or_else(|| ReadErrorKind::IdeNoSubchannel {
            column: c.clone(),
            subchannels: listing(),
        })
    };
    let chosen: Vec<usize> = if !axes.is_empty() {
        if !(2..=3).contains(&axes.len()) {
            return Err(ReadErrorKind::AxesCount {
                given: axes.len(),
                what: "subchannels",
            });
        }
        axes.iter().map(find).collect::<Result<_, _>>()?
    } else if let Some(c) = column {
        vec![find(c)?]
    } else {
        let accel: Vec<usize> = (0..all.len())
            .filter(|&i| units_of(&all[i].3, &all[i].2).is_ok_and(|u| u != Units::N))
            .collect();
        let first = *accel
            .first()
            .ok_or_else(|| ReadErrorKind::IdeNoAcceleration {
                subchannels: listing(),
            })?;
        if accel.len() > 1 {
            crate::note_read(crate::ReadNote::SubchannelChosen {
                subchannel: all[first].2.clone(),
                count: accel.len(),
                subchannels: listing(),
            });
        }
        vec![first]
    };
    let channel = all[chosen[0]].0;
    if chosen.iter().any(|&i| all[i].0 != channel) {
        return Err(ReadErrorKind::IdeAxesChannels);
    }
    for (k, &i) in chosen.iter().enumerate() {
        units_of(&all[i].3, &all[i].2)?;
        if chosen[..k].contains(&i) {
            return Err(ReadErrorKind::AxisTwice {
                what: "subchannel",
                name: all[i].2.clone(),
            });
        }
    }
    for &i in &chosen {
        for id in file.missing_calibrations(channel, all[i].1) {
            crate::note(&format!(
                "{}: its calibration {id} is not in the file's calibration list, so that \
                 polynomial is skipped (as enDAQ's idelib skips it) and its values may be \
                 uncalibrated though labelled [{}]: check their scale against a known level \
                 (1 g at rest)",
                all[i].2, all[i].3
            ));
        }
    }
    Ok(Pick {
        channel,
        subs: chosen.iter().map(|&i| all[i].1).collect(),
        names: chosen.iter().map(|&i| all[i].2.clone()).collect(),
    })
}

/// The channel (or the axes' resultant) of an `.ide` file with its time base, checked as a
/// CSV's time column is (every interval within 0.5–1.5× the median; `--resample` otherwise).
pub fn read_ide(path: &Path, opts: &ReadOptions) -> Result<Channel, ReadError> {
    let err = |kind: ReadErrorKind| ReadError::new(path, kind);
    let mut file = IdeFile::open(path).map_err(|e| err(e.into()))?;
    let pick = pick(&file, opts.column.as_ref(), &opts.axes).map_err(err)?;
    let series = file
        .read_channel_subs(pick.channel, &pick.subs)
        .map_err(|e| err(e.into()))?;
    let (times, mut columns) = (series.times, series.columns);
    if times.len() < 2 {
        return Err(err(ReadErrorKind::IdeTooFewSamples {
            subchannel: pick.names[0].clone(),
            samples: times.len(),
        }));
    }
    let at = |i: usize| At::Sample(i as u64);
    let (rate_hz, jitter) = match opts.rate_hz {
        Some(_) => return Err(err(ReadErrorKind::IdeRate)),
        None => check_time(path, &times, opts.resample, at)?,
    };
    let time_s = if opts.resample {
        let mut grid = Vec::new();
        for values in &mut columns {
            let (t, v) = resample(path, &times, values, rate_hz)?;
            *values = v;
            grid = t;
        }
        grid
    } else {
        times
    };
    let (name, values, axes) = if opts.axes.is_empty() {
        (pick.names[0].clone(), columns.remove(0), Vec::new())
    } else {
        let resultant = (0..time_s.len())
            .map(|k| {
                columns
                    .iter()
                    .map(|c| c.get(k).map_or(0.0, |v| v * v))
                    .sum::<f64>()
                    .sqrt()
            })
            .collect();
        (
            format!("|{}|", pick.names.join(",")),
            resultant,
            pick.names.into_iter().zip(columns).collect(),
        )
    };
    Ok(Channel {
        name,
        values,
        time_s,
        rate_hz,
        jitter: if opts.resample { 0.0 } else { jitter },
        resampled: opts.resample,
        axes,
        // The recorder's own time stamps.
        time_unit_assumed: None,
    })
}

/// One block: its samples' times (s) and values.
pub type Block = (Vec<f64>, Vec<f64>);

/// Blocks of one subchannel, read on a thread of their own and handed over a few at a time
/// (bounded memory): `(times_s, values)`, or the error that ended the reading.
pub struct Blocks {
    rx: mpsc::Receiver<Result<Block, IdeError>>,
}

impl Blocks {
    /// Starts reading subchannel `sub` of `channel`.
    pub fn start(path: &Path, channel: u64, sub: u64) -> Self {
        let (tx, rx) = mpsc::sync_channel(4);
        let path = path.to_path_buf();
        std::thread::spawn(move || {
            let result = IdeFile::open(&path).and_then(|mut f| {
                f.for_each_block(channel, &[sub], |t, cols| {
                    tx.send(Ok((t.to_vec(), cols[0].clone()))).is_ok()
                })
            });
            if let Err(e) = result {
                let _ = tx.send(Err(e));
            }
        });
        Self { rx }
    }

    /// The next block; `None` at the end.
    pub fn next_block(&mut self) -> Option<Result<Block, IdeError>> {
        self.rx.recv().ok()
    }
}
