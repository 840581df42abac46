//! One contract per wire format: the `impact` log line's fields are `impact_core::report`'s
//! `FIELDS` and `BOUNCE_FIELDS`, between the logger's `seq` and the line's `report_latency_s`.
//! The firmware's defmt format string has to be a literal, so this test reads it out of the
//! reporter's source and holds it to the lists; the host's CSV header and `impact log`'s
//! parser use the lists themselves.

mod common;

use impact_core::report::{BOUNCE_FIELDS, FIELDS};

/// The keys of the firmware's `impact ...` format string, in order.
fn firmware_impact_keys() -> Vec<String> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../firmware/src/tasks/reporter.rs"
    );
    let source = std::fs::read_to_string(path).unwrap();
    let start = source
        .find("\"impact seq=")
        .expect("the reporter's impact line");
    let literal = &source[start + 1..];
    let literal = &literal[..literal.find('"').unwrap()];
    literal
        .split(' ')
        .skip(1)
        .map(|kv| kv.split_once('=').expect("key=value").0.to_string())
        .collect()
}

#[test]
fn the_firmwares_impact_line_has_the_contracts_fields_in_order() {
    let mut want = vec!["seq".to_string()];
    want.extend(FIELDS.iter().map(|s| s.to_string()));
    want.extend(BOUNCE_FIELDS.iter().map(|s| s.to_string()));
    want.push("report_latency_s".to_string());
    assert_eq!(firmware_impact_keys(), want);
}

#[test]
fn the_csv_header_is_the_contracts_fields() {
    let file = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/data/afrl-drop-tower/series1_test1_full_100ms.csv"
    );
    let (csv, _) = common::impact_ok(&["analyze", file, "--csv"]);
    assert_eq!(csv.lines().next().unwrap(), FIELDS.join(","));
}

#[test]
fn impact_log_reads_every_field_of_the_contract_and_names_a_missing_one() {
    let line = |skip: Option<&str>| {
        let mut s = String::from("impact seq=0");
        for k in FIELDS.iter().chain(&BOUNCE_FIELDS) {
            if Some(*k) == skip {
                continue;
            }
            let v = match *k {
                "status" => "complete",
                "analysis" => "full",
                "clipped" => "false",
                "index" | "flags" | "start_sample" | "end_sample" | "decimation" => "1",
                "start_s"
                | "peak_time_s"
                | "peak_acceleration_m_s2"
                | "duration_s"
                | "baseline_m_s2" => "0.5",
                _ => "none",
            };
            s.push_str(&format!(" {k}={v}"));
        }
        s.push_str(" report_latency_s=none\n");
        s
    };
    let log = impact_host::firmware_link::log::parse_log(&line(None)).unwrap();
    assert_eq!(log.impacts.len(), 1);
    for k in FIELDS {
        let parsed = impact_host::firmware_link::log::parse_log(&line(Some(k)));
        if k == "decimation" {
            // Older firmware wrote none: it held every sample.
            assert_eq!(parsed.unwrap().impacts[0].decimation, 1);
            continue;
        }
        let err = parsed.unwrap_err().to_string();
        assert!(err.contains(k), "without {k}: {err}");
    }
}
