//! The bring-up self-test: what the board's DAC plays into its own ADC, and how each analysed
//! pulse is judged against it.
//!
//! A jumper from the DAC's output (PA4, DAC channel 1) to the ADC's input (PA1) closes the
//! loop. The DAC plays [`TABLE`] over and over, one code every [`DAC_RATE_HZ`]-th of a
//! second (TIM6's update, DMA1 stream 5 in circular mode from flash): a half-sine of
//! [`AMPLITUDE_CODES`] above [`ZERO_CODE`] lasting [`PULSE_S`], then rest, every [`PERIOD_S`].
//! The samples go the way every sample goes (TIM3, ADC2, DMA2, the stream, the analysis), and
//! each report is judged here against what was played:
//!
//! * the peak: the DAC and the ADC both convert against VREF+ (VDDA on the Discovery), so the
//!   played codes come back as the same codes whatever the supply; the peak in m/s² is the
//!   amplitude in codes times the ADC's gain. Within [`PEAK_TOLERANCE`] (DS8626: the DAC's and
//!   the ADC's gain errors, ±0.5 % and a few counts; the baseline removes both offsets);
//! * the full width at half maximum: two thirds of the half-sine's duration, within
//!   [`FWHM_TOLERANCE`] (the DAC holds each code for 10 ADC samples: up to one hold, 1.5 %);
//! * the sample rate: the stream's time between the starts of whole pulses of the played
//!   width (a spurious one times nothing) against the DAC's period. Each start is the rising
//!   flank extrapolated to zero, which a few counts of noise move by microseconds (the crest's
//!   plateau of codes within noise of the top spans ±60 µs, too wide to time by). Both timers run from the one crystal, so they agree exactly
//!   unless the ADC's trigger or its count is wrong; within [`RATE_TOLERANCE`].
//!
//! Pulses that start in the first [`SETTLE_S`] of the stream are not judged (the DAC starts
//! before the ADC, so the first may be cut; the baseline is still being learned). After
//! [`PULSES`] judged pulses the test gives its verdict: PASS when every one passed. If they
//! have not all come by [`DEADLINE_S`] of stream time (no jumper, a dead DAC), the verdict is
//! FAIL then ([`Judge::deadline`]), so a board whose stream never ends still gives one. Nothing
//! here touches the chip, so the host tests judge replayed samples with it, and the emulator
//! runs the same judge on the DAC's samples replayed through the whole monitor.

/// The DAC's update rate, Hz (TIM6 at 84 MHz / 1680).
pub const DAC_RATE_HZ: u32 = 50_000;

/// DAC updates in the half-sine: 100 × 20 µs = 2 ms, an even number so that its middle
/// code is the crest.
pub const PULSE_STEPS: usize = 100;

/// The half-sine's duration, s.
pub const PULSE_S: f32 = PULSE_STEPS as f32 / DAC_RATE_HZ as f32;

/// Codes in the played table: one period of 0.2 s.
pub const TABLE_LEN: usize = 10_000;

/// The time between pulses, s.
pub const PERIOD_S: f32 = TABLE_LEN as f32 / DAC_RATE_HZ as f32;

/// The rest level, DAC (and ADC) codes: mid-scale, the default sensor's 0 m/s² at 3.0 V.
pub const ZERO_CODE: u16 = 2048;

/// The half-sine's amplitude, codes: a quarter of the full scale (400 m/s² for the default
/// sensor at 3.0 V), well inside both rails.
pub const AMPLITUDE_CODES: u16 = 1024;

/// The start of the stream in which no pulse is judged, s.
pub const SETTLE_S: f64 = 0.5;

/// Pulses judged before the verdict.
pub const PULSES: u32 = 10;

/// Stream time by which the [`PULSES`] pulses must have been judged, s: the settling time and
/// two periods to spare.
pub const DEADLINE_S: f64 = SETTLE_S + (PULSES as f64 + 2.0) * PERIOD_S as f64;

/// The largest relative difference of the measured peak from the played one.
pub const PEAK_TOLERANCE: f32 = 0.03;

/// The largest relative difference of the measured FWHM from the played one.
pub const FWHM_TOLERANCE: f32 = 0.03;

/// The largest relative difference of the measured sample rate from the nominal one.
pub const RATE_TOLERANCE: f32 = 1e-3;

/// The codes the DAC plays, one period: the half-sine first, then rest. In flash (the DMA
/// reads it from there: DMA1's memory port reaches the flash through the bus matrix).
pub static TABLE: [u16; TABLE_LEN] = table();

/// `sin(x)` for `x` in [0, π], in a constant: its Taylor series to x^23 (error below 1e-9
/// there), as `core::f64::sin` is not `const`.
const fn sin(x: f64) -> f64 {
    let x2 = x * x;
    let mut term = x;
    let mut sum = x;
    let mut k = 1;
    while k < 12 {
        term = -term * x2 / ((2 * k) as f64 * (2 * k + 1) as f64);
        sum += term;
        k += 1;
    }
    sum
}

const fn table() -> [u16; TABLE_LEN] {
    let mut t = [ZERO_CODE; TABLE_LEN];
    let mut i = 1;
    while i < PULSE_STEPS {
        let x = core::f64::consts::PI * i as f64 / PULSE_STEPS as f64;
        let code = ZERO_CODE as f64 + AMPLITUDE_CODES as f64 * sin(x);
        t[i] = (code + 0.5) as u16;
        i += 1;
    }
    t
}

/// The code the DAC holds when the ADC takes sample `n` at `adc_rate_hz`, with the table
/// started `offset` DAC updates before the first sample: what the replayed self-test feeds
/// the emulator (each code held until the next update, as the DAC's output register holds it).
pub fn code_at(n: u64, adc_rate_hz: f64, offset: u64) -> u16 {
    let len = TABLE_LEN as u64;
    // Saturating casts: any rate gives an update count, and the table wraps it.
    let update = (n as f64 * f64::from(DAC_RATE_HZ) / adc_rate_hz) as u64 % len;
    TABLE
        .get(((update + offset % len) % len) as usize)
        .copied()
        .unwrap_or(ZERO_CODE)
}

/// What the DAC played, in the units of the reports.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Played {
    /// The half-sine's crest above rest, m/s²: [`AMPLITUDE_CODES`] × the ADC's gain.
    pub peak_m_s2: f32,
    /// The half-sine's full width at half maximum, s: 2/3 of [`PULSE_S`].
    pub fwhm_s: f32,
    /// The stream's nominal sample rate, Hz.
    pub rate_hz: f32,
    /// The supply the ADC's gain was derived from, if the board measured it (VREFINT).
    pub vdda_v: Option<f32>,
}

impl Played {
    /// The played pulse for an ADC of `gain_m_s2_per_count` sampled at `rate_hz`, its gain
    /// from the supply `vdda_v` (or assumed).
    pub fn new(gain_m_s2_per_count: f32, rate_hz: f32, vdda_v: Option<f32>) -> Self {
        Self {
            peak_m_s2: f32::from(AMPLITUDE_CODES) * gain_m_s2_per_count,
            fwhm_s: PULSE_S * 2.0 / 3.0,
            rate_hz,
            vdda_v,
        }
    }
}

/// What the self-test takes from one impact's report.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Measured {
    /// Whether the pulse was whole and unclipped (`complete`, not clipped).
    pub whole: bool,
    /// Stream time of the impact's start (its rising flank extrapolated to zero), s.
    pub start_s: f64,
    /// Peak above the baseline, m/s².
    pub peak_m_s2: f32,
    /// Full width at half maximum, s, if measured.
    pub fwhm_s: Option<f32>,
}

/// One judged pulse.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PulseCheck {
    /// 1 for the first judged pulse.
    pub number: u32,
    pub measured: Measured,
    /// The sample rate the time since the previous whole pulse of the played width gives, Hz
    /// (none for the first, or when there was none before).
    pub rate_hz: Option<f32>,
    pub peak_pass: bool,
    pub fwhm_pass: bool,
    /// True when there is no rate to check.
    pub rate_pass: bool,
    pub pass: bool,
}

/// The self-test's verdict after [`PULSES`] judged pulses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Verdict {
    pub passed: u32,
    pub judged: u32,
    pub pass: bool,
}

/// What one report gives the self-test.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Outcome {
    /// Before [`SETTLE_S`], or after the verdict: not judged.
    Skipped,
    /// A judged pulse, and the verdict if it was the last.
    Judged(PulseCheck, Option<Verdict>),
}

/// The judge, fed every report in index order.
#[derive(Clone, Copy, Debug)]
pub struct Judge {
    played: Played,
    judged: u32,
    passed: u32,
    /// The start of the last whole pulse of the played width, s.
    last_start_s: Option<f64>,
    /// Whether the verdict has been given.
    given: bool,
}

fn within(measured: f32, played: f32, tolerance: f32) -> bool {
    let d = (measured - played).abs();
    d.is_finite() && d <= tolerance * played.abs()
}

impl Judge {
    pub const fn new(played: Played) -> Self {
        Self {
            played,
            judged: 0,
            passed: 0,
            last_start_s: None,
            given: false,
        }
    }

    pub fn played(&self) -> Played {
        self.played
    }

    /// Judges one report.
    pub fn judge(&mut self, m: Measured) -> Outcome {
        if m.start_s < SETTLE_S || self.given {
            return Outcome::Skipped;
        }
        let peak_pass = m.whole && within(m.peak_m_s2, self.played.peak_m_s2, PEAK_TOLERANCE);
        let fwhm_pass = m
            .fwhm_s
            .is_some_and(|w| within(w, self.played.fwhm_s, FWHM_TOLERANCE));
        // Timed from the last whole pulse of the played width, over whole periods
        // (saturating: a negative time apart gives none).
        let rate_hz = self.last_start_s.and_then(|last| {
            let apart = m.start_s - last;
            let periods = (apart / f64::from(PERIOD_S) + 0.5) as u64;
            (periods >= 1).then(|| {
                let expected_s = periods as f64 * f64::from(PERIOD_S);
                (f64::from(self.played.rate_hz) * apart / expected_s) as f32
            })
        });
        // A whole pulse of the played width times the next (whatever its height: a divider on
        // the wire fails the peak, and the rate can still be told).
        if m.whole && fwhm_pass {
            self.last_start_s = Some(m.start_s);
        }
        let rate_pass = rate_hz.is_none_or(|r| within(r, self.played.rate_hz, RATE_TOLERANCE));
        let pass = peak_pass && fwhm_pass && rate_pass;
        self.judged += 1;
        self.passed += u32::from(pass);
        let check = PulseCheck {
            number: self.judged,
            measured: m,
            rate_hz,
            peak_pass,
            fwhm_pass,
            rate_pass,
            pass,
        };
        let verdict = (self.judged == PULSES).then(|| self.give());
        Outcome::Judged(check, verdict)
    }

    /// The verdict, given once: PASS when all [`PULSES`] were judged and passed.
    fn give(&mut self) -> Verdict {
        self.given = true;
        Verdict {
            passed: self.passed,
            judged: self.judged,
            pass: self.judged == PULSES && self.passed == PULSES,
        }
    }

    /// After `samples` of the stream (at the played rate): a failing verdict if it is past
    /// [`DEADLINE_S`] and the pulses have not all come (none once the verdict was given).
    pub fn deadline(&mut self, samples: u64) -> Option<Verdict> {
        let stream_s = samples as f64 / f64::from(self.played.rate_hz);
        (!self.given && stream_s > DEADLINE_S).then(|| self.give())
    }

    /// At the end of a finite stream: a failing verdict if fewer than [`PULSES`] pulses were
    /// judged (none if the verdict was given).
    pub fn at_end(&mut self) -> Option<Verdict> {
        (!self.given).then(|| self.give())
    }
}
