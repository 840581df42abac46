//! The firmware's deadlines beyond a 32-bit one-shot timer's reach (`impact_firmware::ticks`),
//! on the host: the emulated DMA's block period of a replay slowed below 1.5 S/s is longer
//! than the 171.8 s a CMSDK timer reaches at 25 MHz. The whole path in emulation:
//! `tests/emulator.rs`, `a_replay_slower_than_the_timers_reach_reports_the_right_latency`.

use impact_firmware::ticks::shot;

/// The emulator's counter and timers, ticks per second.
const CLOCK_HZ: u64 = 25_000_000;

#[test]
fn a_shot_reaches_its_deadline_or_is_a_step_toward_it() {
    assert_eq!(shot(1000, 400, u32::MAX), (600, true));
    assert_eq!(shot(1000, 1000, u32::MAX), (1, true), "due: at once");
    assert_eq!(shot(1000, 2000, u32::MAX), (1, true), "passed: at once");
    assert_eq!(
        shot(10 << 32, 0, u32::MAX),
        (u32::MAX, false),
        "beyond reach"
    );
    let reach = u64::from(u32::MAX);
    assert_eq!(shot(reach, 0, u32::MAX), (u32::MAX, true), "just within");
}

/// The emulated DMA at 1 S/s: a block of 256 samples every 256 s. Each block comes at its
/// deadline after a step and a last shot, never at the end of the first shot (171.8 s: the
/// blocks came early, and a report's latency, taken from the samples' nominal times, was
/// short or negative), whatever the interrupt's latency.
#[test]
fn a_block_period_beyond_the_timers_reach_takes_a_step_and_is_never_early() {
    let period = 256 * CLOCK_HZ;
    let (start, mut now) = (12_345u64, 12_345u64);
    for block in 0..20u64 {
        let deadline = start + (block + 1) * period;
        let mut shots = 0;
        // The handler: another shot after a step, the block after a shot that reaches.
        loop {
            let (ticks, reaches) = shot(deadline, now, u32::MAX);
            shots += 1;
            // The interrupt comes a little after the shot runs out.
            now += u64::from(ticks) + 17 * (block % 5);
            if reaches {
                break;
            }
        }
        assert!(now >= deadline, "block {block} early");
        assert!(now - deadline <= 17 * 8, "block {block} late");
        assert_eq!(shots, 2, "block {block}: 256 s in shots of at most 171.8 s");
    }
}
