//! First touch where the force jumped at it, placed from the contact's law.
//!
//! A damped pad pushes back with `c v0` the instant it is touched (a Kelvin–Voigt pad; the
//! two-phase pad's damper on reloading its dent): the last sample without force and the
//! first with it bracket touch, and nothing in those two says where between them it lies
//! ([`crate::signal::power_flank::steep_zero`] takes the middle: up to half a sample off,
//! 0.8 % of `x_m` for the 60 g body dropped 91 mm on a 1e4 N/m pad at 20 kS/s). The compression that
//! follows does say, if the pad's force is affine in its deformation and velocity,
//! `F = k x + c v`: a touch `s` samples earlier than the middle leaves every deformation
//! the sums integrated `v0 s dt` short, less what the body's deceleration over that extra
//! time (`c v0 / m - g`) took off the velocity since. Fitting the compression's samples with `k`, `c` and `s` (linear
//! least squares in the sums' own variables, the products in f32 and their sums to f64
//! accuracy as the fits do) gives `s`; where the fit holds (its residual within
//! [`JUMP_RESIDUAL`], a stiffness and a damper both positive, `s` within a sample of the
//! middle, then held to the interval), the report's touch, crush, deformations and Δv move
//! with it. `s` rests on the fit's intercept: an error in the baseline or in gravity of
//! `δa` moves it by `δa / (k v0 dt / m)` samples (0.09 per m/s² for that drop at 20 kS/s),
//! which the residual cannot see.
//!
//! In the sums' units (time in samples from the integration's start, velocity `w = v / kv`
//! in units of `C`, deformation `y = x / (kv dt)`), with `V_j = C_j + d_j / 2` the velocity
//! lost by sample `j`'s instant and `Π_j` the deformation lost (its integral):
//!
//! ```text
//! d_j = -K Π_j - Cw V_j + (K w0 - K l s) j
//!       + K y_lead + K w0 / 2 + Cw w0 - G + s (K w0 - K l / 2 - Cw l),   l = Cw w0 - G
//! ```
//!
//! (`G`: gravity's shift of `d` in a vertical contact; `h = Cw w0`: the force at touch, the
//! reading's; `l = h - G`: the body's deceleration then.)

use super::motion::to_f32;
use crate::fit::{solve, Sums};
use crate::report::motion::{Found, Frame};
use crate::signal::baseline::Deviation;

/// Largest RMS residual of the compression's fit, relative to its mean force, for the fit
/// to place touch: an affine pad's samples lie on it within their noise (0.1–0.3 % at
/// 20–500 kS/s with 0.3 counts of noise); a law that is not affine (a Hertz foot that
/// jumped, a pad that stiffens) lies further off, and the middle stands.
pub const JUMP_RESIDUAL: f64 = 0.02;

/// Fewest compression samples the fit needs (four unknowns and their noise).
pub const JUMP_MIN_SAMPLES: usize = 8;

/// Touch placed in the jump's interval: `s` samples earlier than its middle (`-0.5..=0.5`);
/// `h` the force at touch (the reading's, units of `d`) and `lost` the body's deceleration
/// then (`h` less gravity's shift).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shift {
    pub s: f64,
    pub h: f64,
    pub lost: f64,
}

/// The shift of touch from the compression `samples` (from the integration's first up to
/// the crush's sample, exclusive), `dev` the kinematics' deviation (gravity's shift `g_d`
/// taken off), `None` where the law is not affine or the samples too few. Not inlined: its
/// sums stay off the caller's frame.
#[inline(never)]
pub fn shift(
    samples: &[i16],
    dev: Deviation,
    g_d: i64,
    frame: &Frame,
    found: &Found,
) -> Option<Shift> {
    let scale = &frame.scale;
    let n = libm::floor(found.crush + 0.5);
    if !(n >= JUMP_MIN_SAMPLES as f64 && n < samples.len() as f64) {
        return None;
    }
    let n = n as usize;
    let w0 = scale.v0 / scale.kv;
    let (sn, sw) = (n as f32, w0 as f32);
    // Scaled to O(1): time by n, V by w0, Π by n w0, d by its mean w0 / n.
    let (inv_n, inv_w, inv_nw) = (1.0 / sn, 1.0 / sw, 1.0 / (sn * sw));
    let inv_d = sn / sw;
    let mut sums = Sums::<15>::new();
    // C_j and S_j = Σ_{i<j} (C_i + C_{i+1}), exact.
    let (mut c, mut pairs) = (0i64, 0i64);
    for (j, &x) in samples.get(..n)?.iter().enumerate() {
        let d = i64::from(dev.of(x));
        // V_j = C_j + d_j / 2; Π_j = S_j / 2 + C_j / 2 + d_j / 8.
        let (cf, df) = (to_f32(c), d as f32);
        let v = (cf + 0.5 * df) * inv_w;
        let p = (0.5 * (to_f32(pairs) + cf) + 0.125 * df) * inv_nw;
        let t = j as f32 * inv_n;
        let y = d as f32 * inv_d;
        sums.add([
            t,
            v,
            p,
            t * t,
            t * v,
            t * p,
            v * v,
            v * p,
            p * p,
            y,
            t * y,
            v * y,
            p * y,
            y * y,
            1.0,
        ]);
        // (Wrapping: an adversarial scale cannot panic; a real one stays far below 2^62.)
        pairs = pairs.wrapping_add(c.wrapping_mul(2).wrapping_add(d));
        c = c.wrapping_add(d);
    }
    let [st, sv, sp, tt, tv, tp, vv, vp, pp, sy, ty, vy, py, yy, s1] = sums.get();
    let gram = [
        [s1, st, sv, sp],
        [st, tt, tv, tp],
        [sv, tv, vv, vp],
        [sp, tp, vp, pp],
    ];
    let rhs = [sy, ty, vy, py];
    let b = solve(gram, rhs)?;
    // Residual sum of squares: Σ y² - bᵀ (Xᵀ y).
    let rss = yy - b.iter().zip(rhs).map(|(b, r)| b * r).sum::<f64>();
    let rms = libm::sqrt(rss.max(0.0) / s1);
    if !rss.is_finite() {
        return None;
    }
    // Back to the sums' units.
    let d_mean = w0 / n as f64;
    let k = -b[3] * d_mean / (n as f64 * w0);
    let cw = -b[2] * d_mean / w0;
    let b0 = b[0] * d_mean;
    let h = cw * w0;
    let lost = h - g_d as f64;
    let y_lead = scale.x_lead / (scale.kv * scale.dt);
    let lever = k * w0 - (k / 2.0 + cw) * lost;
    let s = (b0 - k * y_lead - k * w0 / 2.0 - cw * w0 + g_d as f64) / lever;
    let fits = rms <= JUMP_RESIDUAL && k > 0.0 && h > 0.0 && lever > 0.0;
    // (Beyond the interval by more than the fit's own scatter: not this law.)
    (fits && s.abs() <= 1.0).then(|| Shift {
        s: s.clamp(-0.5, 0.5),
        h,
        lost,
    })
}

impl Shift {
    /// Moves `frame`'s touch and `found`'s crush and deformations by the shift; `d_crush`:
    /// the crush's sample's deviation (units of `d`, gravity's shift taken off). Returns the
    /// area of the reading the sums missed, as Δv (m/s).
    pub fn apply(&self, frame: &mut Frame, found: &mut Found, d_crush: f64) -> f64 {
        found.x_max += self.at(frame, found.crush).0;
        found.x_sep += self.at(frame, frame.separation).0;
        // The velocity reached zero `lost s / d_crush` samples earlier (no further than the
        // shift itself: a crush's sample that reads less than the force at touch is noise).
        if d_crush > 0.0 {
            // (max/min, not clamp: clamp asserts its bounds are ordered.)
            let half = libm::fabs(self.s);
            found.crush -= (self.lost * self.s / d_crush).max(-half).min(half);
        }
        frame.touch -= self.s;
        frame.scale.kv * self.h * self.s
    }

    /// The shift's change of the deformation (m) and the velocity (m/s) at time `t`
    /// (samples from the integration's start): the deformation was short by
    /// `s dt (v0 - kv l (t + ½))`, the velocity high by `kv l s` (`l`: [`Self::lost`]).
    pub fn at(&self, frame: &Frame, t: f64) -> (f64, f64) {
        let scale = &frame.scale;
        let x = self.s * scale.dt * (scale.v0 - scale.kv * self.lost * (t + 0.5));
        (x, -scale.kv * self.lost * self.s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::motion::Scale;

    /// A pad's compression read every `dt` (counts of `q` m/s² each) with touch `s` samples
    /// before the middle of the interval before sample 0, under gravity `g` (m/s², the body
    /// decelerating at the reading less `g`): the reading `k x + c v` per unit mass, or
    /// `k x^1.5` (`hertz`). With the frame and the crush the sums see, and the true crush
    /// time (s) and maximum deformation (m).
    fn pad(
        k: f64,
        c: f64,
        hertz: bool,
        s: f64,
        g: f64,
    ) -> (heapless::Vec<i16, 512>, Frame, f64, (f64, f64)) {
        pad_at(k, c, hertz, s, g, 1.3357)
    }

    fn pad_at(
        k: f64,
        c: f64,
        hertz: bool,
        s: f64,
        g: f64,
        v0: f64,
    ) -> (heapless::Vec<i16, 512>, Frame, f64, (f64, f64)) {
        let (dt, q) = (5e-5, 0.05);
        let (mut x, mut v, mut t) = (0.0f64, v0, 0.0f64);
        let mut samples = heapless::Vec::<i16, 512>::new();
        let mut crush = None;
        let mut truth = (0.0, 0.0);
        let reading = |x: f64, v: f64| {
            if hertz {
                k * libm::pow(x.max(0.0), 1.5)
            } else {
                k * x + c * v
            }
        };
        // Fine Euler steps from touch at -(0.5 + s) samples.
        let h = dt / 2000.0;
        let mut next = 0.5 + s;
        while samples.len() < 300 {
            while t + h <= next * dt {
                let a = reading(x, v) - g;
                if v > 0.0 && v - a * h <= 0.0 && crush.is_none() {
                    crush = Some(t / dt - 0.5 - s);
                    truth = (t, x);
                }
                x += v * h;
                v -= a * h;
                t += h;
            }
            samples
                .push(libm::round(reading(x, v) / q).clamp(-32000.0, 32000.0) as i16)
                .unwrap();
            next += 1.0;
        }
        let scale = Scale {
            v0,
            kv: q * dt,
            dt,
            x_lead: 0.0,
            count: 1.0,
        };
        let frame = Frame {
            lead: 0,
            touch: -0.5,
            separation: 250.0,
            sep_floor: 250,
            frac: 0.5,
            scale,
        };
        (samples, frame, crush.unwrap(), truth)
    }

    fn found(crush: f64) -> Found {
        Found {
            crush,
            x_max: 0.0,
            x_sep: 0.0,
            step_c: 0,
        }
    }

    #[test]
    fn a_jump_onto_an_affine_pad_is_placed_within_a_tenth_of_a_sample() {
        for s in [-0.45, -0.2, 0.0, 0.3, 0.45] {
            let (samples, frame, crush, _) = pad(1e4 / 0.06, 5.0 / 0.06, false, s, 0.0);
            let dev = Deviation::new(0, 1);
            let got = shift(&samples, dev, 0, &frame, &found(crush)).unwrap();
            assert!((got.s - s).abs() < 0.1, "{s}: {got:?}");
            assert!(
                (got.h / (5.0 / 0.06 * 1.3357 / 0.05) - 1.0).abs() < 0.02,
                "{got:?}"
            );
        }
    }

    /// Under gravity (a drop): the sums integrate the reading less `g`; touch, the crush
    /// time and `x_m` from the sums and the shift within 0.1 % where the interval's middle
    /// was up to 0.8 % off (from 5 mm, 0.313 m/s, where gravity is 37 % of the jump: the
    /// deformation's correction taken from the reading's jump instead of the body's
    /// deceleration leaves `x_m` 0.16 % off).
    #[test]
    fn a_jump_under_gravity_moves_the_kinematics_to_the_truth() {
        let g = crate::consts::STANDARD_GRAVITY;
        for (s, v0) in [
            (-0.45, 1.3357),
            (0.3, 1.3357),
            (0.45, 1.3357),
            (0.45, 0.313),
        ] {
            let (samples, mut frame, _, (crush_s, x_m)) =
                pad_at(1e4 / 0.06, 5.0 / 0.06, false, s, g, v0);
            let dev = Deviation::new(0, 1).above(g / 0.05);
            let g_d = i64::from(Deviation::new(0, 1).of(0)) - i64::from(dev.of(0));
            let (crush, seps) =
                super::super::motion::integrate(&samples, dev, &frame, None).unwrap();
            let mut found = frame.found(crush, seps);
            let crush_time =
                |frame: &Frame, found: &Found| (found.crush - frame.touch) * frame.scale.dt;
            let before = (
                crush_time(&frame, &found) / crush_s - 1.0,
                found.x_max / x_m - 1.0,
            );
            let got = shift(&samples, dev, g_d, &frame, &found).unwrap();
            assert!((got.s - s).abs() < 0.1, "{s}: {got:?}");
            let d_crush = f64::from(dev.of(samples[libm::floor(found.crush + 0.5) as usize]));
            got.apply(&mut frame, &mut found, d_crush);
            let after = (
                crush_time(&frame, &found) / crush_s - 1.0,
                found.x_max / x_m - 1.0,
            );
            assert!(
                after.0.abs() < 1e-3 && after.1.abs() < 1e-3,
                "{s}: {before:?} -> {after:?}"
            );
            assert!(before.1.abs() > 2e-3, "{s}: the middle was off: {before:?}");
        }
    }

    #[test]
    fn a_pad_that_is_not_affine_keeps_the_middle() {
        let dev = Deviation::new(0, 1);
        let (samples, frame, crush, _) = pad(2e7, 0.0, true, 0.3, 0.0);
        assert_eq!(shift(&samples, dev, 0, &frame, &found(crush)), None);
        // Too few samples to fit.
        let (samples, frame, _, _) = pad(1e4 / 0.06, 5.0 / 0.06, false, 0.3, 0.0);
        assert_eq!(shift(&samples, dev, 0, &frame, &found(5.0)), None);
        assert_eq!(shift(&samples[..3], dev, 0, &frame, &found(20.0)), None);
    }
}
