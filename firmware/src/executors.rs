//! The three priorities the tasks run at, each an embassy `InterruptExecutor` on an interrupt
//! line no device uses (the board module picks the lines and the NVIC priorities, and calls
//! `on_interrupt` from their handlers), as in embassy's `multiprio` example. Thread mode only
//! sleeps (`wfi`) between interrupts.
//!
//! | executor | tasks | preempted by |
//! |---|---|---|
//! | [`HIGH`] | sample source (DMA half-buffers, sensor FIFO, replay), light gate | device interrupts |
//! | [`MEDIUM`] | stream: baseline, trigger, capture, exact sums; reporter (defmt lines) | the above |
//! | [`LOW`] | analysis: widths, kinematics, CFC, fits | all of the above |
//!
//! The reporter shares the middle priority with the stream (both take microseconds per step),
//! so a report goes out as soon as it is made, not after the next analysis.

use embassy_executor::InterruptExecutor;

/// The sample source: never starved by anything below.
pub static HIGH: InterruptExecutor = InterruptExecutor::new();
/// The streaming stage and the reporter.
pub static MEDIUM: InterruptExecutor = InterruptExecutor::new();
/// Per-impact analysis.
pub static LOW: InterruptExecutor = InterruptExecutor::new();
