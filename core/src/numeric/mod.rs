//! Numerical building blocks with no physics in them: bracketed roots and minima, quadrature.

pub mod dopri;
pub mod quad;
pub mod roots;
