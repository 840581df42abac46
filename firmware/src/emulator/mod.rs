//! The `emulator` board: QEMU `-machine mps2-an386` (Cortex-M4F). It has no STM32
//! peripherals, so the STM32 HAL is left out; instead SysTick drives embassy-time ([`time`]),
//! samples come from a host file ([`crate::source::replay`]) and defmt frames and the exit
//! status go to the host through semihosting ([`host`]).

pub mod host;
pub mod time;

use core::sync::atomic::{AtomicBool, Ordering};

use cortex_m_rt::{exception, ExceptionFrame};
use defmt::{error, unwrap};
use embassy_executor::Spawner;
use impact_core::Scene;
use static_cell::ConstStaticCell;

use crate::scene::SceneError;

use defmt_semihosting as _;

/// Longest semihosting command line accepted, bytes.
const COMMAND_LINE_LEN: usize = 2048;

/// What the semihosting command line asks for:
/// `<program> <samples-file> [realtime|lossless] [key=value ...]` (scene keys: see
/// [`crate::scene::apply`]; unset keys keep the seed bench's values, [`crate::scene::BENCH`]).
pub struct Config {
    /// Host path of the raw little-endian i16 samples.
    pub samples_path: &'static str,
    /// Replay pacing.
    pub pacing: Pacing,
    /// The scene the monitor runs.
    pub scene: Scene,
}

/// How the replay hands blocks to the monitor.
#[derive(Clone, Copy, PartialEq, Eq, defmt::Format)]
pub enum Pacing {
    /// One block per block period of the scene's sample rate, dropped (and counted) when the
    /// monitor is behind, as on the board.
    RealTime,
    /// Waits for room in the queue: every sample reaches the monitor.
    Lossless,
}

#[derive(defmt::Format)]
enum ConfigError {
    Host(host::HostError),
    NoSamplesFile,
    /// A positional argument after the samples file that is not a pacing.
    BadPacing,
    Scene {
        key: &'static str,
        error: SceneError,
    },
    /// The scene does not validate (or does not fit the monitor's buffers).
    Invalid(impact_core::Error),
}

fn parse(line: &'static str) -> Result<Config, ConfigError> {
    let mut positional = line
        .split(' ')
        .filter(|a| !a.is_empty() && !a.contains('='));
    let _program = positional.next();
    let samples_path = positional.next().ok_or(ConfigError::NoSamplesFile)?;
    let pacing = match positional.next() {
        None | Some("realtime") => Pacing::RealTime,
        Some("lossless") => Pacing::Lossless,
        Some(_) => return Err(ConfigError::BadPacing),
    };
    if positional.next().is_some() {
        return Err(ConfigError::BadPacing);
    }
    let mut scene = crate::scene::BENCH;
    for arg in line.split(' ') {
        if let Some((key, value)) = arg.split_once('=') {
            crate::scene::apply(&mut scene, key, value)
                .map_err(|error| ConfigError::Scene { key, error })?;
        }
    }
    scene.validate().map_err(ConfigError::Invalid)?;
    Ok(Config {
        samples_path,
        pacing,
        scene,
    })
}

/// Reads the command line, brings the board up and spawns the sample source; returns the
/// scene for the monitor. A bad command line ends the run (exit status 1).
pub fn start(spawner: Spawner, samples: crate::tasks::SampleSender) -> Scene {
    static LINE: ConstStaticCell<[u8; COMMAND_LINE_LEN]> =
        ConstStaticCell::new([0; COMMAND_LINE_LEN]);
    let Some(buf) = LINE.try_take() else {
        error!("emulator: started twice");
        host::exit(false)
    };
    let config = match host::command_line(buf)
        .map_err(ConfigError::Host)
        .and_then(parse)
    {
        Ok(config) => config,
        Err(e) => {
            error!("emulator: bad command line: {}", e);
            host::exit(false)
        }
    };
    time::init();
    spawner.spawn(unwrap!(crate::source::replay::replay(
        config.samples_path,
        config.pacing,
        config.scene.calibration.sample_rate_hz,
        samples,
    )));
    config.scene
}

/// The stream is over: exit QEMU with status 0 if `success`, else 1. The defmt frames are
/// already on the host (semihosting writes are synchronous).
pub fn end_of_stream(success: bool) -> ! {
    host::exit(success)
}

static PANICKED: AtomicBool = AtomicBool::new(false);

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    // A panic inside the defmt logger (or inside this handler) must not recurse.
    if !PANICKED.swap(true, Ordering::Relaxed) {
        error!("panic: {}", defmt::Display2Format(info));
    }
    host::exit(false)
}

#[exception]
unsafe fn HardFault(frame: &ExceptionFrame) -> ! {
    if !PANICKED.swap(true, Ordering::Relaxed) {
        error!("HardFault at pc={=u32:#010x}", frame.pc());
    }
    host::exit(false)
}
