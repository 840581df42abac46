//! The benchmarks (`impact bench …`): run time against error on the host ([`precision`],
//! [`two_body`]), the solvers' stability sweep ([`stability`]), the pipeline's throughput and
//! a soak ([`throughput`], [`soak`]), the Cortex-M4's exact instruction counts ([`m4`]) and
//! the firmware in real-time emulation ([`realtime`]).

pub mod m4;
pub mod precision;
pub mod realtime;
pub mod soak;
pub mod stability;
pub mod throughput;
pub mod two_body;
