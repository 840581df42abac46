//! Host side of the impact monitor: the `impact` tool's building blocks, shared by the
//! integration tests and the benchmarks.

pub mod bench;
pub mod cli;
pub mod firmware_link;
pub mod io;
pub mod parse;
pub mod pipeline;
pub mod plot;
pub mod quantise;
pub mod report;
pub mod simulate;
pub mod synth;
pub mod testkit;

/// Notes for the user, each once (a file read in passes is opened again for each pass).
static NOTES: std::sync::Mutex<Vec<String>> = std::sync::Mutex::new(Vec::new());

/// Keeps `note: MESSAGE` for stderr: the tool prints its notes after a run that succeeded
/// ([`take_notes`]), so that an error stays one line.
pub fn note(message: &str) {
    if let Ok(mut notes) = NOTES.lock() {
        if !notes.iter().any(|m| m == message) {
            notes.push(message.to_string());
        }
    }
}

/// The notes kept so far (and forgets them).
pub fn take_notes() -> Vec<String> {
    NOTES
        .lock()
        .map(|mut n| std::mem::take(&mut *n))
        .unwrap_or_default()
}

/// Runs `f` on a thread with a 64 MiB stack: the core's monitors hold their capture buffers
/// inline (no allocation in `core`), which is more than a default thread's stack.
pub fn on_big_stack<T: Send + 'static>(
    f: impl FnOnce() -> Result<T, String> + Send + 'static,
) -> Result<T, String> {
    std::thread::Builder::new()
        .stack_size(64 << 20)
        .spawn(f)
        .map_err(|e| e.to_string())?
        .join()
        .map_err(|_| "the worker thread panicked".to_string())?
}
