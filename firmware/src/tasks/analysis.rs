//! Analysis task (lowest priority): the per-impact analysis ([`impact_core::analyse`], the same
//! code as the host's) of each capture the stream task hands over, read in its queue slot and
//! released as soon as the report is made.

use defmt::error;
use impact_core::{analyse, Scene, Workspace};
use static_cell::ConstStaticCell;

use super::{CaptureReceiver, ANALYSED, CAPTURE_LEN};

/// The analysis's scratch memory (the acceleration of a whole capture, f32). All zeros, so it
/// starts in `.bss`; on the board it lives in the CCM RAM (`firmware/stm32/board-memory.x`),
/// which the DMA cannot reach and the analysis does not need it to.
#[cfg_attr(feature = "stm32", link_section = ".ccmram.workspace")]
static WORKSPACE: ConstStaticCell<Workspace<CAPTURE_LEN>> = ConstStaticCell::new(Workspace::new());

/// Analyses captures until the stream ends (it then waits forever).
#[embassy_executor::task]
pub async fn analysis(scene: Scene, mut captures: CaptureReceiver) {
    let Some(work) = WORKSPACE.try_take() else {
        error!("analysis: started twice");
        return;
    };
    loop {
        let capture = captures.receive().await;
        let report = analyse(capture, &scene, work);
        captures.receive_done();
        ANALYSED.send(report).await;
    }
}
