//! Emulator sample source: replays a host file of raw little-endian i16 samples, read
//! through semihosting in blocks of [`BLOCK_LEN`] samples, as the ADC would deliver them.
//!
//! The semihosting command line (see [`crate::emulator::Config`]) names the file and the
//! pacing (`scripts/emulate.sh` and `impact emulate` pass it with `-semihosting-config arg=...`):
//!
//! * `realtime` (default): one block every `BLOCK_LEN` sample periods of the scene's rate,
//!   queued without waiting like the DMA does; blocks the monitor cannot take in time are
//!   lost and counted, as they would be on the board (here the budget is the emulator's speed);
//! * `lossless`: waits for room in the queue, so every sample reaches the monitor whatever
//!   the emulator's speed (reproducible runs over recorded signals).
//!
//! Paths cannot contain spaces (semihosting joins the arguments with spaces).

use defmt::{error, info, Format};
use embassy_time::{Duration, Ticker};

use crate::emulator::host::{HostError, HostFile};
use crate::emulator::Pacing;
use crate::tasks::sampler::{BlockSender, SOURCE_STATS};
use crate::tasks::{StreamEnd, BLOCK_LEN};

/// Bytes per sample in the file.
const SAMPLE_BYTES: usize = 2;

#[derive(Format)]
enum ReplayError {
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

/// Replays the file at `path` as if sampled at `rate_hz`, then ends the stream.
#[embassy_executor::task]
pub async fn replay(
    path: &'static str,
    pacing: Pacing,
    rate_hz: f32,
    samples: crate::tasks::SampleSender,
) {
    let mut sender = BlockSender::new(samples);
    let end = match run(&mut sender, path, pacing, rate_hz).await {
        Ok(()) => StreamEnd::Complete,
        Err(e) => {
            SOURCE_STATS.error();
            error!("replay: {}", e);
            StreamEnd::Failed
        }
    };
    sender.finish(end).await;
}

async fn run(
    sender: &mut BlockSender,
    path: &'static str,
    pacing: Pacing,
    rate_hz: f32,
) -> Result<(), ReplayError> {
    let mut file = HostFile::open(path)?;
    let bytes = file.len_bytes()?;
    if bytes % SAMPLE_BYTES != 0 {
        return Err(ReplayError::OddLength { bytes });
    }
    info!(
        "replay: {=str}: {} samples at {=f32} S/s, {}",
        path,
        bytes / SAMPLE_BYTES,
        rate_hz,
        pacing
    );

    // The time the ADC takes to fill one block (at least 1 us; the scene's rate is
    // validated as finite and positive).
    let block_period_us = (BLOCK_LEN as f32 * 1e6 / rate_hz).max(1.0) as u64;
    let mut ticker = Ticker::every(Duration::from_micros(block_period_us));
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
        let fill = |block: &mut [i16; BLOCK_LEN]| {
            let bytes = raw.get(..n).unwrap_or(&[]);
            for (sample, le) in block.iter_mut().zip(bytes.chunks_exact(SAMPLE_BYTES)) {
                if let [lo, hi] = *le {
                    *sample = i16::from_le_bytes([lo, hi]);
                }
            }
            n / SAMPLE_BYTES
        };
        match pacing {
            Pacing::RealTime => {
                ticker.next().await;
                sender.publish(fill);
            }
            Pacing::Lossless => sender.send(fill).await,
        }
        if n < raw.len() {
            return Ok(());
        }
    }
}
