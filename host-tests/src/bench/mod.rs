//! The benchmarks (`impact bench …`): run time against error on the host ([`precision`],
//! [`two_body`]), the solvers' stability sweep ([`stability`]), the pipeline's throughput and
//! a soak ([`throughput`], [`soak`]), the Cortex-M4's exact instruction counts ([`m4`]) and
//! the firmware in real-time emulation ([`realtime`]).

pub mod m4;
pub mod precision;
pub mod realtime;
pub mod soak;
pub mod stability;
pub mod throughput;
pub mod two_body;

use std::path::PathBuf;

/// Why a benchmark could not run, or its results are not what it checks (the M4 bench's own
/// are [`m4::M4Error`]).
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    #[error(transparent)]
    Qemu(#[from] crate::firmware_link::qemu::QemuError),
    #[error(transparent)]
    M4(#[from] m4::M4Error),
    #[error(transparent)]
    Regressed(#[from] m4::report::Regressed),
    #[error(transparent)]
    Memory(#[from] crate::firmware_link::memory::MemoryError),
    /// The core refused a bench's scene or model (its words, the parameter by name).
    #[error(transparent)]
    Core(#[from] impact_core::Error),
    #[error(transparent)]
    Log(#[from] crate::firmware_link::log::LogError),
    #[error(transparent)]
    Spec(#[from] crate::pipeline::spec::SpecError),
    /// The thread a bench runs on (with its big stack) could not be started, or panicked.
    #[error(transparent)]
    Worker(#[from] crate::WorkerError),
    #[error("the emulator's log has no summary line")]
    NoSummary,
    #[error("summary: no {}", .counter.name())]
    NoCounter {
        counter: crate::firmware_link::line::Counter,
    },
    #[error("--spacing must exceed the pulse by the hold and the baseline window")]
    Spacing,
    #[error("noise triggered {count} impacts")]
    NoiseTriggered { count: u32 },
    #[error("expected 200 impacts, got {plain} and {fits}")]
    Impacts200 { plain: u32, fits: u32 },
    #[error("runs disagree: {first} and {other} impacts")]
    RunsDisagree { first: u64, other: u64 },
    #[error("{inserted} impacts inserted, {reported} reported")]
    Lost { inserted: usize, reported: u64 },
    /// A file a bench reads or writes, or the program it runs.
    #[error("{}: {source}", .path.display())]
    File {
        path: PathBuf,
        source: std::io::Error,
    },
    /// Waiting for a child, writing a bench's CSV, finding this program.
    #[error(transparent)]
    Io(std::io::Error),
    /// A child `impact analyze` failed: its command and its stderr, the only account of why.
    #[error("{} {args} failed: {stderr}", .exe.display())]
    ChildFailed {
        exe: PathBuf,
        args: String,
        stderr: String,
    },
    #[error("the child printed no peak memory")]
    NoPeakMemory,
    #[error("analyze JSON: {0}")]
    AnalyzeJson(serde_json::Error),
    #[error("analyze reported {reported} impacts, about {expected} expected")]
    Reported { reported: u64, expected: u64 },
    #[error("no run of the default path")]
    NoDefaultRun,
    /// A figure could not be drawn (plotters' SVG backend).
    #[error(transparent)]
    Draw(#[from] plotters::drawing::DrawingAreaErrorKind<std::io::Error>),
    #[error(transparent)]
    Output(#[from] crate::output::OutputError),
    #[error(transparent)]
    Json(#[from] serde_json::Error),
    /// A stored M4 baseline that is not one.
    #[error("{}: {source}", .path.display())]
    Baseline {
        path: PathBuf,
        source: serde_json::Error,
    },
    #[error("bench stability: {failures} results outside their stated bounds or not finite")]
    Stability { failures: u32 },
    #[error("soak: {inserted} impacts inserted, {reported} reported, {mismatched} mismatched")]
    Soak {
        inserted: u64,
        reported: u64,
        mismatched: u64,
    },
}

/// An I/O error of the file at `path`.
fn file(path: &std::path::Path) -> impl FnOnce(std::io::Error) -> BenchError + '_ {
    move |source| BenchError::File {
        path: path.to_path_buf(),
        source,
    }
}

/// `f` on a thread with a big stack ([`crate::on_big_stack`]).
fn on_big_stack<T: Send + 'static>(
    f: impl FnOnce() -> Result<T, BenchError> + Send + 'static,
) -> Result<T, BenchError> {
    crate::on_big_stack(f)
}
