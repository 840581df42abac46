//! Value parsers the options share.

/// A command-line number that must be finite and > 0.
pub fn positive_f64(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        Ok(_) => Err("must be finite and > 0".into()),
        Err(_) => Err("not a number".into()),
    }
}
