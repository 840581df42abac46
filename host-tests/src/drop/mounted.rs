//! A horizontal strike on a target that moves, the tests' oracle for the contact's kinematics
//! against it: the body (sensor on it) at `v0` strikes a pad on a mass `m2` held by a spring
//! `k2` and damper `c2` to ground (seed 000, section 3.2), once; or on a linear target in
//! state-space form (`z' = A z + B F`, its contact point at `y = Cx z`, `w = Cv z`:
//! [`Strike::render_on`]).
//!
//! ```text
//! m1 x1'' = m1 g - F,   m2 y'' = F - k2 y - c2 y',   F = law(δ, δ'),  δ = x1 - y
//! ```
//!
//! (`g` along the impact: 0 for a horizontal strike; the target's `y` from its equilibrium
//! under its own weight.) The accelerometer on the body reads `F / m1` (0 in free flight). Integrated by classic RK4 at a fixed step
//! (the shorter of the law's and the target's time scales over
//! [`super::contact::STEPS_PER_SCALE`]), the crush (`δ' = 0`) and the separation (the law's
//! force back to zero) located by bisection, and every sample taken by an RK4 sub-step to
//! its time, as [`super::contact`] does for a drop. Independent of the core's target
//! solver (`two_body`) and of its analysis.
//!
//! Definitions (Stronge, *Impact Mechanics*, ch. 1–2): the deformation is the relative
//! approach `δ = x1 - y` since first touch; the crush where its rate is zero; Newton's COR
//! the relative separation speed over the approach speed, `(w - u1) / v0`; the energy the
//! contact absorbed is the body's loss (with gravity's work on it, `m1 g x1`) less what went
//! into the target (its kinetic and spring energy at separation and what its damper took).

use super::contact::STEPS_PER_SCALE;
use super::pad::{Branch, Pad};
use impact_core::two_body::{Target, MAX_STATES};
use impact_core::{ContactLaw, Error, Impact, Model};

/// The target: a mass on a spring and damper to ground.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mount {
    pub mass_kg: f64,
    pub stiffness_n_m: f64,
    pub damping_n_s_m: f64,
}

/// One strike: the body, its pad, the target, and when and how fast it touches.
#[derive(Clone, Copy, Debug)]
pub struct Strike {
    pub law: Model<f64>,
    pub mass_kg: f64,
    pub v0_m_s: f64,
    pub touch_s: f64,
    pub mount: Mount,
    /// Gravity along the impact, m/s² (0: a horizontal strike).
    pub gravity_m_s2: f64,
}

/// What is true about the strike (times from the record's start).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StrikeTruth {
    pub touch_s: f64,
    /// First touch to `δ' = 0`, s.
    pub crush_time_s: f64,
    /// `δ` there, m.
    pub max_deformation_m: f64,
    pub contact_time_s: f64,
    /// The body's speed away from the target at separation, m/s.
    pub rebound_m_s: f64,
    /// The target's velocity at separation, m/s (in the impact direction).
    pub target_velocity_m_s: f64,
    /// Newton's: `(w - u1) / v0`.
    pub cor: f64,
    /// `δ` at separation, m.
    pub separation_deformation_m: f64,
    /// The body's loss less the target's gain (kinetic, spring, damper), J.
    pub contact_work_j: f64,
    /// What went into the target up to separation, J.
    pub target_work_j: f64,
    pub peak_force_n: f64,
    /// The body's own, against a wall's reading of the same record: `u1 = 0` (its crush),
    /// and the rebound over `v0` (what a rigid-barrier analysis reports).
    pub body_cor: f64,
}

/// Components of the integrated state: the body's `x1`, `u1`, then the target's.
const N: usize = 3 + MAX_STATES;

/// The integrated state: `v = [x1, u1, target...]`, the target's a spring–mass's
/// `(y, w, energy its damper took)` or a state space's `(z, ∫ F w dt)`.
#[derive(Clone, Copy, Debug)]
struct S {
    t: f64,
    v: [f64; N],
}

/// The target the body strikes.
#[derive(Clone, Copy)]
enum Body<'a> {
    Mount(Mount),
    Space(&'a Target<f64>),
}

impl Body<'_> {
    /// The contact point's displacement and velocity in `s`.
    fn point(&self, s: &S) -> (f64, f64) {
        match self {
            Body::Mount(_) => (s.v[2], s.v[3]),
            Body::Space(t) => {
                let (mut y, mut w) = (0.0, 0.0);
                for i in 0..t.n {
                    y += t.c[0][i] * s.v[2 + i];
                    w += t.c[1][i] * s.v[2 + i];
                }
                (y, w)
            }
        }
    }

    /// The work the contact force did on the target in `s`, J.
    fn work(&self, s: &S) -> f64 {
        match self {
            Body::Mount(m) => {
                let (y, w) = (s.v[2], s.v[3]);
                0.5 * m.mass_kg * w * w + 0.5 * m.stiffness_n_m * y * y + s.v[4]
            }
            Body::Space(t) => s.v[2 + t.n],
        }
    }
}

struct System<'a> {
    pad: &'a Pad,
    m1: f64,
    body: Body<'a>,
    g: f64,
}

impl System<'_> {
    fn raw_force(&self, s: &S, branch: Branch) -> f64 {
        let (y, w) = self.body.point(s);
        self.pad.raw_force(s.v[0] - y, s.v[1] - w, branch)
    }

    fn rates(&self, s: &S, branch: Branch) -> [f64; N] {
        let f = self.raw_force(s, branch);
        let mut r = [0.0; N];
        r[0] = s.v[1];
        r[1] = self.g - f / self.m1;
        match self.body {
            Body::Mount(Mount {
                mass_kg: m2,
                stiffness_n_m: k2,
                damping_n_s_m: c2,
            }) => {
                let (y, w) = (s.v[2], s.v[3]);
                r[2] = w;
                r[3] = (f - k2 * y - c2 * w) / m2;
                r[4] = c2 * w * w;
            }
            Body::Space(t) => {
                for i in 0..t.n {
                    let mut d = t.b[i] * f;
                    for j in 0..t.n {
                        d += t.a[i][j] * s.v[2 + j];
                    }
                    r[2 + i] = d;
                }
                r[2 + t.n] = f * self.body.point(s).1;
            }
        }
        r
    }

    fn step(&self, s: &S, h: f64, branch: Branch) -> S {
        let at = |s: &S, k: &[f64; N], a: f64| S {
            t: s.t + a,
            v: core::array::from_fn(|i| s.v[i] + a * k[i]),
        };
        let k1 = self.rates(s, branch);
        let k2 = self.rates(&at(s, &k1, h / 2.0), branch);
        let k3 = self.rates(&at(s, &k2, h / 2.0), branch);
        let k4 = self.rates(&at(s, &k3, h), branch);
        let mut k = [0.0; N];
        for i in 0..N {
            k[i] = (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]) / 6.0;
        }
        at(s, &k, h)
    }

    /// The time from `s` within `(0, h]` at which `event(state) >= 0` first.
    fn locate(&self, s: &S, h: f64, branch: Branch, event: impl Fn(&S) -> f64) -> f64 {
        let (mut lo, mut hi) = (0.0, h);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if event(&self.step(s, mid, branch)) >= 0.0 {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        hi
    }
}

/// The target's fastest rate, 1/s: its spectral radius, `|A^64|^(1/64)` (an estimate from
/// above; `|A|` where that fails). A fixture's `|A|` is `k / m` where its fastest mode is
/// `sqrt(k / m)`: the norm alone would step a thousand times finer than it needs.
fn fastest_rate(t: &Target<f64>) -> f64 {
    let a = t.a_mat();
    let norm = a.norm_inf();
    if !(norm > 0.0 && norm.is_finite()) {
        return norm;
    }
    let mut b = a.scaled(1.0 / norm);
    for _ in 0..6 {
        b = b.mul(&b);
    }
    let r = b.norm_inf().powf(1.0 / 64.0) * norm;
    if r > 0.0 && r.is_finite() {
        r
    } else {
        norm
    }
}

impl Strike {
    /// Renders `n` samples at `rate_hz` of the body's reading (`F / m1`, m/s²) and the truth.
    pub fn render(&self, rate_hz: f64, n: usize) -> Result<(Vec<f64>, StrikeTruth), Error> {
        self.render_on(None, rate_hz, n)
    }

    /// As [`Strike::render`], on the state-space target `space` (validated: `Cv = Cx A`,
    /// `Cx B = 0`) instead of the mount where one is given.
    pub fn render_on(
        &self,
        space: Option<&Target<f64>>,
        rate_hz: f64,
        n: usize,
    ) -> Result<(Vec<f64>, StrikeTruth), Error> {
        self.law.validate()?;
        let bad = |name, reason| Err(Error::InvalidParameter { name, reason });
        let impact = Impact::new(self.mass_kg, self.v0_m_s);
        let mut scale = ContactLaw::time_scale(&self.law, &impact);
        let body = match space {
            Some(t) => {
                t.validate()?;
                let rate = fastest_rate(t);
                if rate > 0.0 {
                    scale = scale.min(1.0 / rate);
                }
                Body::Space(t)
            }
            None => {
                let Mount {
                    mass_kg: m2,
                    stiffness_n_m: k2,
                    damping_n_s_m: c2,
                } = self.mount;
                if !(m2.is_finite() && m2 > 0.0) {
                    return bad("target-mass", "must be finite and > 0");
                }
                if !(k2.is_finite() && k2 >= 0.0) {
                    return bad("target-stiffness", "must be finite and >= 0");
                }
                if !(c2.is_finite() && c2 >= 0.0) {
                    return bad("target-damping", "must be finite and >= 0");
                }
                if k2 > 0.0 {
                    scale = scale.min((m2 / k2).sqrt());
                }
                if c2 > 0.0 {
                    scale = scale.min(m2 / c2);
                }
                Body::Mount(self.mount)
            }
        };
        let pad = Pad::new(self.law);
        let sys = System {
            pad: &pad,
            m1: self.mass_kg,
            body,
            g: self.gravity_m_s2,
        };
        let h = scale / STEPS_PER_SCALE;
        let mut out = Vec::with_capacity(n);
        let mut times = (0..n).map(|k| k as f64 / rate_hz).peekable();
        while times.next_if(|&t| t < self.touch_s).is_some() {
            out.push(0.0);
        }
        let mut v = [0.0; N];
        v[1] = self.v0_m_s;
        let mut s = S { t: self.touch_s, v };
        let mut branch = pad.first_branch();
        let mut crush: Option<S> = None;
        let mut peak: f64 = 0.0;
        let limit = self.touch_s + 1e6 * scale;
        let sep = loop {
            if s.t > limit {
                return bad("target", "the contact did not end within 1e6 time scales");
            }
            let next = sys.step(&s, h, branch);
            let rate = |x: &S| x.v[1] - body.point(x).1;
            let (end, event) = if crush.is_none() && rate(&next) <= 0.0 {
                let tau = sys.locate(&s, h, branch, |x| -rate(x));
                (sys.step(&s, tau, branch), Some(true))
            } else if crush.is_some() && sys.raw_force(&next, branch) <= 0.0 {
                let tau = sys.locate(&s, h, branch, |x| -sys.raw_force(x, branch));
                (sys.step(&s, tau, branch), Some(false))
            } else {
                (next, None)
            };
            while let Some(&t) = times.peek() {
                if t > end.t {
                    break;
                }
                let at = sys.step(&s, t - s.t, branch);
                out.push(sys.raw_force(&at, branch).max(0.0) / self.mass_kg);
                times.next();
            }
            peak = peak.max(sys.raw_force(&end, branch));
            s = end;
            match event {
                Some(true) => {
                    crush = Some(s);
                    branch = pad.after_max(branch, s.v[0] - body.point(&s).0);
                    if sys.raw_force(&s, branch) <= 0.0 {
                        break s;
                    }
                }
                Some(false) => break s,
                None => {}
            }
        };
        out.extend(times.map(|_| 0.0));
        let crush = crush.expect("the separation follows the crush");
        let m1 = self.mass_kg;
        let target_work = body.work(&sep);
        let [x1, u1] = [sep.v[0], sep.v[1]];
        let (y, w) = body.point(&sep);
        let (crush_x1, crush_y) = (crush.v[0], body.point(&crush).0);
        let body_loss =
            0.5 * m1 * (self.v0_m_s * self.v0_m_s - u1 * u1) + m1 * self.gravity_m_s2 * x1;
        Ok((
            out,
            StrikeTruth {
                touch_s: self.touch_s,
                crush_time_s: crush.t - self.touch_s,
                max_deformation_m: crush_x1 - crush_y,
                contact_time_s: sep.t - self.touch_s,
                rebound_m_s: -u1,
                target_velocity_m_s: w,
                cor: (w - u1) / self.v0_m_s,
                separation_deformation_m: x1 - y,
                contact_work_j: body_loss - target_work,
                target_work_j: target_work,
                peak_force_n: peak,
                body_cor: -u1 / self.v0_m_s,
            },
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use impact_core::model::{Hertz, Linear};

    fn strike(law: Model<f64>, mount: Mount) -> StrikeTruth {
        let s = Strike {
            law,
            mass_kg: 0.06,
            v0_m_s: 1.3357,
            touch_s: 1e-3,
            mount,
            gravity_m_s2: 0.0,
        };
        s.render(1e6, 20_000).unwrap().1
    }

    #[test]
    fn an_elastic_contact_on_a_free_target_is_the_reduced_mass_s() {
        // A linear spring between two free bodies: the relative motion is the spring on the
        // reduced mass μ (crush a quarter period of sqrt(k / μ), x_m = v0 sqrt(μ / k)),
        // Newton's COR 1, no work left in the contact, the target leaving at 2 m1 v0 / (m1 + m2).
        let (m1, m2, k) = (0.06, 0.3, 1e5);
        let mu = m1 * m2 / (m1 + m2);
        let t = strike(
            Model::Linear(Linear { k }),
            Mount {
                mass_kg: m2,
                stiffness_n_m: 0.0,
                damping_n_s_m: 0.0,
            },
        );
        let omega = (k / mu).sqrt();
        let rel = |a: f64, b: f64| ((a - b) / b).abs();
        assert!(
            rel(t.crush_time_s, std::f64::consts::FRAC_PI_2 / omega) < 1e-6,
            "{t:?}"
        );
        assert!(rel(t.max_deformation_m, 1.3357 / omega) < 1e-6, "{t:?}");
        assert!(
            (t.cor - 1.0).abs() < 1e-6 && t.contact_work_j.abs() < 1e-7,
            "{t:?}"
        );
        assert!(rel(t.target_velocity_m_s, 2.0 * m1 * 1.3357 / (m1 + m2)) < 1e-6);
    }

    #[test]
    fn a_stiff_heavy_mount_is_a_wall() {
        // Hertz against a 1e4 kg mount on 1e12 N/m: the wall's COR 1 and its crush.
        let hertz = Model::Hertz(Hertz { k: 1e9 });
        let wall = strike(
            hertz,
            Mount {
                mass_kg: 1e4,
                stiffness_n_m: 1e12,
                damping_n_s_m: 0.0,
            },
        );
        assert!((wall.cor - 1.0).abs() < 1e-4, "{wall:?}");
        assert!((wall.body_cor - 1.0).abs() < 1e-4, "{wall:?}");
    }
}
