//! A band's first pass: the recursion alone over blocks of [`BLOCK`] samples, each block
//! marked with a bound on both responses over it, and the blocks' statistics.

use super::*;

/// Samples a band's recursion takes at a time: the largest `|y|` is kept per block, and
/// only the block that holds it is run again to find the outputs around it.
pub(super) const BLOCK: usize = 128;

/// A band's input: a level's samples, or (without room for a pre-emphasised copy) the
/// pre-emphasis of them computed as it goes, `len + 4` outputs.
#[derive(Clone, Copy)]
pub(super) enum Input<'a> {
    Plain(&'a [f32]),
    Emphasised(&'a [f32]),
}

impl Input<'_> {
    pub(super) fn len(&self) -> usize {
        match self {
            Input::Plain(x) => x.len(),
            Input::Emphasised(x) => x.len() + 4,
        }
    }

    /// Sample `i` (0 beyond the end).
    pub(super) fn at(&self, i: usize) -> f32 {
        match self {
            Input::Plain(x) => x.get(i).copied().unwrap_or(0.0),
            Input::Emphasised(x) if i < x.len() + 4 => emphasised(x, i),
            Input::Emphasised(_) => 0.0,
        }
    }

    /// Samples `from..` (at most [`BLOCK`]): the slice itself, or computed into `buf`.
    pub(super) fn block<'b>(&'b self, from: usize, buf: &'b mut [f32; BLOCK]) -> &'b [f32] {
        let to = self.len().min(from + BLOCK);
        match self {
            Input::Plain(x) => x.get(from..to).unwrap_or(&[]),
            Input::Emphasised(x) => {
                let buf = buf.get_mut(..to.saturating_sub(from)).unwrap_or(&mut []);
                for (k, slot) in buf.iter_mut().enumerate() {
                    *slot = emphasised(x, from + k);
                }
                buf
            }
        }
    }
}

/// Where one response's largest `|y|` came: its block, the recursion's state at the
/// block's start and the output before it.
#[derive(Clone, Copy, Default)]
pub(super) struct Best {
    pub(super) value: f32,
    pub(super) from: usize,
    pub(super) w1: f32,
    pub(super) w2: f32,
    pub(super) before: f32,
}

/// A bound on one response's `|y|` over a block from the recursion's state at its start.
/// Over the block the input is the line `u + v m` through its first and last samples plus a
/// rest `r`; the line alone drives `w` along `α + β m` (the recursion's particular
/// solution), and the difference `e = w - α - β m` follows the recursion driven by `r`.
/// With `p` the pole, `z = e1 - p̄ e2` evolves as `z ← p z + r` (`|p| <= 1`), and that part
/// of `y` is `Re(g z)` for the state at the block's start plus the rest through the impulse
/// response `h`: so `|y| <= |y_line| + |g| |z| + ‖h‖ ‖r‖` (Cauchy–Schwarz), with room for
/// `f32` rounding. (The triangle inequality's `|b0| ‖r‖ + |g| Σ|r|`, kept as the smaller of
/// the two until 2026-11-30, cost a second statistic a sample, `Σ|r|`, and on the seed's
/// impact pruned no more: without it the second pass's instructions are the same within
/// 0.03 %, and the spectra's some 100 000 fewer, `impact bench m4`. On a rest that is one
/// spike it was the smaller, by up to some 8 times for a lightly damped band: such blocks
/// may now be computed where they were skipped, which costs time, never a bit.)
#[derive(Clone, Copy)]
pub(super) struct Bound {
    pub(super) a: [f32; 2],
    /// `1 / (1 + a1 + a2)`: the recursion's gain at 0 Hz.
    pub(super) inv_dc: f32,
    /// The pole's real and imaginary parts.
    pub(super) re: f32,
    pub(super) im: f32,
    /// Per response: the numerator, `|g|` and the root sum of squares of the impulse
    /// response's first [`BLOCK`] + 1 samples ([`impulse_norm`]).
    pub(super) num: [[f32; 3]; 2],
    pub(super) gain: [f32; 2],
    pub(super) energy: [f32; 2],
}

impl Bound {
    /// The bound's constants for poles `a` and the numerators; `None` unless the poles are a
    /// complex pair inside or on the unit circle, clear of 1: at most some 140 samples a
    /// period (`1 + a1 + a2 ≈ (ω T)²`), where [`impulse_norm`]'s `f32` stays within its
    /// margin (the spectra run every band at 8 to 64; a band without a bound has every block
    /// computed).
    pub(super) fn new([a1, a2]: [f32; 2], num: [[f32; 3]; 2]) -> Option<Self> {
        let re = -0.5 * a1;
        let im2 = a2 - re * re;
        let dc = 1.0 + a1 + a2;
        if !(im2 > 0.0 && a2 <= 1.0 && dc > 2e-3) {
            return None;
        }
        let im = crate::real::fpu_sqrt(im2);
        let gain = num.map(|[b0, b1, b2]| {
            let (d1, d2) = (b1 - b0 * a1, b2 - b0 * a2);
            let q = (d1 * re + d2) / im;
            crate::real::fpu_sqrt(d1 * d1 + q * q)
        });
        let energy = num.map(|b| impulse_norm([a1, a2], b));
        let ok = gain.iter().chain(&energy).all(|v| v.is_finite());
        ok.then_some(Self {
            a: [a1, a2],
            inv_dc: 1.0 / dc,
            re,
            im,
            num,
            gain,
            energy,
        })
    }

    /// The largest `|y|` each response can reach over `block` (whose rest about its line
    /// is `rest`) from state `(w1, w2)`.
    pub(super) fn over(&self, w1: f32, w2: f32, block: &[f32], rest: Rest) -> [f32; 2] {
        let (u, v) = line(block);
        let [a1, a2] = self.a;
        let beta = v * self.inv_dc;
        let alpha = (u + beta * (a1 + 2.0 * a2)) * self.inv_dc;
        let (e1, e2) = (w1 - (alpha - beta), w2 - (alpha - 2.0 * beta));
        let (zr, zi) = (e1 - self.re * e2, self.im * e2);
        let z = crate::real::fpu_sqrt(zr * zr + zi * zi);
        let last = block.len().saturating_sub(1) as f32;
        // The scale of `w` over the block, for the rounding of the recursion (at most
        // `BLOCK` = 128 steps of 4 operations: the 512 below) and of the outputs.
        let scale = w1.abs() + w2.abs() + alpha.abs() + beta.abs() * (last + 2.0);
        let eps = f32::EPSILON;
        [0, 1].map(|k| {
            let [b0, b1, b2] = self.num.get(k).copied().unwrap_or([f32::INFINITY; 3]);
            let (g, h) = (
                self.gain.get(k).copied().unwrap_or(f32::INFINITY),
                self.energy.get(k).copied().unwrap_or(f32::INFINITY),
            );
            let sum = b0 + b1 + b2;
            let shift = beta * (b1 + 2.0 * b2);
            let (y0, y1) = (
                (sum * alpha - shift).abs(),
                (sum * (alpha + beta * last) - shift).abs(),
            );
            // A comparison, not `f32::max` (a library call on the M4).
            let y_line = if y1 > y0 { y1 } else { y0 };
            let rounding = (g * 512.0 * eps + 8.0 * eps * (b0.abs() + b1.abs() + b2.abs())) * scale;
            // The rest's part, by Cauchy–Schwarz.
            let forced = h * rest.norm;
            1.002 * (y_line + g * z + forced) + rounding
        })
    }
}

/// `sqrt(Σ h_k²)` over the first [`BLOCK`] + 1 samples of the impulse response `h` of
/// `b(z) / a(z)` from rest (rounded up by far more than `f32` loses over it), in closed
/// form: `h_0 = b0` and, from the state `x_1 = (1, 0)`, `h_k = d · A^(k-1) x_1` with
/// `A = [[-a1, -a2], [1, 0]]`, `d = (b1 - b0 a1, b2 - b0 a2)`; so `Σ_{k=1}^{N} h_k²` is
/// `G_N[0][0]`, `G_N = Σ_{j<N} (A^j)ᵀ d dᵀ A^j`, and `G_2N = G_N + (A^N)ᵀ G_N A^N`:
/// seven doublings, some 300 operations, where running the filter over the block took
/// 2 000 instructions.
pub(super) fn impulse_norm([a1, a2]: [f32; 2], [b0, b1, b2]: [f32; 3]) -> f32 {
    const _: () = assert!(BLOCK == 1 << 7);
    type M = [[f32; 2]; 2];
    let mul =
        |x: M, y: M| -> M { [0, 1].map(|i| [0, 1].map(|j| x[i][0] * y[0][j] + x[i][1] * y[1][j])) };
    let d = [b1 - b0 * a1, b2 - b0 * a2];
    let mut g: M = [[d[0] * d[0], d[0] * d[1]], [d[1] * d[0], d[1] * d[1]]];
    let mut p: M = [[-a1, -a2], [1.0, 0.0]];
    for _ in 0..7 {
        let pt = [[p[0][0], p[1][0]], [p[0][1], p[1][1]]];
        let q = mul(pt, mul(g, p));
        g = [0, 1].map(|i| [0, 1].map(|j| g[i][j] + q[i][j]));
        p = mul(p, p);
    }
    crate::real::fpu_sqrt(b0 * b0 + g[0][0]) * 1.001
}

/// The line `u + v m` through a block's first and last samples.
pub(super) fn line(block: &[f32]) -> (f32, f32) {
    match (block.first(), block.last()) {
        (Some(&u), Some(&l)) if block.len() > 1 => (u, (l - u) / (block.len() - 1) as f32),
        (Some(&u), _) => (u, 0.0),
        _ => (0.0, 0.0),
    }
}

/// One block's input about its [`fn@line`]: `sqrt(Σ r²)`.
#[derive(Clone, Copy, Default)]
pub(super) struct Rest {
    pub(super) norm: f32,
}

impl Rest {
    pub(super) const ZERO: Self = Self { norm: 0.0 };
}

/// Blocks whose statistics a level keeps: 32 768 samples (the board's windows are shorter);
/// blocks beyond are always computed.
pub(super) const STAT_BLOCKS: usize = 128;

/// Each block's [`Rest`] of a band's input.
pub(super) fn rests(input: Input, out: &mut [Rest; STAT_BLOCKS]) {
    let mut buf = [0.0f32; BLOCK];
    for (k, slot) in out.iter_mut().enumerate() {
        let from = k * BLOCK;
        if from >= input.len() {
            break;
        }
        let block = input.block(from, &mut buf);
        let (u, v) = line(block);
        let mut squares = 0.0f32;
        // `m` as f32, counted in f32 (exact below 2^24): no conversion a sample.
        let mut m = 0.0f32;
        for &x in block {
            let r = x - (u + v * m);
            squares += r * r;
            m += 1.0;
        }
        // Rounded up a little: the sum in `f32`.
        *slot = Rest {
            norm: crate::real::fpu_sqrt(squares) * 1.0001,
        };
    }
}
