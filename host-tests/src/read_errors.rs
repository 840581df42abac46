//! The readers' errors as the tool words them. `impact_io` names a setting a message asks
//! for or refuses by its [`impact_io::Opt`] (its own Display writes the `ReadOptions` field);
//! here each is spelled as the `impact` option that gives it ([`crate::flags::flag`]), so the messages read as they always have
//! (`one sample: the rate cannot be told; give --rate`). The host's error types hold a
//! reader's error in one of the wrappers here ([`ReadFailure`], [`InputFileFailure`],
//! [`UnitsFailure`]), whose Display is the message the tool prints.

pub use crate::flags::flag;
use impact_io::units::UnitsConflict;
use impact_io::{ReadError, ReadErrorKind};

/// A reader's error as the tool prints it: `FILE[:LINE]: what`, the settings named by their
/// options.
pub fn read_error_message(e: &ReadError) -> String {
    e.display_with(flag).to_string()
}

/// A secondary input's error ([`impact_io::read_limited`]: a scene file, a target, an
/// ELF), the file named by its path as given: `-` is a file there, not standard input.
pub fn input_file_message(e: &ReadError) -> String {
    let at = match e.at {
        Some(impact_io::At::Line(l)) => format!(":{l}"),
        Some(impact_io::At::Sample(n)) => format!(": sample {n}"),
        None => String::new(),
    };
    format!("{}{at}: {}", e.path.display(), kind_message(&e.kind))
}

/// What went wrong, without the file (for a message that names the input its own way).
pub fn kind_message(kind: &ReadErrorKind) -> String {
    kind.display_with(flag).to_string()
}

/// Units given (`--units`, or the scene file's) that the channel's header contradicts.
pub fn units_message(e: &UnitsConflict) -> String {
    e.display_with(flag).to_string()
}

/// A reader's error (the recording's, a free-fall recording's) as the tool prints it
/// ([`read_error_message`]: `FILE[:LINE]: what`, the settings named by their options).
/// (Boxed, as in [`InputFileFailure`]: a `ReadError` is large, the errors holding it many.)
#[derive(Debug, thiserror::Error)]
#[error("{}", read_error_message(.0))]
pub struct ReadFailure(#[source] pub Box<ReadError>);

impl From<ReadError> for ReadFailure {
    fn from(e: ReadError) -> Self {
        Self(Box::new(e))
    }
}

/// A secondary input's error (a scene file) as the tool prints it
/// ([`input_file_message`]: the file named by its path as given).
#[derive(Debug, thiserror::Error)]
#[error("{}", input_file_message(.0))]
pub struct InputFileFailure(#[source] pub Box<ReadError>);

impl From<ReadError> for InputFileFailure {
    fn from(e: ReadError) -> Self {
        Self(Box::new(e))
    }
}

/// Units given that the channel's header contradicts, as the tool prints them
/// ([`units_message`]).
#[derive(Debug, thiserror::Error)]
#[error("{}", units_message(.0))]
pub struct UnitsFailure(#[source] pub UnitsConflict);

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    #[test]
    fn the_options_are_named_as_the_command_line_spells_them() {
        let e = ReadError::new(Path::new("a.csv"), ReadErrorKind::OneSample);
        assert_eq!(
            read_error_message(&e),
            "a.csv: one sample: the rate cannot be told; give --rate"
        );
        assert_eq!(
            e.to_string(),
            "a.csv: one sample: the rate cannot be told; give `rate_hz`"
        );
        let e = ReadError::new(Path::new("-"), ReadErrorKind::NoTimeColumn);
        assert_eq!(
            read_error_message(&e),
            "stdin: no time column found: give --time-column or --rate"
        );
        assert_eq!(
            kind_message(&ReadErrorKind::NpyOptions),
            "an .npy array takes --rate and --column only (no --time-column, --resample, --axes)"
        );
        // A secondary input's `-` is a file of that name.
        let e = impact_io::read_limited(Path::new("-"), 1024, "scene file").unwrap_err();
        let message = input_file_message(&e);
        assert!(message.starts_with("-: "), "{message}");
        let conflict =
            impact_io::units::Units::resolve(Some(impact_io::units::Units::G), "table_m_s2")
                .unwrap_err();
        assert_eq!(
            units_message(&conflict),
            "--units g contradicts the column's header \"table_m_s2\", which names m/s2: drop --units or choose another column"
        );
    }
}
