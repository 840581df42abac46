//! The impact's motion integrated online: the kinematics' exact sums kept while the impact
//! streams, so that an impact whose approach speed is known has its crush and its
//! separation's states however long its contact, whether or not a capture holds it (or,
//! rarely, says why not: `crush-not-held`/`edge-not-held` when what is found only at the end
//! moved them beyond the samples kept around them). Only the impact's window counts: a next
//! hit's flank the sums took before the impact ended is beyond its end.
//!
//! ```text
//!            foot          onset                crush band           separation
//!   ... p_32 … p_2 p_1 | d'_0 d'_1 … ──────── [ 128 samples ] ─────── [4 states] ───
//!   `before` (raw)      C'_m, Q'_m from the onset, per sample (wrapping i64)
//! ```
//!
//! The sums run from the onset sample (`m` samples after it: `C'_m = Σ_{j<m} d'_j`,
//! `Q'_m = Σ_{i=1..m} C'_i`, `d'` the deviation less gravity's shift in a vertical contact).
//! What is found only at the end — first touch (the foot's fit, the whole lobe), and with it
//! the approach speed of a bounce — moves where the host's pass starts (`lead` samples before
//! the onset) and where it stops (`c_stop`). Both are exact integer shifts of the sums: with
//! `L = Σ_{r=1..lead} p_r` and `Q_L = Σ r p_r` over the foot (`p_r` the sample `r` before the
//! onset), the pass's state after `lead + m` samples is `(L + C'_m, Q_L + m L + Q'_m)`. So the
//! stream keeps:
//!
//! - the raw samples of the foot ([`BEFORE`]), and the sums over a longer lobe found at the
//!   start;
//! - the raw samples from where `C'` first reached within reach of the crush ([`BAND`],
//!   from a provisional `c_stop` less a margin): the crush for the final `c_stop` is found in
//!   them, the same sample as the pass's, since every `C'` before them lies below the margin;
//! - the sums at the four samples around the separation, walked back from the running sums
//!   over the ring while it holds them.
//!
//! Per in-impact sample this costs one i64 addition in the stream's loop (the sum of its
//! running `Σ d`); the rest is per call, from the call's sums (`Σ d' = Σ d - n g`), except
//! in the few strides where `C'` may reach the band, taken one by one (`impact bench m4`:
//! 4.0 instructions per in-impact sample, 43.6 → 47.6). The sums wrap instead of overflowing: exact modulo 2^64, so
//! every state is exact while its true value fits an i64 (`|Q| <= |d'| m² / 2`: at full scale
//! 2^17 samples; for a real contact, whose `C` stays near `v0 / kv`, far longer).

use super::REACH;
use crate::report::motion::{Crush, Frame, Missing, Record, Sums};
use crate::report::{Status, Summary};
use crate::scene::Scene;
use crate::signal::baseline::{Deviation, Stats, STRIDE};
use crate::signal::ring::Ring;

/// Raw samples kept from where the sums first came within reach of the crush.
pub(super) const BAND: usize = 128;
/// Raw samples kept before the onset: the foot a first touch found at the end reaches back
/// to (a longer lobe's sums are taken at the start).
pub(super) const BEFORE: usize = 32;
/// States kept around the separation: from one sample before the one it falls in to two
/// after.
const AROUND: usize = 4;

/// The sums over a lead of the foot: `L`, `Q_L`, and the largest `C` within it.
#[derive(Clone, Copy, Debug, Default)]
struct Lead {
    len: u32,
    l: i64,
    q: i64,
    max_c: i64,
}

/// The four states around a separation.
#[derive(Clone, Copy, Debug, Default)]
struct Around {
    /// The separation's stream index and offset they are for.
    index: u64,
    offset: f32,
    /// `m` of the first state.
    first_m: i64,
    /// `(C'_m, Q'_m)` for `m = first_m ..`, once `held`.
    states: [(i64, i64); AROUND],
    held: bool,
    /// The ring no longer reached back to them: never tried again.
    lost: bool,
}

/// The online sums of the impact being followed.
pub(super) struct Online {
    /// The deviation the kinematics integrate (the baseline's, less gravity in a vertical
    /// contact).
    motion: Deviation,
    /// Gravity's shift: `d' = d - g` (0 in a horizontal contact).
    g: i64,
    /// Samples integrated since the onset, and `C'`, `Q'` after them.
    m: u64,
    c: i64,
    q: i64,
    /// The band takes the samples from the first whose `C'` reaches this on (`i64::MIN`:
    /// while it fills, and for the sample after it; `i64::MAX`: never, or full).
    mark: i64,
    /// Where the band starts: the first `C'` at or above it.
    lo: i64,
    band_from: Option<Sums>,
    band_len: usize,
    band: [i16; BAND],
    /// The raw samples just before the band's first and just after its last (a crush at
    /// either end has its neighbours, as the capture's pass does: [`Crush::beside`]).
    band_before: Option<i16>,
    band_after: Option<i16>,
    /// The raw sample before the next one the sums take (`p_1` at the onset; `None` where
    /// not kept).
    last_x: Option<i16>,
    /// `p_1 ..`: the raw samples before the onset, newest first.
    before: [i16; BEFORE],
    before_len: usize,
    /// The whole lobe's sums if it reaches further back than `before`.
    lobe: Option<Lead>,
    around: Option<Around>,
}

impl Online {
    pub(super) const fn new() -> Self {
        Self {
            motion: Deviation::new(0, 1),
            g: 0,
            m: 0,
            c: 0,
            q: 0,
            mark: i64::MAX,
            lo: 0,
            band_from: None,
            band_len: 0,
            band: [0; BAND],
            band_before: None,
            band_after: None,
            last_x: None,
            before: [0; BEFORE],
            before_len: 0,
            lobe: None,
            around: None,
        }
    }

    /// A new impact: `deviation` the baseline's, `motion` the one the kinematics integrate
    /// (less gravity in a vertical contact), the ring's newest `pulse` samples from the onset
    /// on, `room` samples before the onset a pass may start at (the window's margin);
    /// `leads` the first touches known now (whole samples of foot: the straight line's, the
    /// lobe's), `c_stop` the provisional stop (`None`: no approach speed known now) and
    /// `peak_d` at least the largest `|d|` of the pulse so far.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn start<const PRE: usize>(
        &mut self,
        deviation: Deviation,
        motion: Deviation,
        ring: &Ring<PRE>,
        pulse: usize,
        room: usize,
        leads: [usize; 2],
        c_stop: Option<i64>,
        peak_d: i64,
    ) {
        self.motion = motion;
        self.g = (deviation.of(0) as i64).wrapping_sub(motion.of(0) as i64);
        self.m = 0;
        self.c = 0;
        self.q = 0;
        self.band_from = None;
        self.band_len = 0;
        self.band_before = None;
        self.band_after = None;
        self.around = None;
        self.lobe = None;
        // Sample `r` before the onset is the ring's `pulse + r - 1` from the newest.
        let p = |r: usize| ring.back(pulse + r - 1).filter(|_| pulse + r <= REACH);
        self.before_len = 0;
        for r in 1..=BEFORE.min(room) {
            let Some(x) = p(r) else { break };
            if let Some(slot) = self.before.get_mut(r - 1) {
                *slot = x;
                self.before_len = r;
            }
        }
        self.last_x = self.before.first().copied().filter(|_| self.before_len > 0);
        let leads = leads.map(|l| l.min(room));
        if let Some(&far) = leads.iter().filter(|&&l| l > self.before_len).max() {
            // Oldest first: the `far` samples before the pulse's, straight from the ring.
            if pulse + far <= REACH && pulse + far <= ring.len() {
                let (older, newer) = ring.last(pulse + far);
                let (mut c, mut q, mut top) = (0i64, 0i64, i16::MIN);
                let in_older = far.min(older.len());
                for part in [
                    older.get(..in_older).unwrap_or(&[]),
                    newer.get(..far - in_older).unwrap_or(&[]),
                ] {
                    for chunk in part.chunks(STRIDE) {
                        bulk(motion, chunk, &mut c, &mut q);
                        top = top.max(Stats::of(chunk).max);
                    }
                }
                // (The largest `C` within it bounded: `far` times its largest `d'`.)
                let max_c = (far as i64).saturating_mul((motion.of(top) as i64).max(0));
                self.lobe = Some(Lead {
                    len: far as u32,
                    l: c,
                    q,
                    max_c,
                });
            }
        }
        // The band from the lowest stop the known touches give, less a margin: 1/4096 of the
        // stop (a bounce's speed moves with the final touch, by g/2 a sample) and eight foot
        // samples (the foot's fit moves first touch by a few).
        self.mark = match c_stop {
            Some(c_stop) => {
                let lowest = leads
                    .iter()
                    .filter_map(|&l| self.lead(l).map(|s| c_stop.saturating_sub(s.l)))
                    .min()
                    .unwrap_or(c_stop);
                let foot = self
                    .before
                    .iter()
                    .take(8)
                    .map(|&x| motion.of(x).unsigned_abs() as i64);
                let margin = c_stop / 4096 + foot.max().unwrap_or(0).saturating_mul(8);
                lowest.saturating_sub(margin.max(1))
            }
            None => i64::MAX,
        };
        self.lo = self.mark;
        // The pulse so far, oldest first: in bulk if `C'` cannot reach the band within it
        // (`pulse` times the largest `|d'| <= |d| + |g|`), else a stride at a time.
        let (older, newer) = ring.last(pulse);
        let rise = (pulse as i64).saturating_mul(peak_d.saturating_add(self.g.saturating_abs()));
        if self.mark == i64::MAX || self.c.saturating_add(rise) < self.mark {
            for chunk in older.chunks(STRIDE).chain(newer.chunks(STRIDE)) {
                self.stride(chunk);
            }
        } else {
            self.run(older);
            self.run(newer);
        }
    }

    /// Samples in order (the pulse's first ones, and a run where `C'` may reach the band): a
    /// stride at a time, one by one with the band's test only where `C'` may reach it (at
    /// most the stride's length times its largest `d'` above where it starts).
    fn run(&mut self, xs: &[i16]) {
        for part in xs.chunks(STRIDE) {
            if self.mark != i64::MAX {
                let top = self.motion.of(Stats::of(part).max) as i64;
                let rise = (part.len() as i64).saturating_mul(top.max(0));
                if self.c.saturating_add(rise) >= self.mark {
                    self.run_checked(part);
                    continue;
                }
            }
            self.stride(part);
        }
    }

    /// At most a stride of samples at once ([`bulk`]).
    fn stride(&mut self, part: &[i16]) {
        bulk(self.motion, part, &mut self.c, &mut self.q);
        self.m += part.len() as u64;
        if let Some(&x) = part.last() {
            self.last_x = Some(x);
        }
    }

    /// Samples one by one, each tested against the band.
    fn run_checked(&mut self, xs: &[i16]) {
        let motion = self.motion;
        let (mut m, mut c, mut q, mut mark) = (self.m, self.c, self.q, self.mark);
        let mut prev = self.last_x;
        for &x in xs {
            let (c0, q0) = (c, q);
            c = c.wrapping_add(motion.of(x) as i64);
            q = q.wrapping_add(c);
            if c >= mark {
                mark = self.band_step(x, prev, m, c0, q0);
            }
            prev = Some(x);
            m += 1;
        }
        (self.m, self.c, self.q, self.mark, self.last_x) = (m, c, q, mark, prev);
    }

    /// The sums over the `len` samples of foot before the onset, from the kept samples or
    /// the lobe's.
    fn lead(&self, len: usize) -> Option<Lead> {
        if len <= self.before_len {
            // `before` is newest first: the foot oldest first is its first `len` reversed.
            let foot = self.before.get(..len)?.iter().rev().copied();
            return Some(foot_sums(self.motion, len, foot));
        }
        self.lobe.filter(|l| l.len as usize == len)
    }

    /// The in-impact loop took `kept`, with `sum = Σ d` over them and `sum2` the sum of the
    /// running `Σ d` after each (from the first of them); `max_x` is at least their largest
    /// raw sample. Exact, and per call, not per sample: `Σ d' = Σ d - n g`, and
    /// `Q'` grows by `n C' + sum2 - g n (n + 1) / 2`. Only where `C'` may reach the band
    /// within them (at most `n` times the largest `d'` above where it starts) are they taken
    /// one by one.
    pub(super) fn advance(&mut self, kept: &[i16], sum: i64, sum2: i64, max_x: i16) {
        let n = kept.len() as i64;
        if self.mark != i64::MAX {
            let rise = n.saturating_mul((self.motion.of(max_x) as i64).max(0));
            if self.c.saturating_add(rise) >= self.mark {
                self.run(kept);
                return;
            }
        }
        let c = self.c;
        self.c = c.wrapping_add(sum).wrapping_sub(n.wrapping_mul(self.g));
        let ramp = self.g.wrapping_mul(n.wrapping_mul(n + 1) / 2);
        self.q = self
            .q
            .wrapping_add(n.wrapping_mul(c))
            .wrapping_add(sum2)
            .wrapping_sub(ramp);
        self.m += n as u64;
        if let Some(&x) = kept.last() {
            self.last_x = Some(x);
        }
    }

    /// Sample `x`, the `m`-th from the onset, took the sums to `C' >= mark`; `(c, q)` are
    /// the sums before it, `prev` the sample before it. Returns the next mark.
    #[inline(never)]
    fn band_step(&mut self, x: i16, prev: Option<i16>, m: u64, c: i64, q: i64) -> i64 {
        if self.band_from.is_none() {
            self.band_from = Some(Sums {
                k: u32::try_from(m).unwrap_or(u32::MAX),
                c,
                q,
            });
            self.band_before = prev;
        }
        if let Some(slot) = self.band.get_mut(self.band_len) {
            *slot = x;
            self.band_len += 1;
            return i64::MIN;
        }
        // Full: the sample after its last.
        self.band_after = Some(x);
        i64::MAX
    }

    /// The separation at stream index `index` (offset `offset`) of an impact whose onset is
    /// `onset`: the states around it, walked back from the running sums over the ring (the
    /// stream's next sample is `next`) once the sums have passed them.
    pub(super) fn follow_separation<const PRE: usize>(
        &mut self,
        ring: &Ring<PRE>,
        next: u64,
        onset: u64,
        index: u64,
        offset: f32,
    ) {
        let fresh = match self.around {
            Some(a) => a.index != index || a.offset.to_bits() != offset.to_bits(),
            None => true,
        };
        if fresh {
            let m = index.saturating_sub(onset) as f64 + offset as f64 + 0.5;
            self.around = Some(Around {
                index,
                offset,
                first_m: libm::floor(m) as i64 - 1,
                states: [(0, 0); AROUND],
                held: false,
                lost: false,
            });
        }
        let Some(a) = self.around.as_mut() else {
            return;
        };
        let last = a.first_m + AROUND as i64 - 1;
        if a.held || a.lost || a.first_m < 0 || (self.m as i64) < last {
            return;
        }
        // The walk reads the samples from `first_m` on: give up at once (and for good) if the
        // ring no longer holds them, so that a late separation (a settled signal's) costs one
        // test, not a walk per chunk.
        let reach = next.checked_sub(onset + a.first_m as u64);
        if reach.is_none_or(|r| r > ring.len() as u64) {
            a.lost = true;
            return;
        }
        // Back from `m` to `first_m`: C'_{k-1} = C'_k - d'_{k-1}, Q'_{k-1} = Q'_k - C'_k.
        let (mut c, mut q) = (self.c, self.q);
        let mut k = self.m as i64;
        while k > a.first_m {
            if k <= last {
                if let Some(s) = a.states.get_mut((k - a.first_m) as usize) {
                    *s = (c, q);
                }
            }
            // Sample `k - 1` from the onset is stream index `onset + k - 1`.
            let back = next.checked_sub(onset + k as u64);
            let Some(x) = back
                .and_then(|b| usize::try_from(b).ok())
                .and_then(|b| ring.back(b))
            else {
                a.lost = true;
                return;
            };
            q = q.wrapping_sub(c);
            c = c.wrapping_sub(self.motion.of(x) as i64);
            k -= 1;
        }
        if let Some(s) = a.states.get_mut(0) {
            *s = (c, q);
        }
        a.held = true;
    }

    /// The record of the impact that ended with summary `s` (its touch, speed and
    /// separation final).
    pub(super) fn finish(&self, s: &Summary, scene: &Scene) -> Record {
        let kinematic = matches!(s.status, Status::Complete | Status::BufferFull)
            && !(s.clipped || s.cut_at_start || s.in_previous);
        // The impact's window (to its end: the hold's, or where a next hit began), as a
        // capture that holds it gives it to the pass: the sums took more (a next hit's
        // rising flank), which no state may use.
        let window = usize::try_from(s.end_index.saturating_sub(s.first_index)).ok();
        let frame = Frame::of(s, scene, window).filter(|_| kinematic);
        let (Some(frame), Some(c_stop)) = (frame, frame.and_then(|f| f.scale.c_stop())) else {
            return Record::missing(Missing::NotKinematic);
        };
        // Samples of the window from the first the pass integrates.
        let start = (s.onset_index.saturating_sub(s.first_index) as usize)
            .saturating_sub(frame.lead as usize);
        let reach = window.unwrap_or(0).saturating_sub(start) as u64;
        let Some(lead) = self.lead(frame.lead as usize) else {
            return Record::missing(Missing::EdgeNotHeld);
        };
        let crush = match self.crush(lead, c_stop) {
            // The sample that stopped it must lie in the window (and its neighbour after it,
            // to be counted, as the pass's samples end there).
            Ok(c) if u64::from(c.at.k) < reach => Crush {
                beside: c.beside.filter(|_| u64::from(c.at.k) + 1 < reach),
                ..c
            },
            Ok(_) => return Record::missing(Missing::NoStop),
            Err(why) => return Record::missing(why),
        };
        if u64::from(frame.sep_floor) + 1 > reach {
            return Record::missing(Missing::NoStop);
        }
        let Some(separation) = self.separation(&frame, lead, s) else {
            return Record::missing(Missing::EdgeNotHeld);
        };
        Record::found(frame.found(crush, separation))
    }

    /// The crush in the pass's coordinates (`lead` samples of foot first).
    fn crush(&self, lead: Lead, c_stop: i64) -> Result<Crush, Missing> {
        if lead.max_c >= c_stop {
            // Stopped within the foot (an approach far slower than the pulse's Δv): from
            // the kept samples.
            return self.crush_in_foot(lead.len as usize, c_stop);
        }
        let theta = c_stop.wrapping_sub(lead.l);
        let Some(from) = self.band_from else {
            // The sums never reached the band: nor the stop, if it lies above it.
            return Err(if theta >= self.lo {
                Missing::NoStop
            } else {
                Missing::CrushNotHeld
            });
        };
        if theta < self.lo {
            return Err(Missing::CrushNotHeld);
        }
        let (mut k, mut c, mut q) = (from.k, from.c, from.q);
        let band = self.band.get(..self.band_len).unwrap_or(&[]);
        for (i, &x) in band.iter().enumerate() {
            let c_next = c.wrapping_add(self.motion.of(x) as i64);
            if c_next >= theta {
                let before = match i.checked_sub(1) {
                    Some(j) => band.get(j).copied(),
                    None => self.band_before,
                };
                let after = match band.get(i + 1) {
                    Some(&x) => Some(x),
                    None if i + 1 == BAND => self.band_after,
                    None => None,
                };
                let at = shifted(lead, k, c, q);
                return Ok(Crush {
                    at,
                    c_next: lead.l.wrapping_add(c_next),
                    // (The pass's first sample has none before it in the pass's samples.)
                    beside: before
                        .zip(after)
                        .filter(|_| at.k > 0)
                        .map(|(b, a)| (self.motion.of(b), self.motion.of(a))),
                });
            }
            c = c_next;
            q = q.wrapping_add(c);
            k = k.saturating_add(1);
        }
        Err(if self.band_len < BAND {
            Missing::NoStop
        } else {
            Missing::CrushNotHeld
        })
    }

    /// The crush within the foot's `len` kept samples.
    fn crush_in_foot(&self, len: usize, c_stop: i64) -> Result<Crush, Missing> {
        let oldest_first = self.before.get(..len).ok_or(Missing::EdgeNotHeld)?;
        let (mut c, mut q) = (0i64, 0i64);
        for (k, &x) in oldest_first.iter().rev().enumerate() {
            let c_next = c + self.motion.of(x) as i64;
            if c_next >= c_stop {
                return Ok(Crush {
                    at: Sums { k: k as u32, c, q },
                    c_next,
                    // (A crush within the foot: no step looked for.)
                    beside: None,
                });
            }
            c = c_next;
            q += c;
        }
        Err(Missing::EdgeNotHeld)
    }

    /// The states after `sep_floor` and `sep_floor + 1` samples of the pass.
    fn separation(&self, frame: &Frame, lead: Lead, s: &Summary) -> Option<[Sums; 2]> {
        let a = self.around?;
        if !(a.held && Some(a.index) == s.separation_index)
            || a.offset.to_bits() != s.separation_offset.to_bits()
        {
            return None;
        }
        let m = frame.sep_floor as i64 - lead.len as i64;
        let i = usize::try_from(m - a.first_m).ok()?;
        let (c0, q0) = *a.states.get(i)?;
        let (c1, q1) = *a.states.get(i + 1)?;
        let m = u32::try_from(m).ok()?;
        Some([shifted(lead, m, c0, q0), shifted(lead, m + 1, c1, q1)])
    }
}

/// The pass's state after `lead` samples of foot and `m` from the onset, from the onset's
/// sums `(c, q)`.
fn shifted(lead: Lead, m: u32, c: i64, q: i64) -> Sums {
    Sums {
        k: lead.len.saturating_add(m),
        c: lead.l.wrapping_add(c),
        q: lead
            .q
            .wrapping_add((m as i64).wrapping_mul(lead.l))
            .wrapping_add(q),
    }
}

/// The sums over the `len` samples of foot given oldest first.
fn foot_sums(motion: Deviation, len: usize, foot: impl Iterator<Item = i16>) -> Lead {
    let (mut l, mut q, mut max_c) = (0i64, 0i64, i64::MIN);
    for x in foot {
        l += motion.of(x) as i64;
        q += l;
        max_c = max_c.max(l);
    }
    Lead {
        len: len as u32,
        l,
        q,
        max_c,
    }
}

/// `(c, q)` after at most a stride of samples (`C'` and `Q'` going in), from two integer
/// sums (no i64 per sample): with `d'_j = W x_j - S'`, `C'` grows by `Σ d'` and `Q'` by
/// `n C' + Σ_j (n - j) d'_j`, where `Σ_j j d'_j = W Σ j x_j - S' n (n - 1) / 2`
/// (`|Σ j x_j| < 2^27` in an i32).
fn bulk(motion: Deviation, part: &[i16], c: &mut i64, q: &mut i64) {
    let n = part.len() as i64;
    let (mut sx, mut sjx) = (0i32, 0i32);
    for (j, &x) in part.iter().enumerate() {
        sx = sx.wrapping_add(x as i32);
        sjx = sjx.wrapping_add((j as i32).wrapping_mul(x as i32));
    }
    // `d' = W x - S'`: W and S' from the deviation itself.
    let s = -(motion.of(0) as i64);
    let w = motion.of(1) as i64 + s;
    let sum = w.wrapping_mul(sx as i64).wrapping_sub(n.wrapping_mul(s));
    let weighted = w
        .wrapping_mul(sjx as i64)
        .wrapping_sub(s.wrapping_mul(n * (n - 1) / 2));
    *q = q
        .wrapping_add(n.wrapping_mul(*c))
        .wrapping_add(n.wrapping_mul(sum))
        .wrapping_sub(weighted);
    *c = c.wrapping_add(sum);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Online sums whose full band (sample `j`: `10 + j`, from the state after 5 samples)
    /// has `before` and `after` kept beside it.
    fn band(before: Option<i16>, after: Option<i16>) -> Online {
        let mut o = Online::new();
        o.band_from = Some(Sums { k: 5, c: 0, q: 0 });
        o.band_len = BAND;
        for (j, slot) in o.band.iter_mut().enumerate() {
            *slot = 10 + j as i16;
        }
        (o.band_before, o.band_after) = (before, after);
        o.lo = 0;
        o
    }

    /// The stop that band sample `i` reaches first.
    fn stop_at(i: usize) -> i64 {
        (0..=i).map(|j| 10 + j as i64).sum::<i64>() - 1
    }

    #[test]
    fn a_crush_anywhere_in_the_band_has_its_neighbours() {
        let lead = Lead::default();
        let o = band(Some(7), Some(900));
        let beside = |i: usize| o.crush(lead, stop_at(i)).unwrap().beside;
        assert_eq!(beside(0), Some((7, 11)), "first: the one kept before");
        assert_eq!(beside(60), Some((69, 71)), "inside");
        assert_eq!(beside(BAND - 1), Some((10 + BAND as i32 - 2, 900)), "last");
        // Not kept beside it (the ring held none, or the stream ended): none.
        let o = band(None, None);
        assert_eq!(o.crush(lead, stop_at(0)).unwrap().beside, None);
        assert_eq!(o.crush(lead, stop_at(BAND - 1)).unwrap().beside, None);
        assert!(o.crush(lead, stop_at(60)).unwrap().beside.is_some());
    }
}
