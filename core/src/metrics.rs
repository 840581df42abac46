//! The per-impact report: what one captured pulse says (peak, Δv, widths) and, when the
//! approach speed is known, the impact's kinematics (crush time, deformations, COR).

use crate::scene::Scene;

/// How an impact's capture ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Status {
    /// The signal came back to the baseline and stayed there.
    Complete,
    /// The stream ended inside the impact.
    StreamEnded,
    /// The capture buffer filled up: Δv and the peak cover the whole impact, the rest only
    /// the captured part (no kinematics, no fits).
    BufferFull,
    /// The signal stayed away from the baseline longer than the scene's maximum impact time
    /// (stuck, drifting or disconnected sensor); the baseline is learned again.
    TooLong,
}

/// What the deceleration says once `v0` is known. SI.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Kinematics {
    /// Approach speed used, m/s.
    pub impact_velocity_m_s: f32,
    /// From first touch to zero velocity, s.
    pub crush_time_s: f32,
    /// Deformation at zero velocity, m.
    pub max_deformation_m: f32,
    /// Speed after the impact (`Δv - v0`), m/s.
    pub rebound_velocity_m_s: f32,
    /// `v' / v0`.
    pub cor: f32,
    /// Deformation left at separation, m.
    pub permanent_deformation_m: f32,
    /// `m (v0² - v'²) / 2`, J (when the mass is known).
    pub absorbed_energy_j: Option<f32>,
}

/// Two-phase Kelvin–Voigt parameters identified from one impact.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TwoPhaseFit {
    pub kc_n_m: f32,
    pub kr_n_m: f32,
    pub c_n_s_m: f32,
    pub permanent_m: f32,
    /// RMS force residual relative to the peak force.
    pub residual: f32,
}

/// Nonlinear `F = k x^n (1 + c v)` identified from one impact.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct NonlinearFit {
    /// N/m^n.
    pub k: f32,
    /// s/m.
    pub c_s_m: f32,
    pub n: f32,
    pub residual: f32,
}

/// Hertz `F = K x^1.5` identified from one impact.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct HertzFit {
    /// N/m^1.5.
    pub k: f32,
    pub residual: f32,
}

/// The identified models (each present if asked for and identifiable).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Fits {
    pub two_phase: Option<TwoPhaseFit>,
    pub nonlinear: Option<NonlinearFit>,
    pub hertz: Option<HertzFit>,
}

/// One impact. Times are from the start of the stream unless named otherwise.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ImpactReport {
    /// 0 for the stream's first impact.
    pub index: u32,
    pub status: Status,
    /// The sensor reached a rail inside the impact: peak and Δv are lower bounds.
    pub clipped: bool,
    /// Sample index of the pulse's first sample above the edge level.
    pub start_sample: u64,
    /// First touch (edge crossing), s.
    pub start_s: f64,
    /// Time of the peak, s.
    pub peak_time_s: f64,
    /// Signed peak deceleration, m/s² (positive: the body was slowed).
    pub peak_acceleration_m_s2: f32,
    /// `m a` at the peak, N (when the mass is known).
    pub peak_force_n: Option<f32>,
    /// Velocity change over the impact, m/s (`v0 + v'` for a rebound).
    pub delta_v_m_s: f32,
    /// From first touch to separation (edge crossings), s.
    pub duration_s: f32,
    /// Width at half the peak, s.
    pub fwhm_s: f32,
    /// Baseline the pulse was measured from, m/s² (sensor offset).
    pub baseline_m_s2: f32,
    pub kinematics: Option<Kinematics>,
    pub fits: Fits,
}

/// A captured pulse, as the monitor hands it over.
pub(crate) struct Window<'a> {
    /// Raw samples from the capture's start.
    pub samples: &'a [i16],
    /// Acceleration of each captured sample, m/s² (filtered if the scene asks), same length.
    pub accel: &'a [f32],
    /// Stream index of `samples[0]`.
    pub first_index: u64,
    /// Index (in `samples`) of the first sample above the edge level.
    pub onset: usize,
    /// Index of the first sample back below the edge level after the pulse, if seen.
    pub separation: Option<usize>,
    /// Exact `Σ d` over the whole impact (also beyond a full capture), in `W·counts`.
    pub total_c: i64,
    /// Baseline as the rational `base_sum / base_n` counts.
    pub base_sum: i64,
    pub base_n: i64,
    pub peak_d: i64,
    pub peak_index: u64,
    pub status: Status,
    pub clipped: bool,
}

/// Linear interpolation: where `y` crosses `level` between `(x0, y0)` and `(x0 + 1, y1)`.
fn crossing(x0: f32, y0: f32, y1: f32, level: f32) -> f32 {
    let dy = y1 - y0;
    if dy == 0.0 {
        x0
    } else {
        x0 + ((level - y0) / dy).clamp(0.0, 1.0)
    }
}

/// Where `|a|` crosses `level` between samples `i` and `i + 1` (fractional sample index),
/// if both samples are held.
fn abs_crossing(a: &[f32], i: usize, level: f32) -> Option<f32> {
    let (&y0, &y1) = (a.get(i)?, a.get(i + 1)?);
    Some(crossing(i as f32, libm::fabsf(y0), libm::fabsf(y1), level))
}

/// Where the pulse's flank extrapolates to zero: a least-squares line through `|a|` over the
/// samples between the edge level and `FLANK` times it, walking from `from` forwards (onset)
/// or backwards (separation). `None` if the flank is too short or not monotonic (a pulse that
/// starts with a jump: then the edge crossing is used).
fn flank_zero(a: &[f32], from: usize, forward: bool, edge: f32) -> Option<f32> {
    const FLANK: f32 = 4.0;
    let (mut n, mut sx, mut sy, mut sxx, mut sxy) = (0u32, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let mut i = from;
    while let Some(&v) = a.get(i) {
        let y = libm::fabsf(v);
        if y > FLANK * edge || n >= 4096 {
            break;
        }
        let x = i as f64;
        n += 1;
        sx += x;
        sy += y as f64;
        sxx += x * x;
        sxy += x * y as f64;
        if forward {
            i += 1;
        } else if let Some(prev) = i.checked_sub(1) {
            i = prev;
        } else {
            break;
        }
    }
    if n < 3 {
        return None;
    }
    let nf = n as f64;
    let den = nf * sxx - sx * sx;
    let slope = (nf * sxy - sx * sy) / den;
    let icept = (sy - slope * sx) / nf;
    let zero = -icept / slope;
    let span = nf + 1.0;
    let f = from as f64;
    // The line must pass through the edge level next to `from` (where the signal was still
    // below it): a pulse that starts or ends with a jump (Kelvin–Voigt's `c v0`) does not,
    // and its edge crossing is the better estimate.
    let outside = if forward { f - 1.0 } else { f + 1.0 };
    let consistent = icept + slope * outside <= 1.5 * edge as f64;
    let ok = consistent
        && if forward {
            slope > 0.0 && zero <= f && zero >= f - span
        } else {
            slope < 0.0 && zero >= f && zero <= f + span
        };
    ok.then_some(zero as f32)
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

/// Builds the report of one window.
pub(crate) fn report(w: &Window<'_>, scene: &Scene, index: u32, v0: Option<f32>) -> ImpactReport {
    let cal = &scene.calibration;
    let fs = cal.sample_rate_hz as f64;
    let n = w.base_n.max(1) as f64;
    // Physical acceleration per unit of d = W x - S.
    let per_d = cal.gain_m_s2_per_count as f64 / n;
    let a = w.accel;
    let edge = scene.edge_m_s2;

    // The peak on the captured (possibly filtered) signal; if the capture overflowed, the
    // raw peak seen over the whole impact.
    let raw_peak = (w.peak_d as f64 * per_d) as f32;
    let delta_v = (w.total_c as f64 * per_d / fs) as f32;
    let t_on = flank_zero(a, w.onset, true, edge).unwrap_or_else(|| {
        w.onset
            .checked_sub(1)
            .and_then(|i| abs_crossing(a, i, edge))
            .unwrap_or(w.onset as f32)
    });

    // Peak and half-width on the (possibly filtered) acceleration. Unfiltered, the first
    // largest |a| is the first largest |d| the monitor already found: a = d · per_count is
    // strictly monotonic in |d| while |d| < 2^22 (neighbouring integers stay more than an
    // f32 ulp apart after the product), so the scan over the window is skipped.
    let raw_i = (w.peak_index.checked_sub(w.first_index)).map(|i| i as usize);
    let raw_peak_exact = scene.cfc.is_none()
        && w.status != Status::BufferFull
        && w.peak_d != 0
        && w.peak_d.unsigned_abs() < 1 << 22;
    let (peak_i, peak_a) = match (
        raw_peak_exact,
        raw_i.and_then(|i| a.get(i).map(|&v| (i, v))),
    ) {
        (true, Some(found)) => found,
        _ => scan_peak(a, w.onset),
    };
    #[cfg(test)]
    {
        let scan = scan_peak(a, w.onset);
        assert_eq!((peak_i, peak_a.to_bits()), (scan.0, scan.1.to_bits()));
    }
    let (peak_acc, peak_time) = if w.status == Status::BufferFull {
        (raw_peak, w.peak_index as f64 / fs)
    } else {
        (peak_a, (w.first_index + peak_i as u64) as f64 / fs)
    };
    let half = libm::fabsf(peak_a) / 2.0;
    // Half-maximum crossings: the last sample below half before the peak, the first after.
    let left = (0..peak_i)
        .rev()
        .find(|&i| a.get(i).is_some_and(|v| libm::fabsf(*v) < half))
        .and_then(|i| abs_crossing(a, i, half))
        .unwrap_or(peak_i as f32);
    let right = (peak_i..a.len().saturating_sub(1))
        .find(|&i| a.get(i + 1).is_some_and(|v| libm::fabsf(*v) < half))
        .and_then(|i| abs_crossing(a, i, half))
        .unwrap_or(peak_i as f32);
    let t_sep = w.separation.and_then(|s| {
        let last = s.checked_sub(1)?;
        let edge_crossing = abs_crossing(a, last, edge)?;
        Some(flank_zero(a, last, false, edge).unwrap_or(edge_crossing))
    });
    let end_for_duration = t_sep.unwrap_or(a.len() as f32);

    let kinematics = match (v0, w.status, t_sep) {
        (Some(v0), Status::Complete, Some(t_sep)) => {
            kinematics(w, v0, t_on, t_sep, per_d, fs, delta_v, scene.mass_kg)
        }
        _ => None,
    };
    #[cfg(feature = "fit")]
    let fits = match (kinematics, scene.mass_kg) {
        (Some(k), Some(m)) if scene.fits.any() => crate::fit::fit(
            &crate::fit::Trajectory {
                accel: a,
                onset: w.onset,
                separation: w.separation.unwrap_or(a.len()),
                v0: k.impact_velocity_m_s,
                dt: 1.0 / cal.sample_rate_hz,
                mass_kg: m,
                x_m: k.max_deformation_m,
                x0_m: k.impact_velocity_m_s * (w.onset as f32 - t_on).max(0.0) / cal.sample_rate_hz,
            },
            &scene.fits,
        ),
        _ => Fits::default(),
    };
    #[cfg(not(feature = "fit"))]
    let fits = Fits::default();

    let start = w.first_index as f64;
    ImpactReport {
        index,
        status: w.status,
        clipped: w.clipped,
        start_sample: w.first_index + w.onset as u64,
        start_s: (start + t_on as f64) / fs,
        peak_time_s: peak_time,
        peak_acceleration_m_s2: peak_acc,
        peak_force_n: scene.mass_kg.map(|m| m * peak_acc),
        delta_v_m_s: delta_v,
        duration_s: ((end_for_duration - t_on) as f64 / fs) as f32,
        fwhm_s: ((right - left) as f64 / fs) as f32,
        baseline_m_s2: (w.base_sum as f64 * per_d) as f32,
        kinematics,
        fits,
    }
}

/// Velocity and deformation by exact summation of the raw counts from the onset.
#[allow(clippy::too_many_arguments)]
fn kinematics(
    w: &Window<'_>,
    v0: f32,
    t_on: f32,
    t_sep: f32,
    per_d: f64,
    fs: f64,
    delta_v: f32,
    mass: Option<f32>,
) -> Option<Kinematics> {
    let dt = 1.0 / fs;
    let v0d = v0 as f64;
    let kv = per_d / fs;
    if !(kv > 0.0 && kv.is_finite() && v0d > 0.0) {
        return None;
    }
    // Between the edge crossing and the onset sample the body still moves at ~v0.
    let lead = (w.onset as f64 - t_on as f64).max(0.0);
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
    let samples = w.samples.get(w.onset..).unwrap_or(&[]);
    for (k, &raw) in samples.iter().enumerate() {
        let d = raw as i64 * w.base_n - w.base_sum;
        let c_next = c + d;
        let t_next = t + (c + c_next) as i128;
        let i = w.onset + k;
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
        absorbed_energy_j: mass.map(|m| 0.5 * m * (v0 * v0 - rebound * rebound)),
    })
}
