//! Small dense matrices (at most [`DIM`] square) and their exponential, for linear targets.
//!
//! `exp(A t)` by scaling and squaring with a degree-18 Taylor polynomial: `A t` is halved until
//! its infinity norm is at most 1/2, where the truncation error (`0.5^19 / 19!`) is far below
//! either type's epsilon, then squared back.

use crate::real::Real;

/// Largest matrix order: the impactor's two states, six target states and one constant.
pub const DIM: usize = 9;

/// A square matrix of order `n <= DIM`; entries beyond `n` are zero.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mat<R> {
    pub n: usize,
    pub a: [[R; DIM]; DIM],
}

/// A vector of length `n <= DIM` (entries beyond `n` are zero).
pub type Vector<R> = [R; DIM];

impl<R: Real> Mat<R> {
    /// The zero matrix of order `n` (clamped to `DIM`).
    pub fn zero(n: usize) -> Self {
        Self {
            n: n.min(DIM),
            a: [[R::ZERO; DIM]; DIM],
        }
    }

    /// The identity of order `n`.
    pub fn identity(n: usize) -> Self {
        let mut m = Self::zero(n);
        for (i, row) in m.a.iter_mut().enumerate().take(m.n) {
            row[i] = R::ONE;
        }
        m
    }

    /// `self * other` (orders must agree; the smaller is used).
    pub fn mul(&self, other: &Self) -> Self {
        let n = self.n.min(other.n).min(DIM);
        let mut out = Self::zero(n);
        for i in 0..n {
            for k in 0..n {
                let aik = self.a[i][k];
                if aik == R::ZERO {
                    continue;
                }
                for j in 0..n {
                    out.a[i][j] += aik * other.a[k][j];
                }
            }
        }
        out
    }

    /// `self * v`.
    pub fn apply(&self, v: &Vector<R>) -> Vector<R> {
        let mut out = [R::ZERO; DIM];
        for (o, row) in out.iter_mut().zip(&self.a).take(self.n) {
            let mut s = R::ZERO;
            for (a, x) in row.iter().zip(v).take(self.n) {
                s += *a * *x;
            }
            *o = s;
        }
        out
    }

    /// `self * s`.
    pub fn scaled(&self, s: R) -> Self {
        let mut out = *self;
        for row in out.a.iter_mut().take(self.n) {
            for x in row.iter_mut().take(self.n) {
                *x *= s;
            }
        }
        out
    }

    /// The infinity norm (largest absolute row sum); NaN if an entry is NaN.
    pub fn norm_inf(&self) -> R {
        let mut best = R::ZERO;
        for row in self.a.iter().take(self.n) {
            let mut s = R::ZERO;
            for x in row.iter().take(self.n) {
                if x.is_nan() {
                    return *x;
                }
                s += x.abs();
            }
            best = best.max(s);
        }
        best
    }

    /// `exp(self * t)`, balanced first (`D^-1 A D` with `D` powers of two, as LAPACK's
    /// `gebal`): a mechanical system's states differ by its frequencies (m against m/s), and
    /// without balancing the norm, the squarings and the rounding grow with that ratio.
    /// `None` if the result is not finite.
    pub fn exp(&self, t: R) -> Option<Self> {
        let (balanced, d) = self.balance();
        let mut e = balanced.exp_unbalanced(t)?;
        let n = self.n.min(DIM);
        for i in 0..n {
            for j in 0..n {
                e.a[i][j] = e.a[i][j] * d[i] / d[j];
            }
        }
        e.all_finite().then_some(e)
    }

    /// `D^-1 A D` and `D`, with the off-diagonal row and column norms of each state brought
    /// within a factor of two of each other (exact: powers of two only).
    fn balance(&self) -> (Self, Vector<R>) {
        let mut m = *self;
        let mut d = [R::ONE; DIM];
        let n = self.n.min(DIM);
        for _sweep in 0..64 {
            let mut changed = false;
            for i in 0..n {
                let mut col = R::ZERO;
                let mut row = R::ZERO;
                for j in 0..n {
                    if j != i {
                        col += m.a[j][i].abs();
                        row += m.a[i][j].abs();
                    }
                }
                if !(col > R::ZERO && row > R::ZERO && col.is_finite() && row.is_finite()) {
                    continue;
                }
                let total = col + row;
                let mut f = R::ONE;
                let mut steps = 0;
                while col < row * R::HALF * R::HALF && steps < 256 {
                    col *= R::TWO * R::TWO;
                    row *= R::HALF * R::HALF;
                    f *= R::TWO;
                    steps += 1;
                }
                while col > row * R::TWO * R::TWO && steps < 256 {
                    col *= R::HALF * R::HALF;
                    row *= R::TWO * R::TWO;
                    f *= R::HALF;
                    steps += 1;
                }
                if col + row < R::from_f64(0.95) * total {
                    // Scale state i by f: column i times f, row i over f.
                    changed = true;
                    d[i] *= f;
                    for j in 0..n {
                        m.a[j][i] *= f;
                        m.a[i][j] = m.a[i][j] / f;
                    }
                }
            }
            if !changed {
                break;
            }
        }
        (m, d)
    }

    fn exp_unbalanced(&self, t: R) -> Option<Self> {
        let at = self.scaled(t);
        let norm = at.norm_inf();
        if !norm.is_finite() {
            return None;
        }
        let mut squarings = 0u32;
        let mut scale = R::ONE;
        let mut reduced = norm;
        while reduced > R::HALF {
            reduced *= R::HALF;
            scale *= R::HALF;
            squarings += 1;
            if squarings > 1100 {
                return None;
            }
        }
        let x = at.scaled(scale);
        // Horner: I + X (I + X/2 (I + X/3 (... (I + X/18)))).
        let mut p = Self::identity(self.n);
        for k in (1..=18u32).rev() {
            p = x.mul(&p).scaled(R::ONE / R::from_u32(k));
            for i in 0..self.n.min(DIM) {
                p.a[i][i] += R::ONE;
            }
        }
        for _ in 0..squarings {
            p = p.mul(&p);
        }
        p.all_finite().then_some(p)
    }

    /// The inverse by Gauss–Jordan elimination with partial pivoting; `None` if the matrix is
    /// singular (a pivot below `n` epsilons of its column's largest entry) or not finite.
    pub fn inverse(&self) -> Option<Self> {
        let n = self.n.min(DIM);
        let mut m = *self;
        let mut inv = Self::identity(n);
        let scale = m.norm_inf();
        if !(scale > R::ZERO && scale.is_finite()) {
            return None;
        }
        for col in 0..n {
            let mut pivot = col;
            for row in col + 1..n {
                if m.a[row][col].abs() > m.a[pivot][col].abs() {
                    pivot = row;
                }
            }
            if !(m.a[pivot][col].abs() > R::from_u32(n as u32) * R::EPSILON * scale) {
                return None;
            }
            m.a.swap(col, pivot);
            inv.a.swap(col, pivot);
            let p = m.a[col][col];
            for j in 0..n {
                m.a[col][j] = m.a[col][j] / p;
                inv.a[col][j] = inv.a[col][j] / p;
            }
            for row in 0..n {
                let f = m.a[row][col];
                if row == col || f == R::ZERO {
                    continue;
                }
                for j in 0..n {
                    m.a[row][j] -= f * m.a[col][j];
                    inv.a[row][j] -= f * inv.a[col][j];
                }
            }
        }
        inv.all_finite().then_some(inv)
    }

    /// The smallest eigenvalue modulus, 1/s: the slowest mode's rate (a mount's natural
    /// angular frequency, or the inverse of its slowest time constant). The spectral radius
    /// of the inverse by Gelfand's formula (`‖B^k‖^(1/k)`, `k = 2^40` by repeated squaring,
    /// each power normalised); `None` for a singular matrix (a free body: no slowest mode).
    pub fn slowest_rate(&self) -> Option<R> {
        let (balanced, _) = self.balance();
        let b = balanced.inverse()?;
        let mut norm = b.norm_inf();
        let mut m = b.scaled(R::ONE / norm);
        // `norm` is ‖B^(2^j)‖^(1/2^j); each squaring refines it by ‖M²‖^(1/2^(j+1)).
        for j in 0..40u32 {
            let sq = m.mul(&m);
            let f = sq.norm_inf();
            if !(f > R::ZERO && f.is_finite()) {
                break;
            }
            let mut root = f;
            for _ in 0..=j {
                root = root.sqrt();
            }
            norm *= root;
            m = sq.scaled(R::ONE / f);
        }
        (norm > R::ZERO && norm.is_finite()).then(|| R::ONE / norm)
    }

    /// True if every entry is finite.
    pub fn all_finite(&self) -> bool {
        self.a
            .iter()
            .take(self.n)
            .all(|row| row.iter().take(self.n).all(|x| x.is_finite()))
    }
}

/// `a · b` over the first `n` entries.
pub fn dot<R: Real>(a: &Vector<R>, b: &Vector<R>, n: usize) -> R {
    let mut s = R::ZERO;
    for (x, y) in a.iter().zip(b).take(n) {
        s += *x * *y;
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exponential_of_an_oscillator_is_a_rotation() {
        // x'' = -w^2 x: exp(A t) = [[cos, sin/w], [-w sin, cos]].
        let w = 3.0f64;
        let mut a = Mat::zero(2);
        a.a[0][1] = 1.0;
        a.a[1][0] = -w * w;
        for t in [0.0, 0.1, 1.0, 10.0, 1e3] {
            let e = a.exp(t).unwrap();
            let (s, c) = libm::sincos(w * t);
            let tol = 1e-13 * (1.0 + w * t);
            assert!((e.a[0][0] - c).abs() < tol, "{t}");
            assert!((e.a[0][1] - s / w).abs() < tol, "{t}");
            assert!((e.a[1][0] + w * s).abs() < tol * w, "{t}");
        }
        // A stiff, badly scaled oscillator (k/m = 1e16): balancing keeps full accuracy.
        let w = 1e8f64;
        let mut a = Mat::zero(2);
        a.a[0][1] = 1.0;
        a.a[1][0] = -w * w;
        for t in [1e-9, 1.7e-3] {
            let e = a.exp(t).unwrap();
            let (s, c) = libm::sincos(w * t);
            let tol = 1e-15 * w * t;
            assert!((e.a[0][0] - c).abs() < tol, "{t}: {} vs {c}", e.a[0][0]);
            assert!((e.a[0][1] * w - s).abs() < tol, "{t}");
        }
        assert!(a.exp(f64::NAN).is_none());
        assert!(a.scaled(1e300).exp(1e300).is_none());
    }

    #[test]
    fn inverse_and_slowest_rate() {
        // Two masses on springs (k = 1, 4 and 9 N/m between wall, m1 = 1 kg, m2 = 2 kg, wall).
        let (k1, k2, k3, m1, m2) = (1.0f64, 4.0, 9.0, 1.0, 2.0);
        let mut a = Mat::zero(4);
        a.a[0][2] = 1.0;
        a.a[1][3] = 1.0;
        a.a[2][0] = -(k1 + k2) / m1;
        a.a[2][1] = k2 / m1;
        a.a[3][0] = k2 / m2;
        a.a[3][1] = -(k2 + k3) / m2;
        let inv = a.inverse().unwrap();
        let id = a.mul(&inv);
        for i in 0..4 {
            for j in 0..4 {
                let want = if i == j { 1.0 } else { 0.0 };
                assert!((id.a[i][j] - want).abs() < 1e-14, "{i}{j}: {}", id.a[i][j]);
            }
        }
        // Natural frequencies: w^2 the eigenvalues of [[5, -4], [-2, 6.5]].
        let (tr, det) = (5.0 + 6.5, 5.0 * 6.5 - 8.0);
        let w_low = ((tr - (tr * tr - 4.0 * det).sqrt()) / 2.0).sqrt();
        let got = a.slowest_rate().unwrap();
        assert!((got / w_low - 1.0).abs() < 1e-9, "{got} vs {w_low}");
        // A damped mode (rate |lambda| = wn) and a badly scaled one (k/m = 1e4).
        let mut a = Mat::zero(2);
        a.a[0][1] = 1.0;
        a.a[1][0] = -1e4;
        a.a[1][1] = -20.0;
        assert!((a.slowest_rate().unwrap() / 100.0 - 1.0).abs() < 1e-9);
        // A free body: singular, no slowest mode.
        a.a[1][0] = 0.0;
        assert!(a.inverse().is_none());
        assert!(a.slowest_rate().is_none());
    }
}
