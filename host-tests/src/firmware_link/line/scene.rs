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

/// The target a board's scene line states (owned: a log may state many).
#[derive(Clone, Debug, PartialEq)]
pub enum LineTarget {
    SpringMass(impact_core::two_body::SpringMass<f32>),
    StateSpace(Box<impact_core::two_body::Target<f32>>),
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

    /// The longest impact the core follows, s (`max_impact_s`; `None` if the line lacks it
    /// or it is not a finite time > 0): only a bound on the impacts' sample spans.
    pub fn max_impact_s(&self) -> Option<f64> {
        (self.fields.readable::<f64>("max_impact_s")).filter(|x| x.is_finite() && *x > 0.0)
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

    /// The Butterworth low-pass the board filters with, if the line states one
    /// (`lowpass_order`, `lowpass_cutoff_hz`; absent in an older board's line) the core takes.
    pub fn lowpass(&self) -> Option<impact_core::signal::lowpass::Lowpass> {
        let order = self.fields.readable::<u8>("lowpass_order")?;
        let cutoff = self.fields.readable::<f32>("lowpass_cutoff_hz")?;
        impact_core::signal::lowpass::Lowpass::new(order, cutoff).ok()
    }

    /// The target the board's kinematics are relative to (`target_mass_kg` and its spring and
    /// damper, or `target_space`; absent or `none`: a rigid, fixed barrier, as an older
    /// board's line). A `target_space` that is not a state space's list is an error, not a
    /// rigid barrier: the board's numbers are relative to a target.
    pub fn target(&self) -> Result<Option<LineTarget>, LineError> {
        use impact_core::two_body::{SpringMass, Target, MAX_STATES};
        if let Some(text) = self.fields.get("target_space").filter(|v| *v != "none") {
            let bad = || LineError::SceneTarget {
                text: text.to_string(),
            };
            let mut items = text.split(',');
            let n = (items.next())
                .and_then(|v| v.parse::<usize>().ok())
                .filter(|n| (1..=MAX_STATES).contains(n))
                .ok_or_else(bad)?;
            let values: Vec<f32> = items
                .map(|v| v.parse::<f32>().ok().filter(|x| x.is_finite()))
                .collect::<Option<_>>()
                .filter(|v: &Vec<f32>| v.len() == n * n + 3 * n)
                .ok_or_else(bad)?;
            let mut t = Target::unset(n);
            for (slot, v) in t.entries_mut().zip(values) {
                *slot = v;
            }
            return Ok(Some(LineTarget::StateSpace(Box::new(t))));
        }
        let spring = || {
            Some(SpringMass {
                mass_kg: self.fields.readable::<f32>("target_mass_kg")?,
                stiffness_n_m: self.fields.readable::<f32>("target_stiffness_n_m")?,
                damping_n_s_m: self.fields.readable::<f32>("target_damping_n_s_m")?,
            })
        };
        Ok(spring().map(LineTarget::SpringMass))
    }

    /// The pulse the board judges ([`spec_of`] its fields).
    pub fn spec(&self) -> Result<Option<impact_core::spec::Spec>, LineError> {
        spec_of(&self.fields)
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

/// A user's band read from a scene line, for the program's life: each distinct band once
/// (a log of many restarts repeats one band, and keeps one copy; a band the spec then refuses
/// is kept too). At most 768 B a band (64 rows), one per distinct band the log states.
fn leak_band(u: &[f32], lower: &[f32], upper: &[f32]) -> &'static [impact_core::spec::BandPoint] {
    use impact_core::spec::BandPoint;
    use std::sync::Mutex;
    static KEPT: Mutex<Vec<&'static [BandPoint]>> = Mutex::new(Vec::new());
    let rows: Vec<BandPoint> = u
        .iter()
        .zip(lower)
        .zip(upper)
        .map(|((&u, &lower), &upper)| BandPoint { u, lower, upper })
        .collect();
    let mut kept = KEPT
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    if let Some(found) = kept.iter().find(|k| **k == rows.as_slice()) {
        return found;
    }
    let leaked: &'static [BandPoint] = Box::leak(rows.into_boxed_slice());
    kept.push(leaked);
    leaked
}

/// The pulse a scene line's fields state (`spec` and its `spec_*` fields), as the core's
/// `Spec`: `None` for `spec=none` or a line without the field (an older board's). A user's
/// band is kept for the program's life (each distinct one once: [`leak_band`]).
pub fn spec_of(f: &Fields) -> Result<Option<impact_core::spec::Spec>, LineError> {
    use impact_core::spec::{Shape, Spec, Tolerance};
    let shape = match f.get("spec") {
        None | Some("none") => return Ok(None),
        Some(name) => name,
    };
    let bad = |why: String| LineError::SceneSpec { why };
    let num = |k: &'static str| -> Result<f32, LineError> {
        f.opt::<f32>(k)?.ok_or_else(|| bad(format!("{k}=none")))
    };
    let shape = match shape {
        "half-sine" => Shape::HalfSine,
        "sawtooth" => Shape::Sawtooth,
        "trapezoid" => Shape::Trapezoid {
            rise: num("spec_rise")?,
            fall: num("spec_fall")?,
        },
        other => return Err(bad(format!("{other}: not a shape"))),
    };
    let column = |k: &'static str| -> Result<Option<Vec<f32>>, LineError> {
        match f.get(k) {
            None | Some("none") => Ok(None),
            Some(list) => list
                .split(',')
                .map(|v| v.parse::<f32>().ok().filter(|x| x.is_finite()))
                .collect::<Option<Vec<f32>>>()
                .map(Some)
                .ok_or_else(|| bad(format!("{k}: {list} is not a list of numbers"))),
        }
    };
    let band = match (
        column("spec_band_u")?,
        column("spec_band_lower")?,
        column("spec_band_upper")?,
    ) {
        (None, None, None) => None,
        (Some(u), Some(lo), Some(hi)) if u.len() == lo.len() && u.len() == hi.len() => {
            Some(leak_band(&u, &lo, &hi))
        }
        _ => return Err(bad("the band's three columns differ in length".to_string())),
    };
    let spec = Spec {
        shape,
        peak_m_s2: num("spec_peak_m_s2")?,
        duration_s: num("spec_duration_s")?,
        tolerance: Tolerance {
            band: num("spec_band")?,
            outside: num("spec_outside")?,
            slack: num("spec_slack")?,
            delta_v: num("spec_dv")?,
            before: num("spec_before")?,
            after: num("spec_after")?,
            watch: num("spec_watch")?,
        },
        band,
    };
    spec.validate().map_err(|e| bad(e.to_string()))?;
    Ok(Some(spec))
}
