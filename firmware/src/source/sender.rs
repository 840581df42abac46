//! The source-independent half of every sample source: numbers the blocks, hands them to the
//! stream task without ever waiting (a live source cannot), and turns every loss into an exact
//! count that travels with the next block (`lost_before`), so the stream's positions stay right.

use core::cell::Cell;
use core::sync::atomic::{AtomicU32, Ordering};

use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::blocking_mutex::Mutex;

use crate::queues::{Block, SampleSender, SourceEvent, StreamEnd, BLOCK_LEN};
use defmt::{info, warn};

/// A u64 shared between priorities (the Cortex-M4 has no 64-bit atomics).
struct SharedU64(Mutex<CriticalSectionRawMutex, Cell<u64>>);

impl SharedU64 {
    const fn new() -> Self {
        Self(Mutex::new(Cell::new(0)))
    }

    fn load(&self) -> u64 {
        self.0.lock(Cell::get)
    }

    fn store(&self, v: u64) {
        self.0.lock(|c| c.set(v));
    }

    fn add(&self, v: u64) {
        self.0.lock(|c| c.set(c.get().saturating_add(v)));
    }
}

/// Loss and error counters of the sample source, read by the reporter.
pub struct SourceStats {
    blocks_sent: AtomicU32,
    blocks_lost: AtomicU32,
    samples_lost: SharedU64,
    overruns: AtomicU32,
    errors: AtomicU32,
}

/// A copy of [`SourceStats`] at one instant.
#[derive(Clone, Copy, defmt::Format)]
pub struct SourceCounts {
    /// Blocks handed to the stream task.
    pub blocks_sent: u32,
    /// Blocks dropped because the sample queue was full (the stream task fell behind).
    pub blocks_lost: u32,
    /// Samples lost in all (full queue, DMA or sensor overruns).
    pub samples_lost: u64,
    /// Overrun events of the source hardware: DMA ring or ADC overruns on the STM32, FIFO
    /// overruns of the ADXL375, the emulated DMA ring in QEMU.
    pub overruns: u32,
    /// Source errors (bus errors, stalls, host file errors).
    pub errors: u32,
}

impl SourceStats {
    const fn new() -> Self {
        Self {
            blocks_sent: AtomicU32::new(0),
            blocks_lost: AtomicU32::new(0),
            samples_lost: SharedU64::new(),
            overruns: AtomicU32::new(0),
            errors: AtomicU32::new(0),
        }
    }

    /// Counts one overrun event of the source hardware.
    pub fn overrun(&self) -> u32 {
        self.overruns.fetch_add(1, Ordering::Relaxed) + 1
    }

    /// Counts one source error.
    pub fn error(&self) -> u32 {
        self.errors.fetch_add(1, Ordering::Relaxed) + 1
    }

    /// The counters now.
    pub fn snapshot(&self) -> SourceCounts {
        SourceCounts {
            blocks_sent: self.blocks_sent.load(Ordering::Relaxed),
            blocks_lost: self.blocks_lost.load(Ordering::Relaxed),
            samples_lost: self.samples_lost.load(),
            overruns: self.overruns.load(Ordering::Relaxed),
            errors: self.errors.load(Ordering::Relaxed),
        }
    }
}

/// The one set of source counters.
pub static SOURCE_STATS: SourceStats = SourceStats::new();

/// When the source's sample 0 was taken and at what rate the samples come, so the reporter
/// can tell how long after an impact its report appears. Only real-time sources set it.
pub struct SampleClock {
    /// embassy-time ticks at sample 0, plus one (0: not running in real time).
    start_ticks: SharedU64,
    /// Samples per second, as f32 bits.
    rate_bits: AtomicU32,
}

impl SampleClock {
    const fn new() -> Self {
        Self {
            start_ticks: SharedU64::new(),
            rate_bits: AtomicU32::new(0),
        }
    }

    /// Sample 0 is taken now; samples come at `rate_hz`.
    pub fn start(&self, rate_hz: f32) {
        self.rate_bits.store(rate_hz.to_bits(), Ordering::Relaxed);
        let now = embassy_time::Instant::now().as_ticks();
        self.start_ticks.store(now + 1);
    }

    /// Seconds from the moment sample `index` was taken to now; `None` unless a real-time
    /// source runs.
    pub fn since_sample_s(&self, index: u64) -> Option<f32> {
        let start = self.start_ticks.load().checked_sub(1)?;
        let rate = f32::from_bits(self.rate_bits.load(Ordering::Relaxed));
        if rate.is_nan() || rate <= 0.0 {
            return None;
        }
        let now = embassy_time::Instant::now().as_ticks();
        let tick = embassy_time::TICK_HZ as f64;
        let taken = start as f64 / tick + index as f64 / rate as f64;
        Some((now as f64 / tick - taken) as f32)
    }
}

/// The one sample clock.
pub static SAMPLE_CLOCK: SampleClock = SampleClock::new();

/// Fills `slot` as block `seq` (in place: the samples are written once, into the queue), with
/// the `lost` samples since the previous block.
fn fill_slot(
    slot: &mut SourceEvent,
    seq: u32,
    lost: u32,
    len: usize,
    fill: impl FnOnce(&mut [i16; BLOCK_LEN]),
) {
    if !matches!(slot, SourceEvent::Block(_)) {
        *slot = SourceEvent::Block(Block::new());
    }
    if let SourceEvent::Block(block) = slot {
        fill(&mut block.samples);
        block.seq = seq;
        block.lost_before = lost;
        block.set_len(len);
    }
}

/// Numbers the blocks of one source and writes them into the sample queue's slots.
pub struct BlockSender {
    queue: SampleSender,
    next_seq: u32,
    /// Samples lost since the queue last accepted a block; they go with the next one.
    lost: u32,
    /// Blocks lost in the current run of losses (logged when it ends).
    losing: u32,
}

impl BlockSender {
    /// A sender into `queue` whose first block gets sequence number 0.
    pub const fn new(queue: SampleSender) -> Self {
        Self {
            queue,
            next_seq: 0,
            lost: 0,
            losing: 0,
        }
    }

    fn take_seq(&mut self) -> u32 {
        let seq = self.next_seq;
        self.next_seq = self.next_seq.wrapping_add(1);
        seq
    }

    /// `n` samples were lost by the source hardware (an overrun): they are announced with the
    /// next block.
    #[cfg_attr(all(feature = "stm32", feature = "adxl375"), allow(dead_code))]
    pub fn lost(&mut self, n: u32) {
        self.lost = self.lost.saturating_add(n);
        SOURCE_STATS.samples_lost.add(u64::from(n));
    }

    /// For real-time sources: queues a block of `len` samples, written by `fill` straight into
    /// the queue's slot, without waiting. If the queue is full the block is lost and counted
    /// (`fill` is not called); the first loss of a run is logged at once, the run's length
    /// when it ends. Returns whether the block was queued.
    pub fn publish(&mut self, len: usize, fill: impl FnOnce(&mut [i16; BLOCK_LEN])) -> bool {
        let seq = self.take_seq();
        let lost = self.lost;
        match self.queue.try_send() {
            Some(slot) => {
                fill_slot(slot, seq, lost, len, fill);
                self.queue.send_done();
                self.lost = 0;
                SOURCE_STATS.blocks_sent.fetch_add(1, Ordering::Relaxed);
                if self.losing > 0 {
                    warn!(
                        "sample queue: {} blocks lost before block {}",
                        self.losing, seq
                    );
                    self.losing = 0;
                }
                true
            }
            None => {
                let total = SOURCE_STATS.blocks_lost.fetch_add(1, Ordering::Relaxed) + 1;
                self.lost(len.min(BLOCK_LEN) as u32);
                if self.losing == 0 {
                    warn!(
                        "sample queue full: block {} lost ({} lost so far)",
                        seq, total
                    );
                }
                self.losing += 1;
                false
            }
        }
    }

    /// For sources that can wait (the lossless file replay): waits for room in the queue,
    /// then fills the block in place, so nothing is lost.
    #[cfg_attr(feature = "stm32", allow(dead_code))]
    pub async fn send(&mut self, len: usize, fill: impl FnOnce(&mut [i16; BLOCK_LEN])) {
        let seq = self.take_seq();
        let lost = core::mem::take(&mut self.lost);
        let slot = self.queue.send().await;
        fill_slot(slot, seq, lost, len, fill);
        self.queue.send_done();
        SOURCE_STATS.blocks_sent.fetch_add(1, Ordering::Relaxed);
    }

    /// Ends a finite stream (the replay's, or a live source that gave up); waits for room so
    /// the end is never lost.
    #[cfg_attr(all(feature = "stm32", not(feature = "adxl375")), allow(dead_code))]
    pub async fn finish(mut self, end: StreamEnd) {
        if self.losing > 0 {
            warn!(
                "sample queue: {} blocks lost at the end of the stream",
                self.losing
            );
        }
        info!(
            "sample source ended ({}) after {} blocks",
            end, self.next_seq
        );
        let lost = core::mem::take(&mut self.lost);
        *self.queue.send().await = SourceEvent::End { end, lost };
        self.queue.send_done();
    }
}
