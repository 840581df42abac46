//! Deadlines further away than a 32-bit one-shot timer reaches, waited for in several shots:
//! the emulator's DMA and ADXL375 (QEMU's 25 MHz CMSDK timers reach 171.8 s; a block period
//! of a replay slowed below 1.5 S/s is longer). Hardware-free, so the host tests it.

/// A one-shot timer's next shot toward `deadline` from `now` (ticks): its length, from 1 (a
/// deadline due or passed: at once) to `reach`, and whether it reaches the deadline. A shot
/// that does not is only a step: its handler arms the next one instead of acting.
pub fn shot(deadline: u64, now: u64, reach: u32) -> (u32, bool) {
    let left = deadline.saturating_sub(now);
    if left > u64::from(reach) {
        (reach, false)
    } else {
        (left.max(1) as u32, true)
    }
}
