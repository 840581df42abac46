//! What the streaming stage knows of one impact when it ends (the [`Summary`] it hands over
//! with the capture), and a bounce of a train ([`Bounce`]).

use super::Status;

/// One bounce of a train (an impact after the first): its approach speed by both measures.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Bounce {
    /// 1 for the first bounce after the train's first impact.
    pub number: u32,
    /// From the previous separation to this first touch, s.
    pub flight_s: f32,
    /// The landing speed the flight time gives, `g t / 2 - h / t`, m/s.
    pub v0_flight_m_s: f32,
    /// The previous impact's rebound `v_r` brought down by the flight `t`, `g t - v_r`, m/s;
    /// absent if it had none (no Δv, a COR out of range) or the flight was too short to come
    /// back from it.
    pub v0_rebound_m_s: Option<f32>,
    /// `h`: how far above the previous separation the body landed, m. The body leaves a pad
    /// at its separation deformation `x_sep`; a pad that recovers its shape (elastic,
    /// viscoelastic) meets it again at the surface it touched (`h = x_sep`), one that keeps
    /// the dent where the body left it (a crushed pad) at that depth (`h = 0`): recovered,
    /// unless the previous rebound clearly says dented (see `stream/train.rs`).
    pub landing_height_m: f32,
}

/// What the streaming stage knows of one impact when it ends: positions, and exact integer
/// sums of the baseline-removed raw counts `d = W x - S` (`S / W` is the frozen baseline).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Summary {
    /// 0 for the stream's first impact.
    pub index: u32,
    pub status: Status,
    /// A sample reached the scene's rails.
    pub clipped: bool,
    /// The stream began inside the pulse (its first sample was already beyond the edge
    /// level): the onset is not in the record.
    pub cut_at_start: bool,
    /// The signal settled at another level since the previous impact (a step, an orientation
    /// change, drift, free fall): the baseline is that level, the one just before this impact.
    pub level_change: bool,
    /// The signal never came back and the onset came more than the settle time before the
    /// peak: the pulse rode on drift, which its start, duration and Δv take in.
    pub drift: bool,
    /// The pulse was under way before the previous impact's window ended: beyond the edge
    /// level where that contact ended (the signal never came back between them: its start is
    /// that contact's end), or on a ramp under the edge level that runs back into that window
    /// (its start where the ramp or the foot's fit puts it, not before that window's end).
    pub in_previous: bool,
    /// The impact follows a flight and the scene's approach speed is only the first
    /// impact's: `v0_m_s` is `None` for that reason ([`crate::stream::train`]).
    pub approach_unknown: bool,
    /// Stream index of the impact's window's first sample (the pre-trigger margin before the
    /// onset); every streaming field is measured over the window.
    pub first_index: u64,
    /// Samples the capture holds before `first_index`: with a CFC, the filter's lead-in (SAE
    /// J211's padding), which no unfiltered field sees. 0 without a filter.
    pub filter_lead: u32,
    /// Stream index of the first sample beyond the edge level.
    pub onset_index: u64,
    /// First touch relative to `onset_index`, samples (≤ 0): where the rising flank reaches
    /// zero force (its foot fitted as a power curve on a captured impact,
    /// [`crate::signal::power_flank`], else a straight line), or the edge crossing.
    pub touch_offset: f32,
    /// First touch lies in the interval before a force that may have jumped there from zero
    /// (a damper's `c v0`, [`crate::signal::power_flank::steep_zero`]): at its middle, or at
    /// the zero of the onset's line (a jump onto a ramp, smaller than a sample's rise, lies
    /// on one; where that zero lies before the sample before the onset, touch lies between
    /// it and the onset, or that sample where it stands out of the noise); the samples cannot
    /// tell where in that interval it lies;
    /// the analysis places it from the contact's law where it can ([`crate::analysis::jump`]),
    /// and where not, says how far off it may be (`touch_reach`).
    pub touch_jump: bool,
    /// Samples first touch may lie from `touch_offset` where it is a jump's (`touch_jump`;
    /// else 0) and nothing but the contact's law can narrow it: half a sample from the
    /// interval's middle; from a line's zero (a jump onto a ramp lies on a line whose zero is
    /// earlier), as far as the onset, or as far as the sample before it where that sample
    /// stands out of the noise (its force says touch came earlier); 0 from a power curve's
    /// other than the line (a jump onto a ramp gives none: the foot's zero).
    pub touch_reach: f32,
    /// Stream index of the first sample back within the edge level after the peak, if any.
    pub separation_index: Option<u64>,
    /// Separation relative to `separation_index`, samples (the falling flank extrapolated to
    /// zero, or the edge crossing; between -1 and a few samples).
    pub separation_offset: f32,
    /// Stream index just after the impact's last sample (the end of the hold, or the cut).
    pub end_index: u64,
    /// Baseline as the rational `base_sum / base_n` counts.
    pub base_sum: i64,
    pub base_n: i64,
    /// The first largest `|d|` and its stream index.
    pub peak_d: i64,
    pub peak_index: u64,
    /// `Σ d` over the whole impact (also beyond a full capture), in `W · counts`.
    pub total_c: i64,
    /// `Σ d` over the contact, from the onset to the separation (exclusive), if the signal
    /// came back; for a captured impact also over its feet below the edge level: the whole
    /// samples from first touch to the onset and from the separation sample to the falling
    /// flank's zero. (The report's Δv adds the online sums' [`Found::step_c`], or the
    /// capture pass's where the online sums found no crush.)
    pub contact_c: Option<i64>,
    /// The approach speed of this impact, m/s: the scene's (or a light gate's), or, in a
    /// bounce train, the bounce's ([`crate::stream::train`]).
    pub v0_m_s: Option<f32>,
    /// The impact continues a bounce train: both measures of its approach speed.
    pub bounce: BounceSlot,
    /// The kinematics' states the stream's online sums found (`stream/online.rs`), or why
    /// not: the crush and the separation however long the contact, captured or not.
    pub motion: Record,
}

/// A summary's bounce, all zeros when the impact continues no train: `Option<Bounce>` keeps
/// `None` in a non-zero tag (the niche of its `Option<f32>`), which would put every static
/// capture in `.data` (its image in flash, copied at start-up) instead of `.bss`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BounceSlot {
    /// The bounce's number (1 for the first bounce after the train's first impact); 0 for no
    /// bounce.
    number: u32,
    flight_s: f32,
    v0_flight_m_s: f32,
    v0_rebound_m_s: f32,
    has_rebound: bool,
    landing_height_m: f32,
}

impl BounceSlot {
    /// No bounce.
    pub const NONE: Self = Self {
        number: 0,
        flight_s: 0.0,
        v0_flight_m_s: 0.0,
        v0_rebound_m_s: 0.0,
        has_rebound: false,
        landing_height_m: 0.0,
    };

    /// The bounce kept (a bounce's number is at least 1).
    pub fn get(&self) -> Option<Bounce> {
        (self.number > 0).then_some(Bounce {
            number: self.number,
            flight_s: self.flight_s,
            v0_flight_m_s: self.v0_flight_m_s,
            v0_rebound_m_s: self.has_rebound.then_some(self.v0_rebound_m_s),
            landing_height_m: self.landing_height_m,
        })
    }
}

impl From<Option<Bounce>> for BounceSlot {
    fn from(b: Option<Bounce>) -> Self {
        match b {
            Some(b) => Self {
                number: b.number.max(1),
                flight_s: b.flight_s,
                v0_flight_m_s: b.v0_flight_m_s,
                v0_rebound_m_s: b.v0_rebound_m_s.unwrap_or(0.0),
                has_rebound: b.v0_rebound_m_s.is_some(),
                landing_height_m: b.landing_height_m,
            },
            None => Self::NONE,
        }
    }
}

impl Summary {
    /// A placeholder (all zero).
    pub const EMPTY: Self = Self {
        index: 0,
        status: Status::Complete,
        clipped: false,
        cut_at_start: false,
        level_change: false,
        drift: false,
        in_previous: false,
        approach_unknown: false,
        first_index: 0,
        filter_lead: 0,
        onset_index: 0,
        touch_offset: 0.0,
        touch_jump: false,
        touch_reach: 0.0,
        separation_index: None,
        separation_offset: 0.0,
        end_index: 0,
        base_sum: 0,
        base_n: 0,
        peak_d: 0,
        peak_index: 0,
        total_c: 0,
        contact_c: None,
        v0_m_s: None,
        bounce: BounceSlot::NONE,
        motion: Record::NONE,
    };
}

/// What the stream's online sums found ([`Summary::motion`], `stream/online.rs`): the kinematics from the crush
/// and the two states around the separation, or why not. All zeros: nothing (so a capture's
/// summary stays in `.bss`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Record {
    /// 0: found; else why not ([`Missing`] as a number; 0 with `held` false: no reason).
    why: u8,
    held: bool,
    found: Found,
}

/// Why the online sums hold no kinematics.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Missing {
    /// No approach speed, or the impact is not one the kinematics are for (not complete,
    /// clipped, cut at the start, inside the previous one).
    NotKinematic = 1,
    /// The velocity never reached zero within the impact.
    NoStop = 2,
    /// The crush lay outside the samples the stream kept around it (the approach speed or
    /// first touch found at the end moved it beyond them).
    CrushNotHeld = 3,
    /// The separation's samples were no longer in the ring when it was located, or first
    /// touch lay further back than the samples kept before the onset.
    EdgeNotHeld = 4,
}

impl Record {
    /// Nothing, no reason (a placeholder).
    pub const NONE: Self = Self {
        why: 0,
        held: false,
        found: Found {
            crush: 0.0,
            x_max: 0.0,
            x_sep: 0.0,
            step_c: 0,
        },
    };

    /// Found.
    pub fn found(found: Found) -> Self {
        Self {
            why: 0,
            held: true,
            found,
        }
    }

    /// Nothing, for `why`.
    pub fn missing(why: Missing) -> Self {
        Self {
            why: why as u8,
            ..Self::NONE
        }
    }

    /// The kinematics found, or why not.
    pub fn get(&self) -> Result<Found, Option<Missing>> {
        if self.held {
            return Ok(self.found);
        }
        Err(match self.why {
            1 => Some(Missing::NotKinematic),
            2 => Some(Missing::NoStop),
            3 => Some(Missing::CrushNotHeld),
            4 => Some(Missing::EdgeNotHeld),
            _ => None,
        })
    }
}

/// The kinematics the sums found, in samples from the onset and metres.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Found {
    /// When the velocity reached zero (fractional samples from the integration's first
    /// sample's instant).
    pub crush: f64,
    /// The deformation then, m.
    pub x_max: f64,
    /// The deformation at the separation, m.
    pub x_sep: f64,
    /// The area the sums missed where the force steps at the crush, in units of `C`
    /// (`Σ d`): the report's Δv adds it to [`Summary::contact_c`]
    /// ([`crate::report::motion::Frame::found`], [`crate::report::measured`]).
    pub step_c: i64,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::capture::Capture;

    #[test]
    fn an_empty_summary_has_no_bounce_and_a_bounce_survives_the_slot() {
        // NONE is the all-zero value (Default): an empty capture is all zeros, so its statics
        // go to `.bss` (the firmware's memory check reads it off the ELF).
        assert_eq!(BounceSlot::NONE, BounceSlot::default());
        assert_eq!(Capture::<64>::new().summary().bounce.get(), None);
        let b = Bounce {
            number: 3,
            flight_s: 0.1,
            v0_flight_m_s: 0.5,
            v0_rebound_m_s: None,
            landing_height_m: 2e-4,
        };
        assert_eq!(BounceSlot::from(Some(b)).get(), Some(b));
        let b = Bounce {
            v0_rebound_m_s: Some(0.4),
            ..b
        };
        assert_eq!(BounceSlot::from(Some(b)).get(), Some(b));
        assert_eq!(BounceSlot::from(None), BounceSlot::NONE);
    }
}
