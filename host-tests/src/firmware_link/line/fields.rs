//! The `key=value` fields of one of the firmware's log lines, each read at its own type
//! (floats at their own width, so the firmware's shortest round-trip decimals give back its
//! exact bits).

use std::collections::HashMap;

/// A field of a line that is missing or cannot be read at its type.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum FieldError {
    /// The line lacks the field.
    #[error("missing field {field}")]
    Missing { field: &'static str },
    /// The value is not a number of the field's type.
    #[error("{field}={text}: not a number")]
    NotANumber { field: &'static str, text: String },
    /// A float field that parsed to infinity or NaN (an `f32` written beyond its range).
    #[error("{field}={value}: not finite (a float out of range, or NaN)")]
    NotFinite { field: &'static str, value: f64 },
    /// A flag that is neither `true` nor `false`.
    #[error("{field}={text}: not true or false")]
    NotAFlag { field: &'static str, text: String },
    /// The line gives a key twice (its name as the line spells it).
    #[error("field {key} given twice")]
    Twice { key: String },
}

/// A number a log line may hold: integers, and floats that must be finite (an `f32` field
/// written beyond its range parses to infinity).
pub trait Number: std::str::FromStr + Copy {
    /// The value if it is not finite (floats only), as the error shows it.
    fn non_finite(self) -> Option<f64> {
        None
    }
}

impl Number for u8 {}
impl Number for u16 {}
impl Number for u32 {}
impl Number for u64 {}
impl Number for i64 {}
impl Number for f32 {
    fn non_finite(self) -> Option<f64> {
        (!self.is_finite()).then_some(f64::from(self))
    }
}
impl Number for f64 {
    fn non_finite(self) -> Option<f64> {
        (!self.is_finite()).then_some(self)
    }
}

/// `field=text` as a number, finite.
fn parse<T: Number>(field: &'static str, text: &str) -> Result<T, FieldError> {
    let x = text.parse::<T>().map_err(|_| FieldError::NotANumber {
        field,
        text: text.to_string(),
    })?;
    match x.non_finite() {
        None => Ok(x),
        Some(value) => Err(FieldError::NotFinite { field, value }),
    }
}

/// The `key=value` fields of a line, by key.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Fields(HashMap<String, String>);

impl Fields {
    /// The fields of `text` (what follows a line's marker). Tokens without `=` (decoder
    /// decorations) are skipped; a key given twice is an error.
    pub fn parse(text: &str) -> Result<Self, FieldError> {
        let mut map = HashMap::new();
        for token in text.split_whitespace() {
            if let Some((k, v)) = token.split_once('=') {
                if map.insert(k.to_string(), v.to_string()).is_some() {
                    return Err(FieldError::Twice { key: k.to_string() });
                }
            }
        }
        Ok(Self(map))
    }

    /// Whether the line has `key`.
    pub fn contains(&self, key: &str) -> bool {
        self.0.contains_key(key)
    }

    /// `key`'s text, if the line has it.
    pub fn get(&self, key: &str) -> Option<&str> {
        self.0.get(key).map(String::as_str)
    }

    /// Every field, as the line spells it (in no order).
    pub fn iter(&self) -> impl Iterator<Item = (&str, &str)> {
        self.0.iter().map(|(k, v)| (k.as_str(), v.as_str()))
    }

    /// `field`'s text; missing is an error.
    pub fn text(&self, field: &'static str) -> Result<&str, FieldError> {
        self.get(field).ok_or(FieldError::Missing { field })
    }

    /// `field` as a number; missing is an error.
    pub fn num<T: Number>(&self, field: &'static str) -> Result<T, FieldError> {
        parse(field, self.text(field)?)
    }

    /// `field` as a number or `none`; missing is an error.
    pub fn opt<T: Number>(&self, field: &'static str) -> Result<Option<T>, FieldError> {
        match self.text(field)? {
            "none" => Ok(None),
            v => parse(field, v).map(Some),
        }
    }

    /// `field` as a number if the line has it (a field older firmware did not write).
    pub fn given<T: Number>(&self, field: &'static str) -> Result<Option<T>, FieldError> {
        self.get(field).map(|v| parse(field, v)).transpose()
    }

    /// `field` as `T` if the line has it and it reads as one (a value only shown).
    pub fn readable<T: std::str::FromStr>(&self, field: &str) -> Option<T> {
        self.get(field).and_then(|v| v.parse().ok())
    }

    /// `field` as `true` or `false`; missing is an error.
    pub fn flag(&self, field: &'static str) -> Result<bool, FieldError> {
        match self.text(field)? {
            "true" => Ok(true),
            "false" => Ok(false),
            v => Err(FieldError::NotAFlag {
                field,
                text: v.to_string(),
            }),
        }
    }
}
