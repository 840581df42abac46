//! Arbitrary bytes as a CSV recording: `read_csv` must return a channel or an error, never
//! panic, with the default options and with a given sample rate (which skips the time column),
//! with the sniffed delimiter and with `;` and decimal commas.

#![no_main]

use std::path::PathBuf;

use impact_io::channel::CsvFormat;
use impact_io::channel::ReadOptions;
use impact_io::recording::read_csv;
use libfuzzer_sys::fuzz_target;

fn path() -> PathBuf {
    std::env::temp_dir().join(format!("impact-fuzz-csv-{}.csv", std::process::id()))
}

fuzz_target!(|data: &[u8]| {
    let path = path();
    std::fs::write(&path, data).expect("temp file");
    let formats = [
        CsvFormat::default(),
        CsvFormat {
            delimiter: Some(b';'),
            decimal_comma: true,
        },
    ];
    for (rate_hz, format) in [None, Some(1000.0), Some(f64::NAN), Some(0.0), Some(-1.0)]
        .into_iter()
        .flat_map(|r| formats.map(|f| (r, f)))
    {
        let opts = ReadOptions {
            rate_hz,
            format,
            ..ReadOptions::default()
        };
        if let Ok(ch) = read_csv(&path, &opts) {
            assert_eq!(ch.values.len(), ch.time_s.len(), "one time per sample");
        }
    }
});
