//! The pipeline's sizes on the board, defined once: the firmware (both builds: the STM32F407
//! and its emulation), the host's `--board-capture` analysis, and the M4 benchmark and panic
//! check all take them from here.

use crate::monitor::Monitor;

/// Samples per block: one DMA half-buffer on the STM32, one emulated DMA transfer in QEMU.
pub const BLOCK_LEN: usize = 256;

/// Pre-trigger ring (and baseline window, and reach of the flank fits), samples.
pub const PRE_TRIGGER_LEN: usize = 4096;

/// Capture length, samples: 30.2 ms at 500 kS/s (the seed bench's 27 ms window with room).
/// 118 blocks of 128 samples, so that the analysis's workspace (4 bytes a sample and the
/// spectra's 3.5 KiB scratch, 63 896 bytes) fits the STM32F407's 64 KiB CCM RAM.
pub const CAPTURE_LEN: usize = 15_104;

/// The pipeline as the board runs it, in one object (host, benchmarks, panic check).
pub type BoardMonitor = Monitor<PRE_TRIGGER_LEN, CAPTURE_LEN>;

#[cfg(test)]
mod tests {
    #[test]
    fn the_workspace_fits_the_ccm_ram() {
        let size = core::mem::size_of::<crate::Workspace<{ super::CAPTURE_LEN }>>();
        assert!(size <= 64 * 1024, "{size} bytes");
    }
}
