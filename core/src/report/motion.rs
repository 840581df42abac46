//! The frame of an impact's kinematics, shared by the two ways its motion is integrated: the
//! pass over a capture ([`crate::analysis::motion`]) and the sums the stream keeps online
//! (`stream/online.rs`). Both integrate `d' = W x - S - G` (the deviation from the frozen
//! baseline, less gravity's shift `G` in a vertical contact) from the first whole sample of
//! the contact's foot, and both hand their states here, so the two give the same bits.
//!
//! After `k` samples of the integration, `C_k = Σ_{j<k} d'_j` and `Q_k = Σ_{j=1..k} C_j`:
//!
//! ```text
//! v_k = v0 - kv C_k                          (kv = gain / (W fs), m/s per unit of C)
//! x_k = x_lead + dt (k v0 - kv T_k / 2)      (trapezoid; T_k = 2 Q_k - C_k)
//! ```
//!
//! Samples are instants (sample `j` at time `j`, in samples from the integration's start),
//! each standing for the interval `[j - ½, j + ½)` (the midpoint rule): `v_k` is the velocity
//! at time `k - ½`, and `x_k` the deformation then (`x_lead` the deformation at `-½`).

use super::summary::Summary;
pub use super::summary::{Found, Missing, Record};
use super::{rebound_m_s, Flags, ImpactReport, Kinematics, COR_TOLERANCE};
use crate::scene::Scene;
use crate::signal::baseline::Deviation;

/// The sums after `k` samples: `(k, C_k, Q_k)`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Sums {
    pub k: u32,
    pub c: i64,
    pub q: i64,
}

impl Sums {
    /// `T_k = 2 Q_k - C_k`.
    pub fn t(&self) -> i64 {
        self.q.wrapping_mul(2).wrapping_sub(self.c)
    }
}

/// Where the velocity first reached zero: the state before the sample whose `C` first reached
/// [`Scale::c_stop`], and `C` after it; and the deviations (`d'`) of the samples just before
/// and just after that one, where the sums' samples hold both (a force that steps at the
/// crush is placed from them: [`Frame::found`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Crush {
    pub at: Sums,
    pub c_next: i64,
    pub beside: Option<(i32, i32)>,
}

/// A force steps at the crush where the crush's sample lies this many times further from
/// one neighbour than from the other (the nearer at least [`STEP_NOISE`] ADC counts off)…
pub const STEP_RATIO: f64 = 8.0;
/// …counting the nearer neighbour at least this many ADC counts off (quantised samples are
/// often equal: their noise is what a step must stand out of)…
pub const STEP_NOISE: f64 = 2.0;
/// …and the step is at least this share of the crush's sample: a pad that crushes and
/// unloads along another line (the two-phase law's `kc x_m` to `kr (x_m - x_p)`: 14 % on the
/// seed's pad), not the noise on a smooth force (Kelvin–Voigt's force falls through the
/// crush, an elastic law's peaks there: both neighbours alike)…
pub const STEP_SHARE: f64 = 0.05;
/// …in a contact of at least this many samples: coarser, a smooth force bends enough
/// between samples to look like one (a Kelvin–Voigt contact of 6–14 samples, its peak just
/// before the crush: one phase in five), and a step's half sample is no longer the error
/// that matters.
pub const STEP_MIN_SAMPLES: f64 = 32.0;

/// How far past the sample's instant the stop may lie on the side its sample does not
/// read, samples, and still be the step's (placed at the instant): the sums' own error puts
/// a stop that lies at the instant a little either side of it.
pub const STEP_SLACK: f64 = 0.05;

/// A force that steps at the crush, placed there: the crush's sample stands for the whole
/// interval around it (the midpoint rule), which holds the force before the step up to the
/// crush and the force after it beyond.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Step {
    /// The crush, in samples from the start of the crush sample's interval (`[0, 1]`).
    f: f64,
    /// The area the sums missed over that interval, in units of `C`.
    c: f64,
}

impl Step {
    /// The step at `crush`, if its sample and neighbours show one that lies where the sums
    /// put the stop: `rem` is `C` left to the stop before the crush's sample (`v / kv`),
    /// `count` one ADC count in units of `C`'s samples.
    fn of(crush: &Crush, rem: f64, count: f64) -> Option<Self> {
        let (before, after) = crush.beside?;
        let d = crush.c_next.wrapping_sub(crush.at.c) as f64;
        let (p, q) = (before as f64, after as f64);
        let (to_p, to_q) = (libm::fabs(d - p), libm::fabs(d - q));
        let (near, far) = (to_p.min(to_q), to_p.max(to_q));
        let floor = STEP_NOISE * count;
        if !(d > 0.0 && far > STEP_RATIO * near.max(floor) && far > STEP_SHARE * d) {
            return None;
        }
        if to_p <= to_q {
            // The sample reads the loading side: the step came after its instant, where
            // the force `d` reached the stop.
            let f = rem / d;
            (0.5 - STEP_SLACK..=1.0).contains(&f).then(|| {
                let f = f.max(0.5);
                Self {
                    f,
                    c: (q - d) * (1.0 - f),
                }
            })
        } else {
            // The unloading side: the force was the loading side's `p` up to the stop, before
            // the sample's instant.
            let f = rem / p;
            (p > 0.0 && (0.0..=0.5 + STEP_SLACK).contains(&f)).then(|| {
                let f = f.min(0.5);
                Self { f, c: (p - d) * f }
            })
        }
    }
}

/// What turns sums into metres and metres per second.
#[derive(Clone, Copy, Debug)]
pub struct Scale {
    /// Approach speed, m/s.
    pub v0: f64,
    /// Velocity per unit of `C`, m/s (`gain / (W fs)`).
    pub kv: f64,
    /// Sample period, s.
    pub dt: f64,
    /// Deformation at half a sample before the integration's first sample, m (first touch
    /// came a fraction of a sample earlier or later, at `v0`: negative if later).
    pub x_lead: f64,
    /// One ADC count in units of the deviation `d'` (the baseline's samples `W`).
    pub count: f64,
}

impl Scale {
    /// The scale of an impact at `v0` measured from a baseline of `base_n` samples in
    /// `scene` (`kv = gain / (W fs)`), the deformation `x_lead` at its first half sample.
    pub fn new(v0: f64, scene: &Scene, base_n: i64, x_lead: f64) -> Self {
        let fs = scene.calibration.sample_rate_hz as f64;
        Self {
            v0,
            kv: scene.calibration.gain_m_s2_per_count as f64 / base_n.max(1) as f64 / fs,
            dt: 1.0 / fs,
            x_lead,
            count: base_n.max(1) as f64,
        }
    }

    pub fn velocity(&self, c: i64) -> f64 {
        self.v0 - self.kv * c as f64
    }

    /// Deformation after `k` samples, with `t = T_k`.
    pub fn deformation(&self, k: u32, t: i64) -> f64 {
        self.x_lead + self.dt * (k as f64 * self.v0 - self.kv * t as f64 / 2.0)
    }

    /// Stopped (`v <= 0`) once `C >= c_stop`; `None` if the scale cannot stop anything.
    pub fn c_stop(&self) -> Option<i64> {
        if !(self.kv > 0.0 && self.kv.is_finite() && self.v0 > 0.0) {
            return None;
        }
        let c = libm::ceil(self.v0 / self.kv);
        Some(if c < i64::MAX as f64 {
            c as i64
        } else {
            i64::MAX
        })
    }
}

/// An impact's kinematic frame, from its summary: where the integration starts, where first
/// touch and the separation lie, and the scale.
#[derive(Clone, Copy, Debug)]
pub struct Frame {
    /// Whole samples of the foot before the onset the integration starts with.
    pub lead: u32,
    /// First touch, fractional samples from the integration's first sample (`<= 0` … `< 1`).
    pub touch: f64,
    /// Samples first touch may lie from `touch` where it is a jump's that the contact's law
    /// has not placed ([`Summary::touch_reach`]); 0 where none, or placed.
    pub touch_reach: f64,
    /// The separation, fractional samples from the integration's first sample.
    pub separation: f64,
    /// The separation's two states are after `sep_floor` and `sep_floor + 1` samples, and
    /// the separation lies `frac` of the way between them.
    pub sep_floor: u32,
    pub frac: f64,
    pub scale: Scale,
}

/// The deviation the kinematics integrate for the baseline `base_sum / base_n`: the reading's
/// less gravity in a vertical contact (the body decelerates at the reading less `g`).
pub fn motion_deviation(base_sum: i64, base_n: i64, scene: &Scene) -> Deviation {
    let deviation = Deviation::new(base_sum, base_n);
    match scene.contact_gravity_m_s2() {
        Some(g) => deviation.above(g as f64 / scene.calibration.gain_m_s2_per_count as f64),
        None => deviation,
    }
}

impl Frame {
    /// The frame of summary `s` if its kinematics can be known (an approach speed, a
    /// separation); `held`: the samples a capture holds from the window's first sample on
    /// (the pass over it stops at its end), `None` for the online sums.
    pub fn of(s: &Summary, scene: &Scene, held: Option<usize>) -> Option<Self> {
        let v0 = s.v0_m_s? as f64;
        let sep_index = s.separation_index?;
        let onset = s.onset_index.checked_sub(s.first_index)?;
        let onset = usize::try_from(onset).ok()?;
        // The whole samples between first touch and the onset are the contact's foot (its Δv
        // counts them, [`Summary::contact_c`]): the integration starts at the first of them.
        let lead = (libm::floor(-(s.touch_offset as f64)).max(0.0) as usize).min(onset);
        let fs = scene.calibration.sample_rate_hz as f64;
        let dt = 1.0 / fs;
        // Fractional positions from the first sample of the integration.
        let touch = s.touch_offset as f64 + lead as f64;
        let first_quiet = sep_index.checked_sub(s.onset_index)? as f64 + lead as f64;
        let separation = first_quiet + s.separation_offset as f64;
        // (A falling foot's zero may lie a little past the hold's end, where a capture stops:
        // the pass stops at its last sample; a separation sample beyond it is no stop.)
        let separation = match held {
            Some(n) => {
                let captured = n.saturating_sub(onset - lead + 1) as f64;
                if first_quiet <= captured {
                    separation.min(captured)
                } else {
                    separation
                }
            }
            None => separation,
        };
        if !(separation >= 0.0) {
            return None;
        }
        // The deformation at time `s` is the sums' after `s + ½` samples (midpoint rule).
        let sep_at = separation + 0.5;
        let sep_floor = libm::floor(sep_at);
        if !(sep_floor < u32::MAX as f64 - 1.0) {
            return None;
        }
        Some(Self {
            lead: lead as u32,
            touch,
            touch_reach: f64::from(s.touch_reach),
            separation,
            sep_floor: sep_floor as u32,
            frac: sep_at - sep_floor,
            // The sums start half a sample before their first sample's instant (the midpoint
            // rule); from first touch to there the body moves at ~v0 (a touch within that
            // half sample leaves the body short of it: negative).
            scale: Scale::new(v0, scene, s.base_n, v0 * (-touch - 0.5) * dt),
        })
    }

    /// The kinematics from the crush and the separation's two states. A force that steps at
    /// the crush ([`STEP_RATIO`], [`STEP_SHARE`]: the two-phase law unloading along another
    /// line) is placed there, not at the crush sample's interval's edge: the crush within
    /// the interval from the force on the stop's side, and the area the sums missed
    /// (`step_c`: half a sample of the step at most) added to the velocity after it.
    pub fn found(&self, crush: Crush, separation: [Sums; 2]) -> Found {
        let scale = &self.scale;
        let (v, v_next) = (scale.velocity(crush.at.c), scale.velocity(crush.c_next));
        let resolved = self.separation - self.touch >= STEP_MIN_SAMPLES;
        let step = resolved
            .then(|| Step::of(&crush, v / scale.kv, scale.count))
            .flatten();
        let f = step.map_or(v / (v - v_next), |s| s.f);
        let x_max = scale.deformation(crush.at.k, crush.at.t()) + scale.dt * f * v / 2.0;
        let [s0, s1] = separation;
        let (x0, x1) = (
            scale.deformation(s0.k, s0.t()),
            scale.deformation(s1.k, s1.t()),
        );
        // The velocity after the crush's interval is `kv step_c` lower than the sums': the
        // deformation at the separation, that much less for the time since.
        let step_c = step.map_or(0.0, |s| s.c);
        let since = (self.separation - (crush.at.k as f64 + 0.5)).max(0.0);
        Found {
            crush: crush.at.k as f64 + f - 0.5,
            x_max,
            x_sep: x0 + self.frac * (x1 - x0) - scale.kv * step_c * scale.dt * since,
            step_c: libm::round(step_c) as i64,
        }
    }
}

/// Fewest samples from first touch to the crush for the crush time and the deformations
/// ([`Flags::UNDERSAMPLED`]). Where the force steps or rises steeply at touch, first touch
/// lies somewhere in the interval before the onset, and the foot's power curve or the jump's
/// law places it there; where that guess is wrong (the samples cannot tell a steep foot from
/// a jump at some touch phases) first touch is off by 0.3 to 0.9 of a sample, which moves
/// the crush time by that share of the compression and `x_m` by `v0` times it. On 1 ms
/// contacts (`docs/accuracy.md`) that is up to −15 % at 10 kS/s (5 samples to the crush),
/// −28 % at 5 kS/s; 8 samples (a 1 ms contact at 16 kS/s) and more report them.
pub const MIN_CRUSH_SAMPLES: f64 = 8.0;

/// Where first touch lies in a jump's interval that the contact's law has not placed
/// ([`Frame::touch_reach`]), the crush time and the deformations stand only where the
/// farthest touch may lie from where it was put, at `v0`, is at most this share of `x_m`
/// (else [`Flags::UNDERSAMPLED`]): the samples cannot tell where in that interval the
/// contact began (measured: a Kelvin–Voigt pad at 20 kS/s, `x_m` +6.5 % on a wall and +7 %
/// on a target; half a sample is 0.7 % of its `x_m` at 100 kS/s).
pub const JUMP_TOUCH_SHARE: f64 = 0.01;

/// Whether first touch, `reach` samples from where `frame` puts it at most, is known
/// closely enough for the crush time and the deformations at `x_max` ([`JUMP_TOUCH_SHARE`]).
pub fn touch_placed(reach: f64, frame: &Frame, x_max: f64) -> bool {
    reach <= 0.0 || reach * frame.scale.dt * frame.scale.v0 <= JUMP_TOUCH_SHARE * x_max
}

/// Fills in `r`'s kinematics from what the sums found in `frame`: the rebound from the
/// report's Δv, the COR (flagged and left out beyond its tolerance), the energy absorbed;
/// the crush time and the deformations where the compression spans [`MIN_CRUSH_SAMPLES`]
/// and first touch is known closely enough ([`touch_placed`]; else flagged
/// [`Flags::UNDERSAMPLED`] and left out). The set a pad keeps comes from the
/// fits ([`crate::fit::set`]).
pub fn kinematics(r: &mut ImpactReport, scene: &Scene, frame: &Frame, found: &Found) {
    // (Again where a jump's law moved first touch: [`crate::analysis`].)
    r.flags.remove(Flags::UNDERSAMPLED);
    let v0 = frame.scale.v0 as f32;
    let gravity = scene.contact_gravity_m_s2();
    let Some(rebound) = rebound_m_s(r, v0, gravity) else {
        return;
    };
    let cor = rebound / v0;
    if !(-COR_TOLERANCE..=1.0 + COR_TOLERANCE).contains(&cor) {
        r.flags.insert(Flags::COR_OUT_OF_RANGE);
        return;
    }
    let crush_s = (found.crush - frame.touch) * frame.scale.dt;
    // In the stream's samples (a decimated capture's pass counts coarser values).
    let resolved = crush_s * scene.calibration.sample_rate_hz as f64 >= MIN_CRUSH_SAMPLES
        && touch_placed(frame.touch_reach, frame, found.x_max);
    if !resolved {
        r.flags.insert(Flags::UNDERSAMPLED);
    }
    let held = |v: f64| resolved.then_some(v as f32);
    r.kinematics = Some(Kinematics {
        impact_velocity_m_s: v0,
        crush_time_s: held(crush_s),
        max_deformation_m: held(found.x_max),
        rebound_velocity_m_s: rebound,
        cor,
        separation_deformation_m: held(found.x_sep),
        permanent_deformation_m: None,
        // Gravity's work over the contact counts in a vertical one.
        absorbed_energy_j: scene.mass_kg.map(|m| {
            0.5 * m * (v0 * v0 - rebound * rebound)
                + gravity.map_or(0.0, |g| m * g * found.x_sep as f32)
        }),
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The crush's sample `d` after `c` of the sums, its neighbours `p` and `q`.
    fn crush(c: i64, d: i64, p: i64, q: i64) -> Crush {
        Crush {
            at: Sums { k: 10, c, q: 0 },
            c_next: c + d,
            beside: Some((p as i32, q as i32)),
        }
    }

    #[test]
    fn a_force_that_steps_at_the_crush_is_placed_there() {
        // Loading at 1000 counts, unloading at 800: the stop 700 of `C` into the sample.
        // The sample reads the loading side (the step after its instant): the stop at 0.7 of
        // the interval, the rest of it at 800, not 1000.
        let s = Step::of(&crush(0, 1000, 1000, 800), 700.0, 1.0).unwrap();
        assert!(
            (s.f - 0.7).abs() < 1e-12 && (s.c - -200.0 * 0.3).abs() < 1e-9,
            "{s:?}"
        );
        // The sample reads the unloading side: the stop 300 in at the loading force, 0.3 of
        // the interval, which the sums took at 800.
        let s = Step::of(&crush(0, 800, 1000, 800), 300.0, 1.0).unwrap();
        assert!(
            (s.f - 0.3).abs() < 1e-12 && (s.c - 200.0 * 0.3).abs() < 1e-9,
            "{s:?}"
        );
        // A stop just past the sample's instant on the side its sample does not read (the
        // sums' own error): the step at the instant.
        let s = Step::of(&crush(0, 1000, 1000, 800), 480.0, 1.0).unwrap();
        assert!(
            (s.f - 0.5).abs() < 1e-12 && (s.c - -100.0).abs() < 1e-9,
            "{s:?}"
        );
        let s = Step::of(&crush(0, 800, 1000, 800), 520.0, 1.0).unwrap();
        assert!(
            (s.f - 0.5).abs() < 1e-12 && (s.c - 100.0).abs() < 1e-9,
            "{s:?}"
        );
        // A stop the step cannot lie at (the loading side's sample puts it well before its
        // instant; the unloading side's well after): none.
        assert_eq!(Step::of(&crush(0, 1000, 1000, 800), 300.0, 1.0), None);
        assert_eq!(Step::of(&crush(0, 800, 1000, 800), 700.0, 1.0), None);
    }

    #[test]
    fn a_smooth_force_through_the_crush_is_no_step() {
        // An elastic law's peak (both neighbours a little lower), Kelvin–Voigt's falling
        // force (evenly), a step under 5 % of the force: none.
        for (d, p, q) in [(1000, 990, 990), (1000, 1010, 990), (1000, 1000, 960)] {
            assert_eq!(
                Step::of(&crush(0, d, p, q), 500.0, 1.0),
                None,
                "{d} {p} {q}"
            );
        }
        // Noise on a small pulse (100 counts): the nearer neighbour a count off, the other
        // 12 (in units of `d'`, 16 to a count): a step for a floor of a fraction of a count,
        // none for [`STEP_NOISE`] counts.
        let noisy = crush(0, 100 * 16, 101 * 16, 88 * 16);
        assert!(Step::of(&noisy, 1200.0, 1.0 / 16.0).is_some());
        assert_eq!(Step::of(&noisy, 1200.0, 16.0), None);
        let none = Crush {
            beside: None,
            ..crush(0, 1000, 1000, 800)
        };
        assert_eq!(Step::of(&none, 700.0, 1.0), None);
    }

    /// A frame whose sums start at first touch, at `v0` 1 m/s and 1 count = 1 unit of `d'`,
    /// separating after `len` samples.
    fn frame(len: f64) -> Frame {
        let sep_at = len + 0.5;
        Frame {
            lead: 0,
            touch: 0.0,
            touch_reach: 0.0,
            separation: len,
            sep_floor: libm::floor(sep_at) as u32,
            frac: sep_at - libm::floor(sep_at),
            scale: Scale {
                v0: 1.0,
                kv: 1e-3,
                dt: 1e-4,
                x_lead: 0.0,
                count: 1.0,
            },
        }
    }

    #[test]
    fn a_step_counts_only_in_a_contact_the_sampling_resolves() {
        // A Kelvin–Voigt contact of 10 samples at 20 kS/s whose peak lies just before the
        // crush: 982, 992 at the crush, 907 after (its sample nearer the one before): no
        // step, though it reads as one; the same in a contact of 40 samples, a step.
        let (c, d) = (1000 - 700, 992);
        let crush = Crush {
            at: Sums { k: 5, c, q: 0 },
            c_next: c + d,
            beside: Some((982, 907)),
        };
        let sums = [Sums::default(); 2];
        assert_eq!(frame(10.0).found(crush, sums).step_c, 0);
        assert_ne!(frame(40.0).found(crush, sums).step_c, 0);
    }
}
