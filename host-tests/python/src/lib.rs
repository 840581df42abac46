//! `impact._impact`: the `impact` tool's own Rust code behind the Python package `impact`
//! (`python/impact/__init__.py` turns what these functions return into NumPy arrays,
//! pandas DataFrames and typed exceptions).
//!
//! Every function takes the command line's options as arguments (`["--mass", "0.06"]`, made
//! by the package from keyword arguments) and parses them with the tool's own parser, so an
//! option means here what it means to `impact analyze`, is checked the same way, and is
//! refused with the same message. The results are the tool's JSON text: `json.loads` of it
//! gives Python floats equal bit for bit to `impact analyze --json`'s (serde_json writes the
//! shortest text that reads back to the same f64). The GIL is released while Rust works.

use pyo3::create_exception;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;

mod analyze;
mod read;

create_exception!(
    impact,
    ImpactError,
    PyException,
    "What the impact tool refused or could not do; its message is the tool's."
);
create_exception!(
    impact,
    UsageError,
    ImpactError,
    "An option the tool does not take, or a value it refuses (the message names the \
     command line's option: `mass=` is `--mass`)."
);
create_exception!(
    impact,
    ReadError,
    ImpactError,
    "The recording (or a file an option names) could not be read."
);
create_exception!(
    impact,
    AnalysisError,
    ImpactError,
    "The recording was read but could not be analysed with these settings."
);
create_exception!(
    impact,
    SimulationError,
    ImpactError,
    "The model or its parameters refused."
);

/// A command line's parse error as the `UsageError` Python sees: clap's own message (the
/// value refused, the accepted ones, a hint) without its `error: ` and its pointer to
/// `--help`; asked for help, where Python's is.
fn usage(e: &clap::Error) -> PyErr {
    use clap::error::ErrorKind;
    if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion) {
        return UsageError::new_err(
            "help= is the command line's: in Python, help(impact.analyze) or \
             docs/python.md (every option of `impact analyze --help` is a keyword)",
        );
    }
    let text = e.render().to_string();
    let lines: Vec<&str> = text
        .lines()
        .filter(|l| !l.starts_with("For more information, try"))
        .collect();
    let text = lines.join("\n");
    let text = text.strip_prefix("error: ").unwrap_or(&text);
    UsageError::new_err(text.trim_end().to_string())
}

#[pymodule]
fn _impact(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("ImpactError", py.get_type::<ImpactError>())?;
    m.add("UsageError", py.get_type::<UsageError>())?;
    m.add("ReadError", py.get_type::<ReadError>())?;
    m.add("AnalysisError", py.get_type::<AnalysisError>())?;
    m.add("SimulationError", py.get_type::<SimulationError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(analyze::analyze_file, m)?)?;
    m.add_function(wrap_pyfunction!(analyze::analyze_array, m)?)?;
    m.add_function(wrap_pyfunction!(analyze::series, m)?)?;
    m.add_function(wrap_pyfunction!(analyze::statistics, m)?)?;
    m.add_function(wrap_pyfunction!(analyze::simulate, m)?)?;
    m.add_function(wrap_pyfunction!(analyze::impact_fields, m)?)?;
    m.add_function(wrap_pyfunction!(read::read, m)?)?;
    Ok(())
}
