//! The emulator's interrupt priorities, the three executors on their lines, and the dispatch
//! of every external interrupt (QEMU `mps2-an386`, 32 external lines, 8 priority bits). There is no PAC for the MPS2, so every external interrupt goes
//! through cortex-m-rt's `DefaultHandler`, which dispatches on the interrupt number.

use cortex_m::interrupt::InterruptNumber;
use cortex_m::peripheral::NVIC;
use cortex_m_rt::exception;
use embassy_executor::{InterruptExecutor, SendSpawner};

use super::lines::Irq;
use crate::executors::{HIGH, LOW, MEDIUM};

/// NVIC priorities (lower is more urgent; multiples of 0x20 so they behave as on a 3-bit
/// part): the device interrupts (the DMA's timer, the time driver) above everything, then the
/// executors.
const DEVICE_PRIORITY: u8 = 0x00;
const HIGH_PRIORITY: u8 = 0x20;
const MEDIUM_PRIORITY: u8 = 0x40;
const LOW_PRIORITY: u8 = 0x60;

/// Sets the device interrupts' priorities (before any of them is unmasked).
pub fn init() {
    // SAFETY: priorities are set once, before the interrupts they concern are unmasked.
    let mut nvic = unsafe { cortex_m::Peripherals::steal() }.NVIC;
    unsafe {
        nvic.set_priority(Irq::Timer0, DEVICE_PRIORITY);
        nvic.set_priority(Irq::Timer1, DEVICE_PRIORITY);
        nvic.set_priority(Irq::Drain, DEVICE_PRIORITY);
    }
}

/// Starts an executor on `line` at `priority`.
fn start(executor: &'static InterruptExecutor, line: Irq, priority: u8) -> SendSpawner {
    // SAFETY: each line's priority is set once, before its executor starts.
    let mut nvic = unsafe { cortex_m::Peripherals::steal() }.NVIC;
    unsafe { nvic.set_priority(line, priority) };
    executor.start(line)
}

/// Starts the high executor (the sample source).
pub fn start_high() -> SendSpawner {
    start(&HIGH, Irq::High, HIGH_PRIORITY)
}

/// Starts the middle executor (the stream and the reporter).
pub fn start_medium() -> SendSpawner {
    start(&MEDIUM, Irq::Medium, MEDIUM_PRIORITY)
}

/// Starts the low executor (the analysis).
pub fn start_low() -> SendSpawner {
    start(&LOW, Irq::Low, LOW_PRIORITY)
}

/// Every external interrupt.
#[exception]
unsafe fn DefaultHandler(irqn: i16) {
    match irqn {
        8 if super::adxl375::active() => super::adxl375::on_timer(),
        8 => super::dma::on_timer(),
        9 => super::time::on_alarm(),
        10 => super::drain::on_timer(),
        // SAFETY: each executor's interrupt calls its `on_interrupt` and nothing else does.
        29 => unsafe { LOW.on_interrupt() },
        30 => unsafe { MEDIUM.on_interrupt() },
        31 => unsafe { HIGH.on_interrupt() },
        // An interrupt nobody unmasked: mask it so it cannot come back.
        n if n >= 0 => NVIC::mask(Raw(n as u16)),
        // A system exception without a handler (cortex-m-rt routes them here too).
        _ => {}
    }
}

/// Any line, to mask it.
#[derive(Clone, Copy)]
struct Raw(u16);

// SAFETY: only used with the number the NVIC reported as active.
unsafe impl InterruptNumber for Raw {
    fn number(self) -> u16 {
        self.0
    }
}
