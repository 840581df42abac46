//! The link to the firmware: its log lines, one struct per kind ([`mod@line`]), a log read back
//! and checked ([`log`]; its reports' values, [`plausible`]; as JSON, [`log_json`]; the
//! windows it sends, [`waves`]), its raw defmt stream decoded ([`decode`]), the emulated board
//! run ([`qemu`]) and its memory budget read off the ELF ([`memory`]).

pub mod decode;
pub mod line;
pub mod log;
pub mod log_json;
pub mod memory;
pub mod plausible;
pub mod qemu;
pub mod waves;
