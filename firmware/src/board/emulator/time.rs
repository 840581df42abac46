//! embassy-time driver for the emulator: the MPS2 FPGA's free-running 25 MHz counter for the
//! time, and CMSDK timer 1 (0x4000_1000, IRQ 9) in one-shot mode for the alarms.
//!
//! Both follow QEMU's virtual clock, so under `-icount` the firmware's time is instruction
//! time. One-shot alarms re-armed from the interrupt, rather than a periodic tick, because
//! QEMU 7.2 with `-icount sleep=off` skips every other period of a periodic timer that wakes
//! the CPU from `wfi` (fixed upstream in QEMU 10.0, gitlab issue 2703).

use core::cell::RefCell;
use core::task::Waker;

use cortex_m::peripheral::NVIC;
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::blocking_mutex::Mutex;
use embassy_time_driver::{Driver, TICK_HZ};
use embassy_time_queue_utils::Queue;

use super::lines::Irq;
use super::timer::CmsdkTimer;

/// The clock of the FPGA counter and of the CMSDK timers (SYSCLK_FRQ in QEMU's hw/arm/mps2.c).
pub const CLOCK_HZ: u64 = 25_000_000;

/// The FPGA I/O block's COUNTER register: counts `CLOCK_HZ`, wraps every 171.8 s.
const FPGAIO_COUNTER: *const u32 = 0x4002_8018 as *const u32;

/// The alarm timer.
const ALARM: CmsdkTimer = CmsdkTimer::at(0x4000_1000);

/// Longest one-shot delay, counter ticks: well under half the counter's wrap, so the
/// interrupt handler extends the counter to 64 bits at least twice per wrap (the alarm stays
/// armed with no timer waiting: [`State::arm`]).
const MAX_DELAY: u64 = 1 << 31;

const CYCLES_PER_TICK: u64 = CLOCK_HZ / TICK_HZ;
const _: () = assert!(
    CLOCK_HZ % TICK_HZ == 0,
    "embassy-time's tick rate must divide the 25 MHz counter"
);

struct State {
    /// Counter wraps seen.
    wraps: u64,
    /// The counter at the last read.
    last: u32,
    queue: Queue,
}

impl State {
    /// The counter extended to 64 bits (called at least once per wrap: see `MAX_DELAY`).
    fn counter(&mut self) -> u64 {
        // SAFETY: a read of a device register.
        let now = unsafe { core::ptr::read_volatile(FPGAIO_COUNTER) };
        if now < self.last {
            self.wraps += 1;
        }
        self.last = now;
        (self.wraps << 32) | u64::from(now)
    }

    /// Arms the alarm for `at` (embassy ticks; `u64::MAX`: none, and the alarm comes after
    /// `MAX_DELAY` all the same, so that the counter is read twice per wrap whoever else reads
    /// it: a slowed replay's DMA may not for longer than a wrap).
    fn arm(&mut self, at: u64) {
        let now = self.counter();
        let delay = at
            .saturating_mul(CYCLES_PER_TICK)
            .saturating_sub(now)
            .clamp(1, MAX_DELAY);
        ALARM.one_shot(delay as u32);
    }
}

struct CounterDriver {
    state: Mutex<CriticalSectionRawMutex, RefCell<State>>,
}

embassy_time_driver::time_driver_impl!(static DRIVER: CounterDriver = CounterDriver {
    state: Mutex::new(RefCell::new(State {
        wraps: 0,
        last: 0,
        queue: Queue::new(),
    })),
});

/// Counter ticks (25 MHz) since power-up, for the emulated DMA's deadlines.
pub fn counter() -> u64 {
    critical_section::with(|cs| DRIVER.state.borrow(cs).borrow_mut().counter())
}

/// Unmasks the alarm interrupt. Call once, before anything waits on a timer.
pub fn init() {
    ALARM.stop();
    // SAFETY: the alarm interrupt's handler is `on_alarm`, reached through `irq::DefaultHandler`.
    unsafe { NVIC::unmask(Irq::Timer1) };
}

/// The alarm timer's interrupt.
pub fn on_alarm() {
    ALARM.clear();
    critical_section::with(|cs| {
        let mut state = DRIVER.state.borrow(cs).borrow_mut();
        let now = state.counter() / CYCLES_PER_TICK;
        // Wakes every expired timer; returns the next deadline.
        let next = state.queue.next_expiration(now);
        state.arm(next);
    });
}

impl Driver for CounterDriver {
    fn now(&self) -> u64 {
        critical_section::with(|cs| self.state.borrow(cs).borrow_mut().counter() / CYCLES_PER_TICK)
    }

    fn schedule_wake(&self, at: u64, waker: &Waker) {
        critical_section::with(|cs| {
            let mut state = self.state.borrow(cs).borrow_mut();
            if state.queue.schedule_wake(at, waker) {
                let now = state.counter() / CYCLES_PER_TICK;
                // Wakes at once whatever is already due (including `at` if it has passed).
                let next = state.queue.next_expiration(now);
                state.arm(next);
            }
        });
    }
}
