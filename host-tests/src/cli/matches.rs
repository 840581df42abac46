//! A quoted pattern's files (`impact analyze 'runs/**/*.csv'`): a walk from the pattern's
//! literal folder that enters every directory once, however many links lead to it.
//!
//! The `glob` crate's walk follows a symbolic link to a directory each time it meets it, so a
//! link to a parent (`lp/loop -> ..`) gave the same file once per level until the path grew
//! too long (41 analyses of one drop, counted as 41 drops), and two such links make the walk
//! exponential. Here a directory is entered only if its identity (device, inode) is new, a file
//! is kept only if its identity is new (the first name in sorted order wins), and a pattern
//! without `**` descends no deeper than its components (it cannot loop). The names are matched with
//! [`glob::Pattern`], `*` never crossing a `/`, as the shell's.

use std::collections::HashSet;
use std::path::{Component, Path, PathBuf};

/// Why a pattern's files could not be listed: a folder under it that cannot be read (its
/// files would be missing from the series without a word).
#[derive(Debug, thiserror::Error)]
#[error("{}: {source}", .path.display())]
pub struct WalkError {
    pub path: PathBuf,
    pub source: std::io::Error,
}

/// A file's or directory's identity, following links; `None` if it cannot be read.
#[cfg(unix)]
fn identity(meta: &std::fs::Metadata) -> Option<(u64, u64)> {
    use std::os::unix::fs::MetadataExt;
    Some((meta.dev(), meta.ino()))
}

#[cfg(not(unix))]
fn identity(_: &std::fs::Metadata) -> Option<(u64, u64)> {
    None
}

/// The files `pattern` (a valid [`glob::Pattern`], as given) names, sorted, each file once.
pub fn files(pattern: &str, compiled: &glob::Pattern) -> Result<Vec<PathBuf>, WalkError> {
    let path = Path::new(pattern);
    let mut base = PathBuf::new();
    let mut rest = 0usize;
    let mut deep = false;
    for c in path.components() {
        let text = c.as_os_str().to_string_lossy();
        if rest == 0 && !text.contains(['*', '?', '[']) {
            base.push(c);
            continue;
        }
        rest += 1;
        deep |= matches!(c, Component::Normal(n) if n == "**");
    }
    let options = glob::MatchOptions {
        case_sensitive: true,
        require_literal_separator: true,
        require_literal_leading_dot: false,
    };
    let mut walk = Walk {
        compiled,
        options,
        max_depth: if deep { usize::MAX } else { rest },
        dirs: HashSet::new(),
        found: Vec::new(),
    };
    let start = if base.as_os_str().is_empty() {
        Path::new(".")
    } else {
        base.as_path()
    };
    if let Ok(meta) = std::fs::metadata(start) {
        if meta.is_dir() {
            walk.dirs.extend(identity(&meta));
            walk.dir(&base, start, 1)?;
        }
    }
    let mut found = walk.found;
    found.sort_by(|a, b| a.0.cmp(&b.0));
    let mut files = HashSet::new();
    Ok(found
        .into_iter()
        .filter(|(_, id)| id.is_none_or(|id| files.insert(id)))
        .map(|(p, _)| p)
        .collect())
}

/// The walk's state: the directories entered and the files found (with their identities).
struct Walk<'a> {
    compiled: &'a glob::Pattern,
    options: glob::MatchOptions,
    max_depth: usize,
    dirs: HashSet<(u64, u64)>,
    found: Vec<(PathBuf, Option<(u64, u64)>)>,
}

impl Walk<'_> {
    /// Lists `dir` (`shown`: its name as the pattern spells it, empty for `.`), `depth`
    /// components below the pattern's literal folder.
    fn dir(&mut self, shown: &Path, dir: &Path, depth: usize) -> Result<(), WalkError> {
        let failed = |source| WalkError {
            path: dir.to_path_buf(),
            source,
        };
        let mut entries: Vec<_> = std::fs::read_dir(dir)
            .map_err(failed)?
            .collect::<Result<_, _>>()
            .map_err(failed)?;
        entries.sort_by_key(|e| e.file_name());
        for e in entries {
            let name = shown.join(e.file_name());
            let path = e.path();
            // A dangling link or one that cannot be followed names nothing to read.
            let Ok(meta) = std::fs::metadata(&path) else {
                continue;
            };
            if meta.is_file() {
                if self.compiled.matches_path_with(&name, self.options) {
                    self.found.push((name, identity(&meta)));
                }
            } else if meta.is_dir() && depth < self.max_depth {
                // Only `**` can loop: its walk enters a directory once; without identities
                // (not unix) it follows no link.
                let deep = self.max_depth == usize::MAX;
                let link = e.file_type().is_ok_and(|t| t.is_symlink());
                let enter = !deep
                    || match identity(&meta) {
                        Some(id) => self.dirs.insert(id),
                        None => !link,
                    };
                if enter {
                    self.dir(&name, &path, depth + 1)?;
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[cfg(unix)]
    #[test]
    fn a_link_loop_gives_each_file_once() {
        let d = tempfile::tempdir().unwrap();
        let lp = d.path().join("lp");
        std::fs::create_dir_all(lp.join("sub")).unwrap();
        std::fs::write(lp.join("a.csv"), "x").unwrap();
        std::fs::write(lp.join("sub/b.csv"), "x").unwrap();
        std::os::unix::fs::symlink("..", lp.join("sub/up")).unwrap();
        std::os::unix::fs::symlink(".", lp.join("here")).unwrap();
        let pattern = format!("{}/**/*.csv", lp.display());
        let found = files(&pattern, &glob::Pattern::new(&pattern).unwrap()).unwrap();
        assert_eq!(found, vec![lp.join("a.csv"), lp.join("sub/b.csv")]);
        // Without `**`: one level only, `*` not crossing a separator.
        let pattern = format!("{}/*.csv", lp.display());
        let found = files(&pattern, &glob::Pattern::new(&pattern).unwrap()).unwrap();
        assert_eq!(found, vec![lp.join("a.csv")]);
        let pattern = format!("{}/*/*.csv", lp.display());
        let found = files(&pattern, &glob::Pattern::new(&pattern).unwrap()).unwrap();
        // `here/a.csv` is a.csv again; sub/b.csv is new.
        assert_eq!(found, vec![lp.join("here/a.csv"), lp.join("sub/b.csv")]);
    }
}
