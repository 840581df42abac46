//! Instruction counts of the core on the Cortex-M4F, run under QEMU by `impact bench m4`.
//!
//! Bare metal (no executor, no interrupt but SysTick's wrap count), so nothing but the measured
//! code runs between two marks. The semihosting command line is
//! `<program> <trace|count> <samples-file> <jobs-file>`; the jobs file holds one job per line:
//!
//! * `scene key=value ...`: the scene of the next streams, from the board's
//!   [`scene::BENCH`] with the keys of [`scene::apply`], and `spec_rows=U:LOWER:UPPER;…` a
//!   user's band for its spec (one per run);
//! * `stream <label>`: the samples file (raw little-endian i16) through the board's
//!   `impact_core::board::BoardMonitor` in blocks of [`BLOCK_LEN`], each `push_block` call between
//!   [`bench_begin`] and [`bench_end`]. Prints the kind of every block (`i` idle, `t` the
//!   trigger fired, `a` inside an impact, `e` an impact ended and was reported, `m` mixed) and,
//!   in `count` mode, the SysTick time of each kind and of the whole stream;
//! * `solve <label> <reps> <method> <steps|rtol> <mass> <v0> <model> <p1> <p2> <p3>
//!   <permanent|none>`: `reps` identical f32
//!   [`impact_core::solve`] calls; prints their SysTick time and the outcome's bits;
//! * `selftest`: the board's hand-written routines (SIMD stride statistics, word-wise copy,
//!   the spectra's recursion and both responses, FPU square root)
//!   against their portable references; prints `selftest ok`;
//! * `math <op> <backend> <lo> <hi>`: [`MATH_CALLS`] calls of one maths function (`libm`,
//!   `micromath`, or the FPU's `vsqrt`) on inputs spread over `lo..hi`; prints the SysTick time of the calls and of the bare loop.
//!
//! `trace` mode is meant for `qemu-system-arm -singlestep -d exec,nochain` (the host counts
//! the traced instructions between the marks and weighs them by the Cortex-M4's timings);
//! `count` mode for `-icount shift=0`, where the virtual clock advances one nanosecond per
//! instruction and SysTick counts the 25 MHz processor clock (a `calibrate` line measures the
//! instructions per tick on a loop of known length).
//!
//! Build: `cargo build --release -p impact-firmware --target thumbv7em-none-eabihf
//! --no-default-features --features m4-bench --bin m4-bench`.

#![no_std]
#![no_main]

use impact_firmware::scene;
use impact_firmware::semihosting as host;

use core::hint::black_box;
use core::sync::atomic::{AtomicU32, Ordering};

use cortex_m::peripheral::syst::SystClkSource;
use cortex_m_rt::{entry, exception};
use cortex_m_semihosting::hprintln;
use impact_core::model::{Hertz, KelvinVoigt, Linear, Nonlinear, TwoPhase};
use impact_core::spec::BandPoint;
use impact_core::{solve, Impact, ImpactReport, Method, Model, Monitor, Scene, Settings};
use static_cell::ConstStaticCell;

use defmt_semihosting as _;

/// Samples per `push_block` call: the firmware's DMA half-buffer.
use impact_core::board::BLOCK_LEN;
/// Largest samples file, samples.
const MAX_SAMPLES: usize = 1 << 18;
/// Largest jobs file, bytes.
const MAX_JOBS: usize = 16 * 1024;
/// Calls per `math` job.
const MATH_CALLS: usize = 1024;

static MONITOR: ConstStaticCell<impact_core::board::BoardMonitor> =
    ConstStaticCell::new(Monitor::unconfigured());
static SAMPLES: ConstStaticCell<[i16; MAX_SAMPLES]> = ConstStaticCell::new([0; MAX_SAMPLES]);
static RAW: ConstStaticCell<[u8; 2 * MAX_SAMPLES]> = ConstStaticCell::new([0; 2 * MAX_SAMPLES]);
static JOBS: ConstStaticCell<[u8; MAX_JOBS]> = ConstStaticCell::new([0; MAX_JOBS]);
static KINDS: ConstStaticCell<[u8; MAX_SAMPLES / BLOCK_LEN + 1]> =
    ConstStaticCell::new([0; MAX_SAMPLES / BLOCK_LEN + 1]);

/// SysTick wraps (2^24 ticks each) so far.
static WRAPS: AtomicU32 = AtomicU32::new(0);

#[exception]
fn SysTick() {
    WRAPS.fetch_add(1, Ordering::Relaxed);
}

/// SysTick ticks since start (processor clock; 2^24 per wrap).
fn now() -> u64 {
    loop {
        let w = WRAPS.load(Ordering::Relaxed);
        let current = cortex_m::peripheral::SYST::get_current();
        if WRAPS.load(Ordering::Relaxed) == w {
            return ((w as u64) << 24) + (0x00FF_FFFF - current as u64);
        }
    }
}

/// Start of a measured region: the host's trace counter starts after this returns.
#[inline(never)]
#[no_mangle]
pub extern "C" fn bench_begin() {
    cortex_m::asm::nop();
}

/// End of a measured region: the host's trace counter stops when this is entered.
#[inline(never)]
#[no_mangle]
pub extern "C" fn bench_end() {
    // Two, so that the linker does not fold the two marks into one function.
    cortex_m::asm::nop();
    cortex_m::asm::nop();
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Mode {
    Trace,
    Count,
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    hprintln!("error panic");
    host::exit(false)
}

#[entry]
fn main() -> ! {
    let ok = run().is_ok();
    host::exit(ok)
}

fn run() -> Result<(), ()> {
    let mut line = [0u8; 512];
    let cmd = host::command_line(&mut line).map_err(|_| hprintln!("error command line"))?;
    let mut args = cmd.split_ascii_whitespace().skip(1);
    let mode = match args.next() {
        Some("trace") => Mode::Trace,
        Some("count") => Mode::Count,
        _ => {
            hprintln!("error usage: <program> <trace|count> <samples> <jobs>");
            return Err(());
        }
    };
    // SysTick only in `count` mode: in a trace run its interrupt would land in the regions.
    if mode == Mode::Count {
        let mut core = cortex_m::Peripherals::take().ok_or(())?;
        core.SYST.set_clock_source(SystClkSource::Core);
        core.SYST.set_reload(0x00FF_FFFF);
        core.SYST.clear_current();
        core.SYST.enable_interrupt();
        core.SYST.enable_counter();
    }
    let samples_path = args.next().ok_or(())?;
    let jobs_path = args.next().ok_or(())?;

    let raw = RAW.take();
    let bytes = read(samples_path, raw)?;
    let samples = SAMPLES.take();
    let n = bytes / 2;
    for (s, b) in samples.iter_mut().zip(raw.chunks_exact(2)).take(n) {
        *s = i16::from_le_bytes([b[0], b[1]]);
    }
    let samples = &samples[..n];
    let jobs = JOBS.take();
    let len = read(jobs_path, jobs)?;
    let jobs = core::str::from_utf8(&jobs[..len]).map_err(|_| hprintln!("error jobs not UTF-8"))?;

    if mode == Mode::Count {
        calibrate();
    }
    let monitor = MONITOR.take();
    let kinds = KINDS.take();
    let mut scene = scene::BENCH;
    let mut ok = true;
    for job in jobs.lines() {
        let mut words = job.split_ascii_whitespace();
        let result = match words.next() {
            None => Ok(()),
            Some("scene") => set_scene(&mut scene, words),
            Some("stream") => stream(
                mode,
                monitor,
                &scene,
                samples,
                kinds,
                words.next().unwrap_or("-"),
            ),
            Some("solve") if mode == Mode::Count => solve_job(words),
            Some("math") if mode == Mode::Count => math_job(words),
            Some("selftest") => selftest(),
            Some(_) => Ok(()),
        };
        if result.is_err() {
            hprintln!("error job: {}", job);
            ok = false;
        }
    }
    hprintln!("done");
    if ok {
        Ok(())
    } else {
        Err(())
    }
}

/// Reads a host file into `buf`; returns its length.
fn read(path: &str, buf: &mut [u8]) -> Result<usize, ()> {
    let mut file = host::HostFile::open(path).map_err(|_| hprintln!("error open {}", path))?;
    let len = file.len_bytes().map_err(|_| ())?;
    if len > buf.len() {
        hprintln!("error {} is longer than {} bytes", path, buf.len());
        return Err(());
    }
    file.read_full(&mut buf[..len])
        .map_err(|_| hprintln!("error read {}", path))
}

/// Instructions per SysTick tick, from a loop of 2 × 10^6 instructions.
fn calibrate() {
    const ITERATIONS: u32 = 1_000_000;
    let t0 = now();
    // SAFETY: a register-only count-down loop: `subs` and `bne`, two instructions per pass.
    unsafe {
        core::arch::asm!(
            "2:",
            "subs {n}, {n}, #1",
            "bne 2b",
            n = inout(reg) ITERATIONS => _,
            options(nomem, nostack),
        );
    }
    let ticks = now() - t0;
    hprintln!("calibrate instructions={} ticks={}", 2 * ITERATIONS, ticks);
}

fn set_scene<'a>(scene: &mut Scene, words: impl Iterator<Item = &'a str>) -> Result<(), ()> {
    *scene = scene::BENCH;
    let mut rows = None;
    for kv in words {
        let (k, v) = kv.split_once('=').ok_or(())?;
        if k == "spec_rows" {
            rows = Some(v);
            continue;
        }
        scene::apply(scene, k, v).map_err(|_| ())?;
    }
    if let Some(text) = rows {
        let spec = scene.spec.as_mut().ok_or(())?;
        spec.band = Some(band_rows(text)?);
    }
    Ok(())
}

/// A user's band (`spec_rows=U:LOWER:UPPER;…`, [`impact_core::spec::Spec::band`]) in the
/// firmware's one static band table ([`scene::band_table`]): one band per run.
fn band_rows(text: &str) -> Result<&'static [BandPoint], ()> {
    let rows = text.split(';').map(|row| {
        let mut f = row.split(':').map(|x| x.parse::<f32>().map_err(|_| ()));
        match (f.next(), f.next(), f.next(), f.next()) {
            (Some(u), Some(lower), Some(upper), None) => Ok(BandPoint {
                u: u?,
                lower: lower?,
                upper: upper?,
            }),
            _ => Err(()),
        }
    });
    scene::band_table(rows).map_err(|e| {
        if e == scene::BandTableError::Taken {
            hprintln!("error one spec_rows per run");
        }
    })
}

fn stream(
    mode: Mode,
    monitor: &mut impact_core::board::BoardMonitor,
    scene: &Scene,
    samples: &[i16],
    kinds: &mut [u8],
    label: &str,
) -> Result<(), ()> {
    monitor.configure(*scene).map_err(|_| ())?;
    // Ticks per kind: idle, trigger, active, end, mixed.
    let mut ticks = [0u64; 5];
    let mut blocks = [0u32; 5];
    let mut reports = 0u32;
    let mut fits = [0u32; 3];
    let mut last: Option<ImpactReport> = None;
    let t_stream = now();
    for (k, block) in samples.chunks(BLOCK_LEN).enumerate() {
        let before = monitor.in_impact();
        let mut ended = 0u32;
        let mut out = |r: &ImpactReport| {
            ended += 1;
            last = Some(*r);
        };
        let t0 = if mode == Mode::Count { now() } else { 0 };
        bench_begin();
        monitor.push_block(black_box(block), &mut out);
        bench_end();
        let t = if mode == Mode::Count { now() - t0 } else { 0 };
        let after = monitor.in_impact();
        let kind = match (before, after, ended) {
            (false, false, 0) => 0,
            (false, true, 0) => 1,
            (true, true, 0) => 2,
            (true, false, 1) => 3,
            _ => 4,
        };
        ticks[kind] += t;
        blocks[kind] += 1;
        reports += ended;
        if let Some(slot) = kinds.get_mut(k) {
            *slot = b"itaem"[kind];
        }
        if ended > 0 {
            if let Some(r) = &last {
                fits[0] += r.fits.two_phase.is_some() as u32;
                fits[1] += r.fits.nonlinear.is_some() as u32;
                fits[2] += r.fits.hertz.is_some() as u32;
            }
        }
    }
    let total = now() - t_stream;
    let n_blocks = samples.len().div_ceil(BLOCK_LEN).min(kinds.len());
    hprintln!(
        "stream {} samples={} block={} reports={} fits={}{}{}",
        label,
        samples.len(),
        BLOCK_LEN,
        reports,
        fits[0],
        fits[1],
        fits[2]
    );
    for chunk in kinds[..n_blocks].chunks(64) {
        hprintln!("kinds {}", core::str::from_utf8(chunk).unwrap_or("?"));
    }
    if mode == Mode::Count {
        hprintln!(
            "ticks {} total={} idle={} trigger={} active={} end={} mixed={} blocks={},{},{},{},{}",
            label,
            total,
            ticks[0],
            ticks[1],
            ticks[2],
            ticks[3],
            ticks[4],
            blocks[0],
            blocks[1],
            blocks[2],
            blocks[3],
            blocks[4]
        );
    }
    if let Some(r) = last {
        hprintln!(
            "report {} status={:?} peak_m_s2={:e} delta_v_m_s={:?} duration_s={:e}",
            label,
            r.status,
            r.peak_acceleration_m_s2,
            r.delta_v_m_s,
            r.duration_s
        );
    }
    Ok(())
}

/// The board's hand-written routines against their portable references: the SIMD stride
/// statistics at every alignment and length up to two strides, on extreme and random values,
/// the word-wise copy, the spectra's recursion and both responses at every length up to 160
/// (`skim_mismatch`, `tops_mismatch`)
/// and the FPU square root on a sweep of magnitudes. Prints `selftest ok` or the first
/// mismatch.
fn selftest() -> Result<(), ()> {
    use impact_core::signal::baseline::Stats;
    let mut buf = [0i16; 160];
    let mut state = 0x2545_f491u32;
    for round in 0..8u32 {
        for (k, x) in buf.iter_mut().enumerate() {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            *x = match (round, k % 5) {
                (0, _) => i16::MIN,
                (1, _) => i16::MAX,
                (2, 0) => i16::MIN,
                (2, 1) => i16::MAX,
                _ => state as i16,
            };
        }
        for start in 0..4 {
            for len in 0..=(buf.len() - start).min(130) {
                let s = &buf[start..start + len];
                if Stats::of(s) != Stats::of_portable(s) {
                    hprintln!(
                        "selftest stats mismatch round={} start={} len={}",
                        round,
                        start,
                        len
                    );
                    return Err(());
                }
            }
        }
    }
    let mut dst = [0i16; 160];
    for start in 0..4 {
        for at in 0..4 {
            for len in 0..=100 {
                dst.fill(7);
                impact_core::signal::copy::copy_samples(
                    &mut dst[at..at + len],
                    &buf[start..start + len],
                );
                let same = dst[at..at + len] == buf[start..start + len];
                let untouched = dst[..at].iter().chain(&dst[at + len..]).all(|&x| x == 7);
                if !(same && untouched) {
                    hprintln!(
                        "selftest copy mismatch start={} at={} len={}",
                        start,
                        at,
                        len
                    );
                    return Err(());
                }
            }
        }
    }
    let samples: [f32; 160] = core::array::from_fn(|k| f32::from(buf[k]) * 1e-3);
    if let Some(len) = impact_core::signal::spectrum::skim_mismatch(&samples) {
        hprintln!("selftest skim mismatch len={}", len);
        return Err(());
    }
    if let Some(len) = impact_core::signal::spectrum::tops_mismatch(&samples) {
        hprintln!("selftest tops mismatch len={}", len);
        return Err(());
    }
    let mut x = 1e-30f32;
    while x < 1e30 {
        for v in [x, x * 1.000_001, x * 3.7] {
            if impact_core::real::fpu_sqrt(v).to_bits() != libm::sqrtf(v).to_bits() {
                hprintln!("selftest sqrt mismatch x={:e}", v);
                return Err(());
            }
        }
        x *= 1.37;
    }
    hprintln!("selftest ok");
    Ok(())
}

fn float(w: Option<&str>) -> Result<f32, ()> {
    w.ok_or(())?.parse::<f32>().map_err(|_| ())
}

fn solve_job<'a>(mut w: impl Iterator<Item = &'a str>) -> Result<(), ()> {
    let label = w.next().ok_or(())?;
    let reps = w.next().ok_or(())?.parse::<u32>().map_err(|_| ())?.max(1);
    let method = w.next().ok_or(())?;
    let knob = w.next().ok_or(())?;
    let mass = float(w.next())?;
    let v0 = float(w.next())?;
    let model = w.next().ok_or(())?;
    let p = [float(w.next())?, float(w.next())?, float(w.next())?];
    let permanent_m = match w.next() {
        Some("none") => None,
        other => Some(float(other)?),
    };
    let model: Model<f32> = match model {
        "hertz" => Model::Hertz(Hertz { k: p[0] }),
        "linear" => Model::Linear(Linear { k: p[0] }),
        "kelvin-voigt" => Model::KelvinVoigt(KelvinVoigt { k: p[0], c: p[1] }),
        "two-phase" => Model::TwoPhase(TwoPhase {
            kc: p[0],
            kr: p[1],
            c: p[2],
            permanent_m,
        }),
        "nonlinear" => Model::Nonlinear(Nonlinear {
            k: p[0],
            c: p[1],
            n: p[2],
        }),
        _ => return Err(()),
    };
    let settings = match method {
        "exact" => Settings::exact(),
        "adaptive" => Settings::adaptive(knob.parse::<f32>().map_err(|_| ())?),
        m => {
            let method = match m {
                "euler" => Method::Euler,
                "verlet" => Method::Verlet,
                "rk4" => Method::Rk4,
                _ => return Err(()),
            };
            Settings::fixed(method, knob.parse::<u32>().map_err(|_| ())?)
        }
    };
    let impact = Impact::new(mass, v0);
    let t0 = now();
    bench_begin();
    let mut outcome = solve(black_box(&model), black_box(&impact), black_box(&settings));
    for _ in 1..reps {
        outcome = solve(black_box(&model), black_box(&impact), black_box(&settings));
    }
    bench_end();
    let ticks = now() - t0;
    match outcome {
        Ok(o) => hprintln!(
            "solve {} reps={} ticks={} ok=1 rhs={} bits={:08x},{:08x},{:08x},{:08x},{:08x},{:08x}",
            label,
            reps,
            ticks,
            o.rhs_evaluations,
            o.max_deformation_m.to_bits(),
            o.crush_time_s.to_bits(),
            o.contact_time_s.to_bits(),
            o.rebound_velocity_m_s.to_bits(),
            o.peak_force_n.to_bits(),
            o.permanent_deformation_m.to_bits()
        ),
        Err(_) => hprintln!("solve {} ticks={} ok=0", label, ticks),
    }
    Ok(())
}

/// `vsqrt.f32`: the FPU's square root (IEEE correctly rounded, 14 cycles on the M4).
fn vsqrt(x: f32) -> f32 {
    impact_core::real::fpu_sqrt(x)
}

/// A maths function of one f32.
type MathFn = fn(f32) -> f32;

/// The maths function `op` of back-end `backend`.
fn math_fn(op: &str, backend: &str) -> Option<MathFn> {
    use micromath::F32Ext;
    Some(match (op, backend) {
        ("none", _) => |x| x,
        ("sqrt", "libm") => libm::sqrtf,
        ("sqrt", "micromath") => |x| F32Ext::sqrt(x),
        ("sqrt", "vsqrt") => vsqrt,
        ("exp", "libm") => libm::expf,
        ("exp", "micromath") => |x| F32Ext::exp(x),
        ("ln", "libm") => libm::logf,
        ("ln", "micromath") => |x| F32Ext::ln(x),
        ("pow1.5", "libm") => |x| libm::powf(x, 1.5),
        ("pow1.5", "micromath") => |x| F32Ext::powf(x, 1.5),
        ("pow1.5", "vsqrt") => |x| x * vsqrt(x),
        ("sin", "libm") => libm::sinf,
        ("sin", "micromath") => |x| F32Ext::sin(x),
        ("cos", "libm") => libm::cosf,
        ("cos", "micromath") => |x| F32Ext::cos(x),
        ("asin", "libm") => libm::asinf,
        ("asin", "micromath") => |x| F32Ext::asin(x),
        ("acos", "libm") => libm::acosf,
        ("acos", "micromath") => |x| F32Ext::acos(x),
        _ => return None,
    })
}

fn math_job<'a>(mut w: impl Iterator<Item = &'a str>) -> Result<(), ()> {
    let op = w.next().ok_or(())?;
    let backend = w.next().ok_or(())?;
    let (lo, hi) = (float(w.next())?, float(w.next())?);
    let f = math_fn(op, backend).ok_or(())?;
    let step = (hi - lo) / MATH_CALLS as f32;
    let f = black_box(f);
    let t0 = now();
    bench_begin();
    let mut acc = 0.0f32;
    for k in 0..MATH_CALLS {
        acc += f(black_box(lo + step * k as f32));
    }
    bench_end();
    let ticks = now() - t0;
    black_box(acc);
    hprintln!(
        "math {} {} calls={} ticks={}",
        op,
        backend,
        MATH_CALLS,
        ticks
    );
    Ok(())
}
