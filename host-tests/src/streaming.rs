//! `impact analyze --stream`: a raw recording (`.i16`/`.f32`, a file or standard input)
//! analysed as it is read, a block at a time, in memory that does not grow with its length
//! (an hour at 500 kS/s is 3.6 GB of i16). The per-sample arithmetic is the whole-file path's
//! (units, gain, quantisation to counts at the `--range` full scale), so with the same
//! levels both give the same reports (tested); what needs the whole signal is refused or
//! asked for instead: the quantisation's full scale (`--range`), the trigger level
//! (`--trigger`), spike screening (not done), figures, axes, free fall, resampling.

use std::io::Read;

use impact_core::{Calibration, ImpactReport};

use crate::analyze::{self, AnalyzeArgs, HostMonitor, Prepared, Setup};
use crate::raw::RawType;
use crate::table::is_stdin;

/// Samples whose noise sets the default edge level (the whole-file path uses the whole
/// recording's): the first 65 536.
const HEAD: usize = 1 << 16;

/// Bytes read at a time.
const CHUNK: usize = 1 << 16;

/// Reads and analyses `args.file` as a stream; the setup (without samples) and the reports.
pub fn analyze(args: &AnalyzeArgs) -> Result<(Setup, Vec<ImpactReport>), String> {
    let name = if is_stdin(&args.file) {
        "stdin".to_string()
    } else {
        args.file.display().to_string()
    };
    let kind = match (args.raw_type, RawType::of(&args.file)) {
        (Some(k), _) | (None, Some(k)) => k,
        (None, None) => {
            return Err(format!(
                "{name}: --stream reads raw .i16/.f32 samples: give --raw-type i16 or f32"
            ))
        }
    };
    let refuse = |what: &str| Err(format!("--stream: {what} needs the whole recording"));
    if args.plot.is_some() {
        return refuse("--plot");
    }
    if !args.axes.is_empty() {
        return refuse("--axes");
    }
    if args.free_fall.is_some() {
        return refuse("--free-fall");
    }
    if args.resample || args.time_column.is_some() {
        return Err("--stream: a raw stream has no time column (give --rate)".into());
    }
    let rate_hz = args
        .rate
        .ok_or("--stream: a raw stream holds no time: give --rate")?;
    if !(rate_hz.is_finite() && rate_hz > 0.0 && rate_hz <= 1e9) {
        return Err(format!("--rate {rate_hz}: not in (0, 1e9]"));
    }
    let channels = args.raw_channels.unwrap_or(1);
    if !(1..=64).contains(&channels) {
        return Err(format!("--raw-channels {channels}: must lie in 1..=64"));
    }
    let column = crate::recording::numbered_column(
        args.column.as_ref(),
        channels,
        &format!("the stream's {channels} interleaved channels"),
    )?;
    let file = match &args.scene {
        Some(p) => analyze::load_scene(p)?,
        None => analyze::SceneFile::default(),
    };
    let (mass, scale) = analyze::mass_and_scale(args, &file)?;
    let range = args.range.or(file.range).ok_or(
        "--stream: give --range (the sensor's full scale sets the quantisation before the \
         recording's extremes are known)",
    )?;
    if !(range.is_finite() && range > 0.0) {
        return Err(format!("--range: {range} must be finite and > 0"));
    }
    let trigger = args.trigger.or(file.trigger_m_s2).ok_or(
        "--stream: give --trigger (the level cannot be learned from a recording not yet read)",
    )?;
    let full_scale = range * scale.abs();
    let gain = full_scale / 32000.0;
    let calibration = Calibration {
        gain_m_s2_per_count: gain as f32,
        sample_rate_hz: rate_hz as f32,
    };
    let clipping = crate::screen::from_range(full_scale);

    let input: Box<dyn Read + Send> = if is_stdin(&args.file) {
        Box::new(std::io::stdin())
    } else {
        Box::new(std::fs::File::open(&args.file).map_err(|e| format!("{name}: {e}"))?)
    };
    let mut samples = Samples {
        input,
        kind,
        frame: kind.bytes() * channels,
        at: column * kind.bytes(),
        buf: vec![0u8; CHUNK],
        held: 0,
        read: 0,
        name: name.clone(),
    };
    // The head: its noise sets the default edge level.
    let mut head = Vec::with_capacity(HEAD);
    while head.len() < HEAD {
        let before = head.len();
        samples.next_values(HEAD - head.len(), |v| head.push(v * scale))?;
        if head.len() == before {
            break;
        }
    }
    let edge = args.edge.or(file.edge_m_s2).unwrap_or_else(|| {
        let sigma = analyze::noise_rms(&head);
        (3.0 * sigma).max(trigger / 5.0).min(trigger / 2.0)
    });
    let (scene, source) = analyze::build_scene(
        args,
        &file,
        calibration,
        trigger,
        edge,
        Some(&clipping),
        mass,
    )?;
    let (reports, count) = crate::on_big_stack(move || {
        let mut m = HostMonitor::new(scene).map_err(|e| e.to_string())?;
        let mut out = Vec::new();
        let mut counts: Vec<i16> = head.iter().map(|a| analyze::to_count(*a, gain)).collect();
        let mut total = 0u64;
        loop {
            for block in counts.chunks(256) {
                m.push_block(block, &mut |r: &ImpactReport| out.push(*r));
            }
            total += counts.len() as u64;
            counts.clear();
            samples.next_values(CHUNK, |v| counts.push(analyze::to_count(v * scale, gain)))?;
            if counts.is_empty() {
                break;
            }
        }
        m.finish(&mut |r: &ImpactReport| out.push(*r));
        if !m.is_armed() {
            return Err("the signal never settled to a baseline (no quiet stretch of 64 samples within the edge level): give --edge".into());
        }
        Ok((out, total))
    })?;
    let setup = Setup {
        prepared: Prepared {
            counts: Vec::new(),
            calibration,
            t0: 0.0,
            accel_m_s2: Vec::new(),
        },
        scene,
        v0_source: source.map(str::to_string),
        free_fall_s: None,
        samples: count,
        rate_hz,
        spikes: Vec::new(),
        clipping: Some(clipping),
        resampled: false,
        axes: Vec::new(),
    };
    Ok((setup, reports))
}

/// The chosen channel's values, read a chunk at a time.
struct Samples {
    input: Box<dyn Read + Send>,
    kind: RawType,
    /// Bytes per frame (all channels) and the channel's offset in it.
    frame: usize,
    at: usize,
    buf: Vec<u8>,
    /// Bytes in `buf` not yet used (a partial frame).
    held: usize,
    /// Bytes read so far.
    read: u64,
    name: String,
}

impl Samples {
    /// Hands up to about `want` values to `push` (none at the end of the input).
    fn next_values(&mut self, want: usize, mut push: impl FnMut(f64)) -> Result<(), String> {
        // At most `want` frames (the head stops at exactly HEAD samples whatever a pipe's
        // reads return), at least one whole frame's room.
        let end = (self.held + want.max(1) * self.frame).min(self.buf.len());
        let n = loop {
            match self.input.read(&mut self.buf[self.held..end]) {
                Ok(n) => break n,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
                Err(e) => return Err(format!("{}: {e}", self.name)),
            }
        };
        if n == 0 {
            if self.held > 0 {
                return Err(format!(
                    "{}: {} bytes: not a whole number of {}-byte frames; the last frame starts at byte {}",
                    self.name,
                    self.read,
                    self.frame,
                    self.read - self.held as u64
                ));
            }
            return Ok(());
        }
        self.read += n as u64;
        let have = self.held + n;
        let whole = have / self.frame * self.frame;
        for (k, f) in self.buf[..whole].chunks_exact(self.frame).enumerate() {
            let at = self.at;
            let v = match self.kind {
                RawType::I16 => f64::from(i16::from_le_bytes([f[at], f[at + 1]])),
                RawType::F32 => {
                    let v = f32::from_le_bytes([f[at], f[at + 1], f[at + 2], f[at + 3]]);
                    if !v.is_finite() {
                        let frame_no = (self.read - have as u64) / self.frame as u64 + k as u64;
                        return Err(format!(
                            "{}: frame {frame_no} (byte {}): {v} is not finite",
                            self.name,
                            frame_no * self.frame as u64 + at as u64
                        ));
                    }
                    f64::from(v)
                }
            };
            push(v);
        }
        self.buf.copy_within(whole..have, 0);
        self.held = have - whole;
        Ok(())
    }
}
