//! The measured motion of one captured impact: one pass of exact integer sums over the
//! capture (the frame, the formulas and the midpoint rule in [`crate::report::motion`]) that
//! gives the crush and the separation's states and, for the fits, the deformation and
//! velocity at evenly spaced points of the contact.
//!
//! With the baseline frozen as the rational `S / W`, sample `j` contributes the integer
//! `d_j = W x_j - S` (less gravity's shift in a vertical contact). `C_k` and `Q_k` are exact
//! (i64: `|d| < 2^29`, and at most 2^17 samples keep `|Q| <= |d| k (k + 1) / 2` below 2^62):
//! nothing drifts however long the capture; the only rounding is the conversion of the sums
//! at the few points where a value is needed. Per sample the pass costs two i64 additions
//! (no floating point), which is what makes it cheap on the Cortex-M4. The stream keeps the
//! same sums online (`stream/online.rs`), so a contact longer than the capture has them too.

use crate::report::motion::{Crush, Frame, Sums};
use crate::signal::baseline::Deviation;

/// Longest run the sums may cover, samples (keeps `Q` within i64).
pub const MAX_SAMPLES: usize = 1 << 17;

/// Where the fit points go: `x[i]` and `v[i]` get the deformation (m) and the velocity (in
/// units of `v0`) after sample `every * i` of the contact, for `i < x.len()`.
pub struct PointsOut<'a> {
    pub x: &'a mut [f32],
    pub v: &'a mut [f32],
    pub every: usize,
}

/// `v` as f32 by the FPU's 32-bit conversions (two of them, a multiply-add; `i64 as f32` is
/// a soft-float call on the Cortex-M4): within two f32 roundings of the exact value.
#[inline]
pub(crate) fn to_f32(v: i64) -> f32 {
    // Sign and magnitude: both halves non-negative, so nothing cancels.
    let m = v.unsigned_abs();
    let f = (m >> 32) as u32 as f32 * 4_294_967_296.0 + m as u32 as f32;
    if v < 0 {
        -f
    } else {
        f
    }
}

/// Integrates `samples` (the next ones), without looking for the crush.
#[inline]
fn run(s: &mut Sums, samples: &[i16], dev: Deviation) {
    let (mut c, mut q) = (s.c, s.q);
    for &x in samples {
        c += dev.of(x) as i64;
        q += c;
    }
    s.c = c;
    s.q = q;
    s.k += samples.len() as u32;
}

/// Integrates `samples` until `C` first reaches `c_stop` (it is below it on entry): returns
/// the crush (the state before the sample that reached it, and `C` after it) and stops
/// there.
#[inline]
fn run_to_stop(s: &mut Sums, samples: &[i16], dev: Deviation, c_stop: i64) -> Option<Crush> {
    let (mut c, mut q) = (s.c, s.q);
    let mut rest = samples.iter();
    let mut hit = None;
    for &x in rest.by_ref() {
        let c_next = c + dev.of(x) as i64;
        if c_next >= c_stop {
            hit = Some(c_next);
            break;
        }
        c = c_next;
        q += c;
    }
    // Samples integrated before the hit (the hit itself is the one taken out last).
    let before = samples.len() - rest.len() - usize::from(hit.is_some());
    let at = Sums {
        k: s.k + before as u32,
        c,
        q,
    };
    match hit {
        Some(c_next) => {
            *s = Sums {
                k: at.k + 1,
                c: c_next,
                q: q + c_next,
            };
            Some(Crush {
                at,
                c_next,
                beside: None,
            })
        }
        None => {
            *s = at;
            None
        }
    }
}

/// The deviations of the samples just before and after sample `k` of `samples`, if both
/// are there ([`Crush::beside`]).
pub(crate) fn beside(samples: &[i16], k: usize, dev: Deviation) -> Option<(i32, i32)> {
    let before = samples.get(k.checked_sub(1)?)?;
    let after = samples.get(k.checked_add(1)?)?;
    Some((dev.of(*before), dev.of(*after)))
}

/// Runs the sums over `samples` (the raw samples from the frame's first; `dev` removes the
/// baseline and gravity): the crush (first zero of the velocity) and the states around the
/// separation, and the fit points if asked. `None` if the velocity never reaches zero or the
/// separation lies beyond the samples.
pub fn integrate(
    samples: &[i16],
    dev: Deviation,
    frame: &Frame,
    mut points: Option<PointsOut<'_>>,
) -> Option<(Crush, [Sums; 2])> {
    let samples = samples.get(..samples.len().min(MAX_SAMPLES)).unwrap_or(&[]);
    let scale = &frame.scale;
    let c_stop = scale.c_stop()?;
    let sep_floor = frame.sep_floor as usize;
    let n_points = points.as_ref().map_or(0, |p| p.x.len().min(p.v.len()));
    let every = points.as_ref().map_or(1, |p| p.every.max(1));
    // The points in f32 (one conversion of each sum, a multiply-add): the velocity in units
    // of v0, V = 1 - (kv / v0) C, and the deformation x = x_lead + k v0 dt - (kv dt / 2) T.
    let pv = (scale.kv / scale.v0) as f32;
    let px = (
        scale.x_lead as f32,
        (scale.v0 * scale.dt) as f32,
        (scale.kv * scale.dt / 2.0) as f32,
    );

    // Events in order of k: point i at k = every i + 1 (the state after sample every i), the
    // separation's two samples. Between events the sums run in tight loops.
    let mut s = Sums::default();
    let mut crush: Option<Crush> = None;
    let mut at_sep: [Option<Sums>; 2] = [None, None];
    let mut point = 0usize;
    loop {
        let next_point = if point < n_points {
            every * point + 1
        } else {
            usize::MAX
        };
        let next_sep = match at_sep {
            [None, _] => sep_floor,
            [Some(_), None] => sep_floor + 1,
            _ => usize::MAX,
        };
        let next = next_point.min(next_sep);
        if next > samples.len() {
            break;
        }
        let k = s.k as usize;
        let run_samples = samples.get(k..next).unwrap_or(&[]);
        if crush.is_none() {
            if let Some(found) = run_to_stop(&mut s, run_samples, dev, c_stop) {
                crush = Some(found);
                let k = s.k as usize;
                run(&mut s, samples.get(k..next).unwrap_or(&[]), dev);
            }
        } else {
            run(&mut s, run_samples, dev);
        }
        if next_point == next {
            if let Some(p) = points.as_mut() {
                if let (Some(x), Some(v)) = (p.x.get_mut(point), p.v.get_mut(point)) {
                    *v = 1.0 - pv * to_f32(s.c);
                    // (`fmax` inline: `f32::max` is a libm call on the M4, once a point.)
                    *x = crate::numeric::fmax(px.0 + px.1 * s.k as f32 - px.2 * to_f32(s.t()), 0.0);
                }
            }
            point += 1;
        }
        if next_sep == next {
            if let Some(slot) = at_sep.get_mut(next - sep_floor) {
                *slot = Some(s);
            }
        }
    }
    // The crush may come after the last event.
    if crush.is_none() {
        let k = s.k as usize;
        crush = run_to_stop(&mut s, samples.get(k..).unwrap_or(&[]), dev, c_stop);
    }
    let mut crush = crush?;
    // (Not within the foot, where the online sums look for no step either.)
    if crush.at.k >= frame.lead {
        crush.beside = beside(samples, crush.at.k as usize, dev);
    }
    let [Some(s0), Some(s1)] = at_sep else {
        return None;
    };
    Some((crush, [s0, s1]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::motion::Scale;

    /// A constant deceleration of `a` counts from the onset: v = v0 - kv a k, exactly.
    #[test]
    fn the_two_part_conversion_is_within_two_roundings() {
        for v in [
            0i64,
            1,
            -1,
            123_456_789_012,
            -(1 << 62) + 12_345,
            (1 << 40) + 7,
            i64::MAX,
        ] {
            let exact = v as f64;
            let got = to_f32(v) as f64;
            assert!(
                (got - exact).abs() <= exact.abs() * 2.0 * f32::EPSILON as f64,
                "{v}"
            );
        }
    }

    /// A frame whose sums start at the first sample, the separation at `separation`.
    fn frame(scale: Scale, separation: f64) -> Frame {
        let sep_at = separation + 0.5;
        Frame {
            lead: 0,
            touch: 0.0,
            touch_reach: 0.0,
            separation,
            sep_floor: sep_at.floor() as u32,
            frac: sep_at - sep_at.floor(),
            scale,
        }
    }

    #[test]
    fn a_constant_deceleration_stops_where_the_algebra_says() {
        let dev = Deviation::new(0, 1);
        let samples = [10i16; 1000];
        let scale = Scale {
            v0: 1.0,
            kv: 1e-3,
            dt: 1e-3,
            x_lead: 0.0,
            count: 1.0,
        };
        let fr = frame(scale, 150.5);
        // The sums start half a sample before the onset's instant (x_lead there): v reaches 0
        // after 1 / (1e-3 * 10) = 100 samples, at 99.5; x then is v0^2 / (2 a) with
        // a = 10 * kv / dt = 10 m/s²: 0.05 m.
        let mut x = [0f32; 4];
        let mut v = [0f32; 4];
        let (crush, sep) = integrate(
            &samples,
            dev,
            &fr,
            Some(PointsOut {
                x: &mut x,
                v: &mut v,
                every: 40,
            }),
        )
        .unwrap();
        let f = fr.found(crush, sep);
        assert!((f.crush - 99.5).abs() < 1e-9, "{}", f.crush);
        assert!((f.x_max - 0.05).abs() < 1e-9, "{}", f.x_max);
        // At 150.5 samples, 151 after the start: 0.05 - 10 (0.051)^2 / 2 (moving back out).
        let want = 0.05 - 10.0 * 0.051f64.powi(2) / 2.0;
        assert!((f.x_sep - want).abs() < 2e-6, "{} {want}", f.x_sep);
        // Point i: after sample 40 i, k = 40 i + 1: v = 1 - 0.01 k.
        for (i, (&x, &v)) in x.iter().zip(&v).enumerate() {
            let k = (40 * i + 1) as f64;
            assert!((v as f64 - (1.0 - 0.01 * k)).abs() < 1e-6, "{i}: {v}");
            let want = 1e-3 * k - 10.0 * (1e-3 * k).powi(2) / 2.0;
            assert!((x as f64 - want).abs() < 1e-7, "{i}: {x} {want}");
        }
        // No stop within the samples: nothing.
        assert!(integrate(&samples[..50], dev, &frame(scale, 40.0), None).is_none());
    }
}
