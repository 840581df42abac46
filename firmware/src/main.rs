//! Impact monitor firmware for the STM32F4-Discovery (STM32F407VG), which also runs,
//! with the same tasks, on QEMU's `mps2-an386` machine.
//!
//! A sample source fills blocks of samples and queues them for the stream task, which hands
//! each impact's capture to the analysis task; the reporter logs the reports over defmt (see
//! [`tasks`], [`queues`]). The three run at three interrupt priorities ([`executors`]), so
//! sampling is never starved by analysis; `main` below starts them one priority at a time. The
//! builds differ only in the board ([`board`]: its sample sources, clocks, interrupt lines and
//! embassy-time driver); the hardware-free half is the `impact_firmware` library:
//!
//! * `stm32` (default): the board, brought up at 168 MHz; ADC2 (or, with `adxl375`, an
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
#[cfg(all(feature = "selftest", feature = "adxl375"))]
compile_error!("the self-test plays into the ADC: build `selftest` without `adxl375`");

mod board;
mod executors;
mod fault;
mod logger;
mod queues;
mod reset;
mod source;
mod stack;
mod tasks;

use cortex_m_rt::entry;
use defmt::{info, unwrap};

#[entry]
fn main() -> ! {
    stack::zero_ccmram();
    stack::paint();
    stack::guard();
    // Before anything can fault again: what the previous run kept before it reset the chip.
    let previous = reset::take_previous();
    info!(
        "impact-firmware {} up; blocks of {}, pre-trigger {}, {} captures of {} samples",
        env!("CARGO_PKG_VERSION"),
        queues::BLOCK_LEN,
        queues::PRE_TRIGGER_LEN,
        queues::CAPTURE_SLOTS,
        queues::CAPTURE_LEN
    );
    let setup = board::init(previous);
    let (samples_in, samples_out) = unwrap!(queues::sample_queue());
    let (captures_in, captures_out) = unwrap!(queues::capture_queue());

    // Low priority: the per-impact analysis (widths, kinematics, CFC, fits, spectra), one
    // capture at a time; preempted by everything else.
    let low = board::start_low();
    low.spawn(unwrap!(tasks::analysis::analysis(
        setup.scene,
        captures_out
    )));

    // Middle: the streaming stage (baseline, trigger, capture, exact sums; it feeds the
    // watchdog) and the reporter (defmt lines in index order); preempt the analysis.
    let medium = board::start_medium();
    medium.spawn(unwrap!(tasks::reporter::reporter(
        board::end_of_stream,
        setup.selftest
    )));
    medium.spawn(unwrap!(tasks::stream::stream(
        setup.scene,
        setup.backpressure,
        samples_out,
        captures_in,
        board::feed_watchdog
    )));

    // High: the sample source (and the light gate), which never waits for anything.
    let high = board::start_high();
    board::spawn_sources(setup, high, samples_in);

    loop {
        cortex_m::asm::wfi();
    }
}
