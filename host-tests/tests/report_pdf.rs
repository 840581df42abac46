//! `impact report --pdf`: the AFRL series (A4) and the enDAQ `.IDE` recording (Letter)
//! printed, every page rendered to PNG (poppler's `pdftoppm`) and checked: the paper asked
//! for, more than one page, no page blank, nothing in the margins (a table or figure cut at
//! the paper's edge would reach them), and the report's first words on the first page.

use std::path::Path;
use std::process::Command;

mod common;
use common::Scratch;

/// poppler's tools, if installed (`scripts/setup.sh` installs them with Chromium).
fn poppler() -> bool {
    let found = Command::new("pdftoppm")
        .arg("-v")
        .output()
        .is_ok_and(|o| o.status.success() || !o.stderr.is_empty());
    assert!(
        found || std::env::var_os("IMPACT_REQUIRE_BROWSER").is_none(),
        "no pdftoppm: scripts/setup.sh installs poppler-utils"
    );
    if !found {
        eprintln!("skipped: no pdftoppm (scripts/setup.sh installs poppler-utils)");
    }
    found
}

/// `pdfinfo`'s pages and page size (points).
fn info(pdf: &Path) -> (usize, f64, f64) {
    let out = Command::new("pdfinfo").arg(pdf).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout).to_string();
    let field = |name: &str| {
        text.lines()
            .find_map(|l| l.strip_prefix(name))
            .unwrap_or_else(|| panic!("no {name} in {text}"))
            .trim()
            .to_string()
    };
    let pages = field("Pages:").parse().unwrap();
    let size = field("Page size:");
    let mut wh = size
        .split_whitespace()
        .filter_map(|w| w.parse::<f64>().ok());
    (pages, wh.next().unwrap(), wh.next().unwrap())
}

/// Every page as grey levels at `dpi`: (width, height, pixels).
fn pages(pdf: &Path, dpi: u32, scratch: &Scratch) -> Vec<(usize, usize, Vec<u8>)> {
    let prefix = scratch.join("page");
    let out = Command::new("pdftoppm")
        .args(["-r", &dpi.to_string(), "-png"])
        .arg(pdf)
        .arg(&prefix)
        .output()
        .unwrap();
    assert!(out.status.success(), "{out:?}");
    let mut files: Vec<_> = std::fs::read_dir(scratch.join("."))
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.file_name()
                .is_some_and(|n| n.to_string_lossy().starts_with("page-"))
        })
        .collect();
    files.sort_by_key(|p| {
        let n = p.file_stem().unwrap().to_string_lossy().to_string();
        n.rsplit('-').next().unwrap().parse::<u32>().unwrap()
    });
    files
        .iter()
        .map(|f| {
            let decoder =
                png::Decoder::new(std::io::BufReader::new(std::fs::File::open(f).unwrap()));
            let mut reader = decoder.read_info().unwrap();
            let mut buf = vec![0; reader.output_buffer_size().unwrap()];
            let frame = reader.next_frame(&mut buf).unwrap();
            buf.truncate(frame.buffer_size());
            let (w, h) = (frame.width as usize, frame.height as usize);
            // Grey levels whatever the PNG's colour type: each pixel's darkest channel.
            let per = buf.len() / (w * h);
            let grey = buf
                .chunks(per)
                .map(|p| p[..per.min(3)].iter().copied().min().unwrap())
                .collect();
            (w, h, grey)
        })
        .collect()
}

/// Checks every page of `pdf`: `paper` points (±1), at least 2 pages, none blank, nothing
/// within `margin_mm` of an edge (the print margins are 12 mm at the sides, 14 and 16 mm at
/// top and bottom).
fn check(pdf: &Path, paper: (f64, f64), scratch: &Scratch) -> usize {
    let (n, w, h) = info(pdf);
    assert!(
        (w - paper.0).abs() < 1.0 && (h - paper.1).abs() < 1.0,
        "{w} x {h} pt"
    );
    assert!(n >= 2, "{n} pages");
    let dpi = 50;
    let px = |mm: f64| (mm / 25.4 * dpi as f64).floor() as usize;
    let shown = pages(pdf, dpi, scratch);
    assert_eq!(shown.len(), n);
    for (k, (width, height, grey)) in shown.iter().enumerate() {
        let at = |x: usize, y: usize| grey[y * width + x];
        let ink = grey.iter().filter(|&&g| g < 200).count();
        assert!(ink > 500, "page {}: blank ({ink} dark pixels)", k + 1);
        let (side, top, bottom) = (px(10.0), px(12.0), px(14.0));
        for y in 0..*height {
            for x in 0..*width {
                let in_margin = x < side || x >= width - side || y < top || y >= height - bottom;
                if in_margin {
                    assert!(
                        at(x, y) > 235,
                        "page {}: something in the margin at ({x}, {y}) px of {width} x {height} \
                         at {dpi} dpi (a table or figure cut at the paper's edge?)",
                        k + 1
                    );
                }
            }
        }
    }
    n
}

#[test]
fn the_afrl_series_and_the_ide_recording_print_whole_on_a4_and_letter() {
    let scratch = Scratch::new();
    if common::browser::chromium().is_none() || !poppler() {
        return;
    }
    let data = concat!(env!("CARGO_MANIFEST_DIR"), "/data");
    let accel_5 = format!("{data}/afrl-drop-tower/accel_5.csv");
    let high_drop = format!("{data}/endaq-high-drop/High-Drop.IDE");
    let afrl = scratch.join("afrl.pdf");
    let (code, _, err) = common::impact(&[
        "report",
        &accel_5,
        "--channels",
        "1,2,3,4,5",
        "--units",
        "kgn",
        "--spec",
        "half-sine,11000g,0.1ms",
        "--meta",
        "test-id=T-042",
        "--pdf",
        afrl.to_str().unwrap(),
    ]);
    // (The pulses fail the spec: exit status 3, the report written.)
    assert_eq!(code, 3, "{err}");
    assert!(err.contains(&format!("wrote {}", afrl.display())), "{err}");
    let a4 = check(&afrl, (595.0, 842.0), &Scratch::new());
    let ide = scratch.join("ide.pdf");
    let html = scratch.join("ide.html");
    let (code, _, err) = common::impact(&[
        "report",
        &high_drop,
        "--srs",
        "--html",
        html.to_str().unwrap(),
        "--pdf",
        ide.to_str().unwrap(),
        "--paper",
        "letter",
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(html.is_file());
    let letter = check(&ide, (612.0, 792.0), &Scratch::new());
    eprintln!("AFRL series: {a4} A4 pages; the .IDE: {letter} Letter pages");
    // The report's first words head its first page.
    let text = Command::new("pdftotext")
        .args(["-f", "1", "-l", "1"])
        .arg(&afrl)
        .arg("-")
        .output()
        .unwrap();
    let first = String::from_utf8_lossy(&text.stdout);
    assert!(first.trim_start().starts_with("Impact report"), "{first}");
    assert!(first.contains("FAIL") && first.contains("T-042"), "{first}");
}

#[test]
fn without_a_browser_the_pdf_is_refused_with_the_way_out() {
    let scratch = Scratch::new();
    let out = scratch.join("r.pdf");
    let o = Command::new(env!("CARGO_BIN_EXE_impact"))
        .args([
            "report",
            concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/data/afrl-drop-tower/accel_6.csv"
            ),
            "--units",
            "kgn",
            "--pdf",
        ])
        .arg(&out)
        .env("PATH", "/nonexistent")
        .env_remove("IMPACT_CHROMIUM")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("none was found") && err.contains("--html"),
        "{err}"
    );
    assert!(!out.exists());
}
