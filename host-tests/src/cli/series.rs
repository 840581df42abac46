//! A test series: several recordings (files, folders, patterns) and channels analysed in one
//! call, in parallel; one row per impact with its file and channel, and each metric's
//! statistics across the series.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use impact_core::consts::STANDARD_GRAVITY;
use impact_io::channel::ColumnRef;
use serde::Serialize;

use crate::pipeline::{self, AnalyzeArgs, PipelineError};
use crate::report::fmt::human;
use crate::report::statistics::{
    direction_groups, series_statistics, DirectionGroup, SeriesStatistics, Statistic,
};
use crate::report::{AnalysisJson, ImpactJson};

/// The extensions of the recordings a folder contributes (as `impact analyze` reads them).
pub const RECORDING_EXTENSIONS: [&str; 7] = ["csv", "ide", "wav", "npy", "tdms", "i16", "f32"];

/// Why a series' recordings could not be listed.
#[derive(Debug, thiserror::Error)]
pub enum SeriesError {
    #[error("a series reads files: standard input (-) can be one recording only")]
    Stdin,
    /// A folder given not listed.
    #[error("{}: {source}", .path.display())]
    Folder {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error(
        "{}: a folder with no recordings (files ending .{})",
        .path.display(),
        RECORDING_EXTENSIONS.join(", .")
    )]
    NoRecordings { path: PathBuf },
    /// A pattern (as given) that is none.
    #[error("{pattern}: not a pattern ({source})")]
    Pattern {
        pattern: String,
        source: glob::PatternError,
    },
    /// A folder under a pattern that cannot be listed.
    #[error(transparent)]
    Walk(#[from] super::matches::WalkError),
    /// A pattern (as given) that matches no file.
    #[error("{pattern}: no file matches")]
    NoMatch { pattern: String },
}

/// Why one recording of a series has no analysis.
#[derive(Debug, thiserror::Error)]
pub enum EntryError {
    /// Its analysis failed (`file`: the recording, as its entry names it).
    #[error("{error}")]
    Analysis {
        file: PathBuf,
        #[source]
        error: PipelineError,
    },
    /// Its thread panicked.
    #[error("the analysis stopped on an internal error (please report it)")]
    Internal,
}

impl EntryError {
    /// What the error says of its recording: the message without the recording's name
    /// where it would begin with it ([`PipelineError::of_recording`]), for a line that names
    /// the recording first ([`failure`]).
    pub fn of_recording(&self) -> OfEntry<'_> {
        OfEntry(self)
    }
}

/// An [`EntryError`] said of its recording ([`EntryError::of_recording`]).
pub struct OfEntry<'a>(&'a EntryError);

impl std::fmt::Display for OfEntry<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.0 {
            EntryError::Analysis { file, error } => error.of_recording(file).fmt(f),
            e => e.fmt(f),
        }
    }
}

/// The JSON's `error`: the message as the tool prints it.
fn error_message<S: serde::Serializer>(e: &Option<EntryError>, s: S) -> Result<S::Ok, S::Error> {
    match e {
        Some(e) => s.collect_str(e),
        None => s.serialize_none(),
    }
}

/// A failed recording of a series: its file and channel as its entry names them, and why.
#[derive(Debug)]
pub struct Failed {
    pub file: String,
    pub channel: String,
    pub error: EntryError,
}

impl std::fmt::Display for Failed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        Named {
            file: &self.file,
            channel: &self.channel,
            what: self.error.of_recording(),
        }
        .fmt(f)
    }
}

/// One recording of a series: a file and its channel (`None`: the file's default).
#[derive(Clone, Debug)]
pub struct Entry {
    pub file: PathBuf,
    pub column: Option<ColumnRef>,
    /// Its shock direction (`--direction`; none: not asked, or not found).
    pub direction: Option<String>,
}

impl Entry {
    /// The channel as the table and the CSV name it (empty: the file's default).
    pub fn channel(&self) -> String {
        match &self.column {
            Some(ColumnRef::Name(n)) => n.clone(),
            Some(ColumnRef::Index(i)) => i.to_string(),
            None => String::new(),
        }
    }

    /// The channel as the table, the JSON and the figures name it: as given (the series' own
    /// names), else the file's default as it `resolved`.
    pub fn shown_channel(&self, resolved: Option<&str>) -> String {
        match (&self.column, resolved) {
            (None, Some(resolved)) => resolved.to_string(),
            _ => self.channel(),
        }
    }
}

/// Whether `path` is a pattern (`*`, `?`, `[`) rather than a file name.
fn is_pattern(path: &Path) -> bool {
    path.to_string_lossy().contains(['*', '?', '['])
}

/// Whether `files` and `channels` make a series rather than one recording: more than one
/// file, a folder, a pattern, or a list of channels.
pub fn is_series(files: &[PathBuf], channels: &[ColumnRef]) -> bool {
    files.len() > 1 || !channels.is_empty() || files.iter().any(|f| f.is_dir() || is_pattern(f))
}

/// The series' recordings, in the order given: each file (a folder: its recordings by name;
/// a pattern: its matches by name, each file once, [`super::matches`]) with each of `channels` (none: `column`, or the file's
/// default). A file given twice is analysed twice; a folder or pattern that holds no
/// recording, and standard input, are errors.
pub fn entries(
    files: &[PathBuf],
    channels: &[ColumnRef],
    column: Option<&ColumnRef>,
) -> Result<Vec<Entry>, SeriesError> {
    let mut paths = Vec::new();
    for f in files {
        if f.as_os_str() == "-" {
            return Err(SeriesError::Stdin);
        }
        if f.is_dir() {
            let mut found: Vec<PathBuf> = std::fs::read_dir(f)
                .map_err(|source| SeriesError::Folder {
                    path: f.clone(),
                    source,
                })?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.is_file() && is_recording(p))
                .collect();
            found.sort();
            if found.is_empty() {
                return Err(SeriesError::NoRecordings { path: f.clone() });
            }
            paths.extend(found);
        } else if is_pattern(f) && !f.exists() {
            let pattern = f.to_string_lossy();
            let compiled = glob::Pattern::new(&pattern).map_err(|source| SeriesError::Pattern {
                pattern: pattern.to_string(),
                source,
            })?;
            let found = super::matches::files(&pattern, &compiled)?;
            if found.is_empty() {
                return Err(SeriesError::NoMatch {
                    pattern: pattern.to_string(),
                });
            }
            paths.extend(found);
        } else {
            paths.push(f.clone());
        }
    }
    let columns: Vec<Option<ColumnRef>> = if channels.is_empty() {
        vec![column.cloned()]
    } else {
        channels.iter().cloned().map(Some).collect()
    };
    Ok(paths
        .into_iter()
        .flat_map(|file| {
            columns.iter().map(move |column| Entry {
                file: file.clone(),
                column: column.clone(),
                direction: None,
            })
        })
        .collect())
}

/// Gives every entry its direction from `source`; a note names each recording it finds none
/// for (its impacts are grouped as of no direction).
pub fn with_directions(entries: &mut [Entry], source: &super::direction::Direction) {
    for e in entries {
        e.direction = source.of(&e.file, &e.channel());
        if e.direction.is_none() {
            crate::note(
                &Named {
                    file: &e.file.display().to_string(),
                    channel: &e.channel(),
                    what: format!(
                        "no direction ({}): its impacts are grouped as of none",
                        source.words()
                    ),
                }
                .to_string(),
            );
        }
    }
}

fn is_recording(path: &Path) -> bool {
    let hidden = path
        .file_name()
        .is_some_and(|n| n.to_string_lossy().starts_with('.'));
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    !hidden && RECORDING_EXTENSIONS.contains(&ext.as_str())
}

/// One recording's analysis, or why it failed, with the notes it gave.
#[derive(Debug, Serialize)]
pub struct EntryJson {
    pub file: String,
    pub channel: String,
    /// Its shock direction (`--direction`), if asked and found.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub direction: Option<String>,
    #[serde(
        skip_serializing_if = "Option::is_none",
        serialize_with = "error_message"
    )]
    pub error: Option<EntryError>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    pub analysis: Option<AnalysisJson>,
    /// With [`analyze_drawn`]: each impact's pulse as an inline SVG (the report's).
    #[serde(skip)]
    pub figures: Vec<crate::html::Html>,
}

/// Analyses every entry with `args` (its file and channel replaced), on as many threads as
/// the machine has cores (at most one per entry), in the entries' order. Each analysis
/// reads its file as `impact analyze` does, so memory is bounded by the threads' analyses.
pub fn analyze(args: &AnalyzeArgs, entries: &[Entry]) -> Vec<EntryJson> {
    analyze_all(args, entries, false)
}

/// As [`analyze`], each impact's pulse drawn as well (`impact report`).
pub fn analyze_drawn(args: &AnalyzeArgs, entries: &[Entry]) -> Vec<EntryJson> {
    analyze_all(args, entries, true)
}

fn analyze_all(args: &AnalyzeArgs, entries: &[Entry], draw: bool) -> Vec<EntryJson> {
    let next = AtomicUsize::new(0);
    let workers = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(entries.len())
        .max(1);
    let mut done: Vec<(usize, EntryJson)> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..workers)
            .map(|_| {
                scope.spawn(|| {
                    let mut mine = Vec::new();
                    loop {
                        let k = next.fetch_add(1, Ordering::Relaxed);
                        let Some(entry) = entries.get(k) else { break };
                        mine.push((k, analyze_one(args, entry, draw)));
                    }
                    mine
                })
            })
            .collect();
        handles
            .into_iter()
            .flat_map(|h| {
                h.join().unwrap_or_else(|_| {
                    // A panicking analysis is a bug; its entries are reported, not lost.
                    Vec::new()
                })
            })
            .collect()
    });
    done.sort_by_key(|(k, _)| *k);
    // An entry whose thread panicked is missing: named as failed.
    let mut out = Vec::with_capacity(entries.len());
    let mut done = done.into_iter().peekable();
    for (k, entry) in entries.iter().enumerate() {
        match done.next_if(|(j, _)| *j == k) {
            Some((_, json)) => out.push(json),
            None => out.push(EntryJson {
                file: entry.file.display().to_string(),
                channel: entry.channel(),
                direction: entry.direction.clone(),
                error: Some(EntryError::Internal),
                notes: Vec::new(),
                analysis: None,
                figures: Vec::new(),
            }),
        }
    }
    out
}

fn analyze_one(args: &AnalyzeArgs, entry: &Entry, draw: bool) -> EntryJson {
    let mut a = args.clone();
    a.file = entry.file.clone();
    a.column = entry.column.clone();
    // A figure reads its windows in a last pass when the recording is read in passes.
    if draw {
        a.plot = Some(std::path::PathBuf::from("report.svg"));
    }
    let title = |r: &impact_core::ImpactReport, channel: &str| {
        format!(
            "{} [{channel}] impact {}",
            entry.file.file_name().map_or_else(
                || entry.file.display().to_string(),
                |n| n.to_string_lossy().into_owned()
            ),
            r.index,
        )
    };
    let (result, notes) = impact_io::with_own_notes(crate::read_errors::flag, || {
        pipeline::analyze(&a, impact_io::progress::Progress::none()).map(|(setup, reports)| {
            let json = pipeline::to_json(&setup, &reports);
            let channel = entry.shown_channel(json.column.as_deref());
            let figures = if draw {
                reports
                    .iter()
                    .take(super::pulse::MAX_FIGURES)
                    .map(|r| {
                        super::pulse::pulse_svg(
                            &setup.plot_signal(),
                            setup.scene.spec.as_ref(),
                            r,
                            title(r, &channel),
                            None,
                        )
                    })
                    // A recording read in passes holds only the first impacts' windows.
                    .filter(|svg| !svg.is_empty())
                    .collect()
            } else {
                Vec::new()
            };
            (json, figures)
        })
    });
    let (analysis, figures, error) = match result {
        Ok((j, f)) => (Some(j), f, None),
        Err(error) => (
            None,
            Vec::new(),
            Some(EntryError::Analysis {
                file: entry.file.clone(),
                error,
            }),
        ),
    };
    EntryJson {
        file: entry.file.display().to_string(),
        channel: entry.shown_channel(analysis.as_ref().and_then(|a| a.column.as_deref())),
        direction: entry.direction.clone(),
        error,
        notes,
        analysis,
        figures,
    }
}

/// The series as JSON: every recording's analysis (or its error), then the statistics
/// ([`SeriesStatistics`]'s fields, in its order).
#[derive(Debug, Serialize)]
pub struct SeriesJson<'a> {
    pub recordings: usize,
    pub failed: usize,
    #[serde(flatten)]
    pub summary: SeriesStatistics,
    /// With `--direction`: the statistics of each direction's recordings.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub direction_statistics: Vec<DirectionGroup>,
    pub entries: &'a [EntryJson],
}

/// Every impact of the series with its entry, in order.
pub fn impacts(entries: &[EntryJson]) -> impl Iterator<Item = (&EntryJson, &ImpactJson)> + Clone {
    entries.iter().flat_map(|e| {
        e.analysis
            .iter()
            .flat_map(move |a| a.impacts.iter().map(move |i| (e, i)))
    })
}

pub fn to_json(entries: &[EntryJson]) -> SeriesJson<'_> {
    SeriesJson {
        recordings: entries.len(),
        failed: entries.iter().filter(|e| e.error.is_some()).count(),
        summary: series_statistics(impacts(entries).map(|(_, i)| i)),
        direction_statistics: if entries.iter().any(|e| e.direction.is_some()) {
            direction_groups(entries.iter().map(|e| {
                (
                    e.direction.as_deref(),
                    e.analysis.as_ref().map_or(&[][..], |a| &a.impacts[..]),
                )
            }))
        } else {
            Vec::new()
        },
        entries,
    }
}

/// The series as CSV: `analyze --csv`'s columns with `file` and `channel` (and with
/// `--direction`, `direction`) first and
/// `peak_acceleration_g` last, one row per impact of every recording.
pub fn to_csv(entries: &[EntryJson]) -> String {
    let Some(first) = entries.iter().find_map(|e| e.analysis.as_ref()) else {
        return "file,channel\n".into();
    };
    let columns = crate::report::csv::Columns::of(first, impacts(entries).map(|(_, i)| i));
    let mut w = crate::report::csv::writer(Vec::new());
    let directions = entries.iter().any(|e| e.direction.is_some());
    let mut header = vec!["file".to_string(), "channel".to_string()];
    if directions {
        header.push("direction".into());
    }
    header.extend(columns.header());
    header.push("peak_acceleration_g".into());
    // Writing to a Vec cannot fail.
    let _ = w.write_record(&header);
    for (e, i) in impacts(entries) {
        let mut row = vec![
            crate::report::csv::text(&e.file),
            crate::report::csv::text(&e.channel),
        ];
        if directions {
            row.push(crate::report::csv::text(
                e.direction.as_deref().unwrap_or(""),
            ));
        }
        row.extend(columns.row(i));
        // In the f32 digits of the peak it comes from.
        row.push(crate::report::fmt::number(f64::from(
            (i.peak_acceleration_m_s2 / STANDARD_GRAVITY) as f32,
        )));
        let _ = w.write_record(&row);
    }
    String::from_utf8_lossy(&w.into_inner().unwrap_or_default()).into_owned()
}

/// The series as a person reads it: a row per impact, then the statistics, then the
/// recordings that failed.
pub fn to_table(entries: &[EntryJson]) -> String {
    let json = to_json(entries);
    let mut s = format!(
        "series: {} recordings, {} impacts{}\n",
        json.recordings,
        json.summary.impacts,
        if json.failed > 0 {
            format!(", {} FAILED", json.failed)
        } else {
            String::new()
        }
    );
    let rows: Vec<[String; 10]> = impacts(entries)
        .map(|(e, i)| {
            let o = |v: Option<f64>, unit: &str| {
                v.map_or("-".to_string(), |v| human(v, unit).trim_end().to_string())
            };
            [
                e.file.clone(),
                e.channel.clone(),
                i.index.to_string(),
                human(i.start_s, "s"),
                human(i.peak_acceleration_m_s2 / STANDARD_GRAVITY, "g"),
                human(i.peak_acceleration_m_s2, "m/s²"),
                o(i.delta_v_m_s, "m/s"),
                human(i.duration_s, "s"),
                o(i.cor, ""),
                {
                    let verdict = match &i.spec {
                        Some(Some(v)) if v.pass => " PASS",
                        Some(Some(_)) => " FAIL",
                        Some(None) => " not-judged",
                        None => "",
                    };
                    if i.flags.is_empty() {
                        format!("{}{verdict}", i.status)
                    } else {
                        format!("{} {}{verdict}", i.status, i.flags.join(","))
                    }
                },
            ]
        })
        .collect();
    let head = [
        "file", "channel", "#", "start", "peak", "peak", "Δv", "duration", "COR", "status",
    ];
    s.push_str(&columns(&head, &rows));
    if let Some(r) = &json.summary.spec {
        s.push_str(&format!(
            "\nspec: {} of {} judged impacts pass{}{}\n",
            r.passed,
            r.judged,
            r.pass_rate
                .map_or(String::new(), |p| format!(" ({:.1} %)", 100.0 * p)),
            if r.not_judged > 0 {
                format!("; {} NOT JUDGED (see each impact's reason)", r.not_judged)
            } else {
                String::new()
            }
        ));
    }
    if let Some(text) = json.summary.statistics_left_out.text(json.summary.impacts) {
        s.push_str(&format!("\n{text}\n"));
    }
    if !json.summary.statistics.is_empty() {
        s.push_str("\nstatistics (sd: sample standard deviation; CV: sd / |mean|)\n");
        s.push_str(&statistics_table(&json.summary.statistics));
    }
    for g in &json.summary.bounce_statistics {
        s.push_str(&format!(
            "\nstatistics of bounce {} (each drop's, complete and unclipped)\n",
            g.bounce_number
        ));
        s.push_str(&statistics_table(&g.statistics));
    }
    for g in &json.direction_statistics {
        s.push_str(&direction_section(g));
    }
    for e in entries {
        if let Some(err) = &e.error {
            s.push_str(&format!("FAILED {}\n", failure(e, err.of_recording())));
        }
    }
    s
}

/// A direction's lines in the table: its recordings, impacts and verdicts, its statistics.
fn direction_section(g: &DirectionGroup) -> String {
    let mut s = format!(
        "\ndirection {}: {} recording{}, {} impact{}{}\n",
        g.shown(),
        g.recordings,
        if g.recordings == 1 { "" } else { "s" },
        g.summary.impacts,
        if g.summary.impacts == 1 { "" } else { "s" },
        g.summary.spec.as_ref().map_or(String::new(), |r| format!(
            "; spec: {} of {} judged impacts pass{}",
            r.passed,
            r.judged,
            if r.not_judged > 0 {
                format!(", {} NOT JUDGED", r.not_judged)
            } else {
                String::new()
            }
        ))
    );
    if !g.summary.statistics.is_empty() {
        s.push_str(&statistics_table(&g.summary.statistics));
    }
    s
}

/// A recording's line (a failure, a note): its file, its channel if given, and `what` it
/// says of it (an error without the file: [`EntryError::of_recording`]).
pub fn failure(e: &EntryJson, what: impl std::fmt::Display) -> String {
    Named {
        file: &e.file,
        channel: &e.channel,
        what,
    }
    .to_string()
}

/// `FILE: what`, or `FILE channel CHANNEL: what` if a channel is named.
struct Named<'a, D> {
    file: &'a str,
    channel: &'a str,
    what: D,
}

impl<D: std::fmt::Display> std::fmt::Display for Named<'_, D> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.channel.is_empty() {
            write!(f, "{}: {}", self.file, self.what)
        } else {
            write!(f, "{} channel {}: {}", self.file, self.channel, self.what)
        }
    }
}

impl EntryJson {
    /// The recording's failure, if it failed.
    pub fn into_failure(self) -> Option<Failed> {
        Some(Failed {
            error: self.error?,
            file: self.file,
            channel: self.channel,
        })
    }
}

/// A statistics table: a row per metric (n, mean, sd, CV, min, max in its unit).
fn statistics_table(statistics: &[Statistic]) -> String {
    let rows: Vec<[String; 7]> = statistics.iter().map(|st| st.cells("-")).collect();
    columns(&["metric", "n", "mean", "sd", "CV", "min", "max"], &rows)
}

/// Left-aligned columns two spaces apart.
fn columns<const N: usize>(head: &[&str; N], rows: &[[String; N]]) -> String {
    let mut widths = head.map(|h| h.chars().count());
    for r in rows {
        for (w, c) in widths.iter_mut().zip(r) {
            *w = (*w).max(c.chars().count());
        }
    }
    let line = |cells: &mut dyn Iterator<Item = &str>| {
        let mut l = String::new();
        for (k, (c, w)) in cells.zip(widths).enumerate() {
            if k > 0 {
                l.push_str("  ");
            }
            l.push_str(c);
            l.extend(std::iter::repeat_n(' ', w - c.chars().count()));
        }
        l.trim_end().to_string() + "\n"
    };
    let mut s = line(&mut head.iter().copied());
    for r in rows {
        s.push_str(&line(&mut r.iter().map(String::as_str)));
    }
    s
}
