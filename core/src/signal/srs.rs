//! Shock response spectra of a pulse: the maximax absolute-acceleration SRS and the
//! pseudo-velocity shock spectrum (PVSS) of a damped single-degree-of-freedom oscillator
//! driven by the pulse, with ISO 18431-4 (Smallwood) ramp-invariant filters, and the
//! half-sine pulse that envelopes the PVSS.
//!
//! The response after the pulse (the residual) is included exactly: two zero samples end the
//! input (the ramp to zero the filter assumes between samples), after which the filter's
//! output is a decaying cosine whose largest magnitude is found in closed form rather than
//! by running the filter on for half the lowest period.
//!
//! `f64` here (the host's reference): the oscillators of the low bands have poles within
//! `ω T` of 1 (1e-4 at 10 Hz and 500 kS/s), where `f32` coefficients lose the response; the
//! board runs `f32` ones at lower rates ([`super::spectrum`]).

use core::f64::consts::PI;

use crate::real::Real;

/// A second-order section `y[n] = b0 x[n] + b1 x[n-1] + b2 x[n-2] - a1 y[n-1] - a2 y[n-2]`,
/// started at rest, with the pole data for the residual. `f64` on the host (the reference);
/// the board's multirate spectra ([`super::spectrum`]) use `f32` ones at rates where their
/// poles stay clear of 1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Oscillator<R = f64> {
    pub b: [R; 3],
    pub a: [R; 2],
    /// `ζ ω T`: the decay per sample (the poles' radius is `exp(-decay)`).
    decay: R,
    /// `ω_d T`: the damped oscillation's phase advance per sample, rad.
    advance: R,
    /// `exp(-decay)`, `sin advance`, `cos advance`: the poles.
    radius: R,
    sin_advance: R,
    cos_advance: R,
    /// The free response's extrema lie where its phase is `psi` (mod π): `atan(-decay /
    /// advance)`, and `|cos psi|`.
    psi: R,
    cos_psi: R,
}

/// Which response of the oscillator a spectrum records.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Response {
    /// Absolute acceleration of the mass, m/s² (the SRS).
    AbsoluteAcceleration,
    /// `ω` × relative displacement, m/s (the PVSS).
    PseudoVelocity,
}

impl<R: Real> Oscillator<R> {
    /// The oscillator of natural frequency `freq_hz` and damping ratio `damping` (in
    /// `[0, 0.5]`) sampled at `rate_hz`; `None` outside `0 < freq_hz <= rate_hz / 4`.
    pub fn new(response: Response, freq_hz: R, damping: R, rate_hz: R) -> Option<Self> {
        Poles::new(freq_hz, damping, rate_hz).map(|p| p.oscillator(response))
    }

    /// Both responses' oscillators, `[absolute acceleration, pseudo-velocity]`, for the
    /// price of one (they share the poles).
    pub fn pair(freq_hz: R, damping: R, rate_hz: R) -> Option<[Self; 2]> {
        Poles::new(freq_hz, damping, rate_hz).map(|p| {
            [
                p.oscillator(Response::AbsoluteAcceleration),
                p.oscillator(Response::PseudoVelocity),
            ]
        })
    }

    /// `ω_d T`, rad per sample.
    pub fn advance(&self) -> R {
        self.advance
    }

    /// Largest `|y|` over the pulse `x` (from rest) and the free response after it.
    pub fn peak(&self, x: impl IntoIterator<Item = R>) -> R {
        let [b0, b1, b2] = self.b;
        let [a1, a2] = self.a;
        let (mut x1, mut x2, mut y1, mut y2) = (R::ZERO, R::ZERO, R::ZERO, R::ZERO);
        let mut peak = R::ZERO;
        // The pulse, then two zeros: the input's ramp back to zero.
        for xn in x.into_iter().chain([R::ZERO, R::ZERO]) {
            let y = b0 * xn + b1 * x1 + b2 * x2 - a1 * y1 - a2 * y2;
            peak = peak.max(y.abs());
            (x2, x1, y2, y1) = (x1, xn, y1, y);
        }
        peak.max(self.residual_peak(y2, y1))
    }

    /// Largest `|y(t)|`, `t >= 0`, of the free response through `y(0) = y0`, `y(1) = y1` (one
    /// sample apart): `y(t) = C r^t cos(θ t + φ)` with `r = exp(-decay)`, `θ = advance`.
    pub fn residual_peak(&self, y0: R, y1: R) -> R {
        let (r, sin_t, cos_t) = (self.radius, self.sin_advance, self.cos_advance);
        // y0 = C cos φ; y1 = C r (cos θ cos φ - sin θ sin φ).
        let c_cos = y0;
        let c_sin = (y0 * r * cos_t - y1) / (r * sin_t);
        let c = (c_cos * c_cos + c_sin * c_sin).sqrt();
        if !(c > R::ZERO) {
            return y0.abs();
        }
        let phi = c_sin.atan2(c_cos);
        // Extrema where tan(θ t + φ) = -decay / θ; the first one at t >= 0 is the largest
        // after t = 0 (the envelope decays).
        let psi = self.psi;
        let d = psi - phi;
        let turn = d - (d / R::PI).floor() * R::PI;
        let t = turn / self.advance;
        let at_extremum = c * (-self.decay * t).exp() * self.cos_psi;
        y0.abs().max(at_extremum)
    }
}

/// `sin x` and `cos x` by their Taylor series for `|x| <= 2` (libm's otherwise), summed until a
/// term no longer changes either sum: as accurate as `R` holds them there, and on the M4 some
/// 150 instructions where libm's `sinf` takes 1 250 (it works in software `f64`).
pub fn sin_cos<R: Real>(x: R) -> (R, R) {
    if !(x.abs() <= R::TWO) {
        return (x.sin(), x.cos());
    }
    let x2 = x * x;
    let (mut sin, mut cos) = (x, R::ONE);
    // x^(2k+1) / (2k+1)! and x^(2k) / (2k)!, signs alternating.
    let (mut s_term, mut c_term) = (x, R::ONE);
    let mut n = R::ZERO;
    for _ in 0..16 {
        c_term = -c_term * x2 / ((n + R::ONE) * (n + R::TWO));
        s_term = -s_term * x2 / ((n + R::TWO) * (n + R::TWO + R::ONE));
        n += R::TWO;
        let (next_sin, next_cos) = (sin + s_term, cos + c_term);
        if next_sin == sin && next_cos == cos {
            break;
        }
        (sin, cos) = (next_sin, next_cos);
    }
    (sin, cos)
}

/// What both responses' oscillators share: the poles of one band at one rate.
#[derive(Clone, Copy)]
struct Poles<R> {
    damping: R,
    /// `ω T`, `ζ ω T`, `ω_d T`, `sqrt(1 - ζ²)`, `exp(-ζ ω T)`, `exp(-2 ζ ω T)`, `sin`,
    /// `cos` of `ω_d T`.
    wt: R,
    big_a: R,
    big_b: R,
    s: R,
    e: R,
    e2: R,
    sin_b: R,
    cos_b: R,
    t: R,
    w: R,
    psi: R,
    cos_psi: R,
}

impl<R: Real> Poles<R> {
    fn new(freq_hz: R, damping: R, rate_hz: R) -> Option<Self> {
        let four = R::TWO * R::TWO;
        if !(freq_hz > R::ZERO
            && rate_hz.is_finite()
            && freq_hz <= rate_hz / four
            && damping >= R::ZERO
            && damping <= R::HALF)
        {
            return None;
        }
        let t = R::ONE / rate_hz;
        let w = R::TWO * R::PI * freq_hz;
        // ISO 18431-4 with Q = 1 / (2 ζ): A = ω T / (2 Q) = ζ ω T, B = ω_d T.
        let big_a = damping * w * t;
        let s = (R::ONE - damping * damping).sqrt();
        let big_b = w * t * s;
        let ratio = -big_a / big_b;
        let psi = ratio.atan();
        let (sin_b, cos_b) = sin_cos(big_b);
        Some(Self {
            damping,
            wt: w * t,
            big_a,
            big_b,
            s,
            e: (-big_a).exp(),
            e2: (-R::TWO * big_a).exp(),
            sin_b,
            cos_b,
            t,
            w,
            psi,
            // cos(atan y) = 1 / sqrt(1 + y²).
            cos_psi: R::ONE / (R::ONE + ratio * ratio).sqrt(),
        })
    }

    fn oscillator(&self, response: Response) -> Oscillator<R> {
        let Self {
            damping,
            wt,
            big_a,
            big_b,
            s,
            e,
            e2,
            sin_b,
            cos_b,
            t,
            w,
            psi,
            cos_psi,
        } = *self;
        let a = [-R::TWO * e * cos_b, e2];
        let b = match response {
            Response::AbsoluteAcceleration => {
                let sinc = sin_b / big_b;
                [
                    R::ONE - e * sinc,
                    R::TWO * e * (sinc - cos_b),
                    e2 - e * sinc,
                ]
            }
            Response::PseudoVelocity => {
                // 1/Q = 2 ζ; q = (1/(2 Q²) - 1) / sqrt(1 - 1/(4 Q²)) = (2 ζ² - 1) / s.
                let inv_q = R::TWO * damping;
                let q = (R::TWO * damping * damping - R::ONE) / s;
                let c = t * w * w;
                [
                    ((R::ONE - e * cos_b) * inv_q - q * e * sin_b - wt) / c,
                    (R::TWO * e * cos_b * wt - (R::ONE - e2) * inv_q + R::TWO * q * e * sin_b) / c,
                    (-e2 * (wt + inv_q) + e * cos_b * inv_q - q * e * sin_b) / c,
                ]
            }
        };
        Oscillator {
            b,
            a,
            decay: big_a,
            advance: big_b,
            radius: e,
            sin_advance: sin_b,
            cos_advance: cos_b,
            psi,
            cos_psi,
        }
    }
}

/// The highest a band may be, Hz: the lower of `high_hz` (`None`: no limit) and `rate_hz / 8`
/// (where the ramp-invariant filters still follow the oscillator closely). A NaN `high_hz`
/// is no limit (`f64::min`); the settings refuse one before.
pub fn top_hz(rate_hz: f64, high_hz: Option<f64>) -> f64 {
    let top = rate_hz / 8.0;
    high_hz.map_or(top, |high| top.min(high))
}

/// Band centre frequencies `1000 × 2^(k / per_octave)` Hz from `low_hz` up to [`top_hz`],
/// written into `out`; returns how many.
pub fn bands(
    per_octave: u32,
    low_hz: f64,
    high_hz: Option<f64>,
    rate_hz: f64,
    out: &mut [f64],
) -> usize {
    if per_octave == 0 || !(low_hz > 0.0 && rate_hz.is_finite() && rate_hz > 0.0) {
        return 0;
    }
    let top = top_hz(rate_hz, high_hz);
    let n = per_octave as f64;
    let first = libm::ceil(n * libm::log2(low_hz / 1000.0) - 1e-9);
    let mut count = 0;
    for slot in out.iter_mut() {
        let f = 1000.0 * libm::exp2((first + count as f64) / n);
        if !(f <= top) {
            break;
        }
        *slot = f;
        count += 1;
    }
    count
}

/// A half-sine pulse.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HalfSine {
    /// Peak acceleration, m/s².
    pub amplitude_m_s2: f64,
    /// Duration, s.
    pub duration_s: f64,
}

/// The half-sine pulse whose PVSS envelopes `pvss` (m/s at `freqs_hz`) for an oscillator of
/// damping ratio `damping` (Gaberson's rule, as enDAQ's `enveloping_half_sine`): amplitude
/// `2π max(f PVSS)`, duration `max(PVSS) / (4 k(ζ) max(f PVSS))` with `k(ζ)` the damped
/// oscillator's low-frequency PVSS attenuation. `None` for an empty or zero spectrum.
pub fn enveloping_half_sine(freqs_hz: &[f64], pvss: &[f64], damping: f64) -> Option<HalfSine> {
    enveloping_half_sine_of(freqs_hz.iter().copied().zip(pvss.iter().copied()), damping)
}

/// [`enveloping_half_sine`] of `(frequency, PVSS)` pairs.
pub fn enveloping_half_sine_of(
    bands: impl Iterator<Item = (f64, f64)>,
    damping: f64,
) -> Option<HalfSine> {
    let (max_pvss, max_f_pvss) = bands.fold((0.0f64, 0.0f64), |(m, mf), (f, v)| {
        (m.max(v), mf.max(f * v))
    });
    if !(max_pvss > 0.0 && max_f_pvss > 0.0) {
        return None;
    }
    // k(ζ) = max over t of e^(-ζ t) sin(s t) / s, s = sqrt(1 - ζ²): at t = 2 atan2(s, 1 + ζ) / s.
    let s = libm::sqrt(1.0 - damping * damping);
    let t = 2.0 / s * libm::atan2(s, 1.0 + damping);
    let k = libm::exp(-damping * t) * libm::sin(s * t) / s;
    Some(HalfSine {
        amplitude_m_s2: 2.0 * PI * max_f_pvss,
        duration_s: max_pvss / (4.0 * k * max_f_pvss),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const RATE: f64 = 1e6;

    /// A half-sine of `amp` m/s² lasting `dur` s, sampled at [`RATE`].
    fn half_sine(amp: f64, dur: f64) -> impl Iterator<Item = f64> + Clone {
        let n = (dur * RATE) as usize;
        (0..=n).map(move |k| amp * libm::sin(PI * k as f64 / n as f64))
    }

    /// `|F(ω)|` of the half-sine: `(2 A π/T) |cos(ω T / 2)| / |(π/T)² - ω²|`.
    fn fourier(amp: f64, dur: f64, w: f64) -> f64 {
        let p = PI / dur;
        2.0 * amp * p * libm::fabs(libm::cos(w * dur / 2.0)) / libm::fabs(p * p - w * w)
    }

    #[test]
    fn the_series_sine_and_cosine_match_libm() {
        let mut x = -2.0f64;
        while x <= 2.0 {
            let (s, c) = sin_cos(x);
            assert!((s - libm::sin(x)).abs() < 4e-16 && (c - libm::cos(x)).abs() < 4e-16);
            let (s, c) = sin_cos(x as f32);
            let (ws, wc) = (libm::sinf(x as f32), libm::cosf(x as f32));
            assert!(
                (s - ws).abs() < 4e-7 && (c - wc).abs() < 4e-7,
                "{x}: {s} {c}"
            );
            x += 0.01;
        }
        // Beyond the series' range: libm's.
        assert_eq!(sin_cos(3.0f64), (libm::sin(3.0), libm::cos(3.0)));
    }

    #[test]
    fn undamped_residual_of_a_half_sine_is_omega_times_its_fourier_magnitude() {
        // Below 1/(2T) the largest response is the residual: ω |F(ω)| for the acceleration,
        // |F(ω)| for the pseudo-velocity.
        let (amp, dur) = (1000.0, 1e-3);
        for f in [20.0, 50.0, 100.0, 200.0, 400.0] {
            let w = 2.0 * PI * f;
            let srs = Oscillator::new(Response::AbsoluteAcceleration, f, 0.0, RATE).unwrap();
            let got = srs.peak(half_sine(amp, dur));
            let want = w * fourier(amp, dur, w);
            assert!(
                (got / want - 1.0).abs() < 1e-4,
                "SRS at {f} Hz: {got} vs {want}"
            );
            let pv = Oscillator::new(Response::PseudoVelocity, f, 0.0, RATE).unwrap();
            let got = pv.peak(half_sine(amp, dur));
            let want = fourier(amp, dur, w);
            assert!(
                (got / want - 1.0).abs() < 1e-4,
                "PVSS at {f} Hz: {got} vs {want}"
            );
        }
    }

    #[test]
    fn far_above_the_pulse_the_oscillator_follows_it() {
        // f T = 100: the mass moves with the base; the SRS is the peak within ~1 %.
        let osc = Oscillator::new(Response::AbsoluteAcceleration, 1e5, 0.05, RATE).unwrap();
        let got = osc.peak(half_sine(1000.0, 1e-3));
        assert!((got / 1000.0 - 1.0).abs() < 0.01, "{got}");
    }

    #[test]
    fn the_residual_peak_matches_running_the_filter_on() {
        let osc = Oscillator::new(Response::AbsoluteAcceleration, 150.0, 0.05, RATE).unwrap();
        let closed = osc.peak(half_sine(1000.0, 1e-3));
        // Half a period of zeros more, sampled: the same maximum to the sampling's resolution.
        let padded = osc.peak(half_sine(1000.0, 1e-3).chain(core::iter::repeat_n(0.0, 4000)));
        assert!((closed / padded - 1.0).abs() < 1e-6, "{closed} vs {padded}");
    }

    #[test]
    fn the_enveloping_half_sine_follows_gabersons_rule() {
        let (amp, dur) = (1000.0, 1e-3);
        let mut freqs = [0.0; 128];
        let n = bands(12, 10.0, None, RATE, &mut freqs);
        assert!(n > 100 && (freqs[0] - 10.0).abs() < 0.6 && freqs[n - 1] <= RATE / 8.0);
        let pvss: [f64; 128] = core::array::from_fn(|i| {
            Oscillator::new(Response::PseudoVelocity, freqs[i].max(1.0), 0.0, RATE)
                .map_or(0.0, |o| o.peak(half_sine(amp, dur)))
        });
        // Undamped (k = 1): the PVSS plateau is the velocity change 2 A T / π, and the high
        // band's f PVSS reaches the SRS's overshoot, A / 2π times 1.5–1.8.
        let h = enveloping_half_sine(&freqs[..n], &pvss[..n], 0.0).unwrap();
        let plateau = pvss[..n].iter().copied().fold(0.0, f64::max);
        assert!(
            (plateau / (2.0 * amp * dur / PI) - 1.0).abs() < 0.02,
            "{plateau}"
        );
        assert!((1.5..1.8).contains(&(h.amplitude_m_s2 / amp)), "{h:?}");
        assert!(
            (h.duration_s - plateau * PI / (2.0 * h.amplitude_m_s2)).abs() < 1e-12,
            "{h:?}"
        );
        // k(ζ) as enDAQ 1.5.3's `amp_factor` computes it (numpy, 2026-11-23).
        for (damping, k) in [(0.05, 0.9266920209946191), (0.2, 0.7561349268383103)] {
            let h = enveloping_half_sine(&[1.0], &[1.0], damping).unwrap();
            let got = 1.0 / (4.0 * h.duration_s);
            assert!((got / k - 1.0).abs() < 1e-12, "{damping}: {got} vs {k}");
        }
    }

    #[test]
    fn out_of_range_oscillators_are_refused() {
        assert!(Oscillator::new(Response::AbsoluteAcceleration, 0.0, 0.05, RATE).is_none());
        assert!(Oscillator::new(Response::AbsoluteAcceleration, RATE, 0.05, RATE).is_none());
        assert!(Oscillator::new(Response::AbsoluteAcceleration, 10.0, f64::NAN, RATE).is_none());
        assert!(Oscillator::new(Response::PseudoVelocity, 10.0, 0.05, f64::NAN).is_none());
        assert_eq!(bands(6, 0.0, None, RATE, &mut [0.0; 4]), 0);
    }
}
