//! The per-impact report: what the streaming stage measured exactly (peak, Δv, times), and,
//! when the analysis ran, the widths, the kinematics (with the approach speed) and the fits.

pub mod fields;
pub mod motion;
pub mod summary;

pub use crate::fit::{Fits, HertzFit, NonlinearFit, TwoPhaseFit};
use crate::scene::Scene;
pub use crate::signal::spectrum::Spectrum;
pub use fields::{BOUNCE_FIELDS, FIELDS};
pub use summary::{Bounce, BounceSlot, Summary};

/// How far beyond [0, 1] a measured COR may lie before it is taken as wrong, not noisy
/// ([`Flags::COR_OUT_OF_RANGE`]; a bounce's rebound must lie in `[0, 1 + COR_TOLERANCE]`).
pub const COR_TOLERANCE: f32 = 0.02;

/// How an impact's capture ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Status {
    /// The signal came back to the baseline and stayed there.
    Complete,
    /// The stream ended inside the impact.
    StreamEnded,
    /// The capture buffer filled up: Δv, the peak and the kinematics (the stream's online
    /// sums, `stream/online.rs`) cover the whole impact; the width, the filtered fields, the
    /// spectra and the verdict only the captured part; no fits (they need the whole loop).
    BufferFull,
    /// The signal stayed away from the baseline longer than the scene's maximum impact time
    /// (stuck, drifting or disconnected sensor); the baseline is learned again.
    TooLong,
    /// Samples were lost inside the impact (the sample source overran): Δv and the peak cover
    /// only what arrived, and nothing that needs the whole impact is reported.
    Gap,
    /// After the pulse the signal settled at a new level instead of coming back (the body came
    /// to rest on a DC sensor, or the sensor's offset moved): no kinematics; the baseline is
    /// learned again.
    Settled,
}

impl Status {
    /// Every status.
    pub const ALL: [Status; 6] = [
        Status::Complete,
        Status::StreamEnded,
        Status::BufferFull,
        Status::TooLong,
        Status::Gap,
        Status::Settled,
    ];

    /// The name the reports use (`complete`, `stream-ended`, `buffer-full`, `too-long`, `gap`,
    /// `settled`).
    pub fn name(self) -> &'static str {
        match self {
            Status::Complete => "complete",
            Status::StreamEnded => "stream-ended",
            Status::BufferFull => "buffer-full",
            Status::TooLong => "too-long",
            Status::Gap => "gap",
            Status::Settled => "settled",
        }
    }
}

/// Whether the per-impact analysis ran.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Analysis {
    /// The impact was captured and analysed: every field the scene asks for is there.
    Full,
    /// No capture buffer was free when the impact started (the analysis of earlier impacts
    /// was still running): only the streaming fields are reported.
    Skipped,
}

impl Analysis {
    /// The name the reports use (`full`, `skipped`).
    pub fn name(self) -> &'static str {
        match self {
            Analysis::Full => "full",
            Analysis::Skipped => "skipped",
        }
    }
}

/// Why fields of a report are absent (a bit set): each flag names what was found and which
/// fields it empties. A value that cannot be known is absent, never a plausible-looking
/// number.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Flags(pub u16);

impl Flags {
    /// After the pulse the signal undid most of its velocity change within the window (a
    /// sustained undershoot): the channel does not hold DC (a piezoelectric, AC-coupled
    /// sensor). Δv, the kinematics and the fits are absent.
    pub const AC_COUPLED: Flags = Flags(1 << 0);
    /// The coefficient of restitution came out outside [0, 1] (beyond a 2 % tolerance): the
    /// rebound went the wrong way or gained energy, so the approach speed or the signal is
    /// wrong. The kinematics and the fits are absent.
    pub const COR_OUT_OF_RANGE: Flags = Flags(1 << 1);
    /// The velocity never reached zero: the approach speed is more than the measured Δv
    /// could stop. The kinematics and the fits are absent.
    pub const NO_STOP: Flags = Flags(1 << 2);
    /// Half the raw peak is not reached on both sides inside the capture: no FWHM.
    pub const HALF_MAXIMUM_OUTSIDE: Flags = Flags(1 << 3);
    /// The capture holds less signal around the contact than the window filter (the CFC or
    /// the low-pass) needs to settle (its padding: SAE J211's for a CFC): the filtered peak
    /// and its FWHM are absent.
    pub const CFC_WINDOW: Flags = Flags(1 << 4);
    /// The approach speed is unknown (no `v0`, drop height, free fall or light gate): the
    /// kinematics and the fits are absent.
    pub const NO_APPROACH_SPEED: Flags = Flags(1 << 5);
    /// The sensor was at its rail during the impact (`clipped`): the peak and Δv are lower
    /// bounds of the pulse's, so the kinematics, the fits and a bounce's COR are absent.
    pub const CLIPPED: Flags = Flags(1 << 6);
    /// The recording starts inside the impact (its first sample already beyond the edge
    /// level: the tail of an earlier event, or the pulse itself): the onset is not in the
    /// record, so the start, duration, peak and Δv cover the recorded part only; the
    /// kinematics and the fits are absent.
    pub const CUT_AT_START: Flags = Flags(1 << 7);
    /// The signal settled at another level since the previous impact (a sub-trigger step, an
    /// orientation change, drift, free fall): the baseline is that level, the one just before
    /// this impact, not the sensor's zero. Empties no field.
    pub const LEVEL_CHANGE: Flags = Flags(1 << 8);
    /// The signal never came back to the baseline and left it more than the settle time
    /// before the peak: the pulse rode on drift or an orientation change, which the start and
    /// duration take in; or a slow ramp into the pulse began beyond the flanks' reach
    /// ([`crate::stream::REACH`] samples), so where the contact began is unknown; or the
    /// baseline was learned from a short stretch the signal never came back to (a record
    /// that starts on a ramp: [`crate::signal::baseline::Baseline::unconfirmed`]), so the
    /// zero is not the sensor's. Δv, the kinematics and the fits are absent.
    pub const DRIFT: Flags = Flags(1 << 9);
    /// The pulse was already under way where the previous impact's contact ended (the signal
    /// never came back to the baseline between them), or a slow ramp into it where the
    /// previous impact's window ended: its start is that contact's or window's end, so the
    /// start, duration and Δv cover only the part after it; the kinematics and the fits are
    /// absent.
    pub const IN_PREVIOUS: Flags = Flags(1 << 10);
    /// The impact follows a flight (its first touch came within a train's longest flight of
    /// the previous contact's end, or before it), and the scene's approach speed is the
    /// first impact's (a drop's `v0` or height) and no train timed this flight: its approach
    /// speed is unknown, so the kinematics and the fits are absent. A train measures a
    /// bounce's approach speed; a rig that strikes every time at one speed says `v0_every`.
    pub const APPROACH_UNKNOWN: Flags = Flags(1 << 11);
    /// No capture holds the whole contact (it outlasted the capture, or the analysis was
    /// skipped) and the stream's online sums lost its crush or its separation (first touch or
    /// the approach speed found at the end moved them beyond the samples kept around them);
    /// or, against a target ([`Scene::target`]), no capture holds the whole contact (the
    /// online sums are the body's alone) or its relative motion overflowed: the kinematics
    /// and the fits are absent.
    pub const KINEMATICS_NOT_HELD: Flags = Flags(1 << 12);
    /// The contact outlasted the capture, which holds it whole at a coarser step: each value
    /// the mean of `decimation` samples. The streaming fields and the kinematics are the
    /// stream's (every sample); the widths, the filtered fields, the spectra, the verdict,
    /// the fit points (and the kinematics where the stream's online sums lost them, or
    /// against a target) are
    /// measured on the coarser values, as on a recording at the coarser rate, where they
    /// resolve them (else absent).
    pub const DECIMATED: Flags = Flags(1 << 13);
    /// Half the CFC-filtered peak is not reached on both sides inside the capture: no
    /// `filtered_fwhm_s` (a decimated capture whose filtered width is too coarse to resolve
    /// does not set it: that is [`Self::DECIMATED`]'s).
    pub const FILTERED_HALF_MAXIMUM_OUTSIDE: Flags = Flags(1 << 14);
    /// The compression (first touch to the crush) spans fewer samples than
    /// [`motion::MIN_CRUSH_SAMPLES`]: where in the sample interval before the onset the
    /// contact began, the samples cannot tell (a foot's curve or a jump's law places it, and
    /// a wrong guess moves the crush time and `x_m` by up to a sample's share of them: −15 %
    /// on a 1 ms contact at 10 kS/s); or first touch lies in a jump's interval that neither
    /// the contact's law placed nor is short enough ([`motion::JUMP_TOUCH_SHARE`]): the
    /// crush time, the deformations and the fits are absent; the COR, the rebound and the
    /// energy (from Δv) stand.
    pub const UNDERSAMPLED: Flags = Flags(1 << 15);

    /// Every flag with its name in the reports.
    pub const NAMES: [(Flags, &'static str); 16] = [
        (Flags::AC_COUPLED, "ac-coupled"),
        (Flags::COR_OUT_OF_RANGE, "cor-out-of-range"),
        (Flags::NO_STOP, "no-stop"),
        (Flags::HALF_MAXIMUM_OUTSIDE, "half-maximum-outside"),
        (Flags::CFC_WINDOW, "cfc-window"),
        (Flags::NO_APPROACH_SPEED, "no-approach-speed"),
        (Flags::CLIPPED, "clipped"),
        (Flags::CUT_AT_START, "cut-at-start"),
        (Flags::LEVEL_CHANGE, "level-change"),
        (Flags::DRIFT, "drift"),
        (Flags::IN_PREVIOUS, "in-previous"),
        (Flags::APPROACH_UNKNOWN, "approach-unknown"),
        (Flags::KINEMATICS_NOT_HELD, "kinematics-not-held"),
        (Flags::DECIMATED, "decimated"),
        (
            Flags::FILTERED_HALF_MAXIMUM_OUTSIDE,
            "filtered-half-maximum-outside",
        ),
        (Flags::UNDERSAMPLED, "undersampled"),
    ];

    pub const fn empty() -> Self {
        Flags(0)
    }

    pub const fn contains(self, other: Flags) -> bool {
        self.0 & other.0 == other.0
    }

    pub fn insert(&mut self, other: Flags) {
        self.0 |= other.0;
    }

    pub fn remove(&mut self, other: Flags) {
        self.0 &= !other.0;
    }

    /// The names of the flags set, in [`Self::NAMES`] order.
    pub fn names(self) -> impl Iterator<Item = &'static str> {
        Self::NAMES
            .into_iter()
            .filter(move |(f, _)| self.contains(*f))
            .map(|(_, n)| n)
    }
}

/// What the deceleration says once `v0` is known. SI.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Kinematics {
    /// Approach speed used, m/s.
    pub impact_velocity_m_s: f32,
    /// From first touch to zero velocity, s (`None`: [`Flags::UNDERSAMPLED`]).
    pub crush_time_s: Option<f32>,
    /// Deformation at zero velocity, m (`None`: [`Flags::UNDERSAMPLED`]).
    pub max_deformation_m: Option<f32>,
    /// Speed after the impact (`Δv - v0`), m/s.
    pub rebound_velocity_m_s: f32,
    /// `v' / v0`.
    pub cor: f32,
    /// Deformation at separation (where the contact force returned to zero), m: the set
    /// plus what the pad's viscous part still held (a Kelvin–Voigt pad's `c v_r / k`)
    /// (`None`: [`Flags::UNDERSAMPLED`]).
    pub separation_deformation_m: Option<f32>,
    /// The set the pad keeps once it has recovered, m ([`crate::fit::set`]): 0 for a
    /// Kelvin–Voigt pad, `x_p` for the two-phase law; `None` where the record cannot tell
    /// (the unloading no line of an elastic and a viscous part, or no fit points: no mass or
    /// no fit asked).
    pub permanent_deformation_m: Option<f32>,
    /// `m (v0² - v'²) / 2` (plus gravity's work `m g x_sep` in a vertical contact), J (when
    /// the mass is known).
    pub absorbed_energy_j: Option<f32>,
}

/// One impact. Times are from the start of the stream unless named otherwise.
///
/// The streaming fields (from `status` to `baseline_m_s2`) come from the streaming stage's
/// exact integer sums over the raw samples and are the same whether or not the analysis ran;
/// the analysis fields (`fwhm_s` and after) are absent when it was skipped.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ImpactReport {
    /// 0 for the stream's first impact.
    pub index: u32,
    pub status: Status,
    pub analysis: Analysis,
    /// The sensor reached a rail inside the impact: peak and Δv are lower bounds.
    pub clipped: bool,
    /// Why fields below are absent.
    pub flags: Flags,
    /// Sample index of the pulse's first sample beyond the edge level.
    pub start_sample: u64,
    /// Sample index just after the impact: the end of the hold (or where it was cut).
    pub end_sample: u64,
    /// First touch, s: the raw pulse's rising flank extrapolated to zero, or its edge crossing.
    pub start_s: f64,
    /// Time of the (raw) peak, s.
    pub peak_time_s: f64,
    /// Signed raw peak deceleration, m/s² (positive: the body was slowed).
    pub peak_acceleration_m_s2: f32,
    /// `m a` at the peak, N (when the mass is known).
    pub peak_force_n: Option<f32>,
    /// Velocity change over the contact, from first touch to separation, m/s (`v0 + v'` for a
    /// rebound); over the whole window if the signal never came back. Absent for an
    /// AC-coupled channel.
    pub delta_v_m_s: Option<f32>,
    /// From first touch to separation (both flank-extrapolated), or to the end of the capture
    /// if the signal never came back, s.
    pub duration_s: f32,
    /// Baseline the pulse was measured from, m/s² (sensor offset).
    pub baseline_m_s2: f32,
    /// Width at half the peak of the raw signal, s (a filter never changes it).
    pub fwhm_s: Option<f32>,
    /// Peak of the filtered signal, m/s² (only with a CFC or the low-pass).
    pub filtered_peak_acceleration_m_s2: Option<f32>,
    /// Width at half the filtered peak, s (only with a CFC or the low-pass).
    pub filtered_fwhm_s: Option<f32>,
    /// Samples per value of the capture the analysis fields were measured on: 1, or the power
    /// of two a contact longer than the capture was decimated to ([`Flags::DECIMATED`]).
    pub decimation: u32,
    pub kinematics: Option<Kinematics>,
    pub fits: Fits,
    /// The impact continues a bounce train (a streaming field): its flight and both measures
    /// of its approach speed.
    pub bounce: Option<Bounce>,
    /// Shock spectra of the impact's window (an analysis field, when the scene asks).
    pub spectrum: Option<Spectrum>,
    /// The verdict against the scene's specified pulse (an analysis field, when the scene
    /// asks), or why there is none.
    pub verdict: Option<Result<crate::spec::verdict::Verdict, crate::spec::verdict::Missing>>,
}

/// A window whose Δv is less than this share of its contact's (the rest undone after
/// separation) is from an AC-coupled channel. A DC sensor on a body that flies off or rings
/// keeps most of it (the AFRL drop tower's ringing table: 88 %).
pub const AC_COUPLED_RATIO: f64 = 0.5;

/// Acceleration per unit of `d = W x - S`, m/s², in f32 as the analysis converts samples:
/// `a = d as f32 * per_count(..)`.
pub(crate) fn per_count(scene: &Scene, base_n: i64) -> f32 {
    scene.calibration.gain_m_s2_per_count / base_n.max(1) as f32
}

/// The rebound speed the report's Δv gives for an approach at `v0`, m/s: the pulse's area
/// less the approach, less gravity's `g t_c` over the contact in a vertical one (the reading
/// is specific force: in a contact the body's deceleration is the reading less `g`).
/// `None` without a Δv.
pub fn rebound_m_s(r: &ImpactReport, v0: f32, gravity_m_s2: Option<f32>) -> Option<f32> {
    let delta_v = r.delta_v_m_s?;
    Some(delta_v - v0 - gravity_m_s2.map_or(0.0, |g| g * r.duration_s))
}

/// The report of what the stream measured (`analysis` skipped): its fields and the
/// kinematics its online sums found; the analysis fills in the rest.
pub fn streaming(s: &Summary, scene: &Scene) -> ImpactReport {
    streaming_as(s, scene, false)
}

/// The report of an impact whose analysis was skipped: [`streaming`]'s, less the
/// kinematics against a target (the online sums are the impactor's, and only the analysis
/// of a capture gives the contact's).
pub fn skipped(s: &Summary, scene: &Scene) -> ImpactReport {
    streaming_as(s, scene, true)
}

/// [`streaming`], or [`skipped`]'s. (One function, one report built in place: the report
/// is large, and a second copy on the stream task's stack cost it 0.9 KiB.)
#[inline(always)]
fn streaming_as(s: &Summary, scene: &Scene, skipped: bool) -> ImpactReport {
    let mut r = measured(s, scene);
    // The kinematics from the stream's online sums, however long the contact.
    match s.motion.get() {
        Ok(found) => {
            if let Some(frame) = motion::Frame::of(s, scene, None) {
                motion::kinematics(&mut r, scene, &frame, &found);
            }
        }
        Err(Some(motion::Missing::NoStop)) => r.flags.insert(Flags::NO_STOP),
        Err(Some(motion::Missing::CrushNotHeld | motion::Missing::EdgeNotHeld)) => {
            r.flags.insert(Flags::KINEMATICS_NOT_HELD)
        }
        Err(_) => {}
    }
    if skipped && scene.target.is_some() {
        // (Its null reason is the skipped analysis's: no flag stands for it.)
        without_target_kinematics(&mut r, false);
    }
    r
}

/// Empties the kinematics and the fits of an impact on a target whose contact's kinematics
/// could not be found ([`Flags::KINEMATICS_NOT_HELD`]: the impactor's own, against the
/// rigid wall they assume, would be a plausible-looking wrong answer).
pub fn without_target_kinematics(r: &mut ImpactReport, flag: bool) {
    // The body's own verdicts on its kinematics (no stop, its COR out of range, too few
    // samples) say nothing of the contact's: they give way to the one that does.
    let body = [Flags::NO_STOP, Flags::COR_OUT_OF_RANGE, Flags::UNDERSAMPLED];
    let tried = body.iter().any(|f| r.flags.contains(*f));
    if (r.kinematics.take().is_some() || tried) && flag {
        r.flags.insert(Flags::KINEMATICS_NOT_HELD);
    }
    for f in body {
        r.flags.remove(f);
    }
    r.fits = Fits::default();
}

/// The contact's Δv, m/s, with `step_c` added to its sums (a force that steps at the crush:
/// [`motion::Frame::found`]); none for drift, or with [`Flags::AC_COUPLED`] in `flags` where
/// the whole window undoes most of it.
pub(crate) fn contact_delta_v(
    s: &Summary,
    scene: &Scene,
    step_c: i64,
    flags: &mut Flags,
) -> Option<f32> {
    let fs = scene.calibration.sample_rate_hz as f64;
    let per_d = scene.calibration.gain_m_s2_per_count as f64 / s.base_n.max(1) as f64;
    match s.contact_c.map(|c| c.wrapping_add(step_c)) {
        _ if s.drift => None,
        Some(c) if c != 0 && (s.total_c as f64 / c as f64) < AC_COUPLED_RATIO => {
            flags.insert(Flags::AC_COUPLED);
            None
        }
        c => Some((c.unwrap_or(s.total_c) as f64 * per_d / fs) as f32),
    }
}

/// The streaming fields alone (peak, Δv, times, flags), no kinematics: what a bounce
/// train needs of the previous impact.
pub(crate) fn measured(s: &Summary, scene: &Scene) -> ImpactReport {
    let fs = scene.calibration.sample_rate_hz as f64;
    let n = s.base_n.max(1) as f64;
    let per_d = scene.calibration.gain_m_s2_per_count as f64 / n;
    // The same conversion as the analysis's acceleration array, so the peak here and the
    // peak of the (unfiltered) array have the same bits.
    let peak = s.peak_d as f32 * per_count(scene, s.base_n);
    let start = s.onset_index as f64 + s.touch_offset as f64;
    // Δv over the contact; the whole window's (the contact and the hold after it) undoing
    // most of it is the mark of a channel that does not hold DC.
    let mut flags = Flags::empty();
    if s.approach_unknown {
        flags.insert(Flags::APPROACH_UNKNOWN);
    } else if s.v0_m_s.is_none() {
        flags.insert(Flags::NO_APPROACH_SPEED);
    }
    if s.clipped {
        flags.insert(Flags::CLIPPED);
    }
    if s.cut_at_start {
        flags.insert(Flags::CUT_AT_START);
    }
    if s.level_change {
        flags.insert(Flags::LEVEL_CHANGE);
    }
    if s.drift {
        flags.insert(Flags::DRIFT);
    }
    if s.in_previous {
        flags.insert(Flags::IN_PREVIOUS);
    }
    // (A force that steps at the crush: the contact's Δv takes the area the sums missed,
    // where they found the crush.)
    let step_c = s.motion.get().map_or(0, |f| f.step_c);
    let delta_v = contact_delta_v(s, scene, step_c, &mut flags);
    let end = match s.separation_index {
        Some(i) => i as f64 + s.separation_offset as f64,
        None => s.end_index as f64,
    };
    ImpactReport {
        index: s.index,
        status: s.status,
        analysis: Analysis::Skipped,
        clipped: s.clipped,
        flags,
        start_sample: s.onset_index,
        end_sample: s.end_index,
        start_s: start / fs,
        peak_time_s: s.peak_index as f64 / fs,
        peak_acceleration_m_s2: peak,
        peak_force_n: scene.mass_kg.map(|m| m * peak),
        delta_v_m_s: delta_v,
        duration_s: ((end - start) / fs) as f32,
        baseline_m_s2: (s.base_sum as f64 * per_d) as f32,
        fwhm_s: None,
        filtered_peak_acceleration_m_s2: None,
        filtered_fwhm_s: None,
        decimation: 1,
        kinematics: None,
        fits: Fits::default(),
        bounce: s.bounce.get(),
        spectrum: None,
        verdict: None,
    }
}
