//! A captured impact judged against a specified pulse: the nominal pulse placed where the
//! measured one fits its band best, the worst excursion there, and the velocity change over the
//! standards' window against its tolerance.
//!
//! The placement is a search over the nominal pulse's start, within half a duration of where
//! its peak meets the measured peak, for the least worst excursion: first on the signal's
//! extremes in [`BUCKETS`] spans against the band on the same grid (at most 129 starts of
//! 128 comparisons), then over every sample for up to 9 starts around the best one. Where
//! the band is flat (before and after the pulse and its slack, or a user's band's rows) a
//! start's worst excursion is read off the same extremes (a bucket's samples are read only
//! where its extreme is the greatest); where it follows the pulse (or the rows), each
//! bucket's excursion is bounded by its extremes against the band's tightest limits over it
//! ([`super::band_bound`]) and the buckets are read greatest bound first, only while one may
//! still matter; a start whose excursion somewhere already reaches the best's is left there.
//! All give the verdict of reading every sample, bit for bit, on a window of numbers (the
//! tests hold the search to the one that did, `verdict_reference.rs`); a window holding a NaN
//! or an infinity is no verdict here ([`Missing::Overflow`]). The window's samples are read
//! from the record once, into the scratch after the tables (the board's analysis workspace).
//! The nominal half-sine's table is copied from constants (`spec/half_sine.rs`: 257 `sinf`,
//! in f64 on the board's libm, were about a third of a verdict against a standard's band on
//! the Cortex-M4); a user's band does not read the nominal shape at all.

use super::record::Record;
use super::{band_bound, band_over, Nominal, Spec};
use crate::numeric::fmax;
use core::cell::Cell;

/// Spans the signal is summarised in for the search (its least and greatest value each).
pub const BUCKETS: usize = 128;

/// A bucket's bound on the excursion is widened by this much of itself and of the peak: the
/// band's limits at its samples may stray from its bound's by the rounding of their
/// evaluation (a few ulps of the limits: up to ~1.4e-6 of the peak for a user's band whose
/// limits reach ±10 of it; `spec::tests` holds the bound over every shape).
const BOUND_SLACK: f32 = 1e-5;

/// The verdict of one impact.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Verdict {
    /// Within the band and the velocity tolerance.
    pub pass: bool,
    pub band_pass: bool,
    pub delta_v_pass: bool,
    /// The nominal pulse's start, s from the stream's first sample.
    pub start_s: f64,
    /// The worst excursion: how far beyond its limit (negative: inside), over the peak.
    pub margin: f32,
    /// Where (s from the stream's first sample), and the acceleration there and its limit,
    /// m/s².
    pub worst_s: f64,
    pub worst_m_s2: f32,
    pub limit_m_s2: f32,
    /// The velocity change over the standards' window, m/s.
    pub delta_v_m_s: f32,
}

/// Why there is no verdict.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Missing {
    /// The record holds neither side of the window the verdict watches around the pulse (a
    /// nominal duration too long for the capture at this rate, or for the recording).
    Window,
    /// The capture (or the recording) does not reach back over the window the verdict
    /// watches before the pulse (`before` × D before it, and the search's half duration): the
    /// record starts too soon before the pulse.
    WindowBefore,
    /// The capture (or the recording) ends before the window the verdict watches after the
    /// pulse (`watch` × D after it): the pulse is cut by the capture's length, or the record
    /// ends too soon after it.
    WindowAfter,
    /// The nominal duration is shorter than 4 samples at this rate.
    Resolution,
    /// A number of the verdict is beyond f32 (the scene's gain or peak out of any real range),
    /// or a sample in the window is not a number (a caller's NaN or infinity).
    Overflow,
}

impl Missing {
    /// Every reason.
    pub const ALL: [Missing; 5] = [
        Missing::Window,
        Missing::WindowBefore,
        Missing::WindowAfter,
        Missing::Resolution,
        Missing::Overflow,
    ];

    /// The reason's name in the reports.
    pub fn name(self) -> &'static str {
        match self {
            Missing::Window => "spec-window",
            Missing::WindowBefore => "spec-window-before",
            Missing::WindowAfter => "spec-window-after",
            Missing::Resolution => "spec-resolution",
            Missing::Overflow => "spec-overflow",
        }
    }
}

/// Whether a placement of worst excursion `worst` is better than the best so far, the
/// placements tried nearest first: one that passes (the standards: a pulse that "can be
/// contained" in the band complies) over one that fails, and among failing ones the least
/// excursion; among passing ones the nearest stays.
fn better(worst: f32, best: f32) -> bool {
    match (worst <= 0.0, best <= 0.0) {
        (true, false) => true,
        (false, false) => worst < best,
        _ => false,
    }
}

/// Where the verdict looks, in samples of the record: the nominal duration `d`, the window
/// watched before the pulse (`lead`) and after it (`watch` × D), and the span every start of
/// the search needs, from stream index `base` over `span` samples.
struct Window {
    d: f32,
    lead: f32,
    watch: f32,
    /// The start where the nominal peak meets the measured one, and the earliest start
    /// searched, samples from `base`.
    guess: f32,
    from: f32,
    span: u32,
    base: u64,
}

impl Window {
    /// The window for `spec` at `rate_hz` around the measured peak at `peak_index`, if the
    /// record (`held`: whether it holds a stream index) holds it.
    fn place(
        spec: &Spec,
        rate_hz: f32,
        peak_index: u64,
        held: impl Fn(u64) -> bool,
    ) -> Result<Window, Missing> {
        let t = &spec.tolerance;
        let d = spec.duration_s * rate_hz; // samples
        if !(d >= 4.0) {
            return Err(Missing::Resolution);
        }
        // The start where the nominal peak meets the measured one; the search half a duration
        // either way; the span the signal must cover for any of them, from `base` (its first
        // sample) over `span` samples.
        // The band's watched window (a user's band widens it to its rows), × D.
        let (before, watch) = spec.watched();
        let lead = before * d;
        let reach = spec.shape.peak_at() * d + d / 2.0 + lead;
        let before_reach = libm::ceilf(reach) as u64;
        // From base: the difference of the two indices is exact in u64, where each index
        // alone in f32 is not (past 2^24 samples, 33 s of a board's stream at 500 kS/s).
        let guess = before_reach as f32 - spec.shape.peak_at() * d;
        let from = guess - d / 2.0 - lead; // >= 0
        let to = guess + d / 2.0 + (1.0 + watch.max(t.after)) * d;
        // A window beyond any record's reach (2^32 samples) is held by none.
        if !(to < u32::MAX as f32) {
            return Err(Missing::Window);
        }
        let span = libm::ceilf(to) as u32 + 1;
        // Which side of the window the record lacks, if any: both, or the one it lacks.
        let last = peak_index
            .saturating_add(u64::from(span))
            .saturating_sub(before_reach.saturating_add(1));
        let after_held = held(last);
        let base = match peak_index.checked_sub(before_reach) {
            Some(base) if held(base) => base,
            _ if after_held => return Err(Missing::WindowBefore),
            _ => return Err(Missing::Window),
        };
        Ok(Window {
            d,
            lead,
            watch,
            guess,
            from,
            span,
            base,
        })
    }

    /// Bucket `j`'s first sample (of [`BUCKETS`] over the span; `j = BUCKETS`: the span).
    fn bucket_start(&self, j: usize) -> u32 {
        let span = u64::from(self.span);
        ((j as u64 * span).div_ceil(BUCKETS as u64)).min(span) as u32
    }

    /// The bucket of sample `k`.
    fn bucket(&self, k: u32) -> usize {
        // (A span is at least 1 sample: `max` only keeps a division by 0 out of the code.)
        (k as usize * BUCKETS / (self.span as usize).max(1)).min(BUCKETS - 1)
    }
}

/// A placement of the nominal pulse: its start (samples from the window's base), its worst
/// excursion (how far beyond the band, m/s²; negative: inside) at sample `worst_k`, the
/// acceleration there and the limit it is measured against.
#[derive(Clone, Copy)]
struct Placement {
    start: f32,
    worst: f32,
    worst_k: u32,
    worst_v: f32,
    limit: f32,
}

impl Placement {
    /// A start at `start` with no sample read yet.
    fn none(start: f32) -> Placement {
        Placement {
            start,
            worst: f32::NEG_INFINITY,
            worst_k: 0,
            worst_v: 0.0,
            limit: 0.0,
        }
    }

    /// Its worst excursion is now `over`, at sample `k` of value `v` against `limit`.
    fn set(&mut self, over: f32, k: u32, v: f32, limit: f32) {
        (self.worst, self.worst_k, self.worst_v, self.limit) = (over, k, v, limit);
    }
}

/// The signal over the window, by sample from its base: held in the workspace (read from the
/// record once, by the extremes' pass) or, where the workspace is too short for it, read from
/// the record each time (every sample of the window is held there: that pass read them all).
/// (Not generic over the record's reader: the search is compiled once, not once per caller.)
enum Signal<'a> {
    Held(&'a [f32]),
    Read(&'a dyn Fn(u32) -> Result<f32, Missing>),
}

impl Signal<'_> {
    /// Sample `k` of the window.
    #[inline(always)]
    fn at(&self, k: u32) -> Result<f32, Missing> {
        match self {
            // (Never beyond: the window's samples are `0..span`.)
            Signal::Held(v) => v.get(k as usize).copied().ok_or(Missing::WindowAfter),
            Signal::Read(read) => read(k),
        }
    }
}

/// The search's fixed parts: the signal, the band, the window and the signal's extremes per
/// bucket.
struct Search<'a> {
    a: Signal<'a>,
    spec: &'a Spec,
    nominal: &'a Nominal<'a>,
    w: &'a Window,
    /// The signal's least and greatest value per bucket, in pairs ([`extremes`]).
    ext: &'a [f32],
    /// The band outside the pulse and its rows (`band_with`'s flat part), m/s².
    outside: (f32, f32),
    /// A bound per bucket on the excursion over it ([`Self::pulse_worst`]'s, BUCKETS of
    /// them).
    bounds: &'a [Cell<f32>],
}

impl Search<'_> {
    /// The excursion at sample `k` for a start at `start`: (how far beyond, the value, the
    /// limit).
    fn excursion(&self, k: u32, start: f32) -> Result<(f32, f32, f32), Missing> {
        let v = self.a.at(k)?;
        let (lo, hi) = self
            .spec
            .band_with(|u| self.nominal.at(u), self.u(k, start));
        let peak = self.spec.peak_m_s2;
        Ok(excursion(v, lo * peak, hi * peak))
    }

    /// Sample `k`'s time from the start at `start`, over D.
    fn u(&self, k: u32, start: f32) -> f32 {
        (k as f32 - start) / self.w.d
    }

    /// The worst excursion for a start at `start` over samples `k0..=k1`, if it is better
    /// than `best`'s ([`better`]): the same as reading every sample in order (the first
    /// sample of the greatest excursion), where the band is flat (before and after the pulse
    /// and its rows) read off the buckets' extremes. A start whose excursion somewhere
    /// already reaches the best's cannot be better: it is left there (the best's worst
    /// sample and the flat stretches are looked at first).
    fn try_start(&self, start: f32, best: &mut Placement) -> Result<(), Missing> {
        let (w, d) = (self.w, self.w.d);
        let k0 = libm::ceilf((start - w.lead).max(0.0)) as u32;
        let k1 = (libm::floorf(start + (1.0 + w.watch) * d) as u32).min(w.span - 1);
        if best.worst.is_finite()
            && (k0..=k1).contains(&best.worst_k)
            && self.excursion(best.worst_k, start)?.0 >= best.worst
        {
            return Ok(());
        }
        // The flat band before the pulse's rows, the rows, the flat band after them.
        let region = |k: u32| self.spec.band_region(self.u(k, start));
        let inside = first_where(k0, k1 + 1, |k| region(k) >= 0);
        let after = first_where(inside, k1 + 1, |k| region(k) > 0);
        let before = self.flat_worst(start, k0, inside)?;
        let behind = self.flat_worst(start, after, k1 + 1)?;
        if fmax(before.worst, behind.worst) >= best.worst {
            return Ok(());
        }
        let floor = fmax(before.worst, behind.worst);
        let Some(within) = self.pulse_worst(start, inside, after, floor, best.worst)? else {
            return Ok(());
        };
        // In the samples' order: the first of the greatest.
        let mut worst = before;
        for p in [within, behind] {
            if p.worst > worst.worst {
                worst = p;
            }
        }
        if better(worst.worst, best.worst) {
            *best = worst;
        }
        Ok(())
    }

    /// [`Self::try_start`]'s reading over `k0..k1`, where the band follows the pulse (or a
    /// user's rows): each bucket's excursion bounded by its extremes against the band's
    /// tightest limits over its samples ([`band_bound`]), then the buckets read in full,
    /// greatest bound first, while one may reach the greatest excursion found or `floor` (the
    /// flat stretches' worst: below it this stretch's worst is not the placement's). The
    /// first sample of the greatest excursion, as reading every sample in order finds it
    /// where it reaches `floor`; `None` where a sample's reaches `best` (the start cannot be
    /// better; no unread one can reach it either).
    fn pulse_worst(
        &self,
        start: f32,
        k0: u32,
        k1: u32,
        floor: f32,
        best: f32,
    ) -> Result<Option<Placement>, Missing> {
        let mut worst = Placement::none(start);
        if k0 >= k1 {
            return Ok(Some(worst));
        }
        let (w, peak) = (self.w, self.spec.peak_m_s2);
        let (j0, j1) = (w.bucket(k0), w.bucket(k1 - 1));
        let samples = |j: usize| (w.bucket_start(j).max(k0), w.bucket_start(j + 1).min(k1));
        let bounds = self.bounds.get(..=j1 - j0).unwrap_or(&[]);
        for (j, bound) in (j0..).zip(bounds) {
            let (a, z) = samples(j);
            bound.set(if a < z {
                let (u0, u1) = (self.u(a, start), self.u(z - 1, start));
                let (lo, hi) = band_bound(self.spec, |u| self.nominal.at(u), u0, u1);
                let (least, most) = pair(self.ext, j);
                let over = fmax(most - hi * peak, lo * peak - least);
                let bound = over + (libm::fabsf(over) + libm::fabsf(peak)) * BOUND_SLACK;
                // (A limit beyond f32 times the peak: no bound, the bucket is read.)
                if bound.is_nan() {
                    f32::INFINITY
                } else {
                    bound
                }
            } else {
                f32::NAN
            });
        }
        // The unread bucket of greatest bound while it may reach the bar (NaN: read).
        while let Some((i, _)) = bounds
            .iter()
            .enumerate()
            .map(|(i, b)| (i, b.get()))
            .filter(|&(_, b)| b >= fmax(floor, worst.worst))
            .reduce(|m, x| if x.1 > m.1 { x } else { m })
        {
            if let Some(b) = bounds.get(i) {
                b.set(f32::NAN);
            }
            let (a, z) = samples(j0 + i);
            for k in a..z {
                let (over, v, lim) = self.excursion(k, start)?;
                if over >= best {
                    return Ok(None);
                }
                if over > worst.worst || (over == worst.worst && k < worst.worst_k) {
                    worst.set(over, k, v, lim);
                }
            }
        }
        Ok(Some(worst))
    }

    /// [`Self::try_start`]'s reading over `k0..k1`, where the band is the flat outside one:
    /// whole buckets by their extremes (each sample's excursion `max(v - hi, lo - v)` is
    /// greatest at the bucket's greatest or least value), then the first sample of the
    /// greatest in that bucket.
    fn flat_worst(&self, start: f32, k0: u32, k1: u32) -> Result<Placement, Missing> {
        let (lo, hi) = self.outside;
        let mut worst = Placement::none(start);
        let mut bucket: Option<(usize, f32)> = None;
        let mut k = k0;
        while k < k1 {
            let j = self.w.bucket(k);
            let end = self.w.bucket_start(j + 1);
            if k == self.w.bucket_start(j) && end <= k1 {
                let (least, most) = pair(self.ext, j);
                let over = fmax(excursion(most, lo, hi).0, excursion(least, lo, hi).0);
                if over > worst.worst && bucket.is_none_or(|(_, b)| over > b) {
                    bucket = Some((j, over));
                }
                k = end;
                continue;
            }
            // A sample of a bucket the range holds in part; after a bucket that beat it, it
            // is the bucket's to beat.
            let v = self.a.at(k)?;
            let (over, v, lim) = excursion(v, lo, hi);
            let to_beat = bucket.map_or(worst.worst, |(_, b)| b);
            if over > to_beat {
                if let Some((j, _)) = bucket.take() {
                    self.bucket_worst(j, &mut worst)?;
                }
                worst.set(over, k, v, lim);
            }
            k += 1;
        }
        if let Some((j, _)) = bucket {
            self.bucket_worst(j, &mut worst)?;
        }
        Ok(worst)
    }

    /// Bucket `j`'s samples read in order against the flat band.
    fn bucket_worst(&self, j: usize, worst: &mut Placement) -> Result<(), Missing> {
        let (lo, hi) = self.outside;
        for k in self.w.bucket_start(j)..self.w.bucket_start(j + 1) {
            let v = self.a.at(k)?;
            let (over, v, lim) = excursion(v, lo, hi);
            if over > worst.worst {
                worst.set(over, k, v, lim);
            }
        }
        Ok(())
    }
}

/// How far `v` lies beyond the band `lo..=hi` (negative: inside), the value and the limit
/// it is nearest.
fn excursion(v: f32, lo: f32, hi: f32) -> (f32, f32, f32) {
    if v - hi >= lo - v {
        (v - hi, v, hi)
    } else {
        (lo - v, v, lo)
    }
}

/// The first `k` in `from..to` where `p` holds, `p` false then true over the range (`to`
/// if it never holds).
fn first_where(from: u32, to: u32, p: impl Fn(u32) -> bool) -> u32 {
    let (mut lo, mut hi) = (from, to.max(from));
    while lo < hi {
        let mid = lo + (hi - lo) / 2;
        if p(mid) {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    lo
}

/// Values of scratch [`judge_in`] takes for its tables: the signal's extremes and the band's
/// limits per bucket (a pair each), the nominal shape's table. The window's samples follow
/// them where the scratch holds them too.
pub const SCRATCH: usize = 4 * BUCKETS + Nominal::LEN;

/// [`judge_in`] with its tables on the stack (3 KiB).
#[inline(never)]
pub fn judge(
    a: impl Record,
    rate_hz: f32,
    spec: &Spec,
    peak_index: u64,
) -> Result<Verdict, Missing> {
    let mut scratch = [0.0f32; SCRATCH];
    judge_in(a, rate_hz, spec, peak_index, &mut scratch)
}

/// Judges the acceleration `a(i)` (m/s² in the pulse's direction, stream index `i`; `None`
/// outside what is held) at `rate_hz` against `spec` (a valid one, [`Spec::validate`]: a
/// user's rows in time order), the measured peak at stream index `peak_index`, its tables in
/// `scratch` (on the stack if it holds fewer than [`SCRATCH`] values) and the window's samples
/// after them (read from `a` once; each time they are needed if the scratch is too short).
/// Written for the FPU: positions in f32 samples from the first sample watched (`base`), the
/// half-sine tabulated, compensated f32 sums for the velocity change.
pub fn judge_in(
    a: impl Record,
    rate_hz: f32,
    spec: &Spec,
    peak_index: u64,
    scratch: &mut [f32],
) -> Result<Verdict, Missing> {
    let scratch_len = scratch.len();
    let Some((ext, rest)) = scratch
        .split_at_mut_checked(2 * BUCKETS)
        .filter(|_| scratch_len >= SCRATCH)
    else {
        return judge(a, rate_hz, spec, peak_index);
    };
    let Some((limits, (table, values))) = rest
        .split_at_mut_checked(2 * BUCKETS)
        .and_then(|(l, r)| Some((l, r.split_at_mut_checked(Nominal::LEN)?)))
    else {
        return judge(a, rate_hz, spec, peak_index);
    };
    let w = Window::place(spec, rate_hz, peak_index, |i| a.at(i).is_some())?;
    // Sample `k` of the window; one the record does not hold is missing before the pulse when
    // it lies before the measured peak, after it otherwise.
    let read = |k: u32| {
        let i = w.base + u64::from(k);
        a.at(i).ok_or(if i < peak_index {
            Missing::WindowBefore
        } else {
            Missing::WindowAfter
        })
    };
    let a = match values.get_mut(..w.span as usize) {
        // The record's run at once where it can give it (the same values), then the
        // extremes over the copy; else sample by sample.
        Some(held) => {
            if a.run(w.base, held) {
                let copy = |k: u32| Ok(held.get(k as usize).copied().unwrap_or(0.0));
                extremes(&copy, &w, ext, None)?;
            } else {
                extremes(&read, &w, ext, Some(&mut *held))?;
            }
            Signal::Held(&*held)
        }
        None => {
            extremes(&read, &w, ext, None)?;
            Signal::Read(&read)
        }
    };
    let ext = &*ext;
    // A user's band is its rows: the nominal shape is not read (its table not even copied).
    let tabulated = if spec.band.is_some() { 0 } else { table.len() };
    let nominal = Nominal::fill(spec.shape, table.get_mut(..tabulated).unwrap_or(&mut []));
    let peak = spec.peak_m_s2;
    let coarse = coarse_start(spec, &nominal, &w, ext, limits);
    let search = Search {
        a,
        spec,
        nominal: &nominal,
        w: &w,
        ext,
        outside: (
            -spec.tolerance.outside * peak,
            spec.tolerance.outside * peak,
        ),
        bounds: Cell::from_mut(limits).as_slice_of_cells(),
    };
    let fine = refine(&search, coarse)?;
    let delta_v = delta_v(&search.a, spec, &w, fine.start, rate_hz)?;
    let t = &spec.tolerance;
    let nominal_dv = spec.delta_v_m_s();
    let band_pass = fine.worst <= 0.0;
    let delta_v_pass = libm::fabsf(delta_v - nominal_dv) <= t.delta_v * nominal_dv;
    let seconds = |k: f64| (w.base as f64 + k) / f64::from(rate_hz);
    let margin = fine.worst / peak;
    if ![margin, fine.worst_v, fine.limit, delta_v]
        .iter()
        .all(|x| x.is_finite())
    {
        return Err(Missing::Overflow);
    }
    Ok(Verdict {
        pass: band_pass && delta_v_pass,
        band_pass,
        delta_v_pass,
        start_s: seconds(f64::from(fine.start)),
        margin,
        worst_s: seconds(f64::from(fine.worst_k)),
        worst_m_s2: fine.worst_v,
        limit_m_s2: fine.limit,
        delta_v_m_s: delta_v,
    })
}

/// The signal's least and greatest value in each of [`BUCKETS`] spans of the window, in
/// pairs in `ext`; the samples kept in `held` if given.
fn extremes(
    a: &impl Fn(u32) -> Result<f32, Missing>,
    w: &Window,
    ext: &mut [f32],
    mut held: Option<&mut [f32]>,
) -> Result<(), Missing> {
    // A NaN is neither least nor greatest (`fmin`/`fmax` pass over it): `v - v`, 0 for every
    // finite sample and NaN for a NaN or an infinity, finds it without a sum that could
    // overflow, so that a window holding a non-number is no verdict, never a pass.
    let mut sum = 0.0f32;
    for (j, e) in ext.chunks_exact_mut(2).enumerate() {
        let (mut least, mut most) = (f32::INFINITY, f32::NEG_INFINITY);
        for k in w.bucket_start(j)..w.bucket_start(j + 1) {
            let v = a(k)?;
            if let Some(slot) = held.as_deref_mut().and_then(|h| h.get_mut(k as usize)) {
                *slot = v;
            }
            #[allow(clippy::eq_op)]
            let zero_or_nan = v - v;
            sum += zero_or_nan;
            // `fmin(least, v)` and `fmax(most, v)`, bit for bit (`most` is never a NaN).
            if v <= least {
                least = v;
            }
            if most < v {
                most = v;
            }
        }
        e.copy_from_slice(&[least, most]);
    }
    if sum.is_finite() {
        Ok(())
    } else {
        Err(Missing::Overflow)
    }
}

/// Pair `j` of a table of pairs (0s beyond it).
fn pair(t: &[f32], j: usize) -> (f32, f32) {
    match t.get(2 * j..2 * j + 2) {
        Some(&[x, y]) => (x, y),
        _ => (0.0, 0.0),
    }
}

/// The start in whole buckets (samples from the window's base): nearest the peak-aligned one
/// among those that may pass, else of least worst excursion ([`better`]), against the band
/// over each bucket on the same grid: the loosest limits over the bucket's two ends and a
/// user's band's rows between them (a bucket's extremes inside them is necessary for its
/// samples to lie inside: the search finds where the pulse can fit, the exact pass says
/// whether it does). The band is watched from `before` × D before the pulse to `watch` × D
/// after it. At most 129 starts of 128 comparisons.
fn coarse_start(
    spec: &Spec,
    nominal: &Nominal,
    w: &Window,
    ext: &[f32],
    limits: &mut [f32],
) -> f32 {
    let (d, lead, peak) = (w.d, w.lead, spec.peak_m_s2);
    let width = w.span as f32 / BUCKETS as f32;
    let watched = (((lead + (1.0 + w.watch) * d) / width) as usize).min(BUCKETS);
    for (j, l) in limits.chunks_exact_mut(2).enumerate().take(watched) {
        let u = |j: f32| (j * width - lead) / d;
        let (lo, hi) = band_over(spec, |u| nominal.at(u), u(j as f32), u(j as f32 + 1.0));
        l.copy_from_slice(&[lo * peak, hi * peak]);
    }
    let limits = &*limits;
    let first = libm::ceilf(w.from / width) as usize;
    let steps = ((d / width) as usize).min(BUCKETS);
    let centre = libm::roundf((w.guess - lead) / width) as usize;
    let mut best = (centre, f32::INFINITY);
    for k in 0..=2 * steps {
        // centre, centre + 1, centre - 1, centre + 2, …
        let offset = k.div_ceil(2);
        let Some(s) = (if k % 2 == 1 {
            Some(centre + offset)
        } else {
            centre.checked_sub(offset)
        })
        .filter(|&s| (first..=first + steps).contains(&s)) else {
            continue;
        };
        let mut worst = f32::NEG_INFINITY;
        let buckets = ext.chunks_exact(2).skip(s);
        for (e, l) in buckets.zip(limits.chunks_exact(2).take(watched)) {
            if let (&[lo, hi], &[lower, upper]) = (e, l) {
                // `fmax` twice, bit for bit (`worst` is never a NaN).
                for over in [hi - upper, lower - lo] {
                    if worst < over {
                        worst = over;
                    }
                }
            }
        }
        if better(worst, best.1) {
            best = (s, worst);
        }
    }
    best.0 as f32 * width + lead
}

/// Every sample, for the coarse start and then, halving the step from half a bucket down to
/// an eighth (at least a sample), a step either way of the best so far: the placement of
/// least worst excursion. The first start that passes is the one (the nearest).
fn refine(search: &Search<'_>, coarse: f32) -> Result<Placement, Missing> {
    let width = search.w.span as f32 / BUCKETS as f32;
    let mut fine = Placement {
        start: coarse,
        worst: f32::INFINITY,
        worst_k: 0,
        worst_v: 0.0,
        limit: 0.0,
    };
    search.try_start(coarse, &mut fine)?;
    let mut step = width / 2.0;
    while fine.worst > 0.0 {
        let around = fine.start;
        search.try_start(around - step, &mut fine)?;
        if fine.worst > 0.0 {
            search.try_start(around + step, &mut fine)?;
        }
        if step <= 1.0 || step <= width / 8.0 {
            break;
        }
        step = fmax(step / 2.0, 1.0);
    }
    Ok(fine)
}

/// The velocity change from `before` × D before the pulse starting at `start` to `after`
/// × D after it, m/s: compensated f32 sums (Kahan), an f64's accuracy at the FPU's speed.
fn delta_v(
    a: &Signal<'_>,
    spec: &Spec,
    w: &Window,
    start: f32,
    rate_hz: f32,
) -> Result<f32, Missing> {
    let (t, d) = (&spec.tolerance, w.d);
    let k0 = libm::ceilf((start - t.before * d).max(0.0)) as u32;
    let k1 = (libm::floorf(start + (1.0 + t.after) * d) as u32).min(w.span - 1);
    let (mut sum, mut carry) = (0.0f32, 0.0f32);
    for k in k0..=k1 {
        let y = a.at(k)? - carry;
        let next = sum + y;
        carry = (next - sum) - y;
        sum = next;
    }
    Ok(sum / rate_hz)
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::spec::{BandPoint, Shape, Tolerance};

    /// A pulse of `shape`, 500 m/s² for 11 ms, IEC's tolerances with a 1.5 D watch (also
    /// `record.rs`'s tests').
    pub(in crate::spec) fn spec(shape: Shape) -> Spec {
        Spec {
            shape,
            peak_m_s2: 500.0,
            duration_s: 0.011,
            tolerance: Tolerance {
                band: 0.2,
                outside: 0.2,
                slack: 0.0,
                delta_v: 0.15,
                before: 0.4,
                after: 0.1,
                watch: 1.5,
            },
            band: None,
        }
    }

    /// A pulse of `shape` of `peak` (m/s²) and `dur` (s), at 50 kS/s, its start at
    /// sample 2000 (and `glitch` added at a sample).
    fn judge_pulse(shape: Shape, peak: f32, dur: f32, glitch: Option<(u64, f32)>) -> Verdict {
        judge_against(&spec(shape), peak, dur, glitch)
    }

    /// [`judge_pulse`] against `spec`, its shape's pulse measured.
    fn judge_against(spec: &Spec, peak: f32, dur: f32, glitch: Option<(u64, f32)>) -> Verdict {
        let shape = spec.shape;
        let rate = 50_000.0f32;
        let start = 2000.0;
        let a = |i: u64| {
            let u = (i as f32 - start) / (dur * rate);
            let g = glitch.filter(|g| g.0 == i).map_or(0.0, |g| g.1);
            Some(peak * shape.at(u) + g)
        };
        let peak_index = (start + shape.peak_at() * dur * rate) as u64;
        let held = |i: u64| (i < 10_000).then(|| a(i)).flatten();
        judge(
            held,
            rate,
            spec,
            peak_index.min(2000 + (dur * rate) as u64 - 1),
        )
        .unwrap()
    }

    /// The same pulse late in a long stream (its indices past 2^31, where an index alone in
    /// f32 is off by hundreds of samples) gets the same verdict as at its start: the
    /// placement works from the indices' difference.
    #[test]
    fn a_pulse_late_in_the_stream_is_judged_as_an_early_one() {
        let s = spec(Shape::HalfSine);
        let (rate, dur, start) = (50_000.0f32, 0.011f32, 2000u64);
        let at = |offset: u64| {
            let a = move |i: u64| {
                let k = i.checked_sub(offset)?;
                (k < 10_000).then(|| {
                    let u = (k as f32 - start as f32) / (dur * rate);
                    500.0 * s.shape.at(u)
                })
            };
            let peak = offset + start + (0.5 * dur * rate) as u64;
            judge(a, rate, &s, peak).unwrap()
        };
        let (early, late) = (at(0), at((1 << 31) + 12_345));
        assert!(early.pass && late.pass, "{early:?} {late:?}");
        assert_eq!(early.margin, late.margin);
        assert_eq!(early.delta_v_m_s, late.delta_v_m_s);
    }

    /// Samples that are not numbers in the watched window (a caller's signal: the board's
    /// counts are always numbers) give no verdict: a run of NaN where the pulse is too high
    /// passed, `min`/`max` passing over it.
    #[test]
    fn a_window_holding_a_non_number_is_no_verdict() {
        let s = spec(Shape::HalfSine);
        let (rate, dur, start) = (50_000.0f32, 0.011f32, 2000u64);
        for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            for (from, to) in [(2270, 2280), (2275, 2276), (1800, 1900)] {
                let a = |i: u64| {
                    (i < 10_000).then(|| {
                        if (from..to).contains(&i) {
                            bad
                        } else {
                            let u = (i as f32 - start as f32) / (dur * rate);
                            500.0 * s.shape.at(u)
                        }
                    })
                };
                let peak = start + (0.5 * dur * rate) as u64;
                assert_eq!(
                    judge(a, rate, &s, peak),
                    Err(Missing::Overflow),
                    "{bad} {from}"
                );
            }
        }
    }

    #[test]
    fn a_nominal_pulse_passes_and_its_delta_v_is_the_nominal_one() {
        for shape in [
            Shape::HalfSine,
            Shape::Sawtooth,
            Shape::Trapezoid {
                rise: 0.1,
                fall: 0.1,
            },
        ] {
            let v = judge_pulse(shape, 500.0, 0.011, None);
            assert!(v.pass, "{shape:?}: {v:?}");
            let want = spec(shape).delta_v_m_s();
            assert!(
                (v.delta_v_m_s / want - 1.0).abs() < 0.01,
                "{shape:?}: {v:?}"
            );
            assert!(
                (v.start_s * 50_000.0 - 2000.0).abs() < 10.0,
                "{shape:?}: {v:?}"
            );
        }
    }

    #[test]
    fn a_pulse_too_high_or_too_short_fails_by_its_margin() {
        // 30 % high: beyond the ±20 % band by 10 % of the peak.
        let v = judge_pulse(Shape::HalfSine, 650.0, 0.011, None);
        assert!(!v.band_pass, "{v:?}");
        assert!((v.margin - 0.1).abs() < 0.01, "{v:?}");
        // Half as long: its Δv is half the nominal one.
        let v = judge_pulse(Shape::HalfSine, 500.0, 0.0055, None);
        assert!(!v.pass && !v.delta_v_pass, "{v:?}");
        // A spike after the pulse beyond ±20 %: the band fails there.
        let v = judge_pulse(Shape::HalfSine, 500.0, 0.011, Some((2800, 150.0)));
        assert!(
            !v.band_pass && (v.worst_s * 50_000.0 - 2800.0).abs() < 1e-6,
            "{v:?}"
        );
        assert!((v.margin - 0.1).abs() < 0.01, "{v:?}");
    }

    /// `spec(shape)`'s band as a user's table: from `before` to `watch` around the pulse, and
    /// the standard band at `n` + 1 rows over it (a step where the nominal ends at its peak).
    fn tabulated(shape: Shape, n: usize) -> Spec {
        extern crate std;
        let s = spec(shape);
        let mut rows = std::vec![BandPoint {
            u: -0.4,
            lower: -0.2,
            upper: 0.2,
        }];
        for k in 0..=n {
            let u = k as f32 / n as f32;
            let (lower, upper) = s.band_at(u);
            rows.push(BandPoint { u, lower, upper });
        }
        rows.push(BandPoint {
            u: 1.0,
            lower: -0.2,
            upper: 0.2,
        });
        rows.push(BandPoint {
            u: 1.5,
            lower: -0.2,
            upper: 0.2,
        });
        let t = Spec {
            band: Some(rows.leak()),
            ..s
        };
        t.validate().unwrap();
        t
    }

    #[test]
    fn a_users_table_of_the_standard_band_judges_as_the_standard_band() {
        for shape in [Shape::HalfSine, Shape::Sawtooth] {
            let table = tabulated(shape, 60);
            for (peak, dur, glitch) in [
                (500.0, 0.011, None),
                (650.0, 0.011, None),
                (500.0, 0.0055, None),
                (500.0, 0.011, Some((2800, 150.0))),
                (560.0, 0.012, None),
            ] {
                let (a, b) = (
                    judge_pulse(shape, peak, dur, glitch),
                    judge_against(&table, peak, dur, glitch),
                );
                // The table is the band to within its chords' sag (sin over 1/60: 3.4e-4).
                assert_eq!((a.band_pass, a.delta_v_pass), (b.band_pass, b.delta_v_pass));
                assert!(
                    (a.margin - b.margin).abs() < 2e-3,
                    "{shape:?} {peak}: {a:?} {b:?}"
                );
            }
        }
    }

    #[test]
    fn a_users_narrow_band_fails_by_its_own_margin() {
        // The standard band, but at most 1.05 × the peak from 0.3 to 0.7 of the pulse: a
        // half-sine 10 % high fails there by 5 % (the standard band passes it).
        extern crate std;
        let s = spec(Shape::HalfSine);
        let rows = std::vec![
            BandPoint {
                u: -0.4,
                lower: -0.2,
                upper: 0.2
            },
            BandPoint {
                u: 0.0,
                lower: -0.2,
                upper: 0.2
            },
            BandPoint {
                u: 0.3,
                lower: 0.6,
                upper: 1.05
            },
            BandPoint {
                u: 0.7,
                lower: 0.6,
                upper: 1.05
            },
            BandPoint {
                u: 1.0,
                lower: -0.2,
                upper: 0.2
            },
            BandPoint {
                u: 1.5,
                lower: -0.2,
                upper: 0.2
            },
        ];
        let narrow = Spec {
            band: Some(rows.leak()),
            ..s
        };
        narrow.validate().unwrap();
        assert!(judge_pulse(Shape::HalfSine, 550.0, 0.011, None).band_pass);
        let v = judge_against(&narrow, 550.0, 0.011, None);
        assert!(!v.band_pass, "{v:?}");
        assert!((v.margin - 0.05).abs() < 2e-3, "{v:?}");
        assert!((v.limit_m_s2 - 525.0).abs() < 0.5, "{v:?}");
        // The nominal pulse passes it.
        assert!(judge_against(&narrow, 500.0, 0.011, None).pass);
    }

    #[test]
    fn a_users_band_reads_between_its_rows_and_its_steps() {
        extern crate std;
        let rows: &'static [BandPoint] = std::vec![
            BandPoint {
                u: 0.0,
                lower: 0.1,
                upper: 0.2
            },
            BandPoint {
                u: 0.5,
                lower: 0.4,
                upper: 0.7
            },
            BandPoint {
                u: 1.0,
                lower: 0.8,
                upper: 1.2
            },
            BandPoint {
                u: 1.0,
                lower: -0.2,
                upper: 0.2
            },
            BandPoint {
                u: 1.2,
                lower: -0.2,
                upper: 0.2
            },
        ]
        .leak();
        let s = Spec {
            shape: Shape::Sawtooth,
            band: Some(rows),
            ..spec(Shape::Sawtooth)
        };
        // The sawtooth starts at 0: below the first row's 0.1.
        assert!(s.validate().is_err());
        let t = Spec {
            tolerance: Tolerance {
                outside: 0.3,
                ..s.tolerance
            },
            band: Some(&rows[1..]),
            ..s
        };
        t.validate().unwrap();
        let (lo, hi) = t.band_at(0.75);
        assert!(
            (lo - 0.6).abs() < 1e-6 && (hi - 0.95).abs() < 1e-6,
            "{lo} {hi}"
        );
        assert_eq!(t.band_at(1.0), (-0.2, 1.2)); // the step: the looser limits
        assert_eq!(t.band_at(1.1), (-0.2, 0.2));
        assert_eq!(t.band_at(0.4), (-0.3, 0.3)); // before the table: `outside`
        assert_eq!(t.band_at(1.3), (-0.3, 0.3));
        let bad = |rows: std::vec::Vec<BandPoint>| {
            Spec {
                band: Some(rows.leak()),
                ..t
            }
            .validate()
            .is_err()
        };
        let p = |u, lower, upper| BandPoint { u, lower, upper };
        assert!(bad(std::vec![p(0.5, 0.0, 1.0)])); // one row
        assert!(bad(std::vec![p(0.6, 0.0, 1.0), p(0.5, 0.0, 1.0)])); // back in time
        assert!(bad(std::vec![p(0.5, 0.0, 1.0); 3])); // three rows at one time
        assert!(bad(std::vec![p(0.5, 1.0, 0.0), p(0.6, 0.0, 1.0)])); // lower above upper
        assert!(bad(std::vec![p(0.5, 0.0, f32::NAN), p(0.6, 0.0, 1.0)]));
        assert!(bad((0..65)
            .map(|k| p(k as f32 / 64.0, -1.0, 2.0))
            .collect()));
        assert!(!bad((0..64)
            .map(|k| p(k as f32 / 63.0, -1.0, 2.0))
            .collect()));
        // Times from -10 to 11 durations.
        assert!(!bad(std::vec![p(-10.0, -1.0, 1.0), p(11.0, -1.0, 1.0)]));
        assert!(bad(std::vec![p(-10.5, -1.0, 1.0), p(1.0, -1.0, 1.0)]));
        assert!(bad(std::vec![p(0.0, -1.0, 1.0), p(11.5, -1.0, 1.0)]));
        // The band is watched over its rows: the window widened to them, not beyond 10 D.
        let wide = Spec {
            band: Some(std::vec![p(-2.0, -1.0, 1.0), p(4.0, -1.0, 2.0)].leak()),
            ..t
        };
        assert_eq!(wide.watched(), (2.0, 3.0));
        assert_eq!(t.watched(), (0.4, 1.5));
        // A band the nominal pulse cannot pass between its rows or on one side of a step.
        let sine = |rows: std::vec::Vec<BandPoint>| Spec {
            shape: Shape::HalfSine,
            band: Some(rows.leak()),
            ..spec(Shape::HalfSine)
        };
        let flat = sine(std::vec![p(0.0, -0.2, 0.2), p(1.0, -0.2, 0.2)]);
        assert!(flat.band_misses_nominal().is_some() && flat.validate().is_err());
        let chord = sine(std::vec![
            p(0.0, -0.2, 0.2),
            p(0.5, 0.8, 1.1),
            p(1.0, -0.2, 0.2)
        ]);
        let u = chord.band_misses_nominal().unwrap().u; // the sine above the chord to 1.1
        assert!((0.0..0.5).contains(&u) || (0.5..1.0).contains(&u), "{u}");
        let step = sine(std::vec![
            p(0.0, -0.2, 0.2),
            p(0.5, 0.8, 1.2),
            p(0.5, -0.2, 0.2),
            p(1.0, -0.2, 0.2),
        ]);
        let miss = step.band_misses_nominal();
        assert_eq!(miss.map(|m| m.u), Some(0.5));
        assert_eq!(miss.and_then(|m| m.row), Some(2)); // the step's second row
        let fine = sine(std::vec![
            p(0.0, -0.2, 0.2),
            p(0.25, 0.5, 0.95),
            p(0.5, 0.8, 1.2),
            p(0.75, 0.5, 0.95),
            p(1.0, -0.2, 0.2),
        ]);
        assert_eq!(fine.band_misses_nominal(), None);
        fine.validate().unwrap();
    }

    #[test]
    fn a_users_band_at_its_ends_and_over_spans() {
        extern crate std;
        let p = |u, lower, upper| BandPoint { u, lower, upper };
        let rows: &'static [BandPoint] = std::vec![
            p(0.0, -0.5, 0.5),
            p(0.0, -0.3, 0.3),
            p(0.5, 0.0, 2.0),
            p(1.0, -0.3, 0.3),
            p(1.0, -0.1, 0.1),
        ]
        .leak();
        let s = Spec {
            shape: Shape::Sawtooth,
            band: Some(rows),
            ..spec(Shape::Sawtooth)
        };
        // Steps at both ends: the looser rows' limits at the instant; `outside` (0.2) beyond.
        assert_eq!(s.band_at(0.0), (-0.5, 0.5));
        assert_eq!(s.band_at(1.0), (-0.3, 0.3));
        assert_eq!(s.band_at(-0.01), (-0.2, 0.2));
        assert_eq!(s.band_at(1.01), (-0.2, 0.2));
        // On an interior row, and an ulp or two off an end row, the row.
        assert_eq!(s.band_at(0.5), (0.0, 2.0));
        assert_eq!(s.band_at(1.0 + 2e-7), (-0.3, 0.3));
        assert_eq!(s.band_at(-1e-7), (-0.5, 0.5));
        // Over a span: the loosest of its ends and of the rows inside it.
        let at = |u| s.shape.at(u);
        let (lo, hi) = super::band_over(&s, at, 0.4, 0.6);
        assert!((lo + 0.06).abs() < 1e-6 && hi == 2.0, "{lo} {hi}"); // 0.4's lower, the row's upper
        let (lo, hi) = super::band_over(&s, at, -0.1, 0.1);
        assert!(lo == -0.5 && (hi - 0.64).abs() < 1e-5, "{lo} {hi}"); // the step's, 0.1's
        let (lo, hi) = super::band_over(&s, at, 0.9, 1.5);
        assert!(lo == -0.3 && (hi - 0.64).abs() < 1e-5, "{lo} {hi}"); // the step's, 0.9's
    }

    /// A user's band that reaches further back than `before` widens the band's window, not
    /// the velocity change's: a slow pre-pulse dip before −0.4 D leaves Δv as it is.
    #[test]
    fn a_wide_users_band_leaves_the_delta_v_window_alone() {
        extern crate std;
        let shape = Shape::HalfSine;
        let s = spec(shape);
        let p = |u, lower, upper| BandPoint { u, lower, upper };
        let wide = Spec {
            band: Some(
                std::vec![
                    p(-2.0, -0.2, 0.2),
                    p(0.0, -0.2, 0.2),
                    p(0.25, 0.5, 0.95),
                    p(0.5, 0.8, 1.2),
                    p(0.75, 0.5, 0.95),
                    p(1.0, -0.2, 0.2),
                    p(1.5, -0.2, 0.2),
                ]
                .leak(),
            ),
            ..s
        };
        wide.validate().unwrap();
        let rate = 50_000.0f32;
        let d = 0.011 * rate;
        let a = |i: u64| {
            let u = (i as f32 - 3000.0) / d;
            let dip = if (-1.5..-0.5).contains(&u) {
                -60.0
            } else {
                0.0
            };
            (i < 12_000).then_some(500.0 * shape.at(u) + dip)
        };
        let peak = (3000.0 + 0.5 * d) as u64;
        let (narrow, wide) = (
            judge(a, rate, &s, peak).unwrap(),
            judge(a, rate, &wide, peak).unwrap(),
        );
        assert!(
            (wide.delta_v_m_s / narrow.delta_v_m_s - 1.0).abs() < 1e-3,
            "{narrow:?} {wide:?}"
        );
        assert!(wide.delta_v_pass && wide.band_pass, "{wide:?}");
    }

    /// Every field of a verdict as bits (the reason where there is none), to compare two.
    #[allow(clippy::type_complexity)]
    fn bits(v: &Result<Verdict, Missing>) -> Result<(bool, u64, u32, u64, u32, u32, u32), Missing> {
        v.map(|v| {
            (
                v.pass,
                v.start_s.to_bits(),
                v.margin.to_bits(),
                v.worst_s.to_bits(),
                v.worst_m_s2.to_bits(),
                v.limit_m_s2.to_bits(),
                v.delta_v_m_s.to_bits(),
            )
        })
    }

    /// The search that reads the band's flat stretches off the buckets gives the verdict of
    /// the one that read every sample ([`crate::spec::verdict_reference`]), bit for bit:
    /// pulses of every shape, longer and shorter, higher and lower than the nominal one, with
    /// noise, a glitch, an offset, against the standard band (with and without slack) and
    /// users' bands, at any rate.
    #[test]
    fn the_search_gives_the_verdict_of_reading_every_sample() {
        use crate::spec::verdict_reference::judge_reference;
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut rnd = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f32 / (1u64 << 53) as f32
        };
        let shapes = crate::spec::tests::SHAPES_UNDER_TEST;
        let mut passes = 0;
        let mut scratch = [0.0f32; SCRATCH + 32_768];
        for case in 0..1000 {
            let which = (case / 2) % shapes.len();
            let shape = shapes[which];
            // Half the cases near the nominal pulse (most pass), half anything (most fail).
            let near = case % 2 == 0;
            let measured = if near {
                shape
            } else {
                shapes[(case / 3) % shapes.len()]
            };
            // (A user's rows tabulating the short-topped trapezoid at 1/32 D would cut its
            // peak off: `validate` refuses them.)
            let mut spec = if case % 4 == 3 && which < 3 {
                tabulated(shape, 32 + case % 7)
            } else {
                spec(shape)
            };
            spec.tolerance.slack = if case % 4 == 1 { 0.1 * rnd() } else { 0.0 };
            let rate = [20_000.0f32, 50_000.0, 200_000.0][case % 5 % 3];
            spec.duration_s = 0.002 + 0.01 * rnd();
            let spread = if near { 0.15 } else { 0.8 };
            let dur = spec.duration_s * (1.0 + spread * (rnd() - 0.5));
            let peak = spec.peak_m_s2 * (1.0 + spread * (rnd() - 0.5));
            let (noise, offset) = (0.05 * peak * rnd(), spread * 0.1 * peak * (rnd() - 0.5));
            let glitch = (case % 6 == 1).then(|| 2.0 * peak * (rnd() - 0.5));
            let d = dur * rate;
            let start = 4.0 * d + 100.0;
            let total = (start + 8.0 * d) as u64;
            let glitch_at = (start + d * 2.0 * rnd()) as u64;
            let a = |i: u64| {
                if i >= total {
                    return None;
                }
                let u = (i as f32 - start) / d;
                let hash =
                    (i.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 40) as f32 / (1u64 << 24) as f32;
                let g = glitch.filter(|_| i == glitch_at).unwrap_or(0.0);
                Some(peak * measured.at(u) + offset + noise * (hash - 0.5) + g)
            };
            let peak_index = (start + measured.peak_at() * d) as u64;
            let want = judge_reference(a, rate, &spec, peak_index);
            let got = judge(a, rate, &spec, peak_index);
            // The window's samples held in the scratch, as the board's analysis holds them.
            let held = judge_in(a, rate, &spec, peak_index, &mut scratch);
            assert_eq!(bits(&got), bits(&want), "case {case}: {got:?} vs {want:?}");
            assert_eq!(
                bits(&held),
                bits(&want),
                "case {case}: {held:?} vs {want:?}"
            );
            passes += usize::from(want.is_ok_and(|v| v.band_pass));
        }
        // Both sides of the band are exercised.
        assert!(
            (80..920).contains(&passes),
            "{passes} of 1000 within the band"
        );
    }

    /// An initial-peak pulse written as a trapezoid (rise 0.001 D, a top far shorter than
    /// a table step: tabulated, its peak moved off [`Shape::peak_at`] and the band's bound
    /// there was none) judged on its own shape lifted by an offset: the search gives the
    /// reference's verdict (with the tabulated shape it passed at 90 where reading every
    /// sample failed).
    #[test]
    fn a_trapezoid_with_a_short_top_is_judged_as_reading_every_sample() {
        use crate::spec::verdict_reference::judge_reference;
        let shape = Shape::Trapezoid {
            rise: 0.001,
            fall: 0.999,
        };
        let mut s = spec(shape);
        s.tolerance.slack = 0.05;
        let (rate, d) = (50_000.0f32, 0.011 * 50_000.0f32);
        let start = 4.0 * d + 100.0;
        for offset in [0.0f32, 20.0, 90.0, 110.0] {
            let a = |i: u64| {
                (i < (start + 8.0 * d) as u64)
                    .then(|| 500.0 * shape.at((i as f32 - start) / d) + offset)
            };
            let peak = (start + shape.peak_at() * d) as u64;
            let (got, want) = (judge(a, rate, &s, peak), judge_reference(a, rate, &s, peak));
            assert_eq!(bits(&got), bits(&want), "{offset}: {got:?} vs {want:?}");
        }
    }
}
