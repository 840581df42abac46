//! `impact emulate` and `impact log`: the firmware's own pipeline on an emulated Cortex-M4F
//! (QEMU `mps2-an386`), and its defmt log turned back into `impact analyze`'s JSON and CSV.
//!
//! `impact emulate FILE [analyze options]` prepares the recording exactly as `impact analyze`
//! does ([`analyze::setup`]: the same i16 counts, the same [`Scene`]), writes the counts to a
//! raw file, builds the emulator firmware if needed, replays the file on QEMU with the scene on
//! the semihosting command line, decodes the defmt log against the ELF (`defmt-decoder`), and parses the
//! firmware's `impact ...` lines back into [`ImpactReport`]s. The log's line format is in
//! `docs/board.md`.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

use clap::Args;

use impact_core::{Approach, Scene};

use crate::analyze::{self, AnalyzeArgs};
use crate::log::{get, num, parse_log};

/// `impact emulate` options: `impact analyze`'s, and where the firmware comes from.
#[derive(Args, Clone, Debug)]
pub struct EmulateArgs {
    #[command(flatten)]
    pub analyze: AnalyzeArgs,
    /// Real time: QEMU with an instruction-paced clock (`-icount shift=3`, 8 ns of virtual
    /// time per instruction, standing for the STM32F407 at 168 MHz), the samples written by an
    /// emulated DMA at the recording's rate whatever the firmware is doing; samples lost,
    /// analyses skipped and each report's latency are reported. Default: lossless replay.
    #[arg(long, help_heading = "Emulator")]
    pub realtime: bool,
    /// With --realtime: the emulated chip's speed, as QEMU's `-icount shift`: each
    /// instruction takes 2^N ns. 3 (125 M instructions/s) stands for the STM32F407 at
    /// 168 MHz (1.34 cycles an instruction, `impact bench m4`); 2 is a chip twice as fast,
    /// 4 one half as fast.
    #[arg(long, help_heading = "Emulator", requires = "realtime", default_value_t = BOARD_CLOCK_SHIFT, value_parser = clap::value_parser!(u8).range(0..=8))]
    pub clock_shift: u8,
    /// With --realtime: replay this many times faster than the recording's rate (headroom).
    #[arg(long, help_heading = "Emulator", requires = "realtime", default_value_t = 1.0, value_parser = positive_f32)]
    pub rate_scale: f32,
    /// The firmware sends each impact's captured window after its analysis (scene `wave`):
    /// whole, or the mean of every EVERY samples; checked against the replayed samples, and
    /// in the JSON's `waveforms`. Keep them with --log, draw them with `impact log --plot`.
    #[arg(long, help_heading = "Emulator", num_args = 0..=1, default_missing_value = "1", value_name = "EVERY",
          value_parser = clap::value_parser!(u16).range(1..))]
    pub waveforms: Option<u16>,
    /// The samples come from an ADXL375 (±200 g, 49 mg per count, 13 bits per axis), as on
    /// the board built with `--features adxl375`: each axis in the part's counts, its FIFO
    /// emulated (32 entries and the output registers) and polled every 5 ms by the board's
    /// ADXL375 source, which computes the axes' resultant and counts what the FIFO overwrote.
    /// The axes are --axes (or the channel as the x axis), at one of the part's rates
    /// (3200, 1600, 800, 400, 200 or 100 S/s).
    #[arg(long, help_heading = "Emulator")]
    pub adxl375: bool,
    /// Emulator firmware ELF (built with `--no-default-features --features emulator`)
    /// [default: build it with cargo into target/emulator when its sources changed].
    #[arg(long, help_heading = "Emulator")]
    pub elf: Option<PathBuf>,
    /// Stop QEMU after this many seconds.
    #[arg(long, help_heading = "Emulator", default_value_t = 600)]
    pub timeout: u64,
    /// Write the firmware's decoded log (one line per defmt frame, waveform frames included)
    /// to this file, as `impact log` reads it.
    #[arg(long, help_heading = "Output", value_name = "FILE")]
    pub log: Option<PathBuf>,
    /// Write the firmware's raw defmt stream (as `probe-rs` or an RTT reader saves it) to
    /// this file: `impact log --elf FIRMWARE FILE` decodes it.
    #[arg(long, help_heading = "Output", value_name = "FILE", alias = "raw")]
    pub defmt: Option<PathBuf>,
}

/// The `-icount shift` that stands for the STM32F407 at 168 MHz: 8 ns an instruction.
pub const BOARD_CLOCK_SHIFT: u8 = 3;

fn positive_f32(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(format!("{s}: not a positive number")),
    }
}

/// How the emulator replays the samples.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Pacing {
    /// Every sample reaches the firmware and every impact is analysed, at QEMU's own speed.
    Lossless,
    /// An emulated DMA at `rate_scale` times the recording's rate, in instruction-paced
    /// virtual time: each instruction takes 2^`clock_shift` ns ([`BOARD_CLOCK_SHIFT`]: the
    /// STM32F407's speed). `stall` (tests only): before block `.0` the firmware's sampler
    /// busy-waits `.1` µs, so the DMA ring overruns as on a board whose sampler is held up.
    RealTime {
        rate_scale: f32,
        clock_shift: u8,
        stall: Option<(u32, u32)>,
    },
}

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
        ]),
    }
    match scene.train {
        None => args.push("train=none".into()),
        Some(t) => args.extend([
            format!("train={}", t.speed.name()),
            format!("gravity={}", f(t.gravity_m_s2)),
            format!("max_flight={}", f(t.max_flight_s)),
        ]),
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
pub fn build_firmware() -> Result<PathBuf, String> {
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
pub fn build_firmware_bin(feature: &str, bin: Option<&str>) -> Result<PathBuf, String> {
    let root = workspace_root();
    if !root.join("firmware").join("Cargo.toml").is_file() {
        return Err(format!(
            "the workspace ({}) is not here to build the firmware: give --elf",
            root.display()
        ));
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
    eprintln!(
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
        .map_err(|e| format!("cargo: {e}"))?;
    if !status.success() {
        return Err(format!(
            "building the QEMU firmware ({feature}) failed ({status}); is the thumbv7em-none-eabihf target installed (scripts/setup.sh)?"
        ));
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
fn require(tool: &str, how: &str) -> Result<(), String> {
    match Command::new(tool)
        .arg("--version")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
    {
        Ok(_) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            Err(format!("{tool} not found: run scripts/setup.sh (or {how})"))
        }
        Err(e) => Err(format!("{tool}: {e}")),
    }
}

/// True if `qemu-system-arm` can be run (the defmt log is decoded in this process).
pub fn tools_available() -> Result<(), String> {
    require("qemu-system-arm", "apt-get install qemu-system-arm")
}

/// A semihosting argument cannot hold spaces (arguments are joined by them) nor commas
/// (QEMU's option separator).
fn check_arg(what: &str, s: &str) -> Result<(), String> {
    if s.contains([' ', ',', '\t', '\n']) {
        Err(format!(
            "{what} contains a space or comma, which semihosting cannot pass: {s}"
        ))
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

/// Removes a file when dropped.
struct TempFile(PathBuf);

impl Drop for TempFile {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
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
}

impl Samples<'_> {
    /// Samples in the stream.
    pub fn len(&self) -> usize {
        match self {
            Samples::Adc(c) => c.len(),
            Samples::Adxl375(a, _) => a.len(),
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
        }
    }
}

/// The ADXL375's scale, m/s² per count: 49 mg per LSB (the firmware's `G_PER_LSB` times
/// standard gravity, in f32 as there).
pub const ADXL375_GAIN_M_S2: f32 = 0.049 * impact_core::consts::STANDARD_GRAVITY as f32;

/// The ADXL375's output data rates, S/s.
pub const ADXL375_RATES_HZ: [f64; 6] = [3200.0, 1600.0, 800.0, 400.0, 200.0, 100.0];

/// One axis's range on the ADXL375: 13-bit two's complement, counts.
const ADXL375_AXIS_COUNTS: (i16, i16) = (-4096, 4095);

/// The resultant's rail on the board (the firmware's `CLIP_COUNTS` with the ADXL375): it
/// reaches 4095 counts whenever an axis is at its rail.
const ADXL375_CLIP_COUNTS: (i16, i16) = (i16::MIN, 4095);

/// Turns a prepared recording into what an ADXL375 would give: each axis (`setup.axes`, or
/// the channel as x) in the part's counts, and the setup changed to the board's ADXL375 scene
/// (scale, rails) with what the board streams as its counts: the resultant of the axes, or
/// the one channel's axis.
pub fn adxl375_axes(setup: &mut analyze::Setup) -> Result<Vec<[i16; 3]>, String> {
    let rate = setup.rate_hz;
    if !ADXL375_RATES_HZ
        .iter()
        .any(|r| ((rate - r) / r).abs() < 1e-3)
    {
        return Err(format!(
            "--adxl375: the ADXL375 samples at 3200, 1600, 800, 400, 200 or 100 S/s; this recording is at {rate} S/s (render one at the part's rate with `impact synth --rate 3200`)"
        ));
    }
    let gain = f64::from(ADXL375_GAIN_M_S2);
    let count = |a: f64| {
        (a / gain).round().clamp(
            f64::from(ADXL375_AXIS_COUNTS.0),
            f64::from(ADXL375_AXIS_COUNTS.1),
        ) as i16
    };
    let columns: Vec<&[f64]> = if setup.axes.is_empty() {
        vec![&setup.prepared.accel_m_s2]
    } else {
        setup.axes.iter().map(|a| a.accel_m_s2.as_slice()).collect()
    };
    let n = setup.prepared.counts.len();
    let axes: Vec<[i16; 3]> = (0..n)
        .map(|i| {
            let mut s = [0i16; 3];
            for (slot, column) in s.iter_mut().zip(&columns) {
                *slot = column.get(i).map_or(0, |&a| count(a));
            }
            s
        })
        .collect();
    let one_axis = setup.axes.is_empty();
    setup.prepared.counts = axes
        .iter()
        .map(|&[x, y, z]| {
            if one_axis {
                x
            } else {
                impact_core::signal::resultant::resultant_counts(x, y, z)
            }
        })
        .collect();
    setup.scene.calibration.gain_m_s2_per_count = ADXL375_GAIN_M_S2;
    setup.prepared.calibration.gain_m_s2_per_count = ADXL375_GAIN_M_S2;
    setup.scene.clip_counts = if one_axis {
        ADXL375_AXIS_COUNTS
    } else {
        ADXL375_CLIP_COUNTS
    };
    setup
        .scene
        .validate()
        .map_err(|e| format!("--adxl375: {e}"))?;
    Ok(axes)
}

/// Replays `samples` on the emulator firmware `elf` with `scene` and `pacing`; each decoded
/// line is passed to `echo` as it arrives.
pub fn run_emulator(
    elf: &Path,
    samples: Samples<'_>,
    scene: &Scene,
    pacing: Pacing,
    timeout: Duration,
    echo: impl FnMut(&str) + Send + 'static,
) -> Result<EmulatorRun, String> {
    tools_available()?;
    if !elf.is_file() {
        return Err(format!("{}: no such firmware ELF", elf.display()));
    }
    let elf = elf
        .canonicalize()
        .map_err(|e| format!("{}: {e}", elf.display()))?;
    let elf_s = elf.to_string_lossy().into_owned();
    check_arg("the ELF path", &elf_s)?;
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.subsec_nanos());
    let raw = TempFile(
        std::env::temp_dir().join(format!("impact-emulate-{}-{nanos}.i16", std::process::id())),
    );
    let raw_s = raw.0.to_string_lossy().into_owned();
    check_arg("the temporary directory", &raw_s)?;
    std::fs::write(&raw.0, samples.bytes()).map_err(|e| format!("{raw_s}: {e}"))?;

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
    let mut icount = Vec::new();
    match pacing {
        Pacing::Lossless => config.push_str(",arg=lossless"),
        Pacing::RealTime {
            rate_scale,
            clock_shift,
            stall,
        } => {
            config.push_str(&format!(",arg=realtime,arg=rate_scale={rate_scale:e}"));
            if let Some((block, us)) = stall {
                config.push_str(&format!(",arg=stall={block}:{us}"));
            }
            // 2^shift ns of virtual time per instruction; idle time (wfi) skipped, so runs
            // are deterministic and fast.
            icount = vec![
                "-icount".to_string(),
                format!("shift={clock_shift},sleep=off"),
            ];
        }
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
        .map_err(|e| format!("qemu-system-arm: {e}"))?;
    let Some(frames) = qemu.stdout.take() else {
        let _ = qemu.kill();
        return Err("qemu-system-arm: no stdout".into());
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
            let decoded =
                crate::decode::decode(&elf, &mut tee, "the emulator's defmt stream", |_, line| {
                    echo(line);
                    lines.push(line.to_string());
                    Ok(())
                });
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
                return Err(format!(
                    "the emulator did not finish within {} s (--timeout)",
                    timeout.as_secs()
                ));
            }
            Ok(None) => std::thread::sleep(Duration::from_millis(20)),
            Err(e) => return Err(format!("qemu-system-arm: {e}")),
        }
    };
    let seconds = started.elapsed().as_secs_f64();
    let (decoded, lines, raw) = reader
        .join()
        .map_err(|_| "decoding the emulator's log failed".to_string())?;
    let skipped = decoded?;
    if skipped > 0 {
        return Err(format!(
            "the emulator's defmt stream had {skipped} malformed frames"
        ));
    }
    Ok(EmulatorRun {
        lines,
        raw,
        status,
        seconds,
    })
}

/// `impact emulate`: prints what `impact analyze` would, computed by the emulated firmware.
pub fn emulate(args: &EmulateArgs) -> Result<(), String> {
    let a = &args.analyze;
    // Check the tools before a possibly long build.
    tools_available()?;
    if a.stream {
        return Err(
            "--stream: the emulator replays a recording it has read whole (impact analyze --stream reads one as it comes)"
                .into(),
        );
    }
    if let Some(path) = &a.plot {
        crate::plot::check_output(path, &[a.file.as_path()])?;
    }
    let mut setup = analyze::setup(a, None)?;
    setup.scene.waveform_every = args.waveforms.unwrap_or(0);
    let axes = if args.adxl375 {
        Some(adxl375_axes(&mut setup)?)
    } else {
        None
    };
    // One channel is the part's x axis, streamed as such (the board's `AXIS = Axis::X`):
    // kinematics apply; the resultant of --axes has none.
    let axis = setup.axes.is_empty().then_some(0);
    let samples = match &axes {
        Some(axes) => Samples::Adxl375(axes, axis),
        None => Samples::Adc(&setup.prepared.counts),
    };
    let elf = match &args.elf {
        Some(p) => p.clone(),
        None => build_firmware()?,
    };
    // The log goes to stderr when stdout carries JSON or CSV.
    let to_stderr = a.json || a.csv;
    let pacing = if args.realtime {
        Pacing::RealTime {
            rate_scale: args.rate_scale,
            clock_shift: args.clock_shift,
            stall: None,
        }
    } else {
        Pacing::Lossless
    };
    let run = run_emulator(
        &elf,
        samples,
        &setup.scene,
        pacing,
        Duration::from_secs(args.timeout),
        move |line| {
            // The waveform frames are for files (--log), not for the terminal.
            if line.contains("wave_frame ") {
                return;
            }
            if to_stderr {
                eprintln!("{line}");
            } else {
                println!("{line}");
            }
        },
    )?;
    if !run.status.success() {
        return Err(format!(
            "the emulated firmware failed ({}); see its log above",
            run.status
        ));
    }
    let text = run.lines.join("\n") + "\n";
    if let Some(path) = &args.log {
        std::fs::write(path, &text).map_err(|e| format!("{}: {e}", path.display()))?;
        eprintln!("wrote {}", path.display());
    }
    if let Some(path) = &args.defmt {
        std::fs::write(path, &run.raw).map_err(|e| format!("{}: {e}", path.display()))?;
        eprintln!(
            "wrote {} (decode: impact log --elf {} {})",
            path.display(),
            elf.display(),
            path.display()
        );
    }
    let log = parse_log(&text)?;
    let summary = log
        .summary
        .as_ref()
        .ok_or("the emulator's log has no summary line")?;
    let samples: u64 = num(summary, "samples")?;
    let lost: u64 = num(summary, "samples_lost")?;
    if samples + lost != setup.prepared.counts.len() as u64 || get(summary, "result")? != "ok" {
        return Err(format!(
            "the emulator processed {samples} and lost {lost} of {} samples (result={})",
            setup.prepared.counts.len(),
            get(summary, "result")?
        ));
    }
    eprintln!("emulated in {:.2} s", run.seconds);
    let mut json = analyze::to_json(&setup, &log.impacts);
    json.samples_lost = lost;
    json.analyses_skipped = num(summary, "analyses_skipped")?;
    json.lines_dropped = log.lines_dropped;
    json.lines_missing = log.lines_missing;
    for w in &log.warnings {
        eprintln!("warning: {w}");
    }
    for (j, latency) in json.impacts.iter_mut().zip(&log.latencies) {
        j.report_latency_s = latency.map(f64::from);
    }
    if let Some(every) = args.waveforms {
        check_waveforms(&log, &setup.prepared.counts, every)?;
        json.waveforms = log.waveforms.iter().map(|w| w.json()).collect();
    }
    let mut out = std::io::stdout().lock();
    let text = if a.json {
        serde_json::to_string_pretty(&json).map_err(|e| e.to_string())? + "\n"
    } else if a.csv {
        crate::report::to_csv(&json)
    } else {
        crate::report::to_table(&json)
    };
    out.write_all(text.as_bytes()).map_err(|e| e.to_string())?;
    if let Some(path) = &a.plot {
        crate::plot::impacts(&setup.plot_signal(), &log.impacts, path)?;
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}

/// Every analysed impact's window, as the firmware sent it, against the replayed samples
/// (whole or averaged the same way): equal value for value, or an error naming the first
/// difference. Prints what it checked.
pub fn check_waveforms(log: &crate::log::Log, counts: &[i16], every: u16) -> Result<(), String> {
    let analysed = log
        .impacts
        .iter()
        .filter(|r| r.analysis != impact_core::Analysis::Skipped)
        .count();
    if log.waveforms.len() != analysed {
        return Err(format!(
            "the firmware sent {} waveforms for {analysed} analysed impacts",
            log.waveforms.len()
        ));
    }
    let mut frames = 0;
    for w in &log.waveforms {
        if w.every != every {
            return Err(format!(
                "impact {}: waveform every={}, asked {every}",
                w.index, w.every
            ));
        }
        let from = usize::try_from(w.first_sample).map_err(|e| e.to_string())?;
        let window = counts
            .get(from..from + w.samples as usize)
            .ok_or_else(|| format!("impact {}: its window lies beyond the recording", w.index))?;
        let mut expected = [0i16; impact_core::waveform::FRAME_LEN];
        for k in 0..w.frames as usize {
            let n = impact_core::waveform::frame(window, every, k, &mut expected);
            for (j, want) in expected.iter().take(n).enumerate() {
                let at = k * impact_core::waveform::FRAME_LEN + j;
                let got = w.value(at);
                if got != Some(*want) {
                    return Err(format!(
                        "impact {}: waveform value {at} is {got:?}, the replayed samples give {want}",
                        w.index
                    ));
                }
            }
        }
        frames += w.frames;
    }
    eprintln!(
        "waveforms: {} windows, {frames} frames, equal to the replayed samples",
        log.waveforms.len()
    );
    Ok(())
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
