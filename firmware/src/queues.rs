//! The queues joining the tasks of both builds (`stm32`, `emulator`), their sizes and what
//! travels on them; the tasks run at three priorities (see `docs/board.md`, "Priorities").
//!
//! ```text
//!  high    sample source ──blocks (zero-copy, 8 deep)──► stream: baseline, trigger,   medium
//!                                                        capture, exact sums
//!                                         skipped impacts, heartbeats │   │ captures (zero-copy,
//!                                                                     ▼   ▼ 2 slots)
//!  medium  defmt log ◄── reporter ◄──────── analysed impacts ── analysis: widths,      low
//!                        (index order)                          kinematics, CFC, fits
//! ```
//!
//! The source never waits for the stream and the stream never waits for the analysis: a full
//! sample queue is a counted gap, announced to the stream with the next block; an impact that
//! finds both capture slots busy is reported from its streaming fields alone
//! (`analysis=skipped`). Only the sample source, the clocks and the embassy-time driver differ
//! between the builds.

use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::channel::Channel;
use embassy_sync::zerocopy_channel;
use impact_core::{Capture, Counters, ImpactReport};
use static_cell::{ConstStaticCell, StaticCell};

/// Samples per block, pre-trigger ring and capture length: the board's, in both builds (the
/// emulator has the board's limits), defined once in `impact_core::board`.
pub use impact_core::board::{BLOCK_LEN, CAPTURE_LEN, PRE_TRIGGER_LEN};

/// Blocks the sample queue holds before the source starts losing (counting) them:
/// 8 x 256 samples = 4.1 ms of signal at 500 kS/s.
pub const SAMPLE_QUEUE_BLOCKS: usize = 8;

/// Capture buffers: one being filled by the stream while the other is analysed.
pub const CAPTURE_SLOTS: usize = 2;

/// Reports the analysis task can queue for the reporter.
pub const REPORT_QUEUE_LEN: usize = 2;

/// Skipped-impact reports, heartbeats and the end of the stream the stream task can queue
/// for the reporter without waiting (each holds a whole report, ~1 KiB: the board's RAM
/// counts; a report that finds the queue full is counted, `reports_dropped`).
pub const STREAM_QUEUE_LEN: usize = 4;

/// One block of samples, in the order the source produced them.
pub struct Block {
    /// Sequence number given by the source, from 0, one per block taken or lost.
    pub seq: u32,
    /// Samples the source lost just before this block (overruns, a full queue).
    pub lost_before: u32,
    pub(crate) len: u16,
    pub(crate) samples: [i16; BLOCK_LEN],
}

impl Block {
    /// An empty block.
    pub const fn new() -> Self {
        Self {
            seq: 0,
            lost_before: 0,
            len: 0,
            samples: [0; BLOCK_LEN],
        }
    }

    /// Sets the number of valid samples, clamped to [`BLOCK_LEN`].
    pub fn set_len(&mut self, len: usize) {
        self.len = len.min(BLOCK_LEN) as u16;
    }

    /// The valid samples (a source's last block may be short).
    pub fn samples(&self) -> &[i16] {
        // `len` is clamped in `set_len`; `get` keeps this path free of panics regardless.
        self.samples
            .get(..usize::from(self.len))
            .unwrap_or(&self.samples)
    }
}

impl Default for Block {
    fn default() -> Self {
        Self::new()
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

/// What a sample source sends to the stream task.
// Every queue slot has to hold a block anyway (no heap to box it into); `End` comes once.
#[allow(clippy::large_enum_variant)]
pub enum SourceEvent {
    /// The next block of samples.
    Block(Block),
    /// No more samples will come; `lost` were lost after the last block.
    #[cfg_attr(all(feature = "stm32", not(feature = "adxl375")), allow(dead_code))]
    End { end: StreamEnd, lost: u32 },
}

/// The source's end of the sample queue: it fills the queue's own slots in place.
pub type SampleSender = zerocopy_channel::Sender<'static, CriticalSectionRawMutex, SourceEvent>;
/// The stream task's end of the sample queue: it reads the slots in place.
pub type SampleReceiver = zerocopy_channel::Receiver<'static, CriticalSectionRawMutex, SourceEvent>;

/// One capture buffer of the firmware.
pub type FwCapture = Capture<CAPTURE_LEN>;
/// The stream task's end of the capture queue: it captures into the free slot in place.
pub type CaptureSender = zerocopy_channel::Sender<'static, CriticalSectionRawMutex, FwCapture>;
/// The analysis task's end: it analyses the captured slot in place.
pub type CaptureReceiver = zerocopy_channel::Receiver<'static, CriticalSectionRawMutex, FwCapture>;

/// The sample queue, [`SAMPLE_QUEUE_BLOCKS`] blocks deep. A zero-copy channel: the source
/// writes each block into a slot of the queue and the stream task reads it there, where an
/// ordinary channel would move every 512-byte block by value several times (about 34
/// instructions per sample on the Cortex-M4, measured by `impact bench m4`). `None` if
/// called twice.
pub fn sample_queue() -> Option<(SampleSender, SampleReceiver)> {
    // All zeros (empty blocks), so the slots start in `.bss`.
    static SLOTS: ConstStaticCell<[SourceEvent; SAMPLE_QUEUE_BLOCKS]> =
        ConstStaticCell::new([const { SourceEvent::Block(Block::new()) }; SAMPLE_QUEUE_BLOCKS]);
    static QUEUE: StaticCell<
        zerocopy_channel::Channel<'static, CriticalSectionRawMutex, SourceEvent>,
    > = StaticCell::new();
    let slots = SLOTS.try_take()?;
    let queue = QUEUE.try_init(zerocopy_channel::Channel::new(slots))?;
    Some(queue.split())
}

/// The capture queue: [`CAPTURE_SLOTS`] captures of [`CAPTURE_LEN`] samples. `None` if called
/// twice.
pub fn capture_queue() -> Option<(CaptureSender, CaptureReceiver)> {
    // `Capture::new()` is all zeros: the buffers start in `.bss`, not in flash.
    static SLOTS: ConstStaticCell<[FwCapture; CAPTURE_SLOTS]> =
        ConstStaticCell::new([const { Capture::new() }; CAPTURE_SLOTS]);
    static QUEUE: StaticCell<
        zerocopy_channel::Channel<'static, CriticalSectionRawMutex, FwCapture>,
    > = StaticCell::new();
    let slots = SLOTS.try_take()?;
    let queue = QUEUE.try_init(zerocopy_channel::Channel::new(slots))?;
    Some(queue.split())
}

/// Analysis -> reporter: analysed impacts.
pub static ANALYSED: Channel<CriticalSectionRawMutex, ImpactReport, REPORT_QUEUE_LEN> =
    Channel::new();

/// Stream -> reporter: what the stream task reports itself (never waiting for room).
pub static FROM_STREAM: Channel<CriticalSectionRawMutex, FromStream, STREAM_QUEUE_LEN> =
    Channel::new();

/// Running totals over the blocks the stream task has received.
#[derive(Clone, Copy, defmt::Format)]
pub struct Tally {
    /// Blocks received.
    pub blocks: u32,
    /// Samples received.
    pub samples: u64,
    /// Blocks missing from the sequence numbers (lost between source and monitor).
    pub blocks_missing: u32,
    /// Smallest sample (i16::MAX before any sample).
    pub min: i16,
    /// Largest sample (i16::MIN before any sample).
    pub max: i16,
    /// Sum of all samples, a cheap checksum of what arrived.
    pub sum: i64,
}

impl Tally {
    /// Nothing seen yet.
    pub const fn new() -> Self {
        Self {
            blocks: 0,
            samples: 0,
            blocks_missing: 0,
            min: i16::MAX,
            max: i16::MIN,
            sum: 0,
        }
    }
}

impl Default for Tally {
    fn default() -> Self {
        Self::new()
    }
}

/// The stream's state at one instant.
#[derive(Clone, Copy)]
pub struct Heartbeat {
    /// What arrived from the source.
    pub tally: Tally,
    /// The streaming stage's counters.
    pub counters: Counters,
    /// The scene's sample rate, S/s.
    pub rate_hz: f32,
    /// Share of the time spent in the streaming stage, per mille: since the previous heartbeat,
    /// or over the whole run in the summary.
    pub busy_permille: u32,
    /// A baseline has been learned (impacts can be detected).
    pub armed: bool,
    /// An impact is being captured.
    pub in_impact: bool,
    /// Skipped-impact reports the stream task could not queue.
    pub reports_dropped: u32,
}

/// What the stream task tells the reporter.
// Every queue slot holds the largest variant anyway (no heap to box it into).
#[allow(clippy::large_enum_variant)]
pub enum FromStream {
    /// An impact that found no free capture slot: its streaming fields only.
    Skipped(ImpactReport),
    /// Periodic state.
    Heartbeat(Heartbeat),
    /// The stream ended.
    End {
        /// Final state.
        last: Heartbeat,
        /// How the source ended.
        end: StreamEnd,
    },
}
