//! A spring–mass target's exact step over one sample interval with the force held over it
//! (zero-order hold): `[Φ Γ; 0 1] = exp([A B; 0 0] dt)`, `A = [0 1; -k/m -c/m]`,
//! `B = [0; 1/m]`. Computed once per impact in f64 (a 3×3 exponential), applied per sample in
//! f32 ([`crate::analysis::target`]).

use super::SpringMass;

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
