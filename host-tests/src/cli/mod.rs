//! The subcommands, each with its options, its run and its output (`bin/impact.rs` parses
//! and dispatches).

pub mod analyze;
pub mod bench;
pub mod direction;
pub mod emulate;
pub mod html;
pub mod log;
pub mod matches;
pub mod progress;
pub mod pulse;
pub mod selftest;
pub mod series;
pub mod simulate;
pub mod srs_required;
pub mod synth;
pub mod watch;
