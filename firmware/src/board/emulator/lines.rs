//! The interrupt lines the emulator uses (the AN386's map).

use cortex_m::interrupt::InterruptNumber;

/// The interrupt lines used (the AN386's map, hw/arm/mps2.c): the two CMSDK timers, and three
/// lines that no device drives (free for the executors, pended by software).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u16)]
pub enum Irq {
    /// CMSDK timer 0: the emulated ADC + DMA ([`super::dma`]), or the emulated ADXL375
    /// ([`super::adxl375`]).
    Timer0 = 8,
    /// CMSDK timer 1: embassy-time's alarms ([`super::time`]).
    Timer1 = 9,
    /// CMSDK dual timer: the logger's drain ([`super::drain`]).
    Drain = 10,
    /// The lowest executor: the analysis.
    Low = 29,
    /// The middle executor: the streaming stage.
    Medium = 30,
    /// The highest executor: the sample source.
    High = 31,
}

// SAFETY: every value is an interrupt line of the AN386's NVIC (0..32).
unsafe impl InterruptNumber for Irq {
    fn number(self) -> u16 {
        self as u16
    }
}
