//! Host side of the impact monitor: the `impact` tool's building blocks, shared by the
//! integration tests and the benchmarks.

pub mod analyze;
pub mod axes;
pub mod cases;
pub mod compare;
pub mod csv_fast;
pub mod decode;
pub mod emulate;
pub mod histogram;
pub mod log;
pub mod m4;
pub mod npy;
pub mod plot;
pub mod precision;
pub mod raw;
pub mod realtime;
pub mod recording;
pub mod screen;
pub mod simulate;
pub mod soak;
pub mod sources;
pub mod spectrum;
pub mod spool;
pub mod stability;
pub mod streaming;
pub mod survey;
pub mod synth;
pub mod table;
pub mod tape;
pub mod target;
pub mod target_bench;
pub mod tdms;
pub mod throughput;
pub mod train;
pub mod wav;
pub mod waves;

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
