//! Light-gate speed: two beams a known distance apart, cut in turn by the body just before it
//! hits, give the approach speed `v0 = spacing / (t2 - t1)` that an accelerometer cannot.
//!
//! Hardware-free (the host tests include this file): the speed, the pairing of beam cuts
//! into passages with their direction, and the capture timer's 32-bit counts made into one
//! time line ([`CaptureClock`]). The timer's input capture that time-stamps the cuts and the
//! task that pairs them are in `board/stm32/gate.rs`.

/// Slowest and fastest approach speeds believed, m/s: outside them the gate was cut by
/// something else (a hand, a bounce) and the reading is refused.
pub const PLAUSIBLE_M_S: (f32, f32) = (0.01, 100.0);

/// Why a pair of beam cuts gave no speed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum GateError {
    /// The second beam was cut before (or with) the first.
    Order,
    /// The speed is outside [`PLAUSIBLE_M_S`].
    Implausible,
    /// The spacing is not a positive finite length.
    Spacing,
}

/// Approach speed, m/s, from the beam-cut times (µs, any common origin) and the beams'
/// spacing (m).
pub fn speed_m_s(t1_us: u64, t2_us: u64, spacing_m: f32) -> Result<f32, GateError> {
    if !(spacing_m.is_finite() && spacing_m > 0.0) {
        return Err(GateError::Spacing);
    }
    let dt_us = t2_us
        .checked_sub(t1_us)
        .filter(|&d| d > 0)
        .ok_or(GateError::Order)?;
    let v = (spacing_m as f64 * 1e6 / dt_us as f64) as f32;
    if (PLAUSIBLE_M_S.0..=PLAUSIBLE_M_S.1).contains(&v) {
        Ok(v)
    } else {
        Err(GateError::Implausible)
    }
}

/// One of the two beams: `First` is the one farther from the barrier.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Beam {
    First,
    Second,
}

/// A body through both beams.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Passage {
    /// First then second beam: moving toward the barrier at this speed, m/s (the approach
    /// speed of the next impact).
    Toward(f32),
    /// Second then first beam: moving away (a rebound) at this speed, m/s.
    Away(f32),
}

/// Edges of one beam closer than this, µs, are one cut (a receiver's output bouncing as the
/// body's edge crosses the beam): the first edge of such a burst is the cut's time. At the
/// fastest speed believed (100 m/s) the two beams, 10 mm apart, are cut 100 µs apart, so no
/// real passage is merged; a rebound re-cuts a beam milliseconds later.
pub const DEBOUNCE_US: u32 = 50;

/// Whether an edge at `now_us` is a new cut, given the beam's previous edge (accepted or
/// not) at `last_us`; times in µs of a wrapping 32-bit clock. Edges that keep coming closer
/// than [`DEBOUNCE_US`] apart stay one cut.
pub fn new_cut(last_us: Option<u32>, now_us: u32) -> bool {
    last_us.is_none_or(|last| now_us.wrapping_sub(last) >= DEBOUNCE_US)
}

/// Longest time between the two cuts of one passage, µs: a later cut starts a new passage.
pub const PAIRING_WINDOW_US: u64 = 1_000_000;

/// Pairs time-stamped beam cuts into passages. A cut of the same beam again replaces the
/// pending one (the body wobbled in the beam, or a previous passage was incomplete); a cut of
/// the other beam within [`PAIRING_WINDOW_US`] completes a passage, whose direction is the
/// order of the beams.
#[derive(Clone, Copy, Debug, Default)]
pub struct Pairing {
    pending: Option<(Beam, u64)>,
}

impl Pairing {
    pub const fn new() -> Self {
        Self { pending: None }
    }

    /// A cut of `beam` at `t_us`: the passage it completes, if any.
    pub fn cut(
        &mut self,
        beam: Beam,
        t_us: u64,
        spacing_m: f32,
    ) -> Option<Result<Passage, GateError>> {
        match self.pending {
            Some((earlier, t0))
                if earlier != beam && t_us.saturating_sub(t0) <= PAIRING_WINDOW_US =>
            {
                self.pending = None;
                Some(speed_m_s(t0, t_us, spacing_m).map(|v| match earlier {
                    Beam::First => Passage::Toward(v),
                    Beam::Second => Passage::Away(v),
                }))
            }
            _ => {
                self.pending = Some((beam, t_us));
                None
            }
        }
    }
}

/// A 32-bit capture counter at 1 MHz (it wraps every 71.6 minutes) made into one 64-bit time
/// line, µs: each capture is placed from the previous one by the counts between them, forward
/// or back (a capture read late, after a later one of the other beam, is earlier), whichever
/// the coarse clock's own advance is nearer. After a silence longer than half a wrap (told by
/// a coarse clock that does not wrap, e.g. the system's uptime) the line starts again from the
/// coarse clock: the pairing only compares cuts a second apart at most, so nothing it uses
/// spans the restart.
#[derive(Clone, Copy, Debug, Default)]
pub struct CaptureClock {
    /// The last capture: its raw count, its time on the line and on the coarse clock, µs.
    last: Option<(u32, u64, u64)>,
}

/// Half the capture counter's wrap, µs: captures closer than this are ordered by their counts.
pub const HALF_WRAP_US: u64 = 1 << 31;

impl CaptureClock {
    pub const fn new() -> Self {
        Self { last: None }
    }

    /// The time, µs, of a capture of `raw` counts, read at `coarse_us` on the coarse clock
    /// (soon after the capture).
    pub fn extend(&mut self, raw: u32, coarse_us: u64) -> u64 {
        let t = match self.last {
            Some((raw0, t0, coarse0)) if coarse_us.saturating_sub(coarse0) < HALF_WRAP_US => {
                let ahead = i64::from(raw.wrapping_sub(raw0));
                let behind = ahead - (1i64 << 32);
                let coarse = coarse_us as i64 - coarse0 as i64;
                let step = if (ahead - coarse).abs() <= (behind - coarse).abs() {
                    ahead
                } else {
                    behind
                };
                t0.saturating_add_signed(step)
            }
            _ => coarse_us,
        };
        self.last = Some((raw, t, coarse_us));
        t
    }
}

/// Two captures taken together (both beams' flags found in one interrupt, microseconds
/// apart), in the order they were taken: `b` is after `a` when it is less than half a wrap of
/// counts after it.
pub fn in_capture_order<T>(a: (u32, T), b: (u32, T)) -> [(u32, T); 2] {
    if u64::from(b.0.wrapping_sub(a.0)) < HALF_WRAP_US {
        [a, b]
    } else {
        [b, a]
    }
}
