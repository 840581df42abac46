//! The firmware's log lines (docs/board.md, "Log lines"), one struct per kind, each parsed
//! beside the format the firmware's reporter prints (`firmware/src/tasks/reporter.rs`): which
//! kind a decoded line is ([`find`]), its `key=value` fields ([`Fields`]), and each kind's
//! values at their types ([`ImpactLine`], [`SrsLine`], [`SpecLine`], [`WaveLine`],
//! [`WaveFrameLine`], [`SceneLine`], [`HeartbeatLine`], [`SummaryLine`]).
//!
//! A struct holds as fields what every reader of its line needs when it reads it; what only
//! some readers need, later (the scene's mass for a figure, a heartbeat's counters at the end
//! of a run), is read when asked, so that a reader that does not need a field does not refuse
//! a line for it.

mod fields;
mod impact;
mod scene;
mod spectrum;
mod state;
mod wave;

pub use fields::{FieldError, Fields, Number};
pub use impact::ImpactLine;
pub use scene::{spec_of, LineTarget, SceneDifference, SceneLine};
pub use spectrum::{SpecLine, SrsLine};
pub use state::{Counter, HeartbeatLine, State, SummaryLine};
pub use wave::{WaveFrameLine, WaveLine, MAX_WAVE_VALUES};

use crate::firmware_link::plausible::Implausible;

/// The kinds of line the firmware logs, each starting with its name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum LineKind {
    /// The scene in use, once at start-up (again after a restart).
    Scene,
    /// One impact's report.
    Impact,
    /// An impact's shock response spectra.
    Srs,
    /// An impact's verdict against the scene's pulse specification.
    Spec,
    /// A captured window's header, before its frames.
    Wave,
    /// A frame of a captured window's counts.
    WaveFrame,
    /// The board's counters, once per second of signal.
    Heartbeat,
    /// The counters at the end of a finite stream.
    Summary,
}

impl LineKind {
    /// Every kind, in the order `impact log` tries them on a line.
    pub const ALL: [LineKind; 8] = [
        LineKind::Impact,
        LineKind::Srs,
        LineKind::Spec,
        LineKind::WaveFrame,
        LineKind::Wave,
        LineKind::Heartbeat,
        LineKind::Summary,
        LineKind::Scene,
    ];

    /// The line's first word.
    pub fn name(self) -> &'static str {
        let marker = self.marker();
        &marker[..marker.len() - 1]
    }

    /// The name and the space after it.
    fn marker(self) -> &'static str {
        match self {
            LineKind::Scene => "scene ",
            LineKind::Impact => "impact ",
            LineKind::Srs => "srs ",
            LineKind::Spec => "spec ",
            LineKind::Wave => "wave ",
            LineKind::WaveFrame => "wave_frame ",
            LineKind::Heartbeat => "heartbeat ",
            LineKind::Summary => "summary ",
        }
    }

    /// Whether the line is a data line (numbered by the logger's `seq`): all but the scene.
    pub fn is_data(self) -> bool {
        self != LineKind::Scene
    }
}

impl std::fmt::Display for LineKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The first of `kinds` (tried in that order) that the decoded `line` is, and its fields; `None`
/// if it is none of them. The name may stand anywhere a message starts (at the start of the
/// line or after a space: defmt-print puts a time stamp and the level first), and the first
/// token after it must be a field, so that a prose message starting with the same word is not
/// taken for one.
pub fn find(line: &str, kinds: &[LineKind]) -> Option<(LineKind, Result<Fields, FieldError>)> {
    kinds
        .iter()
        .find_map(|&kind| after_name(line, kind).map(|rest| (kind, Fields::parse(rest))))
}

/// What follows `kind`'s name in `line`, if the line is one of that kind.
fn after_name(line: &str, kind: LineKind) -> Option<&str> {
    let marker = kind.marker();
    let at = line
        .match_indices(marker)
        .map(|(i, _)| i)
        .find(|&i| i == 0 || line[..i].ends_with(' '))?;
    let rest = &line[at + marker.len()..];
    rest.split_whitespace()
        .next()?
        .contains('=')
        .then_some(rest)
}

/// A line whose values are not what its kind holds.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum LineError {
    #[error(transparent)]
    Field(#[from] FieldError),
    /// A report's number beyond what the firmware can report.
    #[error(transparent)]
    Implausible(#[from] Implausible),
    /// A `rate_hz` no board samples at (outside [`RATE_HZ`]).
    #[error(
        "rate_hz={}: not a sample rate from {} Hz to {:e} Hz (the core's highest): no board \
         samples at it, and no time can be checked against it",
        shown(*.value), RATE_HZ.start(), RATE_HZ.end()
    )]
    Rate { value: f32 },
    /// An impact's `status` that is none of the core's.
    #[error("status={text}: unknown status")]
    Status { text: String },
    /// An impact's `analysis` that is neither `full` nor `skipped`.
    #[error("analysis={text}: not full or skipped")]
    Analysis { text: String },
    /// A `spec` line's `reason` that is none of the core's.
    #[error("reason={text}: not a reason a verdict is missing")]
    Reason { text: String },
    /// The scene line's pulse specification does not make one (its shape unknown, a number
    /// missing, its band's columns of different lengths, or refused by the core).
    #[error("scene: spec: {why}")]
    SceneSpec { why: String },
    /// The scene line's `target_space` not a state space's list: its order (1 to 6), then
    /// `n² + 3n` finite numbers.
    #[error(
        "scene: target_space={text}: not an order of 1 to 6 states and its n² + 3n finite numbers"
    )]
    SceneTarget { text: String },
    /// A value of an `srs` line's list that is not a finite number >= 0.
    #[error("{field}: {text} is not a finite value >= 0")]
    ListValue { field: &'static str, text: String },
    /// An `srs` line whose lists do not hold `bands` values (or `bands` out of range).
    #[error("bands={bands} with {srs} SRS and {pvss} PVSS values")]
    Bands { bands: u8, srs: usize, pvss: usize },
    /// A `wave` line with `every=0`.
    #[error("every=0: a window is sent with every >= 1")]
    EveryZero,
    /// A `wave` line whose frame count does not follow from its samples.
    #[error("frames={frames}: {samples} samples at every={every} make {expected} frames")]
    Frames {
        frames: u32,
        samples: u32,
        every: u16,
        expected: usize,
    },
    /// A `wave` line declaring more values than a window of the board holds.
    #[error(
        "samples={samples} every={every}: {values} values, and a window of the board holds at \
         most {max} (a capture, with room to spare): not the board's line"
    )]
    WaveTooLong {
        samples: u32,
        every: u16,
        values: usize,
        max: usize,
    },
    /// A value of a `wave_frame` line's counts that is not an i16.
    #[error("counts: {text} is not an i16")]
    Count { text: String },
}

/// The sample rates a line may state, Hz: from 1 Hz (a board's heartbeat counts seconds of
/// signal, and at a lower rate one capture of the board spans over four hours) to the core's
/// highest, [`impact_core::scene::MAX_RATE_HZ`] (100 MHz: a scene beyond it is refused by the
/// core, so no board or emulator runs one). A rate outside voids every check that a time is
/// within its stream (`rate_hz=1e-38` made every duration plausible).
pub const RATE_HZ: std::ops::RangeInclusive<f32> = 1.0..=impact_core::scene::MAX_RATE_HZ;

/// `x` as read, or in exponent form when huge or tiny (`1e-38`).
fn shown(x: f32) -> String {
    if x != 0.0 && x.is_finite() && !(1e-4..1e9).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        x.to_string()
    }
}

/// A line's `rate_hz`: within [`RATE_HZ`].
pub fn rate(fields: &Fields) -> Result<f32, LineError> {
    let value: f32 = fields.num("rate_hz")?;
    if RATE_HZ.contains(&value) {
        Ok(value)
    } else {
        Err(LineError::Rate { value })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_line_is_the_first_kind_tried_whose_name_starts_a_message() {
        let line = "0.1 INFO heartbeat seq=3 samples=10 note=srs x";
        let (kind, fields) = find(line, &LineKind::ALL).unwrap();
        assert_eq!(kind, LineKind::Heartbeat);
        assert_eq!(fields.unwrap().get("samples"), Some("10"));
        // A name inside a word, or followed by prose, is not a line.
        assert!(find("INFO impact_firmware::tasks @ x=1", &LineKind::ALL).is_none());
        assert!(find("WARN summary of nothing", &LineKind::ALL).is_none());
        // The order tried decides between two names in one line.
        let both = "srs index=1 wave index=2";
        assert_eq!(find(both, &LineKind::ALL).unwrap().0, LineKind::Srs);
        let waves_first = [LineKind::Wave, LineKind::Srs];
        assert_eq!(find(both, &waves_first).unwrap().0, LineKind::Wave);
        // A key given twice is the line's error.
        let twice = find("spec index=1 index=2", &LineKind::ALL).unwrap().1;
        assert_eq!(twice.unwrap_err().to_string(), "field index given twice");
    }

    #[test]
    fn a_rate_is_finite_and_positive() {
        let rate_of = |v: &str| rate(&Fields::parse(&format!("rate_hz={v}")).unwrap());
        assert_eq!(rate_of("500000.0"), Ok(500000.0));
        assert_eq!(
            rate_of("-5").unwrap_err().to_string(),
            "rate_hz=-5: not a sample rate from 1 Hz to 1e8 Hz (the core's highest): no \
             board samples at it, and no time can be checked against it"
        );
        assert!(rate_of("1e-38")
            .unwrap_err()
            .to_string()
            .starts_with("rate_hz=1e-38: not a sample rate"));
        assert!(rate_of("1e9").is_err() && rate_of("1").is_ok() && rate_of("1e8").is_ok());
        assert_eq!(
            rate_of("1e39").unwrap_err().to_string(),
            "rate_hz=inf: not finite (a float out of range, or NaN)"
        );
    }
}
