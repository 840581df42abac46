//! The supply the ADC converts against (VDDA = VREF+ on the Discovery), measured on ADC1 from
//! VREFINT (channel 17, the only ADC that reaches it) at start-up and then once a second, while
//! ADC2 samples the sensor ([`super::adc`]): the two ADCs run independently, so the
//! measurement takes none of the sampling's conversions.
//!
//! The start-up value sets the ADC's gain for the run (`impact_firmware::analog`); the
//! measurement each second logs `supply vdda_v=… start_vdda_v=… change=…` (the relative
//! change since start-up) and warns when the supply has moved more than
//! [`analog::WARN_CHANGE`]: every reading is then off by about that much, since the gain was
//! set at start-up ([`analog::SupplyChange`]).
//!
//! ADC1 is driven through its registers, not embassy's `Adc`: dropped, that gates ADC1's
//! clock, and its reads spin for each conversion, where these are awaited. Each measurement
//! sets up what it needs (clock on, VREFINT on, channel 17 at 480 cycles), which costs a few
//! register writes and leaves nothing to what ran before it.
//!
//! The start-up measurement runs with ADC2 idle, the later ones while it converts at
//! 500 kS/s; the warning compares each with the first of the later ones (the same
//! conditions), and the line gives the change since start-up too.

use defmt::{info, warn};
use embassy_stm32::pac::adc::vals::SampleTime;
use embassy_stm32::pac::adccommon::vals::Adcpre;
use embassy_stm32::pac::{ADC1, ADC123_COMMON, RCC};
use embassy_stm32::peripherals::ADC1 as Adc1;
use embassy_stm32::Peri;
use embassy_time::{block_for, Duration, Instant, Timer};
use impact_firmware::analog::{self, VddaError};

/// Conversions of VREFINT averaged per measurement (each sampled 480 ADCCLK cycles, 22.9 us:
/// VREFINT needs 10 us of sampling, DS8626 Table 71).
const READS: u32 = 16;

/// VREFINT's channel on ADC1.
const VREFINT_CHANNEL: u8 = 17;

/// One conversion's wait: 480 + 12 ADCCLK cycles at 21 MHz is 23.4 us; 30 us leaves the
/// 1 MHz tick's rounding and the start's latency room.
const CONVERSION: Duration = Duration::from_micros(30);

/// How often the supply is measured.
const EVERY: Duration = Duration::from_secs(1);

/// ADC1, kept for the supply's measurements (nothing else converts on it).
pub struct Supply {
    _adc: Peri<'static, Adc1>,
}

impl Supply {
    /// Takes ADC1; its clock on, and ADCCLK the fastest PCLK2 division within 36 MHz
    /// (21 MHz from 84 MHz: the prescaler embassy picks for the sampler's ADC2 too).
    pub fn new(adc: Peri<'static, Adc1>) -> Self {
        RCC.apb2enr().modify(|w| w.set_adc1en(true));
        let pclk2 = embassy_stm32::rcc::frequency::<Adc1>().0;
        let pre = match pclk2.div_ceil(36_000_000) {
            0..=2 => Adcpre::DIV2,
            3..=4 => Adcpre::DIV4,
            5..=6 => Adcpre::DIV6,
            _ => Adcpre::DIV8,
        };
        ADC123_COMMON.ccr().modify(|w| w.set_adcpre(pre));
        Self { _adc: adc }
    }

    /// The supply now, volts, from [`READS`] conversions of VREFINT and the factory's
    /// calibration word. Blocks for about 0.5 ms (start-up only: no executor runs yet, and
    /// embassy's timer queue takes only its executors' wakers, so the async twin below cannot
    /// be blocked on).
    pub fn vdda_v(&mut self) -> Result<f32, VddaError> {
        self.set_up();
        let mut sum = 0;
        for _ in 0..READS {
            self.start();
            block_for(CONVERSION);
            sum += self.take().ok_or(VddaError::NoReading)?;
        }
        analog::vdda_v(calibration(), sum as f32 / READS as f32)
    }

    /// As [`Supply::vdda_v`], each conversion awaited: the task's executor runs others meanwhile.
    pub async fn vdda_v_async(&mut self) -> Result<f32, VddaError> {
        self.set_up();
        let mut sum = 0;
        for _ in 0..READS {
            self.start();
            Timer::after(CONVERSION).await;
            sum += self.take().ok_or(VddaError::NoReading)?;
        }
        analog::vdda_v(calibration(), sum as f32 / READS as f32)
    }

    /// ADC1's clock, VREFINT, channel 17 at 480 cycles as the one conversion, the ADC on.
    fn set_up(&mut self) {
        RCC.apb2enr().modify(|w| w.set_adc1en(true));
        if !ADC123_COMMON.ccr().read().tsvrefe() {
            ADC123_COMMON.ccr().modify(|w| w.set_tsvrefe(true));
            // VREFINT's start-up time (DS8626 Table 71: 10 us).
            block_for(Duration::from_micros(10));
        }
        ADC1.smpr1()
            .modify(|w| w.set_smp(usize::from(VREFINT_CHANNEL - 10), SampleTime::CYCLES480));
        ADC1.sqr1().modify(|w| w.set_l(0));
        ADC1.sqr3().modify(|w| w.set_sq(0, VREFINT_CHANNEL));
        if !ADC1.cr2().read().adon() {
            ADC1.cr2().modify(|w| w.set_adon(true));
            // tSTAB (DS8626: 3 us).
            block_for(Duration::from_micros(3));
        }
    }

    fn start(&mut self) {
        ADC1.sr().modify(|w| w.set_eoc(false));
        ADC1.cr2().modify(|w| w.set_swstart(true));
    }

    /// The conversion's code, if it has ended.
    fn take(&mut self) -> Option<u32> {
        ADC1.sr()
            .read()
            .eoc()
            .then(|| u32::from(ADC1.dr().read().data() & 0x0FFF))
    }
}

/// The factory's VREFINT conversion at 3.3 V.
fn calibration() -> u16 {
    // SAFETY: a read of the factory calibration word in the system memory's OTP area, which
    // the F407 always maps (RM0090 2.3, DS8626 6.3.22).
    unsafe { core::ptr::read_volatile(analog::VREFINT_CAL_ADDR as *const u16) }
}

/// Measures the supply once a second (each conversion awaited, so the high executor it
/// shares with the sampler is held for microseconds at a time) and logs it against the
/// start-up value (`start`, none when the start-up measurement failed and 3.0 V was assumed);
/// warns once each time it moves past [`analog::WARN_CHANGE`] from the first in-run reading.
#[embassy_executor::task]
pub async fn watch(mut supply: Supply, start: Option<f32>) {
    let mut next = Instant::now() + EVERY;
    let mut reference: Option<f32> = None;
    let mut warned = false;
    loop {
        Timer::at(next).await;
        next += EVERY;
        let v = match supply.vdda_v_async().await {
            Ok(v) => v,
            Err(_) => {
                warn!("supply: VREFINT gave no plausible VDDA");
                continue;
            }
        };
        let since_start = start.map(|v0| analog::SupplyChange::new(v0, v).change);
        info!(
            "supply vdda_v={=f32} start_vdda_v={} change={}",
            v,
            crate::tasks::reporter::Opt(start),
            crate::tasks::reporter::Opt(since_start)
        );
        let r = *reference.get_or_insert(v);
        let c = analog::SupplyChange::new(r, v);
        if c.warn && !warned {
            warn!(
                "VDDA has moved {=f32} % since the first reading: a sensor not powered from VDDA now reads {=f32} % off (the ADC's gain was set at start-up; restart to set it again)",
                c.change * 100.0,
                c.reading_error * 100.0
            );
        }
        warned = c.warn;
    }
}
