//! Why the firmware reset itself, kept across the reset: a fault's registers or the end of
//! the sample stream, written just before the firmware resets the chip and read (then cleared)
//! at the next start-up.
//!
//! A fault's log line is written into the RTT buffer microseconds before the reset; a probe
//! has usually not read it yet, and the start-up's `.data` copy puts the buffer's positions
//! back to zero, so the line is gone (and with no probe attached there is nobody to read it).
//! The record lives in the `.uninit` section, which nothing initialises at start-up, so it
//! survives a system reset; a word of magic and a check word tell a record from the random
//! contents SRAM powers up with. The next start-up logs it with the reset reason, so a fault
//! on a bench without a probe is seen at the next attach.
//!
//! The record is kept as soon as the cause is known ([`PENDING`]: a fault's registers are
//! safe even if its log line hangs) and committed ([`MAGIC`]) just before the firmware
//! resets the chip. A software reset with a committed record is the firmware's; without one
//! it is a debugger's (flashing, `probe-rs reset`, perhaps during the probe wait or the
//! restart countdown), which the board names so.
//!
//! The encoding is plain words, so the host tests check it (`tests/reset_record.rs`).

/// Marks a record the firmware committed just before it reset the chip (not SRAM's random
/// power-up contents).
pub const MAGIC: u32 = 0x1A7F_C0DE;

/// Marks a record kept but not yet committed: the reset that followed was not the
/// firmware's.
pub const PENDING: u32 = 0x1A7F_0BAD;

/// A record read back: what the firmware kept, and whether it then reset the chip itself.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Record {
    pub cause: Cause,
    pub reset_by_firmware: bool,
}

/// Words in a stored record.
pub const WORDS: usize = 10;

/// What made the firmware reset the chip.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Cause {
    /// A HardFault (or an escalated bus, memory or usage fault) with the core's registers.
    Fault(Fault),
    /// The sample stream ended (a source that gave up); the board restarts it.
    StreamEnded,
}

/// Where a fault happened and why (the fault status registers, ARMv7-M ARM B3.2.15–B3.2.18).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub struct Fault {
    /// The stacked program counter: the faulting instruction.
    pub pc: u32,
    /// The stacked link register.
    pub lr: u32,
    /// The stack pointer at the fault (the exception frame's address).
    pub sp: u32,
    /// Configurable Fault Status Register.
    pub cfsr: u32,
    /// HardFault Status Register.
    pub hfsr: u32,
    /// MemManage Fault Address Register.
    pub mmfar: u32,
    /// BusFault Address Register.
    pub bfar: u32,
}

const FAULT: u32 = 1;
const STREAM_ENDED: u32 = 2;

/// The check word of a record's words before it (the magic first): a rotate-xor fold, so an
/// all-zero or all-ones RAM, or a record with one word changed, does not pass.
pub fn check(words: &[u32]) -> u32 {
    words
        .iter()
        .fold(0x5A5A_5A5A, |acc, &w| acc.rotate_left(5) ^ w)
}

/// A kept record's words committed: the magic [`MAGIC`] and the check word again.
pub fn commit(words: &mut [u32; WORDS]) {
    words[0] = MAGIC;
    words[9] = check(&words[..9]);
}

impl Cause {
    /// The record's words as kept (not yet committed): [`PENDING`], kind, seven registers
    /// (zero for a stream's end), check.
    pub fn encode(&self) -> [u32; WORDS] {
        let mut w = [0u32; WORDS];
        w[0] = PENDING;
        match self {
            Cause::Fault(f) => {
                w[1] = FAULT;
                w[2..9].copy_from_slice(&[f.pc, f.lr, f.sp, f.cfsr, f.hfsr, f.mmfar, f.bfar]);
            }
            Cause::StreamEnded => w[1] = STREAM_ENDED,
        }
        w[9] = check(&w[..9]);
        w
    }

    /// The record the words hold, or `None` for anything that is not a whole record.
    pub fn decode(w: &[u32; WORDS]) -> Option<Record> {
        if !matches!(w[0], MAGIC | PENDING) || w[9] != check(&w[..9]) {
            return None;
        }
        let cause = match w[1] {
            FAULT => Some(Cause::Fault(Fault {
                pc: w[2],
                lr: w[3],
                sp: w[4],
                cfsr: w[5],
                hfsr: w[6],
                mmfar: w[7],
                bfar: w[8],
            })),
            STREAM_ENDED if w[2..9].iter().all(|&x| x == 0) => Some(Cause::StreamEnded),
            _ => None,
        }?;
        Some(Record {
            cause,
            reset_by_firmware: w[0] == MAGIC,
        })
    }
}
