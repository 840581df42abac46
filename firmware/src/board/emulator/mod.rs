//! The `emulator` board: QEMU `-machine mps2-an386` (Cortex-M4F). It has no STM32
//! peripherals, so the STM32 HAL is left out; instead the FPGA counter and a CMSDK timer drive
//! embassy-time ([`time`]), samples come from a host file ([`crate::source::replay`]), through
//! an emulated DMA paced by the other CMSDK timer in real time ([`dma`]), and defmt frames and
//! the exit status go to the host through semihosting ([`host`]).

pub mod adxl375;
pub mod dma;
pub mod drain;
pub mod irq;
pub mod lines;
pub mod replay;
pub mod time;
pub mod timer;

use core::sync::atomic::{AtomicBool, Ordering};

use defmt::{error, info, unwrap};
use embassy_executor::SendSpawner;
use impact_core::spec::BandPoint;
use impact_core::Scene;
use static_cell::ConstStaticCell;

use crate::tasks::stream::Backpressure;
use impact_firmware::adxl375::{Axis, Picker};
use impact_firmware::reset_record::{Cause, Record};
use impact_firmware::scene::{BandTableError, SceneError};
use impact_firmware::semihosting as host;

pub use irq::{start_high, start_low, start_medium};

/// Longest semihosting command line accepted, bytes: the recording's path and every scene
/// key `impact emulate` passes (about 700 bytes with a spec, up to 900 more with a
/// six-state target's `target_space`: 54 numbers of at most 16 characters) with room to
/// spare. Read into
/// `init`'s frame, not a static: the emulator's data RAM is the board's 104 KiB, which the
/// board's own statics fill; only the samples file's path is kept (a static of
/// [`host::MAX_PATH_LEN`] bytes).
const COMMAND_LINE_LEN: usize = 2560;

/// What the semihosting command line asks for:
/// `<program> <samples-file> [realtime|lossless] [rate_scale=X] [stall=BLOCK:US]
/// [fault=udf|guard|below-stack] [sensor=adc|adxl375] [axis=x|y|z|resultant] [selftest=0|1] [spec_table=PATH] [key=value ...]`
/// (scene keys:
/// see [`impact_firmware::scene::apply`]; unset keys keep the seed bench's values,
/// [`impact_firmware::scene::BENCH`]).
pub struct Config {
    /// Host path of the raw little-endian i16 samples.
    pub samples_path: &'static str,
    /// Replay pacing.
    pub pacing: Pacing,
    /// Real time only: the samples come this many times faster than the scene's rate.
    pub rate_scale: f32,
    /// Real time only, fault injection for tests: the sampler busy-waits this long (µs) before
    /// taking this block (or poll, with the ADXL375), so the emulated DMA (or FIFO) laps it as
    /// it would on a stalled board.
    pub stall: Option<(u32, u32)>,
    /// `fault=udf|guard`, fault injection for tests: a fault at start-up (an undefined
    /// instruction, or a write into the stack's guard), after which the machine resets as the
    /// board would (not exits), unless the previous run kept a fault: the reset record's path
    /// through a real system reset, and the guard's proof.
    pub fault_at_start: Option<StartFault>,
    /// `sensor=adxl375`: the file holds three axes, read through the ADXL375 path.
    pub adxl375: bool,
    /// `axis=x|y|z|resultant` (ADXL375 path): what the stream gets of each sample.
    pub axis: Axis,
    /// `selftest=1`: the samples are the self-test's DAC output replayed (its codes); each
    /// report is judged against the played pulse at the scene's gain.
    pub selftest: bool,
    /// The scene the stream runs.
    pub scene: Scene,
}

/// A fault the tests inject at start-up.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum StartFault {
    /// An undefined instruction (`udf`): a UsageFault escalated to a HardFault.
    Undefined,
    /// A write into the stack's MPU guard: a MemManage fault escalated to a HardFault, at
    /// the guard's address.
    Guard,
    /// A write 2 KiB below the stack's bottom, where a large frame's stores land past the
    /// guard: a MemManage fault there too.
    BelowStack,
}

/// How the replay hands blocks to the stream.
#[derive(Clone, Copy, PartialEq, Eq, defmt::Format)]
pub enum Pacing {
    /// The emulated DMA writes one block per block period of virtual time (run QEMU with
    /// `-icount`), whatever the tasks are doing; the stream never waits for the analysis.
    /// Samples are lost (and counted) exactly when the board would lose them.
    RealTime,
    /// Waits for room at every step: every sample reaches the stream and every impact is
    /// analysed, whatever the emulator's speed.
    Lossless,
}

#[derive(defmt::Format)]
enum ConfigError<'a> {
    Host(host::HostError),
    NoSamplesFile,
    /// A positional argument after the samples file that is not a pacing.
    BadPacing,
    /// `rate_scale` is not a positive number.
    BadRateScale,
    /// `stall` is not `BLOCK:MICROSECONDS`.
    BadStall,
    /// `sensor` is not `adc` or `adxl375`.
    BadSensor,
    /// `fault` is not `udf`, `guard` or `below-stack`.
    BadFault,
    /// `axis` is not `x`, `y`, `z` or `resultant`.
    BadAxis,
    /// `selftest` is not `0` or `1`.
    BadSelftest,
    Scene {
        key: &'a str,
        error: SceneError,
    },
    /// `spec_table` is given without a `spec`, or its file is not whole rows of three
    /// little-endian f32s, at most `MAX_BAND_POINTS` of them.
    BadBandTable,
    /// The scene does not validate (or does not fit the monitor's buffers).
    Invalid(impact_core::Error),
}

/// Reads a user's tolerance band (`spec_table=PATH`, [`impact_core::spec::Spec::band`]): rows
/// of three little-endian f32s (time over the duration, lower and upper limit over the peak),
/// as `impact` writes them, so that the board judges with the host's very bits
/// ([`impact_firmware::scene::band_table`]).
fn read_band(path: &str) -> Result<&'static [BandPoint], ConfigError<'static>> {
    let mut file = host::HostFile::open(path).map_err(ConfigError::Host)?;
    let rows = core::iter::from_fn(|| {
        let mut row = [0u8; 12];
        match file.read_full(&mut row) {
            Ok(0) => None,
            Ok(12) => {
                let mut f = row
                    .chunks_exact(4)
                    .filter_map(|b| <[u8; 4]>::try_from(b).ok())
                    .map(f32::from_le_bytes);
                Some(match (f.next(), f.next(), f.next()) {
                    (Some(u), Some(lower), Some(upper)) => Ok(BandPoint { u, lower, upper }),
                    _ => Err(ConfigError::BadBandTable),
                })
            }
            Ok(_) => Some(Err(ConfigError::BadBandTable)),
            Err(e) => Some(Err(ConfigError::Host(e))),
        }
    });
    impact_firmware::scene::band_table(rows).map_err(|e| match e {
        BandTableError::Row(e) => e,
        _ => ConfigError::BadBandTable,
    })
}

fn parse(line: &str) -> Result<Config, ConfigError<'_>> {
    let mut positional = line
        .split(' ')
        .filter(|a| !a.is_empty() && !a.contains('='));
    let _program = positional.next();
    let samples_path = keep_path(positional.next().ok_or(ConfigError::NoSamplesFile)?)?;
    let pacing = match positional.next() {
        None | Some("realtime") => Pacing::RealTime,
        Some("lossless") => Pacing::Lossless,
        Some(_) => return Err(ConfigError::BadPacing),
    };
    if positional.next().is_some() {
        return Err(ConfigError::BadPacing);
    }
    let mut scene = impact_firmware::scene::BENCH;
    let mut rate_scale = 1.0f32;
    let mut stall = None;
    let mut fault_at_start = None;
    let mut adxl375 = false;
    let mut axis = Axis::Resultant;
    let mut selftest = false;
    let mut band_path = None;
    for arg in line.split(' ') {
        match arg.split_once('=') {
            Some(("axis", value)) => {
                axis = match value {
                    "x" => Axis::X,
                    "y" => Axis::Y,
                    "z" => Axis::Z,
                    "resultant" => Axis::Resultant,
                    _ => return Err(ConfigError::BadAxis),
                };
            }
            Some(("selftest", value)) => {
                selftest = match value {
                    "0" => false,
                    "1" => true,
                    _ => return Err(ConfigError::BadSelftest),
                };
            }
            Some(("sensor", value)) => {
                adxl375 = match value {
                    "adc" => false,
                    "adxl375" => true,
                    _ => return Err(ConfigError::BadSensor),
                };
            }
            Some(("stall", value)) => {
                let (block, us) = value.split_once(':').ok_or(ConfigError::BadStall)?;
                let parse = |v: &str| v.parse::<u32>().map_err(|_| ConfigError::BadStall);
                stall = Some((parse(block)?, parse(us)?));
            }
            Some(("fault", value)) => {
                fault_at_start = Some(match value {
                    "udf" => StartFault::Undefined,
                    "guard" => StartFault::Guard,
                    "below-stack" => StartFault::BelowStack,
                    _ => return Err(ConfigError::BadFault),
                });
            }
            Some(("rate_scale", value)) => {
                rate_scale = value
                    .parse::<f32>()
                    .ok()
                    .filter(|x| x.is_finite() && *x > 0.0)
                    .ok_or(ConfigError::BadRateScale)?;
            }
            Some(("spec_table", path)) => band_path = Some(path),
            Some((key, value)) => impact_firmware::scene::apply(&mut scene, key, value)
                .map_err(|error| ConfigError::Scene { key, error })?,
            None => {}
        }
    }
    if let Some(path) = band_path {
        let spec = scene.spec.as_mut().ok_or(ConfigError::BadBandTable)?;
        spec.band = Some(read_band(path)?);
    }
    scene.validate().map_err(ConfigError::Invalid)?;
    Ok(Config {
        samples_path,
        pacing,
        rate_scale,
        stall,
        fault_at_start,
        adxl375,
        axis,
        selftest,
        scene,
    })
}

/// The samples file's path, kept for the run in a static of its longest length (the command
/// line it came from lives in `init`'s frame).
fn keep_path(path: &str) -> Result<&'static str, ConfigError<'static>> {
    static PATH: ConstStaticCell<[u8; host::MAX_PATH_LEN]> =
        ConstStaticCell::new([0; host::MAX_PATH_LEN]);
    let bytes = path.as_bytes();
    let kept = PATH
        .try_take()
        .ok_or(ConfigError::Host(host::HostError::CommandLine))?;
    let slot = kept
        .get_mut(..bytes.len())
        .ok_or(ConfigError::Host(host::HostError::PathTooLong))?;
    slot.copy_from_slice(bytes);
    core::str::from_utf8(slot).map_err(|_| ConfigError::Host(host::HostError::CommandLineNotUtf8))
}

/// What the board hands the tasks.
pub struct Setup {
    /// The scene the stream and the analysis run.
    pub scene: Scene,
    /// Whether the stream may wait for the analysis (lossless replay only).
    pub backpressure: Backpressure,
    /// `selftest=1`: the pulse the self-test's DAC plays, at the scene's gain.
    pub selftest: Option<impact_firmware::selftest::Played>,
    config: Config,
}

/// Reads the command line and brings the board up (the time driver). A bad command line ends
/// the run (exit status 1). Not inlined: the line's buffer lives in this frame, which is gone
/// before the executors start (inlined into `main`, it sat under every task's stack).
#[inline(never)]
pub fn init(previous: Option<Record>) -> Setup {
    let mut buf = [0u8; COMMAND_LINE_LEN];
    let config = match host::command_line(&mut buf)
        .map_err(ConfigError::Host)
        .and_then(parse)
    {
        Ok(config) => config,
        Err(e) => {
            error!("emulator: bad command line: {}", e);
            fault_exit()
        }
    };
    crate::reset::log_previous(previous);
    if let Some(fault) = config.fault_at_start {
        if !matches!(previous.map(|r| r.cause), Some(Cause::Fault(_))) {
            inject(fault)
        }
    }
    irq::init();
    time::init();
    let lossless = config.pacing == Pacing::Lossless;
    crate::logger::set_waiting(lossless);
    drain::init(lossless);
    // The replayed counts are the DAC's codes: the played peak through the stream's own gain.
    let selftest = config.selftest.then(|| {
        impact_firmware::selftest::Played::new(
            config.scene.calibration.gain_m_s2_per_count,
            config.scene.calibration.sample_rate_hz,
            None,
        )
    });
    Setup {
        scene: config.scene,
        backpressure: match config.pacing {
            Pacing::RealTime => Backpressure::Never,
            Pacing::Lossless => Backpressure::WaitForCapture,
        },
        selftest,
        config,
    }
}

/// Spawns the sample source on the highest-priority executor.
pub fn spawn_sources(setup: Setup, high: SendSpawner, samples: crate::queues::SampleSender) {
    let c = &setup.config;
    let rate = c.scene.calibration.sample_rate_hz;
    // The ADXL375's axes zeroed as the scene says (the host's `emulate --adxl375` too): one
    // picker, whichever source runs (in a static: two tasks' futures holding one each did
    // not fit the emulator's RAM).
    static PICKER: static_cell::StaticCell<Picker> = static_cell::StaticCell::new();
    let picker = c.adxl375.then(|| {
        let zero = c.scene.axes_zero([impact_firmware::adxl375::AXIS_RAILS; 3]);
        &mut *PICKER.init(Picker::new(c.axis, zero))
    });
    let file = match super::replay::open(c.samples_path, rate, c.adxl375) {
        Ok(file) => file,
        Err(e) => {
            error!("replay: {}", e);
            fault_exit()
        }
    };
    match c.pacing {
        Pacing::RealTime => {
            info!(
                "replay: real time, {=f32} x the recording's rate",
                c.rate_scale
            );
            if let Some(picker) = picker {
                high.spawn(unwrap!(super::replay::adxl375(
                    file,
                    rate * c.rate_scale,
                    picker,
                    c.stall,
                    samples
                )));
            } else {
                high.spawn(unwrap!(super::replay::realtime(
                    file,
                    rate * c.rate_scale,
                    c.stall,
                    samples
                )));
            }
        }
        Pacing::Lossless => {
            info!("replay: lossless");
            high.spawn(unwrap!(super::replay::lossless(file, picker, samples)));
        }
    }
}

/// The stream is over: exit QEMU with status 0 if `success`, else 1. The defmt frames are
/// already on the host (semihosting writes are synchronous).
pub fn end_of_stream(success: bool) -> ! {
    drain::flush();
    host::exit(success)
}

/// Fault injection for the tests: the sampler busy-waits `us` µs, as on a board whose
/// sampler is held up, while the emulated DMA or FIFO goes on filling.
pub fn stall_sampler(us: u32) {
    defmt::warn!("stalling the sampler for {} us (fault injection)", us);
    let until = embassy_time::Instant::now() + embassy_time::Duration::from_micros(u64::from(us));
    while embassy_time::Instant::now() < until {}
}

/// The watchdog is the board's: QEMU stops a locked-up core itself (the run fails).
pub fn feed_watchdog() {}

/// Faults as the test asked (`fault=udf|guard`).
fn inject(fault: StartFault) -> ! {
    INJECTED_FAULT.store(true, Ordering::Relaxed);
    defmt::warn!("faulting at start-up (fault injection)");
    drain::flush();
    match fault {
        StartFault::Undefined => cortex_m::asm::udf(),
        StartFault::Guard | StartFault::BelowStack => {
            let at = match fault {
                StartFault::Guard => crate::stack::guard_address(),
                _ => crate::stack::guard_address() - 2048,
            };
            // SAFETY: none: this write must fault (the MPU forbids it), and the fault
            // handler does not return.
            unsafe { core::ptr::write_volatile(at as *mut u32, 0) };
            // Reached only if the guard let the write through.
            defmt::error!("the stack's guard did not fault");
            drain::flush();
            host::exit(false)
        }
    }
}

/// The fault was the test's (`fault=udf|guard`): reset as the board does.
static INJECTED_FAULT: AtomicBool = AtomicBool::new(false);

/// After a fault has been kept and logged: the run fails; an injected fault resets the
/// machine instead, as the board does (QEMU keeps RAM across a system reset and reloads only
/// the ELF's initialised sections), and the next start-up logs the record.
pub fn fault_exit() -> ! {
    drain::flush();
    if INJECTED_FAULT.load(Ordering::Relaxed) {
        crate::reset::commit();
        cortex_m::peripheral::SCB::sys_reset()
    }
    host::exit(false)
}

static PANICKED: AtomicBool = AtomicBool::new(false);

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    // A panic inside the defmt logger (or inside this handler) must not recurse.
    if !PANICKED.swap(true, Ordering::Relaxed) {
        error!("panic: {}", defmt::Display2Format(info));
    }
    drain::flush();
    host::exit(false)
}
