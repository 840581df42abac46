//! The last line of a firmware that faulted, on both builds, and its record across the reset.
//!
//! A HardFault (or an escalated bus, memory or usage fault) first keeps where it happened and
//! why (the fault status registers) in the reset record (`impact_firmware::reset_record`, in
//! `.uninit`), then logs them, then the board exits: the STM32 resets (after a bounded wait for
//! a probe to read the line) and its next start-up logs the record with the reset reason, so
//! the fault is seen even when the line was lost; the emulator's run fails (or, with the
//! test's injected fault, resets and shows the record at its next start-up). A fault the core
//! cannot even stack (an overflowing stack) locks it up instead: the board's independent
//! watchdog then resets it, and QEMU stops the emulated run.

use core::cell::UnsafeCell;
use core::mem::MaybeUninit;
use core::sync::atomic::{AtomicBool, Ordering};

use cortex_m_rt::{exception, ExceptionFrame};
use defmt::error;
use impact_firmware::reset_record::{self, Cause, Fault};

/// Set by the first fault: one in the logger itself must not recurse.
static FAULTED: AtomicBool = AtomicBool::new(false);

/// The record's words, in RAM that start-up leaves alone.
struct Record(UnsafeCell<MaybeUninit<[u32; reset_record::WORDS]>>);

// SAFETY: written only by `keep` (the fault handler, or a task just before it resets the
// chip: nothing runs after it) and read once by `take_previous` in `main`'s start-up, before
// any interrupt or task.
unsafe impl Sync for Record {}

#[link_section = ".uninit.impact-reset-record"]
static RECORD: Record = Record(UnsafeCell::new(MaybeUninit::uninit()));

/// Keeps `cause` for the next start-up (volatile writes: the reset follows at once).
pub fn keep(cause: Cause) {
    let base = RECORD.0.get().cast::<u32>();
    for (i, w) in cause.encode().into_iter().enumerate() {
        // SAFETY: `i` < WORDS, inside the record; see `Record`.
        unsafe { core::ptr::write_volatile(base.add(i), w) };
    }
}

/// What the previous run kept before it reset the chip, if anything (then forgotten, so a
/// later reset by something else is not taken for it).
pub fn take_previous() -> Option<Cause> {
    let base = RECORD.0.get().cast::<u32>();
    let mut words = [0u32; reset_record::WORDS];
    for (i, w) in words.iter_mut().enumerate() {
        // SAFETY: inside the record; any bit pattern is a valid u32 (uninitialised RAM is
        // read through a volatile pointer, as a debugger would read it).
        *w = unsafe { core::ptr::read_volatile(base.add(i)) };
    }
    // SAFETY: as above.
    unsafe { core::ptr::write_volatile(base, 0) };
    Cause::decode(&words)
}

/// Logs what the previous run kept (the start-up calls it with the reset reason).
pub fn log_previous(previous: Option<Cause>) {
    match previous {
        Some(Cause::Fault(f)) => error!(
            "previous run faulted: pc={=u32:#x} lr={=u32:#x} sp={=u32:#x} cfsr={=u32:#x} hfsr={=u32:#x} mmfar={=u32:#x} bfar={=u32:#x}",
            f.pc, f.lr, f.sp, f.cfsr, f.hfsr, f.mmfar, f.bfar
        ),
        Some(Cause::StreamEnded) => {
            defmt::warn!("previous run: the sample stream ended, the board restarted it")
        }
        None => {}
    }
}

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
