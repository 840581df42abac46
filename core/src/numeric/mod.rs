//! Numerical building blocks with no physics in them: bracketed roots and minima, quadrature,
//! the fits' `e^y` in f32.

pub mod dopri;
pub mod exp;
pub mod quad;
pub mod roots;
