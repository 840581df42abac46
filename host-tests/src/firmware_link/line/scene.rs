//! The `scene` line: the scene the board runs, once at start-up (the reporter's `log_scene`).

use super::{rate, FieldError, Fields, LineError};

/// A `scene` line. Its rate and gain are checked as it is read; the rest is read when asked
/// (a figure needs the mass, the JSON the approach and the fits asked for), each value at
/// its type, `none` as `None`.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneLine {
    /// Samples per second: finite and > 0.
    pub rate_hz: f32,
    /// m/s² per count, if the line has it.
    pub gain_m_s2_per_count: Option<f32>,
    fields: Fields,
}

impl SceneLine {
    pub fn parse(fields: Fields) -> Result<Self, LineError> {
        Ok(Self {
            rate_hz: rate(&fields)?,
            gain_m_s2_per_count: fields.given("gain_m_s2_per_count")?,
            fields,
        })
    }

    /// Every field, as the line spells it.
    pub fn fields(&self) -> &Fields {
        &self.fields
    }

    /// The gain, which turns the board's counts into m/s².
    pub fn gain(&self) -> Result<f32, FieldError> {
        self.gain_m_s2_per_count.ok_or(FieldError::Missing {
            field: "gain_m_s2_per_count",
        })
    }

    /// The impactor's mass, kg.
    pub fn mass_kg(&self) -> Result<Option<f32>, FieldError> {
        self.fields.opt("mass_kg")
    }

    /// The drop height the approach speed comes from, m.
    pub fn drop_height_m(&self) -> Result<Option<f32>, FieldError> {
        self.fields.opt("drop_height_m")
    }

    /// The approach speed given, m/s.
    pub fn v0_m_s(&self) -> Result<Option<f32>, FieldError> {
        self.fields.opt("v0_m_s")
    }

    /// Whether the scene asks for the two-phase fit.
    pub fn two_phase(&self) -> Result<bool, FieldError> {
        self.fields.flag("two_phase")
    }

    /// Whether the scene asks for the nonlinear fit.
    pub fn nonlinear(&self) -> Result<bool, FieldError> {
        self.fields.flag("nonlinear")
    }

    /// Whether the nonlinear fit fits its exponent.
    pub fn fit_exponent(&self) -> Result<bool, FieldError> {
        self.fields.flag("fit_exponent")
    }

    /// Whether the scene asks for the Hertz fit.
    pub fn hertz(&self) -> Result<bool, FieldError> {
        self.fields.flag("hertz")
    }

    /// Gravity the board takes out of each contact, m/s² (`none`: a horizontal strike; a
    /// line without the field, as a log of an older board, is horizontal too).
    pub fn contact_gravity_m_s2(&self) -> Result<Option<f32>, FieldError> {
        match self.fields.get("gravity_m_s2") {
            None => Ok(None),
            Some(_) => self.fields.opt("gravity_m_s2"),
        }
    }

    /// The bounce train's speed (`flight`, `rebound`), as the line names it, if any.
    pub fn train(&self) -> Option<&str> {
        self.fields.get("train").filter(|t| *t != "none")
    }

    /// The CFC class the board filters with, as the line gives it, if any.
    pub fn cfc(&self) -> Option<&str> {
        self.fields.get("cfc").filter(|c| *c != "none")
    }

    /// The first field (in name order) in which the scene `new` differs from this one.
    pub fn difference(&self, new: &SceneLine) -> Option<SceneDifference> {
        let (first, new) = (&self.fields, &new.fields);
        let mut keys: Vec<&str> = first.iter().chain(new.iter()).map(|(k, _)| k).collect();
        keys.sort_unstable();
        keys.into_iter().find_map(|k| {
            let (old, new) = (first.get(k), new.get(k));
            (old != new).then(|| SceneDifference {
                field: k.to_string(),
                new: new.map(str::to_string),
                old: old.map(str::to_string),
            })
        })
    }
}

/// A field in which two scenes differ: shown `key=new, not key=old` (`absent` for a field one
/// of them lacks).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SceneDifference {
    pub field: String,
    pub new: Option<String>,
    pub old: Option<String>,
}

impl std::fmt::Display for SceneDifference {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let show = |v: &Option<String>| match v {
            Some(v) => format!("{}={v}", self.field),
            None => "absent".to_string(),
        };
        write!(f, "{}, not {}", show(&self.new), show(&self.old))
    }
}
