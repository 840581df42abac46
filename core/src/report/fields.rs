//! The report's fields in wire order: the names the firmware's `impact` log line, the host's
//! CSV header and `impact log`'s parser all use, defined once here (the firmware's defmt
//! format string must be a literal; a host test holds it to these lists).

/// Every field of [`super::ImpactReport`] but the bounce, in order, as the `impact` line and
/// the CSV name them (kinematics and fits flattened).
pub const FIELDS: [&str; 37] = [
    "index",
    "status",
    "analysis",
    "clipped",
    "flags",
    "start_sample",
    "end_sample",
    "start_s",
    "peak_time_s",
    "peak_acceleration_m_s2",
    "peak_force_n",
    "delta_v_m_s",
    "duration_s",
    "baseline_m_s2",
    "fwhm_s",
    "filtered_peak_acceleration_m_s2",
    "filtered_fwhm_s",
    "decimation",
    "impact_velocity_m_s",
    "crush_time_s",
    "max_deformation_m",
    "rebound_velocity_m_s",
    "cor",
    "separation_deformation_m",
    "permanent_deformation_m",
    "absorbed_energy_j",
    "two_phase_kc_n_m",
    "two_phase_kr_n_m",
    "two_phase_c_n_s_m",
    "two_phase_permanent_deformation_m",
    "two_phase_residual",
    "nonlinear_k",
    "nonlinear_c_s_m",
    "nonlinear_exponent",
    "nonlinear_residual",
    "hertz_k",
    "hertz_residual",
];

/// The bounce of a train ([`super::Bounce`]), after [`FIELDS`] (all `none` for a train's
/// first impact).
pub const BOUNCE_FIELDS: [&str; 5] = [
    "bounce_number",
    "flight_s",
    "v0_flight_m_s",
    "v0_rebound_m_s",
    "landing_height_m",
];
