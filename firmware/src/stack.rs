//! The RAM start-up leaves to the firmware, on both builds: the CCM section zeroed
//! ([`zero_ccmram`]), and the stack's high-water mark: the stack region below the current
//! frame is painted at start-up, and [`peak_bytes`] finds how deep the stack has gone since
//! (interrupts included: they share the main stack). The heartbeat and the summary report it,
//! so every run shows its margin (see docs/board.md for the RAM budget).

use core::sync::atomic::{AtomicUsize, Ordering};

/// The paint.
const PAINT: u32 = 0x5354_4b21;
/// Left alone below the current stack pointer when painting: the live frames.
const MARGIN: usize = 256;

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

/// Paints the free stack below the caller's frame. Call once, first thing.
pub fn paint() {
    let sp = cortex_m::register::msp::read() as usize;
    let top = sp.saturating_sub(MARGIN) & !3;
    let bottom = (core::ptr::addr_of!(_stack_end) as usize + 3) & !3;
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

/// Stack size available beside the statics, bytes.
pub fn size_bytes() -> usize {
    stack_start().saturating_sub(core::ptr::addr_of!(_stack_end) as usize)
}
