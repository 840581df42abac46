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

/// The 32 KiB below the stack's bottom, guarded too (MPU region 1): a function whose frame
/// is larger than [`GUARD_BYTES`] (the stream's end takes 5.4 KiB) moves the stack pointer
/// past the small guard in one step, and its stores land below it. (On the F407 this is
/// reserved space and the option bytes, which the firmware never reads; the factory's
/// VREFINT calibration at 0x1FFF_7A2A lies below it.)
const BELOW_BYTES: usize = 32 * 1024;

/// Guards the stack's bottom with two MPU regions no access may touch (privileged or not,
/// no execution; the rest of the map stays the default one, PRIVDEFENA): region 0, the
/// stack's lowest [`GUARD_BYTES`] (an overflow by a small frame), and region 1, the
/// [`BELOW_BYTES`] below it (one by a large frame). A stack that grows into either faults
/// while stacking, which locks the core up: the board's watchdog resets it, QEMU stops.
/// Without them an overflow ran below 0x2000_0000, into space the F407 calls reserved, which
/// need not fault. Call after [`paint`] (which leaves the guard alone).
pub fn guard() {
    let bottom = stack_end();
    if bottom % BELOW_BYTES != 0 || bottom < BELOW_BYTES {
        return;
    }
    // RASR: XN (bit 28), AP = 0b000 (bits 26:24: no access), SIZE (bits 5:1: 2^(SIZE+1)
    // bytes), ENABLE. CTRL: PRIVDEFENA (bit 2), ENABLE.
    const fn rasr(size_log2: u32) -> u32 {
        (1 << 28) | ((size_log2 - 1) << 1) | 1
    }
    const CTRL: u32 = (1 << 2) | 1;
    let regions = [
        (bottom, rasr(GUARD_BYTES.trailing_zeros())),
        (bottom - BELOW_BYTES, rasr(BELOW_BYTES.trailing_zeros())),
    ];
    // SAFETY: MPU regions 0 and 1 are only the guard's; they cover no static, no code and no
    // live frame (the stack's bottom, 24 KiB below the first frame, and what lies below).
    unsafe {
        let mpu = &*cortex_m::peripheral::MPU::PTR;
        for (n, (base, rasr)) in regions.into_iter().enumerate() {
            mpu.rnr.write(n as u32);
            mpu.rbar.write(base as u32);
            mpu.rasr.write(rasr);
        }
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
