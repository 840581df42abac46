//! The end of a run: its counts checked against its summary (or last heartbeat), its impacts
//! and windows put in index order.

use super::error::At;
use super::seq::SeqSet;
use super::{Log, LogError, LogErrorKind, LogReader, Run, RunReader};
use crate::firmware_link::line::{Counter, State, SummaryLine};

impl LogReader {
    /// Closes the run read: its counts checked against its summary (or last heartbeat), its
    /// impacts and windows put in index order, its counters added to the log's.
    pub(super) fn end_run(&mut self) -> Result<(), LogError> {
        let run = std::mem::take(&mut self.run);
        let log = &mut self.log;
        let state = run.state();
        let lines_dropped = counter(state, Counter::LinesDropped)?;
        let lost = note_lost_lines(log, &run.seqs, lines_dropped);
        let printed = run.impacts.len() as u64;
        match &run.summary {
            Some((line, summary)) => check_summary(&run, *line, summary, printed, lost)?,
            None => check_heartbeat(&run, printed, &mut log.warnings)?,
        }
        put_in_order(log, &run);
        log.runs.push(Run {
            line: run.line,
            impacts: run.first_impact..log.impacts.len(),
            waveforms: run.first_wave..log.waveforms.len(),
            samples: counter(state, Counter::Samples)?,
            samples_lost: counter(state, Counter::SamplesLost)?,
            analyses_skipped: counter(state, Counter::AnalysesSkipped)?,
        });
        log.heartbeat = run.heartbeat.map(|(_, h)| h);
        log.summary = run.summary.map(|(_, s)| s);
        Ok(())
    }
}

impl RunReader {
    /// The run's counters: its summary's, else its last heartbeat's.
    fn state(&self) -> Option<&State> {
        let summary = self.summary.as_ref().map(|(_, s)| &s.state);
        summary.or(self.heartbeat.as_ref().map(|(_, h)| &h.state))
    }
}

/// Counter `c` of `state`, 0 when there is none or it lacks it.
fn counter(state: Option<&State>, c: Counter) -> Result<u64, LogError> {
    match state {
        Some(s) => Ok(s.given(c).map_err(LogError::whole)?.unwrap_or(0)),
        None => Ok(0),
    }
}

/// Adds the run's lines lost (`lines_dropped` by the board's count, and those missing from
/// the sequence numbers) to the log's, with a warning; whether any were.
fn note_lost_lines(log: &mut Log, seqs: &SeqSet, lines_dropped: u64) -> bool {
    let lines_missing = seqs.missing();
    log.lines_dropped += lines_dropped;
    log.lines_missing += lines_missing;
    if lines_missing > 0 || lines_dropped > 0 {
        let first: Vec<String> = seqs.first_missing(5).iter().map(u32::to_string).collect();
        log.warnings.push(format!(
            "the board dropped {lines_dropped} lines (its logger's count); {lines_missing} \
             numbered lines are missing{}",
            if lines_missing > 0 {
                format!(
                    " (seq {}{})",
                    first.join(", "),
                    if lines_missing > 5 { ", …" } else { "" }
                )
            } else {
                String::new()
            }
        ));
    }
    lines_dropped + lines_missing > 0
}

/// The run's impact lines against its summary (on line `line`): as many as it counts (fewer
/// if lines were `lost`), none beyond, out of order only if it counts reports so.
fn check_summary(
    run: &RunReader,
    line: u64,
    summary: &SummaryLine,
    printed: u64,
    lost: bool,
) -> Result<(), LogError> {
    let counted = summary.impacts;
    let dropped = summary.state.counter(Counter::ReportsDropped).at(line)?;
    // Lines the board dropped (counted) explain missing impact lines.
    if printed + dropped != counted && !(lost && printed + dropped < counted) {
        let count = LogErrorKind::SummaryCount {
            counted,
            dropped,
            printed,
        };
        return Err(LogError::at(line, count));
    }
    if let Some(index) = run
        .impacts
        .keys()
        .copied()
        .filter(|&i| u64::from(i) >= counted)
        .min()
    {
        return Err(LogError::at(
            line,
            LogErrorKind::BeyondSummary { index, counted },
        ));
    }
    if let Some((at, index, previous)) = run.reordered {
        let out_of_order = summary.state.counter(Counter::ReportsOutOfOrder).at(line)?;
        if out_of_order == 0 {
            return Err(LogError::at(
                at,
                LogErrorKind::OutOfOrder { index, previous },
            ));
        }
    }
    Ok(())
}

/// A run without a summary: its impacts in index order, and as many as its last heartbeat
/// counts (fewer: a warning).
fn check_heartbeat(
    run: &RunReader,
    printed: u64,
    warnings: &mut Vec<String>,
) -> Result<(), LogError> {
    if let Some((line, index, previous)) = run.reordered {
        let unordered = LogErrorKind::OutOfOrderUncounted { index, previous };
        return Err(LogError::at(line, unordered));
    }
    if let Some((line, h)) = &run.heartbeat {
        let dropped = h.state.counter(Counter::ReportsDropped).at(*line)?;
        let counted = h.impacts;
        if printed + dropped < counted {
            warnings.push(format!(
                "line {line}: the heartbeat counts {counted} impacts ({dropped} reports \
                 dropped), the log has {printed} impact lines: a cut log, or lines lost \
                 on the link"
            ));
        }
    }
    Ok(())
}

/// The run's windows and impacts in index order (the impacts if they were not), a warning
/// for each window with frames missing.
fn put_in_order(log: &mut Log, run: &RunReader) {
    let waves = &mut log.waveforms[run.first_wave..];
    waves.sort_by_key(|w| w.index);
    for w in waves.iter() {
        if w.missing_frames() > 0 {
            log.warnings.push(format!(
                "impact {}: {} of {} waveform frames missing (the link dropped them)",
                w.index,
                w.missing_frames(),
                w.frames
            ));
        }
    }
    if run.reordered.is_some() {
        let mut both: Vec<_> = log
            .impacts
            .drain(run.first_impact..)
            .zip(log.latencies.drain(run.first_impact..))
            .collect();
        both.sort_by_key(|(r, _)| r.index);
        for (r, l) in both {
            log.impacts.push(r);
            log.latencies.push(l);
        }
    }
}
