//! The RAM start-up leaves to the firmware, on both builds: the CCM section zeroed
//! ([`zero_ccmram`]), the stack's bottom guarded ([`guard`]: an MPU region no access may
//! touch, so an overflow faults on any part, whatever lies below SRAM), and the stack's
//! high-water mark: the stack region below the current frame and above the guard is painted
//! at start-up, and [`peak_bytes`] finds how deep the stack has gone since (interrupts
//! included: they share the main stack). The heartbeat and the summary report it, so every
//! run shows its margin (see docs/board.md for the RAM budget).

use core::sync::atomic::{AtomicUsize, Ordering};

/// The paint.
const PAINT: u32 = 0x5354_4b21;
/// Left alone below the current stack pointer when painting: the live frames.
const MARGIN: usize = 256;
/// The guard at the stack's bottom, bytes: the MPU's smallest region.
pub const GUARD_BYTES: usize = 32;

static BOTTOM: AtomicUsize = AtomicUsize::new(0);
static TOP: AtomicUsize = AtomicUsize::new(0);

extern "C" {
    /// Initial stack pointer: the top of the stack region (board-memory.x).
    static _stack_start: u32;
    /// Lowest address the stack may reach: the bottom of the stack region (board-memory.x).
    static _stack_end: u32;
    /// Start and end of the `.ccmram` section (board-memory.x).
    static mut __sccmram: u32;
    static mut __eccmram: u32;
}

/// Zeroes the `.ccmram` section, which cortex-m-rt neither loads nor zeroes (the statics
/// there start as the zeros they are declared with). Call once, first thing.
pub fn zero_ccmram() {
    // SAFETY: first thing after reset, before anything in `.ccmram` is used: the section is
    // word-aligned and nothing else touches it yet.
    unsafe {
        let start = core::ptr::addr_of_mut!(__sccmram);
        let end = core::ptr::addr_of_mut!(__eccmram);
        let words = (end as usize).saturating_sub(start as usize) / 4;
        core::ptr::write_bytes(start, 0, words);
    }
}

fn stack_start() -> usize {
    // Only the symbol's address is taken, never its contents.
    core::ptr::addr_of!(_stack_start) as usize
}

/// The stack's lowest address (the guard's start).
fn stack_end() -> usize {
    // Only the symbol's address is taken, never its contents.
    core::ptr::addr_of!(_stack_end) as usize
}

/// Guards the stack's bottom [`GUARD_BYTES`] with MPU region 0: no access, privileged or
/// not, and no execution (the rest of the map stays the default one, PRIVDEFENA). A stack
/// that grows into it faults while stacking, which locks the core up: the board's watchdog
/// resets it, QEMU stops. Without it an overflow ran below 0x2000_0000, into space the F407
/// calls reserved, which need not fault. Call after [`paint`] (which leaves the guard alone).
pub fn guard() {
    let bottom = stack_end();
    if bottom % GUARD_BYTES != 0 {
        return;
    }
    // RASR: XN (bit 28), AP = 0b000 (bits 26:24: no access), SIZE = 4 (2^(4+1) = 32 bytes),
    // ENABLE. CTRL: PRIVDEFENA (bit 2), ENABLE.
    const RASR: u32 = (1 << 28) | (4 << 1) | 1;
    const CTRL: u32 = (1 << 2) | 1;
    // SAFETY: MPU region 0 is only this guard's; the region covers no static, no code and no
    // live frame (the stack's bottom, 24 KiB below the first frame).
    unsafe {
        let mpu = &*cortex_m::peripheral::MPU::PTR;
        mpu.rnr.write(0);
        mpu.rbar.write(bottom as u32);
        mpu.rasr.write(RASR);
        mpu.ctrl.write(CTRL);
    }
    cortex_m::asm::dsb();
    cortex_m::asm::isb();
}

/// Paints the free stack below the caller's frame and above the guard. Call once, first
/// thing.
pub fn paint() {
    let sp = cortex_m::register::msp::read() as usize;
    let top = sp.saturating_sub(MARGIN) & !3;
    let bottom = (stack_end() + GUARD_BYTES + 3) & !3;
    if bottom >= top {
        return;
    }
    for addr in (bottom..top).step_by(4) {
        // SAFETY: the words between the end of the statics and the live frames are the free
        // stack: nothing holds data there yet.
        unsafe { core::ptr::write_volatile(addr as *mut u32, PAINT) };
    }
    BOTTOM.store(bottom, Ordering::Relaxed);
    TOP.store(top, Ordering::Relaxed);
}

/// Deepest stack use since [`paint`], in bytes from the initial stack pointer, and whether the
/// stack reached its bottom (every painted word overwritten); `None` if nothing was painted.
/// Reads the painted words from the bottom up to the first one overwritten: at most the
/// stack's size (24 KiB, some 6 000 loads), less as the peak grows.
pub fn peak_bytes() -> Option<(usize, bool)> {
    let (bottom, top) = (BOTTOM.load(Ordering::Relaxed), TOP.load(Ordering::Relaxed));
    if bottom >= top {
        return None;
    }
    let mut addr = bottom;
    // SAFETY: reads of painted words, which are RAM (see `paint`).
    while addr < top && unsafe { core::ptr::read_volatile(addr as *const u32) } == PAINT {
        addr += 4;
    }
    Some((stack_start().saturating_sub(addr), addr == bottom))
}

/// Stack size available beside the statics, bytes (the guard's left out).
pub fn size_bytes() -> usize {
    stack_start().saturating_sub(stack_end() + GUARD_BYTES)
}

/// The guard's address: a test's injected fault writes there (the emulator's `fault=guard`).
#[cfg_attr(not(feature = "emulator"), allow(dead_code))]
pub fn guard_address() -> usize {
    stack_end()
}
