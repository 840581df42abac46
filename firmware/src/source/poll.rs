//! The sample source of a polled three-axis FIFO (the ADXL375's on the board, its emulation in
//! QEMU: the same code): every poll period it drains the FIFO, counts what the FIFO overwrote
//! against the sensor's own stream ([`super::fifo::LossCounter`]), and hands the resultant (or
//! one axis) of what it read to the stream as one short block, so a sample waits at most one
//! poll period (5 ms) before the stream sees it.

use defmt::{warn, Format};
use embassy_time::{Duration, Instant, Ticker};
use impact_firmware::adxl375::{Axes, Picker};

use crate::source::sender::{BlockSender, SOURCE_STATS};
use impact_firmware::fifo::LossCounter;

/// Most entries one poll can find: the ADXL375's 32-sample FIFO and its output registers.
pub const MAX_ENTRIES: usize = 33;

/// Poll period: 5 ms = 16 samples at 3200 S/s, half the FIFO, leaving as much again before
/// it overruns; also the longest a sample waits for the stream (report latency).
pub const POLL_PERIOD: Duration = Duration::from_millis(5);

/// One poll's outcome.
pub struct Read {
    /// When the entry count was read (just before): the samples read are those produced
    /// up to this instant.
    pub at: Instant,
    /// Entries read into the buffer, oldest first.
    pub samples: usize,
    /// The FIFO overran since the previous poll: samples were lost before these.
    pub overrun: bool,
}

/// Why a poll ends the source.
pub enum Poll<E> {
    /// A transient error (a bus error): the FIFO was left as it was; counted, logged. (The
    /// emulated part has no bus.)
    #[cfg_attr(not(feature = "adxl375"), allow(dead_code))]
    Error(E),
    /// No more samples will come (the emulator's file ended; the board's sensor never ends).
    #[cfg_attr(not(feature = "emulator"), allow(dead_code))]
    End,
}

/// A FIFO the source polls. (`async fn` in a trait: the firmware's own, its futures used
/// only by the tasks that own them, so no `Send` bound is needed.)
#[allow(async_fn_in_trait)]
pub trait Fifo {
    type Error: Format;
    /// Reads the entry count and the overrun flag, then every entry counted, into `out`;
    /// stamps the instant the count was read.
    async fn read(&mut self, out: &mut [Axes; MAX_ENTRIES]) -> Result<Read, Poll<Self::Error>>;
}

/// Polls `fifo` every [`POLL_PERIOD`] until it ends, each sample `picker`'s (the resultant
/// of the zeroed axes, or one axis); the sensor started producing at `started` at `rate_hz`.
/// Returns when the FIFO says no more samples will come.
pub async fn run<F: Fifo>(
    fifo: &mut F,
    sender: &mut BlockSender,
    picker: &mut Picker,
    rate_hz: f32,
    started: Instant,
) {
    let mut losses = LossCounter::new(rate_hz, MAX_ENTRIES, started.as_micros());
    let mut entries = [[0i16; 3]; MAX_ENTRIES];
    let mut ticker = Ticker::every(POLL_PERIOD);
    loop {
        ticker.next().await;
        let read = match fifo.read(&mut entries).await {
            Ok(read) => read,
            Err(Poll::End) => return,
            Err(Poll::Error(e)) => {
                let n = SOURCE_STATS.error();
                warn!("FIFO read failed (error #{}): {}", n, e);
                continue;
            }
        };
        let lost = losses.poll(read.at.as_micros(), read.samples, read.overrun);
        // The flag says the FIFO filled; only what the clock says was overwritten is a gap.
        if lost > 0 {
            let n = SOURCE_STATS.overrun();
            warn!(
                "FIFO overrun (#{}): {} samples lost (at {} S/s measured)",
                n,
                lost,
                losses.rate_hz() as f32
            );
            sender.lost(u32::try_from(lost).unwrap_or(u32::MAX));
        }
        let taken = entries.get(..read.samples).unwrap_or(&[]);
        if !taken.is_empty() {
            // Picked before publishing: the resultant's zeros learn every sample the part
            // gave, whether or not the queue has room for the block (the host's, every one).
            let mut picked = [0i16; MAX_ENTRIES];
            for (slot, &sample) in picked.iter_mut().zip(taken) {
                *slot = picker.pick(sample);
            }
            sender.publish(taken.len(), |block| {
                for (slot, &v) in block.iter_mut().zip(&picked) {
                    *slot = v;
                }
            });
        }
    }
}
