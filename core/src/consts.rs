//! Physical constants shared by the crate, the firmware and the host.

/// Standard gravity, m/s² (9.806 65 by definition: CGPM 1901).
pub const STANDARD_GRAVITY: f64 = 9.806_65;
