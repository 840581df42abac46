//! The board's time base (`impact_firmware::conversions`): TIM2's count of ADC triggers against
//! the samples the sampler delivered, at the counters' wrap and with the conversions that
//! break the rule (a software-started one, triggers that made no sample). The sampler that
//! uses it (`firmware/src/board/stm32/adc.rs`) has not run on silicon.

use impact_firmware::conversions::{lead, resync, Resync};

/// Two blocks of 256: the DMA ring.
const RING: u32 = 512;

/// A trigger that came while the previous conversion ran is counted and makes no sample:
/// the resynchronisation counts it lost with the ring's contents, however the counters wrap.
#[test]
fn triggers_that_made_no_sample_are_lost_at_the_resync_across_the_wrap() {
    for delivered in [0u32, u32::MAX - 300, u32::MAX] {
        let counted = delivered.wrapping_add(RING + 1 + 7);
        assert_eq!(resync(counted, delivered), Resync::Lost(RING + 8));
    }
}

/// The software-started first conversion (embassy's `start` sets SWSTART) is a sample TIM2
/// never counted: a lead of −1, not 4 294 967 295 samples lost.
#[test]
fn a_conversion_no_trigger_made_is_one_ahead_not_four_billion_lost() {
    assert_eq!(lead(0, 1), -1);
    assert_eq!(resync(0, 1), Resync::Uncounted(1));
    assert_eq!(resync(u32::MAX, 0), Resync::Uncounted(1));
    assert_eq!(resync(5, u32::MAX), Resync::Lost(6));
}

/// The exact check: the counter against the DMA's position in its 512-sample ring, read
/// together. A healthy board keeps their phase (±1 for a conversion in flight), across the
/// counter's wrap and the ring's; triggers that made no sample move it by their number.
#[test]
fn the_counter_against_the_rings_position_finds_every_missed_trigger() {
    use impact_firmware::conversions::{drift, phase};
    // Start: the software-started sample is in the ring, no trigger counted yet.
    let phase0 = phase(0, 1, RING);
    for step in [0u32, 1, 255, 256, 511, 512, 100_000, u32::MAX - 3] {
        let counted = step;
        let position = step.wrapping_add(1) % RING;
        assert_eq!(drift(phase0, counted, position, RING), 0, "{step}");
        // A conversion in flight: counted, not yet written.
        assert_eq!(drift(phase0, counted.wrapping_add(1), position, RING), 0);
        // Read the other way round: written by the time the position was read.
        assert_eq!(drift(phase0, counted, (position + 1) % RING, RING), 0);
        for missed in [2u32, 3, 100, 300] {
            assert_eq!(
                drift(phase0, counted.wrapping_add(missed), position, RING),
                missed - 1,
                "{step} + {missed}"
            );
        }
    }
}
