//! The reset record in RAM (`impact_firmware::reset_record` is its encoding): kept by the
//! fault handler and by a board about to restart a stream that ended, read once at the next
//! start-up and logged with the reset reason.

use core::cell::UnsafeCell;
use core::mem::MaybeUninit;

use defmt::error;
use impact_firmware::reset_record::{self, Cause};

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
