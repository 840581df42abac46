//! The link to the firmware: its log lines read back ([`log`], [`fields`]; the windows it
//! sends, [`waves`]), its raw defmt stream decoded ([`decode`]), the emulated board run
//! ([`qemu`]) and its memory budget read off the ELF ([`memory`]).

pub mod decode;
pub mod fields;
pub mod log;
pub mod memory;
pub mod qemu;
pub mod waves;
