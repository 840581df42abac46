//! The board's ADC + DMA, emulated for the real-time replay: CMSDK timer 0 interrupts once per
//! block period of virtual time (above every task's priority) and writes the next block of the
//! replayed file into a ring of two blocks, whatever the tasks are doing, as the DMA fills the
//! halves of its ring on the board. The sampler task copies blocks out; if it falls more than
//! the ring behind, the blocks overwritten meanwhile are lost, exactly when the board's DMA
//! ring would overrun.
//!
//! Deadlines are absolute (block `k` at `start + k · period`, in 25 MHz counter ticks), so the
//! pacing does not drift whatever the interrupt latency.

use core::cell::RefCell;
use core::sync::atomic::{AtomicBool, Ordering};

use cortex_m::peripheral::NVIC;
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::signal::Signal;

use super::lines::Irq;
use super::time::{counter, CLOCK_HZ};
use super::timer::CmsdkTimer;
use crate::queues::BLOCK_LEN;
use impact_firmware::semihosting::HostFile;
use impact_firmware::ticks;

/// Blocks in the ring (the board's DMA ring: two halves).
pub const RING_BLOCKS: u32 = 2;

const TIMER: CmsdkTimer = CmsdkTimer::at(0x4000_0000);

struct Dma {
    file: Option<HostFile>,
    ring: [[i16; BLOCK_LEN]; RING_BLOCKS as usize],
    lens: [u16; RING_BLOCKS as usize],
    /// Blocks written so far.
    written: u32,
    /// The file has ended (or failed): no block after `written`.
    ended: bool,
    /// Counter ticks at block 0's deadline, and per block.
    start: u64,
    period: f64,
    /// The timer's shot is a step toward the next deadline, beyond its reach (171.8 s: a
    /// block period of a replay slowed below 1.5 S/s).
    stepping: bool,
}

static DMA: Mutex<CriticalSectionRawMutex, RefCell<Dma>> = Mutex::new(RefCell::new(Dma {
    file: None,
    ring: [[0; BLOCK_LEN]; RING_BLOCKS as usize],
    lens: [0; RING_BLOCKS as usize],
    written: 0,
    ended: false,
    start: 0,
    period: 1.0,
    stepping: false,
}));

/// A block was written (or the file ended).
pub static WRITTEN: Signal<CriticalSectionRawMutex, ()> = Signal::new();

/// The file could not be read.
pub static FAILED: AtomicBool = AtomicBool::new(false);

/// Starts the transfers: one block of `file` every `BLOCK_LEN / rate_hz` seconds of virtual
/// time, the first one period from now.
pub fn start(file: HostFile, rate_hz: f64) {
    let period = BLOCK_LEN as f64 * CLOCK_HZ as f64 / rate_hz;
    critical_section::with(|cs| {
        let mut d = DMA.borrow(cs).borrow_mut();
        d.file = Some(file);
        d.period = period;
        d.start = counter();
        d.written = 0;
        d.ended = false;
        arm(&mut d);
    });
    // SAFETY: the timer's handler is `on_timer`, reached through `irq::DefaultHandler`.
    unsafe { NVIC::unmask(Irq::Timer0) };
}

/// The next block's deadline, counter ticks.
fn deadline(d: &Dma) -> u64 {
    d.start + (f64::from(d.written + 1) * d.period) as u64
}

/// Arms the timer for the next block's deadline (at once if it has passed; a step toward it
/// if it is beyond the timer's reach).
fn arm(d: &mut Dma) {
    let (ticks, reaches) = ticks::shot(deadline(d), counter(), u32::MAX);
    d.stepping = !reaches;
    TIMER.one_shot(ticks);
}

/// The timer's interrupt: the next block arrives (or, after a step toward a deadline beyond
/// the timer's reach, the next shot is armed).
pub fn on_timer() {
    TIMER.clear();
    critical_section::with(|cs| {
        let mut d = DMA.borrow(cs).borrow_mut();
        if d.ended {
            return;
        }
        if d.stepping {
            arm(&mut d);
            return;
        }
        let slot = (d.written % RING_BLOCKS) as usize;
        let mut raw = [0u8; 2 * BLOCK_LEN];
        let read = match d.file.as_mut().map(|f| f.read_full(&mut raw)) {
            Some(Ok(n)) => n,
            _ => {
                FAILED.store(true, Ordering::Relaxed);
                0
            }
        };
        let n = read / 2;
        if n == 0 {
            d.ended = true;
            d.file = None;
        } else {
            if let Some(block) = d.ring.get_mut(slot) {
                for (x, le) in block.iter_mut().zip(raw.chunks_exact(2)) {
                    *x = i16::from_le_bytes([le[0], le[1]]);
                }
            }
            if let Some(len) = d.lens.get_mut(slot) {
                *len = n as u16;
            }
            d.written += 1;
            if n < BLOCK_LEN {
                d.ended = true;
                d.file = None;
            } else {
                arm(&mut d);
            }
        }
    });
    WRITTEN.signal(());
}

/// What the reader finds at block `next`.
pub enum Take {
    /// Nothing new yet.
    Empty,
    /// Blocks `next..next + lost` were overwritten before they were read; the reader goes on
    /// at `next + lost`.
    Overrun { lost: u32 },
    /// The block was handed to `copy` (its samples).
    Block,
    /// The file has ended: no more blocks.
    End,
}

/// Reads block `next` out of the ring into `copy`, if it is there and intact.
pub fn take(next: u32, copy: impl FnOnce(&[i16])) -> Take {
    critical_section::with(|cs| {
        let d = DMA.borrow(cs).borrow();
        if d.written.wrapping_sub(next) > RING_BLOCKS {
            return Take::Overrun {
                lost: d.written - RING_BLOCKS - next,
            };
        }
        if next == d.written {
            return if d.ended { Take::End } else { Take::Empty };
        }
        let slot = (next % RING_BLOCKS) as usize;
        let len = d.lens.get(slot).map_or(0, |&l| usize::from(l));
        if let Some(block) = d.ring.get(slot) {
            copy(block.get(..len).unwrap_or(block));
        }
        Take::Block
    })
}
