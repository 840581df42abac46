//! The last line of a firmware that faulted, on both builds, and its record across the reset.
//!
//! A HardFault (or an escalated bus, memory or usage fault) first keeps where it happened and
//! why (the fault status registers) in the reset record ([`crate::reset`], in `.uninit`), then logs them, then the board exits: the STM32 resets (after a bounded wait for
//! a probe to read the line) and its next start-up logs the record with the reset reason, so
//! the fault is seen even when the line was lost; the emulator's run fails (or, with the
//! test's injected fault, resets and shows the record at its next start-up). A fault the core
//! cannot even stack (an overflowing stack) locks it up instead: the board's independent
//! watchdog then resets it, and QEMU stops the emulated run.

use core::sync::atomic::{AtomicBool, Ordering};

use cortex_m_rt::{exception, ExceptionFrame};
use defmt::error;
use impact_firmware::reset_record::{Cause, Fault};

use crate::reset::keep;

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
    let fault = Fault {
        pc: frame.pc(),
        lr: frame.lr(),
        sp: frame as *const ExceptionFrame as u32,
        cfsr,
        hfsr,
        mmfar,
        bfar,
    };
    // The record first: the log line may be lost, or the logger itself may be what faulted.
    keep(Cause::Fault(fault));
    error!(
        "fault pc={=u32:#x} lr={=u32:#x} sp={=u32:#x} cfsr={=u32:#x} hfsr={=u32:#x} mmfar={=u32:#x} bfar={=u32:#x}",
        fault.pc, fault.lr, fault.sp, fault.cfsr, fault.hfsr, fault.mmfar, fault.bfar
    );
    crate::board::fault_exit()
}
