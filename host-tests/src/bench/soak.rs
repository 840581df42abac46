//! Soak: a long stream with many impacts, generated on the fly, every one accounted for.

use std::time::Instant;

use impact_core::{Calibration, ImpactReport, Monitor, Scene, Status};
use serde::Serialize;

use super::BenchError;

/// What a soak run found.
#[derive(Clone, Debug, Serialize)]
pub struct SoakResult {
    pub samples: u64,
    pub impacts_inserted: u64,
    pub impacts_reported: u64,
    /// Reports whose start is more than 20 samples from an inserted pulse, or not complete.
    pub mismatched: u64,
    pub seconds: f64,
    pub samples_per_second: f64,
}

/// Streams `samples` samples of ±1-count noise with a half-sine pulse (`pulse_len` samples,
/// 200 counts) every `spacing` samples through a monitor at 1 MS/s, in blocks of 256.
pub fn run(samples: u64, spacing: u64, pulse_len: u64) -> Result<SoakResult, BenchError> {
    if spacing <= pulse_len + 8192 {
        return Err(BenchError::Spacing);
    }
    super::on_big_stack(move || run_inner(samples, spacing, pulse_len))
}

fn run_inner(samples: u64, spacing: u64, pulse_len: u64) -> Result<SoakResult, BenchError> {
    let mut scene = Scene::new(
        Calibration {
            gain_m_s2_per_count: 1.0,
            sample_rate_hz: 1e6,
        },
        40.0,
    );
    scene.edge_m_s2 = 8.0;
    scene.hold_s = 1e-3;
    let mut m = Monitor::<4096, 16384>::new(scene)?;
    let pulse: Vec<i16> = (0..pulse_len)
        .map(|k| (200.0 * (std::f64::consts::PI * k as f64 / pulse_len as f64).sin()) as i16)
        .collect();
    let first = spacing / 2;
    let (mut reported, mut mismatched) = (0u64, 0u64);
    let mut block = [0i16; 256];
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let t = Instant::now();
    let mut at = 0u64;
    while at < samples {
        let n = (samples - at).min(256) as usize;
        for (k, slot) in block.iter_mut().take(n).enumerate() {
            let i = at + k as u64;
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let noise = (state % 3) as i16 - 1;
            let in_train = i.checked_sub(first).map(|d| (d / spacing, d % spacing));
            let p = match in_train {
                Some((_, off)) if off < pulse_len => pulse[off as usize],
                _ => 0,
            };
            *slot = 1000 + noise + p;
        }
        m.push_block(&block[..n], &mut |r: &ImpactReport| {
            reported += 1;
            let off = r.start_sample.saturating_sub(first) % spacing;
            let near = off <= 20 || off >= spacing - 20;
            if !near || r.status != Status::Complete {
                mismatched += 1;
            }
        });
        at += n as u64;
    }
    m.finish(&mut |_r: &ImpactReport| reported += 1);
    let seconds = t.elapsed().as_secs_f64();
    let inserted = if samples > first {
        (samples - first).div_ceil(spacing)
    } else {
        0
    };
    // A pulse cut by the end of the stream is reported (as stream-ended) but not complete.
    Ok(SoakResult {
        samples: m.counters().samples,
        impacts_inserted: inserted,
        impacts_reported: reported,
        mismatched,
        seconds,
        samples_per_second: samples as f64 / seconds,
    })
}
