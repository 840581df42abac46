//! What the screens found before the analysis, as reported: the glitches removed and the
//! channel's rails.

use serde::Serialize;

/// An isolated one- or two-sample glitch that was replaced by a straight line between its
/// neighbours.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct Spike {
    /// Index of its first sample.
    pub sample: u64,
    /// Time of its first sample, s (0 until the caller sets it from its time axis).
    pub time_s: f64,
    /// How many samples it spans (1 or 2).
    pub samples: u32,
    /// Its most extreme reading, m/s² (deceleration positive).
    pub value_m_s2: f64,
}

/// The levels at which the channel is clipped, m/s²: nothing beyond them is known.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct Clipping {
    /// Readings at or below this are at the lower rail (if known).
    pub low_m_s2: Option<f64>,
    /// Readings at or above this are at the upper rail (if known).
    pub high_m_s2: Option<f64>,
    /// "range" (the sensor's full scale, given) or "flat-top" (found in the recording).
    pub from: String,
}
