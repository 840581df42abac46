//! The progress bar on stderr while a big file is read (indicatif).

use std::path::Path;

/// A progress bar on stderr (indicatif) for a file over 8 MiB when stderr is a terminal.
pub fn progress_for(file: &Path) -> impact_io::progress::Progress {
    use std::io::IsTerminal;
    let big = std::fs::metadata(file)
        .map(|m| m.len() > 8 << 20)
        .unwrap_or(false);
    if big && std::io::stderr().is_terminal() {
        impact_io::progress::Progress::new(show_progress)
    } else {
        impact_io::progress::Progress::none()
    }
}

/// The terminal's one bar, per mille of the file read (cleared by [`finish`]).
static PROGRESS: std::sync::OnceLock<indicatif::ProgressBar> = std::sync::OnceLock::new();

fn show_progress(fraction: f64) {
    let bar = PROGRESS.get_or_init(|| {
        let bar = indicatif::ProgressBar::new(1000);
        if let Ok(style) = indicatif::ProgressStyle::with_template(
            "reading {wide_bar} {percent:>3} % {elapsed} (about {eta} left)",
        ) {
            bar.set_style(style);
        }
        bar
    });
    bar.set_position((fraction.clamp(0.0, 1.0) * 1000.0) as u64);
    if fraction >= 1.0 {
        bar.finish_and_clear();
    }
}

/// Clears the bar's line (before the results, and at the end).
pub fn finish() {
    if let Some(bar) = PROGRESS.get() {
        bar.finish_and_clear();
    }
}
