//! A specified shock pulse (half-sine, terminal-peak sawtooth, trapezoid of a peak and a
//! duration) and the tolerances it is judged with: the band the measured acceleration must lie
//! within, and the velocity change's. The verdict of a captured impact is [`verdict`].
//!
//! The band follows the figures of the shock-test standards (IEC 60068-2-27, MIL-STD-810
//! Method 516, MIL-STD-202 Method 213; the numbers of each preset and their sources are in
//! docs/standards.md): within the pulse the nominal acceleration ± `band` × the peak, widened
//! in time by `slack` × the duration on each side (the peak may come that much early or late,
//! a sawtooth's drop takes that long); before and after it, within ± `outside` × the peak.
//! The nominal pulse is placed where the measured one fits best (the standards: "any measured
//! pulse which can be contained between the boundaries" is a nominal pulse).
//!
//! A user's own band ([`Spec::band`], a table of [`BandPoint`]s read by linear interpolation)
//! replaces the band and slack; `outside` still applies before its first row and after its
//! last.

mod half_sine;
pub mod record;
pub mod verdict;
#[cfg(test)]
mod verdict_reference;

use crate::error::Error;
use crate::numeric::{fmax, fmin};

/// A nominal pulse's shape.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Shape {
    /// `A sin(π t / D)`.
    HalfSine,
    /// Terminal-peak (final-peak) sawtooth: `A t / D`, then down to 0.
    Sawtooth,
    /// A linear rise over `rise` × D, flat at A, a linear fall over `fall` × D.
    Trapezoid { rise: f32, fall: f32 },
}

impl Shape {
    /// The name a specification uses (`half-sine`, `sawtooth`, `trapezoid`).
    pub fn name(self) -> &'static str {
        match self {
            Shape::HalfSine => "half-sine",
            Shape::Sawtooth => "sawtooth",
            Shape::Trapezoid { .. } => "trapezoid",
        }
    }

    /// The nominal acceleration over the peak at `u` = time / duration (0 outside `[0, 1]`).
    pub fn at(self, u: f32) -> f32 {
        if !(0.0..=1.0).contains(&u) {
            return 0.0;
        }
        match self {
            Shape::HalfSine => libm::sinf(core::f32::consts::PI * u),
            Shape::Sawtooth => u,
            Shape::Trapezoid { rise, fall } => {
                if u < rise {
                    u / rise
                } else if u > 1.0 - fall {
                    (1.0 - u) / fall
                } else {
                    1.0
                }
            }
        }
    }

    /// The nominal velocity change over the peak times the duration (the shape's area).
    pub fn area(self) -> f32 {
        match self {
            Shape::HalfSine => 2.0 / core::f32::consts::PI,
            Shape::Sawtooth => 0.5,
            Shape::Trapezoid { rise, fall } => 1.0 - (rise + fall) / 2.0,
        }
    }

    /// Where the nominal pulse peaks, over the duration (a trapezoid: the middle of its top).
    pub fn peak_at(self) -> f32 {
        match self {
            Shape::HalfSine => 0.5,
            Shape::Sawtooth => 1.0,
            Shape::Trapezoid { rise, fall } => (rise + 1.0 - fall) / 2.0,
        }
    }
}

/// How far a measured pulse may stray from the nominal one, as fractions of its peak and
/// duration.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Tolerance {
    /// Within the pulse: the nominal ± this × the peak.
    pub band: f32,
    /// Before and after the pulse: within ± this × the peak.
    pub outside: f32,
    /// The band's widening in time on each side, × the duration.
    pub slack: f32,
    /// The velocity change within ± this × the nominal one.
    pub delta_v: f32,
    /// The velocity change is integrated from this × D before the nominal pulse to `after` ×
    /// D after it; the band is watched from `before` × D before it to `watch` × D after it.
    pub before: f32,
    pub after: f32,
    pub watch: f32,
}

/// A specified pulse and its tolerances.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Spec {
    pub shape: Shape,
    /// Nominal peak, m/s² (deceleration positive, as the reports).
    pub peak_m_s2: f32,
    /// Nominal duration, s.
    pub duration_s: f32,
    pub tolerance: Tolerance,
    /// A user's band instead of the tolerance's `band` and `slack` (at most
    /// [`MAX_BAND_POINTS`] rows, their times non-decreasing; two rows at one time are a step,
    /// the looser limits holding at that instant). On the board a `static` table.
    pub band: Option<&'static [BandPoint]>,
}

/// One row of a user's band: at `u` = time from the nominal pulse's start / duration, the least
/// and the greatest acceptable acceleration, over the peak.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct BandPoint {
    pub u: f32,
    pub lower: f32,
    pub upper: f32,
}

impl BandPoint {
    /// A row of zeros: the filler of a table read at start-up.
    pub const ZERO: Self = Self {
        u: 0.0,
        lower: 0.0,
        upper: 0.0,
    };
}

/// Most rows of a user's band ([`Spec::band`]).
pub const MAX_BAND_POINTS: usize = 64;

/// Durations within which a time counts as on a user's band's first or last row (a few f32
/// ulps at 10 durations).
const END_SLACK: f32 = 4e-6;

/// Points over the pulse, and over a user's band's span, at which the nominal pulse must lie
/// within the band ([`Spec::band_misses_nominal`]), past the first.
const NOMINAL_CHECKS: usize = 256;

/// Where the nominal pulse lies outside a user's band ([`Spec::band_misses_nominal`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NominalMiss {
    /// Time over D.
    pub u: f32,
    /// The row whose limits it misses (at a step, the side's own row), or `None` between
    /// rows.
    pub row: Option<usize>,
    /// The nominal pulse there and the limits it misses, over the peak.
    pub nominal: f32,
    pub lower: f32,
    pub upper: f32,
}

/// A user's band's first faulty row (its index) and what is wrong with it: a time not
/// finite or beyond −10 to 11 durations, a limit not finite or beyond ±10 peaks, the lower
/// limit above the upper, a time before the previous row's, a third row at one time.
pub fn band_row_fault(points: &[BandPoint]) -> Option<(usize, &'static str)> {
    points.iter().enumerate().find_map(|(k, p)| {
        let fine = |v: f32, r: f32| v.is_finite() && (-r..=r).contains(&v);
        let before = |n: usize| k.checked_sub(n).and_then(|i| points.get(i));
        let fault = if !fine(p.u - 0.5, 10.5) {
            "beyond −10 to 11 durations from the nominal pulse's start"
        } else if !(fine(p.lower, 10.0) && fine(p.upper, 10.0)) {
            "a limit beyond ±10 times the peak"
        } else if p.lower > p.upper {
            "the lower limit is above the upper"
        } else if before(1).is_some_and(|a| p.u < a.u) {
            "the time goes back"
        } else if before(2).is_some_and(|a| a.u == p.u) {
            "a third row at one time (two are a step)"
        } else {
            return None;
        };
        Some((k, fault))
    })
}

/// The band `points` at `u` (linear between rows, the looser limits at a step), `None` before
/// the first row or after the last. `points` is a valid band ([`Spec::validate`]).
fn table_at(points: &[BandPoint], u: f32) -> Option<(f32, f32)> {
    let (first, last) = (points.first()?, points.last()?);
    // A sample's time over D, computed in f32, can miss an end row by an ulp or two.
    let u = if u >= first.u && u <= last.u {
        u
    } else if u < first.u && u >= first.u - END_SLACK {
        first.u
    } else if u > last.u && u <= last.u + END_SLACK {
        last.u
    } else {
        return None;
    };
    // The first row at or after u; it exists since u <= last.u.
    let i = points.partition_point(|p| p.u < u);
    let p = points.get(i)?;
    if p.u == u {
        // A step: its second row, if any, is the next.
        return Some(match points.get(i + 1).filter(|q| q.u == u) {
            Some(q) => (fmin(p.lower, q.lower), fmax(p.upper, q.upper)),
            None => (p.lower, p.upper),
        });
    }
    let q = points.get(i.checked_sub(1)?)?;
    let f = (u - q.u) / (p.u - q.u);
    Some((
        q.lower + f * (p.lower - q.lower),
        q.upper + f * (p.upper - q.upper),
    ))
}

impl Spec {
    /// Checks every value: a finite positive peak and duration, fractions in their ranges.
    pub fn validate(&self) -> Result<(), Error> {
        let invalid = |name, reason| Err(Error::InvalidParameter { name, reason });
        let t = &self.tolerance;
        if !(self.peak_m_s2.is_finite() && self.peak_m_s2 > 0.0) {
            return invalid("spec-peak", "must be finite and > 0");
        }
        if !(self.duration_s.is_finite() && self.duration_s > 0.0) {
            return invalid("spec-duration", "must be finite and > 0");
        }
        if let Shape::Trapezoid { rise, fall } = self.shape {
            if !(rise > 0.0 && fall > 0.0 && rise + fall <= 1.0) {
                return invalid(
                    "spec-shape",
                    "a trapezoid's rise and fall are > 0 and at most the duration together",
                );
            }
        }
        let fraction = |v: f32| v.is_finite() && (0.0..=1.0).contains(&v);
        if !(fraction(t.band) && fraction(t.outside) && fraction(t.slack) && fraction(t.delta_v)) {
            return invalid(
                "spec-tolerance",
                "band, outside, slack and delta_v are fractions in [0, 1]",
            );
        }
        let span = |v: f32| v.is_finite() && (0.0..=10.0).contains(&v);
        if !(span(t.before) && span(t.after) && span(t.watch) && t.watch >= t.after) {
            return invalid(
                "spec-window",
                "before, after and watch are 0 to 10 durations, watch at least after",
            );
        }
        if let Some(points) = self.band {
            self.validate_band(points)?;
        }
        Ok(())
    }

    /// A user's band: 2 to [`MAX_BAND_POINTS`] rows, none faulty ([`band_row_fault`]), and
    /// the nominal pulse inside it ([`Self::band_misses_nominal`]: a band it cannot pass is a
    /// mistake, most often of units).
    fn validate_band(&self, points: &[BandPoint]) -> Result<(), Error> {
        let invalid = |reason| {
            Err(Error::InvalidParameter {
                name: "spec-band-table",
                reason,
            })
        };
        if !(2..=MAX_BAND_POINTS).contains(&points.len()) {
            return invalid("2 to 64 rows");
        }
        if let Some((_, reason)) = band_row_fault(points) {
            return invalid(reason);
        }
        if self.band_misses_nominal().is_some() {
            return invalid("the nominal pulse lies outside the band");
        }
        Ok(())
    }

    /// Where the nominal pulse lies outside a user's band, if anywhere (`None` too without a
    /// user's band): each side of every step against its own row, every row, then
    /// [`NOMINAL_CHECKS`] + 1 points over the pulse and as many over the band's span. The
    /// band's rows must be in order ([`band_row_fault`] finds none).
    pub fn band_misses_nominal(&self) -> Option<NominalMiss> {
        let points = self.band?;
        let (first, last) = (points.first()?.u, points.last()?.u);
        let miss = |u: f32, row: Option<usize>, nominal: f32, (lower, upper): (f32, f32)| {
            (!(lower <= nominal && nominal <= upper)).then_some(NominalMiss {
                u,
                row,
                nominal,
                lower,
                upper,
            })
        };
        // A step: the nominal just before it against its first row, just after it against
        // its second (0 outside the pulse).
        let steps = points.windows(2).enumerate().find_map(|(k, w)| match w {
            [a, b] if a.u == b.u => {
                let before = if a.u > 0.0 { self.shape.at(a.u) } else { 0.0 };
                let after = if a.u < 1.0 { self.shape.at(a.u) } else { 0.0 };
                miss(a.u, Some(k), before, (a.lower, a.upper))
                    .or_else(|| miss(a.u, Some(k + 1), after, (b.lower, b.upper)))
            }
            _ => None,
        });
        // Every row (at a step the looser limits, each side's own checked above).
        let rows = || {
            points
                .iter()
                .enumerate()
                .find_map(|(k, p)| miss(p.u, Some(k), self.shape.at(p.u), table_at(points, p.u)?))
        };
        let grid = |a: f32, b: f32| {
            (0..=NOMINAL_CHECKS).find_map(move |k| {
                let u = a + (b - a) * k as f32 / NOMINAL_CHECKS as f32;
                miss(u, None, self.shape.at(u), table_at(points, u)?)
            })
        };
        steps
            .or_else(rows)
            .or_else(|| grid(0.0, 1.0))
            .or_else(|| grid(first, last))
    }

    /// The band's watched window, durations before the nominal pulse and after it: the
    /// tolerance's `before` and `watch`, widened to a user's band's first and last rows (every
    /// row is watched). The velocity change keeps its own window (`before`, `after`).
    pub fn watched(&self) -> (f32, f32) {
        let t = &self.tolerance;
        match self.band.and_then(|b| Some((b.first()?.u, b.last()?.u))) {
            Some((first, last)) => (t.before.max(-first), t.watch.max(last - 1.0)),
            None => (t.before, t.watch),
        }
    }

    /// Samples the verdict needs held on either side of the contact at `rate_hz`. The nominal
    /// pulse is placed by the measured peak, which may lie anywhere in the contact (at its
    /// end for a terminal-peak pulse, at its start for an initial-peak one, whatever the
    /// spec's shape): so on either side, the watched window's reach from the nominal peak
    /// (before it: the shape's rise and the window before the pulse; after it: the shape's
    /// fall and the window after), and half a duration for the placement.
    pub fn padding_samples(&self, rate_hz: f32) -> u32 {
        let (before, watch) = self.watched();
        let peak_at = self.shape.peak_at();
        let ahead = before.max(self.tolerance.before) + peak_at;
        let behind = watch.max(self.tolerance.after) + 1.0 - peak_at;
        let reach = ahead.max(behind) + 0.5;
        // Two samples over: the verdict rounds its window's ends outward.
        let n = libm::ceilf(reach * self.duration_s * rate_hz) + 2.0;
        if n.is_finite() && n < u32::MAX as f32 {
            n as u32
        } else {
            u32::MAX
        }
    }

    /// The nominal velocity change, m/s.
    pub fn delta_v_m_s(&self) -> f32 {
        self.peak_m_s2 * self.duration_s * self.shape.area()
    }

    /// The band at `u` = time from the nominal pulse's start / duration, over the peak: the
    /// least and the greatest acceptable acceleration.
    pub fn band_at(&self, u: f32) -> (f32, f32) {
        self.band_with(|u| self.shape.at(u), u)
    }

    /// Where `u` lies against the band's flat outside part `(-outside, outside)`, which
    /// [`Self::band_with`] gives without reading the shape: -1 before the pulse and its slack
    /// (or a user's band's first row), 1 after them, 0 between (the band follows the shape
    /// or the rows). Monotone in `u`.
    pub fn band_region(&self, u: f32) -> i8 {
        let t = &self.tolerance;
        if let Some(points) = self.band {
            return match (table_at(points, u), points.first()) {
                (Some(_), _) => 0,
                (None, Some(first)) if u >= first.u => 1,
                (None, _) => -1,
            };
        }
        let (a, b) = (u - t.slack, u + t.slack);
        if b < 0.0 {
            -1
        } else if a > 1.0 {
            1
        } else {
            0
        }
    }

    /// [`Self::band_at`] with the nominal shape given by `at` (over the peak, at `u` in
    /// `[0, 1]`): the verdict's tabulated shape ([`Nominal`]).
    pub fn band_with(&self, at: impl Fn(f32) -> f32, u: f32) -> (f32, f32) {
        let t = &self.tolerance;
        if let Some(points) = self.band {
            return table_at(points, u).unwrap_or((-t.outside, t.outside));
        }
        let (a, b) = (u - t.slack, u + t.slack);
        if b < 0.0 || a > 1.0 {
            return (-t.outside, t.outside);
        }
        // The nominal's extremes over [u - slack, u + slack] (its shapes rise then fall: the
        // ends, and the peak where it lies inside).
        let ends = [at(fmax(a, 0.0)), at(fmin(b, 1.0))];
        let p = self.shape.peak_at();
        let hi = if (a..=b).contains(&p) {
            1.0
        } else {
            fmax(ends[0], ends[1])
        };
        // Past either end of the pulse the nominal is 0 there: the lower limit is 0's.
        let lo = if a < 0.0 || b > 1.0 {
            0.0
        } else {
            fmin(ends[0], ends[1])
        };
        (fmax(lo - t.band, -fmax(t.outside, t.band)), hi + t.band)
    }
}

/// The loosest limits of `spec`'s band over `[u0, u1]` (`u0 <= u1`), the nominal shape given
/// by `at`: a user's band at both ends, at its rows between them and `outside` where the
/// span leaves the table; otherwise the band at both ends (the verdict's coarse search).
pub fn band_over(spec: &Spec, at: impl Fn(f32) -> f32, u0: f32, u1: f32) -> (f32, f32) {
    let (a, b) = (spec.band_with(&at, u0), spec.band_with(&at, u1));
    let (mut lo, mut hi) = (fmin(a.0, b.0), fmax(a.1, b.1));
    if let Some(points) = spec.band {
        for p in rows_within(points, u0, u1).filter(|p| p.u > u0 && p.u < u1) {
            (lo, hi) = (fmin(lo, p.lower), fmax(hi, p.upper));
        }
    }
    (lo, hi)
}

/// Bounds on the tightest limits of `spec`'s band over `[u0, u1]` (`u0 <= u1`, both where
/// the band follows the pulse or its rows: [`Spec::band_region`] 0), the nominal shape given
/// by `at`: (a lower limit no point's exceeds, an upper limit no point's falls below), up to
/// the rounding of its evaluation (ulps; the verdict allows for them). A user's band at both
/// ends and at its rows between them (it is linear between rows); the standard band at both
/// ends, its upper limit being the greatest of a shape that rises then falls over a window
/// sliding with `u`, and its lower limit the least over it (monotone in `u` on either side of
/// the peak's `± slack` and of the pulse's ends' `slack` inward), else the nominal's
/// greatest, 1.
pub fn band_bound(spec: &Spec, at: impl Fn(f32) -> f32, u0: f32, u1: f32) -> (f32, f32) {
    let (a, b) = (spec.band_with(&at, u0), spec.band_with(&at, u1));
    let (mut lo, mut hi) = (fmax(a.0, b.0), fmin(a.1, b.1));
    if let Some(points) = spec.band {
        for p in rows_within(points, u0, u1) {
            (lo, hi) = (fmax(lo, p.lower), fmin(hi, p.upper));
        }
        return (lo, hi);
    }
    let s = spec.tolerance.slack;
    let p = spec.shape.peak_at();
    // Where the lower limit may turn: at the peak's window and where a pulse's end leaves it.
    let turns = |x: f32| u0 < x && x < u1;
    if (u0 < p + s && u1 > p - s) || turns(s) || turns(1.0 - s) {
        lo = fmax(1.0 - spec.tolerance.band, lo);
    }
    (lo, hi)
}

/// A user's band's rows at `u0..=u1`, in order (its rows' times are non-decreasing).
fn rows_within(points: &[BandPoint], u0: f32, u1: f32) -> impl Iterator<Item = &BandPoint> {
    let first = points.partition_point(|p| p.u < u0);
    points
        .get(first..)
        .unwrap_or(&[])
        .iter()
        .take_while(move |p| p.u <= u1)
}

/// Points of the tabulated nominal shape ([`Nominal`]), past the first.
pub const NOMINAL_POINTS: usize = 256;

/// The nominal shape as the verdict reads it: a half-sine tabulated over its duration and
/// read by linear interpolation (the verdict's thousands of band look-ups cost a multiply-add
/// each instead of a sine: off the exact shape by at most 2e-5 of the peak, a thousandth of
/// any band; its table peaks at the sine's, `u` = 1/2, a table point); the straight-line
/// shapes exactly (a division at most: a table's points would cut a trapezoid's corners,
/// and move the peak of a short top away from [`Shape::peak_at`], where the band and its
/// bounds ([`band_bound`]) take it: a rise of 0.001 D read 0.75 of the peak low there). Its
/// table is the caller's (the analysis workspace on the board, not the stack).
pub struct Nominal<'a> {
    table: &'a [f32],
    /// The shape read exactly (not tabulated).
    exact: Option<Shape>,
}

impl<'a> Nominal<'a> {
    /// Values of its table.
    pub const LEN: usize = NOMINAL_POINTS + 1;

    /// A half-sine tabulated in `table`'s first [`Self::LEN`] values (all of them if shorter:
    /// the shape then reads 0 beyond); the other shapes read exactly.
    pub fn fill(shape: Shape, table: &'a mut [f32]) -> Self {
        if !matches!(shape, Shape::HalfSine) {
            return Self {
                table: &[],
                exact: Some(shape),
            };
        }
        let n = table.len().min(Self::LEN);
        let (table, _) = table.split_at_mut(n);
        // `shape.at(k / NOMINAL_POINTS)`, stored (`half_sine`: the same bits, 257 `sinf`
        // fewer per verdict).
        for (v, &h) in table.iter_mut().zip(half_sine::HALF_SINE.iter()) {
            *v = h;
        }
        Self { table, exact: None }
    }

    /// The shape at `u` in `[0, 1]` (clamped).
    pub fn at(&self, u: f32) -> f32 {
        if let Some(shape) = self.exact {
            return shape.at(u.clamp(0.0, 1.0));
        }
        let x = u.clamp(0.0, 1.0) * NOMINAL_POINTS as f32;
        let k = (x as usize).min(NOMINAL_POINTS - 1);
        let f = x - k as f32;
        match (self.table.get(k), self.table.get(k + 1)) {
            (Some(&y0), Some(&y1)) => y0 + f * (y1 - y0),
            _ => 0.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The shapes the verdict's tests judge and bound: the three standard ones first (rows
    /// tabulated from them pass `validate`), then an initial-peak pulse written as a
    /// trapezoid (its top far shorter than a table step or a sample), an unequal one and one
    /// without a top.
    pub(super) const SHAPES_UNDER_TEST: [Shape; 6] = [
        Shape::HalfSine,
        Shape::Sawtooth,
        Shape::Trapezoid {
            rise: 0.1,
            fall: 0.1,
        },
        Shape::Trapezoid {
            rise: 0.001,
            fall: 0.999,
        },
        Shape::Trapezoid {
            rise: 0.3,
            fall: 0.6,
        },
        Shape::Trapezoid {
            rise: 0.3,
            fall: 0.7,
        },
    ];

    /// [`band_bound`] is a bound: every `u` of a span (many f32s along it and its ends) has
    /// its band's lower limit at or below the bound's and its upper at or above, up to the
    /// verdict's allowance for rounding (1e-5 of the peak): every shape (trapezoids with a
    /// top far shorter than a table step among them), slacks from none to a whole duration,
    /// outside limits below and above the band, and a user's band with steps, rows at ±10.
    #[test]
    fn band_bound_bounds_the_band_over_every_span() {
        const fn row(u: f32, lower: f32, upper: f32) -> BandPoint {
            BandPoint { u, lower, upper }
        }
        static ROWS: [BandPoint; 8] = [
            row(-0.4, -0.2, 0.2),
            row(0.0, -0.2, 0.2),
            row(0.0, 0.5, 10.0),
            row(0.3, -10.0, 1.5),
            row(0.5, 0.8, 1.2),
            row(0.5, 0.1, 9.0),
            row(1.0, -0.2, 0.2),
            row(1.5, -0.2, 0.2),
        ];
        let mut table = [0.0f32; Nominal::LEN];
        let mut checked = 0usize;
        for shape in SHAPES_UNDER_TEST {
            let nominal = Nominal::fill(shape, &mut table);
            let at = |u: f32| nominal.at(u);
            for slack in [0.0f32, 1e-7, 0.01, 0.05, 0.5, 1.0] {
                for (band, outside) in [(0.2f32, 0.2f32), (0.2, 0.1), (0.15, 0.3), (0.0, 0.2)] {
                    for user in [false, true] {
                        let spec = Spec {
                            shape,
                            peak_m_s2: 1.0,
                            duration_s: 0.01,
                            tolerance: Tolerance {
                                band,
                                outside,
                                slack,
                                delta_v: 0.15,
                                before: 0.4,
                                after: 0.1,
                                watch: 1.5,
                            },
                            band: user.then_some(&ROWS[..]),
                        };
                        checked += bounds_hold(&spec, &at);
                    }
                }
            }
        }
        assert!(checked > 100_000, "{checked}");
    }

    /// [`band_bound_bounds_the_band_over_every_span`] for one spec: spans of several widths
    /// along where the band follows the pulse; how many points it checked.
    fn bounds_hold(spec: &Spec, at: &impl Fn(f32) -> f32) -> usize {
        let mut checked = 0;
        for width in [1e-4f32, 3e-3, 0.02, 0.1] {
            let mut u0 = -1.2f32;
            while u0 < 2.2 {
                let u1 = u0 + width;
                if spec.band_region(u0) == 0 && spec.band_region(u1) == 0 {
                    let (lo, hi) = band_bound(spec, at, u0, u1);
                    let mut u = u0;
                    while u <= u1 {
                        let (l, h) = spec.band_with(at, if u + width / 40.0 > u1 { u1 } else { u });
                        assert!(
                            l <= lo + 1e-5 && h >= hi - 1e-5,
                            "{spec:?}: at {u} in [{u0}, {u1}] ({l}, {h}) against ({lo}, {hi})"
                        );
                        checked += 1;
                        u += width / 40.0;
                    }
                }
                u0 += width * 0.613;
            }
        }
        checked
    }
}
