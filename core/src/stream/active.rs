//! The state of the impact being followed, from its trigger to its end: where it started,
//! its exact sums, its peak and separation, the flanks' records and its level watch.

use super::level::LevelWatch;
use super::rise::{Fall, Rise};
use crate::signal::baseline::Deviation;

/// The impact being followed.
pub(super) struct Active {
    /// Stream index of the window's first sample.
    pub(super) first_index: u64,
    /// Samples captured before `first_index` (the filter's lead-in).
    pub(super) filter_lead: u32,
    /// Stream index of the sample that fired the trigger.
    pub(super) trigger_index: u64,
    pub(super) onset_index: u64,
    pub(super) touch_offset: f32,
    /// How `touch_offset` was found at the trigger.
    pub(super) flank_touch: FlankTouch,
    /// The earliest first touch relative to the onset (the previous contact's end), samples.
    pub(super) touch_floor: f32,
    pub(super) base_sum: i64,
    pub(super) base_n: i64,
    /// Edge level in units of `d = W x - S`.
    pub(super) edge_d: i64,
    /// Flank level in units of `d`.
    pub(super) flank_d: i64,
    /// The trigger thresholds in units of `d` (a sample fires when `d > d_hi` or `d < d_lo`).
    pub(super) d_hi: i32,
    pub(super) d_lo: i32,
    pub(super) quiet: u32,
    /// Since the latest peak, the signal stayed within the edge level for at least an
    /// eighth of the hold (so a new hit is a new impact, not ringing).
    pub(super) returned: bool,
    /// Stream index of the first sample back within the edge level (or across it, a sign
    /// flip) after the peak (separation: later ringing does not move it unless it brings a
    /// new peak).
    pub(super) separation: Option<u64>,
    /// `Σ d` from `first_index` to the separation (exclusive).
    pub(super) separation_c: i64,
    /// The separation, its offset and the falling foot's `Σ d` beyond it (where the foot is
    /// a power curve: [`super::Stream::fall`], else [`super::Stream::separation_offset`] and 0), found while
    /// its flank was still in the ring (a long ring-down after it would push it out).
    pub(super) separation_at: Option<(u64, f32, i64)>,
    /// The rising side, for the foot's fit at the end; the pulse's sign; `Σ d` over the whole
    /// samples from the trigger's first touch (`touch_offset`) to the onset.
    pub(super) rise: Rise,
    /// The falling foot: from where the signal last came down through the foot's top after
    /// the latest peak to the separation (so its fit sees the whole foot, averaged, for any
    /// split of the stream), and the stream index of its first sample.
    pub(super) fall: Fall,
    pub(super) fall_start: u64,
    pub(super) sign: i64,
    pub(super) lead_c: i64,
    /// `Σ d` over the samples before the onset.
    pub(super) pre_onset_c: i64,
    pub(super) peak_d: i64,
    pub(super) peak_index: u64,
    pub(super) total_c: i64,
    /// Samples since `first_index`.
    pub(super) samples: u64,
    pub(super) clipped: bool,
    /// The walk back to the onset reached the stream's first sample still beyond the edge.
    pub(super) cut_at_start: bool,
    /// The baseline moved to another level since the previous impact.
    pub(super) level_change: bool,
    /// The signal did not come back, and the onset came more than the settle time before the
    /// peak: the pulse rode on drift; or a ramp into it began beyond the flanks' reach.
    pub(super) drift: bool,
    /// The trigger's first touch (`touch_offset`) lies inside the previous impact's contact.
    pub(super) line_in_previous: bool,
    /// The whole lobe before the onset: where it crosses the baseline (relative to the
    /// onset, samples) and `Σ d` over its samples.
    pub(super) lobe_touch: f32,
    pub(super) lobe_c: i64,
    /// The lobe runs back to the previous impact's window ([`super::feet::Lobe`]).
    pub(super) lobe_in_previous: bool,
    /// The sample just before the onset (`d`, the pulse's side positive), if the ring held it
    /// (a deviation of one sample: within i32, as `Deviation::of` gives it).
    pub(super) before_d: Option<i32>,
    /// The sink gave a buffer for this impact.
    pub(super) captured: bool,
    /// The buffer overflowed.
    pub(super) full: bool,
    /// The pulse was already under way when the last gap ended: its start is unknown.
    pub(super) began_in_gap: bool,
    /// Stream index just after the latest sample within the edge level.
    pub(super) last_quiet: u64,
    /// Where the impact's window ends if not at the current position (a next hit began
    /// after the last quiet sample).
    pub(super) end_at: Option<u64>,
    pub(super) level: LevelWatch,
}

/// How first touch was found at the trigger, from the rising flank in the ring
/// (`Stream::rising_flank`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum FlankTouch {
    /// The zero of the line fitted to the flank's samples between the edge and flank levels.
    Line,
    /// The onset stepped past the flank level from the sample before it (within the edge
    /// level, or beyond it the other way: ringing): the middle of the sample interval before
    /// it (`Stream::touch` places it within that interval from the onset and the next two
    /// samples).
    Steep,
    /// The edge level's crossing before the onset (late by design: the foot below the edge
    /// level lies before it), or the onset itself where the ring holds no sample before it:
    /// the flank held too few samples for a line (`Stream::touch` places it from the onset
    /// and the next two samples where they lie on a power curve).
    Crossing,
    /// The edge level's crossing, the flank's line refused (a jump onto it, or a zero out of
    /// its reach).
    Refused,
}

impl Active {
    /// The sample just before the onset lies within half the edge level either way (the
    /// ring held it).
    pub(super) fn quiet_before(&self) -> bool {
        self.before_d
            .is_some_and(|d| 2 * i64::from(d).abs() <= self.edge_d)
    }

    pub(super) fn deviation(&self) -> Deviation {
        Deviation::new(self.base_sum, self.base_n)
    }
}
