//! Impact monitor firmware for the STM32F4-Discovery (STM32F407VG), which also runs,
//! with the same tasks, on QEMU's `mps2-an386` machine.
//!
//! A sample source fills blocks of samples and queues them for the stream task, which hands
//! each impact's capture to the analysis task; the reporter logs the reports over defmt (see
//! [`tasks`]). The three run at three interrupt priorities ([`executors`]), so sampling is never
//! starved by analysis. The builds differ only in the sample source ([`source`]), the clocks,
//! the interrupt lines and the embassy-time driver:
//!
//! * `stm32` (default): the board, brought up at 168 MHz; ADC1 (or, with `adxl375`, an
//!   ADXL375 on SPI1) samples the sensor; defmt over RTT. `cargo fw` at the workspace root
//!   builds it, `cargo run --release` inside `firmware/` flashes it and shows the log.
//! * `emulator`: QEMU `-machine mps2-an386`; samples are replayed from a host file; defmt
//!   and the exit status go through semihosting. `impact emulate` builds and runs it.

#![no_std]
#![no_main]

#[cfg(all(feature = "stm32", feature = "emulator"))]
compile_error!(
    "features `stm32` and `emulator` are exclusive: use `--no-default-features --features emulator`"
);
#[cfg(not(any(feature = "stm32", feature = "emulator")))]
compile_error!("enable one of the features `stm32` (default) or `emulator`");

mod executors;
mod fault;
mod logger;
mod scene;
mod source;
mod stack;
mod tasks;

#[cfg(feature = "emulator")]
mod emulator;
#[cfg(feature = "stm32")]
mod stm32;

// The board module: `init` brings the chip up and returns the scene (compiled in on the board,
// from the command line in the emulator); `start_executors` starts the three priorities;
// `spawn_sources` starts the sample source (and the light gate) at the highest one;
// `end_of_stream` is told when a finite stream (the emulator's) is over.
#[cfg(feature = "emulator")]
use emulator as board;
#[cfg(feature = "stm32")]
use stm32 as board;

use cortex_m_rt::entry;
use defmt::{info, unwrap};

#[entry]
fn main() -> ! {
    stack::zero_ccmram();
    stack::paint();
    info!(
        "impact-firmware {} up; blocks of {}, pre-trigger {}, {} captures of {} samples",
        env!("CARGO_PKG_VERSION"),
        tasks::BLOCK_LEN,
        tasks::PRE_TRIGGER_LEN,
        tasks::CAPTURE_SLOTS,
        tasks::CAPTURE_LEN
    );
    let setup = board::init();
    let (samples_in, samples_out) = unwrap!(tasks::sample_queue());
    let (captures_in, captures_out) = unwrap!(tasks::capture_queue());
    let (high, medium, low) = board::start_executors();
    low.spawn(unwrap!(tasks::analysis::analysis(
        setup.scene,
        captures_out
    )));
    medium.spawn(unwrap!(tasks::reporter::reporter()));
    medium.spawn(unwrap!(tasks::stream::stream(
        setup.scene,
        setup.backpressure,
        samples_out,
        captures_in
    )));
    board::spawn_sources(setup, high, samples_in);
    loop {
        cortex_m::asm::wfi();
    }
}
