//! ADXL375 driver (3-axis, ±200 g, SPI), written only against `embedded-hal-async` 1.0's
//! `SpiDevice`, so that it builds on the host too (`host-tests/tests/adxl375.rs` includes this
//! file and tests it against a mock bus).
//!
//! What it does, after the ADXL375 data sheet (Rev. B):
//!
//! * [`Adxl375::init`]: checks DEVID (register 0x00, 0xE5); configures in standby: DATA_FORMAT
//!   = 0x0B (D3, D1 and D0 must be written as 1 on the ADXL375, whose resolution and range are
//!   fixed; 4-wire SPI, right-justified, interrupts active high), BW_RATE (output data rate),
//!   FIFO_CTL = stream mode with a watermark; then POWER_CTL = measure.
//! * [`Adxl375::read_fifo`]: reads FIFO_STATUS (entries) and INT_SOURCE (overrun flag), then
//!   pops each entry with one multi-byte read of DATAX0..DATAZ1 (six bytes, little-endian
//!   two's complement, 13 significant bits sign-extended).
//! * Scale: 49 mg/LSB typical ([`G_PER_LSB`]); [`Sample::to_m_per_s2`] converts to SI.
//!
//! SPI: mode 3 (CPOL = 1, CPHA = 1), at most 5 MHz; at the 3200 Hz and 1600 Hz data rates the
//! data sheet asks for an SPI clock of at least 2 MHz. A command byte is the register address
//! with bit 7 set to read and bit 6 set for a multi-byte access. Between the end of one FIFO
//! read and the next read of FIFO or FIFO_STATUS the data sheet asks for 5 us (the FIFO pops on
//! chip-select release), which each FIFO read waits after its transaction, chip select high.
//!
//! (DEVID_AD / DEVID_MST / PARTID are ADXL372/ADXL355-family registers; the ADXL375 has only
//! DEVID, 0xE5, at 0x00.)

use embedded_hal_async::delay::DelayNs;
use embedded_hal_async::spi::{Operation, SpiDevice};

/// Register addresses (ADXL375 data sheet, Table 14).
pub mod reg {
    /// Device ID, reads [`super::DEVICE_ID`].
    pub const DEVID: u8 = 0x00;
    /// Output data rate and power mode.
    pub const BW_RATE: u8 = 0x2C;
    /// Power-saving features control; bit 3 = measure.
    pub const POWER_CTL: u8 = 0x2D;
    /// Interrupt enable.
    pub const INT_ENABLE: u8 = 0x2E;
    /// Interrupt source; bit 0 = FIFO overrun, bit 1 = watermark, bit 7 = data ready.
    pub const INT_SOURCE: u8 = 0x30;
    /// Data format control.
    pub const DATA_FORMAT: u8 = 0x31;
    /// X-axis data 0 (first of six data registers up to DATAZ1 at 0x37).
    pub const DATAX0: u8 = 0x32;
    /// FIFO control.
    pub const FIFO_CTL: u8 = 0x38;
    /// FIFO status; bits 5:0 = entries.
    pub const FIFO_STATUS: u8 = 0x39;
}

/// DEVID of the ADXL375.
pub const DEVICE_ID: u8 = 0xE5;

/// Command byte bit: read (clear: write).
pub const SPI_READ: u8 = 0x80;
/// Command byte bit: multi-byte access (the address increments).
pub const SPI_MULTI_BYTE: u8 = 0x40;

/// DATA_FORMAT value written by [`Adxl375::init`]: the fixed bits D3, D1, D0 set; self-test
/// off, 4-wire SPI, interrupts active high, right-justified.
pub const DATA_FORMAT_VALUE: u8 = 0x0B;
/// POWER_CTL measure bit.
pub const POWER_CTL_MEASURE: u8 = 0x08;
/// FIFO_CTL mode field: stream (keeps the last 32 samples, oldest overwritten).
pub const FIFO_CTL_STREAM: u8 = 0x80;
/// FIFO_CTL mode field: bypass (FIFO off and emptied).
pub const FIFO_CTL_BYPASS: u8 = 0x00;
/// FIFO_STATUS entries field.
pub const FIFO_STATUS_ENTRIES: u8 = 0x3F;
/// INT_SOURCE overrun flag: in bypass mode, new data replaced unread data; in stream mode the
/// data sheet sets it when the FIFO fills, whether or not a sample was overwritten
/// (`crate::fifo` counts the loss from the clock).
pub const INT_SOURCE_OVERRUN: u8 = 0x01;

/// FIFO depth in samples; one more sample can wait in the output registers (33 entries).
pub const FIFO_DEPTH: usize = 32;
/// Most entries FIFO_STATUS can report.
pub const MAX_FIFO_ENTRIES: usize = FIFO_DEPTH + 1;
/// FIFO watermark set by [`Adxl375::init`], in samples (half the FIFO).
pub const FIFO_WATERMARK: u8 = 16;

/// Wait after each FIFO read before the next FIFO or FIFO_STATUS read, in nanoseconds.
pub const FIFO_POP_DELAY_NS: u32 = 5_000;

/// Scale factor, typical: 49 mg per LSB, in g per LSB (20.5 LSB/g).
pub const G_PER_LSB: f32 = 0.049;
/// Standard gravity, m/s² per g.
pub const STANDARD_GRAVITY_M_PER_S2: f32 = impact_core::consts::STANDARD_GRAVITY as f32;

/// Output data rate (BW_RATE rate code; normal power mode).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum DataRate {
    /// 100 Hz (the reset default).
    Hz100 = 0x0A,
    /// 200 Hz.
    Hz200 = 0x0B,
    /// 400 Hz.
    Hz400 = 0x0C,
    /// 800 Hz.
    Hz800 = 0x0D,
    /// 1600 Hz (SPI clock >= 2 MHz).
    Hz1600 = 0x0E,
    /// 3200 Hz (SPI clock >= 2 MHz).
    Hz3200 = 0x0F,
}

impl DataRate {
    /// Output data rate in samples per second.
    pub const fn hz(self) -> u32 {
        match self {
            Self::Hz100 => 100,
            Self::Hz200 => 200,
            Self::Hz400 => 400,
            Self::Hz800 => 800,
            Self::Hz1600 => 1_600,
            Self::Hz3200 => 3_200,
        }
    }
}

/// One acceleration sample, raw counts ([`G_PER_LSB`] each).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Sample {
    /// X axis, counts.
    pub x: i16,
    /// Y axis, counts.
    pub y: i16,
    /// Z axis, counts.
    pub z: i16,
}

impl Sample {
    /// Decodes DATAX0..DATAZ1.
    pub fn from_le_bytes(b: [u8; 6]) -> Self {
        Self {
            x: i16::from_le_bytes([b[0], b[1]]),
            y: i16::from_le_bytes([b[2], b[3]]),
            z: i16::from_le_bytes([b[4], b[5]]),
        }
    }

    /// The resultant `sqrt(x² + y² + z²)`, counts, rounded to the nearest integer by exact
    /// integer arithmetic (`impact_core::signal::resultant`, the host's too; at most
    /// `4096 √3 < 7095`).
    pub fn magnitude(self) -> i16 {
        impact_core::signal::resultant::resultant_counts(self.x, self.y, self.z)
    }

    /// The sample in m/s², `[x, y, z]`.
    pub fn to_m_per_s2(self) -> [f32; 3] {
        [self.x, self.y, self.z].map(counts_to_m_per_s2)
    }
}

/// One sample's three axes, counts.
pub type Axes = [i16; 3];

/// What the stream gets of each sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(target_os = "none", derive(defmt::Format))]
pub enum Axis {
    X,
    Y,
    Z,
    /// `|f − f₀|` of the three axes each zeroed ([`Picker`]; crash and drop practice: the
    /// trigger on |a| whatever the direction of the hit).
    Resultant,
}

impl Axis {
    /// Whether the stream is the resultant (whose integral is no velocity change).
    #[allow(dead_code)]
    pub const fn is_resultant(self) -> bool {
        matches!(self, Axis::Resultant)
    }
}

/// Each axis's rails, counts: 13-bit two's complement.
pub const AXIS_RAILS: (i16, i16) = (-4096, 4095);

/// The resultant's clip level, counts: an axis at its rail puts the magnitude of the zeroed
/// axes at least this high while its zero lies within 64 counts (3.1 g) of 0 toward that
/// rail (at rest the zeros are gravity's 1 g, 20 counts, shared among the axes).
pub const RESULTANT_CLIP: i16 = AXIS_RAILS.1 - 64;

/// What the stream gets of each three-axis sample, with the state the resultant needs: the
/// axes zeroed each on its own before their magnitude, `|f − f₀|` (as SAE J211 and ISO 6487
/// zero every channel before a resultant: a 12.6 g pulse along x with gravity's 1 g on z
/// had peaked 7.6 % low as `|f| − |f₀|`, the stream's baseline taking out the magnitude at
/// rest), with the scene's edge level, settle time and free fall
/// ([`impact_core::signal::axes_zero::AxesZero`], the host's `impact emulate --adxl375`'s
/// too).
pub struct Picker {
    axis: Axis,
    zero: impact_core::signal::axes_zero::AxesZero,
}

impl Picker {
    /// `axis` of each sample, the axes zeroed with `settings` for the resultant
    /// ([`impact_core::Scene::axes_zero`] with [`AXIS_RAILS`]).
    pub fn new(axis: Axis, settings: impact_core::signal::axes_zero::Settings) -> Self {
        Self {
            axis,
            zero: impact_core::signal::axes_zero::AxesZero::new(settings),
        }
    }

    /// The stream's sample of one three-axis sample (the resultant learns from it).
    pub fn pick(&mut self, sample: Axes) -> i16 {
        let [x, y, z] = sample;
        match self.axis {
            Axis::X => x,
            Axis::Y => y,
            Axis::Z => z,
            Axis::Resultant => self.zero.push(sample),
        }
    }
}

/// What becomes the sample stream: the resultant (the trigger on |a| whatever the direction
/// of the hit; no kinematics, its integral being no velocity change), or the axis along the
/// impact (kinematics and fits from the bench's approach speed, [`crate::scene::BENCH`]).
pub const AXIS: Axis = Axis::Resultant;

/// Converts counts to m/s² with the typical scale factor.
pub fn counts_to_m_per_s2(counts: i16) -> f32 {
    f32::from(counts) * G_PER_LSB * STANDARD_GRAVITY_M_PER_S2
}

/// Driver errors; `E` is the SPI device's error.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Error<E> {
    /// The SPI transaction failed.
    Spi(E),
    /// DEVID did not read 0xE5 (no ADXL375, or the bus is not working: 0x00 or 0xFF).
    WrongDeviceId {
        /// What DEVID read.
        found: u8,
    },
    /// The FIFO overflowed since the last read: samples were lost before the ones read now.
    /// The first `samples_read` entries of the output buffer are valid and the FIFO has been
    /// drained as usual, so the next read starts clean.
    FifoOverrun {
        /// Samples read into the output buffer despite the overrun.
        samples_read: usize,
    },
}

#[cfg(target_os = "none")]
impl<E: embedded_hal::spi::Error> defmt::Format for Error<E> {
    fn format(&self, f: defmt::Formatter) {
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

#[cfg(target_os = "none")]
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

/// An ADXL375 on an SPI device (which owns the chip select).
pub struct Adxl375<S, D> {
    spi: S,
    delay: D,
}

impl<S: SpiDevice, D: DelayNs> Adxl375<S, D> {
    /// Wraps the SPI device and a delay (for the FIFO pop gap, with chip select high); talks
    /// to the chip only from [`Self::init`] on.
    pub fn new(spi: S, delay: D) -> Self {
        Self { spi, delay }
    }

    /// Gives the SPI device back.
    pub fn release(self) -> S {
        self.spi
    }

    /// Reads one register.
    pub async fn read_register(&mut self, address: u8) -> Result<u8, Error<S::Error>> {
        let mut value = [0u8; 1];
        self.spi
            .transaction(&mut [
                Operation::Write(&[SPI_READ | address]),
                Operation::Read(&mut value),
            ])
            .await
            .map_err(Error::Spi)?;
        Ok(value[0])
    }

    /// Writes one register.
    pub async fn write_register(&mut self, address: u8, value: u8) -> Result<(), Error<S::Error>> {
        self.spi.write(&[address, value]).await.map_err(Error::Spi)
    }

    /// Checks the device ID, configures the data rate and the FIFO (stream mode, watermark
    /// [`FIFO_WATERMARK`]) in standby, then starts measuring. On a wrong ID nothing is written.
    pub async fn init(&mut self, rate: DataRate) -> Result<(), Error<S::Error>> {
        let found = self.read_register(reg::DEVID).await?;
        if found != DEVICE_ID {
            return Err(Error::WrongDeviceId { found });
        }
        self.write_register(reg::POWER_CTL, 0).await?; // standby while configuring
        self.write_register(reg::DATA_FORMAT, DATA_FORMAT_VALUE)
            .await?;
        self.write_register(reg::BW_RATE, rate as u8).await?;
        self.write_register(reg::INT_ENABLE, 0).await?;
        // Bypass empties the FIFO; then stream mode.
        self.write_register(reg::FIFO_CTL, FIFO_CTL_BYPASS).await?;
        self.write_register(reg::FIFO_CTL, FIFO_CTL_STREAM | FIFO_WATERMARK)
            .await?;
        self.write_register(reg::POWER_CTL, POWER_CTL_MEASURE).await
    }

    /// Samples waiting in the FIFO and output registers (0..=33).
    pub async fn fifo_entries(&mut self) -> Result<usize, Error<S::Error>> {
        let status = self.read_register(reg::FIFO_STATUS).await?;
        Ok(usize::from(status & FIFO_STATUS_ENTRIES))
    }

    /// Reads one sample: a multi-byte read of DATAX0..DATAZ1, which pops one FIFO entry when
    /// chip select rises, then the FIFO pop delay with chip select high (data sheet: 5 us
    /// between the end of a FIFO read and the next FIFO or FIFO_STATUS read).
    pub async fn read_sample(&mut self) -> Result<Sample, Error<S::Error>> {
        let mut data = [0u8; 6];
        self.spi
            .transaction(&mut [
                Operation::Write(&[SPI_READ | SPI_MULTI_BYTE | reg::DATAX0]),
                Operation::Read(&mut data),
            ])
            .await
            .map_err(Error::Spi)?;
        self.delay.delay_ns(FIFO_POP_DELAY_NS).await;
        Ok(Sample::from_le_bytes(data))
    }

    /// Drains up to `out.len()` samples from the FIFO into `out`, oldest first; returns how
    /// many. An overrun since the last read is reported as [`Error::FifoOverrun`] after the
    /// samples have been read.
    pub async fn read_fifo(&mut self, out: &mut [Sample]) -> Result<usize, Error<S::Error>> {
        let entries = self.fifo_entries().await?;
        let overrun = self.read_register(reg::INT_SOURCE).await? & INT_SOURCE_OVERRUN != 0;
        let count = entries.min(out.len());
        for slot in &mut out[..count] {
            *slot = self.read_sample().await?;
        }
        if overrun {
            Err(Error::FifoOverrun {
                samples_read: count,
            })
        } else {
            Ok(count)
        }
    }
}
