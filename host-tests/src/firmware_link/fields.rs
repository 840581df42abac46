//! The `key=value` fields of the firmware's log lines, each parsed at its own type (floats at
//! their own width, so the firmware's shortest round-trip decimals give back its exact bits).

use std::collections::HashMap;

/// The `key=value` fields following `marker` (e.g. `"impact "`) in a decoded line, or `None`
/// if the line is not such a line. Tokens without `=` (decoder decorations) are skipped.
pub(crate) fn fields(line: &str, marker: &str) -> Option<Result<HashMap<String, String>, String>> {
    // The marker at the start of the message: at the start of the line or after a space
    // (defmt-print puts a time stamp and the level first).
    let at = line
        .match_indices(marker)
        .map(|(i, _)| i)
        .find(|&i| i == 0 || line[..i].ends_with(' '))?;
    let rest = &line[at + marker.len()..];
    // The first token must be a field, so that a prose message starting with the same word
    // is not taken for one.
    if !rest.split_whitespace().next()?.contains('=') {
        return None;
    }
    let mut map = HashMap::new();
    for token in rest.split_whitespace() {
        if let Some((k, v)) = token.split_once('=') {
            if map.insert(k.to_string(), v.to_string()).is_some() {
                return Some(Err(format!("field {k} given twice")));
            }
        }
    }
    Some(Ok(map))
}

pub(crate) fn get<'a>(m: &'a HashMap<String, String>, key: &str) -> Result<&'a str, String> {
    m.get(key)
        .map(String::as_str)
        .ok_or_else(|| format!("missing field {key}"))
}

/// A number a log line may hold: integers, and floats that must be finite (an `f32` field
/// written beyond its range parses to infinity).
pub(crate) trait Number: std::str::FromStr + std::fmt::Display {
    fn is_finite(&self) -> bool {
        true
    }
}

impl Number for u8 {}
impl Number for u16 {}
impl Number for u32 {}
impl Number for u64 {}
impl Number for i64 {}
impl Number for f32 {
    fn is_finite(&self) -> bool {
        f32::is_finite(*self)
    }
}
impl Number for f64 {
    fn is_finite(&self) -> bool {
        f64::is_finite(*self)
    }
}

/// `key=v` as a number, finite.
pub(crate) fn parse<T: Number>(key: &str, v: &str) -> Result<T, String> {
    let x = v
        .parse::<T>()
        .map_err(|_| format!("{key}={v}: not a number"))?;
    if x.is_finite() {
        Ok(x)
    } else {
        Err(format!(
            "{key}={x}: not finite (a float out of range, or NaN)"
        ))
    }
}

pub(crate) fn num<T: Number>(m: &HashMap<String, String>, key: &str) -> Result<T, String> {
    parse(key, get(m, key)?)
}

pub(crate) fn opt<T: Number>(m: &HashMap<String, String>, key: &str) -> Result<Option<T>, String> {
    match get(m, key)? {
        "none" => Ok(None),
        v => parse(key, v).map(Some),
    }
}

pub(crate) fn flag(m: &HashMap<String, String>, key: &str) -> Result<bool, String> {
    match get(m, key)? {
        "true" => Ok(true),
        "false" => Ok(false),
        v => Err(format!("{key}={v}: not true or false")),
    }
}
