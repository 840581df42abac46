//! Tables as loggers write them, not only as CSV: columns aligned with spaces (LabVIEW's
//! "Write To Measurement File" text, many DAQ exports), a header whose names a tab separates
//! over rows padded with spaces, lines ending CR CR LF, time in ms. Each is made here from rows
//! of the bundled AFRL record and gives its CSV twin's report; a table whose rows never hold
//! numbers says which line and field kept them from being data, not "no data rows".

mod common;

use std::path::{Path, PathBuf};

use common::{impact, impact_ok, Scratch};

/// `count` rows of AFRL test 1 (its bottom channel, kg_n) from row `first`.
fn afrl(first: usize, count: usize) -> Vec<f64> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("data/afrl-drop-tower/series1_test1_full_100ms.csv");
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .skip(1 + first)
        .take(count)
        .map(|l| l.split(',').nth(1).unwrap().parse().unwrap())
        .collect()
}

/// The report's impact lines (the table, rounded as the user sees it) of `file` in kg_n.
fn impacts(file: &Path) -> Vec<String> {
    impacts_with(file, &["--units", "kgn"])
}

/// The impact lines of `file` analysed with `options`.
fn impacts_with(file: &Path, options: &[&str]) -> Vec<String> {
    let mut args = vec!["analyze", file.to_str().unwrap()];
    args.extend_from_slice(options);
    let (out, err) = impact_ok(&args);
    let lines: Vec<String> = out
        .lines()
        .filter(|l| l.starts_with("impact "))
        .map(String::from)
        .collect();
    assert!(!lines.is_empty(), "{out}{err}");
    lines
}

#[test]
fn space_aligned_tables_read_as_their_csv_twin() {
    let scratch = Scratch::new();
    let values = afrl(5000, 20_000);
    // The twin: plain CSV, time in s at 1 MS/s.
    let mut csv = String::from("time_s,bottom\n");
    for (k, v) in values.iter().enumerate() {
        csv.push_str(&format!("{:.6},{v}\n", k as f64 * 1e-6));
    }
    let twin = scratch.file("twin.csv", csv);
    let want = impacts(&twin);
    let stream = [
        "--units",
        "kgn",
        "--stream",
        "--range",
        "20000g",
        "--trigger",
        "1000g",
    ];
    let streamed = |file: &Path| impacts_with(file, &stream);
    let want_streamed = streamed(&twin);
    // (name, header, a row's format from (time in ms, value), line end)
    type Row = fn(f64, f64) -> String;
    let layouts: [(&str, &str, Row, &str); 5] = [
        // LabVIEW: tab-separated names, rows padded with spaces around a tab, CR CR LF.
        (
            "tab-padded",
            "Time (ms)\tbottom",
            |t, v| format!("{t:>10.3}\t{v:>12}"),
            "\r\r\n",
        ),
        // Names a tab separates, rows aligned with spaces only.
        (
            "tab-header-space-rows",
            "Time (ms)\tbottom",
            |t, v| format!("{t:>10.3}  {v:>12}"),
            "\r\r\n",
        ),
        // Everything aligned with spaces: names two spaces apart, leading spaces.
        (
            "spaces",
            "  Time (ms)    bottom",
            |t, v| format!("  {t:>10.3}    {v:>12}"),
            "\n",
        ),
        // One space between names without spaces, a single space between fields.
        (
            "single-space",
            "time_ms bottom",
            |t, v| format!("{t:.3} {v}"),
            "\r\n",
        ),
        // Tabs and spaces mixed in the rows.
        (
            "mixed",
            "time_ms\tbottom",
            |t, v| format!(" {t:.3} \t  {v}\t"),
            "\n",
        ),
    ];
    for (name, header, row, end) in layouts {
        let mut text = format!("{header}{end}");
        for (k, v) in values.iter().enumerate() {
            text.push_str(&row(k as f64 * 1e-3, *v));
            text.push_str(end);
        }
        let file = scratch.file(&format!("{name}.txt"), text);
        assert_eq!(impacts(&file), want, "{name}");
        // Streamed a block at a time alike.
        assert_eq!(streamed(&file), want_streamed, "{name} --stream");
    }
}

/// Names that cannot be matched to the columns (single spaces between names with spaces
/// inside) are refused with the fix; a unit is never put on a column as its name.
#[test]
fn a_header_whose_names_cannot_be_told_apart_is_refused_with_the_fix() {
    let scratch = Scratch::new();
    let mut text = String::from("Time (ms) Accel (g)\n");
    for k in 0..100 {
        text.push_str(&format!("{:.3} {}\n", k as f64 * 0.01, k % 7));
    }
    let file = scratch.file("ambiguous.txt", text);
    let (code, _, err) = impact(&["analyze", file.to_str().unwrap()]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("line 1) splits into 4 names (\"Time\", \"(ms)\", \"Accel\", \"(g)\")")
            && err.contains("separate the header's names with a tab or two spaces"),
        "{err}"
    );
}

/// A file with rows is never "no data rows" without a reason: rows that all hold text (a
/// clock time, a unit after each number) name the first line after the header and its field.
#[test]
fn rows_that_hold_text_say_which_line_and_field() {
    let scratch = Scratch::new();
    for (name, rows, field) in [
        (
            "clock",
            "12:00:01.000,0.5\n12:00:01.001,0.7\n",
            "12:00:01.000",
        ),
        ("units", "0.000 s,0.5 g\n0.001 s,0.7 g\n", "0.000 s"),
    ] {
        let file = scratch.file(&format!("{name}.csv"), format!("time,accel\n{rows}"));
        let (code, _, err) = impact(&["analyze", file.to_str().unwrap()]);
        assert_eq!(code, 1, "{err}");
        assert!(
            err.contains(&format!(
                "no data rows: all 3 lines hold text; line 2, the first after the header, has {field:?}, not a number"
            )),
            "{name}: {err}"
        );
    }
    // No row at all: the plain message.
    let file = scratch.file("empty.csv", "time,accel\n");
    let (_, _, err) = impact(&["analyze", file.to_str().unwrap()]);
    assert!(err.trim_end().ends_with("no data rows"), "{err}");
}

/// A `;` or `,` table's field with a space inside is not split (a thousands separator would
/// make two numbers of one): it stays an error at its line.
#[test]
fn a_space_inside_a_delimited_field_is_not_a_new_column() {
    let scratch = Scratch::new();
    let file = scratch.file(
        "thousands.csv",
        "time;accel\n0,000;1 234,5\n0,001;1 240,0\n",
    );
    let (code, _, err) = impact(&["analyze", file.to_str().unwrap(), "--decimal-comma"]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("line 2, the first after the header, has \"1 234,5\""),
        "{err}"
    );
}

/// Whether a row splits on white space is the file's, decided by its first data row: a `,`
/// table of two columns whose later row is one quoted field with a space inside (`"1 234"`)
/// is refused at that line for the number it is not (read row by row, it was two numbers
/// under the two names); a one-column table aligned with spaces keeps splitting every row.
#[test]
fn white_space_splits_the_rows_of_a_file_not_of_one_row() {
    let scratch = Scratch::new();
    let file = scratch.file(
        "one-field.csv",
        "time,accel\n0.000,1.0\n0.001,2.0\n\"0.002 3.0\"\n0.003,4.0\n",
    );
    let (code, _, err) = impact(&["analyze", file.to_str().unwrap()]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("one-field.csv:4: not a number"), "{err}");
    assert!(err.contains("\"0.002 3.0\""), "{err}");
    // Aligned with spaces from its first row on: every row splits.
    let file = scratch.file(
        "aligned.txt",
        "time accel\n0.000   1.0\n0.001   2.0\n0.002   3.0\n",
    );
    let (code, _, err) = impact(&["analyze", file.to_str().unwrap()]);
    assert_ne!(code, 1, "{err}");
}

/// `--free-fall FILE:COLUMN` takes any column name the main input takes (a phone's
/// `Acceleration z (m/s^2)`, a slash and spaces in it) and reads each column in the unit its
/// header names, as the main input does: the same fall in m/s² and in g gives the same v0,
/// by name or by index; a column that names no unit is read as g, and a note says so.
#[test]
fn free_fall_columns_take_any_name_and_their_units() {
    let scratch = Scratch::new();
    // An impact at 10 ms (a 2 ms half-sine of 50 g at 100 kS/s).
    let mut main = String::from("time_s,accel_g\n");
    for k in 0..5500 {
        let t = f64::from(k) / 1e5;
        let tt = t - 0.01;
        let a = if (0.0..0.002).contains(&tt) {
            50.0 * (std::f64::consts::PI * tt / 0.002).sin()
        } else {
            0.0
        };
        main.push_str(&format!("{t:.5},{a:.6}\n"));
    }
    let main = scratch.file("drop.csv", main);
    // The holder's DC channel: at rest (1 g) until 2 ms, then free fall until the impact,
    // reading 0.1 g there (a phone's sensor in free fall is no exact zero: 0.98 m/s², which
    // read as g is no free fall).
    let fall = |header: &str, g: f64| {
        let mut text = format!("{header}\n");
        for k in 0..200 {
            let t = f64::from(k) / 1e4;
            let z = if (0.002..0.0101).contains(&t) {
                0.1 * g
            } else {
                g
            };
            text.push_str(&format!("{t:.4},0.01,{z}\n"));
        }
        text
    };
    let ms2 = scratch.file(
        "phone.csv",
        fall(
            "Time (s),Acceleration x (m/s^2),Acceleration z (m/s^2)",
            9.80665,
        ),
    );
    let in_g = scratch.file("g.csv", fall("time_s,x_g,z_g", 1.0));
    let bare = scratch.file("bare.csv", fall("time,x,z", 1.0));
    let v0 = |spec: String| -> (String, String) {
        let (out, err) = impact_ok(&["analyze", main.to_str().unwrap(), "--free-fall", &spec]);
        let head = out.lines().next().unwrap_or_default();
        let v0 = head
            .split("; v0 ")
            .nth(1)
            .unwrap_or_else(|| panic!("{spec}: {out}{err}"))
            .to_string();
        (v0, err)
    };
    let (want, _) = v0(format!("{}:Acceleration z (m/s^2)", ms2.display()));
    assert!(want.starts_with("0.0789"), "{want}");
    assert_eq!(v0(format!("{}:2", ms2.display())).0, want, "by index");
    assert_eq!(v0(format!("{}:z_g", in_g.display())).0, want, "in g");
    let (bare_v0, err) = v0(format!("{}:z", bare.display()));
    assert_eq!(bare_v0, want, "no unit: g");
    assert!(err.contains("z names no unit: read as g"), "{err}");
    assert!(
        err.contains("the time column \"time\" names no unit: read in seconds"),
        "{err}"
    );
    // The JSON lists them with the main input's assumptions; a file that names its units
    // adds none.
    let json = |spec: String| -> serde_json::Value {
        let (out, _) = impact_ok(&[
            "analyze",
            main.to_str().unwrap(),
            "--free-fall",
            &spec,
            "--json",
        ]);
        serde_json::from_str(&out).unwrap()
    };
    let listed = json(format!("{}:z", bare.display()))["assumptions"].clone();
    let listed: Vec<&str> = listed
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|a| a.as_str())
        .filter(|a| a.starts_with("--free-fall"))
        .collect();
    assert_eq!(listed.len(), 2, "{listed:?}");
    assert!(
        listed
            .iter()
            .any(|a| a.ends_with("z names no unit: read as g")),
        "{listed:?}"
    );
    assert!(
        listed
            .iter()
            .any(|a| a.contains("the time column \"time\" names no unit")),
        "{listed:?}"
    );
    let named = json(format!("{}:z_g", in_g.display()))["assumptions"].clone();
    // (No assumption at all: the field is left out.)
    assert!(
        !named.as_array().is_some_and(|a| a
            .iter()
            .any(|a| a.as_str().unwrap_or("").starts_with("--free-fall"))),
        "{named}"
    );
}

/// A unit neither the header nor the options name is assumed aloud: the channel read as g
/// and the time column in seconds, each said in a note naming the column and the option that
/// changes it, marked in the table's head and listed in the JSON; named or given, nothing is
/// assumed (and the numbers are the same as with the assumption stated).
#[test]
fn an_assumed_unit_is_said_where_the_user_looks() {
    let scratch = Scratch::new();
    let mut rows = String::new();
    for k in 0..5000 {
        let t = f64::from(k) / 1e5;
        let tt = t - 0.01;
        let a = if (0.0..0.002).contains(&tt) {
            490.0 * (std::f64::consts::PI * tt / 0.002).sin()
        } else {
            0.0
        };
        rows.push_str(&format!("{t:.5},{a:.4}\n"));
    }
    let bare = scratch.file("bare.csv", format!("time,accel\n{rows}"));
    let named = scratch.file("named.csv", format!("time_s,accel_g\n{rows}"));
    let bare = bare.to_str().unwrap();
    let (table, err) = impact_ok(&["analyze", bare]);
    assert!(
        table.starts_with("accel in g (assumed): 5000 samples at 100000 S/s (time assumed in s)"),
        "{table}"
    );
    assert!(
        err.contains("note: \"accel\" names no unit: its values read as g (give --units")
            && err.contains(
                "note: the time column \"time\" names no unit: read in seconds (give --time-unit"
            ),
        "{err}"
    );
    let (json, _) = impact_ok(&["analyze", bare, "--json"]);
    let j: serde_json::Value = serde_json::from_str(&json).unwrap();
    let assumed = j["assumptions"].as_array().unwrap();
    assert_eq!(assumed.len(), 2, "{json}");
    // The report a lab hands in lists them with the recording's provenance.
    let html = scratch.join("bare.html");
    impact_ok(&["report", bare, "--html", html.to_str().unwrap()]);
    let page = std::fs::read_to_string(&html).unwrap();
    assert_eq!(page.matches("<dt>assumed</dt>").count(), 2, "{page}");
    assert!(
        page.contains("names no unit: its values read as g"),
        "{page}"
    );
    // Stated, or named in the header: nothing assumed, the same numbers.
    for (file, more) in [
        (bare, &["--units", "g", "--time-unit", "s"][..]),
        (named.to_str().unwrap(), &[][..]),
    ] {
        let mut args = vec!["analyze", file, "--json"];
        args.extend_from_slice(more);
        let (out, err) = impact_ok(&args);
        let k: serde_json::Value = serde_json::from_str(&out).unwrap();
        assert!(k.get("assumptions").is_none(), "{out}");
        assert!(!err.contains("names no unit"), "{err}");
        assert_eq!(k["impacts"], j["impacts"]);
    }
}

/// A tab at the start of every line (header too) names no column; an empty first field under
/// a header that names that column would shift every value under its neighbour's name, and
/// is refused with the fix.
#[test]
fn an_empty_edge_field_never_shifts_a_column_under_another_name() {
    let scratch = Scratch::new();
    let mut lead = String::from("\tTime (s)\tAccel (g)\n");
    let mut named = String::from("X_Value\tVoltage\tComment\n");
    for k in 0..200 {
        lead.push_str(&format!("\t{:.4}\t{}\n", f64::from(k) * 1e-3, k % 3));
        named.push_str(&format!("\t{}\t\n", k % 3));
    }
    let lead = scratch.file("lead.txt", lead);
    let (out, _) = impact_ok(&["analyze", lead.to_str().unwrap(), "--json"]);
    let j: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(j["sample_rate_hz"], 1000.0, "{out}");
    let named = scratch.file("named.txt", named);
    let (code, _, err) = impact(&["analyze", named.to_str().unwrap(), "--rate", "1000"]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("named.txt:2: the first field is empty under \"X_Value\"")
            && err.contains("remove \"X_Value\" from the header"),
        "{err}"
    );
}

/// Axes whose headers name different units are refused (one scale took them all: an m/s²
/// axis read in the first axis's g was 9.8× high); axes that name none are each said assumed.
#[test]
fn axes_in_different_units_are_refused_and_unnamed_ones_said() {
    let scratch = Scratch::new();
    let mut mixed = String::from("time_s,ax_g,ay_m_s2,az_m_s2\n");
    let mut bare = String::from("time_s,ax,ay,az\n");
    for k in 0..2000 {
        let t = f64::from(k) / 1e4;
        mixed.push_str(&format!("{t:.4},0.1,0.98,9.8\n"));
        bare.push_str(&format!("{t:.4},0.1,0.1,1.0\n"));
    }
    let mixed = scratch.file("mixed.csv", mixed);
    let (code, _, err) = impact(&[
        "analyze",
        mixed.to_str().unwrap(),
        "--axes",
        "ax_g,ay_m_s2,az_m_s2",
    ]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("--axes: \"ax_g\" is in g, \"ay_m_s2\" in m/s2: give axes in one unit"),
        "{err}"
    );
    let bare = scratch.file("bare.csv", bare);
    let (out, err) = impact_ok(&[
        "analyze",
        bare.to_str().unwrap(),
        "--axes",
        "ax,ay,az",
        "--json",
    ]);
    let j: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(j["assumptions"].as_array().map(Vec::len), Some(3), "{out}");
    for axis in ["ax", "ay", "az"] {
        assert!(err.contains(&format!("\"{axis}\" names no unit")), "{err}");
    }
}

/// A time column that names no unit is read in seconds; when the Δv that gives is beyond any
/// drop or shock test (ms read as s: 1000× too long a pulse), a note names it and the fix,
/// with the Δv under each unit. Stated in ms, or with a plausible Δv, there is no such note.
#[test]
fn a_time_base_that_makes_an_impossible_delta_v_is_named_with_the_fix() {
    let scratch = Scratch::new();
    // AFRL's pulse at 1 MS/s, its time column written in ms under a bare `time`.
    let rows = afrl(0, 20_000);
    let mut ms = String::from("time,accel_kgn\n");
    for (k, g) in rows.iter().enumerate() {
        ms.push_str(&format!("{:.3},{g}\n", k as f64 * 1e-3));
    }
    let bare = scratch.text("bare-ms.csv", &ms);
    let (out, err) = impact_ok(&["analyze", &bare]);
    assert!(out.contains("(time assumed in s)"), "{out}");
    assert!(
        err.contains("note: the time column \"time\" was read in seconds (it names no unit), and impact 0's Δv is then"),
        "{err}"
    );
    assert!(err.contains("give --time-unit ms (Δv 7.6"), "{err}");
    // Told the unit: the pulse's true Δv, no such note.
    let (out, err) = impact_ok(&["analyze", &bare, "--time-unit", "ms"]);
    assert!(out.contains("Δv 7.6"), "{out}");
    assert!(!err.contains("beyond any drop"), "{err}");
    // Read in seconds and plausible (the same pulse with its time in s): no note.
    let mut s = String::from("time,accel_kgn\n");
    for (k, g) in rows.iter().enumerate() {
        s.push_str(&format!("{:.6},{g}\n", k as f64 * 1e-6));
    }
    let plain = scratch.text("bare-s.csv", &s);
    let (_, err) = impact_ok(&["analyze", &plain]);
    assert!(err.contains("names no unit: read in seconds"), "{err}");
    assert!(!err.contains("beyond any drop"), "{err}");
}

/// A force channel without a mass is analysed per kilogram, and says so (a note and the
/// JSON's `assumptions`); with `--mass` nothing is assumed.
#[test]
fn a_force_without_a_mass_is_said_to_be_per_kilogram() {
    let file = format!(
        "{}/data/pyfrf-impact-hammer/measurement_1.csv",
        env!("CARGO_MANIFEST_DIR")
    );
    let (json, err) = impact_ok(&["analyze", &file, "--column", "force_n", "--json"]);
    assert!(
        err.contains("no --mass was given: it is analysed per kilogram"),
        "{err}"
    );
    let j: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert!(
        j["assumptions"]
            .as_array()
            .unwrap()
            .iter()
            .any(|a| a.as_str().unwrap().contains("analysed per kilogram")),
        "{json}"
    );
    let (json, err) = impact_ok(&[
        "analyze", &file, "--column", "force_n", "--mass", "0.2", "--json",
    ]);
    let j: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert!(j.get("assumptions").is_none(), "{json}");
    assert!(!err.contains("per kilogram"), "{err}");
}
