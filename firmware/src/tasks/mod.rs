//! The tasks both builds run, board-agnostic: the stream (middle priority), the reporter
//! (middle) and the analysis (low), joined by the queues of [`crate::queues`]. The sample
//! sources at the high priority are the boards' (`crate::board`).

pub mod analysis;
pub mod reporter;
pub mod stream;
