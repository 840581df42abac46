//! A series' shock directions (`--direction`): a shock test runs each pulse in several
//! directions (IEC 60068-2-27: 3 shocks in each of 6 directions), and the series is judged
//! and compared direction by direction. Each recording's direction is its channel (a series
//! over the axes' channels), a part of its file name, or one for the whole report (`--meta
//! direction=…`).

use std::path::Path;

/// Where a recording's direction comes from.
#[derive(Clone, Debug)]
pub enum Direction {
    /// Its channel's name (`--direction channel`).
    Channel,
    /// The part of its file name (without the folder) a pattern matches, its first group if
    /// it has one (`--direction 'name:_([+-][XYZ])_'`).
    Name(regex::Regex),
    /// The same for every recording (`impact report --meta direction=+Z`).
    Fixed(String),
}

/// Why `--direction` was refused.
#[derive(Debug, thiserror::Error)]
pub enum DirectionError {
    #[error("give `channel` or `name:PATTERN` (a regular expression over the file name, its first group the direction: `name:_([+-][XYZ])_`)")]
    Source,
    #[error("name:{pattern}: not a regular expression ({source})")]
    Pattern {
        pattern: String,
        source: Box<regex::Error>,
    },
}

/// `--direction`'s value: `channel` or `name:PATTERN`.
pub fn parse(s: &str) -> Result<Direction, DirectionError> {
    if s == "channel" {
        return Ok(Direction::Channel);
    }
    let pattern = s.strip_prefix("name:").ok_or(DirectionError::Source)?;
    // A bounded pattern: the regex crate runs in linear time, and its compiled size is capped.
    regex::RegexBuilder::new(pattern)
        .size_limit(1 << 20)
        .build()
        .map(Direction::Name)
        .map_err(|source| DirectionError::Pattern {
            pattern: pattern.to_string(),
            source: Box::new(source),
        })
}

impl Direction {
    /// The direction of the recording `file`'s `channel` (as the series names it); none where
    /// the name holds no match (or the channel is the file's default, unnamed).
    pub fn of(&self, file: &Path, channel: &str) -> Option<String> {
        match self {
            Direction::Channel => (!channel.is_empty()).then(|| channel.to_string()),
            Direction::Fixed(d) => Some(d.clone()),
            Direction::Name(re) => {
                let name = file.file_name()?.to_string_lossy();
                // The first group where the pattern has one (a group that did not take part
                // gives none, not the whole match), else the whole match; the first match
                // that is not empty.
                let grouped = re.captures_len() > 1;
                re.captures_iter(&name).find_map(|c| {
                    let m = if grouped { c.get(1) } else { c.get(0) }?;
                    (!m.as_str().is_empty()).then(|| m.as_str().to_string())
                })
            }
        }
    }

    /// In words, for a note on a recording with none.
    pub fn words(&self) -> String {
        match self {
            Direction::Channel => "--direction channel".into(),
            Direction::Name(re) => format!("--direction name:{}", re.as_str()),
            Direction::Fixed(_) => "--meta direction".into(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_direction_comes_from_the_name_its_group_or_the_channel() {
        let d = parse("name:_([+-][XYZ])_").unwrap();
        assert_eq!(
            d.of(Path::new("runs/shock_+Z_3.csv"), "").as_deref(),
            Some("+Z")
        );
        // The folder is not the name.
        assert_eq!(d.of(Path::new("_+X_/shock_3.csv"), ""), None);
        let whole = parse("name:[+-][XYZ]").unwrap();
        assert_eq!(whole.of(Path::new("a-Y.csv"), "").as_deref(), Some("-Y"));
        assert_eq!(
            parse("channel")
                .unwrap()
                .of(Path::new("a.csv"), "x_g")
                .as_deref(),
            Some("x_g")
        );
        assert_eq!(parse("channel").unwrap().of(Path::new("a.csv"), ""), None);
        // An optional group that did not take part is no direction; an empty match hides
        // no later one.
        let optional = parse("name:shock_([+-][XYZ])?").unwrap();
        assert_eq!(optional.of(Path::new("shock_3.csv"), ""), None);
        let empty_first = parse("name:[+-]?[XYZ]?").unwrap();
        assert_eq!(
            empty_first.of(Path::new("shock_+Z.csv"), "").as_deref(),
            Some("+Z")
        );
        assert!(matches!(
            parse("name:("),
            Err(DirectionError::Pattern { .. })
        ));
        assert!(matches!(parse("axis"), Err(DirectionError::Source)));
    }
}
