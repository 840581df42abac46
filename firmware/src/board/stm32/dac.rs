//! The self-test's player (`--features selftest`): DAC channel 1 on PA4 plays
//! [`selftest::TABLE`] from flash, one code per TIM6 update at [`selftest::DAC_RATE_HZ`],
//! over and over (DMA1 stream 5, channel 7, circular), with no CPU after the start. A jumper
//! from PA4 to PA1 feeds it to the ADC (`docs/board.md`, "Bring-up self-test").
//!
//! The channel takes TIM6's TRGO as its trigger (TSEL1 = 000, written by the driver before it
//! enables the channel); TEN1 is set by hand while the channel is off, the rest level loaded,
//! and the DAC asks the DMA for the next code on each trigger (DMAEN1) and moves it to its
//! output three APB1 cycles later (RM0090 14.3.6). TIM6 starts only once the DMA stream is
//! armed: a trigger before it would set DMAUDR1 and stop the DAC's requests for good. The
//! player checks DMAUDR1 once a second and says so if it is ever set.
//!
//! On the Discovery PA4 also goes to the CS43L22 audio codec's I2S word-select pin (UM1472),
//! an input: it only loads the DAC's buffered output.

use defmt::{error, info, warn};
use embassy_futures::join::join;
use embassy_futures::select::select;
use embassy_stm32::dac::{DacChannel, ValueArray};
use embassy_stm32::mode::Async;
use embassy_stm32::pac::timer::vals::Mms;
use embassy_stm32::peripherals::{DAC1, DMA1_CH5, PA4, TIM6};
use embassy_stm32::time::Hertz;
use embassy_stm32::timer::low_level::{RoundTo, Timer};
use embassy_stm32::{bind_interrupts, dma, peripherals, triggers, Peri};
use embassy_time::Duration;
use impact_firmware::selftest;

bind_interrupts!(
    /// The DAC's DMA stream.
    pub struct DacIrqs {
        DMA1_STREAM5 => dma::InterruptHandler<peripherals::DMA1_CH5>;
    }
);

/// The DAC channel and the timer that paces it (dropping the timer would stop its clock).
pub struct Player {
    dac: DacChannel<'static, Async>,
    pace: Timer<'static, TIM6>,
}

/// Sets TIM6 to update at the DAC's rate (TRGO on update, not started) and the DAC to take it
/// as its trigger; nothing plays until [`play`] runs.
pub fn player(
    dac: Peri<'static, DAC1>,
    dma: Peri<'static, DMA1_CH5>,
    pin: Peri<'static, PA4>,
    tim: Peri<'static, TIM6>,
) -> Player {
    let pace = Timer::new(tim);
    pace.set_frequency(Hertz(selftest::DAC_RATE_HZ), RoundTo::Slower);
    pace.generate_update_event();
    // TRGO on update (TIM6 is a basic timer: embassy's `set_master_mode` wants a general one).
    pace.regs_basic().cr2().modify(|w| w.set_mms(Mms::UPDATE));
    let dac = DacChannel::new_triggered(dac, dma, triggers::TIM6_TRGO, DacIrqs, pin);
    // The driver enabled the channel with TSEL1 = TIM6 and TEN1 clear. EN1 is cleared by
    // hand (its `disable` would gate the DAC's clock), the rest level loaded, and TEN1 set
    // while it is off; `write` sets EN1 and DMAEN1 again.
    let regs = embassy_stm32::pac::DAC1;
    regs.cr().modify(|w| w.set_en(0, false));
    regs.dhr12r(0).write(|w| w.set_dhr(selftest::ZERO_CODE));
    regs.cr().modify(|w| w.set_ten(0, true));
    let r = pace.regs_basic();
    let (psc, arr) = (u32::from(r.psc().read()), u32::from(r.arr().read().arr()));
    let rate = pace.get_clock_frequency().0 / ((psc + 1) * (arr + 1));
    if rate == selftest::DAC_RATE_HZ {
        info!("self-test: the DAC plays at {=u32} Hz", rate);
    } else {
        warn!(
            "self-test: the DAC plays at {=u32} Hz, not {=u32} Hz (the played pulse is judged at the latter)",
            rate,
            selftest::DAC_RATE_HZ
        );
    }
    Player { dac, pace }
}

/// Plays the table for ever (the circular transfer never completes): the DMA armed first,
/// then TIM6 started; DMAUDR1 checked once a second.
#[embassy_executor::task]
pub async fn play(mut p: Player) {
    info!(
        "self-test: a {=f32} s half-sine of {=u16} codes every {=f32} s on PA4 (jumper it to PA1)",
        selftest::PULSE_S,
        selftest::AMPLITUDE_CODES,
        selftest::PERIOD_S
    );
    let pace = &p.pace;
    let playing = join(
        p.dac.write(ValueArray::Bit12Right(&selftest::TABLE), true),
        // Polled after the write's first poll has armed the DMA stream.
        async { pace.start() },
    );
    let watch = async {
        let mut said = false;
        loop {
            embassy_time::Timer::after(Duration::from_secs(1)).await;
            if embassy_stm32::pac::DAC1.sr().read().dmaudr(0) && !said {
                error!("self-test: the DAC's DMA underran (DMAUDR1): the DAC stopped playing");
                said = true;
            }
        }
    };
    select(playing, watch).await;
}
