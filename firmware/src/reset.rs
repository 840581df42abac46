//! The reset record in RAM (`impact_firmware::reset_record` is its encoding): kept by the
//! fault handler and by a board about to restart a stream that ended, read once at the next
//! start-up and logged with the reset reason.

use core::cell::UnsafeCell;

use defmt::error;
use impact_firmware::reset_record::{self, Cause, Record, WORDS};

/// The record's words, in RAM that start-up leaves alone (`.uninit`: the initialiser is never
/// loaded, so the words hold whatever the previous run, or power-up, left).
struct Words(UnsafeCell<[u32; WORDS]>);

// SAFETY: written only by `keep` and `commit` (the fault handler, or a task about to reset
// the chip) and read once by `take_previous` in `main`'s start-up, before any interrupt or
// task.
unsafe impl Sync for Words {}

#[link_section = ".uninit.impact-reset-record"]
static RECORD: Words = Words(UnsafeCell::new([0; WORDS]));

fn write(words: [u32; WORDS]) {
    let base = RECORD.0.get().cast::<u32>();
    for (i, w) in words.into_iter().enumerate() {
        // SAFETY: `i` < WORDS, inside the record; see `Words`.
        unsafe { core::ptr::write_volatile(base.add(i), w) };
    }
}

fn read() -> [u32; WORDS] {
    let base = RECORD.0.get().cast::<u32>();
    let mut words = [0u32; WORDS];
    for (i, w) in words.iter_mut().enumerate() {
        // SAFETY: inside the record; any bit pattern is a valid u32 (volatile: the RAM was
        // written by a previous run the compiler never saw).
        *w = unsafe { core::ptr::read_volatile(base.add(i)) };
    }
    words
}

/// Keeps `cause` for the next start-up, not yet committed (volatile writes: a reset may
/// follow at any moment).
pub fn keep(cause: Cause) {
    write(cause.encode());
}

/// Commits the kept record: the firmware resets the chip next (call just before).
pub fn commit() {
    let mut words = read();
    if Cause::decode(&words).is_some() {
        reset_record::commit(&mut words);
        write(words);
    }
}

/// What the previous run kept, if anything (then forgotten, so a later reset by something
/// else is not taken for it).
pub fn take_previous() -> Option<Record> {
    let words = read();
    write([0; WORDS]);
    Cause::decode(&words)
}

/// Logs what the previous run kept (the start-up calls it with the reset reason).
pub fn log_previous(previous: Option<Record>) {
    match previous.map(|r| r.cause) {
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
