//! The board the firmware runs on, one folder each, chosen by cargo feature: its bring-up
//! (clocks, the executors' interrupt lines and priorities, the watchdog), its sample sources
//! (the high-priority tasks) and how a stream ends or a fault exits.
//!
//! Each board offers the same functions: `init` (brings the chip up, gives the scene),
//! `start_high`/`start_medium`/`start_low` (the executors), `spawn_sources`, `feed_watchdog`,
//! `end_of_stream` and `fault_exit`.

#[cfg(feature = "emulator")]
pub mod emulator;
#[cfg(feature = "stm32")]
pub mod stm32;

#[cfg(feature = "emulator")]
pub use emulator::*;
#[cfg(feature = "stm32")]
pub use stm32::*;
