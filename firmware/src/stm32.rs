//! The `stm32` board: STM32F4-Discovery (STM32F407VG). Clock tree, interrupt bindings and
//! the sample source's peripherals; defmt over RTT, panics through panic-probe.

use defmt::{info, unwrap};
use embassy_executor::Spawner;
use embassy_stm32::{bind_interrupts, dma, peripherals, Config};
use {defmt_rtt as _, panic_probe as _};

#[cfg(not(feature = "adxl375"))]
bind_interrupts!(
    /// DMA interrupts of the sample source.
    pub struct Irqs {
        DMA2_STREAM0 => dma::InterruptHandler<peripherals::DMA2_CH0>;
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

/// Brings the chip up at 168 MHz and spawns the sample source; the monitor runs the scene
/// compiled in ([`crate::scene::BENCH`]).
pub fn start(spawner: Spawner, samples: crate::tasks::SampleSender) -> impact_core::Scene {
    let p = embassy_stm32::init(clock_config());

    #[cfg(not(feature = "adxl375"))]
    {
        use crate::source::adc;
        let dma_buf = adc::dma_buffer();
        let sampler = adc::AdcSampler::new(p.ADC1, p.PA1, p.DMA2_CH0, p.TIM3, Irqs, dma_buf);
        spawner.spawn(unwrap!(adc::sampler(sampler, samples)));
    }

    #[cfg(feature = "adxl375")]
    {
        use crate::source::accel;
        let pins = accel::Spi1Pins {
            sck: p.PA5,
            mosi: p.PA7,
            miso: p.PA6,
            cs: p.PE7,
            lis3dsh_cs: p.PE3,
        };
        let sensor = accel::sensor(p.SPI1, pins, p.DMA2_CH3, p.DMA2_CH2, Irqs);
        spawner.spawn(unwrap!(accel::sampler(sensor, samples)));
    }

    #[cfg(feature = "light-gate")]
    {
        use embassy_stm32::exti::ExtiInput;
        use embassy_stm32::gpio::Pull;
        let first = ExtiInput::new(p.PB0, p.EXTI0, Pull::Down, GateIrqs);
        let second = ExtiInput::new(p.PB1, p.EXTI1, Pull::Down, GateIrqs);
        spawner.spawn(unwrap!(light_gate(first, second)));
    }
    crate::scene::BENCH
}

#[cfg(feature = "light-gate")]
bind_interrupts!(
    /// EXTI lines of the two light-gate beams (PB0, PB1).
    pub struct GateIrqs {
        EXTI0 => embassy_stm32::exti::InterruptHandler<embassy_stm32::interrupt::typelevel::EXTI0>;
        EXTI1 => embassy_stm32::exti::InterruptHandler<embassy_stm32::interrupt::typelevel::EXTI1>;
    }
);

/// Times the two beam cuts (rising edges on PB0 then PB1) and hands the approach speed to the
/// monitor for the next impact. A second cut that does not come within a second, or a speed
/// that is not plausible, is logged and ignored: the scene's v0 stays in force.
#[cfg(feature = "light-gate")]
#[embassy_executor::task]
async fn light_gate(
    mut first: embassy_stm32::exti::ExtiInput<'static, embassy_stm32::mode::Async>,
    mut second: embassy_stm32::exti::ExtiInput<'static, embassy_stm32::mode::Async>,
) {
    use crate::source::light_gate::speed_m_s;
    use embassy_time::{with_timeout, Duration, Instant};
    loop {
        first.wait_for_rising_edge().await;
        let t1 = Instant::now().as_micros();
        match with_timeout(Duration::from_secs(1), second.wait_for_rising_edge()).await {
            Ok(()) => {
                let t2 = Instant::now().as_micros();
                match speed_m_s(t1, t2, crate::scene::LIGHT_GATE_SPACING_M) {
                    Ok(v0) => {
                        info!("light_gate v0_m_s={=f32} dt_us={=u64}", v0, t2 - t1);
                        crate::tasks::monitor::APPROACH_SPEED.signal(v0);
                    }
                    Err(e) => defmt::warn!(
                        "light_gate refused dt_us={=u64}: {}",
                        t2.saturating_sub(t1),
                        e
                    ),
                }
            }
            Err(_) => defmt::warn!("light_gate: second beam not cut within 1 s"),
        }
    }
}

/// The live sources never end; if one does, log it and keep the reporter's last words.
pub fn end_of_stream(success: bool) {
    info!(
        "sample stream ended (success: {}); sampling has stopped",
        success
    );
}

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
