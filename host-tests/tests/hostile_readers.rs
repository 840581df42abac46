//! Hostile input, round four: the readers' size fields and non-regular inputs. A size a file
//! declares is checked against the bytes there are before anything is allocated or parsed by
//! it; a FIFO or a device is read as standard input is, in bounded memory.

use std::path::Path;
use std::time::{Duration, Instant};

mod common;
use common::{assert_refused, impact, Scratch};

/// An `.npy` file: the magic, `version`, the header (padded to 64 bytes as numpy pads it,
/// or its length declared as `declared` if given), then `data`.
fn npy(version: u8, header: &str, declared: Option<u32>, data: &[u8]) -> Vec<u8> {
    let prefix = if version == 1 { 10 } else { 12 };
    let mut h = header.to_string();
    while (prefix + h.len() + 1) % 64 != 0 {
        h.push(' ');
    }
    h.push('\n');
    let mut out = b"\x93NUMPY".to_vec();
    out.extend([version, 0]);
    let len = declared.unwrap_or(h.len() as u32);
    if version == 1 {
        out.extend((len as u16).to_le_bytes());
    } else {
        out.extend(len.to_le_bytes());
    }
    out.extend(h.as_bytes());
    out.extend(data);
    out
}

/// `impact analyze FILE --rate 1000` is refused within `within`, naming `want`.
fn refused_in(file: &Path, want: &str, within: Duration) {
    let t = Instant::now();
    let f = file.to_str().unwrap();
    let (code, _, err) = impact(&["analyze", f, "--rate", "1000"]);
    assert!(t.elapsed() < within, "{f}: {:?}", t.elapsed());
    assert_refused(Some(code), &err, want, f);
}

/// A v2 header declaring 4 GiB aborted the tool (`memory allocation … failed`); one of brackets
/// nested 20 deep in 130 bytes hung it (time doubling per level). Both are refused at once,
/// naming what is wrong; a well-formed array beside them still reads.
#[test]
fn an_npy_header_is_checked_before_it_is_parsed() {
    let scratch = Scratch::new();
    let data: Vec<u8> = (0..2000)
        .flat_map(|i| f64::from(i % 7).to_le_bytes())
        .collect();
    let good = "{'descr': '<f8', 'fortran_order': False, 'shape': (2000,), }";
    let ok = scratch.file("ok.npy", npy(1, good, None, &data));
    let (code, _, err) = impact(&["analyze", ok.to_str().unwrap(), "--rate", "1000"]);
    assert_eq!(code, 0, "{err}");
    let ok2 = scratch.file("ok2.npy", npy(2, good, None, &data));
    let (code, _, err) = impact(&["analyze", ok2.to_str().unwrap(), "--rate", "1000"]);
    assert_eq!(code, 0, "{err}");
    let huge = scratch.file("huge.npy", npy(2, good, Some(u32::MAX), &data));
    refused_in(
        &huge,
        "the header declares 4294967295 bytes, but the file holds 16116 after its prefix",
        Duration::from_secs(5),
    );
    let past = scratch.file("past.npy", npy(1, good, Some(60_000), &data[..64]));
    refused_in(
        &past,
        "the header declares 60000 bytes",
        Duration::from_secs(5),
    );
    let deep = format!(
        "{{'descr': '<f8', 'fortran_order': False, 'shape': {}2000,{} }}",
        "(".repeat(20),
        ")".repeat(20)
    );
    let nested = scratch.file("nested.npy", npy(1, &deep, None, &data));
    refused_in(
        &nested,
        "the header nests brackets 21 deep",
        Duration::from_secs(5),
    );
}
