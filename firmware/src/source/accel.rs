//! STM32 sample source (feature `adxl375`): an ADXL375 on SPI1 (PA5 SCK, PA6 MISO, PA7 MOSI,
//! chip select PE7), its FIFO polled every few milliseconds; the three axes' resultant (or
//! one axis) becomes the samples.
//!
//! On the STM32F4-Discovery SPI1 also reaches the on-board LIS3DSH, whose chip select (PE3)
//! is held high here so it stays off the bus. PE7 is a free pin on the P2 header; any free
//! GPIO works as the ADXL375's chip select.

use defmt::{error, info, warn, Formatter};
use embassy_stm32::gpio::{Level, Output, Speed};
use embassy_stm32::mode::Async;
use embassy_stm32::peripherals::{DMA2_CH2, DMA2_CH3, PA5, PA6, PA7, PE3, PE7, SPI1};
use embassy_stm32::spi::{self, mode::Master, Spi, MODE_3};
use embassy_stm32::time::Hertz;
use embassy_stm32::Peri;
use embassy_time::{Delay, Duration, Instant, Ticker, Timer};
use embedded_hal_bus::spi::ExclusiveDevice;

use super::adxl375::{Adxl375, DataRate, Error, Sample, MAX_FIFO_ENTRIES};
use super::SAMPLE_RATE_HZ;
use crate::stm32::Irqs;
use crate::tasks::sampler::{BlockSender, SAMPLE_CLOCK, SOURCE_STATS};
use crate::tasks::{StreamEnd, BLOCK_LEN};

/// Output data rate; [`SAMPLE_RATE_HZ`] is set to match.
const DATA_RATE: DataRate = DataRate::Hz3200;
const _: () = assert!(DATA_RATE.hz() == SAMPLE_RATE_HZ);

/// SPI clock request: the ADXL375 allows up to 5 MHz and wants >= 2 MHz at 3200 Hz. SPI1 runs
/// from APB2 = 84 MHz and embassy-stm32 0.6 maps `84 MHz / f` (floored) to a divider that may
/// be below it: any request in (3.5, 7] MHz gives 84 / 16 = 5.25 MHz, over the part's maximum.
/// This one gives exactly 84 / 32 = 2.625 MHz (checked at start-up).
const SPI_CLOCK_HZ: u32 = 2_625_000;

/// FIFO poll period: 5 ms = 16 samples at 3200 Hz, half of the 32-sample FIFO, which gives
/// another 5 ms of slack before it overruns.
const POLL_PERIOD: Duration = Duration::from_millis(5);

/// Tries at bringing the sensor up before the source gives up.
const INIT_ATTEMPTS: u32 = 3;

/// What becomes the sample stream: the resultant of the three axes (crash and drop practice:
/// the trigger on |a| whatever the direction of the hit), or one axis along the expected
/// impact direction.
#[derive(Clone, Copy)]
#[allow(dead_code)]
enum Axis {
    X,
    Y,
    Z,
    Resultant,
}

const AXIS: Axis = Axis::Resultant;

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

impl<E: embedded_hal::spi::Error> defmt::Format for Error<E> {
    fn format(&self, f: Formatter) {
        match self {
            Error::Spi(e) => defmt::write!(f, "SPI error ({})", spi_error_kind(e.kind())),
            Error::WrongDeviceId { found } => {
                defmt::write!(f, "wrong device id {=u8:#04x} (expected 0xe5)", found)
            }
            Error::FifoOverrun { samples_read } => {
                defmt::write!(f, "FIFO overrun ({} samples read after it)", samples_read)
            }
        }
    }
}

fn spi_error_kind(kind: embedded_hal::spi::ErrorKind) -> &'static str {
    use embedded_hal::spi::ErrorKind;
    match kind {
        ErrorKind::Overrun => "overrun",
        ErrorKind::ModeFault => "mode fault",
        ErrorKind::FrameFormat => "frame format",
        ErrorKind::ChipSelectFault => "chip select fault",
        _ => "other",
    }
}

fn pick(sample: &Sample) -> i16 {
    match AXIS {
        Axis::X => sample.x,
        Axis::Y => sample.y,
        Axis::Z => sample.z,
        Axis::Resultant => sample.magnitude(),
    }
}

/// Brings the sensor up, then polls its FIFO forever, one block per [`BLOCK_LEN`] samples.
/// If the sensor cannot be brought up the stream ends as failed.
#[embassy_executor::task]
pub async fn sampler(mut sensor: Sensor, samples: crate::tasks::SampleSender) {
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
    info!(
        "ADXL375 on SPI1 at {} Hz, polled every {} ms",
        DATA_RATE.hz(),
        POLL_PERIOD.as_millis()
    );

    let mut fifo = [Sample::default(); MAX_FIFO_ENTRIES];
    let mut block = [0i16; BLOCK_LEN];
    let mut filled = 0;
    let mut ticker = Ticker::every(POLL_PERIOD);
    let started = Instant::now();
    SAMPLE_CLOCK.start(SAMPLE_RATE_HZ as f32);
    // Samples read or counted lost since the start.
    let mut accounted = 0u64;
    loop {
        ticker.next().await;
        let read = match sensor.read_fifo(&mut fifo).await {
            Ok(n) => n,
            Err(Error::FifoOverrun { samples_read }) => {
                let n = SOURCE_STATS.overrun();
                // The FIFO overwrote what was not read in time: what the data rate should
                // have given since the start, less what was read (the FIFO has no count of
                // its own; good to a poll period's jitter).
                let due = started.elapsed().as_micros() * u64::from(SAMPLE_RATE_HZ) / 1_000_000;
                let lost = due.saturating_sub(accounted + samples_read as u64);
                accounted += lost;
                // The samples before the gap go out first, in a short block; the gap is
                // announced with the block that holds the samples read after it.
                if filled > 0 {
                    let before = block;
                    sender.publish(filled, |b| *b = before);
                    filled = 0;
                }
                sender.lost(lost.min(u64::from(u32::MAX)) as u32);
                warn!("ADXL375 FIFO overrun (#{}): {} samples lost", n, lost);
                samples_read
            }
            Err(e) => {
                let n = SOURCE_STATS.error();
                warn!("ADXL375 read failed (error #{}): {}", n, e);
                0
            }
        };
        accounted += read as u64;
        for sample in fifo.iter().take(read) {
            if let Some(slot) = block.get_mut(filled) {
                *slot = pick(sample);
                filled += 1;
            }
            if filled == BLOCK_LEN {
                sender.publish(BLOCK_LEN, |b| *b = block);
                filled = 0;
            }
        }
    }
}
