//! The link to the firmware: its log lines read back ([`log`], [`fields`]; checked,
//! [`plausible`]; as JSON, [`log_json`]; the windows it sends, [`waves`]), its raw defmt
//! stream decoded ([`decode`]), the emulated board run ([`qemu`]) and its memory budget read
//! off the ELF ([`memory`]).

pub mod decode;
pub mod fields;
pub mod log;
pub mod log_json;
pub mod memory;
pub mod plausible;
pub mod qemu;
pub mod waves;
