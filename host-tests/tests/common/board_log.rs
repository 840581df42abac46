//! The board's log lines as the firmware prints them (docs/board.md), for tests that feed
//! `impact log` and `impact watch` logs of any length.
#![allow(dead_code)] // not every test file needs each

/// A scene line as the emulator writes it (rate 500 kS/s, the seed bench's gain).
pub const SCENE: &str = "0.000000 INFO  scene rate_hz=500000.0 gain_m_s2_per_count=0.0032348644 mass_kg=0.06 v0_m_s=1.3357 drop_height_m=none trigger_m_s2=4.8433614 edge_m_s2=0.9686723 hold_s=0.002 max_impact_s=1.0 settle_s=0.05 clip_low=-32768 clip_high=32767 cfc=none trigger_cfc=none two_phase=true nonlinear=true fit_exponent=true exponent=1.0 hertz=true train=none gravity_m_s2=none max_flight_s=none srs=false wave_every=0";

/// Impact `index` of a train 80 ms apart at 500 kS/s, as the firmware prints it (line `seq`),
/// with `field=value` replacing the field's value when given.
pub fn impact_line(seq: u64, index: u64, set: Option<(&str, &str)>) -> String {
    let start = 5085 + 40_000 * index;
    let line = format!(
        "{:.6} INFO  impact seq={seq} index={index} status=complete analysis=full clipped=false flags=0 start_sample={start} end_sample={} start_s={:?} peak_time_s={:?} peak_acceleration_m_s2=96.873055 peak_force_n=5.812383 delta_v_m_s=1.5073051 duration_s=0.025262618 baseline_m_s2=6.642605 fwhm_s=0.016305983 filtered_peak_acceleration_m_s2=none filtered_fwhm_s=none impact_velocity_m_s=1.3357 crush_time_s=0.021879222 max_deformation_m=0.018607104 rebound_velocity_m_s=0.17160511 cor=0.12847579 separation_deformation_m=0.018234435 permanent_deformation_m=0.018234435 absorbed_energy_j=0.052639388 two_phase_kc_n_m=309.24127 two_phase_kr_n_m=12376.585 two_phase_c_n_s_m=2.005761 two_phase_permanent_deformation_m=0.018207124 two_phase_residual=0.0023348597 nonlinear_k=2706.92 nonlinear_c_s_m=0.91664284 nonlinear_exponent=1.6248286 nonlinear_residual=0.12266807 hertz_k=2121.7961 hertz_residual=0.20517163 bounce_number=none flight_s=none v0_flight_m_s=none v0_rebound_m_s=none landing_height_m=none report_latency_s=0.0248",
        (start + 13_533) as f64 / 5e5,
        start + 13_533,
        start as f64 / 5e5,
        (start + 10_000) as f64 / 5e5,
    );
    match set {
        None => line,
        Some((field, value)) => {
            let (head, tail) = line.split_once(&format!(" {field}=")).unwrap();
            let rest = tail.split_once(' ').map_or("", |(_, r)| r);
            format!("{head} {field}={value} {rest}")
        }
    }
}

pub fn heartbeat(seq: u64, samples: u64, impacts: u64) -> String {
    format!(
        "INFO  heartbeat seq={seq} samples={samples} rate_hz=500000.0 impacts={impacts} \
         reports_dropped=0 samples_lost=0 analyses_skipped=0 lines_dropped=0"
    )
}

pub fn summary(seq: u64, samples: u64, impacts: u64) -> String {
    format!(
        "INFO  summary seq={seq} result=ok end=complete samples={samples} rate_hz=500000.0 \
         impacts={impacts} samples_lost=0 analyses_skipped=0 reports_dropped=0 \
         reports_out_of_order=0 lines_dropped=0"
    )
}
