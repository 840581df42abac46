//! The per-impact analysis of a finished capture: acceleration (CFC-filtered if the scene asks),
//! width at half maximum, and, when the approach speed is known, the kinematics (crush time,
//! deformations, COR) and the model fits. Runs once per impact, wherever the capture was
//! handed (inline on the host, in a low-priority task on the firmware).

use crate::capture::{Capture, Summary};
use crate::report::{self, Analysis, ImpactReport, Kinematics, Status};
use crate::scene::Scene;
use crate::stream::Deviation;

/// Scratch memory of the analysis: the acceleration of every captured sample, m/s².
/// `Workspace::new()` is all zeros, so a `static` one starts in `.bss`.
pub struct Workspace<const CAP: usize> {
    accel: [f32; CAP],
}

impl<const CAP: usize> Default for Workspace<CAP> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const CAP: usize> Workspace<CAP> {
    pub const fn new() -> Self {
        Self { accel: [0.0; CAP] }
    }
}

/// Where `|a|` crosses `level` between samples `i` and `i + 1` (fractional sample index),
/// if both samples are held.
fn abs_crossing(a: &[f32], i: usize, level: f32) -> Option<f32> {
    let (&y0, &y1) = (a.get(i)?, a.get(i + 1)?);
    let dy = libm::fabsf(y1) - libm::fabsf(y0);
    let f = if dy == 0.0 {
        0.0
    } else {
        ((level - libm::fabsf(y0)) / dy).clamp(0.0, 1.0)
    };
    Some(i as f32 + f)
}

/// The first sample of largest |a| (index and value); `(onset, 0)` if every sample is 0.
fn scan_peak(a: &[f32], onset: usize) -> (usize, f32) {
    a.iter().enumerate().fold((onset, 0.0f32), |best, (i, &v)| {
        if libm::fabsf(v) > libm::fabsf(best.1) {
            (i, v)
        } else {
            best
        }
    })
}

/// Width at half of `|a[peak]|`: from the last sample below half before the peak to the first
/// after it, both interpolated; `None` if either side lies outside the window.
fn fwhm(a: &[f32], peak: usize) -> Option<f32> {
    let half = libm::fabsf(*a.get(peak)?) / 2.0;
    let left = (0..peak)
        .rev()
        .find(|&i| a.get(i).is_some_and(|v| libm::fabsf(*v) < half))
        .and_then(|i| abs_crossing(a, i, half))?;
    let right = (peak..a.len().saturating_sub(1))
        .find(|&i| a.get(i + 1).is_some_and(|v| libm::fabsf(*v) < half))
        .and_then(|i| abs_crossing(a, i, half))?;
    Some(right - left)
}

/// Analyses a finished capture: the streaming fields of its summary, and the analysis fields.
pub fn analyse<const CAP: usize>(
    capture: &Capture<CAP>,
    scene: &Scene,
    work: &mut Workspace<CAP>,
) -> ImpactReport {
    let s = capture.summary();
    let mut r = report::streaming(s, scene);
    r.analysis = Analysis::Full;
    let cal = &scene.calibration;
    let fs = cal.sample_rate_hz as f64;
    let samples = capture.samples();
    let a = work.accel.get_mut(..samples.len()).unwrap_or(&mut []);
    let per_count = report::per_count(scene, s.base_n);
    let deviation = Deviation::new(s.base_sum, s.base_n);
    for (slot, &x) in a.iter_mut().zip(samples) {
        *slot = deviation.of(x) as f32 * per_count;
    }
    let mut filtered = false;
    #[cfg(feature = "cfc")]
    if let Some(class) = scene.cfc {
        if let Some(b) = crate::signal::cfc::Biquad::cfc(class, fs) {
            b.phaseless_f32(a);
            filtered = true;
        }
    }
    let a = &*a;
    let onset = s.onset_index.saturating_sub(s.first_index) as usize;
    // The peak of the analysed signal. Unfiltered, the first largest |a| is the first largest
    // |d| the stream found: a = d · per_count is strictly monotonic in |d| while |d| < 2^22
    // (neighbouring integers stay more than an f32 ulp apart after the product), so the scan
    // is skipped.
    let raw = s
        .peak_index
        .checked_sub(s.first_index)
        .and_then(|i| usize::try_from(i).ok())
        .and_then(|i| a.get(i).map(|&v| (i, v)));
    let (peak_i, peak_a) = match raw {
        Some(found) if !filtered && s.peak_d != 0 && s.peak_d.unsigned_abs() < 1 << 22 => found,
        _ => scan_peak(a, onset),
    };
    #[cfg(test)]
    {
        let scan = scan_peak(a, onset);
        assert_eq!((peak_i, peak_a.to_bits()), (scan.0, scan.1.to_bits()));
    }
    if filtered {
        r.filtered_peak_acceleration_m_s2 = Some(peak_a);
    }
    r.fwhm_s = fwhm(a, peak_i).map(|w| (w as f64 / fs) as f32);

    // Times relative to the capture's first sample.
    let at = |index: u64, offset: f32| (index as f64 - s.first_index as f64 + offset as f64) as f32;
    let t_on = at(s.onset_index, s.touch_offset);
    let t_sep = s.separation_index.map(|i| at(i, s.separation_offset));
    r.kinematics = match (s.v0_m_s, s.status, t_sep) {
        (Some(v0), Status::Complete, Some(t_sep)) if s.onset_index >= s.first_index => {
            kinematics(samples, s, onset, v0, t_on, t_sep, scene)
        }
        _ => None,
    };
    #[cfg(feature = "fit")]
    if let (Some(k), Some(m)) = (r.kinematics, scene.mass_kg) {
        if scene.fits.any() {
            let separation = s
                .separation_index
                .map_or(a.len(), |i| i.saturating_sub(s.first_index) as usize);
            r.fits = crate::fit::fit(
                &crate::fit::Trajectory {
                    accel: a,
                    onset,
                    separation,
                    v0: k.impact_velocity_m_s,
                    dt: 1.0 / cal.sample_rate_hz,
                    mass_kg: m,
                    x_m: k.max_deformation_m,
                    x0_m: k.impact_velocity_m_s * (onset as f32 - t_on).max(0.0)
                        / cal.sample_rate_hz,
                },
                &scene.fits,
            );
        }
    }
    r
}

/// Velocity and deformation by exact summation of the raw counts from the onset.
fn kinematics(
    samples: &[i16],
    s: &Summary,
    onset: usize,
    v0: f32,
    t_on: f32,
    t_sep: f32,
    scene: &Scene,
) -> Option<Kinematics> {
    let fs = scene.calibration.sample_rate_hz as f64;
    let per_d = scene.calibration.gain_m_s2_per_count as f64 / s.base_n.max(1) as f64;
    let delta_v = (s.total_c as f64 * per_d / fs) as f32;
    let dt = 1.0 / fs;
    let v0d = v0 as f64;
    let kv = per_d / fs;
    if !(kv > 0.0 && kv.is_finite() && v0d > 0.0) {
        return None;
    }
    // Between the edge crossing and the onset sample the body still moves at ~v0.
    let lead = (onset as f64 - t_on as f64).max(0.0);
    let x_lead = v0d * lead * dt;
    // After k samples from the onset, with C_k = Σ d (exact), the velocity is
    // v_k = v0 - kv C_k and the trapezoid deformation x_k = x_lead + dt (k v0 - kv T_k / 2),
    // with T_k = Σ_{j<k} (C_j + C_{j+1}) also exact: the loop below is integer-only (no
    // soft-float per sample on the Cortex-M4) and loses nothing to rounding until the end.
    let velocity = |c: i64| v0d - kv * c as f64;
    let deformation = |k: usize, t: i128| x_lead + dt * (k as f64 * v0d - kv * t as f64 / 2.0);
    // Stopped (v <= 0) once C >= v0 / kv.
    let c_stop = libm::ceil(v0d / kv);
    let c_stop = if c_stop < i64::MAX as f64 {
        c_stop as i64
    } else {
        i64::MAX
    };
    let mut c: i64 = 0;
    let mut t: i128 = 0;
    let mut crush: Option<(f64, f64)> = None; // (time index, x_m)
    let mut at_sep: Option<f64> = None;
    let sep_floor = libm::floorf(t_sep) as usize;
    let sep_frac = (t_sep - sep_floor as f32) as f64;
    let from_onset = samples.get(onset..).unwrap_or(&[]);
    for (k, &raw) in from_onset.iter().enumerate() {
        let d = raw as i64 * s.base_n - s.base_sum;
        let c_next = c + d;
        let t_next = t + (c + c_next) as i128;
        let i = onset + k;
        if crush.is_none() && c_next >= c_stop && c < c_stop {
            let (v, v_next) = (velocity(c), velocity(c_next));
            let f = v / (v - v_next);
            crush = Some((i as f64 + f, deformation(k, t) + dt * f * v / 2.0));
        }
        if i == sep_floor {
            let (x, x_next) = (deformation(k, t), deformation(k + 1, t_next));
            at_sep = Some(x + sep_frac * (x_next - x));
            break;
        }
        c = c_next;
        t = t_next;
    }
    let (t_crush, x_m) = crush?;
    let x_p = at_sep?;
    let rebound = delta_v - v0;
    Some(Kinematics {
        impact_velocity_m_s: v0,
        crush_time_s: ((t_crush - t_on as f64) * dt) as f32,
        max_deformation_m: x_m as f32,
        rebound_velocity_m_s: rebound,
        cor: rebound / v0,
        permanent_deformation_m: x_p as f32,
        absorbed_energy_j: scene
            .mass_kg
            .map(|m| 0.5 * m * (v0 * v0 - rebound * rebound)),
    })
}
