//! Repeated bounces under gravity: closed-form flights, one solved contact per bounce, so the
//! cost grows with the number of contacts, never with the flight time.

use super::{solve, Error, Impact, ImpactOutcome, Settings};
use crate::model::ContactLaw;
use crate::real::Real;

/// One contact of a bounce sequence.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounce<R> {
    /// 0 for the first touch.
    pub index: u32,
    /// Time of first touch of this contact since release, s.
    pub touch_time_s: R,
    /// Approach speed, m/s.
    pub impact_velocity_m_s: R,
    /// The contact itself.
    pub outcome: ImpactOutcome<R>,
    /// Height reached after the rebound, m (`v'^2 / 2g`).
    pub apex_height_m: R,
}

/// A body dropped from rest onto a barrier, bouncing until the rebound speed falls below a
/// threshold. Gravity is neglected during each contact (it changes the speed by `g t_c`,
/// below 1e-4 of `v0` for the bench cases), and the barrier recovers between contacts.
///
/// An iterator: each item is one contact, or the error that ended the sequence.
pub struct Bounces<'a, R, L> {
    law: &'a L,
    settings: Settings<R>,
    mass_kg: R,
    gravity_m_s2: R,
    min_rebound_m_s: R,
    max_contacts: u32,
    next_touch_s: R,
    next_speed_m_s: R,
    index: u32,
    done: bool,
}

impl<'a, R: Real, L: ContactLaw<R>> Bounces<'a, R, L> {
    /// Drops `mass_kg` from `drop_height_m` under gravity `gravity_m_s2`; stops after the
    /// contact whose rebound is below `min_rebound_m_s`, or after `max_contacts` contacts.
    pub fn new(
        law: &'a L,
        settings: Settings<R>,
        mass_kg: R,
        drop_height_m: R,
        gravity_m_s2: R,
        min_rebound_m_s: R,
        max_contacts: u32,
    ) -> Result<Self, Error> {
        crate::error::positive(drop_height_m, "drop-height")?;
        crate::error::positive(gravity_m_s2, "gravity")?;
        crate::error::positive(min_rebound_m_s, "min-rebound")?;
        Ok(Self {
            law,
            settings,
            mass_kg,
            gravity_m_s2,
            min_rebound_m_s,
            max_contacts,
            next_touch_s: (R::TWO * drop_height_m / gravity_m_s2).sqrt(),
            next_speed_m_s: (R::TWO * gravity_m_s2 * drop_height_m).sqrt(),
            index: 0,
            done: false,
        })
    }
}

impl<R: Real, L: ContactLaw<R>> Iterator for Bounces<'_, R, L> {
    type Item = Result<Bounce<R>, Error>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.done || self.index >= self.max_contacts {
            return None;
        }
        let v = self.next_speed_m_s;
        let outcome = match solve(self.law, &Impact::new(self.mass_kg, v), &self.settings) {
            Ok(o) => o,
            Err(e) => {
                self.done = true;
                return Some(Err(e));
            }
        };
        let rebound = outcome.rebound_velocity_m_s;
        let bounce = Bounce {
            index: self.index,
            touch_time_s: self.next_touch_s,
            impact_velocity_m_s: v,
            outcome,
            apex_height_m: rebound * rebound / (R::TWO * self.gravity_m_s2),
        };
        self.index += 1;
        // Closed-form flight: up and down again in 2 v'/g, landing at v'.
        self.next_touch_s += outcome.contact_time_s + R::TWO * rebound / self.gravity_m_s2;
        self.next_speed_m_s = rebound;
        if !(rebound >= self.min_rebound_m_s) {
            self.done = true;
        }
        Some(Ok(bounce))
    }
}
