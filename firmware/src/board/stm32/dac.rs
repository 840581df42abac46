//! The self-test's player (`--features selftest`): DAC channel 1 on PA4 plays
//! [`selftest::TABLE`] from flash, one code per TIM6 update at [`selftest::DAC_RATE_HZ`],
//! over and over (DMA1 stream 5, channel 7, circular), with no CPU after the start. A jumper
//! from PA4 to PA1 feeds it to the ADC (`docs/board.md`, "Bring-up self-test").
//!
//! embassy-stm32 0.6 offers no DAC trigger but the software one on the F407, so the channel
//! is made with that and its trigger selection then set to TIM6's TRGO (RM0090 14.5.1:
//! TSEL1 = 000) while the channel is off; the DAC asks the DMA for the next code on each
//! trigger (DMAEN1), and moves it to its output one APB1 cycle later.
//!
//! On the Discovery PA4 is also the CS43L22 audio codec's I2S word-select input (UM1472); the
//! codec is held in reset (PD4 low) and its input only loads the DAC's buffered output.

use defmt::{info, warn};
use embassy_stm32::dac::{DacChannel, ValueArray, SOFTWARE};
use embassy_stm32::mode::Async;
use embassy_stm32::pac::timer::vals::Mms;
use embassy_stm32::peripherals::{DAC1, DMA1_CH5, PA4, TIM6};
use embassy_stm32::time::Hertz;
use embassy_stm32::timer::low_level::{RoundTo, Timer};
use embassy_stm32::{bind_interrupts, dma, peripherals, Peri};
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
    _pace: Timer<'static, TIM6>,
}

/// Sets TIM6 to update at the DAC's rate (TRGO on update) and the DAC to take it as its
/// trigger; nothing plays until [`play`] runs.
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
    let dac = DacChannel::new_triggered(dac, dma, SOFTWARE, DacIrqs, pin);
    // The driver enabled the channel with TSEL1 = software and TEN1 clear. EN1 is cleared by
    // hand (its `disable` would gate the DAC's clock), TSEL1 = 000 (TIM6 TRGO) and TEN1 set
    // while it is off, and the rest level loaded; `write` sets EN1 and DMAEN1 again.
    let regs = embassy_stm32::pac::DAC1;
    regs.cr().modify(|w| w.set_en(0, false));
    regs.cr().modify(|w| {
        w.set_tsel(0, 0);
        w.set_ten(0, true);
    });
    regs.dhr12r(0).write(|w| w.set_dhr(selftest::ZERO_CODE));
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
    pace.start();
    Player { dac, _pace: pace }
}

/// Plays the table for ever (the circular transfer never completes).
#[embassy_executor::task]
pub async fn play(mut p: Player) {
    info!(
        "self-test: a {=f32} s half-sine of {=u16} codes every {=f32} s on PA4 (jumper it to PA1)",
        selftest::PULSE_S,
        selftest::AMPLITUDE_CODES,
        selftest::PERIOD_S
    );
    p.dac
        .write(ValueArray::Bit12Right(&selftest::TABLE), true)
        .await;
}
