//! `impact report … --pdf FILE.pdf`: the report's page printed to a paginated PDF (A4 or
//! Letter) by a headless Chromium, with print rules that keep every figure, table row, title
//! block and banner whole on its page and no heading alone at a page's foot.
//!
//! Why a browser: the page is HTML with inline SVG figures, and Chromium lays out and prints
//! it exactly as a reader sees it (the fonts, the figures' text, the tables' widths), where a
//! PDF writer of our own would lay out a second copy of the report. It is found on the PATH
//! (`chromium`, `chromium-browser`, `google-chrome`, `google-chrome-stable`) or named by
//! `IMPACT_CHROMIUM`; `scripts/setup.sh` installs Debian's. It runs on a copy of the page in
//! a private temporary folder (its own profile, no network needed: the page has no script and
//! loads nothing), under a time limit, and its PDF is checked and written whole.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The paper the PDF is printed on.
#[derive(clap::ValueEnum, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Paper {
    /// ISO A4, 210 × 297 mm.
    #[default]
    A4,
    /// US Letter, 8.5 × 11 in.
    Letter,
}

impl Paper {
    fn css(self) -> &'static str {
        match self {
            Paper::A4 => "A4",
            Paper::Letter => "letter",
        }
    }
}

/// How long the browser may take to print a report, s (a series of 50 recordings prints in
/// a few seconds).
const TIME_LIMIT_S: u64 = 120;
/// The largest PDF read back, bytes.
const MAX_PDF_BYTES: u64 = 256 << 20;

/// Why the PDF was not made.
#[derive(Debug, thiserror::Error)]
pub enum PdfError {
    #[error(
        "--pdf prints the report with Chromium, and none was found (chromium, \
         chromium-browser, google-chrome on the PATH, or IMPACT_CHROMIUM naming one): \
         scripts/setup.sh installs it; or write --html and print that"
    )]
    NoBrowser,
    #[error("--pdf: {what}: {source}")]
    Io {
        what: &'static str,
        source: std::io::Error,
    },
    #[error("--pdf: {browser} ended with {status} without printing the report")]
    Failed { browser: String, status: String },
    #[error("--pdf: {browser} had not printed the report after {TIME_LIMIT_S} s (stopped)")]
    TimedOut { browser: String },
    #[error("--pdf: {browser} wrote no PDF (its output is {bytes} bytes, not a PDF)")]
    NotPdf { browser: String, bytes: u64 },
}

/// The print rules added to the page: the paper and its margins, and what must stay whole.
fn print_style(paper: Paper) -> String {
    format!(
        "@page{{size:{} portrait;margin:14mm 12mm 16mm 12mm}}\
@media print{{\
body{{margin:0;max-width:none;font-size:9pt}}\
h1{{font-size:15pt}}h2{{font-size:11.5pt;margin-top:1.1em}}\
h1,h2,h3,h4{{break-after:avoid;page-break-after:avoid}}\
.banner,dl,table.title,.figure,svg,img,tr,thead{{break-inside:avoid;page-break-inside:avoid}}\
table{{font-size:7pt;max-width:100%}}td,th{{padding:.1em .25em}}\
table.verdicts td{{white-space:normal}}\
.figure{{display:block;margin:.4em 0}}.figure svg,.figure img{{max-width:100%;height:auto}}\
.hash,code,td.l{{overflow-wrap:anywhere;word-break:break-all}}\
*{{-webkit-print-color-adjust:exact;print-color-adjust:exact}}}}",
        paper.css()
    )
}

/// The browser to print with: `IMPACT_CHROMIUM`, else the first Chromium on the PATH.
fn browser() -> Option<PathBuf> {
    if let Some(given) = std::env::var_os("IMPACT_CHROMIUM") {
        return Some(PathBuf::from(given));
    }
    let path = std::env::var_os("PATH")?;
    [
        "chromium",
        "chromium-browser",
        "google-chrome",
        "google-chrome-stable",
    ]
    .iter()
    .flat_map(|name| std::env::split_paths(&path).map(move |dir| dir.join(name)))
    .find(|p| p.is_file())
}

/// Prints `page` (the report's HTML) on `paper` into `out` (written whole, or not at all).
pub fn print(page: &str, paper: Paper, out: &Path) -> Result<(), PdfError> {
    let browser = browser().ok_or(PdfError::NoBrowser)?;
    let name = browser.display().to_string();
    let io = |what| move |source| PdfError::Io { what, source };
    let dir = tempfile::Builder::new()
        .prefix("impact-pdf-")
        .tempdir()
        .map_err(io("a temporary folder"))?;
    let html = dir.path().join("report.html");
    let style = format!("<style>{}</style></head>", print_style(paper));
    let printable = page.replacen("</head>", &style, 1);
    std::fs::write(&html, printable).map_err(io("the page for the browser"))?;
    let pdf = dir.path().join("report.pdf");
    let mut cmd = Command::new(&browser);
    cmd.args(["--headless", "--disable-gpu", "--no-pdf-header-footer"])
        .arg(format!(
            "--user-data-dir={}",
            dir.path().join("profile").display()
        ))
        .arg(format!("--print-to-pdf={}", pdf.display()))
        .arg(url_of(&html))
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null());
    // Chromium will not start as root with its sandbox (a CI container); the page it renders
    // is our own, with no script and nothing to load.
    // SAFETY: geteuid has no preconditions.
    if unsafe { libc::geteuid() } == 0 {
        cmd.arg("--no-sandbox");
    }
    {
        use std::os::unix::process::CommandExt;
        // Its own process group: its renderers end with it on a time-out.
        cmd.process_group(0);
    }
    let mut child = cmd.spawn().map_err(io("the browser not started"))?;
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().map_err(io("the browser"))? {
            break status;
        }
        if start.elapsed() > Duration::from_secs(TIME_LIMIT_S) {
            // SAFETY: kill(2) on the group this child leads.
            unsafe { libc::kill(-(child.id() as i32), libc::SIGKILL) };
            let _ = child.wait();
            return Err(PdfError::TimedOut { browser: name });
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    let bytes = read_pdf(&pdf).map_err(io("the printed PDF"))?;
    match bytes {
        Some(b) if b.starts_with(b"%PDF-") => {
            crate::output::write(out, &b).map_err(|e| PdfError::Io {
                what: "the PDF not written",
                source: std::io::Error::other(e.to_string()),
            })
        }
        Some(b) => Err(PdfError::NotPdf {
            browser: name,
            bytes: b.len() as u64,
        }),
        None if status.success() => Err(PdfError::NotPdf {
            browser: name,
            bytes: 0,
        }),
        None => Err(PdfError::Failed {
            browser: name,
            status: status.to_string(),
        }),
    }
}

/// The printed PDF, if the browser wrote one (at most [`MAX_PDF_BYTES`]).
fn read_pdf(path: &Path) -> std::io::Result<Option<Vec<u8>>> {
    let file = match std::fs::File::open(path) {
        Ok(f) => f,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(e),
    };
    let mut bytes = Vec::new();
    file.take(MAX_PDF_BYTES).read_to_end(&mut bytes)?;
    Ok(Some(bytes))
}

/// A `file://` URL of an absolute path, every byte outside the unreserved set escaped.
fn url_of(path: &Path) -> String {
    use std::os::unix::ffi::OsStrExt;
    let mut url = String::from("file://");
    for &b in path.as_os_str().as_bytes() {
        if b.is_ascii_alphanumeric() || b"/-._~".contains(&b) {
            url.push(b as char);
        } else {
            url.push_str(&format!("%{b:02X}"));
        }
    }
    url
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_path_becomes_a_file_url_with_its_odd_bytes_escaped() {
        assert_eq!(
            url_of(Path::new("/tmp/a b/r#1?.html")),
            "file:///tmp/a%20b/r%231%3F.html"
        );
    }

    #[test]
    fn the_paper_is_the_page_rule() {
        assert!(print_style(Paper::A4).starts_with("@page{size:A4 portrait;"));
        assert!(print_style(Paper::Letter).starts_with("@page{size:letter portrait;"));
    }
}
