//! The ADXL375, emulated for the real-time replay: CMSDK timer 0 interrupts once per sample
//! period of virtual time and pushes the file's next three-axis sample into a FIFO of the
//! part's depth in stream mode (32 entries and the output registers: 33), setting the overrun
//! flag when its 32 levels fill and overwriting the oldest entry when all 33 are taken,
//! whatever the tasks are doing.
//! The board's ADXL375 source ([`crate::source::poll`]) polls it as it polls the part, so a
//! sample is lost exactly when the part's FIFO would overwrite it; the emulation also counts
//! what it overwrote, which the firmware's own estimate can be held to.
//!
//! The file holds little-endian i16 triplets (x, y, z counts). Deadlines are absolute
//! (sample `k` at `start + k · period`, in 25 MHz counter ticks).

use core::cell::RefCell;
use core::sync::atomic::{AtomicBool, Ordering};

use cortex_m::peripheral::NVIC;
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::blocking_mutex::Mutex;
use embassy_time::Instant;

use super::lines::Irq;
use super::time::{counter, CLOCK_HZ};
use super::timer::CmsdkTimer;
use crate::source::poll::{Fifo, Poll, Read, MAX_ENTRIES};
use impact_firmware::adxl375::Axes;
use impact_firmware::semihosting::{HostError, HostFile};
use impact_firmware::ticks;

const TIMER: CmsdkTimer = CmsdkTimer::at(0x4000_0000);

/// Samples read from the host file at a time.
const CHUNK: usize = 64;

struct Sensor {
    file: Option<HostFile>,
    /// Read ahead from the file.
    chunk: [Axes; CHUNK],
    chunk_len: usize,
    chunk_next: usize,
    /// The FIFO: `len` entries from `head` on (a ring).
    fifo: [Axes; MAX_ENTRIES],
    head: usize,
    len: usize,
    overrun: bool,
    /// Samples produced, and overwritten before they were read.
    produced: u64,
    overwritten: u64,
    /// The file has ended: no sample after `produced`.
    ended: bool,
    /// Counter ticks at sample 0's deadline, and per sample.
    start: u64,
    period: f64,
    /// The timer's shot is a step toward the next deadline, beyond its reach (171.8 s).
    stepping: bool,
}

static SENSOR: Mutex<CriticalSectionRawMutex, RefCell<Sensor>> = Mutex::new(RefCell::new(Sensor {
    file: None,
    chunk: [[0; 3]; CHUNK],
    chunk_len: 0,
    chunk_next: 0,
    fifo: [[0; 3]; MAX_ENTRIES],
    head: 0,
    len: 0,
    overrun: false,
    produced: 0,
    overwritten: 0,
    ended: false,
    start: 0,
    period: 1.0,
    stepping: false,
}));

/// Timer 0 drives the emulated ADXL375 instead of the emulated DMA.
static ACTIVE: AtomicBool = AtomicBool::new(false);

/// Whether timer 0's interrupt is this sensor's.
pub fn active() -> bool {
    ACTIVE.load(Ordering::Relaxed)
}

/// The file could not be read.
static FAILED: AtomicBool = AtomicBool::new(false);

/// Whether the host file failed.
pub fn failed() -> bool {
    FAILED.load(Ordering::Relaxed)
}

/// The FIFO's levels (the output registers hold one entry more: [`MAX_ENTRIES`]).
const FIFO_LEVELS: usize = 32;

/// Samples the emulated part produced and overwrote unread so far.
pub fn counts() -> (u64, u64) {
    critical_section::with(|cs| {
        let s = SENSOR.borrow(cs).borrow();
        (s.produced, s.overwritten)
    })
}

/// Starts measuring: one sample of `file` every `1 / rate_hz` seconds of virtual time, the
/// first one period from now.
pub fn start(file: HostFile, rate_hz: f64) {
    ACTIVE.store(true, Ordering::Relaxed);
    critical_section::with(|cs| {
        let mut s = SENSOR.borrow(cs).borrow_mut();
        s.file = Some(file);
        s.period = CLOCK_HZ as f64 / rate_hz;
        s.start = counter();
        arm(&mut s);
    });
    // SAFETY: the timer's handler is `on_timer`, reached through `irq::DefaultHandler`.
    unsafe { NVIC::unmask(Irq::Timer0) };
}

/// The next sample's deadline, counter ticks.
fn deadline(s: &Sensor) -> u64 {
    s.start + ((s.produced + 1) as f64 * s.period) as u64
}

/// Arms the timer for the next sample's deadline (at once if it has passed; a step toward
/// it if it is beyond the timer's reach).
fn arm(s: &mut Sensor) {
    let (ticks, reaches) = ticks::shot(deadline(s), counter(), u32::MAX);
    s.stepping = !reaches;
    TIMER.one_shot(ticks);
}

/// Refills the read-ahead from the file; false at its end (or on an error).
fn refill(s: &mut Sensor) -> bool {
    let mut raw = [0u8; 6 * CHUNK];
    let read = match s.file.as_mut().map(|f| f.read_full(&mut raw)) {
        Some(Ok(n)) => n,
        Some(Err(_)) | None => {
            FAILED.store(true, Ordering::Relaxed);
            0
        }
    };
    let n = read / 6;
    for (slot, le) in s.chunk.iter_mut().zip(raw.chunks_exact(6)) {
        *slot = [
            i16::from_le_bytes([le[0], le[1]]),
            i16::from_le_bytes([le[2], le[3]]),
            i16::from_le_bytes([le[4], le[5]]),
        ];
    }
    s.chunk_len = n;
    s.chunk_next = 0;
    n > 0
}

/// The timer's interrupt: the part produces its next sample (or, after a step toward a
/// deadline beyond the timer's reach, the next shot is armed).
pub fn on_timer() {
    TIMER.clear();
    critical_section::with(|cs| {
        let mut s = SENSOR.borrow(cs).borrow_mut();
        if s.ended {
            return;
        }
        if s.stepping {
            arm(&mut s);
            return;
        }
        if s.chunk_next == s.chunk_len && !refill(&mut s) {
            s.ended = true;
            s.file = None;
            return;
        }
        let sample = s.chunk.get(s.chunk_next).copied().unwrap_or_default();
        s.chunk_next += 1;
        if s.len == MAX_ENTRIES {
            // Stream mode: the oldest entry goes.
            s.head = (s.head + 1) % MAX_ENTRIES;
            s.len -= 1;
            s.overwritten += 1;
        }
        let tail = (s.head + s.len) % MAX_ENTRIES;
        if let Some(slot) = s.fifo.get_mut(tail) {
            *slot = sample;
        }
        s.len += 1;
        s.produced += 1;
        // The data sheet's stream mode: the flag is set when the FIFO fills (its 32 levels;
        // the output registers hold one more), whether or not an entry was overwritten.
        if s.len >= FIFO_LEVELS {
            s.overrun = true;
        }
        arm(&mut s);
    });
}

/// The emulated part, as the poll loop reads it. `stall` (a test's fault injection): before
/// poll `.0`, busy-wait `.1` µs, as a board whose sampler was held up would.
pub struct EmulatedAdxl375 {
    pub stall: Option<(u32, u32)>,
    pub polls: u32,
}

impl Fifo for EmulatedAdxl375 {
    type Error = HostError;

    async fn read(&mut self, out: &mut [Axes; MAX_ENTRIES]) -> Result<Read, Poll<Self::Error>> {
        if let Some((poll, us)) = self.stall {
            if poll == self.polls {
                self.stall = None;
                super::stall_sampler(us);
            }
        }
        self.polls += 1;
        let at = Instant::now();
        critical_section::with(|cs| {
            let mut s = SENSOR.borrow(cs).borrow_mut();
            if s.ended && s.len == 0 {
                return Err(Poll::End);
            }
            let n = s.len;
            for (k, slot) in out.iter_mut().take(n).enumerate() {
                *slot = s
                    .fifo
                    .get((s.head + k) % MAX_ENTRIES)
                    .copied()
                    .unwrap_or_default();
            }
            s.head = (s.head + n) % MAX_ENTRIES;
            s.len = 0;
            let overrun = core::mem::take(&mut s.overrun);
            Ok(Read {
                at,
                samples: n,
                overrun,
            })
        })
    }
}
