//! Tasks shared by the `stm32` and `emulator` builds, and the bounded channels joining them.
//!
//! ```text
//! sample source ──blocks (zero-copy)──> monitor ──REPORTS──> reporter ──> defmt log
//! (ADC+DMA, ADXL375 or host-file replay)                    (and, in QEMU, the exit status)
//! ```
//!
//! Only the sample source (see [`crate::source`]), the clocks and the embassy-time driver
//! differ between the builds; everything in this module runs unchanged on both.

pub mod monitor;
pub mod reporter;
pub mod sampler;

use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::channel::Channel;
use embassy_sync::zerocopy_channel;
use static_cell::StaticCell;

/// Samples per block: one DMA half-buffer on the STM32, one file read in the emulator.
pub const BLOCK_LEN: usize = 256;

/// Blocks the sample queue holds before the source starts losing (counting) them:
/// 8 x 256 samples = 4.1 ms of signal at 500 kS/s.
pub const SAMPLE_QUEUE_BLOCKS: usize = 8;

/// Reports the reporter's queue holds. The monitor waits for room for impact reports and the
/// summary; heartbeats that find it full are dropped (and counted).
pub const REPORT_QUEUE_LEN: usize = 4;

/// One block of samples, in the order the source produced them.
pub struct Block {
    /// Sequence number given by the source, from 0; a gap means blocks were lost.
    pub seq: u32,
    len: u16,
    samples: [i16; BLOCK_LEN],
}

impl Block {
    /// Builds a block from `samples[..len]`; `len` is clamped to [`BLOCK_LEN`].
    pub fn new(seq: u32, samples: [i16; BLOCK_LEN], len: usize) -> Self {
        let len = len.min(BLOCK_LEN) as u16;
        Self { seq, len, samples }
    }

    /// Sets the number of valid samples, clamped to [`BLOCK_LEN`].
    pub fn set_len(&mut self, len: usize) {
        self.len = len.min(BLOCK_LEN) as u16;
    }

    /// The valid samples (a source's last block may be short).
    pub fn samples(&self) -> &[i16] {
        // `len` is clamped in `new`; `get` keeps this path free of panics regardless.
        self.samples
            .get(..usize::from(self.len))
            .unwrap_or(&self.samples)
    }
}

/// How a finite sample stream ended (the live sources never end).
#[derive(Clone, Copy, PartialEq, Eq, defmt::Format)]
pub enum StreamEnd {
    /// All samples were delivered.
    Complete,
    /// The source failed; the reason has been logged.
    // The live ADC source never ends; the replay and the ADXL375 source can fail.
    #[cfg_attr(all(feature = "stm32", not(feature = "adxl375")), allow(dead_code))]
    Failed,
}

/// What a sample source sends to the monitor.
// Every queue slot has to hold a block anyway (no heap to box it into); `End` comes once.
#[allow(clippy::large_enum_variant)]
pub enum SourceEvent {
    /// The next block of samples.
    Block(Block),
    /// No more samples will come.
    #[cfg_attr(all(feature = "stm32", not(feature = "adxl375")), allow(dead_code))]
    End(StreamEnd),
}

/// The source's end of the sample queue: it fills the queue's own slots in place.
pub type SampleSender = zerocopy_channel::Sender<'static, CriticalSectionRawMutex, SourceEvent>;
/// The monitor's end of the sample queue: it reads the slots in place.
pub type SampleReceiver = zerocopy_channel::Receiver<'static, CriticalSectionRawMutex, SourceEvent>;

/// The sample queue, [`SAMPLE_QUEUE_BLOCKS`] blocks deep. A zero-copy channel: the source
/// writes each block into a slot of the queue and the monitor reads it there, where an
/// ordinary channel would move every 512-byte block by value several times (about 34
/// instructions per sample on the Cortex-M4, measured by `impact bench m4`). `None` if
/// called twice.
pub fn sample_queue() -> Option<(SampleSender, SampleReceiver)> {
    static SLOTS: StaticCell<[SourceEvent; SAMPLE_QUEUE_BLOCKS]> = StaticCell::new();
    static QUEUE: StaticCell<
        zerocopy_channel::Channel<'static, CriticalSectionRawMutex, SourceEvent>,
    > = StaticCell::new();
    let slots =
        SLOTS.try_init_with(|| core::array::from_fn(|_| SourceEvent::End(StreamEnd::Complete)))?;
    let queue = QUEUE.try_init(zerocopy_channel::Channel::new(slots))?;
    Some(queue.split())
}

/// Monitor -> reporter.
pub static REPORTS: Channel<CriticalSectionRawMutex, reporter::Report, REPORT_QUEUE_LEN> =
    Channel::new();
