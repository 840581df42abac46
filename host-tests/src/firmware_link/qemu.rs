//! The emulated firmware, run: QEMU's `mps2-an386` (Cortex-M4F) on the emulator build of
//! the firmware (built into `target/emulator` when its sources changed), lossless or in real
//! time (`-icount`), the samples (the ADC's, or an ADXL375's three axes) written to a raw file
//! and replayed with the scene on the semihosting command line; the defmt stream decoded
//! against the ELF as it comes. `impact emulate`, the real-time bench and the tests run it.

use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

use impact_core::Approach;
use impact_core::Scene;

/// Why the emulator could not be built or run.
#[derive(Debug, thiserror::Error)]
pub enum QemuError {
    #[error("the workspace ({}) is not here to build the firmware: give --elf", .root.display())]
    NoWorkspace { root: PathBuf },
    /// Cargo could not be started.
    #[error("cargo: {0}")]
    Cargo(std::io::Error),
    #[error(
        "building the QEMU firmware ({feature}) failed ({status}); is the thumbv7em-none-eabihf target installed (scripts/setup.sh)?"
    )]
    BuildFailed {
        feature: &'static str,
        status: ExitStatus,
    },
    /// A tool the emulator needs is not installed; `how` installs it.
    #[error("{tool} not found: run scripts/setup.sh (or {how})")]
    ToolNotFound {
        tool: &'static str,
        how: &'static str,
    },
    /// A tool could not be run (or waited for), other than missing.
    #[error("{tool}: {source}")]
    Tool {
        tool: &'static str,
        source: std::io::Error,
    },
    /// A semihosting argument (`what`) holding what semihosting cannot pass.
    #[error("{what} contains a space or comma, which semihosting cannot pass: {arg}")]
    Unpassable { what: &'static str, arg: String },
    #[error("{}: no such firmware ELF", .elf.display())]
    NoElf { elf: PathBuf },
    /// A file the emulator reads or is given (the ELF, a temporary file).
    #[error("{}: {source}", .path.display())]
    File {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("qemu-system-arm: no stdout")]
    NoStdout,
    #[error("the emulator did not finish within {seconds} s (--timeout)")]
    Timeout { seconds: u64 },
    /// The thread decoding QEMU's output panicked.
    #[error("decoding the emulator's log failed")]
    DecoderPanicked,
    #[error(transparent)]
    Defmt(#[from] crate::firmware_link::decode::DefmtError),
    #[error("the emulator's defmt stream had {skipped} malformed frames")]
    Malformed { skipped: u64 },
}

impl QemuError {
    /// Whether a tool the emulator needs is missing (the tests skip then).
    pub fn is_tool_missing(&self) -> bool {
        matches!(self, QemuError::ToolNotFound { .. })
    }
}

/// The `-icount shift` that stands for the STM32F407 at 168 MHz: 8 ns an instruction.
pub const BOARD_CLOCK_SHIFT: u8 = 3;

/// How the emulator replays the samples.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Pacing {
    /// Every sample reaches the firmware and every impact is analysed, at QEMU's own speed.
    Lossless,
    /// An emulated DMA at `rate_scale` times the recording's rate, in instruction-paced
    /// virtual time: each instruction takes 2^`clock_shift` ns ([`BOARD_CLOCK_SHIFT`]: the
    /// STM32F407's speed). `inject` (tests only): a fault to inject.
    RealTime {
        rate_scale: f32,
        clock_shift: u8,
        inject: Option<Inject>,
    },
}

/// A fault the tests inject into a real-time run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Inject {
    /// Before block `block` the firmware's sampler busy-waits `us` µs, so the DMA ring
    /// overruns as on a board whose sampler is held up.
    Stall { block: u32, us: u32 },
    /// A fault at start-up: the emulated board resets as the STM32 does (the run goes on
    /// after the reset; the next start-up logs the reset record).
    FaultAtStart(StartFault),
}

/// The fault [`Inject::FaultAtStart`] makes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StartFault {
    /// An undefined instruction.
    Undefined,
    /// A write into the stack's MPU guard (its bottom 32 bytes).
    StackGuard,
    /// A write 2 KiB below the stack's bottom (a large frame's store past the guard).
    BelowStack,
}

use impact_core::two_body::SceneTarget;

/// The scene as the firmware's `key=value` semihosting arguments. Floats are written as
/// Rust's shortest round-trip decimals, which the firmware parses back to the same bits.
pub fn scene_args(scene: &Scene) -> Vec<String> {
    let f = |v: f32| format!("{v:e}");
    let opt = |v: Option<f32>| v.map_or("none".to_string(), f);
    let b = |v: bool| if v { "1" } else { "0" };
    let class = |c: Option<impact_core::signal::cfc::Cfc>| {
        c.map_or("none".to_string(), |c| c.class().to_string())
    };
    let mut args = vec![
        format!("gain={}", f(scene.calibration.gain_m_s2_per_count)),
        format!("rate={}", f(scene.calibration.sample_rate_hz)),
        format!("mass={}", opt(scene.mass_kg)),
    ];
    match scene.approach {
        Approach::Unknown => args.push("v0=none".into()),
        Approach::Speed { v0_m_s } => args.push(format!("v0={}", f(v0_m_s))),
        Approach::DropHeight { height_m } => args.push(format!("drop_height={}", f(height_m))),
    }
    args.extend([
        format!("trigger={}", f(scene.trigger_m_s2)),
        format!("edge={}", f(scene.edge_m_s2)),
        format!("hold={}", f(scene.hold_s)),
        format!("max_impact={}", f(scene.max_impact_s)),
        format!("settle={}", f(scene.settle_s)),
        format!("clip={}:{}", scene.clip_counts.0, scene.clip_counts.1),
        format!("cfc={}", class(scene.cfc)),
        format!("trigger_cfc={}", class(scene.trigger_cfc)),
        format!(
            "lowpass={}",
            // (`ORDER:CUTOFF`: semihosting passes no comma.)
            scene.lowpass.map_or("none".to_string(), |l| format!(
                "{}:{}",
                l.order,
                f(l.cutoff_hz)
            ))
        ),
        format!("two_phase={}", b(scene.fits.two_phase)),
        format!("nonlinear={}", b(scene.fits.nonlinear)),
        format!("fit_exponent={}", b(scene.fits.fit_exponent)),
        format!("exponent={}", f(scene.fits.nonlinear_exponent)),
        format!("hertz={}", b(scene.fits.hertz)),
    ]);
    match scene.spectrum {
        None => args.push("srs=0".into()),
        Some(sp) => args.extend([
            "srs=1".to_string(),
            format!("srs_damping={}", f(sp.damping)),
            format!("srs_bands={}", sp.bands_per_octave),
            format!("srs_low={}", f(sp.low_hz)),
            format!("srs_high={}", opt(sp.high_hz)),
        ]),
    }
    args.extend([
        format!("gravity={}", f(scene.gravity_m_s2)),
        format!("vertical={}", b(scene.vertical)),
        format!("v0_every={}", b(scene.v0_every)),
    ]);
    match scene.train {
        None => args.push("train=none".into()),
        Some(t) => args.extend([
            format!("train={}", t.speed.name()),
            format!("max_flight={}", f(t.max_flight_s)),
        ]),
    }
    if let Some(spec) = scene.spec {
        let t = spec.tolerance;
        args.push(format!("spec={}", spec.shape.name()));
        if let impact_core::spec::Shape::Trapezoid { rise, fall } = spec.shape {
            args.extend([
                format!("spec_rise={}", f(rise)),
                format!("spec_fall={}", f(fall)),
            ]);
        }
        args.extend([
            format!("spec_peak={}", f(spec.peak_m_s2)),
            format!("spec_duration={}", f(spec.duration_s)),
            format!("spec_band={}", f(t.band)),
            format!("spec_outside={}", f(t.outside)),
            format!("spec_slack={}", f(t.slack)),
            format!("spec_dv={}", f(t.delta_v)),
            format!("spec_before={}", f(t.before)),
            format!("spec_after={}", f(t.after)),
            format!("spec_watch={}", f(t.watch)),
        ]);
    }
    match scene.target {
        Some(SceneTarget::SpringMass(s)) => args.extend([
            format!("target_mass={}", f(s.mass_kg)),
            format!("target_stiffness={}", f(s.stiffness_n_m)),
            format!("target_damping={}", f(s.damping_n_s_m)),
        ]),
        // A state space: its order, `A` row by row, `B`, `C`, `:`-separated (semihosting
        // passes no comma).
        Some(SceneTarget::StateSpace(t)) => {
            let n = t.n.min(impact_core::two_body::MAX_STATES);
            let list: Vec<String> = std::iter::once(n.to_string())
                .chain(t.entries().map(|v| f(*v)))
                .collect();
            args.push(format!("target_space={}", list.join(":")));
        }
        None => {}
    }
    args.push(format!("wave={}", scene.waveform_every));
    args
}

/// The workspace root (this crate's parent directory, as built).
fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from("."))
}

/// Builds the emulator firmware with cargo (nothing to do when it is current); returns the ELF.
pub fn build_firmware() -> Result<PathBuf, QemuError> {
    build_firmware_bin("emulator", None)
}

/// The QEMU firmware's own cargo target directory (`target/emulator`, or under
/// `$CARGO_TARGET_DIR`): apart from the board's (`target/thumbv7em-none-eabihf/release`), so
/// that building one never replaces the other's ELF.
fn emulator_target_dir(root: &Path) -> PathBuf {
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .map(|d| if d.is_absolute() { d } else { root.join(d) })
        .unwrap_or_else(|| root.join("target"));
    target.join("emulator")
}

/// The newest modification time among the files a firmware build reads: the core's and the
/// firmware's sources and manifests, the lock file, the memory maps and cargo's
/// configuration. `None` if one cannot be read (then cargo decides).
fn newest_input(root: &Path) -> Option<std::time::SystemTime> {
    fn walk(dir: &Path, newest: &mut std::time::SystemTime) -> Option<()> {
        for entry in std::fs::read_dir(dir).ok()? {
            let entry = entry.ok()?;
            let kind = entry.file_type().ok()?;
            if kind.is_dir() {
                walk(&entry.path(), newest)?;
            } else {
                *newest = (*newest).max(entry.metadata().ok()?.modified().ok()?);
            }
        }
        Some(())
    }
    let mut newest = std::time::SystemTime::UNIX_EPOCH;
    for dir in [
        "core/src",
        "firmware/src",
        "firmware/stm32",
        "firmware/emulator",
        "firmware/.cargo",
    ] {
        walk(&root.join(dir), &mut newest)?;
    }
    for file in [
        "Cargo.toml",
        "Cargo.lock",
        "memory.x",
        ".cargo/config.toml",
        "core/Cargo.toml",
        "firmware/Cargo.toml",
        "firmware/build.rs",
    ] {
        newest = newest.max(std::fs::metadata(root.join(file)).ok()?.modified().ok()?);
    }
    Some(newest)
}

/// Builds a firmware binary for QEMU with cargo feature `feature` (`emulator`, or `m4-bench`
/// with `bin` = `m4-bench`) into the emulator's target directory; returns the ELF. Cargo is
/// not run (it takes about a second to find there is nothing to do) when the ELF is newer
/// than every file the build reads; `IMPACT_REBUILD=1` runs it anyway.
pub fn build_firmware_bin(feature: &'static str, bin: Option<&str>) -> Result<PathBuf, QemuError> {
    let root = workspace_root();
    if !root.join("firmware").join("Cargo.toml").is_file() {
        return Err(QemuError::NoWorkspace { root });
    }
    let target_dir = emulator_target_dir(&root);
    let elf = target_dir
        .join("thumbv7em-none-eabihf")
        .join("release")
        .join(bin.unwrap_or("impact-firmware"));
    let built = std::fs::metadata(&elf).and_then(|m| m.modified()).ok();
    let current = match (built, newest_input(&root)) {
        (Some(built), Some(newest)) => built > newest,
        _ => false,
    };
    if current && std::env::var_os("IMPACT_REBUILD").is_none() {
        return Ok(elf);
    }
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let bin_args = bin.map(|b| vec!["--bin", b]).unwrap_or_default();
    crate::errln!(
        "building the QEMU firmware (cargo build --release -p impact-firmware --no-default-features --features {feature}{}{})",
        if bin.is_some() { " " } else { "" },
        bin_args.join(" ")
    );
    let status = Command::new(&cargo)
        .current_dir(&root)
        .env("CARGO_TARGET_DIR", &target_dir)
        .args([
            "build",
            "--quiet",
            "--release",
            "-p",
            "impact-firmware",
            "--target",
            "thumbv7em-none-eabihf",
            "--no-default-features",
            "--features",
            feature,
        ])
        .args(&bin_args)
        .stdout(Stdio::null())
        .status()
        .map_err(QemuError::Cargo)?;
    if !status.success() {
        return Err(QemuError::BuildFailed { feature, status });
    }
    // Cargo leaves an ELF it found current untouched: dated now, it is current for the check
    // above until an input changes again.
    let _ = std::fs::File::options()
        .append(true)
        .open(&elf)
        .and_then(|f| f.set_modified(std::time::SystemTime::now()));
    Ok(elf)
}

/// Checks that a tool runs; else says how to install it.
fn require(tool: &'static str, how: &'static str) -> Result<(), QemuError> {
    match Command::new(tool)
        .arg("--version")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
    {
        Ok(_) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            Err(QemuError::ToolNotFound { tool, how })
        }
        Err(source) => Err(QemuError::Tool { tool, source }),
    }
}

/// True if `qemu-system-arm` can be run (the defmt log is decoded in this process).
pub fn tools_available() -> Result<(), QemuError> {
    require("qemu-system-arm", "apt-get install qemu-system-arm")
}

/// A semihosting argument cannot hold spaces (arguments are joined by them) nor commas
/// (QEMU's option separator).
fn check_arg(what: &'static str, s: &str) -> Result<(), QemuError> {
    if s.contains([' ', ',', '\t', '\n']) {
        Err(QemuError::Unpassable {
            what,
            arg: s.to_string(),
        })
    } else {
        Ok(())
    }
}

/// A reader that keeps a copy of what it reads.
struct Tee<R> {
    inner: R,
    raw: Vec<u8>,
}

impl<R: std::io::Read> std::io::Read for Tee<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.raw.extend_from_slice(&buf[..n]);
        Ok(n)
    }
}

/// A file written for QEMU's semihosting to read: removed when dropped, and on an interrupt
/// while it lives.
struct TempFile {
    path: PathBuf,
    _guard: crate::interrupt::FileGuard,
}

impl TempFile {
    /// Writes `bytes` to `impact-emulate-PID-NANOS.EXT` in the temporary directory.
    fn write(ext: &str, nanos: u32, bytes: &[u8]) -> Result<Self, QemuError> {
        let path = std::env::temp_dir().join(format!(
            "impact-emulate-{}-{nanos}.{ext}",
            std::process::id()
        ));
        let file = Self {
            _guard: crate::interrupt::temporary(&path),
            path,
        };
        std::fs::write(&file.path, bytes).map_err(|source| QemuError::File {
            path: file.path.clone(),
            source,
        })?;
        Ok(file)
    }
}

impl Drop for TempFile {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.path);
    }
}

/// What a run of the emulator gave.
pub struct EmulatorRun {
    /// The decoded defmt lines.
    pub lines: Vec<String>,
    /// The raw defmt stream QEMU wrote (what `impact log --elf` decodes).
    pub raw: Vec<u8>,
    pub status: ExitStatus,
    /// Wall time of the QEMU run, s.
    pub seconds: f64,
}

/// What the emulated firmware samples.
#[derive(Clone, Copy, Debug)]
pub enum Samples<'a> {
    /// The ADC's counts (the board's default source).
    Adc(&'a [i16]),
    /// An ADXL375's three axes, counts (the board's `adxl375` source), and which of them
    /// the stream gets: one axis (0, 1, 2) or the resultant (`None`).
    Adxl375(&'a [[i16; 3]], Option<usize>),
    /// The ADC's counts already in a file (little-endian i16) and how many: a recording
    /// written there a block at a time ([`crate::pipeline::streaming::counts_file`]), never
    /// held whole.
    File(&'a Path, u64),
}

impl Samples<'_> {
    /// Samples in the stream.
    pub fn len(&self) -> usize {
        match self {
            Samples::Adc(c) => c.len(),
            Samples::Adxl375(a, _) => a.len(),
            Samples::File(_, n) => usize::try_from(*n).unwrap_or(usize::MAX),
        }
    }

    /// Whether the stream has no sample.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    fn bytes(&self) -> Vec<u8> {
        match self {
            Samples::Adc(c) => c.iter().flat_map(|c| c.to_le_bytes()).collect(),
            Samples::Adxl375(a, _) => a
                .iter()
                .flat_map(|s| s.iter().flat_map(|c| c.to_le_bytes()))
                .collect(),
            Samples::File(..) => Vec::new(),
        }
    }
}

/// Replays `samples` on the emulator firmware `elf` with `scene` and `pacing` (`selftest`:
/// the firmware judges each report against the self-test's played pulse); each decoded line
/// is passed to `echo` as it arrives.
pub fn run_emulator(
    elf: &Path,
    samples: Samples<'_>,
    scene: &Scene,
    selftest: bool,
    pacing: Pacing,
    timeout: Duration,
    echo: impl FnMut(&str) + Send + 'static,
) -> Result<EmulatorRun, QemuError> {
    tools_available()?;
    if !elf.is_file() {
        return Err(QemuError::NoElf {
            elf: elf.to_path_buf(),
        });
    }
    let elf = elf.canonicalize().map_err(|source| QemuError::File {
        path: elf.to_path_buf(),
        source,
    })?;
    let elf_s = elf.to_string_lossy().into_owned();
    check_arg("the ELF path", &elf_s)?;
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.subsec_nanos());
    // The samples in a file QEMU's semihosting reads: the caller's, or one written here and
    // removed at the end (or on an interrupt).
    let written;
    let raw_path = match samples {
        Samples::File(path, _) => path.to_path_buf(),
        _ => {
            written = TempFile::write("i16", nanos, &samples.bytes())?;
            written.path.clone()
        }
    };
    let raw_s = raw_path.to_string_lossy().into_owned();
    check_arg("the temporary directory", &raw_s)?;

    let mut config = format!("enable=on,target=native,arg={elf_s},arg={raw_s}");
    if let Samples::Adxl375(_, axis) = samples {
        config.push_str(",arg=sensor=adxl375,arg=axis=");
        config.push_str(match axis {
            Some(0) => "x",
            Some(1) => "y",
            Some(2) => "z",
            _ => "resultant",
        });
    }
    if selftest {
        config.push_str(",arg=selftest=1");
    }
    let mut icount = Vec::new();
    match pacing {
        Pacing::Lossless => config.push_str(",arg=lossless"),
        Pacing::RealTime {
            rate_scale,
            clock_shift,
            inject,
        } => {
            config.push_str(&format!(",arg=realtime,arg=rate_scale={rate_scale:e}"));
            match inject {
                Some(Inject::Stall { block, us }) => {
                    config.push_str(&format!(",arg=stall={block}:{us}"))
                }
                Some(Inject::FaultAtStart(StartFault::Undefined)) => {
                    config.push_str(",arg=fault=udf")
                }
                Some(Inject::FaultAtStart(StartFault::StackGuard)) => {
                    config.push_str(",arg=fault=guard")
                }
                Some(Inject::FaultAtStart(StartFault::BelowStack)) => {
                    config.push_str(",arg=fault=below-stack")
                }
                None => {}
            }
            // 2^shift ns of virtual time per instruction; idle time (wfi) skipped, so runs
            // are deterministic and fast.
            icount = vec![
                "-icount".to_string(),
                format!("shift={clock_shift},sleep=off"),
            ];
        }
    }
    // A user's band in a file of its rows' f32 bits (the board's own table is a `static`).
    let band_file = match scene.spec.and_then(|s| s.band) {
        Some(rows) => {
            let bytes: Vec<u8> = rows
                .iter()
                .flat_map(|p| [p.u, p.lower, p.upper])
                .flat_map(f32::to_le_bytes)
                .collect();
            Some(TempFile::write("band", nanos, &bytes)?)
        }
        None => None,
    };
    if let Some(file) = &band_file {
        let s = file.path.to_string_lossy().into_owned();
        check_arg("the temporary directory", &s)?;
        config.push_str(",arg=spec_table=");
        config.push_str(&s);
    }
    for a in scene_args(scene) {
        check_arg("a scene argument", &a)?;
        config.push_str(",arg=");
        config.push_str(&a);
    }
    let started = Instant::now();
    let mut qemu = Command::new("qemu-system-arm")
        .args(["-machine", "mps2-an386", "-cpu", "cortex-m4", "-nographic"])
        .args(["-monitor", "none", "-serial", "null"])
        .args(&icount)
        .args(["-semihosting-config", &config])
        .arg("-kernel")
        .arg(&elf)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .spawn()
        .map_err(|source| QemuError::Tool {
            tool: "qemu-system-arm",
            source,
        })?;
    // Ended with the tool on an interrupt.
    let _child = crate::interrupt::child(qemu.id());
    let Some(frames) = qemu.stdout.take() else {
        let _ = qemu.kill();
        return Err(QemuError::NoStdout);
    };
    // The raw frames are kept and decoded here against the ELF (defmt-decoder, as
    // defmt-print and probe-rs do), each line echoed as it comes.
    let reader = {
        let elf = elf.clone();
        std::thread::spawn(move || {
            let mut echo = echo;
            let mut lines = Vec::new();
            let mut tee = Tee {
                inner: frames,
                raw: Vec::new(),
            };
            let decoded = crate::firmware_link::decode::decode::<QemuError>(
                &elf,
                &mut tee,
                "the emulator's defmt stream",
                |_, line| {
                    echo(line);
                    lines.push(line.to_string());
                    Ok(())
                },
            );
            (decoded, lines, tee.raw)
        })
    };
    let status = loop {
        match qemu.try_wait() {
            Ok(Some(status)) => break status,
            Ok(None) if started.elapsed() > timeout => {
                let _ = qemu.kill();
                let _ = qemu.wait();
                let _ = reader.join();
                return Err(QemuError::Timeout {
                    seconds: timeout.as_secs(),
                });
            }
            Ok(None) => std::thread::sleep(Duration::from_millis(20)),
            Err(source) => {
                return Err(QemuError::Tool {
                    tool: "qemu-system-arm",
                    source,
                })
            }
        }
    };
    let seconds = started.elapsed().as_secs_f64();
    let (decoded, lines, raw) = reader.join().map_err(|_| QemuError::DecoderPanicked)?;
    let skipped = decoded?;
    if skipped > 0 {
        return Err(QemuError::Malformed { skipped });
    }
    Ok(EmulatorRun {
        lines,
        raw,
        status,
        seconds,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scene_floats_round_trip() {
        let mut scene = Scene::new(
            impact_core::Calibration {
                gain_m_s2_per_count: 0.1 / 3.0,
                sample_rate_hz: 999_999.9,
            },
            7.0 / 3.0,
        );
        scene.approach = Approach::Speed { v0_m_s: 1.3357 };
        for a in scene_args(&scene) {
            let (k, v) = a.split_once('=').unwrap();
            if k == "gain" {
                assert_eq!(
                    v.parse::<f32>().unwrap(),
                    scene.calibration.gain_m_s2_per_count
                );
            }
            if k == "trigger" {
                assert_eq!(v.parse::<f32>().unwrap(), scene.trigger_m_s2);
            }
        }
    }
}
