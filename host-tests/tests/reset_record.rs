//! The reset record's encoding (`impact_firmware::reset_record`): what the firmware keeps in
//! `.uninit` before it resets the chip. The path through a real system reset runs in the
//! emulator (`tests/emulator.rs`, `a_fault_is_kept_across_the_reset_and_logged_at_the_next_start_up`).

use impact_firmware::reset_record::{commit, Cause, Fault, Record, MAGIC, PENDING, WORDS};

fn fault() -> Cause {
    Cause::Fault(Fault {
        pc: 0x0800_1234,
        lr: 0xFFFF_FFF9,
        sp: 0x2000_5F00,
        cfsr: 0x0001_0000,
        hfsr: 0x4000_0000,
        mmfar: 0xE000_EDF4,
        bfar: 0xE000_EDF8,
    })
}

/// Kept, a record reads back as not the firmware's reset (a debugger may reset the chip
/// during the probe wait or the restart countdown); committed, as the firmware's.
#[test]
fn a_record_reads_back_as_what_was_kept_and_whether_it_was_committed() {
    for cause in [fault(), Cause::StreamEnded] {
        let mut words = cause.encode();
        assert_eq!(words[0], PENDING);
        assert_eq!(
            Cause::decode(&words),
            Some(Record {
                cause,
                reset_by_firmware: false
            })
        );
        commit(&mut words);
        assert_eq!(words[0], MAGIC);
        assert_eq!(
            Cause::decode(&words),
            Some(Record {
                cause,
                reset_by_firmware: true
            })
        );
    }
}

/// SRAM powers up with arbitrary contents, and the start-up clears the magic of a record it
/// read: neither may pass for a record, nor may a record with any word changed.
#[test]
fn anything_but_a_whole_record_is_none() {
    assert_eq!(Cause::decode(&[0; WORDS]), None);
    assert_eq!(Cause::decode(&[u32::MAX; WORDS]), None);
    for cause in [fault(), Cause::StreamEnded] {
        let mut words = cause.encode();
        commit(&mut words);
        for i in 0..WORDS {
            for bit in [0, 7, 31] {
                let mut bad = words;
                bad[i] ^= 1 << bit;
                assert_eq!(Cause::decode(&bad), None, "word {i} bit {bit}");
            }
        }
        let mut cleared = words;
        cleared[0] = 0;
        assert_eq!(Cause::decode(&cleared), None);
    }
    // A pseudo-random power-up pattern (xorshift), a million of them: none is a record.
    let mut x = 0x9E37_79B9u32;
    let mut next = || {
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        x
    };
    for _ in 0..1_000_000 {
        let mut w = [0u32; WORDS];
        w.iter_mut().for_each(|v| *v = next());
        // Even with a magic in place by chance.
        w[0] = if w[1] & 1 == 0 { MAGIC } else { PENDING };
        assert_eq!(Cause::decode(&w), None, "{w:x?}");
    }
}
