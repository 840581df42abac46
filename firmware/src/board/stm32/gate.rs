//! The light gate's hardware (feature `light-gate`): two beams on PB0 (first, farther from the
//! barrier) and PB1 (second), rising edge when cut. Each cut is time-stamped in its EXTI
//! interrupt handler, at device priority, so neither the executors nor the analysis add to the
//! measured time; the task (high executor) pairs the cuts ([`super::light_gate::Pairing`]) and
//! hands the approach speed to the stream.

use defmt::{info, warn};
use embassy_stm32::exti::{ExtiInput, TriggerEdge};
use embassy_stm32::gpio::Pull;
use embassy_stm32::peripherals::{EXTI0, EXTI1, PB0, PB1};
use embassy_stm32::{interrupt, pac, Peri};
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::channel::Channel;
use embassy_time::Instant;

use crate::tasks::stream::APPROACH_SPEED;
use core::sync::atomic::{AtomicBool, AtomicU32, Ordering};

use impact_firmware::light_gate::{new_cut, Beam, Pairing, Passage};
use impact_firmware::scene::LIGHT_GATE_SPACING_M;

/// Cuts waiting for the task: (beam, µs since start-up).
static CUTS: Channel<CriticalSectionRawMutex, (Beam, u64), 4> = Channel::new();

#[interrupt]
fn EXTI0() {
    cut(0, Beam::First);
}

#[interrupt]
fn EXTI1() {
    cut(1, Beam::Second);
}

/// Each line's previous edge, µs (low 32 bits), and whether there was one.
static LAST_EDGE_US: [AtomicU32; 2] = [AtomicU32::new(0), AtomicU32::new(0)];
static SEEN: [AtomicBool; 2] = [AtomicBool::new(false), AtomicBool::new(false)];

/// Time-stamps first, then clears the line's pending bit (write 1), debounces (edges of one
/// beam closer than `light_gate::DEBOUNCE_US` are one cut, at the first edge) and queues the
/// cut (a full queue drops it: four cuts faster than the task can take them are not a
/// passage).
fn cut(line: usize, beam: Beam) {
    let t = Instant::now().as_micros();
    pac::EXTI
        .pr(0)
        .write_value(pac::exti::regs::Lines(1 << line));
    let (Some(last), Some(seen)) = (LAST_EDGE_US.get(line), SEEN.get(line)) else {
        return;
    };
    let now = t as u32;
    let previous = seen
        .swap(true, Ordering::Relaxed)
        .then(|| last.load(Ordering::Relaxed));
    last.store(now, Ordering::Relaxed);
    if new_cut(previous, now) {
        let _ = CUTS.try_send((beam, t));
    }
}

/// The two beams' inputs, kept alive (and armed on the rising edge) for the program's life.
pub struct Beams {
    _first: ExtiInput<'static, embassy_stm32::mode::Blocking>,
    _second: ExtiInput<'static, embassy_stm32::mode::Blocking>,
}

impl Beams {
    pub fn new(
        pb0: Peri<'static, PB0>,
        exti0: Peri<'static, EXTI0>,
        pb1: Peri<'static, PB1>,
        exti1: Peri<'static, EXTI1>,
    ) -> Self {
        Self {
            _first: ExtiInput::new_blocking(pb0, exti0, Pull::Down, TriggerEdge::Rising),
            _second: ExtiInput::new_blocking(pb1, exti1, Pull::Down, TriggerEdge::Rising),
        }
    }
}

/// Pairs the cuts into passages: toward the barrier gives the approach speed of the next
/// impact; away (a rebound) is logged; a refused pair is logged and ignored (the scene's v0
/// stays in force).
#[embassy_executor::task]
pub async fn light_gate(_beams: Beams) {
    let mut pairing = Pairing::new();
    loop {
        let (beam, t) = CUTS.receive().await;
        match pairing.cut(beam, t, LIGHT_GATE_SPACING_M) {
            Some(Ok(Passage::Toward(v0))) => {
                info!("light_gate direction=toward v0_m_s={=f32}", v0);
                APPROACH_SPEED.signal(v0);
            }
            Some(Ok(Passage::Away(v))) => info!("light_gate direction=away speed_m_s={=f32}", v),
            Some(Err(e)) => warn!("light_gate refused: {}", e),
            None => {}
        }
    }
}
