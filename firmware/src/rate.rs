//! The sample rate of the build's source.

/// Nominal sample rate of the build's source, in samples per second.
///
/// ADC: 500 kS/s (the limits of the STM32F407's ADC at the 168 MHz clock tree are in
/// `board/stm32/adc.rs`). The emulator's replay paces at its scene's rate, which defaults to
/// this one.
#[cfg(not(feature = "adxl375"))]
pub const SAMPLE_RATE_HZ: u32 = 500_000;

/// Nominal sample rate of the build's source, in samples per second: the ADXL375's fastest
/// output data rate.
#[cfg(feature = "adxl375")]
pub const SAMPLE_RATE_HZ: u32 = 3_200;
