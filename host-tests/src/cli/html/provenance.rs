//! Where a report comes from: every input file (its role, path, size and SHA-256), when the
//! report was written (UTC, ISO 8601; `SOURCE_DATE_EPOCH` fixes it, the reproducible-builds
//! convention), and the tool's version and git commit (`build.rs`).

use std::io::Read;
use std::path::{Path, PathBuf};

use sha2::{Digest, Sha256};

use super::super::series::EntryJson;
use super::super::srs_required::RequiredSrs;
use crate::html;
use crate::html::Html;
use crate::report::fmt::human;

/// The git commit the tool was built from (`build.rs`: `unknown` without one).
pub const COMMIT: &str = env!("IMPACT_GIT_COMMIT");

/// Whether the tool's sources differed from [`COMMIT`] when it was built (`build.rs`).
pub const DIRTY: bool = !env!("IMPACT_GIT_DIRTY").is_empty();

/// The environment variable that fixes the report's time (seconds since 1970-01-01 UTC).
pub const SOURCE_DATE_EPOCH: &str = "SOURCE_DATE_EPOCH";

/// Why the report's provenance could not be written.
#[derive(Debug, thiserror::Error)]
pub enum ProvenanceError {
    /// `SOURCE_DATE_EPOCH` set but no whole number of seconds (the convention: an error).
    #[error("{SOURCE_DATE_EPOCH}={value:?} is not a whole number of seconds since 1970-01-01 UTC")]
    SourceDateEpoch { value: String },
}

/// What an input is to the report.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    Recording,
    Scene,
    FreeFall,
    Band,
    Target,
    RequiredSrs,
    Meta,
    Session,
}

impl Role {
    /// Its name in the report.
    pub fn name(self) -> &'static str {
        match self {
            Role::Recording => "recording",
            Role::Scene => "scene file",
            Role::FreeFall => "free-fall recording",
            Role::Band => "band file",
            Role::Target => "target file",
            Role::RequiredSrs => "required SRS",
            Role::Meta => "meta file",
            Role::Session => "board's session",
        }
    }
}

/// An input as the report lists it: its size and SHA-256, or why it could not be read.
#[derive(Debug)]
pub struct Input {
    pub role: Role,
    pub path: PathBuf,
    pub digest: Result<Digested, std::io::Error>,
}

/// A file's size and SHA-256 (lower-case hex), read whole.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Digested {
    pub size_bytes: u64,
    pub sha256: String,
}

/// `path`'s size and SHA-256, read in 64 KiB pieces.
pub fn digest(path: &Path) -> Result<Digested, std::io::Error> {
    // A pipe, FIFO or device was read once, as it streamed: opened again it would give other
    // bytes (none, or never an end), so its hash would not be of what was analysed.
    if !std::fs::metadata(path)?.is_file() {
        return Err(std::io::Error::other(
            "not a regular file: read once as it streamed, so not hashed",
        ));
    }
    let mut file = std::fs::File::open(path)?;
    let mut hasher = Sha256::new();
    let mut buf = vec![0u8; 64 << 10];
    let mut size_bytes = 0u64;
    loop {
        match file.read(&mut buf) {
            Ok(0) => break,
            Ok(n) => {
                hasher.update(&buf[..n]);
                size_bytes += n as u64;
            }
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    let sha256 = hasher
        .finalize()
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    Ok(Digested { size_bytes, sha256 })
}

/// The inputs, each file once (the first role it was given in), digested on as many threads as
/// the machine has cores.
pub fn inputs(files: &[(Role, PathBuf)]) -> Vec<Input> {
    let mut seen = std::collections::HashSet::new();
    let unique: Vec<&(Role, PathBuf)> = files.iter().filter(|(_, p)| seen.insert(p)).collect();
    let workers = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .clamp(1, unique.len().max(1));
    let next = std::sync::atomic::AtomicUsize::new(0);
    let mut done: Vec<(usize, Input)> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..workers)
            .map(|_| {
                scope.spawn(|| {
                    let mut mine = Vec::new();
                    loop {
                        let k = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                        let Some((role, path)) = unique.get(k) else {
                            break;
                        };
                        mine.push((
                            k,
                            Input {
                                role: *role,
                                path: path.clone(),
                                digest: digest(path),
                            },
                        ));
                    }
                    mine
                })
            })
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().unwrap_or_default())
            .collect()
    });
    done.sort_by_key(|(k, _)| *k);
    done.into_iter().map(|(_, i)| i).collect()
}

/// When the report was written: seconds since 1970-01-01 UTC, and whether `SOURCE_DATE_EPOCH`
/// fixed it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Written {
    pub unix_s: i64,
    pub fixed: bool,
}

impl Written {
    /// `SOURCE_DATE_EPOCH` if set (an error if it is no whole number), else the clock.
    pub fn now() -> Result<Self, ProvenanceError> {
        Self::from_env(std::env::var(SOURCE_DATE_EPOCH).ok().as_deref())
    }

    /// The time `SOURCE_DATE_EPOCH`'s value `value` fixes, else the clock.
    pub fn from_env(value: Option<&str>) -> Result<Self, ProvenanceError> {
        if let Some(v) = value {
            return v
                .trim()
                .parse::<i64>()
                .ok()
                // Years 0 to 9999: what ISO 8601's four digits hold.
                .filter(|s| (-62_167_219_200..=253_402_300_799).contains(s))
                .map(|unix_s| Written {
                    unix_s,
                    fixed: true,
                })
                .ok_or_else(|| ProvenanceError::SourceDateEpoch {
                    value: v.to_string(),
                });
        }
        let unix_s = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| i64::try_from(d.as_secs()).unwrap_or(i64::MAX));
        Ok(Written {
            unix_s,
            fixed: false,
        })
    }

    /// ISO 8601 in UTC: `2026-11-29T03:07:00Z`.
    pub fn iso8601(self) -> String {
        iso8601(self.unix_s)
    }
}

/// `unix_s` (seconds since 1970-01-01 UTC) as ISO 8601 in UTC, `YYYY-MM-DDThh:mm:ssZ`.
pub fn iso8601(unix_s: i64) -> String {
    let (days, secs) = (unix_s.div_euclid(86_400), unix_s.rem_euclid(86_400));
    let (y, m, d) = civil_from_days(days);
    format!(
        "{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}Z",
        secs / 3600,
        secs / 60 % 60,
        secs % 60
    )
}

/// `unix_s` as an ISO 8601 date in UTC, `YYYY-MM-DD`.
pub fn iso8601_date(unix_s: i64) -> String {
    let (y, m, d) = civil_from_days(unix_s.div_euclid(86_400));
    format!("{y:04}-{m:02}-{d:02}")
}

/// The proleptic Gregorian date `days` after 1970-01-01 (Howard Hinnant's `civil_from_days`).
fn civil_from_days(days: i64) -> (i64, i64, i64) {
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    (yoe + era * 400 + i64::from(m <= 2), m, d)
}

/// The settings: the command, each recording (its channel, size and rate, what was assumed
/// of it, a board's log's lines passed over), the filter, the required SRS and the
/// specification with its standard's sources.
pub fn settings(
    h: &mut Html,
    filter: Option<&str>,
    results: &[EntryJson],
    required: Option<&RequiredSrs>,
) {
    h.raw("<h2>Settings and provenance</h2><dl>");
    let mut dd = |k: &str, v: &str| html!(h, "<dt>{}</dt><dd>{}</dd>", k, v);
    dd("command", &command_line());
    for e in results {
        let size =
            std::fs::metadata(&e.file).map_or(String::new(), |m| format!(", {} bytes", m.len()));
        let rate = e.analysis.as_ref().map_or(String::new(), |a| {
            format!(
                ", {} samples at {} S/s",
                a.samples,
                crate::report::fmt::sig(a.sample_rate_hz, 6)
            )
        });
        dd(
            "recording",
            &format!("{} [{}]{size}{rate}", e.file, e.channel),
        );
        // What the tool assumed of this recording, where the customer reads its provenance.
        for assumed in e.analysis.iter().flat_map(|a| &a.assumptions) {
            dd("assumed", assumed);
        }
        // A board's log: the lines passed over (the first 20, and how many more).
        let skipped: Vec<_> = e.analysis.iter().flat_map(|a| &a.skipped_lines).collect();
        for s in skipped.iter().take(20) {
            dd(
                "skipped",
                &format!("line {}: {} (skipped)", s.line, s.reason),
            );
        }
        if skipped.len() > 20 {
            dd("skipped", &format!("and {} more lines", skipped.len() - 20));
        }
    }
    dd("filter", filter.unwrap_or("none (raw signal)"));
    if let Some(r) = required {
        let (first, last) = (r.points()[0].0, r.points()[r.points().len() - 1].0);
        let (low, high) = crate::standards::SRS_TOLERANCE_DB;
        dd(
            "required SRS",
            &format!(
                "{}: {} breakpoints, {} to {}; tolerance {low:+} dB, {high:+} dB ({})",
                r.file,
                r.points().len(),
                human(first, "Hz").trim_end(),
                human(last, "Hz").trim_end(),
                crate::standards::SRS_TOLERANCE_SOURCE,
            ),
        );
    }
    if let Some(s) = results
        .iter()
        .find_map(|e| e.analysis.as_ref()?.spec.clone())
    {
        dd(
            "specification",
            crate::report::spec::table_head(&s)
                .trim_end()
                .trim_start_matches("spec: "),
        );
        if let Some(rows) = &s.band_table {
            let rows: Vec<String> = rows
                .iter()
                .map(|r| {
                    format!(
                        "{}D: {}…{}",
                        r.time_over_duration, r.lower_over_peak, r.upper_over_peak
                    )
                })
                .collect();
            dd(
                "user's band",
                &format!(
                    "{} rows (time from the nominal start: lower…upper limit, × the peak): {}",
                    rows.len(),
                    rows.join("; ")
                ),
            );
        }
        for x in &s.sources {
            dd(
                &format!("source of {}", x.tolerance),
                &format!("{} ({})", x.source, x.confidence),
            );
        }
        if let (Some(o), Some(from)) = (s.delta_v_tolerance_other, s.delta_v_tolerance_other_source)
        {
            dd(
                "Δv, other reading",
                &format!(
                    "±{:.0} %: {from}; each verdict says whether Δv passes under it",
                    100.0 * o
                ),
            );
        }
    }
    h.raw("</dl>\n");
}

/// The inputs' table: role, path, size, SHA-256.
pub fn inputs_table(h: &mut Html, inputs: &[Input]) {
    h.raw("<h2>Inputs</h2><table class=\"inputs\"><tr><th class=\"l\">input</th><th class=\"l\">path</th><th>size (bytes)</th><th class=\"l\">SHA-256</th></tr>\n");
    for i in inputs {
        let path = i.path.display().to_string();
        match &i.digest {
            Ok(d) => html!(
                h,
                "<tr><td class=\"l\">{}</td><td class=\"l\">{}</td><td>{}</td><td class=\"l hash\">{}</td></tr>\n",
                i.role.name(),
                path,
                d.size_bytes,
                d.sha256
            ),
            Err(e) => html!(
                h,
                "<tr><td class=\"l\">{}</td><td class=\"l\">{}</td><td>—</td><td class=\"l fail\">not read: {}</td></tr>\n",
                i.role.name(),
                path,
                e.to_string()
            ),
        }
    }
    h.raw("</table>\n");
}

/// The command line as a shell would take it back: each argument quoted where it needs it
/// (`--meta 'operator=A. Smith'`), bytes that are not UTF-8 shown as U+FFFD (never a panic).
fn command_line() -> String {
    std::env::args_os()
        .map(|a| {
            let a = a.to_string_lossy();
            let plain = !a.is_empty()
                && a.chars()
                    .all(|c| c.is_ascii_alphanumeric() || "-_./,=:+@%".contains(c));
            if plain {
                a.into_owned()
            } else {
                format!("'{}'", a.replace('\'', "'\\''"))
            }
        })
        .collect::<Vec<_>>()
        .join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn times_are_iso_8601_in_utc() {
        assert_eq!(iso8601(0), "1970-01-01T00:00:00Z");
        assert_eq!(iso8601(951_782_400), "2000-02-29T00:00:00Z");
        assert_eq!(iso8601(1_548_719_007), "2019-01-28T23:43:27Z");
        assert_eq!(iso8601(-1), "1969-12-31T23:59:59Z");
        assert_eq!(iso8601(253_402_300_799), "9999-12-31T23:59:59Z");
        assert_eq!(iso8601_date(1_548_719_007), "2019-01-28");
    }

    #[test]
    fn source_date_epoch_fixes_the_time_or_is_refused() {
        assert_eq!(
            Written::from_env(Some("1764385620")).unwrap(),
            Written {
                unix_s: 1_764_385_620,
                fixed: true
            }
        );
        for bad in ["", "soon", "1.5", "1e9", "99999999999999999"] {
            assert!(matches!(
                Written::from_env(Some(bad)),
                Err(ProvenanceError::SourceDateEpoch { .. })
            ));
        }
        assert!(!Written::from_env(None).unwrap().fixed);
    }

    #[test]
    fn a_digest_is_the_files_sha_256() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("abc");
        std::fs::write(&p, "abc").unwrap();
        assert_eq!(
            digest(&p).unwrap(),
            Digested {
                size_bytes: 3,
                sha256: "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad".into()
            }
        );
    }
}
