//! Impact monitor firmware for the STM32F4-Discovery (STM32F407VG), which also runs,
//! with the same tasks, on QEMU's `mps2-an386` machine.
//!
//! A sample source fills blocks of samples and queues them for the monitor task, which
//! reports through the reporter task over defmt (see [`tasks`]). The builds differ only in the
//! sample source ([`source`]), the clocks and the embassy-time driver:
//!
//! * `stm32` (default): the board, brought up at 168 MHz; ADC1 (or, with `adxl375`, an
//!   ADXL375 on SPI1) samples the sensor; defmt over RTT. `cargo fw` at the workspace root
//!   builds it, `cargo run --release` inside `firmware/` flashes it and shows the log.
//! * `emulator`: QEMU `-machine mps2-an386`; samples are replayed from a host file; defmt
//!   and the exit status go through semihosting. `scripts/emulate.sh` builds and runs it.

#![no_std]
#![no_main]

#[cfg(all(feature = "stm32", feature = "emulator"))]
compile_error!(
    "features `stm32` and `emulator` are exclusive: use `--no-default-features --features emulator`"
);
#[cfg(not(any(feature = "stm32", feature = "emulator")))]
compile_error!("enable one of the features `stm32` (default) or `emulator`");

mod scene;
mod source;
mod stack;
mod tasks;

#[cfg(feature = "emulator")]
mod emulator;
#[cfg(feature = "stm32")]
mod stm32;

// `board::start` brings the board up, spawns its sample source and returns the scene (compiled
// in on the board, from the command line in the emulator); `board::end_of_stream` is told
// when a finite stream (the emulator's) is over.
#[cfg(feature = "emulator")]
use emulator as board;
#[cfg(feature = "stm32")]
use stm32 as board;

use defmt::{info, unwrap};
use embassy_executor::Spawner;

#[embassy_executor::main]
async fn main(spawner: Spawner) {
    stack::paint();
    info!(
        "impact-firmware {} up; blocks of {}, pre-trigger {}, capture {} samples",
        env!("CARGO_PKG_VERSION"),
        tasks::BLOCK_LEN,
        tasks::monitor::PRE_TRIGGER_LEN,
        tasks::monitor::CAPTURE_LEN
    );
    let (samples_in, samples_out) = unwrap!(tasks::sample_queue());
    let scene = board::start(spawner, samples_in);
    spawner.spawn(unwrap!(tasks::reporter::reporter()));
    spawner.spawn(unwrap!(tasks::monitor::monitor(scene, samples_out)));
}
