//! The ADC's analog scale, from the chip's own reference rather than an assumed supply.
//!
//! The STM32F407's ADC converts against VREF+, which the STM32F4-Discovery ties to VDDA = VDD
//! = 3.0 V (its LD3985M30R regulator), not 3.3 V: a scale computed for 3.3 V reads every
//! peak, Δv and force ~10 % high. The chip carries a reference that does not move with the
//! supply, VREFINT (1.18–1.24 V, ADC1 channel 17), and the factory's conversion of it at
//! VDDA = 3.3 V, 30 °C (`VREFINT_CAL`, a 16-bit word at 0x1FFF_7A2A; DS8626 §6.3.22, RM0090
//! §13.10). Converting VREFINT at start-up gives the supply the ADC really uses:
//!
//! ```text
//! VDDA = 3.3 V × VREFINT_CAL / VREFINT_DATA
//! gain = VDDA / 4096 / sensitivity          (m/s² per count; sensitivity in V per m/s² at PA1)
//! zero = sensor's zero-g voltage × 4096 / VDDA   (the code at 0 m/s²)
//! ```
//!
//! Nothing here touches the chip (the board's `init` does the conversion), so the host tests
//! check the arithmetic against simulated readings.
//!
//! The default sensor ([`SENSOR`]) puts ±800 m/s² on 0–3.0 V with its zero at 1.5 V: at the
//! Discovery's nominal 3.0 V the gain is exactly 1600/4096 m/s² per count, the compiled-in
//! scene's, and the zero sits at code 2048. A 0–3.3 V or ±5 V output is scaled into the
//! ADC's range by a divider (`docs/board.md`); its sensitivity at the pin is the one to set.

/// Where the factory's VREFINT conversion is kept (RM0090 / DS8626: `VREFIN_CAL`, 2 bytes).
pub const VREFINT_CAL_ADDR: usize = 0x1FFF_7A2A;

/// The supply at which the factory converted VREFINT, volts.
pub const VREFINT_CAL_VDDA_V: f32 = 3.3;

/// The Discovery's supply (LD3985M30R), volts: what the scale assumes when VREFINT cannot be
/// read (the emulator; a blank calibration word).
pub const NOMINAL_VDDA_V: f32 = 3.0;

/// The range of VDDA this ADC set-up runs in, volts: 2.4 V (below it DS8626 limits the ADC
/// clock to 18 MHz; the board's is 21 MHz) to 3.6 V. A reading outside it is a wrong
/// conversion or a supply the board cannot sample with.
pub const VDDA_RANGE_V: (f32, f32) = (2.4, 3.6);

/// VREFINT's range over the part's temperature range, volts (DS8626 Table 71).
const VREFINT_RANGE_V: (f32, f32) = (1.18, 1.24);

/// Full scale of the 12-bit ADC, counts.
pub const FULL_SCALE_COUNTS: f32 = 4096.0;

/// An analog accelerometer as the ADC pin sees it (after any divider).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sensor {
    /// Volts per m/s² at the pin.
    pub v_per_m_s2: f32,
    /// The pin's voltage at 0 m/s², volts.
    pub zero_v: f32,
}

/// The default sensor: ±800 m/s² over 0–3.0 V, zero at 1.5 V (1.875 mV per m/s²).
pub const SENSOR: Sensor = Sensor {
    v_per_m_s2: 1.5 / 800.0,
    zero_v: 1.5,
};

/// Why a VREFINT reading gave no supply voltage.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum VddaError {
    /// The calibration word is blank (0 or 0xFFFF): a part without it, or not an F4.
    NoCalibration(u16),
    /// The conversion of VREFINT read 0 (the channel not enabled, or not settled).
    NoReading,
    /// The supply this gives lies outside the part's range (volts): a wrong conversion.
    OutOfRange(f32),
}

/// The supply, volts, from the factory's VREFINT conversion `cal` (at 3.3 V) and today's
/// `data` (the mean of several conversions, in counts; a fraction is kept).
pub fn vdda_v(cal: u16, data: f32) -> Result<f32, VddaError> {
    if cal == 0 || cal == u16::MAX {
        return Err(VddaError::NoCalibration(cal));
    }
    if data.is_nan() || data <= 0.0 {
        return Err(VddaError::NoReading);
    }
    let v = VREFINT_CAL_VDDA_V * cal as f32 / data;
    // The calibration word itself must be a conversion of VREFINT at 3.3 V.
    let cal_v = VREFINT_CAL_VDDA_V * cal as f32 / FULL_SCALE_COUNTS;
    if !(VREFINT_RANGE_V.0 * 0.95..=VREFINT_RANGE_V.1 * 1.05).contains(&cal_v) {
        return Err(VddaError::NoCalibration(cal));
    }
    if (VDDA_RANGE_V.0..=VDDA_RANGE_V.1).contains(&v) {
        Ok(v)
    } else {
        Err(VddaError::OutOfRange(v))
    }
}

/// The ADC's scale for `sensor` at supply `vdda_v`, as the scene takes it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scale {
    /// m/s² per count.
    pub gain_m_s2_per_count: f32,
    /// The code at 0 m/s² (fractional).
    pub zero_counts: f32,
    /// The most negative and the most positive specific force the ADC can convert, m/s²
    /// (codes 0 and 4095): a sensor whose zero is off mid-scale clips sooner on one side.
    pub range_m_s2: (f32, f32),
}

impl Scale {
    /// The scale of `sensor` on an ADC whose reference is `vdda_v`.
    pub fn new(vdda_v: f32, sensor: Sensor) -> Self {
        let volts_per_count = vdda_v / FULL_SCALE_COUNTS;
        let gain = volts_per_count / sensor.v_per_m_s2;
        let zero = sensor.zero_v / volts_per_count;
        Self {
            gain_m_s2_per_count: gain,
            zero_counts: zero,
            range_m_s2: (-zero * gain, (FULL_SCALE_COUNTS - 1.0 - zero) * gain),
        }
    }
}

/// A change of the supply beyond which the board warns, relative: 0.2 %, about ten times the
/// measurement's own scatter (16 conversions of VREFINT, about ±1 count in 1650 at 3.0 V).
pub const WARN_CHANGE: f32 = 0.002;

/// The supply's change from a reference, relative, and the error it makes in every reading
/// of a sensor not powered from VDDA (the gain set at start-up is kept); a ratiometric sensor
/// on the 3.0 V rail follows the supply and makes none.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SupplyChange {
    /// `now / start − 1`.
    pub change: f32,
    /// The readings' relative error: `start / now − 1`.
    pub reading_error: f32,
    /// Whether `change` exceeds [`WARN_CHANGE`].
    pub warn: bool,
}

impl SupplyChange {
    /// The change from `start_v` (the reference) to `now_v`, volts.
    pub fn new(start_v: f32, now_v: f32) -> Self {
        let change = now_v / start_v - 1.0;
        Self {
            change,
            reading_error: start_v / now_v - 1.0,
            warn: change.abs() > WARN_CHANGE,
        }
    }
}
