//! The light gate's hardware (feature `light-gate`): two beams on PA2 (first, farther from the
//! barrier) and PA3 (second), rising edge when cut, time-stamped by TIM5's input capture
//! (channels 3 and 4, AF2). TIM5 counts at 1 MHz on 32 bits; at a beam's rising edge the
//! hardware copies the count into CCR3 or CCR4, so the time stamp is the edge's, whatever the
//! interrupt's latency (the logger masks interrupts for a few µs while it copies a line: an
//! EXTI handler reading a clock was late by that: up to ~0.3 % of the speed at 10 m/s, 3 %
//! at 100 m/s). The input filter (8 stable samples at 10.5 MHz) drops glitches under about
//! 0.67 µs and delays each edge by 0.67–0.76 µs and a few timer clocks (95 ns of jitter, under
//! the 1 µs count), which the speed, a difference, hardly sees.
//!
//! The interrupt (device priority) reads the captures in the order they were taken, makes them
//! one time line ([`CaptureClock`]), debounces (edges of one beam closer than
//! `light_gate::DEBOUNCE_US` are one cut, at the first) and queues the cut; the task (high
//! executor) pairs the cuts ([`Pairing`]) and hands the approach speed to the stream. A beam
//! edge that came before the previous one's capture was read (an over-capture: a bounce
//! within the interrupt's latency) is counted and logged: the stamp is then the later edge's.

use core::sync::atomic::{AtomicBool, AtomicU32, Ordering};

use defmt::{info, warn};
use embassy_stm32::gpio::Pull;
use embassy_stm32::interrupt::InterruptExt;
use embassy_stm32::pac::timer::vals::{Ckd, FilterValue};
use embassy_stm32::peripherals::{PA2, PA3, TIM5};
use embassy_stm32::time::Hertz;
use embassy_stm32::timer::input_capture::CapturePin;
use embassy_stm32::timer::low_level::{InputCaptureMode, InputTISelection, Timer};
use embassy_stm32::timer::{Ch3, Ch4, Channel as TimChannel};
use embassy_stm32::{interrupt, Peri};
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::channel::Channel;
use embassy_time::Instant;

use crate::tasks::stream::APPROACH_SPEED;

use impact_firmware::light_gate::{
    in_capture_order, new_cut, Beam, CaptureClock, Pairing, Passage,
};
use impact_firmware::scene::LIGHT_GATE_SPACING_M;

/// Cuts waiting for the task: (beam, µs on the capture clock's line).
static CUTS: Channel<CriticalSectionRawMutex, (Beam, u64), 4> = Channel::new();

/// The capture counts made into one time line; only the interrupt touches it.
static CLOCK: Mutex<CriticalSectionRawMutex, core::cell::Cell<CaptureClock>> =
    Mutex::new(core::cell::Cell::new(CaptureClock::new()));

/// Each beam's previous edge, µs (low 32 bits), and whether there was one.
static LAST_EDGE_US: [AtomicU32; 2] = [AtomicU32::new(0), AtomicU32::new(0)];
static SEEN: [AtomicBool; 2] = [AtomicBool::new(false), AtomicBool::new(false)];

/// Edges captured over an unread capture (bounces within the interrupt's latency).
static OVERCAPTURES: AtomicU32 = AtomicU32::new(0);

/// The beams' capture channels: CH3 (PA2) the first beam, CH4 (PA3) the second.
const CHANNELS: [(TimChannel, Beam); 2] = [
    (TimChannel::Ch3, Beam::First),
    (TimChannel::Ch4, Beam::Second),
];

/// The capture clock's rate, Hz: µs counts.
const CAPTURE_HZ: u32 = 1_000_000;

#[interrupt]
fn TIM5() {
    let regs = embassy_stm32::pac::TIM5;
    let sr = regs.sr().read();
    let mut taken: [Option<(u32, Beam)>; 2] = [None, None];
    for (slot, (ch, beam)) in taken.iter_mut().zip(CHANNELS) {
        let i = ch.index();
        // An over-capture is counted whenever seen (it may come without CCxIF when the
        // capture it overwrote was read in the meantime).
        if sr.ccof(i) {
            OVERCAPTURES.fetch_add(1, Ordering::Relaxed);
        }
        if sr.ccif(i) {
            // Reading CCR clears CCxIF.
            *slot = Some((regs.ccr(i).read(), beam));
        }
    }
    // The over-capture flags seen are cleared (SR's flags clear on a written 0; a written 1
    // leaves a flag as it is, so one raised since the read stays for the next interrupt).
    regs.sr().write(|w| {
        w.0 = !0;
        for (ch, _) in CHANNELS {
            w.set_ccof(ch.index(), !sr.ccof(ch.index()));
        }
    });
    let coarse = Instant::now().as_micros();
    let cuts = match taken {
        [Some(a), Some(b)] => in_capture_order(a, b).map(Some),
        [a, b] => [a.or(b), None],
    };
    for (raw, beam) in cuts.into_iter().flatten() {
        let t = CLOCK.lock(|c| {
            let mut clock = c.get();
            let t = clock.extend(raw, coarse);
            c.set(clock);
            t
        });
        cut(beam, t);
    }
}

/// Debounces (edges of one beam closer than `light_gate::DEBOUNCE_US` are one cut, at the
/// first edge) and queues the cut (a full queue drops it: four cuts faster than the task can
/// take them are not a passage).
fn cut(beam: Beam, t: u64) {
    let line = match beam {
        Beam::First => 0,
        Beam::Second => 1,
    };
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

/// TIM5 capturing both beams, and their pins (kept for the program's life).
pub struct Beams {
    _timer: Timer<'static, TIM5>,
    _first: CapturePin<'static, TIM5, Ch3>,
    _second: CapturePin<'static, TIM5, Ch4>,
}

impl Beams {
    /// TIM5 at 1 MHz, free-running over 32 bits; CH3 and CH4 capture their pin's rising edge
    /// through the input filter; their interrupts on.
    pub fn new(
        tim5: Peri<'static, TIM5>,
        pa2: Peri<'static, PA2>,
        pa3: Peri<'static, PA3>,
    ) -> Self {
        let first = CapturePin::new(pa2, Pull::Down);
        let second = CapturePin::new(pa3, Pull::Down);
        let mut t = Timer::new(tim5);
        t.set_tick_freq(Hertz(CAPTURE_HZ));
        t.regs_gp32().arr().write_value(u32::MAX);
        // fDTS = the timer's clock (84 MHz); the filter samples at fDTS/8 = 10.5 MHz.
        t.set_clock_division(Ckd::DIV1);
        for (ch, _) in CHANNELS {
            t.set_input_ti_selection(ch, InputTISelection::Normal);
            t.set_input_capture_filter(ch, FilterValue::FDTS_DIV8_N8);
            t.set_input_capture_mode(ch, InputCaptureMode::Rising);
            t.set_input_capture_prescaler(ch, 0);
            t.enable_channel(ch, true);
            t.clear_input_interrupt(ch);
            t.enable_input_interrupt(ch, true);
        }
        t.regs_gp32().cnt().write_value(0);
        t.start();
        let rate = t.get_clock_frequency().0 / (u32::from(t.regs_gp32().psc().read()) + 1);
        info!("light gate: TIM5 captures at {=u32} Hz", rate);
        // Device priority, with the DMA and the time driver: above every executor.
        interrupt::TIM5.set_priority(embassy_stm32::interrupt::Priority::P0);
        // SAFETY: the handler above is ready; it touches TIM5 and this module's statics.
        unsafe { interrupt::TIM5.enable() };
        Self {
            _timer: t,
            _first: first,
            _second: second,
        }
    }
}

/// Pairs the cuts into passages: toward the barrier gives the approach speed of the next
/// impact; away (a rebound) is logged; a refused pair is logged and ignored (the scene's v0
/// stays in force).
#[embassy_executor::task]
pub async fn light_gate(_beams: Beams) {
    let mut pairing = Pairing::new();
    let mut overcaptures = 0;
    loop {
        let (beam, t) = CUTS.receive().await;
        let now = OVERCAPTURES.load(Ordering::Relaxed);
        if now != overcaptures {
            warn!(
                "light_gate: {=u32} edges came before the previous capture was read (bounces): those cuts are stamped at a later edge",
                now
            );
            overcaptures = now;
        }
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
