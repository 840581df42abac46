//! Sample sources, one per build: where the i16 samples come from. Each one fills blocks of
//! [`crate::tasks::BLOCK_LEN`] samples and hands them to [`crate::tasks::sampler::BlockSender`].
//!
//! * `stm32`: [`adc`], ADC1 on PA1 triggered by TIM3 at [`SAMPLE_RATE_HZ`], through DMA;
//! * `stm32` + `adxl375`: [`accel`], an ADXL375 accelerometer on SPI1 ([`adxl375`] driver);
//! * `emulator`: [`replay`], a host file of raw samples read through semihosting.

#[cfg(all(feature = "stm32", not(feature = "adxl375")))]
pub mod adc;

#[cfg(feature = "adxl375")]
pub mod accel;
// The complete driver; the firmware uses part of it (the host tests use the rest).
#[cfg(feature = "adxl375")]
#[allow(dead_code)]
pub mod adxl375;

#[cfg(feature = "emulator")]
pub mod replay;

// A polled FIFO (the ADXL375's, or its emulation): hardware-free loss accounting (tested on
// the host) and the polling loop.
#[cfg(any(feature = "adxl375", feature = "emulator"))]
pub mod fifo;
#[cfg(any(feature = "adxl375", feature = "emulator"))]
pub mod poll;

// Hardware-free (tested on the host); `gate` is its EXTI half.
#[cfg(feature = "light-gate")]
pub mod gate;
#[cfg(feature = "light-gate")]
pub mod light_gate;

// `SAMPLE_RATE_HZ`, in a file of its own so that `src/bin/m4_bench.rs` can read it too.
include!("rate.rs");
