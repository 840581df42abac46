//! The `wave` and `wave_frame` lines before an analysed impact's line: its captured window's
//! header and frames (the analysis task's `send_waveform`).

use impact_core::waveform;

use super::{FieldError, Fields, LineError};

/// The most values a window (`wave` line) holds: a capture
/// ([`impact_core::board::CAPTURE_LEN`] values, each one sample or, decimated, the mean of
/// several) with room to spare. What a window's readers loop over is bounded by it.
pub const MAX_WAVE_VALUES: usize = 1 << 16;

/// A `wave` line: the window of the impact with its `index`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct WaveLine {
    pub index: u32,
    /// Stream index of the window's first sample.
    pub first_sample: u64,
    /// Samples in the window (on the board).
    pub samples: u32,
    /// One value per `every` samples (their mean when > 1), >= 1.
    pub every: u16,
    /// Frames the window is sent in (as many as its values make).
    pub frames: u32,
    /// The frozen baseline, `base_sum / base_n` counts.
    pub base_sum: i64,
    pub base_n: i64,
}

impl WaveLine {
    pub fn parse(f: &Fields) -> Result<Self, LineError> {
        let every: u16 = f.num("every")?;
        if every == 0 {
            return Err(LineError::EveryZero);
        }
        let samples: u32 = f.num("samples")?;
        let frames: u32 = f.num("frames")?;
        let values = waveform::values(samples as usize, every);
        if values > MAX_WAVE_VALUES {
            return Err(LineError::WaveTooLong {
                samples,
                every,
                values,
                max: MAX_WAVE_VALUES,
            });
        }
        let expected = waveform::frames(samples as usize, every);
        if frames as usize != expected {
            return Err(LineError::Frames {
                frames,
                samples,
                every,
                expected,
            });
        }
        let base_n: i64 = f.num("base_n")?;
        let base_sum: i64 = f.num("base_sum")?;
        Ok(Self {
            index: f.num("index")?,
            first_sample: f.num("first_sample")?,
            samples,
            every,
            frames,
            base_sum,
            base_n,
        })
    }
}

/// A `wave_frame` line: frame `frame` of the window of the impact with its `index`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct WaveFrameLine {
    pub index: u32,
    pub frame: u32,
    pub counts: Vec<i16>,
}

impl WaveFrameLine {
    /// The line `line` and its fields `f`. The counts are the last field, `counts=[v, v, ...]`
    /// as defmt prints a slice (with spaces: read off the line).
    pub fn parse(line: &str, f: &Fields) -> Result<Self, LineError> {
        let index: u32 = f.num("index")?;
        let frame: u32 = f.num("frame")?;
        let list = line
            .split_once("counts=[")
            .and_then(|(_, rest)| rest.split_once(']'))
            .map(|(list, _)| list)
            .ok_or(FieldError::Missing {
                field: "counts=[...]",
            })?;
        let counts = if list.trim().is_empty() {
            Vec::new()
        } else {
            list.split(',')
                .map(|v| {
                    v.trim().parse::<i16>().map_err(|_| LineError::Count {
                        text: v.trim().to_string(),
                    })
                })
                .collect::<Result<Vec<_>, _>>()?
        };
        Ok(Self {
            index,
            frame,
            counts,
        })
    }
}
