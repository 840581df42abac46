//! A contact sampled at a fixed rate: what an ideal accelerometer on the body would record.

use super::adaptive::solve_observed;
use super::events::Observer;
use super::{Error, Impact, ImpactOutcome};
use crate::model::{ContactLaw, Phase};
use crate::real::Real;

/// The body's state at one sample time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample<R> {
    /// Time since first touch, s.
    pub t_s: R,
    /// Deformation, m.
    pub x_m: R,
    /// Deformation rate, m/s.
    pub v_m_s: R,
    /// Contact force, N (never negative).
    pub force_n: R,
}

struct Sampler<'a, R, L, F> {
    law: &'a L,
    offset: R,
    period: R,
    next: u64,
    /// Samples wanted at most.
    max: u64,
    out: F,
}

impl<R: Real, L: ContactLaw<R>, F: FnMut(Sample<R>)> Observer<R> for Sampler<'_, R, L, F> {
    fn piece(&mut self, t_a: R, t_b: R, at: &dyn Fn(R) -> (R, R), phase: Phase<R>) {
        while self.next < self.max {
            // Sample times are offset + k * period, from k (no accumulated rounding).
            let t = R::from_f64(self.offset.to_f64() + self.next as f64 * self.period.to_f64());
            if t > t_b {
                break;
            }
            if t >= t_a {
                let (x, v) = at(t);
                (self.out)(Sample {
                    t_s: t,
                    x_m: x,
                    v_m_s: v,
                    force_n: self.law.force(x, v, phase),
                });
            }
            self.next += 1;
        }
    }
}

/// Solves one contact with the adaptive solver at `rtol` and calls `out` with the state at
/// the times `offset_s + k period_s` (`k = 0, 1, ..., max_samples - 1`, from first touch) up
/// to separation. Returns the outcome. The work follows the samples wanted, not the contact
/// time divided by the period (a contact of 1e30 s at 1 kHz is a few solver steps).
pub fn sample<R: Real, L: ContactLaw<R>>(
    law: &L,
    impact: &Impact<R>,
    rtol: R,
    offset_s: R,
    period_s: R,
    max_samples: u64,
    out: impl FnMut(Sample<R>),
) -> Result<ImpactOutcome<R>, Error> {
    impact.validate()?;
    law.validate()?;
    if !(period_s.is_finite() && period_s > R::ZERO && offset_s.is_finite() && offset_s >= R::ZERO)
    {
        return Err(Error::InvalidParameter {
            name: "rate",
            reason: "sample period must be finite and > 0",
        });
    }
    let mut sampler = Sampler {
        law,
        offset: offset_s,
        period: period_s,
        next: 0,
        max: max_samples,
        out,
    };
    solve_observed(law, impact, rtol, &mut sampler)
}
