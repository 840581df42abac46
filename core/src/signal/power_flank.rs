//! Where a flank that is a power curve reaches zero force: `|d| = A |x - x0|^p` fitted over
//! the pulse's foot (its points from the edge level to [`FOOT`] of the peak), `p` the power
//! of 1 to 2 that fits best.
//!
//! A contact force `k x^n` rises from first touch as `t^n` (the deformation grows as `v0 t`)
//! and falls to separation the same way, so the straight line [`super::flank`] draws through
//! a Hertz-like flank (`n = 1.5`) puts touch late and separation early: a bounce's flight
//! comes out long and its flight-time speed high. Over the foot the curvature stands out of
//! the noise, where between one and four edge levels it does not.

/// The foot reaches this fraction of the peak.
pub const FOOT: f32 = 0.3;

/// Most points fitted (evenly spread over the foot): the board fits each power in f32.
/// `zero` takes at most this many.
pub const MAX_FOOT_POINTS: usize = 32;

/// Least points for a fit.
pub const MIN_FOOT_POINTS: usize = 6;

/// The powers tried; 1 is the straight line. Only the laws' own powers (linear, Hertz, and a
/// square law for foams and felts): a finer grid lets the noise pick between close powers,
/// and a zero extrapolated a few samples moves by tenths of a millisecond with the power.
pub const POWERS: [f32; 3] = [1.0, 1.5, 2.0];

/// The largest reading, as a fraction of the peak, a power fit may give at the sample next
/// to its foot (a larger one is a jump, not a foot).
pub const JUMP: f32 = 0.02;

/// A fit other than the straight line is taken when its unexplained variance (`1 - R²` of
/// `|d|^(1/p)` against `x`) is below this fraction of the line's.
pub const BETTER: f32 = 0.5;

/// The zero of the best power fit to `points` (position in samples, `|d| / peak` in `(0, 1]`)
/// and its power, if a power above 1 fits clearly better than the line, or `prior` (the power
/// an earlier foot of the same contact showed clearly) fits no worse than it (else the line's
/// zero where the caller asks for it, [`Choice::Free`]'s `line`; else `None`: the caller's
/// straight-line estimate stands), and it is a flank: rising (`rising`) or falling, its zero
/// within one point spacing of `outside` (the sample next to the foot, within the edge
/// level) and no further beyond it than the fitted curve takes to rise to four edge levels,
/// and the fit reading at most `1.5 edge` or [`JUMP`] at `outside` (`edge` as a fraction of
/// the peak).
pub fn zero<I>(points: I, rising: bool, outside: f32, edge: f32, choice: Choice) -> Option<Foot>
where
    I: Iterator<Item = (f32, f32)>,
{
    let mut x = [0.0f32; MAX_FOOT_POINTS];
    let mut y = [0.0f32; MAX_FOOT_POINTS];
    let mut n = 0usize;
    for ((xi, yi), (px, py)) in x.iter_mut().zip(y.iter_mut()).zip(points) {
        *xi = px;
        *yi = py;
        n += 1;
    }
    let (x, y) = (x.get(..n)?, y.get(..n)?);
    fit(x, y, rising, outside, edge, choice)
}

/// [`zero`] over the points gathered (one copy of the fits in the firmware, whatever the
/// points' iterator).
#[inline(never)]
fn fit(
    xs: &[f32],
    ys: &[f32],
    rising: bool,
    outside: f32,
    edge: f32,
    choice: Choice,
) -> Option<Foot> {
    // Each point's |d|^(1/p) for each power, computed once (a cube root and a square root:
    // the FPU's).
    let n = xs.len().min(ys.len()).min(MAX_FOOT_POINTS);
    if n < MIN_FOOT_POINTS {
        return None;
    }
    let mut z = [[0.0f32; MAX_FOOT_POINTS]; 3];
    let [z1, z15, z2] = &mut z;
    for (((a, b), c), &py) in z1.iter_mut().zip(z15.iter_mut()).zip(z2.iter_mut()).zip(ys) {
        *a = py;
        *b = root(py, 1.5);
        *c = root(py, 2.0);
    }
    let (x, nf) = (xs.get(..n)?, n as f32);
    let mean_x = x.iter().sum::<f32>() / nf;
    // (1 - R², slope, intercept) of |d|^(1/p) against x.
    let fit = |z: &[f32]| {
        let z = z.get(..n).unwrap_or(&[]);
        let mean_z = z.iter().sum::<f32>() / nf;
        let (mut sxx, mut szz, mut sxz) = (0.0f32, 0.0f32, 0.0f32);
        for (&xi, &zi) in x.iter().zip(z) {
            let (dx, dz) = (xi - mean_x, zi - mean_z);
            sxx += dx * dx;
            szz += dz * dz;
            sxz += dx * dz;
        }
        let slope = sxz / sxx;
        (
            1.0 - sxz * sxz / (sxx * szz),
            slope,
            mean_z - slope * mean_x,
        )
    };
    let fits = [fit(&z[0]), fit(&z[1]), fit(&z[2])];
    let line = fits[0].0;
    let (k, (unexplained, slope, icept)) = (1..POWERS.len())
        .zip(fits.iter().skip(1))
        .map(|(k, f)| (k, *f))
        .fold((0, (f32::INFINITY, 0.0, 0.0)), |best, c| {
            if c.1 .0 < best.1 .0 {
                c
            } else {
                best
            }
        });
    let clear = unexplained.is_finite() && line.is_finite() && unexplained < BETTER * line;
    // The power the same contact showed clearly before (`prior`) wherever it fits at least as
    // well as the line: a smaller impact's noise may favour another power by chance, and a
    // zero extrapolated with the wrong one is off by many samples.
    let (prior, only, line_ok) = match choice {
        Choice::Free { prior, line } => (prior, false, line),
        Choice::Only(p) => (Some(p), true, false),
    };
    let prior = POWERS
        .iter()
        .position(|&p| Some(p) == prior)
        .filter(|&j| j > 0)
        .and_then(|j| fits.get(j).map(|f| (j, *f)))
        .filter(|(_, f)| f.0.is_finite() && f.0 <= line);
    let (k, (_, slope, icept), clear) = match prior {
        Some((j, f)) => (j, f, false),
        None if clear && !only => (k, (unexplained, slope, icept), true),
        None if line_ok => (0, fits[0], false),
        None => return None,
    };
    let x0 = -icept / slope;
    let span = x
        .iter()
        .map(|&xi| libm::fabsf(xi - outside))
        .fold(0.0f32, f32::max);
    // At `outside` the fit reads at most 1.5 edge levels, or JUMP of the peak: a flank that
    // starts with a jump (Kelvin–Voigt's `c v0`) reads more; a power curve fitted over the
    // foot may read a little more than the edge there when the edge is a tiny part of it.
    let p = POWERS.get(k).copied().unwrap_or(1.0);
    let at = power((icept + slope * outside).max(0.0), p);
    let below = at <= (1.5 * edge).max(JUMP);
    // The curve reaches four edge levels at most `(4 edge / FOOT)^(1/p)` of the foot's span
    // from its zero (less where the deceleration bends it): the zero lies no further beyond
    // `outside` (a tail the power does not describe, as a damped law's long return, would
    // put it far out).
    let reach = root(4.0 * edge / FOOT, p) * span + 1.0;
    let within = if rising {
        slope > 0.0 && x0 <= outside + 1.0 && x0 >= outside - reach
    } else {
        slope < 0.0 && x0 >= outside - 1.0 && x0 <= outside + reach
    };
    (below && within && x0.is_finite()).then_some(Foot {
        zero: x0,
        power: p,
        slope,
        clear,
    })
}

/// Where a foot that stepped from within the edge level past the flank level in one sample
/// reaches zero, relative to its first sample, from its first three samples `y` (deviations,
/// the pulse positive, the first at 0): under the power of [`POWERS`] that puts the three
/// most nearly on a line (`|d|^(1/p)` against the position), the line through the first two
/// where it reaches zero within the interval before the first (a foot the sampling is too
/// coarse to fit: a 1 ms contact at 20 kS/s); else the middle of that interval (a jump,
/// Kelvin–Voigt's `c v0`: touch lies anywhere in it, and its middle is the estimate with no
/// bias). In `[-1, 0]`. (A jump onto a ramp, `c v0 + k v0 t`, is a straight line too: it
/// reads as a ramp that began up to a sample earlier.)
pub fn steep_zero(y: [f32; 3]) -> f32 {
    steep_line_zero(y).unwrap_or(JUMP_MIDDLE)
}

/// Where [`steep_zero`] puts a jump's touch: the middle of the interval before it.
pub const JUMP_MIDDLE: f32 = -0.5;

/// [`steep_zero`]'s line's zero, `None` where it takes the middle of the interval (a jump;
/// a zero it gives may be a jump's too, onto a ramp: the stream's caller says so).
pub fn steep_line_zero(y: [f32; 3]) -> Option<f32> {
    steep_line(y).map(|(zero, _)| zero)
}

/// [`steep_line_zero`], and whether its curve is a straight line (power 1: a jump onto a
/// ramp gives one; a power curve other than the line, none).
pub fn steep_line(y: [f32; 3]) -> Option<(f32, bool)> {
    head_fit(y)
        .map(|h| (h.zero, h.p == 1.0))
        .filter(|(zero, _)| (-1.0..=0.0).contains(zero))
}

/// How far the middle of three samples may lie off the line through the outer two, over
/// the rise, for [`head_zero`] to take their line: a power curve's three first samples lie
/// on it within 0.3 % (a Hertz foot at 20 kS/s, its first sample a tenth of a sample in);
/// noise, or a law between the powers (an exponent of 1.6: 0.9–2.3 %, its zero up to 0.09
/// samples off), puts them further off, and the caller's estimate stands.
pub const HEAD_BEND: f32 = 0.02;

/// Where a foot whose first sample lies just past the edge level (its flank too short for a
/// line: fewer than three samples to the flank level), or just within it on the foot, reaches
/// zero, relative to that sample, from its
/// first three samples `y`, as [`steep_zero`] does, but only where the power puts them on a
/// line (within [`HEAD_BEND`]) whose zero lies in the interval before the first: a foot the
/// sampling resolves in three samples (a Hertz contact's `t^1.5` at 20 kS/s). Else `None`
/// (the caller's estimate stands).
pub fn head_zero(y: [f32; 3]) -> Option<f32> {
    head_zero_line(y).map(|(zero, _)| zero)
}

/// [`head_zero`], and whether its curve is a straight line (power 1).
pub fn head_zero_line(y: [f32; 3]) -> Option<(f32, bool)> {
    let h = head_fit(y)?;
    ((-1.0..=0.0).contains(&h.zero) && h.bend <= HEAD_BEND).then_some((h.zero, h.p == 1.0))
}

/// [`head_reach`]'s answer: the curve's zero (samples from the head's first), its value at
/// the time asked (0 before its zero), and whether it is a straight line (power 1: a jump
/// onto a ramp gives one too, so a line's zero before a quiet sample may be a jump's after
/// it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reach {
    pub zero: f32,
    pub at: f32,
    pub line: bool,
}

/// The zero of [`head_zero`]'s curve through three rising samples (the first at 0) where
/// they lie on one (within [`HEAD_BEND`]), wherever it lies, and the curve's value at `t`.
pub fn head_reach(y: [f32; 3], t: f32) -> Option<Reach> {
    let h = head_fit(y)?;
    let z = h.z0 + (h.z1 - h.z0) * t;
    (h.bend <= HEAD_BEND).then(|| Reach {
        zero: h.zero,
        at: h.top * power(z.max(0.0), h.p),
        line: h.p == 1.0,
    })
}

/// [`head_fit`]'s curve: `y = top (z0 + (z1 - z0) t)^p` through the first two samples.
struct Head {
    zero: f32,
    bend: f32,
    p: f32,
    top: f32,
    z0: f32,
    z1: f32,
}

fn head_fit(y: [f32; 3]) -> Option<Head> {
    let [y0, y1, y2] = y;
    if !(y0 > 0.0 && y1 > y0 && y2.is_finite()) {
        return None;
    }
    // Scaled by the largest, so each root is of a number in (0, 1].
    let top = y0.max(y1).max(y2);
    let (bend, z, p) = POWERS
        .iter()
        .map(|&p| {
            let z = [
                root(y0 / top, p),
                root(y1 / top, p),
                root(y2.max(0.0) / top, p),
            ];
            // How far the middle lies off the line through the outer two, over the rise.
            let bend =
                libm::fabsf(z[1] - 0.5 * (z[0] + z[2])) / (z[2] - z[0]).max(f32::MIN_POSITIVE);
            (bend, z, p)
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))?;
    let zero = -z[0] / (z[1] - z[0]);
    zero.is_finite().then_some(Head {
        zero,
        bend,
        p,
        top,
        z0: z[0],
        z1: z[1],
    })
}

/// Which powers a fit may take.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Choice {
    /// The best (see [`zero`]), or `prior` where it fits no worse than the line; with
    /// `line`, the straight line itself where no power is clearly better (the caller has no
    /// better line: its flank between the edge and flank levels held too few samples, or
    /// stepped past the flank level in one).
    Free { prior: Option<f32>, line: bool },
    /// This power only, where it fits no worse than the line (a falling foot takes its
    /// rising foot's: a damped law's slow return is no power curve, and a foot fitted as
    /// one there would put separation far out in it).
    Only(f32),
}

/// A foot fitted as `|d| / peak = (slope (x - zero))^power` (`slope` negative on a falling
/// flank, so the base is positive on the pulse's side).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Foot {
    /// Where the force is zero, samples (in the points' positions).
    pub zero: f32,
    pub power: f32,
    pub slope: f32,
    /// The power fitted clearly better than the line, with no prior taken.
    pub clear: bool,
}

impl Foot {
    /// The fitted `|d| / peak` at position `x` (0 on the far side of the zero).
    pub fn at(&self, x: f32) -> f32 {
        power((self.slope * (x - self.zero)).max(0.0), self.power)
    }

    /// `Σ |d| / peak` of the fit over the whole samples from `from` to `to` (exclusive): the
    /// foot's part of a Δv the samples beyond the edge level leave out.
    pub fn sum(&self, from: i64, to: i64) -> f32 {
        (from..to).map(|x| self.at(x as f32)).sum()
    }
}

/// `b^p` for the powers of [`POWERS`] (`b >= 0`), by the FPU's square root.
fn power(b: f32, p: f32) -> f32 {
    if p == 1.5 {
        b * libm::sqrtf(b)
    } else if p == 2.0 {
        b * b
    } else {
        b
    }
}

/// `y^(1/p)` for the powers of [`POWERS`] (`y >= 0`): the inverse of [`power`].
fn root(y: f32, p: f32) -> f32 {
    if p == 1.5 {
        let c = cbrt(y);
        c * c
    } else if p == 2.0 {
        libm::sqrtf(y)
    } else {
        y
    }
}

/// The cube root of `y > 0` in f32 alone (libm's goes through f64, which the Cortex-M4's FPU
/// does not have: ~2000 cycles a call): an exponent-thirding first guess and three Newton
/// steps, within 2 ulp.
fn cbrt(y: f32) -> f32 {
    if !(y > 0.0 && y.is_finite()) {
        return 0.0;
    }
    let mut t = f32::from_bits(y.to_bits() / 3 + 709_958_130);
    for _ in 0..3 {
        t = (2.0 * t + y / (t * t)) * (1.0 / 3.0);
    }
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `(x, ((x - x0)/w)^p)` for the samples of the foot after `x0`.
    fn foot(x0: f32, p: f32, w: f32, rising: bool) -> impl Iterator<Item = (f32, f32)> + Clone {
        (-60..60)
            .map(move |k| {
                let x = k as f32;
                let u = if rising { x - x0 } else { x0 - x };
                (x, if u > 0.0 { libm::powf(u / w, p) } else { 0.0 })
            })
            .filter(|q| q.1 > 0.02 && q.1 <= FOOT)
    }

    /// The first three samples of feet `A (x - x0)^p` from `x0` in the interval before the
    /// first sample: the zero of each law's power within a few hundredths of a sample; a
    /// jump onto a slow ramp gives the middle.
    #[test]
    fn a_steep_foot_is_placed_within_its_interval_and_a_jump_at_its_middle() {
        for p in POWERS {
            for x0 in [-0.9f32, -0.5, -0.1] {
                let y = [0.0f32, 1.0, 2.0].map(|x| 40.0 * power(x - x0, p));
                let z = steep_zero(y);
                assert!((z - x0).abs() < 0.02, "power {p}, zero {x0}: {z}");
            }
        }
        assert_eq!(steep_zero([100.0, 104.0, 108.0]), -0.5);
        assert_eq!(steep_zero([0.0, 10.0, 20.0]), -0.5);
        assert_eq!(steep_zero([10.0, 10.0, 20.0]), -0.5);
        assert_eq!(steep_zero([f32::NAN, 10.0, 20.0]), -0.5);
    }

    #[test]
    fn a_head_on_a_power_curve_gives_its_zero_and_any_other_none() {
        // The Hertz foot at 20 kS/s that the walk back put 0.87 samples early.
        let z = head_zero([56402.0, 1411154.0, 3620690.0]).unwrap();
        assert!((z + 0.134).abs() < 0.01, "{z}");
        for p in POWERS {
            let y = [0.0f32, 1.0, 2.0].map(|x| 40.0 * power(x + 0.3, p));
            assert!((head_zero(y).unwrap() + 0.3).abs() < 0.02, "power {p}");
        }
        // Bent off every power's line (noise on a slow foot), a zero beyond the interval,
        // no rise: none.
        assert_eq!(head_zero([10.0, 30.0, 31.0]), None);
        assert_eq!(head_zero([100.0, 104.0, 108.0]), None);
        assert_eq!(head_zero([10.0, 10.0, 20.0]), None);
        assert_eq!(head_zero([f32::NAN, 10.0, 20.0]), None);
    }

    #[test]
    fn the_f32_cube_root_is_libms() {
        for k in 1..2000 {
            let y = k as f32 * 0.0005;
            let (got, want) = (cbrt(y), libm::cbrtf(y));
            assert!((got - want).abs() <= 2.5e-7 * want, "{y}: {got} vs {want}");
        }
        assert_eq!(cbrt(0.0), 0.0);
        assert_eq!(cbrt(f32::NAN), 0.0);
    }

    #[test]
    fn a_hertz_foot_extrapolates_to_its_touch_and_a_straight_one_is_left_to_the_line() {
        for (x0, rising) in [(-3.4f32, true), (2.6, false)] {
            let pts = foot(x0, 1.5, 40.0, rising);
            let outside = if rising {
                pts.clone().map(|q| q.0).fold(f32::MAX, f32::min) - 1.0
            } else {
                pts.clone().map(|q| q.0).fold(f32::MIN, f32::max) + 1.0
            };
            let f = zero(
                pts.clone(),
                rising,
                outside,
                0.02,
                Choice::Free {
                    prior: None,
                    line: false,
                },
            )
            .unwrap();
            assert!((f.zero - x0).abs() < 0.05, "{} vs {x0}", f.zero);
            assert_eq!(f.power, 1.5);
            for (x, y) in pts {
                assert!(
                    (f.at(x) - y).abs() < 2e-3 * y.max(0.05),
                    "{x}: {} vs {y}",
                    f.at(x)
                );
            }
        }
        // A straight foot: the caller's line stands, or this one's where it is asked for.
        let pts = foot(-3.4, 1.0, 40.0, true);
        let outside = pts.clone().map(|q| q.0).fold(f32::MAX, f32::min) - 1.0;
        let free = |line| Choice::Free { prior: None, line };
        assert_eq!(zero(pts.clone(), true, outside, 0.02, free(false)), None);
        let line = zero(pts, true, outside, 0.02, free(true)).unwrap();
        assert!((line.zero + 3.4).abs() < 0.05, "{}", line.zero);
        assert_eq!((line.power, line.clear), (1.0, false));
        // Too few points.
        assert_eq!(
            zero(
                [(0.0, 0.1), (1.0, 0.2)].into_iter(),
                true,
                -1.0,
                0.05,
                Choice::Free {
                    prior: None,
                    line: false
                }
            ),
            None
        );
    }

    /// [`head_reach`]: a Hertz head (`t^1.5`) whose zero lies 0.02 of a sample before the
    /// sample before it gives that zero and reads that sample within a thousandth of the
    /// head's top; a jump onto a ramp (`A + B t`) reads `A − (1 − τ) B` there, not 0; an
    /// unbent head off every power is none.
    #[test]
    fn head_reach_extends_a_power_head_one_sample_back() {
        for (p, x0) in [(1.5f32, -1.02f32), (1.0, -1.3), (2.0, -1.6)] {
            let y = [0.0f32, 1.0, 2.0].map(|k| libm::powf(k - x0, p));
            let Reach { zero, at, line } = head_reach(y, -1.0).unwrap();
            assert_eq!(line, p == 1.0);
            let truth = libm::powf(-1.0 - x0, p);
            assert!((zero - x0).abs() < 1e-3, "{p} {x0}: {zero}");
            assert!(
                (at - truth).abs() < 1e-3 * y[2],
                "{p} {x0}: {at} vs {truth}"
            );
        }
        // A jump of A onto a ramp of B a sample, its first sample tau after touch.
        let (a, b, tau) = (0.675f32, 1.0f32, 0.4f32);
        let y = [0.0f32, 1.0, 2.0].map(|k| a + b * (k + tau));
        let Reach { zero, at, line } = head_reach(y, -1.0).unwrap();
        assert!(line);
        assert!((zero + a / b + tau).abs() < 1e-4, "{zero}");
        assert!((at - (a - (1.0 - tau) * b)).abs() < 1e-4, "{at}");
        // Three samples that bend beyond every power: none.
        assert_eq!(head_reach([1.0, 10.0, 10.5], -1.0), None);
    }
}
