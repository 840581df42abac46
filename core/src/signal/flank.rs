//! Where a pulse's flank extrapolates to zero: a least-squares line through `|d|` over the
//! samples between the edge level and the flank level, from exact integer sums.

/// Points of one flank (position in samples, `|d|`), summed exactly.
#[derive(Clone, Copy, Debug, Default)]
pub struct Flank {
    n: i64,
    sx: i64,
    sy: i64,
    sxx: i64,
    sxy: i64,
}

/// Longest flank taken, samples (`|d| < 2^28` keeps `Σ x y` below 2^52).
pub const MAX_POINTS: i64 = 4096;

impl Flank {
    /// Adds one point; false (and nothing added) once [`MAX_POINTS`] are held.
    #[inline]
    pub fn add(&mut self, x: i64, y: i64) -> bool {
        if self.n >= MAX_POINTS {
            return false;
        }
        self.n += 1;
        self.sx += x;
        self.sy += y;
        self.sxx += x * x;
        self.sxy += x * y;
        true
    }

    /// Points held.
    pub fn len(&self) -> i64 {
        self.n
    }

    /// No points held.
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// Where the fitted line reaches zero, if it is a flank: at least three points, rising
    /// (`rising`) or falling, reaching zero within one point spacing beyond the points on the
    /// `outside` side, and passing below `1.5 edge` at `outside` (the sample next to the flank
    /// that was still within the edge level). A pulse that starts or ends with a jump
    /// (Kelvin–Voigt's `c v0`) fails the last test; its edge crossing is the better estimate.
    pub fn zero(&self, rising: bool, outside: f64, edge: f64) -> Option<f64> {
        if self.n < 3 {
            return None;
        }
        let n = self.n as f64;
        let (sx, sy) = (self.sx as f64, self.sy as f64);
        // n Σxx - (Σx)² and n Σxy - Σx Σy exactly in i128, then rounded once.
        let den = (self.n as i128 * self.sxx as i128 - self.sx as i128 * self.sx as i128) as f64;
        let num = (self.n as i128 * self.sxy as i128 - self.sx as i128 * self.sy as i128) as f64;
        let slope = num / den;
        let icept = (sy - slope * sx) / n;
        let zero = -icept / slope;
        let consistent = icept + slope * outside <= 1.5 * edge;
        let span = n + 1.0;
        let ok = consistent
            && if rising {
                slope > 0.0 && zero <= outside + 1.0 && zero >= outside + 1.0 - span
            } else {
                slope < 0.0 && zero >= outside - 1.0 && zero <= outside - 1.0 + span
            };
        (ok && zero.is_finite()).then_some(zero)
    }
}

/// Where `y` crosses `level` between `(0, y0)` and `(1, y1)`, as a fraction in `[0, 1]`.
pub fn crossing(y0: f64, y1: f64, level: f64) -> f64 {
    let dy = y1 - y0;
    if dy == 0.0 {
        0.0
    } else {
        ((level - y0) / dy).clamp(0.0, 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_straight_rising_flank_extrapolates_to_its_zero() {
        // |d| = 10 (x + 0.4) for x = 0..5: zero at -0.4; the sample before (x = -1) was quiet.
        let mut f = Flank::default();
        for x in 0..5 {
            f.add(x, (10.0 * (x as f64 + 0.4)) as i64);
        }
        let z = f.zero(true, -1.0, 6.0).unwrap();
        assert!((z + 0.4).abs() < 0.05, "{z}");
        // A jump (the line far above the edge next to the flank) is refused.
        let mut jump = Flank::default();
        for x in 0..5 {
            jump.add(x, 100 + 10 * x);
        }
        assert_eq!(jump.zero(true, -1.0, 6.0), None);
    }

    #[test]
    fn a_falling_flank_and_too_few_points() {
        // Positions -4..=0 before the first quiet sample at +1: |d| = 10 (0.6 - x).
        let mut f = Flank::default();
        for x in -4..=0 {
            f.add(x, (10.0 * (0.6 - x as f64)) as i64);
        }
        let z = f.zero(false, 1.0, 8.0).unwrap();
        assert!((z - 0.6).abs() < 0.05, "{z}");
        let mut g = Flank::default();
        g.add(0, 5);
        g.add(1, 9);
        assert_eq!(g.zero(true, -1.0, 8.0), None);
    }
}
