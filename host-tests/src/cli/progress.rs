//! The progress bar on stderr while a big file is read (indicatif).

use std::path::Path;

/// A progress bar on stderr (indicatif) for a file over 8 MiB when stderr is a terminal.
pub fn progress_for(file: &Path) -> Option<fn(f64)> {
    use std::io::IsTerminal;
    let big = std::fs::metadata(file)
        .map(|m| m.len() > 8 << 20)
        .unwrap_or(false);
    (big && std::io::stderr().is_terminal()).then_some(show_progress as fn(f64))
}

/// The bar, per mille of the file read (a plain function for the readers' callbacks).
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
