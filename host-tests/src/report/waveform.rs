//! The captured windows the board sent (`impact log`, `impact emulate --waveforms`), as
//! reported.

use serde::Serialize;

/// What `impact log` says of the windows it found.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct WaveformJson {
    pub index: u32,
    pub first_sample: u64,
    pub samples: u32,
    pub every: u16,
    pub frames: u32,
    /// Frames the link dropped (their samples are missing from plots and exports).
    pub missing_frames: u32,
    /// The run the window is from, in a log in which the board restarted (1 for the first).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub run: Option<u32>,
}
