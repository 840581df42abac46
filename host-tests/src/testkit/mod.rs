//! What the tests and the benchmarks share: the model cases with their exact results
//! ([`cases`]), how results are compared ([`compare`]) and a generated drop as a sensor
//! records it ([`sensor`]).

pub mod cases;
pub mod compare;
pub mod sensor;
