//! The last line of a firmware that faulted, on both builds: a HardFault (or an escalated bus,
//! memory or usage fault) logs where it happened and why (the fault status registers), then
//! the board resets (its next start-up logs the reason) and the emulator's run fails. A fault
//! the core cannot even stack (an overflowing stack) locks it up instead: the board's
//! independent watchdog then resets it, and QEMU stops the emulated run.

use core::sync::atomic::{AtomicBool, Ordering};

use cortex_m_rt::{exception, ExceptionFrame};
use defmt::error;

/// Set by the first fault: one in the logger itself must not recurse.
static FAULTED: AtomicBool = AtomicBool::new(false);

#[exception]
unsafe fn HardFault(frame: &ExceptionFrame) -> ! {
    if FAULTED.swap(true, Ordering::Relaxed) {
        crate::board::fault_exit()
    }
    // SAFETY: reads of the System Control Block's fault status and address registers, which
    // the fault handler owns (nothing else runs at its priority).
    let (cfsr, hfsr, mmfar, bfar) = unsafe {
        let scb = &*cortex_m::peripheral::SCB::PTR;
        (
            scb.cfsr.read(),
            scb.hfsr.read(),
            scb.mmfar.read(),
            scb.bfar.read(),
        )
    };
    error!(
        "fault pc={=u32:#x} lr={=u32:#x} sp={=u32:#x} cfsr={=u32:#x} hfsr={=u32:#x} mmfar={=u32:#x} bfar={=u32:#x}",
        frame.pc(),
        frame.lr(),
        frame as *const ExceptionFrame as u32,
        cfsr,
        hfsr,
        mmfar,
        bfar
    );
    crate::board::fault_exit()
}
