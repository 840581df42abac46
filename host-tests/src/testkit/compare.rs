//! Comparing impact outcomes field by field.

use impact_core::{ImpactOutcome, Real};

/// The report fields compared in tests and benchmarks, with their names.
pub fn fields(o: &ImpactOutcome<f64>) -> [(&'static str, f64); 7] {
    [
        ("max_deformation_m", o.max_deformation_m),
        ("crush_time_s", o.crush_time_s),
        ("contact_time_s", o.contact_time_s),
        ("rebound_velocity_m_s", o.rebound_velocity_m_s),
        ("cor", o.cor),
        ("peak_force_n", o.peak_force_n),
        ("permanent_deformation_m", o.permanent_deformation_m),
    ]
}

/// Widens an outcome to f64.
pub fn widen<R: Real>(o: &ImpactOutcome<R>) -> ImpactOutcome<f64> {
    ImpactOutcome {
        max_deformation_m: o.max_deformation_m.to_f64(),
        crush_time_s: o.crush_time_s.to_f64(),
        contact_time_s: o.contact_time_s.to_f64(),
        rebound_velocity_m_s: o.rebound_velocity_m_s.to_f64(),
        cor: o.cor.to_f64(),
        peak_force_n: o.peak_force_n.to_f64(),
        permanent_deformation_m: o.permanent_deformation_m.to_f64(),
        rhs_evaluations: o.rhs_evaluations,
    }
}

/// Largest relative error of `got` against `exact` over the report fields, with the field.
///
/// A field whose exact value is zero (no permanent set, no rebound) is compared relative to
/// its natural scale instead: deformation to `x_m`, speed to the rebound-plus-approach speed,
/// COR to 1.
pub fn max_relative_error(
    got: &ImpactOutcome<f64>,
    exact: &ImpactOutcome<f64>,
) -> (f64, &'static str) {
    let scale_for = |name: &str| match name {
        "permanent_deformation_m" => exact.max_deformation_m,
        "rebound_velocity_m_s" => exact.rebound_velocity_m_s / exact.cor.max(f64::MIN_POSITIVE),
        "cor" => 1.0,
        _ => 0.0,
    };
    let mut worst = (0.0, "");
    for ((name, g), (_, e)) in fields(got).into_iter().zip(fields(exact)) {
        let scale = e.abs().max(scale_for(name));
        let err = if scale > 0.0 {
            (g - e).abs() / scale
        } else {
            (g - e).abs()
        };
        let err = if err.is_nan() { f64::INFINITY } else { err };
        if err >= worst.0 {
            worst = (err, name);
        }
    }
    worst
}
