//! The board-agnostic half of every sample source: the block sender that numbers the blocks
//! and turns losses into exact counts ([`sender`]), and the polling loop of a three-axis FIFO
//! ([`poll`], the ADXL375's on the board and its emulation). The sources themselves are the
//! boards' (`board/stm32/{adc, accel, gate}.rs`, `board/emulator/replay.rs`).

#[cfg(any(feature = "adxl375", feature = "emulator"))]
pub mod poll;
pub mod sender;
