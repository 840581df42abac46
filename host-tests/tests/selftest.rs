//! The bring-up self-test's played pulse and its judge (`impact_firmware::selftest`), on the
//! host: the table the DAC plays is the half-sine it claims, and the judge passes what was
//! played and fails each fault it is there to find. Its run through the whole emulated
//! monitor is in tests/emulator.rs (`impact selftest`).

use impact_firmware::selftest::{
    code_at, Judge, Measured, Outcome, Played, AMPLITUDE_CODES, DAC_RATE_HZ, DEADLINE_S, PERIOD_S,
    PULSES, PULSE_S, PULSE_STEPS, SETTLE_S, TABLE, TABLE_LEN, ZERO_CODE,
};

const GAIN: f32 = 1600.0 / 4096.0;
const RATE: f32 = 500_000.0;

#[test]
fn the_table_is_a_half_sine_then_rest() {
    assert_eq!(TABLE.len(), TABLE_LEN);
    assert_eq!(TABLE[0], ZERO_CODE);
    assert_eq!(TABLE[PULSE_STEPS / 2], ZERO_CODE + AMPLITUDE_CODES);
    for (i, &code) in TABLE.iter().enumerate() {
        let want = if i < PULSE_STEPS {
            let x = std::f64::consts::PI * i as f64 / PULSE_STEPS as f64;
            (f64::from(ZERO_CODE) + f64::from(AMPLITUDE_CODES) * x.sin()).round() as u16
        } else {
            ZERO_CODE
        };
        assert_eq!(code, want, "code {i}");
    }
    assert!((PULSE_S - 2e-3).abs() < 1e-9);
    assert!((PERIOD_S - 0.2).abs() < 1e-9);
}

#[test]
fn the_adc_sees_each_code_held_until_the_next_update() {
    // 500 kS/s against 50 kHz updates: ten samples per code.
    let per = 500_000 / u64::from(DAC_RATE_HZ);
    for n in 0..2000u64 {
        assert_eq!(
            code_at(n, 500_000.0, 0),
            TABLE[(n / per) as usize],
            "sample {n}"
        );
    }
    // The table wraps: a period later the same codes come again.
    let period = per * TABLE_LEN as u64;
    assert_eq!(
        code_at(period + 250, 500_000.0, 0),
        code_at(250, 500_000.0, 0)
    );
}

/// A pulse as the monitor would measure what was played, `k` periods after the settling.
fn measured(k: u32, peak_scale: f32, fwhm_scale: f32, period_scale: f64) -> Measured {
    let played = Played::new(GAIN, RATE, None);
    let start = SETTLE_S + 0.01 + f64::from(k) * f64::from(PERIOD_S) * period_scale;
    Measured {
        whole: true,
        start_s: start,
        peak_m_s2: played.peak_m_s2 * peak_scale,
        fwhm_s: Some(played.fwhm_s * fwhm_scale),
    }
}

fn run(pulses: impl Iterator<Item = Measured>) -> (Vec<bool>, Option<(u32, bool)>) {
    let mut judge = Judge::new(Played::new(GAIN, RATE, Some(2.98)));
    let mut passes = Vec::new();
    let mut verdict = None;
    for m in pulses {
        if let Outcome::Judged(c, v) = judge.judge(m) {
            passes.push(c.pass);
            if let Some(v) = v {
                assert!(verdict.is_none(), "a second verdict");
                verdict = Some((v.passed, v.pass));
            }
        }
    }
    (passes, verdict)
}

#[test]
fn what_was_played_passes_after_ten_pulses() {
    let (passes, verdict) = run((0..12).map(|k| measured(k, 1.0, 1.0, 1.0)));
    assert_eq!(
        passes.len(),
        PULSES as usize,
        "pulses after the verdict are not judged"
    );
    assert!(passes.iter().all(|&p| p));
    assert_eq!(verdict, Some((PULSES, true)));
    // Within the tolerances: 2 % low, FWHM 2 % wide, a start 20 µs off its place.
    let near = (0..10).map(|k| {
        let mut m = measured(k, 0.98, 1.02, 1.0);
        m.start_s += if k % 2 == 0 { 20e-6 } else { 0.0 };
        m
    });
    assert_eq!(run(near).1, Some((PULSES, true)));
}

#[test]
fn a_wrong_gain_width_rate_or_a_clipped_pulse_fails() {
    // A 10 % divider on the wire.
    assert_eq!(
        run((0..10).map(|k| measured(k, 0.9, 1.0, 1.0))).1,
        Some((0, false))
    );
    // A pulse 5 % wide (a DAC or ADC clock wrong by 5 %).
    assert_eq!(
        run((0..10).map(|k| measured(k, 1.0, 1.05, 1.0))).1,
        Some((0, false))
    );
    // An ADC 0.2 % fast: the periods come 0.2 % long in its samples; the first pulse has no
    // rate to check.
    let (passes, verdict) = run((0..10).map(|k| measured(k, 1.0, 1.0, 1.002)));
    assert!(passes[0] && passes[1..].iter().all(|&p| !p), "{passes:?}");
    assert_eq!(verdict, Some((1, false)));
    // Clipped or cut: not whole, fails whatever its peak.
    let cut = (0..10).map(|k| Measured {
        whole: k != 4,
        ..measured(k, 1.0, 1.0, 1.0)
    });
    assert_eq!(run(cut).1, Some((9, false)));
    // No width measured.
    let no_width = (0..10).map(|k| Measured {
        fwhm_s: None,
        ..measured(k, 1.0, 1.0, 1.0)
    });
    assert_eq!(run(no_width).1, Some((0, false)));
}

#[test]
fn pulses_in_the_settling_time_are_not_judged_and_too_few_fail_at_the_end() {
    let mut judge = Judge::new(Played::new(GAIN, RATE, None));
    let mut early = measured(0, 1.0, 1.0, 1.0);
    early.start_s = SETTLE_S - 0.1;
    assert_eq!(judge.judge(early), Outcome::Skipped);
    for k in 0..3 {
        assert!(
            matches!(judge.judge(measured(k, 1.0, 1.0, 1.0)), Outcome::Judged(c, None) if c.pass)
        );
    }
    let v = judge
        .at_end()
        .expect("a verdict for a stream that ended early");
    assert_eq!((v.passed, v.judged, v.pass), (3, 3, false));
    assert_eq!(judge.at_end(), None, "one verdict");
    // A board's stream never ends: pulses that stop coming fail it by the deadline, once.
    let mut judge = Judge::new(Played::new(GAIN, RATE, None));
    judge.judge(measured(0, 1.0, 1.0, 1.0));
    let at = |s: f64| (s * f64::from(RATE)) as u64;
    assert_eq!(judge.deadline(at(DEADLINE_S - 0.01)), None);
    let v = judge
        .deadline(at(DEADLINE_S + 0.01))
        .expect("a verdict at the deadline");
    assert_eq!((v.passed, v.judged, v.pass), (1, 1, false));
    assert_eq!(judge.deadline(at(DEADLINE_S + 1.0)), None, "one verdict");
    assert_eq!(judge.judge(measured(1, 1.0, 1.0, 1.0)), Outcome::Skipped);
    // All ten in time: the deadline passes by without a second verdict.
    let mut judge = Judge::new(Played::new(GAIN, RATE, None));
    for k in 0..10 {
        judge.judge(measured(k, 1.0, 1.0, 1.0));
    }
    assert_eq!(judge.deadline(at(DEADLINE_S + 1.0)), None);
    // A spurious pulse (not of the played width) times nothing: the next is timed from the
    // last one of the played width.
    let mut judge = Judge::new(Played::new(GAIN, RATE, None));
    judge.judge(measured(0, 1.0, 1.0, 1.0));
    let mut spurious = measured(1, 0.5, 0.3, 1.0);
    spurious.start_s += 0.05;
    assert!(matches!(judge.judge(spurious), Outcome::Judged(c, _) if !c.pass));
    assert!(matches!(judge.judge(measured(2, 1.0, 1.0, 1.0)), Outcome::Judged(c, _) if c.pass));
    // A missed pulse between two judged ones: the rate still comes from whole periods.
    let mut judge = Judge::new(Played::new(GAIN, RATE, None));
    judge.judge(measured(0, 1.0, 1.0, 1.0));
    match judge.judge(measured(2, 1.0, 1.0, 1.0)) {
        Outcome::Judged(c, _) => {
            let r = c.rate_hz.expect("a rate");
            assert!((r - RATE).abs() <= 1.0, "{r}");
        }
        o => panic!("{o:?}"),
    }
}

#[test]
fn the_replay_starts_its_first_pulse_50_ms_in_and_scales_it_on_the_wire() {
    use impact_host::cli::selftest::codes;
    let c = codes(200_000, 500_000.0, 1.0);
    let first = c.iter().position(|&x| x != ZERO_CODE as i16).unwrap();
    // The first update after rest lands 50 ms in (sample 25 000): its code, held 10 samples.
    assert_eq!(first, 25_010, "{first}");
    assert_eq!(
        c[25_000 + 10 * PULSE_STEPS / 2],
        (ZERO_CODE + AMPLITUDE_CODES) as i16
    );
    assert_eq!(
        c[125_000 + 10 * PULSE_STEPS / 2],
        (ZERO_CODE + AMPLITUDE_CODES) as i16
    );
    // A 10 % divider scales the excursion from rest, not the rest.
    let d = codes(30_000, 500_000.0, 0.9);
    assert_eq!(d[0], ZERO_CODE as i16);
    assert_eq!(
        d[25_000 + 10 * PULSE_STEPS / 2],
        (2048.0 + 1024.0 * 0.9f64).round() as i16
    );
    // Any rate the option allows gives codes, wrapping the table.
    assert_eq!(
        code_at(u64::MAX, 1e3, u64::MAX),
        code_at(u64::MAX, 1e3, u64::MAX)
    );
}
