//! The defmt logger of both builds, one behaviour: every frame is encoded into a staging slot
//! of its own (one per level of preemption) and then copied whole into the RTT up-buffer, so
//! frames from different priorities never interleave and interrupts are masked only for the
//! copy of one finished frame (a few microseconds), never while a line is being formatted. A
//! frame that does not fit the buffer's free room, or its slot, is dropped whole and counted
//! ([`frames_dropped`]; the heartbeat and the summary report it as `lines_dropped`), and each
//! data line carries a sequence number ([`next_seq`]) so that the host sees which are missing.
//!
//! On the board the buffer is a SEGGER RTT up-channel that probe-rs finds in RAM and drains.
//! In the emulator the same buffer is drained by a timer interrupt at the rate a probe reads
//! it ([`take`]); a lossless replay waits for room instead of dropping ([`set_waiting`]).

use core::cell::UnsafeCell;
use core::sync::atomic::{AtomicBool, AtomicU32, AtomicUsize, Ordering};

/// The RTT up-buffer, bytes (one byte of it always stays free).
pub const BUFFER_LEN: usize = 4096;

/// Staging slots of the longest frames: the two outer depths (a low-priority line preempted by
/// a middle one, the reporter's, which prints the longest lines).
const SLOTS: usize = 2;

/// A staging slot, bytes: the longest frame with room. An `srs` line of the most bands the
/// analysis computes (96) is ~1.6 KB: each of its 192 values costs 8 bytes (the `{=f32}`
/// write and the comma's), the fields before them ~60.
const SLOT_LEN: usize = 1664;

/// The innermost slot, bytes: a high-priority line preempting both (the sample source's
/// warnings and notes, a few numbers each; a longer frame there is dropped and counted).
const INNER_SLOT_LEN: usize = 512;

/// RTT mode bits (`flags`): the target never blocks (probe-rs may set blocking mode on
/// attach; this logger drops and counts regardless).
const MODE_NON_BLOCKING_TRIM: u32 = 1;

/// The SEGGER RTT control block with one up-channel, as probe-rs looks for it in RAM.
#[repr(C)]
struct Header {
    id: [u8; 16],
    max_up_channels: u32,
    max_down_channels: u32,
    up: Channel,
}

/// An RTT up-channel.
#[repr(C)]
struct Channel {
    name: *const u8,
    buffer: *mut u8,
    size: u32,
    /// Written by the target.
    write: AtomicU32,
    /// Written by the host (or the emulator's drain).
    read: AtomicU32,
    flags: AtomicU32,
}

// SAFETY: the raw pointers point at statics; the offsets are atomics; the buffer is written
// only inside a critical section and read by one reader (the probe, or the drain interrupt)
// behind the published write offset.
unsafe impl Sync for Header {}

/// The buffer's bytes (any start-up value: the offsets say which are valid).
struct Buffer(UnsafeCell<[u8; BUFFER_LEN]>);

// SAFETY: see `Header`.
unsafe impl Sync for Buffer {}

#[link_section = ".uninit.impact-logger.BUFFER"]
static BUFFER: Buffer = Buffer(UnsafeCell::new([0; BUFFER_LEN]));

static NAME: [u8; 6] = *b"defmt\0";

#[no_mangle]
static _SEGGER_RTT: Header = Header {
    id: *b"SEGGER RTT\0\0\0\0\0\0",
    max_up_channels: 1,
    max_down_channels: 0,
    up: Channel {
        name: NAME.as_ptr(),
        buffer: BUFFER.0.get() as *mut u8,
        size: BUFFER_LEN as u32,
        write: AtomicU32::new(0),
        read: AtomicU32::new(0),
        flags: AtomicU32::new(MODE_NON_BLOCKING_TRIM),
    },
};

/// One frame being encoded (`B`: its bytes, `[u8; N]` in a static, `[u8]` in use).
struct Slot<B: ?Sized = [u8]> {
    encoder: defmt::Encoder,
    len: usize,
    /// The frame outgrew the slot: it will be dropped.
    overflow: bool,
    bytes: B,
}

impl<const N: usize> Slot<[u8; N]> {
    const fn new() -> Self {
        Self {
            encoder: defmt::Encoder::new(),
            len: 0,
            overflow: false,
            bytes: [0; N],
        }
    }
}

struct Slots(
    [UnsafeCell<Slot<[u8; SLOT_LEN]>>; SLOTS],
    UnsafeCell<Slot<[u8; INNER_SLOT_LEN]>>,
);

// SAFETY: slot `k` is used only by the context at preemption depth `k` (see `Logger`).
unsafe impl Sync for Slots {}

static STAGING: Slots = Slots(
    [const { UnsafeCell::new(Slot::new()) }; SLOTS],
    UnsafeCell::new(Slot::new()),
);

/// Frames under way: acquire takes the slot at this depth, release gives it back. Contexts
/// nest strictly (an interrupt returns before the code it preempted goes on), so the slot of
/// the running context is always the deepest one.
static DEPTH: AtomicUsize = AtomicUsize::new(0);

static DROPPED: AtomicU32 = AtomicU32::new(0);
static SEQ: AtomicU32 = AtomicU32::new(0);
static WAITING: AtomicBool = AtomicBool::new(false);

/// Frames dropped so far (the buffer full, a frame longer than its slot, or nested deeper
/// than the slots).
pub fn frames_dropped() -> u32 {
    DROPPED.load(Ordering::Relaxed)
}

/// Whether the reader (the probe, or the emulator's drain) has taken every byte written.
#[cfg_attr(not(feature = "stm32"), allow(dead_code))]
pub fn drained() -> bool {
    let ch = &_SEGGER_RTT.up;
    ch.read.load(Ordering::Acquire) == ch.write.load(Ordering::Relaxed)
}

/// The next data line's sequence number (from 0, one per `impact`, `srs`, `heartbeat`,
/// `summary`, `scene`, `wave` and `wave_frame` line).
pub fn next_seq() -> u32 {
    SEQ.fetch_add(1, Ordering::Relaxed)
}

/// A full buffer makes the writer wait for room instead of dropping the frame (the
/// emulator's lossless replay, whose drain always runs; never on the board).
#[cfg_attr(not(feature = "emulator"), allow(dead_code))]
pub fn set_waiting(wait: bool) {
    WAITING.store(wait, Ordering::Relaxed);
}

fn slot(depth: usize) -> Option<&'static mut Slot> {
    // SAFETY: only the context at `depth` uses this slot while it holds it (see `DEPTH`).
    match STAGING.0.get(depth) {
        Some(s) => Some(unsafe { &mut *s.get() }),
        None if depth == SLOTS => Some(unsafe { &mut *STAGING.1.get() }),
        None => None,
    }
}

/// Copies a finished frame into the buffer, whole, or drops it (counted); with
/// [`set_waiting`], waits for room.
fn commit(frame: &[u8]) {
    let size = BUFFER_LEN;
    if frame.len() >= size {
        DROPPED.fetch_add(1, Ordering::Relaxed);
        return;
    }
    loop {
        let done = critical_section::with(|_| {
            let ch = &_SEGGER_RTT.up;
            let write = ch.write.load(Ordering::Relaxed) as usize % size;
            let read = ch.read.load(Ordering::Relaxed) as usize % size;
            let free = (read + size - write - 1) % size;
            if frame.len() > free {
                return false;
            }
            let first = frame.len().min(size - write);
            let base = BUFFER.0.get() as *mut u8;
            // SAFETY: `write..write + first` and `0..frame.len() - first` lie in the buffer
            // and in its free part (checked above); nothing else writes it (critical section).
            unsafe {
                core::ptr::copy_nonoverlapping(frame.as_ptr(), base.add(write), first);
                core::ptr::copy_nonoverlapping(
                    frame.as_ptr().add(first),
                    base,
                    frame.len() - first,
                );
            }
            ch.write
                .store(((write + frame.len()) % size) as u32, Ordering::Release);
            true
        });
        if done {
            return;
        }
        if !WAITING.load(Ordering::Relaxed) {
            DROPPED.fetch_add(1, Ordering::Relaxed);
            return;
        }
        core::hint::spin_loop();
    }
}

/// The emulator's drain: hands `f` up to `max` bytes from the buffer (at most two pieces, at
/// its wrap) and frees them. The one reader of the buffer.
#[cfg_attr(not(feature = "emulator"), allow(dead_code))]
pub fn take(max: usize, mut f: impl FnMut(&[u8])) -> usize {
    let size = BUFFER_LEN;
    let ch = &_SEGGER_RTT.up;
    let read = ch.read.load(Ordering::Relaxed) as usize % size;
    let write = ch.write.load(Ordering::Acquire) as usize % size;
    let available = (write + size - read) % size;
    let n = available.min(max);
    let first = n.min(size - read);
    let base = BUFFER.0.get() as *const u8;
    // SAFETY: `read..read + first` and `0..n - first` hold published frames (behind the
    // write offset) that no writer touches until `read` moves past them.
    unsafe {
        if first > 0 {
            f(core::slice::from_raw_parts(base.add(read), first));
        }
        if n > first {
            f(core::slice::from_raw_parts(base, n - first));
        }
    }
    ch.read.store(((read + n) % size) as u32, Ordering::Release);
    n
}

#[defmt::global_logger]
struct Logger;

// SAFETY: acquire/release pair up per context and nest strictly (see `DEPTH`); `write` only
// runs between them in the same context.
unsafe impl defmt::Logger for Logger {
    fn acquire() {
        let depth = DEPTH.fetch_add(1, Ordering::Acquire);
        if let Some(s) = slot(depth) {
            let Slot {
                encoder,
                len,
                overflow,
                bytes,
            } = s;
            *len = 0;
            *overflow = false;
            encoder.start_frame(|b| push(bytes, len, overflow, b));
        }
    }

    unsafe fn flush() {}

    unsafe fn release() {
        let depth = DEPTH.load(Ordering::Relaxed).saturating_sub(1);
        match slot(depth) {
            Some(s) => {
                let Slot {
                    encoder,
                    len,
                    overflow,
                    bytes,
                } = s;
                encoder.end_frame(|b| push(bytes, len, overflow, b));
                if *overflow {
                    DROPPED.fetch_add(1, Ordering::Relaxed);
                } else if let Some(frame) = bytes.get(..*len) {
                    commit(frame);
                }
            }
            None => {
                DROPPED.fetch_add(1, Ordering::Relaxed);
            }
        }
        DEPTH.fetch_sub(1, Ordering::Release);
    }

    unsafe fn write(data: &[u8]) {
        let depth = DEPTH.load(Ordering::Relaxed).saturating_sub(1);
        if let Some(s) = slot(depth) {
            let Slot {
                encoder,
                len,
                overflow,
                bytes,
            } = s;
            encoder.write(data, |b| push(bytes, len, overflow, b));
        }
    }
}

/// Appends `b` to a slot's frame (its fields apart: the encoder borrows the slot meanwhile);
/// a frame that outgrows the slot is marked for dropping.
fn push(bytes: &mut [u8], len: &mut usize, overflow: &mut bool, b: &[u8]) {
    let end = *len + b.len();
    match bytes.get_mut(*len..end) {
        Some(room) => {
            room.copy_from_slice(b);
            *len = end;
        }
        None => *overflow = true,
    }
}
