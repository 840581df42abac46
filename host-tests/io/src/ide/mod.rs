//! Reader for enDAQ / Mide `.IDE` recordings (EBML, DocType "mide"), matching what the Python
//! reader `idelib` (3.4) returns from `EventArray.arraySlice()`:
//!
//! * times: each data block's start and end timecodes are unwrapped per channel (modulus
//!   rollover, as idelib's `fixOverflow`), scaled by the channel's `TimeCodeScale` to
//!   microseconds and truncated to whole microseconds; sample `i` of an `n`-sample block is at
//!   `start + i * (end - start) / (n - 1)`. Returned in seconds on the recorder's clock
//!   (the same zero as idelib, not shifted to the first sample).
//! * values: raw sample → channel polynomial → subchannel polynomial, folded into one linear
//!   map with idelib's algebra. A bivariate subchannel polynomial (e.g. a piezo channel
//!   compensated by temperature) is evaluated, like idelib by default (`useMean`), with the
//!   second variable set to the mean of the referenced subchannel over the whole recording.
//!
//! Anything else (named legacy parsers, higher-order polynomials, a bivariate polynomial on a
//! channel or referencing another bivariate channel, multi-sample blocks without an end
//! timecode) is an [`IdeError::Unsupported`], never a silently different number.

mod ebml;
mod header;
mod metadata;
mod read;

pub use crate::error::IdeError;
use crate::error::{IdeUnsupported, Malformation, NotIde, ReferenceProblem};
pub use header::{Channel, Recording, SubChannel};
pub use metadata::{Calibration, Recorder, Sensor};
pub use read::{is_ide, pick, read_ide, Blocks, Pick};
use std::fs::File;
use std::io::{BufReader, Read, Seek, SeekFrom};
use std::path::Path;

// Element IDs, from idelib's schemata/mide_ide.xml.
const EBML_HEADER: u32 = 0x1A45_DFA3;
const DOC_TYPE: u32 = 0x4282;
const CALIBRATION_LIST: u32 = 0x4B00;
const RECORDING_PROPERTIES: u32 = 0x1852_6570;
const TIME_BASE_UTC: u32 = 0x5462;
const TIME_BASE_UTC_FINE: u32 = 0x5463;
const SIMPLE_BLOCK: u32 = 0xA0;
const BLOCK: u32 = 0xA1;

/// Largest header element (calibration, recording properties) read into memory.
const MAX_HEADER_ELEMENT: u64 = 16 << 20;
/// Largest data block read into memory (devices write a few KiB).
const MAX_BLOCK: u64 = 64 << 20;
/// idelib's default timecode moduli: 2^24 for ChannelDataBlock, 2^16 for SimpleChannelDataBlock.
const MODULUS: u64 = 1 << 24;
const SIMPLE_MODULUS: u64 = 1 << 16;

/// A subchannel's calibration folded to `value = raw * c0 + c1`, or the bivariate form
/// `raw * (d0*y + d1) + (d2*y + d3)` with `y` the referenced subchannel's mean.
enum Resolved {
    Linear(f64, f64),
    Bivariate([f64; 4], u64, u64),
}

/// Samples of one channel: times in seconds and one column per requested subchannel.
#[derive(Debug, Clone, Default)]
pub struct Series {
    pub times: Vec<f64>,
    pub columns: Vec<Vec<f64>>,
}

/// Per-channel timecode unwrapping, exactly as idelib's `SimpleChannelDataBlockParser.fixOverflow`.
struct Clock {
    modulus: u64,
    tick_us: f64,
    offset: u64,
    last: u64,
}

impl Clock {
    fn fix(&mut self, mut ts: u64, at: u64) -> Result<f64, IdeError> {
        if ts > self.modulus {
            self.offset = ts - ts % self.modulus; // a non-modulo timecode
            ts %= self.modulus;
        } else if ts < self.last {
            self.offset = self
                .offset
                .checked_add(self.modulus)
                .ok_or(IdeError::Malformed {
                    offset: at,
                    what: Malformation::TimecodeOverflow,
                })?;
        }
        self.last = ts;
        let total = ts.checked_add(self.offset).ok_or(IdeError::Malformed {
            offset: at,
            what: Malformation::TimecodeOverflow,
        })?;
        Ok((total as f64 * self.tick_us).trunc()) // idelib: int(ticks * µs/tick)
    }
}

/// An open IDE recording. Opening reads only the header elements; samples are streamed
/// block by block from the source on each read.
pub struct IdeFile<R> {
    src: R,
    len: u64,
    data_start: u64,
    info: Recording,
}

impl IdeFile<BufReader<File>> {
    pub fn open(path: impl AsRef<Path>) -> Result<Self, IdeError> {
        Self::new(BufReader::new(File::open(path)?))
    }
}

impl<R: Read + Seek> IdeFile<R> {
    /// Reads the EBML header and the recording's header elements (calibration, channels),
    /// up to the first data block, as idelib's `openFile()` does.
    pub fn new(mut src: R) -> Result<Self, IdeError> {
        let len = src.seek(SeekFrom::End(0))?;
        let mut f = IdeFile {
            src,
            len,
            data_start: len,
            info: Recording::default(),
        };
        let first = match ebml::read_header(&mut f.src, 0) {
            Ok(Some(h)) if h.id == EBML_HEADER => h,
            Ok(None) => return Err(IdeError::NotIde(NotIde::Empty)),
            Ok(Some(_)) | Err(IdeError::Malformed { .. }) | Err(IdeError::Truncated { .. }) => {
                return Err(IdeError::NotIde(NotIde::NoEbmlHeader))
            }
            Err(e) => return Err(e),
        };
        let body = f.read_body(&first, MAX_HEADER_ELEMENT)?;
        for child in ebml::children(&body, first.body) {
            let (id, b, _) = child?;
            if id == DOC_TYPE && ebml::string(b) != "mide" {
                return Err(IdeError::NotIde(NotIde::DocType(ebml::string(b))));
            }
        }
        let mut pos = f.end_of(&first)?;
        while let Some(h) = ebml::read_header(&mut f.src, pos)? {
            match h.id {
                BLOCK | SIMPLE_BLOCK => {
                    f.data_start = pos;
                    break;
                }
                CALIBRATION_LIST => {
                    let body = f.read_body(&h, MAX_HEADER_ELEMENT)?;
                    f.info.parse_calibration(&body, h.body)?;
                }
                RECORDING_PROPERTIES => {
                    let body = f.read_body(&h, MAX_HEADER_ELEMENT)?;
                    f.info.parse_properties(&body, h.body)?;
                }
                TIME_BASE_UTC => {
                    f.info.utc_start = Some(ebml::uint(&f.read_body(&h, 8)?, h.body)? as f64)
                }
                TIME_BASE_UTC_FINE => {
                    f.info.utc_start = Some(ebml::float(&f.read_body(&h, 8)?, h.body)?)
                }
                _ => {}
            }
            pos = f.end_of(&h)?;
        }
        if f.info.channels.is_empty() {
            return Err(IdeError::Unsupported(IdeUnsupported::NoChannelList));
        }
        Ok(f)
    }

    /// Recorder info, channels and calibration, as read from the header.
    pub fn info(&self) -> &Recording {
        &self.info
    }

    /// The calibration ids that `channel`'s subchannel `sub` (or the channel itself) names but
    /// the file's CalibrationList lacks: those values are read uncalibrated, as idelib reads
    /// them.
    ///
    /// A bivariate calibration's reference subchannel counts too (its mean enters the values).
    pub fn missing_calibrations(&self, channel: u64, sub: u64) -> Vec<u64> {
        let own = |channel: u64, sub: u64| -> Vec<Option<u64>> {
            let Some(ch) = self.info.channels.iter().find(|c| c.id == channel) else {
                return Vec::new();
            };
            let sc = ch.subchannels.iter().find(|s| s.id == sub);
            vec![ch.cal, sc.and_then(|s| s.cal)]
        };
        let mut ids = own(channel, sub);
        let reference = ids
            .last()
            .copied()
            .flatten()
            .and_then(|id| self.info.cals.get(&id))
            .and_then(|p| p.second);
        if let Some((_, rc, rs)) = reference {
            ids.extend(own(rc, rs));
        }
        let mut missing: Vec<u64> = ids
            .into_iter()
            .flatten()
            .filter(|id| !self.info.cals.contains_key(id))
            .collect();
        missing.dedup();
        missing
    }

    pub fn channels(&self) -> &[Channel] {
        &self.info.channels
    }

    pub fn channel(&self, id: u64) -> Option<&Channel> {
        self.info.channels.iter().find(|c| c.id == id)
    }

    /// The sensor `channel`'s subchannel `sub` measures with, if the file names it.
    pub fn sensor_of(&self, channel: u64, sub: u64) -> Option<&Sensor> {
        let id = self
            .channel(channel)?
            .subchannels
            .iter()
            .find(|s| s.id == sub)?
            .sensor?;
        self.info.sensors.iter().find(|s| s.id == id)
    }

    /// All subchannels of a channel, calibrated, with their times.
    pub fn read_channel(&mut self, channel: u64) -> Result<Series, IdeError> {
        let ch = self
            .channel(channel)
            .ok_or(IdeError::NoSuchChannel { channel })?;
        let subs: Vec<u64> = ch.subchannels.iter().map(|s| s.id).collect();
        let mut out = Series {
            times: Vec::new(),
            columns: vec![Vec::new(); subs.len()],
        };
        self.for_each_block(channel, &subs, |t, cols| {
            out.times.extend_from_slice(t);
            out.columns
                .iter_mut()
                .zip(cols)
                .for_each(|(o, c)| o.extend_from_slice(c));
            true
        })?;
        Ok(out)
    }

    /// Some subchannels of a channel, calibrated, with their times.
    pub fn read_channel_subs(&mut self, channel: u64, subs: &[u64]) -> Result<Series, IdeError> {
        let mut out = Series {
            times: Vec::new(),
            columns: vec![Vec::new(); subs.len()],
        };
        self.for_each_block(channel, subs, |t, cols| {
            out.times.extend_from_slice(t);
            out.columns
                .iter_mut()
                .zip(cols)
                .for_each(|(o, c)| o.extend_from_slice(c));
            true
        })?;
        Ok(out)
    }

    /// One subchannel, calibrated: (times in seconds, values).
    pub fn read_subchannel(
        &mut self,
        channel: u64,
        subchannel: u64,
    ) -> Result<(Vec<f64>, Vec<f64>), IdeError> {
        let (mut times, mut values) = (Vec::new(), Vec::new());
        self.for_each_block(channel, &[subchannel], |t, cols| {
            times.extend_from_slice(t);
            values.extend_from_slice(&cols[0]);
            true
        })?;
        Ok((times, values))
    }

    /// Streams a channel block by block in file order: `f(times_s, columns)` gets one column per
    /// entry of `subchannels` (calibrated) and returns `false` to stop early. Memory is one block.
    pub fn for_each_block<F>(
        &mut self,
        channel: u64,
        subchannels: &[u64],
        mut f: F,
    ) -> Result<(), IdeError>
    where
        F: FnMut(&[f64], &[Vec<f64>]) -> bool,
    {
        let ch = self
            .channel(channel)
            .ok_or(IdeError::NoSuchChannel { channel })?
            .clone();
        usable(&ch)?;
        let mut maps = Vec::with_capacity(subchannels.len());
        for &s in subchannels {
            let sc =
                ch.subchannels
                    .iter()
                    .find(|x| x.id == s)
                    .ok_or(IdeError::NoSuchSubchannel {
                        channel,
                        subchannel: s,
                    })?;
            let field = *ch.fields.get(s as usize).ok_or_else(|| {
                IdeError::Unsupported(IdeUnsupported::NoField {
                    channel,
                    subchannel: s,
                    format: ch.format.clone(),
                })
            })?;
            let (c0, c1) = match self.resolve(&ch, sc)? {
                Resolved::Linear(c0, c1) => (c0, c1),
                Resolved::Bivariate(d, rc, rs) => {
                    let y = self.mean_of(rc, rs, (channel, s))?;
                    (d[0] * y + d[1], d[2] * y + d[3])
                }
            };
            maps.push((field, c0, c1));
        }
        let (mut times, mut cols) = (Vec::new(), vec![Vec::new(); maps.len()]);
        self.scan(&ch, &mut |start, end, n, payload, _| {
            times.clear();
            let period = if n > 1 {
                (end - start) / (n as f64 - 1.0)
            } else {
                end - start
            };
            times.extend((0..n).map(|i| (i as f64 * period + start) / 1e6));
            for ((field, c0, c1), col) in maps.iter().zip(cols.iter_mut()) {
                col.clear();
                for rec in payload.chunks_exact(ch.record) {
                    let raw = field
                        .decode(rec)
                        .ok_or(IdeError::Unsupported(IdeUnsupported::FieldOutsideRecord))?;
                    col.push(raw * c0 + c1);
                }
            }
            Ok(f(&times, &cols))
        })
    }

    /// Folds channel and subchannel polynomials as idelib's `CombinedPoly` does.
    fn resolve(&self, ch: &Channel, sc: &SubChannel) -> Result<Resolved, IdeError> {
        // A calibration ID missing from the CalibrationList means no calibration (idelib).
        let b = match ch
            .cal
            .and_then(|id| self.info.cals.get(&id).map(|p| (id, p)))
        {
            None => (1.0, 0.0),
            Some((id, p)) => p.finite(id)?.linear(id).map_err(|_| {
                IdeError::Unsupported(IdeUnsupported::ChannelCalibration { id, channel: ch.id })
            })?,
        };
        let Some((id, p)) = sc
            .cal
            .and_then(|id| self.info.cals.get(&id).map(|p| (id, p)))
        else {
            return Ok(Resolved::Linear(b.0, 0.0 + b.1));
        };
        let p = p.finite(id)?;
        let folded = |values: &[f64]| -> Result<(), IdeError> {
            if values.iter().all(|v| v.is_finite()) {
                Ok(())
            } else {
                Err(IdeError::Malformed {
                    offset: p.at,
                    what: Malformation::CalibrationNotFinite { id },
                })
            }
        };
        let Some((ref2, rc, rs)) = p.second else {
            let a = p.linear(id)?;
            let (gain, offset) = (a.0 * b.0, a.1 + a.0 * b.1);
            folded(&[gain, offset])?;
            return Ok(Resolved::Linear(gain, offset));
        };
        let &[c0, c1, c2, c3] = p.coeffs.as_slice() else {
            return Err(IdeError::Unsupported(
                IdeUnsupported::BivariateCoefficients {
                    id,
                    channel: ch.id,
                    subchannel: sc.id,
                    coefficients: p.coeffs.len(),
                },
            ));
        };
        let r = p.reference;
        let a = [
            c0,
            c1 - c0 * ref2,
            c2 - c0 * r,
            c3 + c0 * r * ref2 - c1 * r - c2 * ref2,
        ];
        let d = [
            a[0] * b.0 * 1.0,
            a[0] * b.0 * 0.0 + a[1] * b.0,
            a[0] * b.1 * 1.0 + a[2] * 1.0,
            a[0] * b.1 * 0.0 + a[1] * b.1 + a[2] * 0.0 + a[3],
        ];
        folded(&d)?;
        Ok(Resolved::Bivariate(d, rc, rs))
    }

    /// Mean of a calibrated subchannel over the recording, as idelib's `EventArray.getMean()`:
    /// block means (the block's stored ChannelDataMinMeanMax when present), calibrated,
    /// averaged with the blocks' sample counts as weights.
    fn mean_of(&mut self, channel: u64, sub: u64, user: (u64, u64)) -> Result<f64, IdeError> {
        let fault = |problem| {
            IdeError::Unsupported(IdeUnsupported::Reference {
                user,
                channel,
                subchannel: sub,
                problem,
            })
        };
        let ch = self
            .channel(channel)
            .cloned()
            .ok_or(fault(ReferenceProblem::NotDefined))?;
        let sc = ch
            .subchannels
            .iter()
            .find(|s| s.id == sub)
            .ok_or(fault(ReferenceProblem::NotDefined))?;
        let field = *ch
            .fields
            .get(sub as usize)
            .ok_or(fault(ReferenceProblem::NoSampleField))?;
        let Resolved::Linear(c0, c1) = self.resolve(&ch, sc)? else {
            return Err(fault(ReferenceProblem::Bivariate));
        };
        let (mut sum, mut count) = (0.0, 0.0);
        self.scan(&ch, &mut |_, _, n, payload, mmm| {
            let stored = mmm
                .filter(|m| m.len() == 3 * ch.record && n > 1)
                .and_then(|m| field.decode(&m[ch.record..]));
            let mean = match stored {
                Some(m) => m,
                None => {
                    payload
                        .chunks_exact(ch.record)
                        .filter_map(|r| field.decode(r))
                        .sum::<f64>()
                        / n as f64
                }
            };
            sum += (mean * c0 + c1) * n as f64;
            count += n as f64;
            Ok(true)
        })?;
        if count == 0.0 {
            return Err(fault(ReferenceProblem::NoSamples));
        }
        Ok(sum / count)
    }

    /// Visits the data blocks of one channel: (start µs, end µs, samples, payload, min/mean/max).
    #[allow(clippy::type_complexity)]
    fn scan(
        &mut self,
        ch: &Channel,
        visit: &mut dyn FnMut(f64, f64, usize, &[u8], Option<&[u8]>) -> Result<bool, IdeError>,
    ) -> Result<(), IdeError> {
        usable(ch)?;
        let mut clock = Clock {
            modulus: ch.modulus.unwrap_or(MODULUS),
            tick_us: ch.tick_us,
            offset: 0,
            last: 0,
        };
        let mut simple_clock = Clock {
            modulus: ch.modulus.unwrap_or(SIMPLE_MODULUS),
            ..clock
        };
        let (mut pos, mut buf) = (self.data_start, Vec::new());
        while let Some(h) = ebml::read_header(&mut self.src, pos)? {
            let next = self.end_of(&h)?;
            if h.id == BLOCK || h.id == SIMPLE_BLOCK {
                self.read_body_into(&h, MAX_BLOCK, &mut buf)?;
                let (id, start, end, payload, mmm) = parse_block(&h, &buf)?;
                if id == ch.id {
                    let has_end = end.is_some();
                    let (start, end) = if h.id == BLOCK {
                        (
                            clock.fix(start, h.offset)?,
                            clock.fix(end.unwrap_or(start), h.offset)?,
                        )
                    } else {
                        let t = simple_clock.fix(start, h.offset)?;
                        (t, t)
                    };
                    if payload.len() % ch.record != 0 {
                        return Err(IdeError::Malformed {
                            offset: h.offset,
                            what: Malformation::PartialSample {
                                channel: ch.id,
                                payload: payload.len(),
                                record: ch.record,
                            },
                        });
                    }
                    let n = payload.len() / ch.record;
                    if n > 1 && !has_end {
                        return Err(IdeError::Unsupported(
                            IdeUnsupported::MultiSampleWithoutEnd {
                                channel: ch.id,
                                offset: h.offset,
                            },
                        ));
                    }
                    if n > 0 && !visit(start, end, n, payload, mmm)? {
                        return Ok(());
                    }
                }
            }
            pos = next;
        }
        Ok(())
    }

    fn end_of(&self, h: &ebml::Header) -> Result<u64, IdeError> {
        h.body
            .checked_add(h.size)
            .filter(|&e| e <= self.len)
            .ok_or(IdeError::Truncated { offset: h.offset })
    }

    fn read_body(&mut self, h: &ebml::Header, max: u64) -> Result<Vec<u8>, IdeError> {
        let mut buf = Vec::new();
        self.read_body_into(h, max, &mut buf)?;
        Ok(buf)
    }

    /// Reads an element's body, after checking its size against `max` and the file's length.
    fn read_body_into(
        &mut self,
        h: &ebml::Header,
        max: u64,
        buf: &mut Vec<u8>,
    ) -> Result<(), IdeError> {
        self.end_of(h)?;
        if h.size > max {
            return Err(IdeError::TooLarge {
                offset: h.offset,
                size: h.size,
            });
        }
        buf.clear();
        buf.resize(h.size as usize, 0);
        self.src.seek(SeekFrom::Start(h.body))?;
        self.src.read_exact(buf).map_err(|e| match e.kind() {
            std::io::ErrorKind::UnexpectedEof => IdeError::Truncated { offset: h.offset },
            _ => IdeError::Io(e),
        })
    }
}

fn usable(ch: &Channel) -> Result<(), IdeError> {
    match &ch.unsupported {
        None => Ok(()),
        Some(problem) => Err(IdeError::Unsupported(IdeUnsupported::Channel {
            channel: ch.id,
            name: ch.name.clone(),
            problem: problem.clone(),
        })),
    }
}

/// Splits a data block: (channel, start timecode, end timecode, payload, min/mean/max).
#[allow(clippy::type_complexity)]
fn parse_block<'a>(
    h: &ebml::Header,
    body: &'a [u8],
) -> Result<(u64, u64, Option<u64>, &'a [u8], Option<&'a [u8]>), IdeError> {
    if h.id == SIMPLE_BLOCK {
        // 2-byte big-endian modulo timecode, 1-byte channel ID, then the samples.
        return match body {
            [t0, t1, c, payload @ ..] => Ok((
                *c as u64,
                u16::from_be_bytes([*t0, *t1]) as u64,
                None,
                payload,
                None,
            )),
            _ => Err(IdeError::Malformed {
                offset: h.offset,
                what: Malformation::ShortSimpleBlock,
            }),
        };
    }
    let (mut ch, mut start, mut end, mut payload, mut mmm) = (None, None, None, None, None);
    for c in ebml::children(body, h.body) {
        let (id, v, o) = c?;
        match id {
            0xB0 => ch = Some(ebml::uint(v, o)?),
            0xB2 => payload = Some(v),
            0xB8 | 0xBA => start = Some(ebml::uint(v, o)?),
            0xB9 | 0xBB => end = Some(ebml::uint(v, o)?),
            0xBC => mmm = Some(v),
            _ => {}
        }
    }
    let missing = |what: &'static str| IdeError::Malformed {
        offset: h.offset,
        what: Malformation::BlockWithout(what),
    };
    Ok((
        ch.ok_or_else(|| missing("ChannelIDRef"))?,
        start.ok_or_else(|| missing("a start timecode"))?,
        end,
        payload.unwrap_or(&[]),
        mmm,
    ))
}
