//! The emulator's stand-in for the probe reading RTT: a timer interrupt (the MPS2's CMSDK
//! dual timer) empties the logger's buffer onto semihosting's standard output every
//! millisecond of emulated time, at most [`BYTES_PER_TICK`] a time, as probe-rs drains the
//! board's RTT buffer (docs/board.md: 130 KB/s). So a burst of lines fills the buffer and
//! drops lines (counted) exactly as it would on the board; the lossless replay waits instead.

use core::ptr::write_volatile;
use core::sync::atomic::{AtomicBool, Ordering};

use cortex_m::peripheral::NVIC;
use cortex_m_semihosting::hio;

use super::lines::Irq;
use crate::logger;

/// The dual timer's first timer (QEMU `cmsdk-apb-dualtimer` at 0x4000_2000, on the 25 MHz
/// system clock).
const BASE: usize = 0x4000_2000;
const LOAD: usize = 0x00;
const CONTROL: usize = 0x08;
const INTCLR: usize = 0x0C;
/// CONTROL: one-shot, 32-bit, interrupt enable, enable (prescale 1, free-running mode).
const ONE_SHOT_32_IRQ_ENABLED: u32 = (1 << 0) | (1 << 1) | (1 << 5) | (1 << 7);
/// One millisecond of the 25 MHz clock.
const TICK: u32 = 25_000;

/// Bytes the link takes a millisecond: what probe-rs reads of a 4 KiB RTT buffer without
/// losing any (130 KB/s).
pub const BYTES_PER_TICK: usize = 130;

/// Whether the whole buffer goes out each tick (the lossless replay: the host's speed, not
/// the board's link, sets the pace).
static UNLIMITED: AtomicBool = AtomicBool::new(false);

fn write(offset: usize, value: u32) {
    // SAFETY: a write to one of the dual timer's registers.
    unsafe { write_volatile((BASE + offset) as *mut u32, value) }
}

fn arm() {
    write(CONTROL, 0);
    write(INTCLR, 1);
    write(LOAD, TICK);
    write(CONTROL, ONE_SHOT_32_IRQ_ENABLED);
}

/// Starts draining; `unlimited` for the lossless replay.
pub fn init(unlimited: bool) {
    UNLIMITED.store(unlimited, Ordering::Relaxed);
    arm();
    // SAFETY: the handler (`on_timer`) is ready; nothing masks this line on purpose.
    unsafe { NVIC::unmask(Irq::Drain) };
}

/// Writes `bytes` to the host's standard output.
fn out(bytes: &[u8]) {
    if let Ok(mut stdout) = hio::hstdout() {
        let _ = stdout.write_all(bytes);
    }
}

/// The dual timer's interrupt: one tick's worth of the buffer to the host.
pub fn on_timer() {
    write(INTCLR, 1);
    let max = if UNLIMITED.load(Ordering::Relaxed) {
        logger::BUFFER_LEN
    } else {
        BYTES_PER_TICK
    };
    logger::take(max, out);
    arm();
}

/// Everything still in the buffer, to the host (before the run ends).
pub fn flush() {
    critical_section::with(|_| {
        write(CONTROL, 0);
        while logger::take(logger::BUFFER_LEN, out) > 0 {}
    });
}
