//! The source-independent half of every sampler: hands blocks to the monitor and counts
//! what was lost on the way (full queue, DMA or sensor overruns, source errors).

use core::sync::atomic::{AtomicU32, Ordering};

use super::{Block, SampleSender, SourceEvent, StreamEnd, BLOCK_LEN};
use defmt::{info, warn};

/// Loss and error counters of the sample source, read by the reporter.
pub struct SourceStats {
    blocks_sent: AtomicU32,
    blocks_lost: AtomicU32,
    overruns: AtomicU32,
    errors: AtomicU32,
}

/// A copy of [`SourceStats`] at one instant.
#[derive(Clone, Copy, defmt::Format)]
pub struct SourceCounts {
    /// Blocks handed to the monitor.
    pub blocks_sent: u32,
    /// Blocks dropped because the sample queue was full (the monitor fell behind).
    pub blocks_lost: u32,
    /// Samples overwritten before they were read: DMA ring-buffer or ADC overruns on the
    /// STM32, FIFO overruns of the ADXL375. Counted per event, not per sample.
    pub overruns: u32,
    /// Source errors (bus errors, stalls, host file errors).
    pub errors: u32,
}

impl SourceStats {
    const fn new() -> Self {
        Self {
            blocks_sent: AtomicU32::new(0),
            blocks_lost: AtomicU32::new(0),
            overruns: AtomicU32::new(0),
            errors: AtomicU32::new(0),
        }
    }

    /// Counts one overrun event of the source hardware (the replay has none).
    #[cfg_attr(not(feature = "stm32"), allow(dead_code))]
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
            overruns: self.overruns.load(Ordering::Relaxed),
            errors: self.errors.load(Ordering::Relaxed),
        }
    }
}

/// The one set of source counters.
pub static SOURCE_STATS: SourceStats = SourceStats::new();

/// Numbers the blocks of one source and writes them into the sample queue's slots.
pub struct BlockSender {
    queue: SampleSender,
    next_seq: u32,
    /// Blocks lost since the queue last accepted one; logged when it does again.
    losing: u32,
}

/// Fills `slot` as the next block (in place: the samples are written once, into the queue).
fn fill_slot(slot: &mut SourceEvent, seq: u32, fill: impl FnOnce(&mut [i16; BLOCK_LEN]) -> usize) {
    if !matches!(slot, SourceEvent::Block(_)) {
        *slot = SourceEvent::Block(Block::new(seq, [0; BLOCK_LEN], 0));
    }
    if let SourceEvent::Block(block) = slot {
        let len = fill(&mut block.samples);
        block.seq = seq;
        block.set_len(len);
    }
}

impl BlockSender {
    /// A sender into `queue` whose first block gets sequence number 0.
    pub const fn new(queue: SampleSender) -> Self {
        Self {
            queue,
            next_seq: 0,
            losing: 0,
        }
    }

    fn take_seq(&mut self) -> u32 {
        let seq = self.next_seq;
        self.next_seq = self.next_seq.wrapping_add(1);
        seq
    }

    /// For real-time sources: fills a block with `fill` (which returns how many samples it
    /// wrote) and queues it without waiting. If the queue is full the block is dropped and
    /// counted (`fill` is not called); the first loss of a run is logged at once, the run's
    /// length when it ends. Returns whether the block was queued.
    pub fn publish(&mut self, fill: impl FnOnce(&mut [i16; BLOCK_LEN]) -> usize) -> bool {
        let seq = self.take_seq();
        match self.queue.try_send() {
            Some(slot) => {
                fill_slot(slot, seq, fill);
                self.queue.send_done();
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

    /// For sources that can wait (file replay): waits for room in the queue, then fills the
    /// block in place, so nothing is lost.
    #[cfg_attr(feature = "stm32", allow(dead_code))]
    pub async fn send(&mut self, fill: impl FnOnce(&mut [i16; BLOCK_LEN]) -> usize) {
        let seq = self.take_seq();
        let slot = self.queue.send().await;
        fill_slot(slot, seq, fill);
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
        *self.queue.send().await = SourceEvent::End(end);
        self.queue.send_done();
    }
}
