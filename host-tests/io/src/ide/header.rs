//! The header of an IDE recording: recorder info, channels and subchannels (sample formats,
//! timecode scales) and calibration polynomials, from the `CalibrationList` and
//! `RecordingProperties` elements (IDs from idelib's schemata/mide_ide.xml).

use super::metadata::{self, Calibration, Recorder, Sensor};
use super::{ebml, IdeError};
use crate::error::{ChannelProblem, IdeUnsupported, Malformation};
use std::collections::HashMap;

const UNIVARIATE: u32 = 0x4B01;
const BIVARIATE: u32 = 0x4B02;
const RECORDER_INFO: u32 = 0x5210;
const SENSOR_LIST: u32 = 0x5240;
const CHANNEL_LIST: u32 = 0x5270;
const CHANNEL: u32 = 0x5271;
const SUBCHANNEL: u32 = 0x52A0;
/// idelib's default timecode scale: 32768 ticks per second.
const DEFAULT_TICK_US: f64 = 1_000_000.0 / 32768.0;

/// What the header elements of a recording say.
#[derive(Debug, Clone, Default)]
pub struct Recording {
    /// The recorder (`RecorderInfo`).
    pub recorder: Recorder,
    /// Its sensors (`SensorList`), in the file's order.
    pub sensors: Vec<Sensor>,
    /// The factory calibration's date, expiry and number (`CalibrationList`).
    pub calibration: Calibration,
    /// Session start, Unix seconds (TimeBaseUTC / TimeBaseUTCFine), if recorded.
    pub utc_start: Option<f64>,
    pub channels: Vec<Channel>,
    pub(super) cals: HashMap<u64, Poly>,
}

impl Recording {
    pub(super) fn parse_calibration(&mut self, body: &[u8], base: u64) -> Result<(), IdeError> {
        for child in ebml::children(body, base) {
            let (kind, b, at) = child?;
            if self.calibration.read(kind, b, at) || (kind != UNIVARIATE && kind != BIVARIATE) {
                continue;
            }
            let (mut id, mut p) = (
                None,
                Poly {
                    coeffs: Vec::new(),
                    reference: 0.0,
                    second: None,
                    at,
                },
            );
            let (mut ref2, mut ch2, mut sub2) = (0.0, None, None);
            for c in ebml::children(b, at) {
                let (cid, v, o) = c?;
                match cid {
                    0x4B03 => id = Some(ebml::uint(v, o)?),
                    0x4B04 => p.reference = ebml::float(v, o)?,
                    0x4B05 => ref2 = ebml::float(v, o)?,
                    0x4B06 => ch2 = Some(ebml::uint(v, o)?),
                    0x4B07 => sub2 = Some(ebml::uint(v, o)?),
                    0x4B08 => p.coeffs.push(ebml::float(v, o)?),
                    _ => {}
                }
            }
            let id = id.ok_or(IdeError::Malformed {
                offset: at,
                what: Malformation::CalibrationWithoutId,
            })?;
            if kind == BIVARIATE {
                match (ch2, sub2) {
                    (Some(c), Some(s)) => p.second = Some((ref2, c, s)),
                    _ => {
                        return Err(IdeError::Malformed {
                            offset: at,
                            what: Malformation::BivariateWithoutReference { id },
                        })
                    }
                }
            }
            self.cals.insert(id, p);
        }
        Ok(())
    }

    pub(super) fn parse_properties(&mut self, body: &[u8], base: u64) -> Result<(), IdeError> {
        for child in ebml::children(body, base) {
            let (id, b, at) = child?;
            if id == SENSOR_LIST {
                self.sensors = metadata::sensors(b, at);
                continue;
            }
            for c in ebml::children(b, at).filter(|_| id == RECORDER_INFO || id == CHANNEL_LIST) {
                let (cid, v, o) = c?;
                match (id, cid) {
                    (RECORDER_INFO, _) => self.recorder.read(cid, v, o),
                    (CHANNEL_LIST, CHANNEL) => {
                        let ch = parse_channel(v, o)?;
                        self.channels.retain(|c| c.id != ch.id);
                        self.channels.push(ch);
                    }
                    _ => {}
                }
            }
        }
        Ok(())
    }
}

/// One sample field of a channel's `ChannelFormat` (a Python struct format such as `<hhh`).
#[derive(Debug, Clone, Copy)]
pub(super) struct Field {
    code: u8,
    size: usize,
    big_endian: bool,
    offset: usize,
}

impl Field {
    pub(super) fn decode(&self, record: &[u8]) -> Option<f64> {
        let b = record.get(self.offset..self.offset + self.size)?;
        let mut a = [0u8; 8];
        if self.big_endian {
            a[8 - self.size..].copy_from_slice(b);
            a.reverse(); // now little-endian, zero-filled high bytes
        } else {
            a[..self.size].copy_from_slice(b);
        }
        let u = u64::from_le_bytes(a);
        let sext = |bits: u32| (((u << (64 - bits)) as i64) >> (64 - bits)) as f64;
        Some(match self.code {
            b'b' => sext(8),
            b'h' => sext(16),
            b'i' | b'l' => sext(32),
            b'q' => u as i64 as f64,
            b'?' => (u != 0) as u8 as f64,
            b'f' => f32::from_bits(u as u32) as f64,
            b'd' => f64::from_bits(u),
            _ => u as f64, // B H I L Q
        })
    }
}

/// Parses a `ChannelFormat`; sizes and packing are numpy's (how idelib reads payloads).
fn parse_format(format: &str) -> Result<(Vec<Field>, usize), ChannelProblem> {
    let mut chars = format
        .trim()
        .bytes()
        .filter(|c| !c.is_ascii_whitespace())
        .peekable();
    let big_endian = matches!(chars.peek(), Some(b'>' | b'!'));
    if matches!(chars.peek(), Some(b'<' | b'>' | b'!' | b'=' | b'@')) {
        chars.next();
    }
    let (mut fields, mut offset) = (Vec::new(), 0);
    for code in chars {
        let size = match code {
            b'b' | b'B' | b'?' => 1,
            b'h' | b'H' => 2,
            b'i' | b'I' | b'l' | b'L' | b'f' => 4,
            b'q' | b'Q' | b'd' => 8,
            _ => {
                return Err(ChannelProblem::TypeCode {
                    format: format.to_string(),
                    code: code as char,
                })
            }
        };
        fields.push(Field {
            code,
            size,
            big_endian,
            offset,
        });
        offset += size;
    }
    if fields.is_empty() {
        return Err(ChannelProblem::EmptyFormat(format.to_string()));
    }
    Ok((fields, offset))
}

/// Evaluates a `TimeCodeScale` such as `1.0/32768` (numbers joined by `*` and `/`).
fn parse_ratio(s: &str) -> Option<f64> {
    let (mut value, mut op, mut rest) = (1.0f64, b'*', s.trim());
    loop {
        let cut = rest.find(['*', '/']).unwrap_or(rest.len());
        let n: f64 = rest[..cut].trim().parse().ok()?;
        value = if op == b'*' { value * n } else { value / n };
        let Some(&next) = rest.as_bytes().get(cut) else {
            break;
        };
        op = next;
        rest = &rest[cut + 1..];
    }
    (value.is_finite() && value > 0.0).then_some(value)
}

#[derive(Debug, Clone)]
pub struct SubChannel {
    /// SubChannelID: the index of this subchannel's field in each sample.
    pub id: u64,
    pub name: String,
    /// Measurement type, e.g. "Acceleration".
    pub label: String,
    /// Engineering units after calibration, e.g. "g".
    pub units: String,
    /// The sensor it measures with (`SubChannelSensorRef`: a [`Sensor`]'s id).
    pub sensor: Option<u64>,
    pub(super) cal: Option<u64>,
}

#[derive(Debug, Clone)]
pub struct Channel {
    pub id: u64,
    pub name: String,
    /// The raw sample layout (`ChannelFormat`), e.g. `<hhh`.
    pub format: String,
    pub subchannels: Vec<SubChannel>,
    /// Why this reader cannot read the channel, if it cannot.
    pub unsupported: Option<ChannelProblem>,
    pub(super) cal: Option<u64>,
    /// Microseconds per timecode tick (idelib's `timeScalars`).
    pub(super) tick_us: f64,
    pub(super) modulus: Option<u64>,
    pub(super) fields: Vec<Field>,
    /// Bytes per sample (all subchannels).
    pub(super) record: usize,
}

/// A calibration polynomial from the `CalibrationList`.
#[derive(Debug, Clone)]
pub(super) struct Poly {
    pub(super) coeffs: Vec<f64>,
    pub(super) reference: f64,
    /// Bivariate: (reference of the 2nd variable, its channel, its subchannel).
    pub(super) second: Option<(f64, u64, u64)>,
    /// Its element's byte offset in the file.
    pub(super) at: u64,
}

impl Poly {
    /// The polynomial if every coefficient and reference is a finite number; else the error
    /// naming it (`id`), never values calibrated to NaN.
    pub(super) fn finite(&self, id: u64) -> Result<&Self, IdeError> {
        let second = self.second.map_or(0.0, |(r, _, _)| r);
        let all = self.coeffs.iter().chain([&self.reference, &second]);
        if all.into_iter().all(|v| v.is_finite()) {
            Ok(self)
        } else {
            Err(IdeError::Malformed {
                offset: self.at,
                what: Malformation::CalibrationNotFinite { id },
            })
        }
    }

    /// idelib's `Univariate._fastCoeffs`: a0*(x - ref) + a1 = a0*x + (a1 - a0*ref).
    pub(super) fn linear(&self, id: u64) -> Result<(f64, f64), IdeError> {
        match (self.second, self.coeffs.as_slice()) {
            (None, &[a0, a1]) => Ok((a0, a1 - a0 * self.reference)),
            (None, c) => Err(IdeError::Unsupported(
                IdeUnsupported::UnivariateCoefficients {
                    id,
                    coefficients: c.len(),
                },
            )),
            (Some(_), _) => Err(IdeError::Unsupported(
                IdeUnsupported::BivariateAsUnivariate { id },
            )),
        }
    }
}

fn parse_channel(body: &[u8], base: u64) -> Result<Channel, IdeError> {
    let mut ch = Channel {
        id: u64::MAX,
        name: String::new(),
        format: String::new(),
        subchannels: Vec::new(),
        unsupported: None,
        cal: None,
        tick_us: DEFAULT_TICK_US,
        modulus: None,
        fields: Vec::new(),
        record: 0,
    };
    let (mut id, mut parser, mut scale) = (None, None, None);
    for c in ebml::children(body, base) {
        let (cid, v, o) = c?;
        match cid {
            0x5272 => id = Some(ebml::uint(v, o)?),
            0x5273 => ch.name = ebml::string(v),
            0x5274 => ch.cal = Some(ebml::uint(v, o)?),
            0x5275 => ch.format = ebml::string(v),
            0x5276 => parser = Some(ebml::string(v)),
            0x5277 => scale = Some(ebml::string(v)),
            0x5278 => ch.modulus = Some(ebml::uint(v, o)?),
            SUBCHANNEL => {
                let mut sc = SubChannel {
                    id: ch.subchannels.len() as u64,
                    name: String::new(),
                    label: String::new(),
                    units: String::new(),
                    sensor: None,
                    cal: None,
                };
                for s in ebml::children(v, o) {
                    let (sid, sv, so) = s?;
                    match sid {
                        0x52A1 => sc.id = ebml::uint(sv, so)?,
                        0x52A2 => sc.name = ebml::string(sv),
                        0x52A3 => sc.cal = Some(ebml::uint(sv, so)?),
                        0x52A5 => sc.label = ebml::string(sv),
                        0x52A6 => sc.units = ebml::string(sv),
                        0x52A9 => sc.sensor = ebml::uint(sv, so).ok(),
                        _ => {}
                    }
                }
                ch.subchannels.push(sc);
            }
            _ => {}
        }
    }
    ch.id = id.ok_or(IdeError::Malformed {
        offset: base,
        what: Malformation::ChannelWithoutId,
    })?;
    for sc in ch.subchannels.iter_mut().filter(|s| s.name.is_empty()) {
        sc.name = format!("{}:{:02}", ch.name, sc.id); // idelib's default name
    }
    // Named parsers override ChannelFormat in idelib; "NMEA" is plain signed bytes.
    let problem = match parser.as_deref().map(str::to_ascii_uppercase).as_deref() {
        Some("NMEA") => {
            ch.format = "b".into();
            None
        }
        Some(p @ ("MPL3115" | "LEGACYACCELEROMETER")) => {
            Some(ChannelProblem::LegacyParser(p.to_string()))
        }
        _ if ch.format.is_empty() => Some(ChannelProblem::NoFormat),
        _ => None,
    };
    let problem = problem.or_else(|| match parse_format(&ch.format) {
        Ok((fields, record)) => {
            (ch.fields, ch.record) = (fields, record);
            None
        }
        Err(e) => Some(e),
    });
    let problem = problem.or_else(|| match scale.as_deref().map(parse_ratio) {
        None => None,
        Some(Some(s)) => {
            ch.tick_us = s * 1_000_000.0;
            None
        }
        Some(None) => Some(ChannelProblem::TimeCodeScale(scale.unwrap_or_default())),
    });
    ch.unsupported = problem.or((ch.modulus == Some(0)).then_some(ChannelProblem::ZeroModulus));
    Ok(ch)
}
