//! Per-impact model identification from the measured force–deformation loop.
//!
//! The fits take the loop as [`Points`] (deformation, velocity and force at evenly spaced
//! points of the contact, in scaled units; [`crate::analysis::motion`] integrates them once per impact)
//! and return their own result types; the report assembles them. Linear least squares in the
//! scaled variables `X = x / x_m`, `V = v / v0`, `F = m a / F_peak`, the products in f32 (the
//! Cortex-M4's FPU) and their sums to f64 accuracy ([`sums`]): two-phase Kelvin–Voigt
//! (compression `F = kc x`; restitution `F = kr (x - x_p) + c v`), nonlinear
//! `F = k x^n (1 + c v)` (linear in `k` and `k c` for a given `n`; `n` by Brent's method on
//! the residual, with `ln x` taken once per point), and Hertz `F = K x^1.5`. Each reports its
//! RMS force residual relative to the peak force.

#[cfg(feature = "fit")]
mod least_squares;
#[cfg(feature = "fit")]
mod sums;
#[cfg(feature = "fit")]
pub(crate) use least_squares::solve;
#[cfg(feature = "fit")]
pub use least_squares::{
    hertz, nonlinear, restitution, set, two_phase, Points, Restitution, SET_RESIDUAL,
};
#[cfg(feature = "fit")]
pub(crate) use sums::Sums;

/// Two-phase Kelvin–Voigt parameters identified from one impact.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TwoPhaseFit {
    pub kc_n_m: f32,
    pub kr_n_m: f32,
    pub c_n_s_m: f32,
    pub permanent_m: f32,
    /// RMS force residual relative to the peak force.
    pub residual: f32,
}

/// Nonlinear `F = k x^n (1 + c v)` identified from one impact.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct NonlinearFit {
    /// N/m^n.
    pub k: f32,
    /// s/m.
    pub c_s_m: f32,
    pub n: f32,
    pub residual: f32,
}

/// The identified models (each present if asked for and identifiable).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Fits {
    pub two_phase: Option<TwoPhaseFit>,
    pub nonlinear: Option<NonlinearFit>,
    pub hertz: Option<HertzFit>,
}

/// Hertz `F = K x^1.5` identified from one impact.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct HertzFit {
    /// N/m^1.5.
    pub k: f32,
    pub residual: f32,
}
