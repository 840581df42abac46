//! What is wrong with a log, by line.

use crate::firmware_link::line::{FieldError, LineError, LineKind, SceneDifference};
use crate::firmware_link::plausible::Implausible;
use crate::firmware_link::waves::WaveError;

/// What is wrong with a log, and on which line (none for what its end or a whole run shows):
/// shown `line N: what`.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{}{kind}", at(.line))]
pub struct LogError {
    pub line: Option<u64>,
    pub kind: LogErrorKind,
}

fn at(line: &Option<u64>) -> String {
    line.map_or(String::new(), |n| format!("line {n}: "))
}

impl LogError {
    /// `kind` on line `n`.
    pub fn at(n: u64, kind: impl Into<LogErrorKind>) -> Self {
        Self {
            line: Some(n),
            kind: kind.into(),
        }
    }

    /// `kind`, of no one line.
    pub fn whole(kind: impl Into<LogErrorKind>) -> Self {
        Self {
            line: None,
            kind: kind.into(),
        }
    }
}

/// An error of line `n`: `result.at(n)`.
pub(super) trait At<T> {
    fn at(self, n: u64) -> Result<T, LogError>;
}

impl<T, E: Into<LogErrorKind>> At<T> for Result<T, E> {
    fn at(self, n: u64) -> Result<T, LogError> {
        self.map_err(|e| LogError::at(n, e))
    }
}

/// What is wrong.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum LogErrorKind {
    /// A line's values are not what its kind holds.
    #[error(transparent)]
    Line(#[from] LineError),
    /// An impact's times or lengths beyond what its stream allows.
    #[error(transparent)]
    Implausible(#[from] Implausible),
    /// A frame its window cannot take.
    #[error(transparent)]
    Wave(#[from] WaveError),
    #[error("report_latency_s={value}: not a time >= 0")]
    NegativeLatency { value: f32 },
    #[error(
        "impact index={index} again (first on line {first}): two streams mixed, or a line repeated"
    )]
    ImpactAgain { index: u32, first: u64 },
    /// An `srs` or `spec` line without its impact before it, or a second one.
    #[error(
        "{kind} index={index}: no impact line of that index before it, or a second {kind} line"
    )]
    NoImpactFor { kind: LineKind, index: u32 },
    #[error("wave_frame index={index}: no wave line of that index before it")]
    NoWaveFor { index: u32 },
    #[error("wave index={index} again: two streams mixed, or a line repeated")]
    WaveAgain { index: u32 },
    /// A heartbeat counting fewer samples or impacts than the one on line `line`.
    #[error(
        "heartbeat samples={samples} impacts={impacts} after samples={samples_before} \
         impacts={impacts_before} (line {line}): counters never go back within a run"
    )]
    CountersBack {
        samples: u64,
        impacts: u64,
        samples_before: u64,
        impacts_before: u64,
        line: u64,
    },
    /// A scene unlike the first one (on line `first`): another bench's log.
    #[error(
        "a scene unlike line {first}'s ({difference}): logs of two benches mixed; split the log \
         before line {line}"
    )]
    SceneUnlike {
        first: u64,
        difference: SceneDifference,
        line: u64,
    },
    #[error(
        "the summary counts {counted} impacts ({dropped} reports dropped), the log has {printed} \
         impact lines: lines lost, or two streams mixed"
    )]
    SummaryCount {
        counted: u64,
        dropped: u64,
        printed: u64,
    },
    #[error("impact index={index} but the summary counts {counted} impacts")]
    BeyondSummary { index: u32, counted: u64 },
    /// An impact printed after a later one, which the run's summary does not count.
    #[error(
        "impact index={index} after index={previous}, and the summary counts no report out of \
         order"
    )]
    OutOfOrder { index: u32, previous: u32 },
    /// An impact printed after a later one in a run without a summary.
    #[error(
        "impact index={index} after index={previous} (the firmware prints in index order; a \
         reorder is counted only in a summary line)"
    )]
    OutOfOrderUncounted { index: u32, previous: u32 },
    #[error("the log has no scene, heartbeat or summary line: sample rate unknown")]
    NoRate,
}

impl LogErrorKind {
    /// Whether the error is the line's own (its text cut or garbled, a value no board gives,
    /// a line whose impact or window was such a line): a reader may pass over the line.
    /// Errors only several lines show (two streams mixed, counters going back, a scene unlike
    /// the first, counts at a run's end) are not.
    pub fn is_the_lines(&self) -> bool {
        matches!(
            self,
            LogErrorKind::Line(_)
                | LogErrorKind::Implausible(_)
                | LogErrorKind::Wave(_)
                | LogErrorKind::NegativeLatency { .. }
                | LogErrorKind::NoImpactFor { .. }
                | LogErrorKind::NoWaveFor { .. }
                | LogErrorKind::WaveAgain { .. }
        )
    }
}

impl From<FieldError> for LogErrorKind {
    fn from(e: FieldError) -> Self {
        LogErrorKind::Line(e.into())
    }
}
