//! Analysis task (lowest priority): the per-impact analysis ([`impact_core::analyse`], the same
//! code as the host's) of each capture the stream task hands over, read in its queue slot and
//! released as soon as the report is made (and, when the scene asks for it, the captured
//! window sent off the board as `wave` / `wave_frame` lines).

use defmt::{error, info};
use embassy_time::{Duration, Timer};
use impact_core::waveform::{self, FRAME_LEN};
use impact_core::{analyse, Scene, Workspace};
use static_cell::ConstStaticCell;

use crate::queues::{CaptureReceiver, FwCapture, ANALYSED, CAPTURE_LEN};

/// The analysis's scratch memory (the acceleration of a whole capture, f32, and the spectra's
/// block statistics). All zeros; it lives in the CCM RAM (board-memory.x: the STM32F407's, and
/// the same 64 KiB in the emulator), which the DMA cannot reach and the analysis does not need
/// it to.
#[link_section = ".ccmram.workspace"]
static WORKSPACE: ConstStaticCell<Workspace<CAPTURE_LEN>> = ConstStaticCell::new(Workspace::new());

/// Pause after each waveform frame: 130 bytes a millisecond (130 KB/s) leaves the link time
/// to empty the 4 KiB RTT buffer (probe-rs on the board, the drain interrupt in the
/// emulator), where a frame that does not fit would be dropped (the host counts the missing
/// frame numbers).
const FRAME_GAP: Option<Duration> = Some(Duration::from_millis(1));

/// Analyses captures until the stream ends (it then waits forever).
#[embassy_executor::task]
pub async fn analysis(scene: Scene, mut captures: CaptureReceiver) {
    let Some(work) = WORKSPACE.try_take() else {
        error!("analysis: started twice");
        return;
    };
    // The scene's share of the work (the spectra's bands) now, not at the first impact.
    work.prepare(&scene);
    loop {
        let capture = captures.receive().await;
        let report = analyse(capture, &scene, work);
        if scene.waveform_every > 0 {
            send_waveform(capture, scene.waveform_every).await;
        }
        captures.receive_done();
        ANALYSED.send(report).await;
    }
}

/// The captured window as a `wave` line and its `wave_frame` lines (docs/board.md),
/// before the impact's own line. The line speaks in samples: a decimated capture's values
/// each hold `step` of them, so a value sent is the mean of `every / step` values (at least
/// one) and stands for `every` samples rounded down to a whole number of values (at least
/// `step`; at most `max(every, step)`, within a `u16`); the window spans its values × `step`.
async fn send_waveform(capture: &FwCapture, every: u16) {
    let s = capture.summary();
    let values = capture.samples();
    let step = capture.step();
    // (`step` is at most 4096 and `every / step * step` at most `every`: both fit a u16.)
    let per_value = (u32::from(every) / step).max(1);
    let every_samples = u16::try_from(per_value * step).unwrap_or(u16::MAX);
    let per_value = per_value as u16;
    let frames = waveform::frames(values.len(), per_value);
    info!(
        "wave seq={=u32} index={=u32} first_sample={=u64} samples={=u32} every={=u16} frames={=u32} base_sum={=i64} base_n={=i64}",
        crate::logger::next_seq(),
        s.index,
        capture.window_from(),
        (values.len() as u32).saturating_mul(step),
        every_samples,
        frames as u32,
        s.base_sum,
        s.base_n,
    );
    let mut buf = [0i16; FRAME_LEN];
    for k in 0..frames {
        let n = waveform::frame(values, per_value, k, &mut buf);
        info!(
            "wave_frame seq={=u32} index={=u32} frame={=u32} counts={=[?]}",
            crate::logger::next_seq(),
            s.index,
            k as u32,
            buf.get(..n).unwrap_or(&buf),
        );
        if let Some(gap) = FRAME_GAP {
            Timer::after(gap).await;
        }
    }
}
