//! What a bench is and which stages of the pipeline it needs; shared by host and firmware.

use crate::consts::STANDARD_GRAVITY;
use crate::error::Error;
use crate::error::{non_negative, positive};
use crate::signal::cfc::Cfc;
use crate::signal::lowpass::Lowpass;
use crate::signal::spectrum::SpectrumSettings;
use crate::signal::window_filter::WindowFilter;
use crate::signal::Calibration;
pub mod train;

pub use train::{Train, TrainSpeed};

/// Heaviest impactor, kg: above any drop weight, and forces and energies stay finite f32.
pub const MAX_MASS_KG: f32 = 1e6;

/// Fastest sample rate, Hz.
pub const MAX_RATE_HZ: f32 = 1e8;

/// How the approach speed `v0` is known (an accelerometer alone cannot tell it).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Approach {
    /// Unknown: COR, crush time, deformations and fits are not reported.
    Unknown,
    /// Measured or configured approach speed, m/s.
    Speed { v0_m_s: f32 },
    /// Free drop from rest, m: `v0 = sqrt(2 g h)`.
    DropHeight { height_m: f32 },
}

impl Approach {
    /// The approach speed, m/s, if known, under gravity `gravity_m_s2` (a drop's).
    pub fn v0_m_s(&self, gravity_m_s2: f32) -> Option<f32> {
        match *self {
            Approach::Unknown => None,
            Approach::Speed { v0_m_s } => Some(v0_m_s),
            Approach::DropHeight { height_m } => Some(libm::sqrtf(2.0 * gravity_m_s2 * height_m)),
        }
    }
}

/// Which models to identify per impact (each needs `v0` and the mass).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FitSet {
    /// Two-phase Kelvin–Voigt: `kc`, `kr`, `c`, `x_p`.
    pub two_phase: bool,
    /// Nonlinear `k x^n (1 + c v)`: `k`, `c` (and `n` if `fit_exponent`).
    pub nonlinear: bool,
    /// Fit the nonlinear exponent too (else `nonlinear_exponent` is used).
    pub fit_exponent: bool,
    /// Exponent used when it is not fitted (seed 001: 1; Hunt–Crossley: 1.5).
    pub nonlinear_exponent: f32,
    /// Hertz `F = K x^1.5`.
    pub hertz: bool,
}

impl FitSet {
    /// Every model, the exponent fitted.
    pub fn all() -> Self {
        Self {
            two_phase: true,
            nonlinear: true,
            fit_exponent: true,
            nonlinear_exponent: 1.0,
            hertz: true,
        }
    }

    /// No fits.
    pub fn none() -> Self {
        Self {
            nonlinear_exponent: 1.0,
            ..Self::default()
        }
    }

    pub fn any(&self) -> bool {
        self.two_phase || self.nonlinear || self.hertz
    }
}

/// A bench: sensor, body, triggering and the stages to run. SI units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scene {
    pub calibration: Calibration,
    /// Mass of the instrumented body, kg (for forces, energies and fits).
    pub mass_kg: Option<f32>,
    pub approach: Approach,
    /// An impact starts when |a| exceeds this, m/s² (above the baseline).
    pub trigger_m_s2: f32,
    /// A pulse's edges (onset, separation) are where |a| crosses this, m/s²; `< trigger`.
    pub edge_m_s2: f32,
    /// An impact ends after |a| stays below `edge` for this long, s; with a CFC, for at least
    /// the filter's padding (SAE J211: `rate / (1.667 class)` samples, as far as half the
    /// capture allows). A new hit after an eighth of it back at the baseline is a new impact.
    pub hold_s: f32,
    /// An impact still going after this long is reported as too long, s (a stuck sensor).
    pub max_impact_s: f32,
    /// A signal that stays flat at a new level (beyond the edge level from the baseline) for
    /// this long has settled there, s: a DC sensor's free fall or rest, not an impact; the
    /// baseline is learned again. Longer than any pulse's flat top, at least the hold.
    pub settle_s: f32,
    /// Raw values at or beyond which the sensor is clipped (`(low, high)` rails).
    pub clip_counts: (i16, i16),
    /// Phaseless SAE J211 filter for the captured window's acceleration.
    pub cfc: Option<Cfc>,
    /// Or a phaseless Butterworth low-pass of the lab's choosing (not both:
    /// [`Scene::window_filter`]).
    pub lowpass: Option<Lowpass>,
    /// Causal J211 filter on the live trigger path (rejects spikes and noise above the
    /// class; costs an f64 biquad per idle sample, so it is off unless asked for).
    pub trigger_cfc: Option<Cfc>,
    pub fits: FitSet,
    /// Gravity along the sensor's axis, m/s² (standard gravity unless the bench says): in the
    /// contact of a vertical impact ([`Scene::contact_gravity_m_s2`]), a drop's approach
    /// speed and a train's flights.
    pub gravity_m_s2: f32,
    /// The impact is vertical although neither a drop height nor a train says so (a body
    /// dropped at a measured speed, a light gate above the pad).
    pub vertical: bool,
    /// Every impact comes at the scene's approach speed (a rig that strikes again and again
    /// at one speed). Otherwise the speed is the first impact's, and an impact that follows
    /// a flight (a bounce) has no approach speed unless a train measures it
    /// ([`crate::stream::train`]).
    pub v0_every: bool,
    /// Bounce trains: each impact after the first takes its approach speed from the flight
    /// since the previous separation or from the previous rebound ([`crate::stream::train`]).
    pub train: Option<Train>,
    /// Shock spectra (SRS, PVSS, enveloping half-sine) of each captured impact
    /// ([`crate::signal::spectrum`]).
    pub spectrum: Option<SpectrumSettings>,
    /// A specified shock pulse each captured impact is judged against ([`crate::spec`]).
    pub spec: Option<crate::spec::Spec>,
    /// Send each captured window off the board after its analysis ([`crate::waveform`]):
    /// 0 not, 1 whole, `N` the mean of every `N` samples.
    pub waveform_every: u16,
    /// The body struck a target that moves, not a rigid wall (the analysis's `target`
    /// pass): a mass on a spring and damper to ground, or a linear state space. The COR,
    /// crush time, deformations and absorbed energy are the contact's, relative to the
    /// target's measured-force response. `None`: a rigid, fixed barrier.
    pub target: Option<crate::two_body::SceneTarget>,
}

impl Scene {
    /// The settings three axes are zeroed with in this scene
    /// ([`crate::signal::axes_zero`]), each axis's rails `rails` (counts): the edge level
    /// and settle time in the scene's counts and samples, free fall below a quarter of its
    /// gravity for 10 ms (at least 8 samples: a pulse's zero crossing is quicker, a flight
    /// between bounces longer). The board's ADXL375 source and `impact emulate --adxl375`
    /// take these, so both zero alike.
    pub fn axes_zero(&self, rails: [(i16, i16); 3]) -> crate::signal::axes_zero::Settings {
        use crate::signal::axes_zero::{FreeFall, Settings};
        let gain = f64::from(self.calibration.gain_m_s2_per_count);
        let rate = f64::from(self.calibration.sample_rate_hz);
        Settings {
            edge_counts: (f64::from(self.edge_m_s2) / gain) as f32,
            settle_samples: (f64::from(self.settle_s) * rate).clamp(0.0, f64::from(u32::MAX))
                as u32,
            free_fall: FreeFall {
                below_counts: (0.25 * f64::from(self.gravity_m_s2) / gain) as f32,
                samples: (0.01 * rate).clamp(8.0, f64::from(u32::MAX)) as u32,
            },
            rails,
        }
    }

    /// A scene with the usual defaults: trigger at `trigger_m_s2`, edges at a quarter of it,
    /// 1 ms hold, 50 ms to settle at a new level, 1 s maximum impact, full i16 rails, no
    /// filter, no fits.
    pub fn new(calibration: Calibration, trigger_m_s2: f32) -> Self {
        Self {
            calibration,
            mass_kg: None,
            approach: Approach::Unknown,
            trigger_m_s2,
            edge_m_s2: trigger_m_s2 / 4.0,
            hold_s: 1e-3,
            max_impact_s: 1.0,
            settle_s: 0.05,
            clip_counts: (i16::MIN, i16::MAX),
            cfc: None,
            lowpass: None,
            trigger_cfc: None,
            fits: FitSet::none(),
            gravity_m_s2: STANDARD_GRAVITY as f32,
            vertical: false,
            v0_every: false,
            train: None,
            spectrum: None,
            spec: None,
            waveform_every: 0,
            target: None,
        }
    }

    /// Gravity in the contact, m/s², by the one rule that decides whether an impact is
    /// vertical: a drop from a height, a bounce train (every impact but the first follows a
    /// flight, and the first a fall), or a scene that says `vertical`. `None`: horizontal.
    ///
    /// An accelerometer reads specific force: in a vertical contact the body's deceleration
    /// is the reading less `g`, so the kinematics integrate `a - g` (the pulse's area, the
    /// `delta_v_m_s` the shock standards define, stays the reading's).
    pub fn contact_gravity_m_s2(&self) -> Option<f32> {
        let vertical = self.vertical
            || self.train.is_some()
            || matches!(self.approach, Approach::DropHeight { .. });
        vertical.then_some(self.gravity_m_s2)
    }

    /// The approach speed, m/s, if known (a drop's under the scene's gravity).
    pub fn v0_m_s(&self) -> Option<f32> {
        self.approach.v0_m_s(self.gravity_m_s2)
    }

    /// Checks every field, naming the offending one.
    pub fn validate(&self) -> Result<(), Error> {
        let c = &self.calibration;
        if !(c.gain_m_s2_per_count.is_finite() && c.gain_m_s2_per_count != 0.0) {
            return Err(Error::InvalidParameter {
                name: "gain",
                reason: "must be finite and non-zero",
            });
        }
        positive(c.sample_rate_hz, "rate")?;
        if c.sample_rate_hz > MAX_RATE_HZ {
            return Err(Error::InvalidParameter {
                name: "rate",
                reason: "must be at most 100 MHz",
            });
        }
        if let Some(m) = self.mass_kg {
            positive(m, "mass")?;
            // `m a` at the largest reading the gain allows (±2^16 counts from the baseline)
            // must be a finite f32 force, with room for the energies.
            let largest_force = m as f64 * c.gain_m_s2_per_count.abs() as f64 * 65536.0;
            if !(m <= MAX_MASS_KG && largest_force <= f32::MAX as f64 / 1e3) {
                return Err(Error::InvalidParameter {
                    name: "mass",
                    reason:
                        "must be at most 1e6 kg, and mass x the gain's full scale a finite force",
                });
            }
        }
        match self.approach {
            Approach::Unknown => {}
            Approach::Speed { v0_m_s } => positive(v0_m_s, "v0")?,
            Approach::DropHeight { height_m } => positive(height_m, "drop-height")?,
        }
        positive(self.gravity_m_s2, "gravity")?;
        // Gravity in counts, as the kinematics subtract it: within the sensor's range.
        if self.contact_gravity_m_s2().is_some()
            && !(self.gravity_m_s2 / libm::fabsf(c.gain_m_s2_per_count) <= 32768.0)
        {
            return Err(Error::InvalidParameter {
                name: "gravity",
                reason: "must be within the sensor's range (at most 32768 counts)",
            });
        }
        if let Some(t) = self.target {
            use crate::two_body::SceneTarget;
            // Named as the user gave it: the spring–mass's options, or the state space.
            let name = match t {
                SceneTarget::SpringMass(s) => {
                    positive(s.mass_kg, "target-mass")?;
                    non_negative(s.stiffness_n_m, "target-stiffness")?;
                    non_negative(s.damping_n_s_m, "target-damping")?;
                    "target-mass"
                }
                SceneTarget::StateSpace(t) => {
                    t.validate()?;
                    "target"
                }
            };
            if self.mass_kg.is_none() {
                return Err(Error::InvalidParameter {
                    name,
                    reason: "needs the body's mass: the measured force (mass times the reading) drives the target",
                });
            }
            if self.train.is_some() {
                return Err(Error::InvalidParameter {
                    name,
                    reason: "cannot be given with a bounce train: each contact's kinematics assume the target at rest at first touch, and a bounce comes back to a target still moving",
                });
            }
            // The target's motion after the largest force the sensor can read, held for
            // the longest pass, must be a finite f32 (at this rate; a decimated capture's
            // coarser step gives less).
            let dt = 1.0 / c.sample_rate_hz as f64;
            let largest_force =
                self.mass_kg.unwrap_or(0.0) as f64 * c.gain_m_s2_per_count.abs() as f64 * 65536.0;
            // (The longest pass: the analysis's exact sums cover at most 2^17 samples.)
            let steps = (1u32 << 17) as f64;
            let finite = crate::two_body::step::Stepper::new(&t, dt).is_some_and(|d| {
                d.largest_gain() as f64 * largest_force * steps <= f32::MAX as f64 / 1e3
            });
            if !finite {
                return Err(Error::InvalidParameter {
                    name,
                    reason: match t {
                        SceneTarget::SpringMass(_) => "too light for the forces the sensor reads: the target's motion would overflow",
                        SceneTarget::StateSpace(_) => "too compliant for the forces the sensor reads: the target's motion would overflow",
                    },
                });
            }
        }
        if let Some(t) = self.train {
            positive(t.max_flight_s, "max-flight")?;
        }
        if let Some(sp) = self.spectrum {
            sp.check(c.sample_rate_hz)?;
        }
        if let Some(spec) = self.spec {
            spec.validate()?;
        }
        positive(self.trigger_m_s2, "trigger")?;
        positive(self.edge_m_s2, "edge")?;
        if self.edge_m_s2 >= self.trigger_m_s2 {
            return Err(Error::InvalidParameter {
                name: "edge",
                reason: "must be below the trigger level",
            });
        }
        positive(self.hold_s, "hold")?;
        positive(self.max_impact_s, "max-impact")?;
        if !(self.hold_s <= self.max_impact_s) {
            return Err(Error::InvalidParameter {
                name: "hold",
                reason: "must not exceed the longest impact (max-impact, default 1 s)",
            });
        }
        positive(self.settle_s, "settle")?;
        if self.settle_s < self.hold_s {
            return Err(Error::InvalidParameter {
                name: "settle",
                reason: "must be at least the hold time",
            });
        }
        if self.clip_counts.0 >= self.clip_counts.1 {
            return Err(Error::InvalidParameter {
                name: "clip",
                reason: "low rail must be below high rail",
            });
        }
        if self.fits.any()
            && !(self.fits.nonlinear_exponent >= 1.0 && self.fits.nonlinear_exponent <= 4.0)
        {
            return Err(Error::InvalidParameter {
                name: "exponent",
                reason: "must lie in [1, 4]",
            });
        }
        for (class, name) in [(self.cfc, "cfc"), (self.trigger_cfc, "trigger-cfc")] {
            if let Some(class) = class {
                if crate::signal::cfc::Biquad::cfc(class, c.sample_rate_hz as f64).is_none() {
                    return Err(Error::InvalidParameter {
                        name,
                        reason: "sample rate too low for this class",
                    });
                }
            }
        }
        if let Some(l) = self.lowpass {
            if self.cfc.is_some() {
                return Err(Error::InvalidParameter {
                    name: "lowpass",
                    reason: "one filter on the captured windows: a CFC or a low-pass, not both",
                });
            }
            l.check(c.sample_rate_hz)?;
        }
        #[cfg(not(feature = "cfc"))]
        for (on, name) in [
            (self.cfc.is_some(), "cfc"),
            (self.lowpass.is_some(), "lowpass"),
        ] {
            if on {
                return Err(Error::InvalidParameter {
                    name,
                    reason: "filtering not compiled in (feature `cfc`)",
                });
            }
        }
        #[cfg(not(feature = "fit"))]
        if self.fits.any() {
            return Err(Error::InvalidParameter {
                name: "fit",
                reason: "fits not compiled in (feature `fit`)",
            });
        }
        Ok(())
    }

    /// The phaseless filter on the captured windows: the CFC class, or the low-pass.
    pub fn window_filter(&self) -> Option<WindowFilter> {
        match (self.cfc, self.lowpass) {
            (Some(c), _) => Some(WindowFilter::Cfc(c)),
            (None, Some(l)) => Some(WindowFilter::Lowpass(l)),
            (None, None) => None,
        }
    }

    /// Samples a capture holds beyond the impact's contact on either side, as far as the
    /// signal reaches: the window filter's padding (the CFC's, SAE J211, or the low-pass's)
    /// or the specified pulse's verdict's, whichever is longer; 0 with neither.
    pub fn padding_samples(&self) -> u32 {
        let rate = self.calibration.sample_rate_hz;
        self.window_filter()
            .map_or(0, |f| f.padding_samples(rate))
            .max(self.spec.map_or(0, |s| s.padding_samples(rate)))
    }

    /// Samples in `seconds`, at least 1.
    pub fn samples(&self, seconds: f32) -> u32 {
        let n = seconds * self.calibration.sample_rate_hz;
        if n >= u32::MAX as f32 {
            u32::MAX
        } else if n >= 1.0 {
            n as u32
        } else {
            1
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::two_body::{SceneTarget, SpringMass, Target};
    extern crate std;

    fn with_target(mass_kg: f32, stiffness_n_m: f32) -> Scene {
        let mut s = Scene::new(
            Calibration {
                gain_m_s2_per_count: 1.0,
                sample_rate_hz: 500e3,
            },
            10.0,
        );
        s.mass_kg = Some(0.06);
        s.target = Some(SceneTarget::SpringMass(SpringMass {
            mass_kg,
            stiffness_n_m,
            damping_n_s_m: 0.0,
        }));
        s
    }

    #[test]
    fn a_target_the_pass_cannot_step_in_f32_is_refused() {
        assert_eq!(with_target(0.3, 4e4).validate(), Ok(()));
        // So light that the largest force the sensor reads would overflow its velocity.
        let err = with_target(1e-36, 0.0).validate();
        assert!(
            matches!(
                err,
                Err(Error::InvalidParameter {
                    name: "target-mass",
                    ..
                })
            ),
            "{err:?}"
        );
        let err = with_target(0.3, -1.0).validate();
        assert!(
            matches!(
                err,
                Err(Error::InvalidParameter {
                    name: "target-stiffness",
                    ..
                })
            ),
            "{err:?}"
        );
        let mut no_mass = with_target(0.3, 0.0);
        no_mass.mass_kg = None;
        assert!(no_mass.validate().is_err());
        // A state space is checked as one, named `target`: here an unstable one.
        let mut unstable = with_target(0.3, 0.0);
        let mut t = Target::of_spring_mass(SpringMass {
            mass_kg: 0.3,
            stiffness_n_m: -4e4,
            damping_n_s_m: 0.0,
        });
        t.spring_mass = None;
        static UNSTABLE: std::sync::OnceLock<Target<f32>> = std::sync::OnceLock::new();
        unstable.target = Some(SceneTarget::StateSpace(UNSTABLE.get_or_init(|| t)));
        let err = unstable.validate();
        assert!(
            matches!(err, Err(Error::InvalidParameter { name: "target", .. })),
            "{err:?}"
        );
        // And a stable one passes.
        t.a[1][0] = 4e4 / -0.3;
        static STABLE: std::sync::OnceLock<Target<f32>> = std::sync::OnceLock::new();
        unstable.target = Some(SceneTarget::StateSpace(STABLE.get_or_init(|| t)));
        assert_eq!(unstable.validate(), Ok(()));
    }
}
