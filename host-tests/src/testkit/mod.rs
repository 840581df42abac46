//! What the tests and the benchmarks share: the model cases with their exact results
//! ([`cases`]) and how results are compared ([`compare`]).

pub mod cases;
pub mod compare;
