//! The ADC's conversions counted against the samples delivered: the board's time base.
//!
//! TIM2 counts every TIM3 trigger (32 bits, wrapping); the sampler counts the samples it took
//! out of the DMA ring or declared lost. A sample's place in the stream is its count, so the
//! two must agree: the counter may run ahead by what the ring holds and has not been read yet
//! (at most the ring's length, and the conversion in flight), never further. Further means
//! triggers that made no sample (a conversion still running when the next trigger came, or a
//! ring the DMA lapped unseen): those samples are lost and the stream must be told, or every
//! later time is early by them.
//!
//! Both counts wrap at 2^32 (2.4 hours at 500 kS/s); their difference is taken signed, so a
//! sample delivered before the counter saw its trigger (a software-started conversion) is a
//! count of −1, not 4 294 967 295 lost.
//!
//! The exact check after each block compares the counter with the DMA's position in its
//! ring, read together: every trigger moves both by one (the DMA a conversion later), so
//! `(count − position) mod ring` keeps its value from one resynchronisation to the next, or
//! one more while a conversion is in flight. Any other change is triggers that made no
//! sample ([`drift`]).

/// `(counted − position) mod ring`: what [`drift`] compares (`ring` a power of two, so that
/// the counter's wrap at 2^32 keeps it).
pub fn phase(counted: u32, position: u32, ring: u32) -> u32 {
    counted.wrapping_sub(position) % ring.max(1)
}

/// Triggers that made no sample since the phase was `phase0`, from the counter and the
/// DMA's ring position read together: 0 on a healthy board (a conversion in flight when
/// either was read shows as ±1), else how many at least.
pub fn drift(phase0: u32, counted: u32, position: u32, ring: u32) -> u32 {
    let ring = ring.max(1);
    let d = (phase(counted, position, ring) + ring - phase0 % ring) % ring;
    if d <= 1 || d + 1 == ring {
        0
    } else {
        d - 1
    }
}

/// What a resynchronisation finds (the ring's unread contents dropped first).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Resync {
    /// Conversions counted since the last sample delivered: lost.
    Lost(u32),
    /// More delivered than counted: nothing lost, the stream ran `extra` samples ahead.
    Uncounted(u32),
}

/// The counter's lead over the samples delivered (negative: more delivered than counted).
pub fn lead(counted: u32, delivered: u32) -> i64 {
    i64::from(counted.wrapping_sub(delivered) as i32)
}

/// At a resynchronisation (the ring dropped, the counter read): what was lost since the last
/// sample delivered.
pub fn resync(counted: u32, delivered: u32) -> Resync {
    let lead = lead(counted, delivered);
    if lead < 0 {
        Resync::Uncounted(lead.unsigned_abs() as u32)
    } else {
        Resync::Lost(lead as u32)
    }
}
