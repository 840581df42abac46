//! Emulator sample sources: a host file of raw little-endian i16 samples, replayed
//!
//! * in real time ([`realtime`]): the emulated DMA ([`crate::emulator::dma`]) writes one block
//!   per block period of virtual time into its ring, and this task, at the highest priority,
//!   copies the blocks into the sample queue as the board's sampler copies the DMA's halves;
//!   a ring overrun or a full queue is a counted loss, announced to the stream;
//! * losslessly ([`lossless`]): read through semihosting as fast as the stream takes the
//!   blocks, waiting for room in the queue, so every sample reaches the stream whatever the
//!   emulator's speed (reproducible runs over recorded signals).
//!
//! Paths cannot contain spaces (semihosting joins the arguments with spaces).

use core::sync::atomic::Ordering;

use defmt::{error, info, warn, Format};
use embassy_time::{Duration, Instant};

use crate::emulator::dma::{self, Take};
use crate::emulator::host::{HostError, HostFile};
use crate::tasks::sampler::{BlockSender, SAMPLE_CLOCK, SOURCE_STATS};
use crate::tasks::{SampleSender, StreamEnd, BLOCK_LEN};

/// Bytes per sample in the file.
const SAMPLE_BYTES: usize = 2;

#[derive(Format)]
pub enum ReplayError {
    Host(HostError),
    /// The file ends in half a sample.
    OddLength {
        bytes: usize,
    },
}

impl From<HostError> for ReplayError {
    fn from(e: HostError) -> Self {
        Self::Host(e)
    }
}

/// Opens the file and checks its length; logs what is replayed.
pub fn open(path: &str, rate_hz: f32) -> Result<HostFile, ReplayError> {
    let file = HostFile::open(path)?;
    let bytes = file.len_bytes()?;
    if bytes % SAMPLE_BYTES != 0 {
        return Err(ReplayError::OddLength { bytes });
    }
    info!(
        "replay: {=str}: {} samples at {=f32} S/s",
        path,
        bytes / SAMPLE_BYTES,
        rate_hz
    );
    Ok(file)
}

/// Replays the file block by block, waiting for room in the queue, then ends the stream.
#[embassy_executor::task]
pub async fn lossless(file: HostFile, samples: SampleSender) {
    let mut sender = BlockSender::new(samples);
    let end = match replay_all(&mut sender, file).await {
        Ok(()) => StreamEnd::Complete,
        Err(e) => {
            SOURCE_STATS.error();
            error!("replay: {}", e);
            StreamEnd::Failed
        }
    };
    sender.finish(end).await;
}

async fn replay_all(sender: &mut BlockSender, mut file: HostFile) -> Result<(), ReplayError> {
    let mut raw = [0u8; BLOCK_LEN * SAMPLE_BYTES];
    loop {
        let n = file.read_full(&mut raw)?;
        if n == 0 {
            return Ok(());
        }
        // The length was checked to be even; a file that grew meanwhile ends here.
        if n % SAMPLE_BYTES != 0 {
            return Err(ReplayError::OddLength { bytes: n });
        }
        let bytes = raw.get(..n).unwrap_or(&[]);
        sender
            .send(n / SAMPLE_BYTES, |block| {
                for (sample, le) in block.iter_mut().zip(bytes.chunks_exact(SAMPLE_BYTES)) {
                    if let [lo, hi] = *le {
                        *sample = i16::from_le_bytes([lo, hi]);
                    }
                }
            })
            .await;
        if n < raw.len() {
            return Ok(());
        }
    }
}

/// Starts the emulated DMA on the file at `rate_hz` (the recording's rate times the rate
/// scale) and copies its blocks into the sample queue until the file ends. `stall` (a test's
/// fault injection): before block `.0`, busy-wait `.1` µs, as a board whose sampler was held
/// up would.
#[embassy_executor::task]
pub async fn realtime(
    file: HostFile,
    rate_hz: f32,
    stall: Option<(u32, u32)>,
    samples: SampleSender,
) {
    let mut sender = BlockSender::new(samples);
    SAMPLE_CLOCK.start(rate_hz);
    dma::start(file, rate_hz as f64);
    let mut next = 0u32;
    let mut stall = stall;
    loop {
        if let Some((block, us)) = stall {
            if block == next {
                stall = None;
                warn!(
                    "replay: stalling the sampler for {} us (fault injection)",
                    us
                );
                let until = Instant::now() + Duration::from_micros(u64::from(us));
                while Instant::now() < until {}
            }
        }
        match dma::take(next, |block| {
            sender.publish(block.len(), |slot| {
                impact_core::signal::copy::copy_samples(slot, block);
            });
        }) {
            Take::Block => next += 1,
            Take::Overrun { lost } => {
                SOURCE_STATS.overrun();
                sender.lost(lost * BLOCK_LEN as u32);
                next += lost;
            }
            Take::Empty => dma::WRITTEN.wait().await,
            Take::End => break,
        }
    }
    let end = if dma::FAILED.load(Ordering::Relaxed) {
        SOURCE_STATS.error();
        error!("replay: the host file could not be read");
        StreamEnd::Failed
    } else {
        StreamEnd::Complete
    };
    sender.finish(end).await;
}
