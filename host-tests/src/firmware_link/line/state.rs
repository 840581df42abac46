//! The `heartbeat` and `summary` lines: the board's counters once per second of signal, and
//! at the end of a finite stream (the reporter's `log_heartbeat` and `summarize`).

use super::{rate, FieldError, Fields, LineError};

/// The board's counters a heartbeat or summary line holds (docs/board.md).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Counter {
    Samples,
    Blocks,
    BusyPermille,
    Overruns,
    BlocksLost,
    BlocksMissing,
    SamplesLost,
    Gaps,
    SourceErrors,
    Impacts,
    Incomplete,
    AnalysesSkipped,
    LevelChanges,
    ReportsDropped,
    /// Summary only.
    ReportsOutOfOrder,
    HeartbeatsDropped,
    LinesDropped,
    StackPeakBytes,
    StackSizeBytes,
    /// Summary only.
    ElapsedMs,
}

impl Counter {
    /// The counter's field.
    pub fn name(self) -> &'static str {
        match self {
            Counter::Samples => "samples",
            Counter::Blocks => "blocks",
            Counter::BusyPermille => "busy_permille",
            Counter::Overruns => "overruns",
            Counter::BlocksLost => "blocks_lost",
            Counter::BlocksMissing => "blocks_missing",
            Counter::SamplesLost => "samples_lost",
            Counter::Gaps => "gaps",
            Counter::SourceErrors => "source_errors",
            Counter::Impacts => "impacts",
            Counter::Incomplete => "incomplete",
            Counter::AnalysesSkipped => "analyses_skipped",
            Counter::LevelChanges => "level_changes",
            Counter::ReportsDropped => "reports_dropped",
            Counter::ReportsOutOfOrder => "reports_out_of_order",
            Counter::HeartbeatsDropped => "heartbeats_dropped",
            Counter::LinesDropped => "lines_dropped",
            Counter::StackPeakBytes => "stack_peak_bytes",
            Counter::StackSizeBytes => "stack_size_bytes",
            Counter::ElapsedMs => "elapsed_ms",
        }
    }
}

/// The board's state as a heartbeat or summary line gives it: each counter read when asked
/// (firmware before a counter did not write it).
#[derive(Clone, Debug, PartialEq)]
pub struct State(Fields);

impl State {
    pub fn new(fields: Fields) -> Self {
        Self(fields)
    }

    /// A counter the reader needs: missing is an error.
    pub fn counter(&self, c: Counter) -> Result<u64, FieldError> {
        self.0.num(c.name())
    }

    /// A counter, if the line has it.
    pub fn given(&self, c: Counter) -> Result<Option<u64>, FieldError> {
        self.0.given(c.name())
    }

    /// A counter, if the line has it and it reads as one (a counter only shown).
    pub fn readable(&self, c: Counter) -> Option<u64> {
        self.0.readable(c.name())
    }

    /// The busy share (`busy_permille` / 1000), if it reads as a number.
    pub fn busy_share(&self) -> Option<f64> {
        self.0
            .readable::<f64>(Counter::BusyPermille.name())
            .map(|b| b / 1000.0)
    }

    /// Samples per second: finite and > 0.
    pub fn rate_hz(&self) -> Result<f32, LineError> {
        rate(&self.0)
    }

    /// How the run ended (a summary's `result`: `ok` or `failed`).
    pub fn result(&self) -> Result<&str, FieldError> {
        self.0.text("result")
    }
}

/// A `heartbeat` or `summary` line (the two carry the same counters; a summary adds how the
/// run ended, [`State::result`]): its counts of samples and impacts and its rate checked as
/// it is read, the other counters when asked.
#[derive(Clone, Debug, PartialEq)]
pub struct CountsLine {
    pub samples: u64,
    pub impacts: u64,
    pub rate_hz: f32,
    pub state: State,
}

/// A `heartbeat` line ([`CountsLine`]).
pub type HeartbeatLine = CountsLine;

/// A `summary` line ([`CountsLine`]; how the run ended: [`State::result`]).
pub type SummaryLine = CountsLine;

impl CountsLine {
    pub fn parse(fields: Fields) -> Result<Self, LineError> {
        let (samples, impacts, rate_hz) = counts(&fields)?;
        Ok(Self {
            samples,
            impacts,
            rate_hz,
            state: State(fields),
        })
    }
}

/// A state line's samples, impacts and rate, in that order.
fn counts(f: &Fields) -> Result<(u64, u64, f32), LineError> {
    let samples = f.num(Counter::Samples.name())?;
    let impacts = f.num(Counter::Impacts.name())?;
    Ok((samples, impacts, rate(f)?))
}
