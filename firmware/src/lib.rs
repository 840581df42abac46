//! The hardware-free half of the impact monitor firmware (Stabilizer's pattern): what the
//! firmware's binaries, the host's tests and the benchmarks import as a library, not by
//! `#[path]` or `include!`. Nothing here touches a peripheral; it builds for the host too,
//! where the defmt formatting is left out.
//!
//! * [`analog`]: the ADC's scale from the supply VREFINT measures;
//! * [`conversions`]: the ADC's conversions counted against the samples delivered;
//! * [`scene`]: the compiled-in bench and the emulator's `key=value` scene parser;
//! * [`selftest`]: the bring-up self-test's played pulse (DAC → ADC) and its judge;
//! * [`rate`]: the build's sample rate;
//! * [`adxl375`]: the ADXL375 driver over `embedded-hal-async` (SPI traffic, FIFO, scale);
//! * [`fifo`]: samples a polled FIFO lost, counted against the sensor's own stream;
//! * [`light_gate`]: two beams' cuts paired into passages and speeds;
//! * [`reset_record`]: why the firmware reset itself, kept across the reset;
//! * [`ticks`]: deadlines beyond a 32-bit one-shot timer's reach, in several shots;
//! * `semihosting` (QEMU builds only): the host's command line, files and exit status.

#![no_std]

pub mod adxl375;
pub mod analog;
pub mod conversions;
pub mod fifo;
pub mod light_gate;
pub mod rate;
pub mod reset_record;
pub mod scene;
pub mod selftest;
#[cfg(all(target_os = "none", feature = "emulator"))]
pub mod semihosting;
pub mod ticks;

pub use rate::SAMPLE_RATE_HZ;
