//! Numerical building blocks with no physics in them: bracketed roots and minima, quadrature.

pub mod quad;
pub mod roots;
