//! `impact analyze FILE`: a recording through the pipeline ([`crate::pipeline::analyze`]),
//! printed as the table, JSON or CSV, and drawn (`--plot`).

use crate::pipeline::{self, AnalyzeArgs};
use crate::{plot, report};

/// The files an analysis reads (no output may write over one): the recording, the scene
/// file, the free-fall recording.
pub fn inputs(args: &AnalyzeArgs) -> Vec<&std::path::Path> {
    let mut inputs = vec![args.file.as_path()];
    inputs.extend(args.scene.as_deref());
    inputs.extend(args.free_fall.as_deref().map(pipeline::free_fall::file));
    inputs
}

/// Runs `impact analyze`.
pub fn run(args: &AnalyzeArgs) -> Result<(), String> {
    let progress = super::progress::progress_for(&args.file);
    if let Some(path) = &args.plot {
        plot::check_output(path, &inputs(args))?;
    }
    let (setup, reports) = pipeline::analyze(args, progress)?;
    // Before the results: the bar's line cleared.
    super::progress::finish();
    let a = pipeline::to_json(&setup, &reports);
    if args.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&a).map_err(|e| e.to_string())?
        );
    } else if args.csv {
        print!("{}", report::to_csv(&a));
    } else {
        print!("{}", report::to_table(&a));
    }
    if let Some(path) = &args.plot {
        plot::impacts(&setup.plot_signal(), &reports, path)?;
    }
    Ok(())
}
