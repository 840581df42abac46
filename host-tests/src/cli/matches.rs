//! A quoted pattern's files (`impact analyze 'runs/**/*.csv'`): a walk from the pattern's
//! literal folder that enters every directory once, however many links lead to it.
//!
//! The `glob` crate's walk follows a symbolic link to a directory each time it meets it, so a
//! link to a parent (`lp/loop -> ..`) gave the same file once per level until the path grew
//! too long (41 analyses of one drop, counted as 41 drops), and two such links make the walk
//! exponential. Here `**` does not enter a directory that is already on the path that led to
//! it (by identity: device, inode), the walk enters at most [`MAX_FOLDERS`] directories, a file
//! is kept only if its identity is new (the first name in sorted order wins), and a pattern
//! without `**` descends no deeper than its components (it cannot loop). The names are matched
//! with [`glob::Pattern`], `*` never crossing a `/`, as the shell's; a folder that cannot be
//! listed is skipped with a note naming it. A pattern with `..` after a wildcard is left to
//! `glob` (its walk has no loop to fear there that this one would guard).

use std::collections::HashSet;
use std::path::{Component, Path, PathBuf};

/// The most directories one pattern's walk enters (links between folders can make the
/// paths through them many more than the folders).
pub const MAX_FOLDERS: usize = 100_000;

/// Why a pattern's files could not be listed.
#[derive(Debug, thiserror::Error)]
pub enum WalkError {
    /// More than [`MAX_FOLDERS`] directories under it (`pattern`, as given).
    #[error(
        "{pattern}: the walk entered more than {MAX_FOLDERS} folders (links between folders?): \
         give a narrower pattern"
    )]
    TooManyFolders { pattern: String },
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
    let (mut deep, mut up) = (false, false);
    for c in path.components() {
        let text = c.as_os_str().to_string_lossy();
        if rest == 0 && !text.contains(['*', '?', '[']) {
            base.push(c);
            continue;
        }
        rest += 1;
        deep |= matches!(c, Component::Normal(n) if n == "**");
        up |= matches!(c, Component::ParentDir);
    }
    if up {
        let mut found: Vec<PathBuf> = glob::glob(pattern)
            .map(|paths| {
                paths
                    .filter_map(Result::ok)
                    .filter(|p| p.is_file())
                    .collect()
            })
            .unwrap_or_default();
        found.sort();
        return Ok(found);
    }
    // The names the walk builds are the path's components joined: the pattern as the same
    // (`runs/./*.csv`, `runs//*.csv` match as `runs/*.csv`).
    let normal: PathBuf = path.components().collect();
    let normal = glob::Pattern::new(&normal.to_string_lossy()).unwrap_or_else(|_| compiled.clone());
    let options = glob::MatchOptions {
        case_sensitive: true,
        require_literal_separator: true,
        require_literal_leading_dot: false,
    };
    let mut walk = Walk {
        compiled: &normal,
        options,
        max_depth: if deep { usize::MAX } else { rest },
        path: Vec::new(),
        entered: 0,
        found: Vec::new(),
        pattern,
    };
    let start = if base.as_os_str().is_empty() {
        Path::new(".")
    } else {
        base.as_path()
    };
    if let Ok(meta) = std::fs::metadata(start) {
        if meta.is_dir() {
            walk.path.extend(identity(&meta));
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

/// The walk's state: the directories on the path to the one listed, how many were entered,
/// and the files found (with their identities).
struct Walk<'a> {
    compiled: &'a glob::Pattern,
    options: glob::MatchOptions,
    max_depth: usize,
    path: Vec<(u64, u64)>,
    entered: usize,
    found: Vec<(PathBuf, Option<(u64, u64)>)>,
    pattern: &'a str,
}

impl Walk<'_> {
    /// Lists `dir` (`shown`: its name as the pattern spells it, empty for `.`), `depth`
    /// components below the pattern's literal folder.
    fn dir(&mut self, shown: &Path, dir: &Path, depth: usize) -> Result<(), WalkError> {
        self.entered += 1;
        if self.entered > MAX_FOLDERS {
            return Err(WalkError::TooManyFolders {
                pattern: self.pattern.to_string(),
            });
        }
        let listed = std::fs::read_dir(dir).and_then(|d| d.collect::<Result<Vec<_>, _>>());
        let mut entries = match listed {
            Ok(e) => e,
            Err(e) => {
                impact_io::note(&format!(
                    "{}: not listed ({e}); the pattern's files under it, if any, are not read",
                    dir.display()
                ));
                return Ok(());
            }
        };
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
                // Only `**` can loop: it does not enter a directory already on its path;
                // without identities (not unix) it follows no link.
                let deep = self.max_depth == usize::MAX;
                let link = e.file_type().is_ok_and(|t| t.is_symlink());
                let id = identity(&meta);
                let enter = !deep
                    || match id {
                        Some(id) => !self.path.contains(&id),
                        None => !link,
                    };
                if enter {
                    self.path.extend(id);
                    let r = self.dir(&name, &path, depth + 1);
                    if id.is_some() {
                        self.path.pop();
                    }
                    r?;
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
        // `.` and `//` in the pattern match as the shell's.
        for pattern in [
            format!("{}/./*.csv", lp.display()),
            format!("{}//*.csv", lp.display()),
        ] {
            let found = files(&pattern, &glob::Pattern::new(&pattern).unwrap()).unwrap();
            assert_eq!(found, vec![lp.join("a.csv")], "{pattern}");
        }
    }

    /// A link that sorts before the folder it names (`d/a -> b/run`) does not hide the
    /// folder's own path from a pattern with a literal after `**`.
    #[cfg(unix)]
    #[test]
    fn a_folder_reached_first_by_a_link_is_still_matched_by_its_own_path() {
        let d = tempfile::tempdir().unwrap();
        let root = d.path().join("d");
        std::fs::create_dir_all(root.join("b/run")).unwrap();
        std::fs::write(root.join("b/run/x.csv"), "x").unwrap();
        std::os::unix::fs::symlink("b/run", root.join("a")).unwrap();
        let pattern = format!("{}/**/run/*.csv", root.display());
        let found = files(&pattern, &glob::Pattern::new(&pattern).unwrap()).unwrap();
        assert_eq!(found, vec![root.join("b/run/x.csv")]);
    }
}
