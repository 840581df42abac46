//! The stream's state in two pieces, each with one constructor, so that starting over
//! ([`super::Stream::configure`]) cannot leave a field behind: what a scene fixes
//! ([`Limits`], in counts and samples) and what running changes ([`Run`]). The ring and the
//! baseline, the large buffers, are cleared in place.

use super::{active::Active, online::Online, train, Counters};
use crate::scene::Scene;
use crate::signal::cfc::Causal;

/// The scene in the stream's units: fixed by [`super::Stream::configure`].
#[derive(Clone, Copy)]
pub(super) struct Limits {
    /// Trigger level, counts.
    pub trigger_counts: f32,
    /// Edge level (the contact's start and end), counts.
    pub edge_counts: f32,
    /// Samples within the edge level that end an impact.
    pub hold: u32,
    /// Samples a flat new level must last to be a level change.
    pub settle: u32,
    /// Samples in the longest impact.
    pub max_samples: u64,
    /// The capture's length in use, samples ([`super::Stream::configure_for`]; 0: all `CAP`).
    pub capture_len: usize,
    /// With a CFC or the low-pass: samples the filter needs on each side of a contact (SAE
    /// J211's padding, or the low-pass's); with a specified pulse, the window its verdict
    /// watches (the larger of the two).
    /// The capture takes them beyond the impact's window (a lead-in before it, a tail after
    /// it), so neither ever changes where an impact starts or ends.
    pub filter_pad: u32,
}

impl Limits {
    /// The placeholder scene's ([`super::Stream::unconfigured`]).
    pub const PLACEHOLDER: Limits = Limits {
        trigger_counts: 1.0,
        edge_counts: 0.25,
        hold: 1,
        settle: 1,
        max_samples: 1,
        capture_len: 0,
        filter_pad: 0,
    };

    /// `scene`'s, for a channel of gain `|gain|` m/s² per count (a validated scene's, > 0).
    pub fn of(scene: &Scene) -> Limits {
        let gain = libm::fabsf(scene.calibration.gain_m_s2_per_count);
        Limits {
            trigger_counts: scene.trigger_m_s2 / gain,
            edge_counts: scene.edge_m_s2 / gain,
            hold: scene.samples(scene.hold_s),
            settle: scene.samples(scene.settle_s),
            max_samples: scene.samples(scene.max_impact_s) as u64,
            capture_len: 0,
            // With a CFC on the captured windows the filter needs its padding of signal
            // around the contact (SAE J211): the capture takes it beyond the window (the hold
            // does not change, nor does anything else the stream decides). A specified
            // pulse's verdict watches its window around the pulse: the same padding.
            filter_pad: scene.padding_samples(),
        }
    }
}

/// What running the stream changes: all of it back to [`Run::new`] on a new scene.
pub(super) struct Run {
    pub active: Option<Active>,
    /// Stream index of the next sample.
    pub index: u64,
    pub v0: Option<f32>,
    /// `v0` is a light gate's reading ([`super::Stream::set_approach_speed`]): it holds for
    /// every impact, a bounce's too.
    pub v0_measured: bool,
    /// The previous impact, for bounce trains.
    pub train: train::Tracker,
    pub counters: Counters,
    /// Trigger thresholds (raw counts) in force until the next refresh.
    pub thresholds: Option<(i32, i32)>,
    /// The ring's history is being run again after the first baseline (see `replay_history`).
    pub replaying: bool,
    /// The causal trigger filter, if the scene asks for one.
    pub trigger_filter: Option<Causal>,
    /// Stream index of the first sample after the last gap.
    pub gap_end: Option<u64>,
    /// Where the last impact's contact ended (its separation, or the end of its window): no
    /// report starts before it.
    pub last_end: u64,
    /// The power of the latest foot that showed one clearly ([`crate::signal::power_flank`]):
    /// the same contact's later, smaller impacts take it where their noise leaves it open.
    pub foot_power: Option<f32>,
    /// Where the last impact's window ended: the next capture does not reach back into it.
    pub window_end: u64,
    /// The impact just ended still takes samples into its capture up to this stream index
    /// (its filter's tail), decimating it if full when the flag says so: handed over there,
    /// at the next trigger, a gap or the end.
    pub tail: Option<(u64, bool)>,
    /// A trigger fired while a capture was handed over: the next call starts its impact at
    /// its first sample (see `push_to_impact_end`).
    pub trigger_pending: bool,
    /// A capture was handed over in this call.
    pub handed_over: bool,
    /// The baseline moved to another level (or is being learned again) since the last impact
    /// started: the next one says so.
    pub moved: bool,
    /// The kinematics' sums of the impact being followed ([`super::online`]).
    pub online: Online,
}

impl Run {
    /// Back to the start, in place (over the constant [`Run::new`]; building a second `Run`
    /// beside it and moving it in put 2.7 KiB more on the board's stack), for `scene`: its approach
    /// speed; its trigger filter at rest at 0 until the first baseline resets it to the
    /// baseline's level.
    pub fn restart(&mut self, scene: &Scene) {
        *self = Run::new();
        self.v0 = scene.v0_m_s();
        self.trigger_filter = scene
            .trigger_cfc
            .and_then(|class| {
                crate::signal::cfc::Biquad::cfc(class, scene.calibration.sample_rate_hz as f64)
            })
            .map(|b| Causal::new(b, 0.0));
    }

    /// At the start, with no approach speed and no trigger filter.
    pub const fn new() -> Run {
        Run {
            active: None,
            index: 0,
            v0: None,
            v0_measured: false,
            train: train::Tracker::new(),
            counters: Counters {
                samples: 0,
                impacts: 0,
                incomplete: 0,
                analyses_skipped: 0,
                samples_lost: 0,
                gaps: 0,
                level_changes: 0,
            },
            thresholds: None,
            replaying: false,
            trigger_filter: None,
            gap_end: None,
            last_end: 0,
            foot_power: None,
            window_end: 0,
            tail: None,
            trigger_pending: false,
            handed_over: false,
            moved: false,
            online: Online::new(),
        }
    }
}
