//! The bench the monitor measures: compiled in for the board, given on the semihosting
//! command line in the emulator (so that the host can hand over exactly the [`Scene`] that
//! `impact analyze` builds).

#[cfg(target_os = "none")]
use impact_core::spec::{BandPoint, MAX_BAND_POINTS};
use impact_core::{Approach, Calibration, FitSet, Scene, Train, TrainSpeed};
#[cfg(target_os = "none")]
use static_cell::ConstStaticCell;

/// The seed bench's approach speed, m/s (a light gate may override it per impact through
/// the firmware binary's `tasks::stream::APPROACH_SPEED`).
pub const BENCH_V0_M_S: f32 = 1.3357;

/// ADC: 12 bits over ±800 m/s², so 1600 / 4096 m/s² per count (exact in binary).
#[cfg(not(feature = "adxl375"))]
const CALIBRATION: Calibration = Calibration {
    gain_m_s2_per_count: 1600.0 / 4096.0,
    sample_rate_hz: crate::SAMPLE_RATE_HZ as f32,
};
/// ADC rails: codes 0 and 4095 mean the sensor (or the ADC) is saturated.
#[cfg(not(feature = "adxl375"))]
const CLIP_COUNTS: (i16, i16) = (0, 4095);

/// ADXL375: 49 mg per LSB at 3200 S/s.
#[cfg(feature = "adxl375")]
const CALIBRATION: Calibration = Calibration {
    gain_m_s2_per_count: crate::adxl375::G_PER_LSB * crate::adxl375::STANDARD_GRAVITY_M_PER_S2,
    sample_rate_hz: crate::SAMPLE_RATE_HZ as f32,
};
/// ADXL375: 13-bit two's-complement output per axis (±200 g is about ±4082 counts); the
/// stream is the magnitude of the axes each zeroed (never negative), which reaches
/// [`crate::adxl375::RESULTANT_CLIP`] (4031) whenever an axis is at its rail and its zero
/// lies within 3.1 g of 0: `clipped` then means an axis may have clipped (conservative: a
/// large hit spread over axes is marked too; an axis at its rail with its zero further than
/// 3.1 g toward that rail, held for the settle time before the hit, is missed).
/// One axis (`adxl375::AXIS`) has both rails, -4096 and 4095.
#[cfg(feature = "adxl375")]
const CLIP_COUNTS: (i16, i16) = if crate::adxl375::AXIS.is_resultant() {
    (i16::MIN, crate::adxl375::RESULTANT_CLIP)
} else {
    crate::adxl375::AXIS_RAILS
};

/// The seed bench's approach speed.
#[cfg(not(feature = "adxl375"))]
const APPROACH: Approach = Approach::Speed {
    v0_m_s: BENCH_V0_M_S,
};
/// ADXL375: the seed bench's approach speed if the stream is the axis along the impact; none
/// for the resultant, whose integral is no velocity change (the host's `--axes` gives none
/// either): set `adxl375::AXIS` to that axis for kinematics and fits.
#[cfg(feature = "adxl375")]
const APPROACH: Approach = if crate::adxl375::AXIS.is_resultant() {
    Approach::Unknown
} else {
    Approach::Speed {
        v0_m_s: BENCH_V0_M_S,
    }
};

/// The seed bench (60 g body at 1.3357 m/s): trigger at 10 m/s², edges at 2 m/s², 2 ms hold,
/// 1 s longest impact, no CFC filter; two-phase, nonlinear (exponent fitted) and Hertz fits;
/// no bounce trains (a vertical drop that bounces sets `train: Some(Train::new())`: each
/// bounce then takes its approach speed from its flight; a horizontal bench must not).
pub const BENCH: Scene = Scene {
    calibration: CALIBRATION,
    mass_kg: Some(0.06),
    approach: APPROACH,
    trigger_m_s2: 10.0,
    edge_m_s2: 2.0,
    hold_s: 2e-3,
    max_impact_s: 1.0,
    settle_s: 0.05,
    clip_counts: CLIP_COUNTS,
    cfc: None,
    lowpass: None,
    trigger_cfc: None,
    // The exponent is fitted, as on the host (`impact bench m4`: the whole analysis of the
    // seed impact, all three fits included, costs about 1.5 M instructions, ~12 ms).
    fits: FitSet {
        two_phase: true,
        nonlinear: true,
        fit_exponent: true,
        nonlinear_exponent: 1.0,
        hertz: true,
    },
    // A horizontal strike: no gravity in the contact (a drop height, a train or
    // `vertical: true` puts it there, see `Scene::contact_gravity_m_s2`).
    gravity_m_s2: impact_core::consts::STANDARD_GRAVITY as f32,
    vertical: false,
    v0_every: false,
    train: None,
    spectrum: None,
    spec: None,
    // The captured windows stay on the board (`wave=1` in the emulator sends them).
    waveform_every: 0,
    target: None,
};

/// Why [`band_table`] gave no table.
#[cfg(target_os = "none")]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BandTableError<E> {
    /// The table was taken already: one band per run.
    Taken,
    /// More than [`MAX_BAND_POINTS`] rows.
    TooManyRows,
    /// A row could not be read.
    Row(E),
}

/// A user's band read at start-up (the emulator's `spec_table`, the M4 bench's `spec_rows`),
/// in the one static table a scene's spec can borrow ([`impact_core::spec::Spec::band`]; on
/// the STM32 the band is a `static` in flash instead). The table takes 768 bytes of RAM where
/// this is called; a second call is refused.
#[cfg(target_os = "none")]
pub fn band_table<E>(
    rows: impl IntoIterator<Item = Result<BandPoint, E>>,
) -> Result<&'static [BandPoint], BandTableError<E>> {
    static TABLE: ConstStaticCell<[BandPoint; MAX_BAND_POINTS]> =
        ConstStaticCell::new([BandPoint::ZERO; MAX_BAND_POINTS]);
    let table = TABLE.try_take().ok_or(BandTableError::Taken)?;
    let mut n = 0;
    for row in rows {
        *table.get_mut(n).ok_or(BandTableError::TooManyRows)? = row.map_err(BandTableError::Row)?;
        n += 1;
    }
    let table: &'static [BandPoint; MAX_BAND_POINTS] = table;
    table.get(..n).ok_or(BandTableError::TooManyRows)
}

/// A state-space target from `n:A (row by row):B:C (displacement's row, velocity's)`, in the
/// one static a scene's target can borrow ([`impact_core::two_body::SceneTarget`]; on the
/// STM32 a `static` in flash in [`BENCH`] instead). The static lies in the CCM RAM beside the
/// analysis's workspace (its 240 bytes do not fit the emulator's data RAM; written here,
/// after start-up zeroed it). A second call, a wrong count of numbers or one that is not a
/// number is a bad value; `Scene::validate` checks the target.
#[cfg(target_os = "none")]
fn target_space(value: &str) -> Result<&'static impact_core::two_body::Target<f32>, SceneError> {
    use impact_core::two_body::{Target, MAX_STATES};
    #[link_section = ".ccmram.target"]
    static TARGET: static_cell::StaticCell<Target<f32>> = static_cell::StaticCell::new();
    let mut values = value.split(':');
    let n = (values.next())
        .and_then(|v| v.parse::<usize>().ok())
        .filter(|n| (1..=MAX_STATES).contains(n))
        .ok_or(SceneError::BadValue)?;
    let mut t = Target::unset(n);
    for slot in t.entries_mut() {
        let v = values.next().ok_or(SceneError::BadValue)?;
        *slot = v.parse::<f32>().map_err(|_| SceneError::BadValue)?;
    }
    if values.next().is_some() {
        return Err(SceneError::BadValue);
    }
    TARGET.try_init(t).map(|t| &*t).ok_or(SceneError::BadValue)
}

/// Off the board (the library on the host): no static to keep a target in.
#[cfg(not(target_os = "none"))]
fn target_space(_: &str) -> Result<&'static impact_core::two_body::Target<f32>, SceneError> {
    Err(SceneError::BadValue)
}

/// Why a `key=value` scene argument was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(not(feature = "emulator"), allow(dead_code))]
pub enum SceneError {
    /// Not one of the keys below.
    UnknownKey,
    /// The value does not parse as the key's type.
    BadValue,
}

#[cfg(target_os = "none")]
impl defmt::Format for SceneError {
    fn format(&self, f: defmt::Formatter<'_>) {
        match self {
            SceneError::UnknownKey => defmt::write!(f, "unknown key"),
            SceneError::BadValue => defmt::write!(f, "bad value"),
        }
    }
}

/// Applies one `key=value` scene argument to `scene`. Keys (SI units; `none` clears an
/// optional value):
///
/// | key | value |
/// |---|---|
/// | `gain` | m/s² per count (f32, negative inverts) |
/// | `rate` | samples per second (f32) |
/// | `mass` | kg, or `none` |
/// | `v0` | approach speed, m/s, or `none` (unknown) |
/// | `drop_height` | drop height, m (`v0 = sqrt(2 g h)`) |
/// | `trigger`, `edge` | levels, m/s² |
/// | `hold`, `max_impact`, `settle` | s |
/// | `clip` | `LOW:HIGH` rails in counts (i16) |
/// | `cfc`, `trigger_cfc` | 60, 180, 600, 1000 or `none` |
/// | `lowpass` | a Butterworth low-pass on the captured windows, `ORDER:CUTOFF` (1 to 8, Hz: `4:1000`; a colon, as semihosting passes no comma), or `none` |
/// | `two_phase`, `nonlinear`, `fit_exponent`, `hertz` | `0` or `1` |
/// | `exponent` | nonlinear exponent when not fitted (f32) |
/// | `train` | bounce trains: `flight`, `rebound` (which speed the kinematics use) or `none` |
/// | `gravity` | gravity along the sensor's axis, m/s² (a vertical contact's, a drop's, a train's flights) |
/// | `vertical` | `0` or `1`: gravity in the contact although neither a drop height nor a train says so |
/// | `v0_every` | `0` or `1`: every impact comes at `v0` (else an impact that follows a flight has no approach speed unless a train measures it) |
/// | `max_flight` | a train's longest flight, s |
/// | `srs` | `0` or `1`: shock spectra per impact |
/// | `srs_damping`, `srs_bands`, `srs_low`, `srs_high` | damping ratio, bands per octave (6, 12), lowest band, Hz, highest band, Hz (`none`: rate / 8) |
/// | `spec` | judge each impact against a specified pulse: `half-sine`, `sawtooth`, `trapezoid` or `none` |
/// | `spec_peak`, `spec_duration` | its peak, m/s², and duration, s |
/// | `spec_band`, `spec_outside`, `spec_slack`, `spec_dv`, `spec_before`, `spec_after`, `spec_watch` | its tolerances ([`impact_core::spec::Tolerance`]) |
/// | `spec_rise`, `spec_fall` | a trapezoid's ramps, × the duration (after `spec=trapezoid`) |
/// | `spec_table` | emulator only, not here: a file of the user's band ([`impact_core::spec::Spec::band`]), read by the emulator board; on the STM32 set `band: Some(&BAND)` of a `static` table in [`BENCH`]'s spec (docs/standards.md) |
/// | `wave` | send each captured window: `0` not, `1` whole, `N` the mean of every `N` samples |
/// | `target_mass` | the target the body strikes, kg (a mass on a spring and damper to ground: the kinematics are the contact's), or `none` (a rigid, fixed barrier) |
/// | `target_stiffness`, `target_damping` | its spring, N/m, and damper, N s/m, to ground (after `target_mass`; 0 without them) |
/// | `target_space` | or a linear target in state-space form ([`impact_core::two_body::Target`]), `:`-separated: its order `n` (1 to 6), `A` row by row, `B`, `C` (the displacement's row, then the velocity's); once a run (kept in one static: [`target_space`]) |
///
/// Floats are parsed by `core`'s correctly rounded parser, so the shortest round-trip decimal
/// of an `f32` (Rust's `{}` or `{:e}`) gives back exactly that `f32`.
#[cfg_attr(not(feature = "emulator"), allow(dead_code))]
pub fn apply(scene: &mut Scene, key: &str, value: &str) -> Result<(), SceneError> {
    fn float(v: &str) -> Result<f32, SceneError> {
        v.parse::<f32>().map_err(|_| SceneError::BadValue)
    }
    fn opt_float(v: &str) -> Result<Option<f32>, SceneError> {
        if v == "none" {
            Ok(None)
        } else {
            float(v).map(Some)
        }
    }
    fn flag(v: &str) -> Result<bool, SceneError> {
        match v {
            "0" | "false" => Ok(false),
            "1" | "true" => Ok(true),
            _ => Err(SceneError::BadValue),
        }
    }
    fn cfc(v: &str) -> Result<Option<impact_core::signal::cfc::Cfc>, SceneError> {
        if v == "none" {
            return Ok(None);
        }
        let class = v.parse::<u32>().map_err(|_| SceneError::BadValue)?;
        impact_core::signal::cfc::Cfc::from_class(class)
            .map(Some)
            .ok_or(SceneError::BadValue)
    }
    fn lowpass(v: &str) -> Result<Option<impact_core::signal::lowpass::Lowpass>, SceneError> {
        if v == "none" {
            return Ok(None);
        }
        let (order, cutoff) = v.split_once(':').ok_or(SceneError::BadValue)?;
        let order = order.parse::<u8>().map_err(|_| SceneError::BadValue)?;
        impact_core::signal::lowpass::Lowpass::new(order, float(cutoff)?)
            .map(Some)
            .map_err(|_| SceneError::BadValue)
    }
    match key {
        "gain" => scene.calibration.gain_m_s2_per_count = float(value)?,
        "rate" => scene.calibration.sample_rate_hz = float(value)?,
        "mass" => scene.mass_kg = opt_float(value)?,
        "v0" => {
            scene.approach = match opt_float(value)? {
                Some(v0_m_s) => Approach::Speed { v0_m_s },
                None => Approach::Unknown,
            }
        }
        "drop_height" => {
            scene.approach = Approach::DropHeight {
                height_m: float(value)?,
            }
        }
        "trigger" => scene.trigger_m_s2 = float(value)?,
        "edge" => scene.edge_m_s2 = float(value)?,
        "hold" => scene.hold_s = float(value)?,
        "max_impact" => scene.max_impact_s = float(value)?,
        "settle" => scene.settle_s = float(value)?,
        "clip" => {
            let (lo, hi) = value.split_once(':').ok_or(SceneError::BadValue)?;
            let lo = lo.parse::<i16>().map_err(|_| SceneError::BadValue)?;
            let hi = hi.parse::<i16>().map_err(|_| SceneError::BadValue)?;
            scene.clip_counts = (lo, hi);
        }
        "cfc" => scene.cfc = cfc(value)?,
        "lowpass" => scene.lowpass = lowpass(value)?,
        "trigger_cfc" => scene.trigger_cfc = cfc(value)?,
        "two_phase" => scene.fits.two_phase = flag(value)?,
        "nonlinear" => scene.fits.nonlinear = flag(value)?,
        "fit_exponent" => scene.fits.fit_exponent = flag(value)?,
        "hertz" => scene.fits.hertz = flag(value)?,
        "exponent" => scene.fits.nonlinear_exponent = float(value)?,
        "train" => {
            let speed = match value {
                "none" => {
                    scene.train = None;
                    return Ok(());
                }
                "flight" => TrainSpeed::Flight,
                "rebound" => TrainSpeed::Rebound,
                _ => return Err(SceneError::BadValue),
            };
            scene.train = Some(Train {
                speed,
                ..scene.train.unwrap_or_default()
            });
        }
        "srs" => {
            scene.spectrum = flag(value)?.then(|| scene.spectrum.unwrap_or_default());
        }
        "srs_damping" | "srs_bands" | "srs_low" | "srs_high" => {
            let mut sp = scene.spectrum.ok_or(SceneError::BadValue)?;
            match key {
                "srs_damping" => sp.damping = float(value)?,
                "srs_bands" => {
                    sp.bands_per_octave = value.parse::<u8>().map_err(|_| SceneError::BadValue)?
                }
                "srs_low" => sp.low_hz = float(value)?,
                _ => sp.high_hz = opt_float(value)?,
            }
            scene.spectrum = Some(sp);
        }
        // A spring–mass target: each key rebuilds it from the numbers so far.
        "target_mass" | "target_stiffness" | "target_damping" => {
            use impact_core::two_body::{SceneTarget, SpringMass};
            let old = scene.target.and_then(|t| t.spring_mass());
            let s = match key {
                "target_mass" => opt_float(value)?.map(|mass_kg| SpringMass {
                    mass_kg,
                    ..old.unwrap_or(SpringMass {
                        mass_kg,
                        stiffness_n_m: 0.0,
                        damping_n_s_m: 0.0,
                    })
                }),
                "target_stiffness" => Some(SpringMass {
                    stiffness_n_m: float(value)?,
                    ..old.ok_or(SceneError::BadValue)?
                }),
                _ => Some(SpringMass {
                    damping_n_s_m: float(value)?,
                    ..old.ok_or(SceneError::BadValue)?
                }),
            };
            scene.target = s.map(SceneTarget::SpringMass);
        }
        "target_space" => {
            scene.target = Some(impact_core::two_body::SceneTarget::StateSpace(
                target_space(value)?,
            ))
        }
        "gravity" => scene.gravity_m_s2 = float(value)?,
        "vertical" => scene.vertical = flag(value)?,
        "v0_every" => scene.v0_every = flag(value)?,
        "max_flight" => {
            let mut t = scene.train.ok_or(SceneError::BadValue)?;
            t.max_flight_s = float(value)?;
            scene.train = Some(t);
        }
        "spec" => {
            use impact_core::spec::{Shape, Spec, Tolerance};
            let shape = match value {
                "none" => {
                    scene.spec = None;
                    return Ok(());
                }
                "half-sine" => Shape::HalfSine,
                "sawtooth" => Shape::Sawtooth,
                "trapezoid" => Shape::Trapezoid {
                    rise: 0.1,
                    fall: 0.1,
                },
                _ => return Err(SceneError::BadValue),
            };
            // The numbers follow in their own keys (the scene is validated once complete).
            scene.spec = Some(Spec {
                shape,
                peak_m_s2: 0.0,
                duration_s: 0.0,
                tolerance: Tolerance {
                    band: 0.0,
                    outside: 0.0,
                    slack: 0.0,
                    delta_v: 0.0,
                    before: 0.0,
                    after: 0.0,
                    watch: 0.0,
                },
                band: None,
            });
        }
        k if k.starts_with("spec_") => {
            use impact_core::spec::Shape;
            let mut spec = scene.spec.ok_or(SceneError::BadValue)?;
            let v = float(value)?;
            let t = &mut spec.tolerance;
            match (k, &mut spec.shape) {
                ("spec_peak", _) => spec.peak_m_s2 = v,
                ("spec_duration", _) => spec.duration_s = v,
                ("spec_band", _) => t.band = v,
                ("spec_outside", _) => t.outside = v,
                ("spec_slack", _) => t.slack = v,
                ("spec_dv", _) => t.delta_v = v,
                ("spec_before", _) => t.before = v,
                ("spec_after", _) => t.after = v,
                ("spec_watch", _) => t.watch = v,
                ("spec_rise", Shape::Trapezoid { rise, .. }) => *rise = v,
                ("spec_fall", Shape::Trapezoid { fall, .. }) => *fall = v,
                _ => return Err(SceneError::UnknownKey),
            }
            scene.spec = Some(spec);
        }
        "wave" => scene.waveform_every = value.parse::<u16>().map_err(|_| SceneError::BadValue)?,
        _ => return Err(SceneError::UnknownKey),
    }
    Ok(())
}

/// Distance between the two light-gate beams, m (feature `light-gate`).
#[cfg(feature = "light-gate")]
pub const LIGHT_GATE_SPACING_M: f32 = 0.010;
