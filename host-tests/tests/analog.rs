//! The board's analog scale from the supply it measures (`impact_firmware::analog`), on the
//! host with simulated VREFINT conversions: no board is attached here, so the conversion
//! itself (`firmware/src/board/stm32/adc.rs`, `vdda_v`) has not run on silicon.

use impact_firmware::analog::{
    vdda_v, Scale, Sensor, VddaError, FULL_SCALE_COUNTS, NOMINAL_VDDA_V, SENSOR,
};

/// A part's VREFINT, volts (typical 1.21 V; 1.18–1.24 V over parts and temperature).
const VREFINT_V: f32 = 1.21;

/// The factory's calibration word: VREFINT converted at 3.3 V.
fn cal(vrefint_v: f32) -> u16 {
    (vrefint_v / 3.3 * FULL_SCALE_COUNTS).round() as u16
}

/// The mean of 16 conversions of VREFINT at supply `vdda`, each rounded to a count after
/// ±1 count of deterministic noise.
fn reading(vrefint_v: f32, vdda: f32) -> f32 {
    let ideal = vrefint_v / vdda * FULL_SCALE_COUNTS;
    let sum: f32 = (0..16)
        .map(|i| (ideal + [-1.0, 0.0, 1.0, 0.0][i % 4]).round())
        .sum();
    sum / 16.0
}

#[test]
fn the_supply_comes_from_vrefint_and_its_calibration_within_a_tenth_of_a_percent() {
    for vrefint in [1.18, 1.21, 1.24] {
        for vdda in [2.45, 2.9, 3.0, 3.1, 3.3, 3.55] {
            let v = vdda_v(cal(vrefint), reading(vrefint, vdda)).expect("a supply");
            assert!(
                (v / vdda - 1.0).abs() < 1e-3,
                "VREFINT {vrefint} V at {vdda} V: {v} V"
            );
        }
    }
}

/// The issue's numbers: a sensor scaled for 3.3 V (zero at 1.65 V, ±800 m/s² over 0–3.3 V)
/// on the Discovery's 3.0 V reads its zero near code 2253, at 0.355 m/s² per count, and
/// clips near +654 m/s²; the old fixed scale (0.3906) read every value ~10 % high.
#[test]
fn a_three_point_three_volt_scale_on_a_three_volt_board_is_what_the_issue_measured() {
    let sensor = Sensor {
        v_per_m_s2: 1.65 / 800.0,
        zero_v: 1.65,
    };
    let s = Scale::new(3.0, sensor);
    assert!((s.zero_counts - 2252.8).abs() < 0.05, "{s:?}");
    assert!((s.gain_m_s2_per_count - 0.3551).abs() < 1e-4, "{s:?}");
    assert!((s.range_m_s2.1 - 654.2).abs() < 0.5, "{s:?}");
    let old = 1600.0 / 4096.0;
    assert!(
        old / s.gain_m_s2_per_count > 1.09,
        "the fixed scale read ~10 % high"
    );
}

/// The default sensor at the Discovery's 3.0 V is the compiled-in scene's scale, zero at
/// mid-scale and symmetric within a count; a board whose supply is 2 % off gets a scale 2 %
/// off, not the nominal one.
#[test]
fn the_default_sensor_at_three_volts_is_the_compiled_in_scale() {
    let s = Scale::new(NOMINAL_VDDA_V, SENSOR);
    let bench = impact_firmware::scene::BENCH
        .calibration
        .gain_m_s2_per_count;
    // (The host builds the firmware library without `adxl375`: the ADC's scene.)
    assert!(
        (s.gain_m_s2_per_count / bench - 1.0).abs() < 1e-6,
        "{s:?} vs {bench}"
    );
    assert!((s.zero_counts - 2048.0).abs() < 1e-3, "{s:?}");
    assert!((s.range_m_s2.0 + 800.0).abs() < 0.01, "{s:?}");
    assert!((s.range_m_s2.1 - 799.6).abs() < 0.01, "{s:?}");
    let low = Scale::new(
        vdda_v(cal(VREFINT_V), reading(VREFINT_V, 2.94)).unwrap(),
        SENSOR,
    );
    let ratio = low.gain_m_s2_per_count / s.gain_m_s2_per_count;
    assert!((ratio - 0.98).abs() < 1e-3, "{ratio}");
}

#[test]
fn a_reading_that_cannot_be_a_supply_is_refused_by_name() {
    let c = cal(VREFINT_V);
    assert_eq!(vdda_v(0, 1500.0), Err(VddaError::NoCalibration(0)));
    assert_eq!(
        vdda_v(u16::MAX, 1500.0),
        Err(VddaError::NoCalibration(u16::MAX))
    );
    // A word that is no conversion of VREFINT at 3.3 V (0.8 V).
    assert_eq!(vdda_v(993, 1500.0), Err(VddaError::NoCalibration(993)));
    assert_eq!(vdda_v(c, 0.0), Err(VddaError::NoReading));
    assert_eq!(vdda_v(c, f32::NAN), Err(VddaError::NoReading));
    assert_eq!(vdda_v(c, -3.0), Err(VddaError::NoReading));
    // VREFINT read as if the supply were 5 V, 2 V or 1 V: no F407 runs there (at 2 V not with
    // this ADC clock).
    for vdda in [1.0f32, 2.0, 5.0] {
        match vdda_v(c, reading(VREFINT_V, vdda)) {
            Err(VddaError::OutOfRange(v)) => assert!((v / vdda - 1.0).abs() < 0.01),
            other => panic!("{vdda} V: {other:?}"),
        }
    }
    assert!(matches!(
        vdda_v(c, f32::INFINITY),
        Err(VddaError::OutOfRange(_))
    ));
}

#[test]
fn a_supply_that_moved_since_start_up_is_warned_with_the_error_it_makes() {
    use impact_firmware::analog::{Scale, SupplyChange, SENSOR, WARN_CHANGE};
    // 3.00 V at start-up, 3.03 V now: 1 % up, and the start-up gain reads 1/1.01 − 1 low.
    let c = SupplyChange::new(3.0, 3.03);
    assert!((c.change - 0.01).abs() < 1e-6, "{c:?}");
    assert!(c.warn);
    // The error is the one the start-up scale makes against today's true scale.
    let (then, now) = (Scale::new(3.0, SENSOR), Scale::new(3.03, SENSOR));
    let truth = then.gain_m_s2_per_count / now.gain_m_s2_per_count - 1.0;
    assert!((c.reading_error - truth).abs() < 1e-6, "{c:?} vs {truth}");
    // Within the measurement's scatter: no warning, either way.
    for now in [
        3.0 * (1.0 + WARN_CHANGE * 0.9),
        3.0 * (1.0 - WARN_CHANGE * 0.9),
        3.0,
    ] {
        assert!(!SupplyChange::new(3.0, now).warn, "{now}");
    }
    assert!(SupplyChange::new(3.0, 3.0 * (1.0 - WARN_CHANGE * 1.1)).warn);
}
