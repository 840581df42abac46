//! `impact emulate FILE [analyze options]`: the recording prepared exactly as `impact analyze`
//! prepares it (the same i16 counts, the same scene), replayed on the emulated firmware
//! ([`crate::firmware_link::qemu`]), its `impact ...` lines parsed back into reports, and the
//! same table, JSON or CSV printed. The log's line format is in `docs/board.md`.

use std::io::Write;
use std::path::PathBuf;
use std::time::Duration;

use clap::Args;

use crate::firmware_link::line::{Counter, FieldError};
use crate::firmware_link::log::{parse_log, LogError};
use crate::firmware_link::qemu::{
    build_firmware, run_emulator, tools_available, Pacing, QemuError, Samples, BOARD_CLOCK_SHIFT,
};
use crate::pipeline::{self, AnalyzeArgs};

/// Why `impact emulate` refused, or its run failed or disagreed with the recording.
#[derive(Debug, thiserror::Error)]
pub enum EmulateError {
    #[error(transparent)]
    Qemu(#[from] QemuError),
    #[error(
        "--stream: the emulator replays a recording it has read whole (impact analyze --stream reads one as it comes)"
    )]
    Stream,
    #[error(
        "--capture-samples: the board's capture is {board} samples; the emulator runs the board as built (impact analyze --capture-samples analyses with another)"
    )]
    CaptureSamples { board: usize },
    /// `--plot`: refused before any work, or its figure not written.
    #[error(transparent)]
    Plot(#[from] crate::plot::PlotError),
    /// The recording could not be read or prepared as `impact analyze` prepares it.
    #[error(transparent)]
    Pipeline(#[from] pipeline::PipelineError),
    #[error(transparent)]
    Output(#[from] crate::output::OutputError),
    #[error("--log and --defmt: the same file; give each its own")]
    SameFile,
    #[error("a temporary file in {}: {source}", .dir.display())]
    TempFile {
        dir: PathBuf,
        source: std::io::Error,
    },
    #[error(
        "--adxl375: the ADXL375 samples at 3200, 1600, 800, 400, 200 or 100 S/s; this recording is at {rate} S/s (render one at the part's rate with `impact synth --rate 3200`)"
    )]
    Adxl375Rate { rate: f64 },
    /// The board's ADXL375 scene is invalid (a core parameter, named as its option).
    #[error("--adxl375: {}", crate::flags::core(*.0))]
    Adxl375Scene(impact_core::Error),
    #[error("the emulated firmware failed ({status}); see its log above")]
    Firmware { status: std::process::ExitStatus },
    #[error(transparent)]
    Log(#[from] LogError),
    #[error("the emulator's log has no summary line")]
    NoSummary,
    #[error(transparent)]
    Field(#[from] FieldError),
    #[error(
        "the emulator processed {samples} and lost {lost} of {total} samples (result={result})"
    )]
    Processed {
        samples: u64,
        lost: u64,
        total: u64,
        result: String,
    },
    #[error(transparent)]
    Waveform(#[from] WaveformMismatch),
    #[error(transparent)]
    Replay(#[from] ReplayError),
    #[error(transparent)]
    Json(#[from] serde_json::Error),
    #[error(transparent)]
    Stdout(std::io::Error),
}

/// The replayed stream's counts could not be read back.
#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    /// The counts file (written for QEMU) could not be opened or sought.
    #[error("{}: {source}", .path.display())]
    File {
        path: PathBuf,
        source: std::io::Error,
    },
    /// Past the end of the counts file.
    #[error("a window beyond the recording")]
    WindowBeyond,
    /// Past the end of the counts held.
    #[error("beyond the recording")]
    Beyond,
}

/// How the firmware's windows differ from the replayed samples.
#[derive(Debug, thiserror::Error)]
pub enum WaveformMismatch {
    #[error("the firmware sent {sent} waveforms for {analysed} analysed impacts")]
    Count { sent: usize, analysed: usize },
    #[error("impact {index}: waveform every={every}, asked {asked}")]
    Every { index: u32, every: u16, asked: u16 },
    #[error("impact {index}: its window lies beyond the recording")]
    Beyond { index: u32 },
    #[error("impact {index}: waveform value {at} is {got:?}, the replayed samples give {want}")]
    Value {
        index: u32,
        at: usize,
        got: Option<i16>,
        want: i16,
    },
}

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

/// `--rate-scale` refused (clap shows it after the option and the value).
#[derive(Debug, thiserror::Error)]
#[error("{value}: not a positive number")]
pub struct NotPositive {
    pub value: String,
}

fn positive_f32(s: &str) -> Result<f32, NotPositive> {
    match s.parse::<f32>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(NotPositive {
            value: s.to_string(),
        }),
    }
}

/// The ADXL375's scale, m/s² per count: 49 mg per LSB (the firmware's `G_PER_LSB` times
/// standard gravity, in f32 as there).
pub const ADXL375_GAIN_M_S2: f32 = 0.049 * impact_core::consts::STANDARD_GRAVITY as f32;

/// The ADXL375's output data rates, S/s.
pub const ADXL375_RATES_HZ: [f64; 6] = [3200.0, 1600.0, 800.0, 400.0, 200.0, 100.0];

/// One axis's range on the ADXL375: 13-bit two's complement, counts.
const ADXL375_AXIS_COUNTS: (i16, i16) = impact_firmware::adxl375::AXIS_RAILS;

/// The resultant's rail on the board (the firmware's `CLIP_COUNTS` with the ADXL375, its
/// `RESULTANT_CLIP`): the magnitude of the zeroed axes reaches 4031 counts whenever an axis
/// is at its rail and its zero lies within 64 counts (3.1 g) of 0.
const ADXL375_CLIP_COUNTS: (i16, i16) = (i16::MIN, impact_firmware::adxl375::RESULTANT_CLIP);

/// Turns a prepared recording into what an ADXL375 would give: each axis (`setup.axes`, or
/// the channel as x) in the part's counts, and the setup changed to the board's ADXL375 scene
/// (scale, rails) with what the board streams as its counts: the magnitude of the axes each
/// zeroed, or the one channel's axis.
pub fn adxl375_axes(setup: &mut pipeline::Setup) -> Result<Vec<[i16; 3]>, EmulateError> {
    let rate = setup.rate_hz;
    if !ADXL375_RATES_HZ
        .iter()
        .any(|r| ((rate - r) / r).abs() < 1e-3)
    {
        return Err(EmulateError::Adxl375Rate { rate });
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
    setup.scene.calibration.gain_m_s2_per_count = ADXL375_GAIN_M_S2;
    setup.prepared.calibration.gain_m_s2_per_count = ADXL375_GAIN_M_S2;
    // The board's resultant: the axes each zeroed as the scene says, as they come (no look
    // ahead), then their magnitude (the firmware's `adxl375::Picker`).
    let mut zero = impact_core::signal::axes_zero::AxesZero::new(
        setup.scene.axes_zero([ADXL375_AXIS_COUNTS; 3]),
    );
    setup.prepared.counts = axes
        .iter()
        .map(|&s| if one_axis { s[0] } else { zero.push(s) })
        .collect();
    setup.scene.clip_counts = if one_axis {
        ADXL375_AXIS_COUNTS
    } else {
        ADXL375_CLIP_COUNTS
    };
    setup.scene.validate().map_err(EmulateError::Adxl375Scene)?;
    Ok(axes)
}

/// `impact emulate`: prints what `impact analyze` would, computed by the emulated firmware.
/// Runs `impact emulate`; returns the board's verdicts (the exit status says whether one
/// failed).
pub fn emulate(args: &EmulateArgs) -> Result<crate::report::spec::Judged, EmulateError> {
    let a = &args.analyze;
    // Check the tools before a possibly long build.
    tools_available()?;
    if a.stream {
        return Err(EmulateError::Stream);
    }
    let board = impact_core::board::CAPTURE_LEN;
    if a.capture_samples.is_some_and(|n| n as usize != board) {
        return Err(EmulateError::CaptureSamples { board });
    }
    // No output over an input (the recording, the scene, the free fall, the firmware).
    let mut inputs = super::analyze::inputs(a);
    inputs.extend(args.elf.clone());
    if let Some(path) = &a.plot {
        crate::plot::check_output(path, &inputs)?;
    }
    let all = inputs
        .iter()
        .fold(crate::output::Inputs::new(), |all, i| all.with(i));
    for (option, path) in [("--log", &args.log), ("--defmt", &args.defmt)] {
        if let Some(path) = path {
            crate::output::check(option, path, &all, None)?;
        }
    }
    if args.log.is_some() && args.log == args.defmt {
        return Err(EmulateError::SameFile);
    }
    // One channel from a file or standard input is surveyed in passes and its counts written
    // a block at a time to the file QEMU replays (memory bounded whatever its length); the
    // ADXL375's axes and the options that need the whole recording read it whole.
    let streamed = !args.adxl375 && pipeline::streaming::in_passes(a);
    let counts_file = if streamed {
        let tmp = tempfile::Builder::new()
            .prefix("impact-emulate-")
            .suffix(".i16")
            .tempfile()
            .map_err(|source| EmulateError::TempFile {
                dir: std::env::temp_dir(),
                source,
            })?;
        let guard = crate::interrupt::temporary(tmp.path());
        Some((tmp, guard))
    } else {
        None
    };
    let mut setup = match &counts_file {
        Some((tmp, _)) => {
            let mut out = std::io::BufWriter::with_capacity(1 << 20, tmp.as_file());
            pipeline::streaming::counts_file(a, &mut out)?
        }
        None => {
            pipeline::memory_for_whole(&a.file)?;
            pipeline::setup(a, impact_io::progress::Progress::none())?
        }
    };
    setup.scene.waveform_every = args.waveforms.unwrap_or(0);
    let axes = if args.adxl375 {
        Some(adxl375_axes(&mut setup)?)
    } else {
        None
    };
    // One channel is the part's x axis, streamed as such (the board's `AXIS = Axis::X`):
    // kinematics apply; the resultant of --axes has none.
    let axis = setup.axes.is_empty().then_some(0);
    let samples = match (&axes, &counts_file) {
        (Some(axes), _) => Samples::Adxl375(axes, axis),
        (None, Some((tmp, _))) => Samples::File(tmp.path(), setup.samples),
        (None, None) => Samples::Adc(&setup.prepared.counts),
    };
    let total = samples.len() as u64;
    // Counts of the replayed stream, `n` from stream index `from`: read back from the file
    // when the recording was not held.
    let replayed = |from: u64, n: usize| -> Result<Vec<i16>, ReplayError> {
        match &counts_file {
            Some((tmp, _)) => read_counts(tmp.path(), from, n),
            None => setup
                .prepared
                .counts
                .get(usize::try_from(from).unwrap_or(usize::MAX)..)
                .and_then(|c| c.get(..n))
                .map(<[i16]>::to_vec)
                .ok_or(ReplayError::Beyond),
        }
    };
    let elf = match &args.elf {
        Some(p) => p.clone(),
        None => build_firmware()?,
    };
    // The log goes to stderr when stdout carries JSON or CSV.
    let to_stderr = a.json || a.csv;
    let stdout_terminal = std::io::IsTerminal::is_terminal(&std::io::stdout());
    let pacing = if args.realtime {
        Pacing::RealTime {
            rate_scale: args.rate_scale,
            clock_shift: args.clock_shift,
            inject: None,
        }
    } else {
        Pacing::Lossless
    };
    let run = run_emulator(
        &elf,
        samples,
        &setup.scene,
        false,
        pacing,
        Duration::from_secs(args.timeout),
        move |line| {
            // The waveform frames are for files (--log) and pipes (`| impact watch`), not
            // for the terminal.
            if line.contains("wave_frame ") && (to_stderr || stdout_terminal) {
                return;
            }
            if to_stderr {
                crate::errln!("{line}");
            } else {
                crate::outln!("{line}");
            }
        },
    )?;
    if !run.status.success() {
        return Err(EmulateError::Firmware { status: run.status });
    }
    let text = run.lines.join("\n") + "\n";
    if let Some(path) = &args.log {
        crate::output::write(path, text.as_bytes())?;
        crate::errln!("wrote {}", path.display());
    }
    if let Some(path) = &args.defmt {
        crate::output::write(path, &run.raw)?;
        crate::errln!(
            "wrote {} (decode: impact log --elf {} {})",
            path.display(),
            elf.display(),
            path.display()
        );
    }
    let log = parse_log(&text)?;
    let summary = log.summary.as_ref().ok_or(EmulateError::NoSummary)?;
    let state = &summary.state;
    let samples = summary.samples;
    let lost = state.counter(Counter::SamplesLost)?;
    let result = state.result()?;
    if samples + lost != total || result != "ok" {
        return Err(EmulateError::Processed {
            samples,
            lost,
            total,
            result: result.to_string(),
        });
    }
    crate::errln!("emulated in {:.2} s", run.seconds);
    let mut json = pipeline::to_json(&setup, &log.impacts);
    json.samples_lost = lost;
    json.analyses_skipped = state.counter(Counter::AnalysesSkipped)?;
    json.lines_dropped = log.lines_dropped;
    json.lines_missing = log.lines_missing;
    for w in &log.warnings {
        crate::errln!("warning: {w}");
    }
    for (j, latency) in json.impacts.iter_mut().zip(&log.latencies) {
        j.report_latency_s = latency.map(f64::from);
    }
    if let Some(every) = args.waveforms {
        // The board's zeroed resultant learns its zeros from the samples it got: after a
        // FIFO loss they follow other samples than the host's, and its values can differ.
        let zeroed_after_loss = args.adxl375 && !a.axes.is_empty() && lost > 0;
        check_waveforms(&log, &replayed, every, !zeroed_after_loss)?;
        json.waveforms = log.waveforms.iter().map(|w| w.json()).collect();
    }
    let mut out = crate::output::stdout();
    // The verdicts as the output shows them (with --axes, the transverse check's too).
    let judged = crate::report::spec::Judged::impacts(&json.impacts);
    let text = if a.json {
        serde_json::to_string_pretty(&json)? + "\n"
    } else if a.csv {
        crate::report::to_csv(&json)
    } else {
        crate::report::to_table(&json)
    };
    out.write_all(text.as_bytes())
        .map_err(EmulateError::Stdout)?;
    if let Some(path) = &a.plot {
        if counts_file.is_some() {
            // The windows the figure draws, from the replayed counts.
            let rate = f64::from(setup.scene.calibration.sample_rate_hz);
            let padding = u64::from(setup.scene.padding_samples());
            let mut windows = Vec::new();
            for r in log.impacts.iter().take(crate::plot::SHOWN) {
                let (from, n) = crate::plot::read_window(r, rate, padding);
                let n = n.min(total.saturating_sub(from));
                windows.push((from, replayed(from, n as usize)?));
            }
            setup.windows = windows;
        }
        let mut signal = setup.plot_signal();
        let file = &args.analyze.file;
        let name = file.file_name().map_or_else(
            || file.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        signal.title = format!("{name} on the emulated board, {}", signal.title);
        crate::plot::impacts(&signal, setup.scene.spec.as_ref(), &log.impacts, path)?;
    }
    Ok(judged)
}

/// `n` little-endian i16 counts from index `from` of the file at `path`.
fn read_counts(path: &std::path::Path, from: u64, n: usize) -> Result<Vec<i16>, ReplayError> {
    use std::io::{Read, Seek, SeekFrom};
    let failed = |source| ReplayError::File {
        path: path.to_path_buf(),
        source,
    };
    let mut file = std::fs::File::open(path).map_err(failed)?;
    file.seek(SeekFrom::Start(from * 2)).map_err(failed)?;
    let mut bytes = vec![0u8; n * 2];
    file.read_exact(&mut bytes)
        .map_err(|_| ReplayError::WindowBeyond)?;
    Ok(bytes
        .chunks_exact(2)
        .map(|b| i16::from_le_bytes([b[0], b[1]]))
        .collect())
}

/// Every analysed impact's window, as the firmware sent it, against the replayed samples
/// (whole or averaged the same way): equal value for value, or an error naming the first
/// difference. A decimated capture's window (its values each the mean of `step` samples,
/// halved in place as the buffer filled) comes at `every` rounded down to whole values (at
/// least `step`), each value within [`DECIMATED_ROUNDING`] counts of the samples' mean.
/// Prints what it checked.
pub fn check_waveforms(
    log: &crate::firmware_link::log::Log,
    replayed: &dyn Fn(u64, usize) -> Result<Vec<i16>, ReplayError>,
    every: u16,
    compare_values: bool,
) -> Result<(), WaveformMismatch> {
    let analysed = log
        .impacts
        .iter()
        .filter(|r| r.analysis != impact_core::Analysis::Skipped)
        .count();
    if log.waveforms.len() != analysed {
        return Err(WaveformMismatch::Count {
            sent: log.waveforms.len(),
            analysed,
        });
    }
    let step_of = |index: u32| {
        log.impacts
            .iter()
            .find(|r| r.index == index)
            .map_or(1, |r| r.decimation.max(1))
    };
    let (mut frames, mut decimated) = (0, 0);
    for w in &log.waveforms {
        let step = step_of(w.index);
        // (As the firmware rounds it: whole values of `step` samples, at least one.)
        let asked = u32::from(every) / step * step;
        let asked = u16::try_from(asked.max(step)).unwrap_or(u16::MAX);
        if w.every != asked {
            return Err(WaveformMismatch::Every {
                index: w.index,
                every: w.every,
                asked,
            });
        }
        let tolerance = if step > 1 {
            decimated += 1;
            DECIMATED_ROUNDING
        } else {
            0
        };
        let window = replayed(w.first_sample, w.samples as usize)
            .map_err(|_| WaveformMismatch::Beyond { index: w.index })?;
        if !compare_values {
            frames += w.frames;
            continue;
        }
        let window = window.as_slice();
        let mut expected = [0i16; impact_core::waveform::FRAME_LEN];
        for k in 0..w.frames as usize {
            let n = impact_core::waveform::frame(window, w.every, k, &mut expected);
            for (j, want) in expected.iter().take(n).enumerate() {
                let at = k * impact_core::waveform::FRAME_LEN + j;
                let got = w.value(at);
                let close =
                    got.is_some_and(|g| (i32::from(g) - i32::from(*want)).abs() <= tolerance);
                if !close {
                    return Err(WaveformMismatch::Value {
                        index: w.index,
                        at,
                        got,
                        want: *want,
                    });
                }
            }
        }
        frames += w.frames;
    }
    let coarse = if decimated > 0 {
        format!(" ({decimated} decimated captures within {DECIMATED_ROUNDING} counts of the samples' means)")
    } else {
        String::new()
    };
    if compare_values {
        crate::errln!(
            "waveforms: {} windows, {frames} frames, equal to the replayed samples{coarse}",
            log.waveforms.len()
        );
    } else {
        crate::errln!(
            "waveforms: {} windows, {frames} frames, their values not compared: the ADXL375 \
             lost samples, and the board's zeros learned without them",
            log.waveforms.len()
        );
    }
    Ok(())
}

/// How far a decimated capture's sent value may lie from its samples' mean, counts: each
/// halving rounds the mean of two values (half a count) and halves the error it inherits
/// (so less than one count in all), and the frame's mean of whole values rounds once more,
/// as does the mean it is checked against.
pub const DECIMATED_ROUNDING: i32 = 2;
