//! Why a computation was refused: the crate's one error type, and the parameter checks
//! that produce it.

use crate::real::Real;

/// Why an impact could not be solved.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Error {
    /// A parameter is outside its domain. `name` is the parameter's name (`"mass"`, `"v0"`,
    /// `"kc"`, ...), which the `impact` tool spells as its option (`--mass`).
    InvalidParameter {
        name: &'static str,
        reason: &'static str,
    },
    /// The solver could not resolve the contact within its budget (too few steps for the
    /// stiffness or damping, step size underflow, non-finite state). No result is better than a
    /// wrong one.
    Unresolved(&'static str),
}

impl core::fmt::Display for Error {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Error::InvalidParameter { name, reason } => write!(f, "{name}: {reason}"),
            Error::Unresolved(why) => write!(f, "contact not resolved: {why}"),
        }
    }
}

impl core::error::Error for Error {}

/// Checks that a parameter is finite and strictly positive.
pub(crate) fn positive<R: Real>(value: R, name: &'static str) -> Result<(), Error> {
    if value.is_finite() && value > R::ZERO {
        Ok(())
    } else {
        Err(Error::InvalidParameter {
            name,
            reason: "must be finite and > 0",
        })
    }
}

/// Checks that a parameter is finite and not negative.
pub(crate) fn non_negative<R: Real>(value: R, name: &'static str) -> Result<(), Error> {
    if value.is_finite() && value >= R::ZERO {
        Ok(())
    } else {
        Err(Error::InvalidParameter {
            name,
            reason: "must be finite and >= 0",
        })
    }
}
