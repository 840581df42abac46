//! STM32 sample source (feature `adxl375`): an ADXL375 on SPI1 (PA5 SCK, PA6 MISO, PA7 MOSI,
//! chip select PE7), its FIFO polled every 5 ms by [`super::poll`] (the emulator polls its
//! emulated ADXL375 with the same code); the three axes' resultant (or one axis) becomes the
//! samples.
//!
//! On the STM32F4-Discovery SPI1 also reaches the on-board LIS3DSH, whose chip select (PE3)
//! is held high here so it stays off the bus. PE7 is a free pin on the P2 header; any free
//! GPIO works as the ADXL375's chip select.

use defmt::{error, info};
use embassy_stm32::gpio::{Level, Output, Speed};
use embassy_stm32::mode::Async;
use embassy_stm32::peripherals::{DMA2_CH2, DMA2_CH3, PA5, PA6, PA7, PE3, PE7, SPI1};
use embassy_stm32::spi::{self, mode::Master, Spi, MODE_3};
use embassy_stm32::time::Hertz;
use embassy_stm32::Peri;
use embassy_time::{Delay, Instant, Timer};
use embedded_hal_bus::spi::ExclusiveDevice;

use super::Irqs;
use crate::queues::StreamEnd;
use crate::source::poll::{self, Fifo, Poll, Read, MAX_ENTRIES, POLL_PERIOD};
use crate::source::sender::{BlockSender, SAMPLE_CLOCK, SOURCE_STATS};
use impact_firmware::adxl375::{Adxl375, DataRate, Error, Sample, MAX_FIFO_ENTRIES};
use impact_firmware::adxl375::{Axes, AXIS};
use impact_firmware::SAMPLE_RATE_HZ;

/// Output data rate; [`SAMPLE_RATE_HZ`] is set to match.
const DATA_RATE: DataRate = DataRate::Hz3200;
const _: () = assert!(DATA_RATE.hz() == SAMPLE_RATE_HZ);

/// SPI clock request: the ADXL375 allows up to 5 MHz and wants >= 2 MHz at 3200 Hz. SPI1 runs
/// from APB2 = 84 MHz and embassy-stm32 0.6 maps `84 MHz / f` (floored) to a divider that may
/// be below it: any request in (3.5, 7] MHz gives 84 / 16 = 5.25 MHz, over the part's maximum.
/// This one gives exactly 84 / 32 = 2.625 MHz (checked at start-up).
const SPI_CLOCK_HZ: u32 = 2_625_000;

/// Tries at bringing the sensor up before the source gives up.
const INIT_ATTEMPTS: u32 = 3;

/// The SPI device: SPI1 with DMA, chip select by GPIO, embassy-time for the FIFO delays.
pub type Device = ExclusiveDevice<Spi<'static, Async, Master>, Output<'static>, Delay>;

/// The sensor as the sampler task gets it.
pub type Sensor = Adxl375<Device, Delay>;

/// SPI1 pins and the chip selects on its bus.
pub struct Spi1Pins {
    /// SCK.
    pub sck: Peri<'static, PA5>,
    /// MOSI.
    pub mosi: Peri<'static, PA7>,
    /// MISO.
    pub miso: Peri<'static, PA6>,
    /// The ADXL375's chip select.
    pub cs: Peri<'static, PE7>,
    /// The Discovery's LIS3DSH chip select, held high.
    pub lis3dsh_cs: Peri<'static, PE3>,
}

/// Sets up SPI1 (mode 3) and the chip selects.
pub fn sensor(
    spi1: Peri<'static, SPI1>,
    pins: Spi1Pins,
    tx_dma: Peri<'static, DMA2_CH3>,
    rx_dma: Peri<'static, DMA2_CH2>,
    irqs: Irqs,
) -> Sensor {
    let mut config = spi::Config::default();
    config.mode = MODE_3;
    config.frequency = Hertz(SPI_CLOCK_HZ);
    let bus = Spi::new(
        spi1, pins.sck, pins.mosi, pins.miso, tx_dma, rx_dma, irqs, config,
    );
    let sck = bus.get_current_config().frequency.0;
    if sck > 5_000_000 {
        defmt::error!("SPI1 at {} Hz: over the ADXL375's 5 MHz", sck);
    }

    // Deselected for good; the pin must stay driven, so the output is never dropped.
    core::mem::forget(Output::new(pins.lis3dsh_cs, Level::High, Speed::Low));

    let cs = Output::new(pins.cs, Level::High, Speed::VeryHigh);
    // Setting a GPIO output cannot fail (the error type is `Infallible`).
    let Ok(device) = ExclusiveDevice::new(bus, cs, Delay);
    Adxl375::new(device, Delay)
}

impl Fifo for Sensor {
    type Error = Error<<Device as embedded_hal::spi::ErrorType>::Error>;

    async fn read(&mut self, out: &mut [Axes; MAX_ENTRIES]) -> Result<Read, Poll<Self::Error>> {
        let mut samples = [Sample::default(); MAX_FIFO_ENTRIES];
        // `read_fifo` reads the entry count first.
        let at = Instant::now();
        let (samples_read, overrun) = match self.read_fifo(&mut samples).await {
            Ok(n) => (n, false),
            Err(Error::FifoOverrun { samples_read }) => (samples_read, true),
            Err(e) => return Err(Poll::Error(e)),
        };
        for (slot, s) in out.iter_mut().zip(samples.iter().take(samples_read)) {
            *slot = [s.x, s.y, s.z];
        }
        Ok(Read {
            at,
            samples: samples_read,
            overrun,
        })
    }
}

/// Brings the sensor up, then polls its FIFO forever ([`poll::run`]: losses counted against
/// the sensor's own sample stream, one short block per poll). If the sensor cannot be brought
/// up the stream ends as failed.
#[embassy_executor::task]
pub async fn sampler(mut sensor: Sensor, samples: crate::queues::SampleSender) {
    let mut sender = BlockSender::new(samples);

    let mut attempt = 1;
    while let Err(e) = sensor.init(DATA_RATE).await {
        SOURCE_STATS.error();
        error!("ADXL375 init (try {}/{}): {}", attempt, INIT_ATTEMPTS, e);
        if attempt == INIT_ATTEMPTS {
            sender.finish(StreamEnd::Failed).await;
            return;
        }
        attempt += 1;
        Timer::after_millis(100).await;
    }
    // Measuring starts with init's last write.
    let started = Instant::now();
    SAMPLE_CLOCK.start(SAMPLE_RATE_HZ as f32);
    info!(
        "ADXL375 on SPI1 at {} Hz, polled every {} ms",
        DATA_RATE.hz(),
        POLL_PERIOD.as_millis()
    );
    // The axes zeroed as the bench's scene says.
    let zero = impact_firmware::scene::BENCH.axes_zero([impact_firmware::adxl375::AXIS_RAILS; 3]);
    let mut picker = impact_firmware::adxl375::Picker::new(AXIS, zero);
    poll::run(
        &mut sensor,
        &mut sender,
        &mut picker,
        SAMPLE_RATE_HZ as f32,
        started,
    )
    .await;
    // The board's sensor never ends.
    sender.finish(StreamEnd::Failed).await;
}
