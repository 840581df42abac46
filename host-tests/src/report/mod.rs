//! What the tool reports, and how: the output schema (JSON types with SI field names, why a
//! field is null) and its renderings (CSV, the table, numbers for people). A leaf above the
//! core: the pipeline, the firmware's log reader and the commands build these types; nothing
//! here reads a file or runs the pipeline.

pub mod axes;
pub mod csv;
pub mod filter;
pub mod fmt;
pub mod screen;
pub mod spec;
pub mod spectrum;
pub mod statistics;
pub mod table;
pub mod train;
pub mod waveform;

use std::collections::BTreeMap;

use impact_core::report::{Fits, Flags};
use impact_core::{FitSet, ImpactReport, Status};
use serde::{Deserialize, Serialize};

pub use csv::to_csv;
pub use screen::{Clipping, Spike};
pub use table::to_table;

/// Fits as JSON.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct FitsJson {
    pub two_phase: Option<TwoPhaseJson>,
    pub nonlinear: Option<NonlinearJson>,
    pub hertz: Option<HertzJson>,
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct TwoPhaseJson {
    pub kc_n_m: f64,
    pub kr_n_m: f64,
    pub c_n_s_m: f64,
    pub permanent_deformation_m: f64,
    pub residual: f64,
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct NonlinearJson {
    pub k: f64,
    pub c_s_m: f64,
    pub exponent: f64,
    pub residual: f64,
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct HertzJson {
    pub k: f64,
    pub residual: f64,
}

/// One impact as JSON (SI field names); read back as written (`Deserialize`: a series'
/// statistics over analyses gathered elsewhere, the Python package's `impact.statistics`).
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct ImpactJson {
    pub index: u32,
    pub status: String,
    /// "full", or "skipped" when no capture buffer was free (streaming fields only).
    pub analysis: String,
    pub clipped: bool,
    /// What was found that empties fields ("ac-coupled", "cor-out-of-range", ...).
    pub flags: Vec<String>,
    pub start_sample: u64,
    pub end_sample: u64,
    pub start_s: f64,
    /// What the sample rate leaves first touch (`start_s`) within, s: one sample interval
    /// of the stream. Touch lies between the last sample at the baseline and the first past
    /// it; the foot's power curve or the jump's law places it there, and where that guess
    /// is wrong (a jump smaller than a sample's rise taken for a steep foot) it is off by up
    /// to most of this. The crush time is as uncertain, `x_m` by `impact_velocity_m_s` times
    /// it. (A foot that rises under the noise can put touch further off: 1.7 samples at
    /// 500 kS/s, `docs/accuracy.md`.) Null where `start_s` is no first touch (`cut-at-start`,
    /// `in-previous`, `drift`) or no rate is known.
    #[serde(default)]
    pub touch_uncertainty_s: Option<f64>,
    pub peak_time_s: f64,
    pub peak_acceleration_m_s2: f64,
    pub peak_force_n: Option<f64>,
    pub delta_v_m_s: Option<f64>,
    pub duration_s: f64,
    pub baseline_m_s2: f64,
    pub fwhm_s: Option<f64>,
    pub filtered_peak_acceleration_m_s2: Option<f64>,
    pub filtered_fwhm_s: Option<f64>,
    /// Samples per value of the capture the analysis fields were measured on: 1, or the
    /// power of two a contact longer than the capture was decimated to (flag `decimated`).
    pub decimation: u32,
    pub impact_velocity_m_s: Option<f64>,
    pub crush_time_s: Option<f64>,
    pub max_deformation_m: Option<f64>,
    pub rebound_velocity_m_s: Option<f64>,
    pub cor: Option<f64>,
    /// Deformation at separation, m (the set plus what the pad's viscous part still held).
    pub separation_deformation_m: Option<f64>,
    /// The set the pad keeps once recovered, m (null where the record cannot tell:
    /// `set-not-resolved`).
    pub permanent_deformation_m: Option<f64>,
    pub absorbed_energy_j: Option<f64>,
    pub fits: FitsJson,
    /// Why each absent (null) field is absent: the field's name and the reason.
    pub null_reasons: BTreeMap<String, String>,
    /// Real-time emulation only: virtual time from the end of the impact's hold to its
    /// report, s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub report_latency_s: Option<f64>,
    /// With `--srs`: the impact's shock spectra.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shock_spectrum: Option<crate::report::spectrum::ShockSpectrumJson>,
    /// With `--axes`: the resultant's peak and each axis's peak and Δv.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axes: Option<crate::report::axes::AxesJson>,
    /// A bounce of a train (`--train`): its flight, both approach speeds and their CORs;
    /// null for a train's first impact and without `--train`.
    pub bounce: Option<crate::report::train::BounceJson>,
    /// `impact log` of a log in which the board restarted: the run the impact is from (1 for
    /// the first; each run's indices and times start from 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub run: Option<u32>,
    /// With `--spec`: the verdict against the specified pulse (null, with its reason in
    /// `null_reasons.spec`, when the capture cannot show it).
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "present"
    )]
    pub spec: Option<Option<crate::report::spec::VerdictJson>>,
}

/// `ImpactJson::spec`'s reading: a field present (`null` too, a verdict that could not be
/// judged) is `Some`; an absent one (serde's `default`) is `None`, as it was written.
fn present<'de, D, T>(d: D) -> Result<Option<T>, D::Error>
where
    D: serde::Deserializer<'de>,
    T: Deserialize<'de>,
{
    T::deserialize(d).map(Some)
}

/// The assumption behind every COR, deformation and absorbed energy the tool reports: the body
/// struck an immovable wall, unless a target was given (`--target-mass`, `--target`).
pub const RIGID_BARRIER: &str = "the barrier is taken as rigid and fixed: COR, deformation and \
     absorbed energy are the body's against an immovable wall (a target that moves or yields is \
     not modelled here unless --target-mass or --target gives it); the sensor is taken to ride \
     the body (one on the target or anvil reads that one's motion, not the body's: the force, \
     COR and deformations would not be these)";

/// What the kinematics are against a target the user gave (`--target-mass`, `--target`): said where the
/// rigid barrier would otherwise be.
pub const TARGET_RELATIVE: &str = "the kinematics are the contact's against the target given \
     ({target}, driven by the measured force, --mass \
     times the reading of the sensor, taken to ride the body): the COR is Newton's (the separation speed relative to the target over the \
     approach speed), the crush time and deformations are the relative approach's, and the \
     absorbed energy is the contact's work (the body's loss less what went into the target); \
     the rebound velocity is the body's own; the target is taken at rest at each first touch \
     (a strike before it has settled from the last is measured as if it had)";

/// The target of `--target-mass` (SI), or of `--target FILE` (its state space as the
/// analysis took it, in f32, and the mass its contact point shows to an impulse).
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct TargetJson {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mass_kg: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stiffness_n_m: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub damping_n_s_m: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub state_space: Option<StateSpaceJson>,
    /// `1 / (Cv B)`, kg: a state space's (a spring–mass's is its mass).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contact_mass_kg: Option<f64>,
}

/// A state-space target: `z' = A z + B F`, displacement `Cx z` (m), velocity `Cv z` (m/s).
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct StateSpaceJson {
    pub a: Vec<Vec<f64>>,
    pub b: Vec<f64>,
    /// Rows: displacement, velocity.
    pub c: [Vec<f64>; 2],
}

impl TargetJson {
    pub fn of(t: &impact_core::two_body::SceneTarget) -> Self {
        use impact_core::two_body::SceneTarget;
        match t {
            SceneTarget::SpringMass(s) => Self::of_spring_mass(s),
            SceneTarget::StateSpace(t) => Self::of_state_space(t),
        }
    }

    pub fn of_spring_mass(s: &impact_core::two_body::SpringMass<f32>) -> Self {
        use crate::report::fmt::shortest;
        Self {
            mass_kg: Some(shortest(s.mass_kg)),
            stiffness_n_m: Some(shortest(s.stiffness_n_m)),
            damping_n_s_m: Some(shortest(s.damping_n_s_m)),
            state_space: None,
            contact_mass_kg: None,
        }
    }

    pub fn of_state_space(t: &impact_core::two_body::Target<f32>) -> Self {
        use crate::report::fmt::shortest;
        let n = t.n.min(impact_core::two_body::MAX_STATES);
        let row = |r: &[f32]| r.iter().take(n).map(|v| shortest(*v)).collect::<Vec<f64>>();
        Self {
            mass_kg: None,
            stiffness_n_m: None,
            damping_n_s_m: None,
            state_space: Some(StateSpaceJson {
                a: t.a.iter().take(n).map(|r| row(r)).collect(),
                b: row(&t.b),
                c: [row(&t.c[0]), row(&t.c[1])],
            }),
            contact_mass_kg: Some(shortest(t.contact_mass_kg())),
        }
    }

    /// The target in words: `a mass on a spring and damper to ground, 0.3 kg, 40000 N/m,
    /// 12 N s/m`, or `a linear state space of 4 states, contact-point mass 0.3 kg` (`1 / (Cv
    /// B)`, what the contact point shows to an impulse).
    pub fn describe(&self) -> String {
        match &self.state_space {
            Some(_) => format!("a linear {}", self.short()),
            None => format!("a mass on a spring and damper to ground, {}", self.short()),
        }
    }

    /// The target in few words: `0.3 kg, 40000 N/m, 12 N s/m`, or `state space of 4 states,
    /// contact-point mass 0.3 kg`.
    pub fn short(&self) -> String {
        let n = |v: Option<f64>| v.map_or_else(|| "?".to_string(), |v| v.to_string());
        match &self.state_space {
            Some(ss) => format!(
                "state space of {} state{}, contact-point mass {} kg",
                ss.b.len(),
                if ss.b.len() == 1 { "" } else { "s" },
                n(self.contact_mass_kg)
            ),
            None => format!(
                "{} kg, {} N/m, {} N s/m",
                n(self.mass_kg),
                n(self.stiffness_n_m),
                n(self.damping_n_s_m)
            ),
        }
    }
}

/// The whole analysis as JSON.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct AnalysisJson {
    /// The channel analysed (its header; `|x,y,z|` for the resultant of axes), if known, and
    /// its units (`g`, `m/s2`, `kgn`, `n`): shown in the table (the JSON of a recording read
    /// through another format or the board's log has the same numbers under other names).
    #[serde(skip_serializing)]
    pub column: Option<String>,
    #[serde(skip_serializing)]
    pub units: Option<String>,
    /// What the tool assumed that neither the file nor the options said (a unit), each a
    /// sentence naming the option that changes it; absent when nothing was assumed.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub assumptions: Vec<String>,
    /// Whether the channel's units, and the time column's unit, were assumed (the table
    /// marks them).
    #[serde(skip_serializing)]
    pub units_assumed: bool,
    #[serde(skip_serializing)]
    pub time_unit_assumed: bool,
    pub samples: u64,
    pub sample_rate_hz: f64,
    /// The approach speed of the first impact (from `--v0`, `--drop-height` or a free
    /// fall), m/s.
    pub v0_m_s: Option<f64>,
    /// Where v0 came from: "v0", "drop-height", "free-fall" or null.
    pub v0_source: Option<String>,
    /// Free fall measured on the DC channel, s.
    pub free_fall_s: Option<f64>,
    /// Gravity taken out of each contact, m/s²: the impact is vertical (a drop height, a
    /// free fall, a train, `--vertical`), so the kinematics integrate the reading less `g`
    /// (Δv stays the pulse's area). Null: horizontal, the reading is the deceleration.
    pub contact_gravity_m_s2: Option<f64>,
    /// Samples the source lost (only a real-time run on the firmware loses any).
    pub samples_lost: u64,
    /// Impacts reported without analysis because no capture buffer was free (likewise).
    pub analyses_skipped: u64,
    /// Lines the board's logger dropped, and numbered lines missing from its log (`impact
    /// emulate`, `impact log`; 0 on the host).
    pub lines_dropped: u64,
    pub lines_missing: u64,
    /// Whether the time axis was interpolated onto an even grid (`--resample`).
    pub resampled: bool,
    /// Isolated glitches removed before the analysis (an impact containing one is flagged
    /// `spike-removed`).
    pub spikes_removed: Vec<Spike>,
    /// The channel's rails: from `--range`, or flat tops found in the recording; null when
    /// neither is known (then `clipped` means a reading at the i16 rail).
    pub clipping: Option<Clipping>,
    /// With `--train`: which speed the bounces' kinematics use ("flight" or "rebound").
    pub train_speed: Option<String>,
    /// With `--spec`: the specified pulse and its tolerances (each impact's verdict is its
    /// `spec`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub spec: Option<crate::report::spec::SpecJson>,
    /// With `--lowpass`: the Butterworth low-pass of the filtered fields (absent with a CFC
    /// or no filter).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lowpass: Option<crate::report::filter::LowpassJson>,
    /// With `--target-mass` or `--target`: the target the body struck (the kinematics are the contact's,
    /// relative to it: [`TARGET_RELATIVE`]); absent for the rigid, fixed barrier assumed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub target: Option<TargetJson>,
    pub impacts: Vec<ImpactJson>,
    /// Events the board's trigger took that are no impact: the signal drifted (it left the
    /// baseline and never came back, with no pulse in it: half its peak not reached on both
    /// sides). Not listed among the impacts, nor counted in a series.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub drifts: Vec<DriftJson>,
    /// With `--train`: each train of bounces and its COR against impact speed.
    pub trains: Vec<crate::report::train::TrainJson>,
    /// `impact log` / `impact emulate --waveforms`: the captured windows the board sent.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub waveforms: Vec<crate::report::waveform::WaveformJson>,
    /// `impact log` (and `impact watch`'s exports): the log's lines passed over, each its
    /// number and why (a line cut by the link, a value no board gives); absent when none.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub skipped_lines: Vec<SkippedLineJson>,
}

/// A log's line passed over: its number (from 1) and why.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct SkippedLineJson {
    pub line: u64,
    pub reason: String,
}

impl AnalysisJson {
    /// Whether the impacts have kinematics to report (an approach speed, or a bounce train's):
    /// those assume a rigid barrier ([`RIGID_BARRIER`]), which is then said.
    /// With a target ([`Self::target`]) that is no assumption: what the kinematics are
    /// against it is said instead ([`TARGET_RELATIVE`]).
    pub fn assume_rigid_barrier(&mut self) {
        if self.v0_m_s.is_some() || self.train_speed.is_some() {
            let said = match &self.target {
                Some(t) => TARGET_RELATIVE.replace("{target}", &t.describe()),
                None => RIGID_BARRIER.to_string(),
            };
            self.assumptions.push(said);
        }
    }
}

/// The JSON of `a` with `impacts` in place of `a.impacts` (which must be empty), written to
/// `out` an impact at a time: the bytes of `serde_json::to_string_pretty` on the whole, and
/// a newline. So a long log's report is never held whole, as text or as JSON values.
pub fn write_json(
    a: &AnalysisJson,
    impacts: impl Iterator<Item = ImpactJson>,
    out: &mut impl std::io::Write,
) -> std::io::Result<()> {
    let head = serde_json::to_vec_pretty(a)?;
    // The top-level key: a nested one is indented further, and a string's quotes are escaped.
    const KEY: &[u8] = b"\n  \"impacts\": [";
    let at = head
        .windows(KEY.len())
        .position(|w| w == KEY)
        .map(|k| k + KEY.len())
        .filter(|&k| head.get(k) == Some(&b']'))
        .ok_or_else(|| std::io::Error::other("write_json: the impacts are not an empty list"))?;
    out.write_all(&head[..at])?;
    let mut any = false;
    let mut one = Vec::new();
    for i in impacts {
        out.write_all(if any { b",\n    " } else { b"\n    " })?;
        one.clear();
        serde_json::to_writer_pretty(&mut one, &i)?;
        // Two levels deeper (a JSON string holds no raw newline).
        for (k, line) in one.split(|&b| b == b'\n').enumerate() {
            if k > 0 {
                out.write_all(b"\n    ")?;
            }
            out.write_all(line)?;
        }
        any = true;
    }
    if any {
        out.write_all(b"\n  ")?;
    }
    out.write_all(&head[at..])?;
    out.write_all(b"\n")
}

fn fits_json(f: &Fits) -> FitsJson {
    FitsJson {
        two_phase: f.two_phase.map(|t| TwoPhaseJson {
            kc_n_m: t.kc_n_m as f64,
            kr_n_m: t.kr_n_m as f64,
            c_n_s_m: t.c_n_s_m as f64,
            permanent_deformation_m: t.permanent_m as f64,
            residual: t.residual as f64,
        }),
        nonlinear: f.nonlinear.map(|t| NonlinearJson {
            k: t.k as f64,
            c_s_m: t.c_s_m as f64,
            exponent: t.n as f64,
            residual: t.residual as f64,
        }),
        hertz: f.hertz.map(|t| HertzJson {
            k: t.k as f64,
            residual: t.residual as f64,
        }),
    }
}

/// Why each absent field of `r` is absent; `fits` is what the scene asked for.
pub fn null_reasons(r: &ImpactReport, fits: &FitSet) -> BTreeMap<String, String> {
    let mut out = BTreeMap::new();
    let skipped = r.analysis == impact_core::Analysis::Skipped;
    let flag = |f: Flags| r.flags.contains(f);
    let mut put = |field: &str, reason: &str| {
        out.insert(field.to_string(), reason.to_string());
    };
    if r.peak_force_n.is_none() {
        put("peak_force_n", "no-mass");
    }
    if r.delta_v_m_s.is_none() {
        // (The core empties Δv for these two flags alone.)
        let why = if flag(Flags::DRIFT) {
            "drift"
        } else {
            "ac-coupled"
        };
        put("delta_v_m_s", why);
    }
    if let Some(Err(m)) = r.verdict {
        put("spec", m.name());
    }
    let analysis = |own: Option<&'static str>| {
        if skipped {
            "analysis-skipped"
        } else if flag(Flags::CFC_WINDOW) {
            "cfc-window"
        } else {
            own.unwrap_or("not-found")
        }
    };
    if r.fwhm_s.is_none() {
        // The raw signal's width: a CFC's window does not touch it.
        let why = if skipped {
            "analysis-skipped"
        } else if flag(Flags::DECIMATED) && !flag(Flags::HALF_MAXIMUM_OUTSIDE) {
            // Fewer values across it than `analysis::RESOLVED_WIDTH`.
            "decimated-too-coarse"
        } else {
            "half-maximum-outside"
        };
        put("fwhm_s", why);
    }
    if r.filtered_peak_acceleration_m_s2.is_none() {
        put("filtered_peak_acceleration_m_s2", analysis(Some("no-cfc")));
    }
    if r.filtered_fwhm_s.is_none() {
        let own = if r.filtered_peak_acceleration_m_s2.is_some() {
            if flag(Flags::FILTERED_HALF_MAXIMUM_OUTSIDE) || !flag(Flags::DECIMATED) {
                "half-maximum-outside"
            } else {
                // Fewer values across it than `analysis::RESOLVED_WIDTH`.
                "decimated-too-coarse"
            }
        } else {
            "no-cfc"
        };
        put("filtered_fwhm_s", analysis(Some(own)));
    }
    // The kinematics: the first reason that applies.
    let kinematics = if r.kinematics.is_some() {
        None
    } else if flag(Flags::APPROACH_UNKNOWN) {
        Some("approach-unknown".to_string())
    } else if flag(Flags::NO_APPROACH_SPEED) {
        Some("no-approach-speed".to_string())
    } else if flag(Flags::AC_COUPLED) {
        Some("ac-coupled".to_string())
    } else if flag(Flags::DRIFT) {
        Some("drift".to_string())
    } else if flag(Flags::CLIPPED) {
        Some("clipped".to_string())
    } else if flag(Flags::CUT_AT_START) {
        Some("cut-at-start".to_string())
    } else if !matches!(r.status, Status::Complete | Status::BufferFull) {
        // (A full capture cut nothing the stream's online sums measured.)
        Some(format!("status-{}", r.status.name()))
    } else if flag(Flags::COR_OUT_OF_RANGE) {
        Some("cor-out-of-range".to_string())
    } else if flag(Flags::NO_STOP) {
        Some("no-stop".to_string())
    } else if flag(Flags::KINEMATICS_NOT_HELD) {
        Some("kinematics-not-held".to_string())
    } else if skipped {
        Some("analysis-skipped".to_string())
    } else {
        Some("not-found".to_string())
    };
    if let Some(why) = &kinematics {
        for field in [
            "impact_velocity_m_s",
            "crush_time_s",
            "max_deformation_m",
            "rebound_velocity_m_s",
            "cor",
            "separation_deformation_m",
            "permanent_deformation_m",
            "absorbed_energy_j",
        ] {
            put(field, why);
        }
    } else {
        if flag(Flags::UNDERSAMPLED) {
            for field in [
                "crush_time_s",
                "max_deformation_m",
                "separation_deformation_m",
            ] {
                put(field, "undersampled");
            }
        }
        if r.kinematics.is_some_and(|k| k.absorbed_energy_j.is_none()) {
            put("absorbed_energy_j", "no-mass");
        }
        if r.kinematics
            .is_some_and(|k| k.permanent_deformation_m.is_none())
        {
            // The stream's online sums gave the kinematics of a contact no capture held
            // whole; else no line of an elastic and a viscous part holds the unloading, or no
            // fit points were taken (no mass, no fit asked).
            let why = if flag(Flags::UNDERSAMPLED) {
                "undersampled"
            } else if skipped {
                "analysis-skipped"
            } else if r.status == Status::BufferFull {
                "capture-full"
            } else {
                "set-not-resolved"
            };
            put("permanent_deformation_m", why);
        }
    }
    for (name, asked, got) in [
        ("fits.two_phase", fits.two_phase, r.fits.two_phase.is_some()),
        ("fits.nonlinear", fits.nonlinear, r.fits.nonlinear.is_some()),
        ("fits.hertz", fits.hertz, r.fits.hertz.is_some()),
    ] {
        if !got {
            let why = match &kinematics {
                _ if !asked => "not-asked",
                _ if r.peak_force_n.is_none() => "no-mass",
                Some(k) => k.as_str(),
                None if flag(Flags::UNDERSAMPLED) => "undersampled",
                // Kinematics from the online sums, but the loop the fits need was not held.
                None if skipped => "analysis-skipped",
                None if r.status == Status::BufferFull => "capture-full",
                None => "not-identifiable",
            };
            put(name, why);
        }
    }
    out
}

/// Why `start_s` is no first touch, if it is none: the flag that says so.
fn start_not_touch(r: &ImpactReport) -> Option<&'static str> {
    [Flags::CUT_AT_START, Flags::IN_PREVIOUS, Flags::DRIFT]
        .into_iter()
        .find(|f| r.flags.contains(*f))
        .and_then(|f| f.names().next())
}

/// A core report as JSON; times shifted by `t0` (the recording's first time stamp); `fits`
/// is what the scene asked for (for the reasons of absent fits); `gravity_m_s2` the gravity
/// in its contacts (a bounce's COR by either source takes it out); `rate_hz` the stream's
/// rate (first touch's uncertainty), if known.
pub fn impact_json(
    r: &ImpactReport,
    t0: f64,
    fits: &FitSet,
    gravity_m_s2: Option<f32>,
    rate_hz: Option<f64>,
) -> ImpactJson {
    let k = r.kinematics;
    let touch_uncertainty_s = rate_hz
        .filter(|r| r.is_finite() && *r > 0.0)
        .map(|r| 1.0 / r)
        .filter(|_| start_not_touch(r).is_none());
    let f = |v: f32| v as f64;
    ImpactJson {
        index: r.index,
        status: r.status.name().into(),
        analysis: r.analysis.name().into(),
        clipped: r.clipped,
        flags: r.flags.names().map(str::to_string).collect(),
        start_sample: r.start_sample,
        end_sample: r.end_sample,
        start_s: t0 + r.start_s,
        touch_uncertainty_s,
        peak_time_s: t0 + r.peak_time_s,
        peak_acceleration_m_s2: f(r.peak_acceleration_m_s2),
        peak_force_n: r.peak_force_n.map(f),
        delta_v_m_s: r.delta_v_m_s.map(f),
        duration_s: f(r.duration_s),
        baseline_m_s2: f(r.baseline_m_s2),
        fwhm_s: r.fwhm_s.map(f),
        filtered_peak_acceleration_m_s2: r.filtered_peak_acceleration_m_s2.map(f),
        filtered_fwhm_s: r.filtered_fwhm_s.map(f),
        decimation: r.decimation,
        impact_velocity_m_s: k.map(|k| f(k.impact_velocity_m_s)),
        crush_time_s: k.and_then(|k| k.crush_time_s).map(f),
        max_deformation_m: k.and_then(|k| k.max_deformation_m).map(f),
        rebound_velocity_m_s: k.map(|k| f(k.rebound_velocity_m_s)),
        cor: k.map(|k| f(k.cor)),
        separation_deformation_m: k.and_then(|k| k.separation_deformation_m).map(f),
        permanent_deformation_m: k.and_then(|k| k.permanent_deformation_m).map(f),
        absorbed_energy_j: k.and_then(|k| k.absorbed_energy_j).map(f),
        fits: fits_json(&r.fits),
        null_reasons: {
            let mut why = null_reasons(r, fits);
            if touch_uncertainty_s.is_none() {
                let reason = start_not_touch(r).unwrap_or("no-rate");
                why.insert("touch_uncertainty_s".into(), reason.into());
            }
            why
        },
        report_latency_s: None,
        shock_spectrum: r
            .spectrum
            .as_ref()
            .map(crate::report::spectrum::spectrum_json),
        bounce: crate::report::train::bounce_json(r, gravity_m_s2),
        axes: None,
        run: None,
        spec: r
            .verdict
            .as_ref()
            .map(|v| crate::report::spec::verdict_json(v, t0)),
    }
}

/// A drift the trigger took for an impact: where it started, how long it ran (to the end of
/// the impact's hold or the recording), how far it went from the baseline.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct DriftJson {
    pub index: u32,
    pub start_s: f64,
    pub duration_s: f64,
    pub excursion_m_s2: f64,
}

/// Whether an event is drift rather than an impact: flagged `drift` (it never came back to
/// the baseline and left it more than the settle time before its peak) and no pulse in it
/// (half its peak not reached on both sides: no FWHM), its capture whole.
pub fn is_drift(i: &ImpactJson) -> bool {
    // (A capture that filled cannot tell: its pulse may lie beyond what it holds.)
    i.flags.iter().any(|f| f == "drift") && i.fwhm_s.is_none() && i.status != "buffer-full"
}

/// Moves the events that are drift out of `a`'s impacts into its drifts.
pub fn separate_drifts(a: &mut AnalysisJson) {
    let (drifts, impacts): (Vec<ImpactJson>, Vec<ImpactJson>) = std::mem::take(&mut a.impacts)
        .into_iter()
        .partition(is_drift);
    a.impacts = impacts;
    a.drifts = drifts.iter().map(DriftJson::of).collect();
}

impl DriftJson {
    /// The drift an event (`is_drift`) was.
    pub fn of(i: &ImpactJson) -> Self {
        Self {
            index: i.index,
            start_s: i.start_s,
            duration_s: i.duration_s,
            excursion_m_s2: i.peak_acceleration_m_s2,
        }
    }
}

/// The host's flag on an impact that contained a removed spike.
pub const SPIKE_REMOVED: &str = "spike-removed";
