//! The `stm32` board: STM32F4-Discovery (STM32F407VG). Clock tree and flash accelerator, the
//! executors' interrupt lines and priorities, the watchdog and the reset reason; its sample
//! sources (ADC2 and DMA in [`adc`], with the supply measured on ADC1 in [`supply`]; or the
//! ADXL375 on SPI1 in `accel`) and the light gate (`gate`); defmt over RTT, panics through
//! panic-probe.

use defmt::{info, unwrap};
use embassy_executor::SendSpawner;
use embassy_stm32::interrupt::{InterruptExt, Priority};
use embassy_stm32::{bind_interrupts, dma, interrupt, peripherals, Config, Peripherals};
use impact_core::Scene;
use impact_firmware::reset_record::{Cause, Record};
use panic_probe as _;

use crate::executors::{HIGH, LOW, MEDIUM};
use crate::tasks::stream::Backpressure;

// The board's sample sources (the high-priority tasks): the ADC, or the ADXL375; the light gate.
#[cfg(feature = "adxl375")]
pub mod accel;
#[cfg(not(feature = "adxl375"))]
pub mod adc;
#[cfg(feature = "selftest")]
pub mod dac;
#[cfg(feature = "light-gate")]
pub mod gate;
#[cfg(not(feature = "adxl375"))]
pub mod supply;

#[cfg(not(feature = "adxl375"))]
bind_interrupts!(
    /// DMA interrupts of the sample source.
    pub struct Irqs {
        DMA2_STREAM2 => dma::InterruptHandler<peripherals::DMA2_CH2>;
    }
);

#[cfg(feature = "adxl375")]
bind_interrupts!(
    /// DMA interrupts of the sample source.
    pub struct Irqs {
        DMA2_STREAM2 => dma::InterruptHandler<peripherals::DMA2_CH2>;
        DMA2_STREAM3 => dma::InterruptHandler<peripherals::DMA2_CH3>;
    }
);

// Three interrupt lines of peripherals this board does not use serve the executors (as in
// embassy's `multiprio` example).
#[interrupt]
unsafe fn UART4() {
    // SAFETY: this line is only the high executor's.
    unsafe { HIGH.on_interrupt() }
}

#[interrupt]
unsafe fn UART5() {
    // SAFETY: this line is only the middle executor's.
    unsafe { MEDIUM.on_interrupt() }
}

#[interrupt]
unsafe fn USART6() {
    // SAFETY: this line is only the low executor's.
    unsafe { LOW.on_interrupt() }
}

/// What the board hands the tasks.
pub struct Setup {
    /// The compiled-in scene ([`impact_firmware::scene::BENCH`]).
    pub scene: Scene,
    /// A live source: the stream never waits for the analysis.
    pub backpressure: Backpressure,
    /// With `--features selftest`: the pulse the DAC plays, which the reporter judges.
    pub selftest: Option<impact_firmware::selftest::Played>,
    /// ADC1, which measured the supply at start-up and goes on measuring it, and what it
    /// measured then.
    #[cfg(not(feature = "adxl375"))]
    supply: (supply::Supply, Option<f32>),
    p: Peripherals,
}

/// Brings the chip up at 168 MHz with the flash accelerator on, logs why it last reset,
/// starts the independent watchdog, and sets the ADC's scale from the supply it measures.
pub fn init(previous: Option<Record>) -> Setup {
    #[allow(unused_mut)]
    let mut p = embassy_stm32::init(clock_config());
    enable_flash_accelerator();
    info!(
        "reset reason: {}",
        reset_reason(previous.is_some_and(|r| r.reset_by_firmware))
    );
    crate::reset::log_previous(previous);
    start_watchdog();
    #[allow(unused_mut)]
    let mut scene = impact_firmware::scene::BENCH;
    #[cfg(not(feature = "adxl375"))]
    let (supply, vdda) = {
        // SAFETY: ADC1 is taken here and `p.ADC1` never used again: the supply's measurements
        // own it (the clone stays in `Setup.p` only because `p` moves whole).
        let mut supply = supply::Supply::new(unsafe { p.ADC1.clone_unchecked() });
        let (gain, vdda) = analog_scale(supply.vdda_v());
        scene.calibration.gain_m_s2_per_count = gain;
        (supply, vdda)
    };
    #[cfg(feature = "selftest")]
    let selftest = Some(impact_firmware::selftest::Played::new(
        scene.calibration.gain_m_s2_per_count,
        scene.calibration.sample_rate_hz,
        vdda,
    ));
    #[cfg(not(feature = "selftest"))]
    let selftest = None;
    Setup {
        scene,
        backpressure: Backpressure::Never,
        selftest,
        #[cfg(not(feature = "adxl375"))]
        supply: (supply, vdda),
        p,
    }
}

/// The ADC's gain, m/s² per count, for the supply VREFINT measured (logged with the range the
/// ADC then covers), or for the Discovery's nominal 3.0 V when it could not be measured; and
/// the supply measured.
#[cfg(not(feature = "adxl375"))]
fn analog_scale(vdda: Result<f32, impact_firmware::analog::VddaError>) -> (f32, Option<f32>) {
    use impact_firmware::analog::{Scale, VddaError, NOMINAL_VDDA_V, SENSOR};
    let measured = vdda.as_ref().ok().copied();
    let v = match vdda {
        Ok(v) => v,
        Err(e) => {
            match e {
                VddaError::NoCalibration(cal) => {
                    defmt::warn!("VDDA not measured: VREFINT_CAL reads {=u16:#x}", cal)
                }
                VddaError::NoReading => defmt::warn!("VDDA not measured: VREFINT read 0"),
                VddaError::OutOfRange(v) => {
                    defmt::warn!("VDDA not measured: VREFINT gives {=f32} V", v)
                }
            }
            defmt::warn!(
                "the ADC's scale assumes VDDA = {=f32} V (the Discovery's regulator)",
                NOMINAL_VDDA_V
            );
            NOMINAL_VDDA_V
        }
    };
    let s = Scale::new(v, SENSOR);
    info!(
        "ADC scale: VDDA {=f32} V, {=f32} m/s2 per count, 0 m/s2 at code {=f32}, range {=f32} to {=f32} m/s2",
        v,
        s.gain_m_s2_per_count,
        s.zero_counts,
        s.range_m_s2.0,
        s.range_m_s2.1
    );
    (s.gain_m_s2_per_count, measured)
}

/// Why the chip last reset (RCC_CSR's flags, then cleared): a watchdog reset means the
/// firmware stopped: a hang, or a core locked up by a fault it could not stack (an
/// overflowing stack runs into reserved memory below SRAM). A software reset is the
/// firmware's own when it kept a record (`recorded`: a fault, or a stream that ended),
/// otherwise a debugger's (flashing, `probe-rs reset`).
fn reset_reason(recorded: bool) -> &'static str {
    use embassy_stm32::pac::RCC;
    let csr = RCC.csr().read();
    RCC.csr().modify(|w| w.set_rmvf(true));
    if csr.wdgrstf() {
        "independent watchdog (the firmware had stopped: a hang, or a stack overflow that locked up the core)"
    } else if csr.wwdgrstf() {
        "window watchdog"
    } else if csr.sftrstf() && recorded {
        "software, by the firmware (the next line says why)"
    } else if csr.sftrstf() {
        "software, by a debugger (flashing, or probe-rs reset)"
    } else if csr.lpwrrstf() {
        "low-power management"
    } else if csr.borrstf() || csr.porrstf() {
        "power-on or brown-out"
    } else if csr.padrstf() {
        "reset pin (NRST: the button, or the probe flashing)"
    } else {
        "unknown"
    }
}

/// The independent watchdog's timeout, ms: the stream task feeds it with every block (every
/// 0.5 ms at 500 kS/s, every 20 ms from the ADXL375), so only a stopped firmware lets it run
/// out.
const WATCHDOG_TIMEOUT_MS: u16 = 500;

/// Starts the independent watchdog (LSI, about 32 kHz, divided by 32: ~1 ms a count); it
/// resets the chip unless [`feed_watchdog`] runs within [`WATCHDOG_TIMEOUT_MS`]. Once
/// started it cannot be stopped; its counter is frozen while a debugger halts the core
/// (DBGMCU_APB1_FZ, as ST's HAL freezes it), so stepping through code does not reset the
/// board.
fn start_watchdog() {
    use embassy_stm32::pac::iwdg::vals::{Key, Pr};
    use embassy_stm32::pac::{DBGMCU, IWDG};
    DBGMCU.apb1fzr().modify(|w| w.set_iwdg(true));
    IWDG.kr().write(|w| w.set_key(Key::ENABLE));
    IWDG.pr().write(|w| w.set_pr(Pr::DIVIDE_BY32));
    IWDG.rlr().write(|w| w.set_rl(WATCHDOG_TIMEOUT_MS));
    IWDG.kr().write(|w| w.set_key(Key::RESET));
    IWDG.kr().write(|w| w.set_key(Key::START));
}

/// Reloads the watchdog (the stream task, with each block).
pub fn feed_watchdog() {
    use embassy_stm32::pac::iwdg::vals::Key;
    embassy_stm32::pac::IWDG
        .kr()
        .write(|w| w.set_key(Key::RESET));
}

/// After a fault has been kept and logged: resets the chip (the next start-up logs the
/// record). A debugger attached gets up to [`PROBE_WAIT_MS`] to read the fault's line first.
pub fn fault_exit() -> ! {
    wait_for_probe();
    crate::reset::commit();
    cortex_m::peripheral::SCB::sys_reset()
}

/// The longest wait for a probe to read the log before a reset, ms (probe-rs polls RTT every
/// few ms; the watchdog is fed meanwhile).
const PROBE_WAIT_MS: u32 = 250;

/// With a debugger attached (DHCSR.C_DEBUGEN), waits until it has read the whole RTT buffer,
/// or [`PROBE_WAIT_MS`]; without one, returns at once (nobody would read it: the reset
/// record carries the fault to the next start-up).
fn wait_for_probe() {
    // SAFETY: a read of the Debug Halting Control and Status Register.
    let dhcsr = unsafe { (*cortex_m::peripheral::DCB::PTR).dhcsr.read() };
    if dhcsr & 1 == 0 {
        return;
    }
    let mut clock = CycleClock::start();
    while !crate::logger::drained() && clock.elapsed_ms() < PROBE_WAIT_MS {
        feed_watchdog();
    }
}

/// Milliseconds counted by the core's cycle counter (DWT CYCCNT at 168 MHz): a timer that
/// needs no interrupt, so it also runs in the fault handler, unlike a spin loop's guess of
/// cycles per iteration.
struct CycleClock {
    last: u32,
    cycles: u64,
}

impl CycleClock {
    const HZ: u64 = 168_000_000;

    fn start() -> Self {
        // SAFETY: the core peripherals, stolen: DEMCR's trace enable and DWT's cycle counter
        // are set here only, and a running counter is left running.
        let mut cp = unsafe { cortex_m::Peripherals::steal() };
        cp.DCB.enable_trace();
        cp.DWT.enable_cycle_counter();
        Self {
            last: cortex_m::peripheral::DWT::cycle_count(),
            cycles: 0,
        }
    }

    /// Milliseconds since [`CycleClock::start`]; call at least every 25 s (the counter wraps).
    fn elapsed_ms(&mut self) -> u32 {
        let now = cortex_m::peripheral::DWT::cycle_count();
        self.cycles += u64::from(now.wrapping_sub(self.last));
        self.last = now;
        u32::try_from(self.cycles * 1000 / Self::HZ).unwrap_or(u32::MAX)
    }
}

/// ART accelerator on: prefetch and the instruction and data caches (RM0090 3.5.2).
/// embassy-stm32's clock set-up writes FLASH.ACR with the wait states alone (5 at 168 MHz),
/// leaving all three off; every cycle figure in the README assumes them on.
fn enable_flash_accelerator() {
    use embassy_stm32::pac::FLASH;
    // A cache may only be reset while it is disabled.
    FLASH.acr().modify(|w| {
        w.set_icen(false);
        w.set_dcen(false);
    });
    FLASH.acr().modify(|w| {
        w.set_icrst(true);
        w.set_dcrst(true);
    });
    FLASH.acr().modify(|w| {
        w.set_icrst(false);
        w.set_dcrst(false);
    });
    FLASH.acr().modify(|w| {
        w.set_prften(true);
        w.set_icen(true);
        w.set_dcen(true);
    });
}

// The executors, below the device interrupts (DMA, TIM5's light-gate captures and the time
// driver's timer stay at priority 0), on three lines of peripherals the board does not use.

/// Starts the high executor (the sample source) at NVIC priority 2, on UART4's line.
pub fn start_high() -> SendSpawner {
    interrupt::UART4.set_priority(Priority::P2);
    HIGH.start(interrupt::UART4)
}

/// Starts the middle executor (the stream and the reporter) at priority 3, on UART5's line.
pub fn start_medium() -> SendSpawner {
    interrupt::UART5.set_priority(Priority::P3);
    MEDIUM.start(interrupt::UART5)
}

/// Starts the low executor (the analysis) at priority 4, on USART6's line.
pub fn start_low() -> SendSpawner {
    interrupt::USART6.set_priority(Priority::P4);
    LOW.start(interrupt::USART6)
}

/// Spawns the sample source (and the light gate) on the high executor.
pub fn spawn_sources(setup: Setup, high: SendSpawner, samples: crate::queues::SampleSender) {
    let p = setup.p;

    #[cfg(not(feature = "adxl375"))]
    {
        use super::adc;
        let dma_buf = adc::dma_buffer();
        let sampler =
            adc::AdcSampler::new(p.ADC2, p.PA1, p.DMA2_CH2, p.TIM3, p.TIM2, Irqs, dma_buf);
        high.spawn(unwrap!(adc::sampler(sampler, samples)));
        let (supply, start) = setup.supply;
        high.spawn(unwrap!(super::supply::watch(supply, start)));
    }

    #[cfg(feature = "adxl375")]
    {
        use super::accel;
        let pins = accel::Spi1Pins {
            sck: p.PA5,
            mosi: p.PA7,
            miso: p.PA6,
            cs: p.PE7,
            lis3dsh_cs: p.PE3,
        };
        let sensor = accel::sensor(p.SPI1, pins, p.DMA2_CH3, p.DMA2_CH2, Irqs);
        high.spawn(unwrap!(accel::sampler(sensor, samples)));
    }

    #[cfg(feature = "selftest")]
    {
        let player = super::dac::player(p.DAC1, p.DMA1_CH5, p.PA4, p.TIM6);
        high.spawn(unwrap!(super::dac::play(player)));
    }

    #[cfg(feature = "light-gate")]
    {
        let beams = super::gate::Beams::new(p.TIM5, p.PA2, p.PA3);
        high.spawn(unwrap!(super::gate::light_gate(beams)));
    }
}

/// The live sources never end; if one does (it gave up), log it and restart the board.
pub fn end_of_stream(success: bool) -> ! {
    // The board's sources never end on their own: a source that gave up (a sensor that
    // would not come up) is retried by restarting, after a pause that lets the log be read;
    // the watchdog is fed meanwhile, so the next start-up logs a software reset, not a hang.
    defmt::error!(
        "sample stream ended (success: {}); restarting in {} s",
        success,
        RESTART_AFTER_S
    );
    crate::reset::keep(Cause::StreamEnded);
    // Timed by the cycle counter, the watchdog fed all along (a spin loop's `asm::delay` ran
    // about three times the cycles it was given).
    let mut clock = CycleClock::start();
    while clock.elapsed_ms() < RESTART_AFTER_S * 1000 {
        feed_watchdog();
    }
    crate::reset::commit();
    cortex_m::peripheral::SCB::sys_reset()
}

/// Seconds from the end of the sample stream to the restart.
const RESTART_AFTER_S: u32 = 5;

/// 168 MHz SYSCLK from the Discovery board's 8 MHz HSE crystal, as in embassy's stm32f4
/// examples: 8 MHz / 4 * 168 = 336 MHz VCO; P = /2 -> 168 MHz, Q = /7 -> 48 MHz (USB).
/// AHB 168 MHz, APB1 42 MHz (timers 84 MHz), APB2 84 MHz (timers 168 MHz, ADC clock source:
/// embassy-stm32 divides it by 4 to 21 MHz, the fastest ADCCLK not above 36 MHz).
fn clock_config() -> Config {
    use embassy_stm32::rcc::{
        AHBPrescaler, APBPrescaler, Hse, HseMode, Pll, PllMul, PllPDiv, PllPreDiv, PllQDiv,
        PllSource, Sysclk,
    };
    use embassy_stm32::time::Hertz;

    let mut config = Config::default();
    config.rcc.hse = Some(Hse {
        freq: Hertz(8_000_000),
        mode: HseMode::Oscillator,
    });
    config.rcc.pll_src = PllSource::HSE;
    config.rcc.pll = Some(Pll {
        prediv: PllPreDiv::DIV4,
        mul: PllMul::MUL168,
        divp: Some(PllPDiv::DIV2),
        divq: Some(PllQDiv::DIV7),
        divr: None,
    });
    config.rcc.ahb_pre = AHBPrescaler::DIV1;
    config.rcc.apb1_pre = APBPrescaler::DIV4;
    config.rcc.apb2_pre = APBPrescaler::DIV2;
    config.rcc.sys = Sysclk::PLL1_P;
    config
}
