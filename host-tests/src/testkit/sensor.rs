//! A generated drop as a sensor records it: the generator's specific force through a 16-bit
//! ADC with a code of noise, as a `time_s,accel_g` CSV (the drop tests' and the emulated
//! board's input).

use crate::drop::{ContactTruth, Drop};

/// `drop` rendered for `seconds` at `rate` as a 16-bit ADC over ±`full_scale` m/s² records
/// it (uniform noise of ±1 code, quantised: a sensor whose flat stretches do not vary is
/// stuck), written as `time_s,accel_g`; and the contacts' truth. None if the generator
/// refuses the drop.
pub fn csv(
    drop: &Drop,
    rate: f64,
    seconds: f64,
    full_scale: f64,
) -> Option<(String, Vec<ContactTruth>)> {
    let r = drop.render(rate, (seconds * rate) as usize).ok()?;
    Some((csv_of(&r.accel_m_s2, rate, full_scale), r.contacts))
}

/// Readings `accel` (m/s², sample `k` at `k / rate`) as [`csv()`] records them.
pub fn csv_of(accel: &[f64], rate: f64, full_scale: f64) -> String {
    let g = impact_core::consts::STANDARD_GRAVITY;
    let lsb = 2.0 * full_scale / 65536.0;
    let mut s = String::from("time_s,accel_g\n");
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    for (k, a) in accel.iter().enumerate() {
        // Uniform noise of ±1 code (xorshift).
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        let noise = 2.0 * ((seed >> 11) as f64 / (1u64 << 53) as f64) - 1.0;
        let q = ((a / lsb + noise).round() * lsb).clamp(-full_scale, full_scale);
        s.push_str(&format!("{:.9},{:.9e}\n", k as f64 / rate, q / g));
    }
    s
}
