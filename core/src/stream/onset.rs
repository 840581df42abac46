//! What fired the trigger: a pulse, measured from the level just before it, or the signal
//! creeping past the trigger level (drift), which moves the baseline instead.

use super::{Stream, REACH};
use crate::capture::Sink;
use crate::signal::baseline::{Stats, STRIDE};

/// What fired the trigger ([`Stream::onset`]).
pub(super) enum Onset {
    /// A pulse, from the baseline or from the level (`(Σx, n)` of raw counts) the signal
    /// settled at since.
    Pulse(Option<(i64, i64)>),
    /// No pulse: the level (`(Σx, n)`) the baseline moves to.
    Moved((i64, i64)),
}

impl<const PRE: usize> Stream<PRE> {
    /// The sensor's zero force, counts, in a vertical scene whose baseline is the rest on a
    /// support: free fall reads `g` less than rest (an accelerometer reads specific force).
    /// With the tolerance a level is taken as it within: a quarter of `g` (a gain 25 % off
    /// still tells free fall from rest, `g` apart, whatever the edge level). `None` in a
    /// horizontal scene.
    fn free_fall(&self) -> Option<(f32, f32)> {
        let g = self.scene.contact_gravity_m_s2()?;
        let g_counts = g / self.scene.calibration.gain_m_s2_per_count;
        let level = self.baseline.mean() - g_counts;
        Some((level, 0.25 * libm::fabsf(g_counts)))
    }

    /// True if `level` (counts) is the free-fall level of a vertical scene
    /// ([`Self::free_fall`]).
    pub(super) fn is_free_fall(&self, level: f32) -> bool {
        self.free_fall()
            .is_some_and(|(at, tol)| libm::fabsf(level - at) <= tol)
    }

    /// The steady level just before the pulse, if the signal moved away from the baseline
    /// since it was learned (a step below the trigger, an orientation change, drift): walking
    /// back from the trigger past the pulse's rise (the strides that are not flat), a run of
    /// flat strides (each spanning at most twice the edge level) within the edge level of one
    /// another, beyond the edge level from the baseline, lasting at least the settle time (and
    /// one stride; two strides at the free-fall level of a vertical scene, which physics
    /// names: the body falls before every touch, whatever the ring's length). `(Σx, n)` over
    /// the run, as the baseline's rational; `None` for no such run within the flanks' reach.
    pub(super) fn level_before(&self) -> Option<(i64, i64)> {
        let edge = self.limits.edge_counts;
        let mean = self.baseline.mean();
        // Stride `k` back from the newest sample: Σx, least and greatest sample.
        let stride = |k: usize| -> Option<(i32, i16, i16)> {
            let reach = (k + 1) * STRIDE;
            if reach > REACH.min(self.ring.len()) {
                return None;
            }
            let (older, newer) = self.ring.last(reach);
            let (runs, _) = crate::signal::ring::split_runs(older, newer, STRIDE);
            let (a, b) = (Stats::of(runs[0]), Stats::of(runs[1]));
            Some((a.sum + b.sum, a.min.min(b.min), a.max.max(b.max)))
        };
        let flat = |(_, min, max): (i32, i16, i16)| (max as f32 - min as f32) <= 2.0 * edge;
        let level = |(sum, _, _): (i32, i16, i16)| sum as f32 / STRIDE as f32;
        let free_fall = self.free_fall();
        let at_free_fall = |l: f32| free_fall.is_some_and(|(ff, tol)| libm::fabsf(l - ff) <= tol);
        // Two strides of free fall hold one level to within their noise: their means differ
        // by less than a quarter of their spread (a 64-sample mean's noise is a 36th of its
        // spread), and a count. A slow foot rising out of free fall has strides flat within a
        // low edge level and within the free-fall tolerance (a quarter of g), but each a step
        // above the one before: no level.
        let agree = |a: (i32, i16, i16), b: (i32, i16, i16)| {
            let spread = (a.2 as f32 - a.1 as f32).max(b.2 as f32 - b.1 as f32);
            libm::fabsf(level(a) - level(b)) <= (spread / 4.0).max(1.0)
        };
        let free_fall_at = |k: usize, st: (i32, i16, i16)| {
            at_free_fall(level(st))
                && stride(k + 1).is_some_and(|older| flat(older) && agree(st, older))
        };
        // The first flat stride walking back; in a vertical scene the first at the free-fall
        // level if there is one (a smooth foot rising from free fall through the rest level
        // has flat strides at neither), else the first flat one.
        let first_flat = |only_free_fall: bool| {
            let mut k = 0;
            loop {
                let st = stride(k)?;
                if flat(st) && (!only_free_fall || free_fall_at(k, st)) {
                    return Some((k, st));
                }
                k += 1;
            }
        };
        let (mut k, first) = free_fall
            .and_then(|_| first_flat(true))
            .or_else(|| first_flat(false))?;
        let at = level(first);
        // A free fall's run holds free fall only (an edge level wider than `g` would take the
        // rest before the release into it); free fall is a level however close the edge level
        // puts it to rest.
        let in_free_fall = at_free_fall(at);
        if libm::fabsf(at - mean) <= 2.0 * edge && !in_free_fall {
            return None;
        }
        let (mut sum, mut n) = (0i64, 0i64);
        let mut varies = false;
        let same = |st| {
            flat(st)
                && libm::fabsf(level(st) - at) <= edge
                && (!in_free_fall || (at_free_fall(level(st)) && agree(st, first)))
        };
        while let Some(st) = stride(k).filter(|&st| same(st)) {
            sum += i64::from(st.0);
            n += STRIDE as i64;
            varies |= st.2 > st.1;
            k += 1;
        }
        let needed = if in_free_fall {
            2 * STRIDE as i64
        } else {
            i64::from(self.limits.settle).max(STRIDE as i64)
        };
        (varies && n >= needed).then_some((sum, n))
    }

    /// What fired the trigger at sample `x` (the next one): a pulse, measured from the baseline
    /// or from the level the signal settled at since ([`Self::level_before`]); or no pulse,
    /// and the level the baseline moves to. No pulse when the signal crept past the trigger
    /// level instead of rising through it (it left the edge level on the trigger's side more
    /// than half the settle time before, or since the stream began: drift, an orientation
    /// change, a sensor warming; a pulse rises from the edge level to the trigger level
    /// faster), or when `x` is no further than the trigger level from the level the signal
    /// settled at.
    pub(super) fn onset(&self, x: i16) -> Onset {
        // A vertical scene's release: the step from rest to free fall is no pulse; the
        // baseline moves to the free-fall level at once (its strides then refine it).
        let release = self
            .free_fall()
            .filter(|&(at, tol)| libm::fabsf(x as f32 - at) <= tol);
        if let Some((at, _)) = release {
            let n = STRIDE as i64;
            return Onset::Moved((libm::round(at as f64 * n as f64) as i64, n));
        }
        let level = self.level_before();
        let last_stride = || {
            let sum: i64 = (0..STRIDE)
                .map(|i| self.ring.back(i).map_or(0, i64::from))
                .sum();
            (sum, STRIDE as i64)
        };
        if let Some((sum, n)) = level {
            let from_level = x as f32 - sum as f32 / n as f32;
            if libm::fabsf(from_level) <= self.limits.trigger_counts {
                return Onset::Moved((sum, n));
            }
        }
        let window = (self.limits.settle as usize / 2)
            .clamp(2, REACH)
            .min(self.ring.len());
        let mean = self.baseline.mean();
        let edge = self.limits.edge_counts;
        let above = x as f32 > mean;
        let crept = window >= 2
            && self.ring.len() >= STRIDE
            && (0..window).all(|i| {
                self.ring.back(i).is_some_and(|y| {
                    if above {
                        y as f32 > mean + edge
                    } else {
                        (y as f32) < mean - edge
                    }
                })
            });
        if crept {
            Onset::Moved(level.unwrap_or_else(last_stride))
        } else {
            Onset::Pulse(level)
        }
    }

    /// A pulse fired the trigger at `x`: from the level the signal settled at since the
    /// baseline was learned, if it did (the baseline moves there first), else from the
    /// baseline.
    pub(super) fn pulse<const CAP: usize>(
        &mut self,
        sink: &mut impl Sink<CAP>,
        x: i16,
        level: Option<(i64, i64)>,
    ) {
        if let Some((sum, n)) = level {
            self.move_baseline(sum, n);
        }
        let moved = core::mem::take(&mut self.run.moved);
        self.start(sink, x, moved);
    }

    /// The baseline moves to the level `sum / n` (a level change without a pulse). The
    /// free-fall level of a vertical scene is the sensor's zero: no impact is flagged as
    /// measured from a level other than it.
    #[cold]
    pub(super) fn move_baseline(&mut self, sum: i64, n: i64) {
        let free_fall = n > 0 && self.is_free_fall(sum as f32 / n as f32);
        self.baseline.restart_at(sum, n);
        self.run.thresholds = None;
        self.run.counters.level_changes += 1;
        self.run.moved |= !free_fall;
        let level = self.baseline.mean() as f64;
        if let Some(f) = self.run.trigger_filter.as_mut() {
            f.reset(level);
        }
    }
}
