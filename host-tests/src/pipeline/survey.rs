//! What the whole recording tells before it is analysed (its median, noise, extremes, flat
//! tops and glitches), gathered a block at a time in bounded memory, and the levels and
//! scale the analysis takes from it.
//!
//! The whole-file path runs it over the recording in memory, the passes path over the file
//! as it is read: the same code on the same values, so both give the same reports.

use crate::pipeline::histogram::OrderHistogram;
use crate::pipeline::screen::{self, FlatTops, Removal, SpikeScan, TooManyGlitches};
use crate::report::fmt::human;
use crate::report::Clipping;

/// One pass over a recording (values in m/s²).
pub struct Survey {
    values: OrderHistogram,
    steps: OrderHistogram,
    shape: Shape,
    last: Option<f64>,
    min: f64,
    max: f64,
}

/// The part of a survey that follows the signal's shape (flat tops, glitches): independent
/// of the rest, so it can run on a thread of its own ([`Survey::take_shape`]).
pub struct Shape {
    flat: FlatTops,
    spikes: Option<SpikeScan>,
}

impl Shape {
    /// Its two scans apart, to push on threads of their own (every block to each, in order)
    /// and [`Shape::join`] again.
    pub fn split(self) -> (FlatTops, Option<SpikeScan>) {
        (self.flat, self.spikes)
    }

    pub fn join(flat: FlatTops, spikes: Option<SpikeScan>) -> Self {
        Self { flat, spikes }
    }

    pub fn push(&mut self, block: &[f64]) {
        self.flat.push(block);
        if let Some(s) = &mut self.spikes {
            s.push(block);
        }
    }
}

/// What a pass found.
#[derive(Clone, Debug)]
pub struct Surveyed {
    pub samples: u64,
    /// The median, to 0.2 % ([`OrderHistogram`]); 0 for no samples.
    pub median_m_s2: f64,
    /// Robust noise: the median absolute step / sqrt(2) × 1.4826 (to 0.2 %).
    pub noise_rms_m_s2: f64,
    /// The recording's quantum (an ADC's code, a CSV's last decimal): its smallest non-zero
    /// step when the steps are whole multiples of it; 0 if none is.
    pub resolution_m_s2: f64,
    pub min_m_s2: f64,
    pub max_m_s2: f64,
    /// Flat tops at the extremes ([`FlatTops`]) beyond the noise floor ([`RAIL_STEPS`]).
    pub flat_tops: Option<Clipping>,
    /// Isolated glitches (when screened).
    pub removals: Vec<Removal>,
}

impl Surveyed {
    /// The largest reading's magnitude (0 for none).
    pub fn peak_m_s2(&self) -> f64 {
        if self.samples == 0 {
            return 0.0;
        }
        0.0f64.max(self.max_m_s2.abs()).max(self.min_m_s2.abs())
    }

    /// The largest distance of a reading from the median (0 for none).
    pub fn range_m_s2(&self) -> f64 {
        if self.samples == 0 {
            return 0.0;
        }
        0.0f64
            .max((self.max_m_s2 - self.median_m_s2).abs())
            .max((self.min_m_s2 - self.median_m_s2).abs())
    }
}

impl Survey {
    /// A pass that also screens for glitches when `screen` is set.
    pub fn new(screen: bool) -> Self {
        Self {
            values: OrderHistogram::new(),
            steps: OrderHistogram::new(),
            shape: Shape {
                flat: FlatTops::default(),
                spikes: screen.then(SpikeScan::default),
            },
            last: None,
            min: f64::INFINITY,
            max: f64::NEG_INFINITY,
        }
    }

    pub fn push(&mut self, block: &[f64]) {
        self.push_levels(block);
        self.shape.push(block);
    }

    /// The shape's part, to push on another thread (every block, in order) and put back
    /// before [`Survey::finish`]; meanwhile [`Survey::push_levels`] takes the blocks here.
    pub fn take_shape(&mut self) -> Shape {
        std::mem::replace(
            &mut self.shape,
            Shape {
                flat: FlatTops::default(),
                spikes: None,
            },
        )
    }

    pub fn put_shape(&mut self, shape: Shape) {
        self.shape = shape;
    }

    /// The median, noise and extremes' part of [`Survey::push`].
    pub fn push_levels(&mut self, block: &[f64]) {
        // (Loops of their own, on locals, so each runs at the machine's pace.)
        if let (Some(p), Some(&first)) = (self.last, block.first()) {
            self.steps.add((first - p).abs());
        }
        self.steps
            .add_all(block.windows(2).map(|w| (w[1] - w[0]).abs()));
        self.values.add_all(block.iter().copied());
        // Eight running extremes, so no comparison waits for the one before (only their
        // magnitudes are used: which zero is kept does not matter).
        let (mut min, mut max) = ([self.min; 8], [self.max; 8]);
        let eights = block.chunks_exact(8);
        let rest = eights.remainder();
        for eight in eights {
            for k in 0..8 {
                let v = eight[k];
                min[k] = if v < min[k] { v } else { min[k] };
                max[k] = if v > max[k] { v } else { max[k] };
            }
        }
        let lowest = |a: f64, &b: &f64| if b < a { b } else { a };
        let highest = |a: f64, &b: &f64| if b > a { b } else { a };
        self.min = rest.iter().fold(min.iter().fold(self.min, lowest), lowest);
        self.max = rest
            .iter()
            .fold(max.iter().fold(self.max, highest), highest);
        if let Some(&v) = block.last() {
            self.last = Some(v);
        }
    }

    pub fn finish(self) -> Result<Surveyed, SurveyError> {
        let finite = self.min.is_finite() && self.max.is_finite();
        if !self.values.is_empty() && !finite {
            return Err(SurveyError::NotFinite);
        }
        let median = self.values.median().unwrap_or(0.0);
        let noise = noise_of(&self.steps);
        let removals = match self.shape.spikes {
            Some(s) => s.finish(median)?,
            None => Vec::new(),
        };
        let q = self.shape.flat.resolution();
        Ok(Surveyed {
            samples: self.values.len(),
            median_m_s2: median,
            noise_rms_m_s2: noise,
            resolution_m_s2: if q.is_finite() { q } else { 0.0 },
            min_m_s2: self.min,
            max_m_s2: self.max,
            flat_tops: {
                let found = self.shape.flat.finish();
                let span = if finite { self.max - self.min } else { 0.0 };
                found.and_then(|c| beyond_floor(c, median, q, span))
            },
            removals,
        })
    }

    /// One pass over a slice.
    pub fn of(x: &[f64], screen: bool) -> Result<Surveyed, SurveyError> {
        let mut s = Self::new(screen);
        s.push(x);
        s.finish()
    }
}

/// The levels the analysis takes from a recording's survey (after its glitches are
/// removed) and the options.
#[derive(Clone, Debug)]
pub struct Levels {
    pub clipping: Option<Clipping>,
    /// The full scale quantised to 32 000 counts, m/s² (the sensor's, or the recording's
    /// largest reading).
    pub full_scale_m_s2: Option<f64>,
    pub gain_m_s2_per_count: f64,
    pub trigger_m_s2: f64,
    pub edge_m_s2: f64,
}

/// The levels from a single channel's survey: the sensor's `range_m_s2` (full scale) if
/// known, else the flat tops found; the trigger and edge levels given, or from the noise
/// and range.
pub fn levels(
    s: &Surveyed,
    range_m_s2: Option<f64>,
    trigger: Option<f64>,
    edge: Option<f64>,
    vertical: bool,
) -> Result<Levels, SurveyError> {
    match range_m_s2 {
        Some(fs) => check_range(s.peak_m_s2(), fs)?,
        None => check_peak(s.peak_m_s2())?,
    }
    let clipping = match range_m_s2 {
        Some(fs) => Some(screen::from_range(fs)),
        None => s.flat_tops.clone(),
    };
    let gain = impact_io::quantise::gain_for(range_m_s2.unwrap_or_else(|| s.peak_m_s2()));
    let (trigger, edge) = trigger_and_edge(s, gain, trigger, edge, vertical);
    Ok(Levels {
        clipping,
        full_scale_m_s2: range_m_s2,
        gain_m_s2_per_count: gain,
        trigger_m_s2: trigger,
        edge_m_s2: edge,
    })
}

/// A sensor reads at most a little past its full scale: a recording that reaches more than
/// this many times the range given was given a range in the wrong unit.
pub const RANGE_EXCEEDED: f64 = 2.0;

/// An error if `peak_m_s2` (a reading's distance from zero) exceeds [`RANGE_EXCEEDED`] ×
/// the full scale `range_m_s2`.
pub fn check_range(peak_m_s2: f64, range_m_s2: f64) -> Result<(), SurveyError> {
    if peak_m_s2 > RANGE_EXCEEDED * range_m_s2 {
        return Err(SurveyError::BeyondRange {
            peak_m_s2,
            range_m_s2,
        });
    }
    Ok(())
}

/// An error if `peak_m_s2`, the largest reading's distance from zero and the full scale
/// when no range is given, is not 0 and not within [`impact_io::limits::LEVEL_M_S2`]: counts
/// at a smaller full scale would all be 0 (the impacts lost), at a larger one not finite.
pub fn check_peak(peak_m_s2: f64) -> Result<(), SurveyError> {
    let limits = impact_io::limits::LEVEL_M_S2;
    if peak_m_s2 == 0.0 || limits.contains(peak_m_s2) {
        return Ok(());
    }
    Err(SurveyError::PeakOutOfRange { peak_m_s2 })
}

/// Why a recording's survey refuses it.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum SurveyError {
    #[error(
        "a reading times the units and --gain is beyond the range of f64 (give a smaller --gain)"
    )]
    NotFinite,
    #[error(transparent)]
    Glitches(#[from] TooManyGlitches),
    /// The largest reading's distance from zero beyond [`RANGE_EXCEEDED`] × the full scale
    /// given, both m/s².
    #[error(
        "--range: the recording reaches {}, {:.1}× the full scale given ({}): a bare --range is in m/s²; give its unit, e.g. --range 16g for a ±16 g sensor",
        human(*.peak_m_s2, "m/s²"),
        .peak_m_s2 / .range_m_s2,
        human(*.range_m_s2, "m/s²")
    )]
    BeyondRange { peak_m_s2: f64, range_m_s2: f64 },
    /// The largest reading's distance from zero, m/s², outside
    /// [`impact_io::limits::LEVEL_M_S2`].
    #[error(
        "the recording reaches {} (its values in their units times --gain): out of range ({}); give a --gain that brings it within",
        human(*.peak_m_s2, "m/s²"),
        impact_io::limits::LEVEL_M_S2
    )]
    PeakOutOfRange { peak_m_s2: f64 },
}

/// A flat top is taken for a rail only more than this many steps of the recording's
/// resolution from its median. Nearer, it is the noise floor of a quantised channel at rest:
/// with a few counts of noise its lowest reading comes in runs, entered steeply, which no
/// sensor's full scale is (and with more noise, runs at the extremes are too rare to be
/// taken for flat tops). A recording that sits at its rail for more than half its length
/// has its median there: its flat top is not taken.
const RAIL_STEPS: f64 = 10.0;

/// The histogram median's accuracy, as a fraction of the recording's span (its bins'; taken
/// with room).
const MEDIAN_ACCURACY: f64 = 0.005;

/// The flat tops' levels more than [`RAIL_STEPS`] × `q` (the resolution) from the median;
/// `None` if none is.
fn beyond_floor(c: Clipping, median: f64, q: f64, span: f64) -> Option<Clipping> {
    // Also beyond the histogram median's own accuracy (a fraction of the recording's span):
    // a noise-free recording resting at one level (its minimum, at 1 g) has q = 0 and its
    // median within that of the rest level, which is no rail.
    let floor = (RAIL_STEPS * q).max(MEDIAN_ACCURACY * span);
    let far = |level: &f64| (level - median).abs() > floor;
    let (low, high) = (c.low_m_s2.filter(far), c.high_m_s2.filter(far));
    (low.is_some() || high.is_some()).then_some(Clipping {
        low_m_s2: low,
        high_m_s2: high,
        ..c
    })
}

/// Robust noise of the steps' histogram: their median / sqrt(2) × 1.4826 (0 for none).
fn noise_of(steps: &OrderHistogram) -> f64 {
    steps
        .median()
        .map_or(0.0, |m| 1.4826 * m / std::f64::consts::SQRT_2)
}

/// Robust noise estimate of `x`, m/s²: the median absolute step / sqrt(2) × 1.4826, to
/// 0.2 % (as a survey takes it).
pub fn noise_rms(x: &[f64]) -> f64 {
    let mut steps = OrderHistogram::new();
    steps.add_all(x.windows(2).map(|w| (w[1] - w[0]).abs()));
    noise_of(&steps)
}

/// The default edge level: 3 × the noise, within a fifth and a half of the trigger.
///
/// In a vertical scene (`vertical`: the recording's quantum `resolution_m_s2`, 0 if none)
/// the contact force is zero at separation and in every flight, where the sensor reads its
/// free-fall level to within its noise: the edge is [`VERTICAL_EDGE_NOISE`] × the noise, at
/// least [`VERTICAL_EDGE_QUANTA`] quanta (a quantised channel's noise, whose steps are mostly
/// 0, reads as none) and a [`VERTICAL_EDGE_TRIGGER`]th of the trigger (a noise-free
/// recording's), no higher than the horizontal default. A fifth of the trigger took a soft pad's slow feet for
/// flight up to 0.65 ms early (COR +1.7 %), and a body settling on the pad, whose force dips
/// to 0.04 g without its leaving, for a flight and two more contacts.
pub fn default_edge(noise_m_s2: f64, trigger_m_s2: f64, vertical: Option<f64>) -> f64 {
    let horizontal = (3.0 * noise_m_s2)
        .max(trigger_m_s2 / 5.0)
        .min(trigger_m_s2 / 2.0);
    match vertical {
        Some(q) => (VERTICAL_EDGE_NOISE * noise_m_s2)
            .max(VERTICAL_EDGE_QUANTA * q)
            .max(trigger_m_s2 / VERTICAL_EDGE_TRIGGER)
            .min(horizontal),
        None => horizontal,
    }
}

/// A vertical scene's edge level in the noise's RMS: a sample of Gaussian noise crosses it
/// once in 1.7 million.
pub const VERTICAL_EDGE_NOISE: f64 = 5.0;

/// A vertical scene's edge level is at least this many of the recording's quanta: a code of
/// noise each side of the level, and room.
pub const VERTICAL_EDGE_QUANTA: f64 = 3.0;

/// A vertical scene's edge level is at least the trigger over this: a twentieth of 5 % of
/// the recording's span.
pub const VERTICAL_EDGE_TRIGGER: f64 = 20.0;

/// The trigger level (given, or 10 × the noise, 5 % of the range, 4 counts, the largest)
/// and the edge level (given, or [`default_edge`]).
fn trigger_and_edge(
    s: &Surveyed,
    gain: f64,
    trigger: Option<f64>,
    edge: Option<f64>,
    vertical: bool,
) -> (f64, f64) {
    let sigma = s.noise_rms_m_s2;
    let trigger = trigger.unwrap_or_else(|| {
        (10.0 * sigma)
            .max(0.05 * s.range_m_s2())
            .max(f64::from(gain as f32) * 4.0)
    });
    let quantum = vertical.then_some(s.resolution_m_s2);
    let edge = edge.unwrap_or_else(|| default_edge(sigma, trigger, quantum));
    (trigger, edge)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ±1 count of noise (0.05 g a count; at rest with probability `rest`, else ±1 alike)
    /// with 300-count half-sine pulses every 100 000 samples, the reading clipped at `clip`
    /// counts if given.
    fn at_rest(rest: f64, clip: Option<f64>) -> Vec<f64> {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        (0..500_000usize)
            .map(|i| {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                let u = (state >> 11) as f64 / (1u64 << 53) as f64;
                let noise = if u < rest {
                    0.0
                } else if u < (1.0 + rest) / 2.0 {
                    -1.0
                } else {
                    1.0
                };
                // (And a run of eight at -1 entered from +1 now and then, as a long
                // recording holds them.)
                let noise = match i % 50_000 {
                    25_000 => 1.0,
                    25_001..=25_008 => -1.0,
                    _ => noise,
                };
                let k = i % 100_000;
                let pulse = if i >= 100_000 && k < 500 {
                    (300.0 * (std::f64::consts::PI * k as f64 / 500.0).sin()).round()
                } else {
                    0.0
                };
                clip.map_or(noise + pulse, |c| (noise + pulse).min(c)) * 0.05 * 9.80665
            })
            .collect()
    }

    #[test]
    fn the_noise_floor_of_a_channel_at_rest_is_no_rail() {
        // The lowest reading, one count below rest, comes in runs of eight and more entered
        // two counts steep: a flat top by shape alone, but within the noise.
        // Also when most readings sit at rest, so that the noise estimate (the median step)
        // is 0.
        for rest in [1.0 / 3.0, 0.7] {
            let mut flat = FlatTops::default();
            let x = at_rest(rest, None);
            flat.push(&x);
            assert!(
                flat.finish().is_some_and(|c| c.low_m_s2.is_some()),
                "{rest}"
            );
            let s = Survey::of(&x, false).unwrap();
            assert_eq!(s.flat_tops, None, "{rest}");
            assert_eq!(s.noise_rms_m_s2 == 0.0, rest > 0.5);
            // The pulses clipped at 200 counts: that rail, and no other.
            let s = Survey::of(&at_rest(rest, Some(200.0)), false).unwrap();
            let c = s.flat_tops.expect("the rail");
            assert_eq!(c.low_m_s2, None);
            assert_eq!(c.high_m_s2, Some(200.0 * 0.05 * 9.80665));
        }
    }
}
