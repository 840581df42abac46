//! A target's exact step over one sample interval with the force held over it (zero-order
//! hold): `[Φ Γ; 0 1] = exp([A B; 0 0] dt)`. Computed once per impact in f64, applied per
//! sample in f32 ([`crate::analysis::target`]): for a spring–mass (`A = [0 1; -k/m -c/m]`,
//! `B = [0; 1/m]`, a 3×3 exponential) on its two states `(y, w)` ([`Discrete`]); for a
//! general state-space target of `n <= 6` states by the `(n+1)`-order balanced exponential
//! of [`super::matrix`] (linked anyway: the target's validation runs it), its outputs
//! `y = Cx z`, `w = Cv z` ([`General`]).

use super::matrix::Mat;
use super::{SceneTarget, SpringMass, Target, MAX_STATES};

/// A target's step over one sample interval, as the analysis's pass takes it: the state at
/// rest, one interval of a held force, and the contact point's displacement and velocity.
pub trait Step {
    /// The target's state.
    type State: Copy;
    /// At rest (each first touch).
    const REST: Self::State;
    /// The state after one interval of force `f` (N).
    fn step(&self, z: Self::State, f: f32) -> Self::State;
    /// The contact point's displacement (m) and velocity (m/s) in state `z`.
    fn at(&self, z: &Self::State) -> (f32, f32);
}

/// Either target's step: a spring–mass's own (the 2×2 it is), or a state space's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Stepper {
    SpringMass(Discrete),
    General(General),
}

impl Stepper {
    /// The step of `target` over `dt` seconds; `None` if it is not finite.
    pub fn new(target: &SceneTarget, dt: f64) -> Option<Self> {
        match target {
            SceneTarget::SpringMass(s) => Discrete::new(s, dt).map(Self::SpringMass),
            SceneTarget::StateSpace(t) => General::new(t, dt).map(Self::General),
        }
    }

    /// The largest gain of the step on the state, and of the state on the outputs: what
    /// the scene's validation holds within f32 over the longest pass.
    pub fn largest_gain(&self) -> f32 {
        match self {
            Self::SpringMass(d) => d.largest_gain(),
            Self::General(g) => g.largest_gain(),
        }
    }
}

/// The target's exact step over one sample interval with the force held:
/// `(y, w) <- Φ (y, w) + Γ F` (m, m/s, N).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Discrete {
    phi: [[f32; 2]; 2],
    gamma: [f32; 2],
}

impl Discrete {
    /// The step of `target` over `dt` seconds; `None` if it is not finite (a target whose
    /// parameters the scene's validation would refuse).
    pub fn new(target: &SpringMass<f32>, dt: f64) -> Option<Self> {
        let m = target.mass_kg as f64;
        let k = target.stiffness_n_m as f64;
        let c = target.damping_n_s_m as f64;
        let a = [
            [0.0, dt, 0.0],
            [-k / m * dt, -c / m * dt, dt / m],
            [0.0, 0.0, 0.0],
        ];
        let e = exp3(&a)?;
        let f = |v: f64| v as f32;
        let d = Self {
            phi: [[f(e[0][0]), f(e[0][1])], [f(e[1][0]), f(e[1][1])]],
            gamma: [f(e[0][2]), f(e[1][2])],
        };
        let finite = d
            .phi
            .iter()
            .flatten()
            .chain(&d.gamma)
            .all(|v| v.is_finite());
        finite.then_some(d)
    }

    /// The largest entry of `Φ` and `Γ` in magnitude (the state's growth per step is
    /// bounded by it: what the scene's validation holds within f32).
    pub fn largest_gain(&self) -> f32 {
        self.phi
            .iter()
            .flatten()
            .chain(&self.gamma)
            .fold(0.0f32, |m, v| m.max(libm::fabsf(*v)))
    }

    /// The state after one interval of force `f`.
    #[inline]
    pub fn step(&self, (y, w): (f32, f32), f: f32) -> (f32, f32) {
        let [[p00, p01], [p10, p11]] = self.phi;
        (
            p00 * y + p01 * w + self.gamma[0] * f,
            p10 * y + p11 * w + self.gamma[1] * f,
        )
    }
}

impl Step for Discrete {
    type State = (f32, f32);
    const REST: Self::State = (0.0, 0.0);
    #[inline]
    fn step(&self, z: Self::State, f: f32) -> Self::State {
        Discrete::step(self, z, f)
    }
    #[inline]
    fn at(&self, z: &Self::State) -> (f32, f32) {
        *z
    }
}

/// A state-space target's exact step: `z <- Φ z + Γ F` over `n` states, its contact point at
/// `y = Cx z`, `w = Cv z` (entries beyond `n` zero).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct General {
    n: usize,
    phi: [[f32; MAX_STATES]; MAX_STATES],
    gamma: [f32; MAX_STATES],
    c: [[f32; MAX_STATES]; 2],
}

impl General {
    /// The step of `target`'s matrices over `dt` seconds; `None` if it is not finite or the
    /// target has no states or more than [`MAX_STATES`].
    pub fn new(target: &Target<f32>, dt: f64) -> Option<Self> {
        let n = target.n;
        if n == 0 || n > MAX_STATES || !(dt > 0.0 && dt.is_finite()) {
            return None;
        }
        // `[A B; 0 0]`, its exponential over `dt` (balanced: `Mat::exp`) holding `[Φ Γ; 0 1]`.
        let mut m = Mat::<f64>::zero(n + 1);
        for (i, (row, (a, b))) in
            m.a.iter_mut()
                .zip(target.a.iter().zip(&target.b))
                .enumerate()
        {
            if i < n {
                for (v, a) in row.iter_mut().zip(a).take(n) {
                    *v = *a as f64;
                }
                if let Some(v) = row.get_mut(n) {
                    *v = *b as f64;
                }
            }
        }
        let e = m.exp(dt)?.a;
        let mut g = Self {
            n,
            phi: [[0.0; MAX_STATES]; MAX_STATES],
            gamma: [0.0; MAX_STATES],
            c: [[0.0; MAX_STATES]; 2],
        };
        for ((phi, gamma), e) in g.phi.iter_mut().zip(&mut g.gamma).zip(&e).take(n) {
            for (p, e) in phi.iter_mut().zip(e).take(n) {
                *p = *e as f32;
            }
            *gamma = e.get(n).map_or(f32::NAN, |v| *v as f32);
        }
        for (out, c) in g.c.iter_mut().zip(&target.c) {
            for (o, c) in out.iter_mut().zip(c).take(n) {
                *o = *c;
            }
        }
        let finite = g
            .phi
            .iter()
            .flatten()
            .chain(&g.gamma)
            .chain(g.c.iter().flatten())
            .all(|v| v.is_finite());
        finite.then_some(g)
    }

    /// The largest entry of `Φ` and `Γ`, times the outputs' largest row sum (at least 1).
    pub fn largest_gain(&self) -> f32 {
        let state = self
            .phi
            .iter()
            .flatten()
            .chain(&self.gamma)
            .fold(0.0f32, |m, v| m.max(libm::fabsf(*v)));
        let out = self
            .c
            .iter()
            .map(|r| r.iter().map(|v| libm::fabsf(*v)).sum::<f32>())
            .fold(1.0f32, f32::max);
        state * out
    }
}

impl Step for General {
    type State = [f32; MAX_STATES];
    const REST: Self::State = [0.0; MAX_STATES];
    #[inline]
    fn step(&self, z: Self::State, f: f32) -> Self::State {
        let mut out = [0.0f32; MAX_STATES];
        for ((o, row), g) in out.iter_mut().zip(&self.phi).zip(&self.gamma).take(self.n) {
            let mut s = 0.0f32;
            for (p, x) in row.iter().zip(&z).take(self.n) {
                s += p * x;
            }
            *o = s + g * f;
        }
        out
    }
    #[inline]
    fn at(&self, z: &Self::State) -> (f32, f32) {
        let [cx, cv] = &self.c;
        let (mut y, mut w) = (0.0f32, 0.0f32);
        for ((a, b), x) in cx.iter().zip(cv).zip(z).take(self.n) {
            y += a * x;
            w += b * x;
        }
        (y, w)
    }
}

type M3 = [[f64; 3]; 3];

fn mul3(a: &M3, b: &M3) -> M3 {
    let mut out = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            out[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
        }
    }
    out
}

/// `exp(a)` by scaling and squaring with an 18-term Taylor series (`a` halved until its
/// infinity norm is at most 1/2: the truncation `0.5^19 / 19!` is far below f64's epsilon).
fn exp3(a: &M3) -> Option<M3> {
    let norm = a
        .iter()
        .map(|r| libm::fabs(r[0]) + libm::fabs(r[1]) + libm::fabs(r[2]))
        .fold(0.0, f64::max);
    if !norm.is_finite() {
        return None;
    }
    let mut squarings = 0;
    let mut scale = 1.0;
    while norm * scale > 0.5 && squarings < 1100 {
        scale *= 0.5;
        squarings += 1;
    }
    let b = a.map(|r| r.map(|v| v * scale));
    let mut term = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let mut sum = term;
    for j in 1..=18 {
        term = mul3(&term, &b);
        for (s_row, t_row) in sum.iter_mut().zip(term.iter_mut()) {
            for (s, t) in s_row.iter_mut().zip(t_row.iter_mut()) {
                *t /= j as f64;
                *s += *t;
            }
        }
    }
    for _ in 0..squarings {
        sum = mul3(&sum, &sum);
    }
    sum.iter().flatten().all(|v| v.is_finite()).then_some(sum)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_step_is_the_exact_free_and_spring_response() {
        // A free body: a force held over dt moves it F dt / m and F dt² / 2m.
        let free = SpringMass {
            mass_kg: 2.0,
            stiffness_n_m: 0.0,
            damping_n_s_m: 0.0,
        };
        let d = Discrete::new(&free, 1e-3).unwrap();
        let (y, w) = d.step((0.0, 0.0), 4.0);
        assert!(
            (w - 2e-3).abs() < 1e-9 && (y - 1e-6).abs() < 1e-12,
            "{y} {w}"
        );
        // An undamped oscillator from (y, 0) over a quarter period: (0, -ω y).
        let k = 400.0;
        let osc = SpringMass {
            mass_kg: 1.0,
            stiffness_n_m: k,
            damping_n_s_m: 0.0,
        };
        let omega = 20.0f64;
        let quarter = core::f64::consts::FRAC_PI_2 / omega;
        let d = Discrete::new(&osc, quarter).unwrap();
        let (y, w) = d.step((1.0, 0.0), 0.0);
        assert!(y.abs() < 1e-6 && (w + 20.0).abs() < 1e-5, "{y} {w}");
    }

    /// A spring–mass written as a state space (with its states scaled, so the matrices are
    /// not the spring–mass's own) steps as the spring–mass does, within f32.
    #[test]
    fn a_state_space_steps_as_its_spring_mass() {
        let (m, k, c) = (0.3f32, 4e4f32, 12.0f32);
        // States (1000 y, w): A = [0 1000; -k/m/1000 -c/m], B = [0; 1/m], Cx = [1e-3 0].
        let mut a = [[0.0f32; MAX_STATES]; MAX_STATES];
        a[0][1] = 1000.0;
        a[1][0] = -k / m / 1000.0;
        a[1][1] = -c / m;
        let mut b = [0.0f32; MAX_STATES];
        b[1] = 1.0 / m;
        let mut cm = [[0.0f32; MAX_STATES]; 2];
        cm[0][0] = 1e-3;
        cm[1][1] = 1.0;
        let t = Target::state_space(2, a, b, cm, [0.0, 0.0]).unwrap();
        let g = General::new(&t, 2e-6).unwrap();
        let d = Discrete::new(
            &SpringMass {
                mass_kg: m,
                stiffness_n_m: k,
                damping_n_s_m: c,
            },
            2e-6,
        )
        .unwrap();
        let (mut zg, mut zd) = (General::REST, Discrete::REST);
        // (Over 20 000 steps of f32, against the motion's scale: the static deflection
        // F / k = 2 cm, the velocity F / sqrt(k m) = 7.3 m/s.)
        let mut worst = 0.0f32;
        for i in 0..20_000 {
            let f = if i < 5000 { 800.0 } else { 0.0 };
            zg = Step::step(&g, zg, f);
            zd = Step::step(&d, zd, f);
            let ((yg, wg), (yd, wd)) = (g.at(&zg), d.at(&zd));
            worst = worst.max((yg - yd).abs() / 0.02).max((wg - wd).abs() / 7.3);
        }
        assert!(worst < 1e-4, "{worst}");
        assert!(g.largest_gain() > 0.0 && g.largest_gain().is_finite());
    }

    /// A chain of masses (`m[0]` on `k[0]`, `c[0]` to ground, each next on its own spring and
    /// damper to the one before; the contact on the last), its states in reverse order
    /// (`(y_last, w_last, ..., y_0, w_0)`: the contact point is not state 0), stepped by
    /// [`General`] against RK4 in f64 at a hundredth of the step, the force held: 4 and 6
    /// states, a light soft base that moves within the force's 10 ms.
    #[test]
    fn a_chain_of_masses_steps_as_rk4_integrates_it() {
        extern crate std;
        use std::vec::Vec;
        for (m, k, c) in [
            (&[0.1, 0.3][..], &[2e4, 4e4][..], &[5.0, 12.0][..]),
            (
                &[1.0, 0.2, 0.3][..],
                &[1e6, 2e4, 4e4][..],
                &[60.0, 3.0, 12.0][..],
            ),
        ] {
            let bodies = m.len();
            let n = 2 * bodies;
            // The state index of body `i`'s displacement (its velocity the next).
            let at = |i: usize| 2 * (bodies - 1 - i);
            let mut a = [[0.0f64; MAX_STATES]; MAX_STATES];
            for i in 0..bodies {
                let (y, w) = (at(i), at(i) + 1);
                a[y][w] = 1.0;
                // Own spring and damper (to the one before, or to ground).
                a[w][y] -= k[i] / m[i];
                a[w][w] -= c[i] / m[i];
                if i > 0 {
                    let (yp, wp) = (at(i - 1), at(i - 1) + 1);
                    a[w][yp] += k[i] / m[i];
                    a[w][wp] += c[i] / m[i];
                    // And its reaction on the one before.
                    a[wp][y] += k[i] / m[i - 1];
                    a[wp][w] += c[i] / m[i - 1];
                    a[wp][yp] -= k[i] / m[i - 1];
                    a[wp][wp] -= c[i] / m[i - 1];
                }
            }
            let last = bodies - 1;
            let mut b = [0.0f64; MAX_STATES];
            b[at(last) + 1] = 1.0 / m[last];
            let mut cm = [[0.0f64; MAX_STATES]; 2];
            cm[0][at(last)] = 1.0;
            cm[1][at(last) + 1] = 1.0;
            let f32s = |r: &[f64; MAX_STATES]| r.map(|v| v as f32);
            let t = Target::state_space(
                n,
                a.map(|r| f32s(&r)),
                f32s(&b),
                cm.map(|r| f32s(&r)),
                [0.0; 2],
            )
            .unwrap();
            let dt = 2e-6;
            let g = General::new(&t, dt).unwrap();
            let rate = |z: &[f64], f: f64| -> Vec<f64> {
                (0..n)
                    .map(|i| (0..n).map(|j| a[i][j] * z[j]).sum::<f64>() + b[i] * f)
                    .collect()
            };
            let (mut zg, mut z) = (General::REST, std::vec![0.0f64; n]);
            let (mut worst, mut scale) = (0.0f64, [0.0f64; 2]);
            for step in 0..10_000 {
                let f = if step < 5_000 { 800.0 } else { 0.0 };
                zg = Step::step(&g, zg, f as f32);
                let h = dt / 100.0;
                for _ in 0..100 {
                    let k1 = rate(&z, f);
                    let y2: Vec<f64> = z.iter().zip(&k1).map(|(z, k)| z + h / 2.0 * k).collect();
                    let k2 = rate(&y2, f);
                    let y3: Vec<f64> = z.iter().zip(&k2).map(|(z, k)| z + h / 2.0 * k).collect();
                    let k3 = rate(&y3, f);
                    let y4: Vec<f64> = z.iter().zip(&k3).map(|(z, k)| z + h * k).collect();
                    let k4 = rate(&y4, f);
                    for i in 0..n {
                        z[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
                    }
                }
                let (y, w) = g.at(&zg);
                let (y_ref, w_ref) = (z[at(last)], z[at(last) + 1]);
                scale = [scale[0].max(y_ref.abs()), scale[1].max(w_ref.abs())];
                worst = worst.max(
                    (y as f64 - y_ref)
                        .abs()
                        .max((w as f64 - w_ref).abs() * 1e-3),
                );
            }
            // Against the motion's scale (the displacement's; the velocity's per ms).
            let tol = 1e-4 * scale[0].max(scale[1] * 1e-3);
            assert!(worst < tol, "{n} states: {worst} vs {tol} ({scale:?})");
            // The base moved: its states are not idle.
            let base = z[at(0)].abs();
            assert!(base > 1e-3 * scale[0], "{n} states: base {base}");
        }
    }

    #[test]
    fn a_target_that_cannot_step_gives_none() {
        let bad = SpringMass {
            mass_kg: 0.0,
            stiffness_n_m: 1.0,
            damping_n_s_m: 0.0,
        };
        assert_eq!(Discrete::new(&bad, 1e-3), None);
    }
}
