//! Emulator sample sources: a host file of raw little-endian i16 samples, replayed
//!
//! * in real time ([`realtime`]): the emulated DMA ([`super::dma`]) writes one block
//!   per block period of virtual time into its ring, and this task, at the highest priority,
//!   copies the blocks into the sample queue as the board's sampler copies the DMA's halves;
//!   a ring overrun or a full queue is a counted loss, announced to the stream;
//! * losslessly ([`lossless`]): read through semihosting as fast as the stream takes the
//!   blocks, waiting for room in the queue, so every sample reaches the stream whatever the
//!   emulator's speed (reproducible runs over recorded signals).
//!
//! With `sensor=adxl375` the file holds three-axis samples (i16 triplets, x y z) and goes
//! through the ADXL375 path instead: in real time an emulated ADXL375
//! ([`super::adxl375`]) polled by the board's own ADXL375 source
//! ([`crate::source::poll`]), losslessly the same resultant computed block by block.
//!
//! Paths cannot contain spaces (semihosting joins the arguments with spaces).

use core::sync::atomic::Ordering;

use defmt::{error, info, Format};
use embassy_time::Instant;

use super::adxl375;
use super::dma::{self, Take};
use crate::queues::{SampleSender, StreamEnd, BLOCK_LEN};
use crate::source::poll;
use crate::source::sender::{BlockSender, SAMPLE_CLOCK, SOURCE_STATS};
use impact_firmware::adxl375::Picker;
use impact_firmware::semihosting::{HostError, HostFile};

/// Bytes per sample in the file: one axis, or three (the ADXL375 path).
pub const fn sample_bytes(axes: bool) -> usize {
    if axes {
        6
    } else {
        2
    }
}

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

/// Opens the file and checks its length (whole samples of one axis, or of three with
/// `axes`); logs what is replayed.
pub fn open(path: &str, rate_hz: f32, axes: bool) -> Result<HostFile, ReplayError> {
    let file = HostFile::open(path)?;
    let bytes = file.len_bytes()?;
    if bytes % sample_bytes(axes) != 0 {
        return Err(ReplayError::OddLength { bytes });
    }
    info!(
        "replay: {=str}: {} samples{=str} at {=f32} S/s",
        path,
        bytes / sample_bytes(axes),
        if axes { " of three axes" } else { "" },
        rate_hz
    );
    Ok(file)
}

/// Replays the file block by block (with `axes`, three-axis samples, of which the axis
/// given goes to the stream, the resultant of the axes zeroed with the settings given),
/// waiting for room in the queue, then ends the stream.
#[embassy_executor::task]
pub async fn lossless(file: HostFile, axes: Option<&'static mut Picker>, samples: SampleSender) {
    let mut sender = BlockSender::new(samples);
    let end = match replay_all(&mut sender, file, axes).await {
        Ok(()) => StreamEnd::Complete,
        Err(e) => {
            SOURCE_STATS.error();
            error!("replay: {}", e);
            StreamEnd::Failed
        }
    };
    sender.finish(end).await;
}

async fn replay_all(
    sender: &mut BlockSender,
    mut file: HostFile,
    mut picker: Option<&'static mut Picker>,
) -> Result<(), ReplayError> {
    let width = sample_bytes(picker.is_some());
    let mut raw = [0u8; BLOCK_LEN * 6];
    let raw = raw.get_mut(..BLOCK_LEN * width).unwrap_or(&mut []);
    loop {
        let n = file.read_full(raw)?;
        if n == 0 {
            return Ok(());
        }
        // The length was checked; a file that grew meanwhile ends here.
        if n % width != 0 {
            return Err(ReplayError::OddLength { bytes: n });
        }
        let bytes = raw.get(..n).unwrap_or(&[]);
        sender
            .send(n / width, |block| {
                for (sample, le) in block.iter_mut().zip(bytes.chunks_exact(width)) {
                    *sample = match *le {
                        [lo, hi] => i16::from_le_bytes([lo, hi]),
                        [x0, x1, y0, y1, z0, z1] => picker.as_mut().map_or(0, |p| {
                            p.pick([
                                i16::from_le_bytes([x0, x1]),
                                i16::from_le_bytes([y0, y1]),
                                i16::from_le_bytes([z0, z1]),
                            ])
                        }),
                        _ => 0,
                    };
                }
            })
            .await;
        if n < raw.len() {
            return Ok(());
        }
    }
}

/// Starts the emulated ADXL375 on the file at `rate_hz` (the recording's rate times the rate
/// scale) and polls it with the board's ADXL375 source until the file ends. `stall` (a test's
/// fault injection): before poll `.0`, busy-wait `.1` µs. Logs what the emulated part
/// overwrote, the truth the firmware's own count of lost samples can be held to.
#[embassy_executor::task]
pub async fn adxl375(
    file: HostFile,
    rate_hz: f32,
    picker: &'static mut Picker,
    stall: Option<(u32, u32)>,
    samples: SampleSender,
) {
    let mut sender = BlockSender::new(samples);
    SAMPLE_CLOCK.start(rate_hz);
    let started = Instant::now();
    adxl375::start(file, f64::from(rate_hz));
    let mut part = adxl375::EmulatedAdxl375 { stall, polls: 0 };
    poll::run(&mut part, &mut sender, picker, rate_hz, started).await;
    let (produced, overwritten) = adxl375::counts();
    info!(
        "emulated ADXL375: {} samples produced, {} overwritten unread",
        produced, overwritten
    );
    sender.finish(replay_end(adxl375::failed())).await;
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
                super::stall_sampler(us);
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
    sender
        .finish(replay_end(dma::FAILED.load(Ordering::Relaxed)))
        .await;
}

/// How a real-time replay ended: failed (counted, logged) if its host file could not be read.
fn replay_end(failed: bool) -> StreamEnd {
    if failed {
        SOURCE_STATS.error();
        error!("replay: the host file could not be read");
        StreamEnd::Failed
    } else {
        StreamEnd::Complete
    }
}
