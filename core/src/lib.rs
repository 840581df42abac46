//! `impact-core`: impact models, solvers, the streaming signal pipeline, metrics and fits.
//!
//! `no_std`, allocation-free, and panic-free on any input: bad input gives a typed
//! [`Error`] or a flagged result.
//!
//! # Units and sign conventions
//! SI throughout, and every public field name carries its unit (`_m`, `_s`, `_n`, `_m_s`).
//! `x` is the deformation (overlap) of body and barrier, positive in compression; `v = dx/dt`
//! is positive while the body moves into the barrier. An impact starts at `x = 0, v = v0 > 0`.
//!
//! # Separation
//! A barrier cannot pull: the contact force is `max(0, F)`. Separation is the first instant
//! after the maximum deformation at which the force returns to zero; the deformation left then
//! is the permanent deformation, the speed then the rebound speed `v'`, and `COR = v'/v0`.
#![no_std]
// No unsafe code but five `global_asm!` routines for the Cortex-M4F, each allowing it for
// itself: the FPU square root (`real::fpu_sqrt`), the idle path's SIMD stride statistics
// (`signal::baseline::Stats::of`), its word-wise ring copy (`signal::copy`), the spectra's
// recursion (`signal::spectrum::skim`) and both their responses with each one's largest
// `|y|` (`signal::spectrum::tops`).
#![deny(unsafe_code)]
// Guards are written `!(x > 0)` on purpose: they are true for NaN, so NaN never passes.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod analysis;
pub mod board;
pub mod capture;
pub mod consts;
pub mod error;
pub mod fit;
pub mod model;
pub mod monitor;
pub mod numeric;
pub mod real;
pub mod report;
pub mod scene;
pub mod signal;
pub mod solve;
pub mod spec;
pub mod stream;
#[cfg(test)]
mod testing;
pub mod two_body;
pub mod waveform;

pub use analysis::{analyse, Workspace};
pub use capture::{Capture, Sink, Summary};
pub use error::Error;
pub use model::{ContactLaw, Model};
pub use model::{Impact, ImpactOutcome};
pub use monitor::Monitor;
pub use real::Real;
pub use report::Bounce;
pub use report::{Analysis, ImpactReport, Kinematics, Status};
pub use scene::{Approach, FitSet, Scene};
pub use scene::{Train, TrainSpeed};
pub use signal::Calibration;
pub use solve::{solve, Method, Settings};
pub use stream::{Counters, Stream};
