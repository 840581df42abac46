//! STM32 sample source: ADC2 on PA1 (ADC123_IN1), converted on each TIM3 update (TRGO) at
//! [`SAMPLE_RATE_HZ`] and moved by DMA2 stream 2 (channel 1) into a ring of two blocks; each
//! half of the ring becomes one block for the monitor. ADC2, not ADC1: only ADC1 reaches
//! VREFINT, and it measures the supply once a second meanwhile ([`super::supply`]), taking
//! none of these conversions.
//!
//! Rates. The 168 MHz clock tree gives APB2 = 84 MHz; the ADC prescaler (/2, /4, /6, /8) must
//! keep ADCCLK at or below 36 MHz, so ADCCLK = 84 / 4 = 21 MHz. A 12-bit conversion takes
//! the sampling time plus 12 ADCCLK cycles:
//!
//! | sampling time | conversion | fastest rate |
//! |---------------|------------|--------------|
//! | 3 cycles      | 15 cycles  | 1.4 MS/s     |
//! | 15 cycles     | 27 cycles  | 778 kS/s     |
//! | 28 cycles     | 40 cycles  | 525 kS/s     |
//!
//! so 500 kS/s (2 us, 42 ADCCLK cycles between triggers) takes 15-cycle sampling: 27 cycles of
//! conversion plus the trigger's 2-cycle latency (RM0090 13.3.8) leave 13 cycles (0.62 us) of
//! margin. 28-cycle sampling left none (28 + 12 + 2 = 42), so a trigger could come while the
//! previous conversion ran: TIM2 would count it, no sample would come, and the time base
//! would drift. 15 cycles (0.71 us) settle the ADC's 4 pF sample capacitor to 12 bits through
//! a source up to 11.8 kOhm (DS8626 Eq. 1: R_AIN <= (k - 0.5) / (f_ADC C_ADC ln(2^14)) - R_ADC,
//! with R_ADC = 6 kOhm): drive PA1 from an amplifier or a divider below that. The F407's
//! single-ADC maximum, 2.4 MS/s, needs ADCCLK = 36 MHz, i.e. APB2 = 72 MHz (SYSCLK 144 MHz);
//! the triple-interleaved mode (7.2 MS/s) is not used here. TIM3 runs from 84 MHz: 500 kS/s
//! is exactly 168 timer clocks per sample.
//!
//! Losses are counted, never silent: TIM2 (32 bits) counts every TIM3 trigger, i.e. every
//! conversion, so after a DMA ring overrun (the sampler task fell a full ring behind) or an
//! ADC overrun (no DMA service in time: the ADC stops its DMA requests) the number of samples
//! lost is the count minus the samples delivered, announced to the stream with the next
//! block; and after every block the count is checked against the samples delivered
//! (`impact_firmware::conversions`), so triggers that made no sample are found too. An ADC
//! overrun is taken from its OVR flag by the ADC's interrupt ([`ADC`]), counted there once,
//! and the sampler recovers in RM0090 13.8.1's order (DMA requests re-armed, then OVR
//! cleared). Not verified on a board here: the conversion in flight at the resync (±1 sample).

use defmt::{info, warn};
use embassy_futures::select::{select, Either};
use embassy_stm32::adc::{Adc, AdcChannel, Exten, RingBufferedAdc, SampleTime};
use embassy_stm32::interrupt;
use embassy_stm32::peripherals::{ADC2, DMA2_CH2, PA1, TIM2, TIM3};
use embassy_stm32::time::Hertz;
use embassy_stm32::timer::low_level::{MasterMode, RoundTo, SlaveMode, Timer, TriggerSource};
use embassy_stm32::{triggers, Peri};
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::signal::Signal;
use embassy_time::{with_timeout, Duration};
use static_cell::ConstStaticCell;

use super::Irqs;
use crate::queues::BLOCK_LEN;
use crate::source::sender::{BlockSender, SAMPLE_CLOCK, SOURCE_STATS};
use impact_firmware::conversions::{self, Resync};
use impact_firmware::SAMPLE_RATE_HZ;

/// The DMA2 stream that moves ADC2's conversions (channel 1; `Irqs` binds its interrupt).
const DMA_STREAM: usize = 2;

/// DMA ring length in samples: two blocks, so the DMA fills one half while the task reads
/// the other (half-transfer and transfer-complete interrupts).
pub const DMA_BUF_LEN: usize = 2 * BLOCK_LEN;

/// ADC sampling time: 15 + 12 = 27 ADCCLK cycles at 21 MHz = 1.29 us, and the trigger's 2
/// cycles, in the 42 of a sample's 2 us (module documentation).
const SAMPLE_TIME: SampleTime = SampleTime::CYCLES15;

/// No half-buffer for this long means the ADC stopped (ADC overrun): 10 ms = ~20 blocks.
const STALL_TIMEOUT: Duration = Duration::from_millis(10);

/// The DMA ring; call once.
pub fn dma_buffer() -> &'static mut [u16; DMA_BUF_LEN] {
    static BUF: ConstStaticCell<[u16; DMA_BUF_LEN]> = ConstStaticCell::new([0; DMA_BUF_LEN]);
    BUF.take()
}

/// TIM2 in external clock mode 1 on ITR2 = TIM3's TRGO: a 32-bit count of the conversions
/// triggered (dropping the timer would stop its clock, so it is kept).
struct ConversionCounter(Timer<'static, TIM2>);

impl ConversionCounter {
    fn new(tim2: Peri<'static, TIM2>) -> Self {
        let t = Timer::new(tim2);
        let r = t.regs_gp32();
        r.psc().write_value(0);
        r.arr().write_value(u32::MAX);
        t.generate_update_event();
        t.set_trigger_source(TriggerSource::ITR2);
        t.set_slave_mode(SlaveMode::EXT_CLOCK_MODE);
        r.cnt().write_value(0);
        t.start();
        Self(t)
    }

    fn conversions(&self) -> u32 {
        self.0.regs_gp32().cnt().read()
    }

    fn zero(&self) {
        self.0.regs_gp32().cnt().write_value(0);
    }
}

/// ADC2 in DMA ring-buffer mode with the TIM3 trigger that paces it (dropping the timer
/// would stop its clock, so it is kept here) and the counter of its triggers.
pub struct AdcSampler {
    adc: RingBufferedAdc<'static, ADC2>,
    trigger: Timer<'static, TIM3>,
    counter: ConversionCounter,
}

impl AdcSampler {
    /// Configures TIM3 and ADC2; nothing is converted until [`sampler`] starts them.
    pub fn new(
        adc: Peri<'static, ADC2>,
        pin: Peri<'static, PA1>,
        dma: Peri<'static, DMA2_CH2>,
        tim: Peri<'static, TIM3>,
        count: Peri<'static, TIM2>,
        irqs: Irqs,
        dma_buf: &'static mut [u16; DMA_BUF_LEN],
    ) -> Self {
        // The timer first: loading its prescaler with an update event also pulses TRGO,
        // which must happen before the ADC listens to TRGO.
        let trigger = Timer::new(tim);
        trigger.set_frequency(Hertz(SAMPLE_RATE_HZ), RoundTo::Slower);
        trigger.generate_update_event();
        trigger.set_master_mode(MasterMode::UPDATE);
        // After TRGO follows the updates only (the update event above pulsed it).
        let counter = ConversionCounter::new(count);

        let adc = Adc::new(adc).into_ring_buffered(
            dma,
            dma_buf,
            irqs,
            [(pin.degrade_adc(), SAMPLE_TIME)].into_iter(),
            triggers::TIM3_TRGO,
            Exten::RISING_EDGE,
        );
        Self {
            adc,
            trigger,
            counter,
        }
    }
}

/// The ADC's interrupt raised an overrun (OVR): the sampler re-arms the DMA and resyncs.
static ADC_OVERRUN: Signal<CriticalSectionRawMutex, ()> = Signal::new();

/// The ADC's interrupt, for its overrun flag only (embassy-stm32's DMA mode also enables the
/// end-of-conversion interrupt, which [`sampler`] turns off: it would come 500 000 times a
/// second). Counts the overrun (the one place that counts ADC overruns), masks its own
/// interrupt until the sampler has recovered (OVR stays set: RM0090 13.8.1 clears it after
/// the DMA is re-armed), and wakes the sampler.
#[interrupt]
fn ADC() {
    let regs = embassy_stm32::pac::ADC2;
    if regs.sr().read().ovr() {
        regs.cr1().modify(|w| w.set_ovrie(false));
        SOURCE_STATS.overrun();
        ADC_OVERRUN.signal(());
    }
}

/// Only the overrun interrupt of ADC2, just above the sample source's priority.
fn enable_overrun_interrupt() {
    use embassy_stm32::interrupt::{InterruptExt, Priority};
    embassy_stm32::pac::ADC2.cr1().modify(|w| {
        w.set_eocie(false);
        w.set_ovrie(true);
    });
    // Above the sampler's executor (P2), so the interrupt has always counted and masked an
    // overrun before the sampler's stall path recovers from it.
    interrupt::ADC.set_priority(Priority::P1);
    // SAFETY: the handler above is ready; it touches ADC2's status register and two statics.
    unsafe { interrupt::ADC.enable() };
}

/// Recovers from an ADC overrun (OVR) in RM0090 13.8.1's order: the ADC's DMA requests
/// re-armed (the circular stream keeps its address and count), then OVR cleared, then the
/// overrun interrupt unmasked; the next TIM3 trigger starts the next conversion. Returns
/// whether OVR was set. After OVR the ADC issues no DMA request until this runs.
fn recover_adc_overrun() -> bool {
    let regs = embassy_stm32::pac::ADC2;
    let overrun = regs.sr().read().ovr();
    regs.cr2().modify(|w| w.set_dma(false));
    regs.cr2().modify(|w| w.set_dma(true));
    regs.sr().modify(|w| w.set_ovr(false));
    regs.cr1().modify(|w| w.set_ovrie(true));
    overrun
}

/// Samples forever, one block per DMA half-buffer.
#[embassy_executor::task]
pub async fn sampler(mut s: AdcSampler, samples: crate::queues::SampleSender) {
    let mut sender = BlockSender::new(samples);
    let mut half = [0u16; BLOCK_LEN];
    // Conversions taken out of the ring or counted lost (wrapping, like the counter): set
    // below.

    s.counter.zero();
    // embassy's `start` also sets SWSTART: one conversion no TIM3 trigger made, which TIM2
    // never counts. It is sample 0 of the stream (dropping it would put every block off the
    // ring's halves): `delivered` starts one behind, the signed lead takes it.
    let mut delivered = u32::MAX;
    s.adc.start();
    enable_overrun_interrupt();
    s.trigger.start();
    SAMPLE_CLOCK.start(SAMPLE_RATE_HZ as f32);
    let rate = trigger_rate_hz(&s.trigger);
    if rate == SAMPLE_RATE_HZ {
        info!(
            "ADC2/PA1 sampling at {} Hz (TIM3 TRGO), blocks of {}",
            rate, BLOCK_LEN
        );
    } else {
        defmt::error!(
            "ADC2/PA1 sampling at {} Hz, not the scene's {} Hz: every time is off",
            rate,
            SAMPLE_RATE_HZ
        );
    }
    // The counter against the DMA's position (module documentation), from here and from
    // every resynchronisation.
    let mut phase0 = ring_phase(&s);

    loop {
        let read = select(
            with_timeout(STALL_TIMEOUT, s.adc.read(&mut half)),
            ADC_OVERRUN.wait(),
        )
        .await;
        let read = match read {
            Either::First(r) => r,
            // An ADC overrun (counted by the interrupt): re-arm the DMA, resync, go on.
            Either::Second(()) => {
                recover_adc_overrun();
                let lost = resync(&mut s, &mut delivered);
                phase0 = ring_phase(&s);
                sender.lost(lost);
                warn!(
                    "ADC overrun (#{}): {} samples lost, DMA re-armed",
                    SOURCE_STATS.snapshot().overruns,
                    lost
                );
                continue;
            }
        };
        match read {
            Ok(Ok(_)) => {
                sender.publish(BLOCK_LEN, |block| {
                    for (sample, &raw) in block.iter_mut().zip(half.iter()) {
                        // 12-bit right-aligned conversions: 0..=4095 always fits.
                        *sample = raw as i16;
                    }
                });
                delivered = delivered.wrapping_add(BLOCK_LEN as u32);
                // The count against the DMA's position: triggers that made no sample.
                let (counted, position) = positions(&s);
                let missed = conversions::drift(phase0, counted, position, DMA_BUF_LEN as u32);
                if missed > 0 {
                    let n = SOURCE_STATS.error();
                    let lost = resync(&mut s, &mut delivered);
                    phase0 = ring_phase(&s);
                    sender.lost(lost);
                    warn!(
                        "ADC: at least {} triggers made no sample (error #{}): {} samples lost",
                        missed, n, lost
                    );
                }
            }
            // embassy-stm32's `OverrunError` (not exported by name): the DMA lapped the reader
            // and the ring has dropped what it held. The DMA keeps running.
            Ok(Err(_overrun)) => {
                let n = SOURCE_STATS.overrun();
                let lost = resync(&mut s, &mut delivered);
                phase0 = ring_phase(&s);
                sender.lost(lost);
                warn!("ADC DMA ring overrun (#{}): {} samples lost", n, lost);
            }
            Err(_timeout) => {
                if recover_adc_overrun() {
                    // The interrupt counted it (and may have signalled: that is this one).
                    ADC_OVERRUN.reset();
                    warn!("ADC overrun: conversions stalled, DMA re-armed");
                } else {
                    let n = SOURCE_STATS.error();
                    warn!("ADC stalled without overrun (error #{}): restarting", n);
                    s.adc.start();
                    // Its software-started conversion lands before the resync drops the ring.
                    embassy_time::block_for(Duration::from_micros(5));
                }
                let lost = resync(&mut s, &mut delivered);
                phase0 = ring_phase(&s);
                sender.lost(lost);
            }
        }
    }
}

/// TIM3's trigger rate as its registers make it: the timer clock over (PSC + 1)(ARR + 1).
/// (embassy-stm32 0.6's `get_frequency` divides by ARR, not ARR + 1: 502 994 Hz for these
/// 500 000.)
fn trigger_rate_hz(t: &Timer<'static, TIM3>) -> u32 {
    let r = t.regs_gp16();
    let clocks = (u32::from(r.psc().read()) + 1) * (u32::from(r.arr().read().arr()) + 1);
    t.get_clock_frequency().0 / clocks.max(1)
}

/// TIM2's count and the DMA's write position in the ring (DMA2 stream 2's NDTR counts down
/// from the ring's length), read together.
fn positions(_s: &AdcSampler) -> (u32, u32) {
    critical_section::with(|_| {
        let counted = embassy_stm32::pac::TIM2.cnt().read();
        let left = u32::from(embassy_stm32::pac::DMA2.st(DMA_STREAM).ndtr().read().ndt());
        let ring = DMA_BUF_LEN as u32;
        (counted, (ring - left.min(ring)) % ring)
    })
}

/// The phase [`conversions::drift`] is measured from.
fn ring_phase(s: &AdcSampler) -> u32 {
    let (counted, position) = positions(s);
    conversions::phase(counted, position, DMA_BUF_LEN as u32)
}

/// Drops what the ring holds and returns how many conversions were not delivered since the
/// last block (the ring's contents included). A count behind the samples delivered (a
/// conversion no trigger made) loses nothing.
fn resync(s: &mut AdcSampler, delivered: &mut u32) -> u32 {
    let now = critical_section::with(|_| {
        s.adc.clear();
        s.counter.conversions()
    });
    let lost = match conversions::resync(now, *delivered) {
        Resync::Lost(n) => n,
        Resync::Uncounted(extra) => {
            warn!("ADC: {} conversions no trigger counted", extra);
            0
        }
    };
    *delivered = now;
    lost
}
