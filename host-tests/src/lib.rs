//! Host side of the impact monitor: the `impact` tool's building blocks, shared by the
//! integration tests and the benchmarks.

pub mod bench;
pub mod cli;
pub mod drop;
pub mod firmware_link;
pub mod flags;
pub mod html;
pub mod interrupt;
pub mod output;
pub mod parse;
pub mod pipeline;
pub mod plot;
pub mod read_errors;
pub mod report;
pub mod simulate;
pub mod small_csv;
pub mod standards;
pub mod synth;
pub mod testkit;

pub use impact_io::note;

/// The notes kept so far (and forgets them), worded as the tool words them
/// ([`read_errors::flag`]).
pub fn take_notes() -> Vec<String> {
    impact_io::take_notes(read_errors::flag)
}

/// Why [`on_big_stack`]'s thread gave no result.
#[derive(Debug, thiserror::Error)]
pub enum WorkerError {
    /// The thread could not be started (the system's limit on threads or memory).
    #[error(transparent)]
    Spawn(std::io::Error),
    #[error("the worker thread panicked")]
    Panicked,
}

/// Runs `f` on a thread with a 64 MiB stack: the core's monitors hold their capture buffers
/// inline (no allocation in `core`), which is more than a default thread's stack. `f`'s
/// error, or the thread's own ([`WorkerError`]) as `f`'s error type.
pub fn on_big_stack<T: Send + 'static, E: From<WorkerError> + Send + 'static>(
    f: impl FnOnce() -> Result<T, E> + Send + 'static,
) -> Result<T, E> {
    // The worker's notes go where the caller's go ([`impact_io::NoteScope`]).
    let scope = impact_io::NoteScope::here();
    let (result, notes) = std::thread::Builder::new()
        .stack_size(64 << 20)
        .spawn(move || scope.run(f))
        .map_err(WorkerError::Spawn)?
        .join()
        .map_err(|_| WorkerError::Panicked)?;
    notes.keep();
    result
}
