//! Link-time proof that the pipeline cannot panic on the target (`scripts/test.sh`).
//!
//! The panic handler calls `__pipeline_can_panic`, which is defined nowhere: if the release
//! build for `thumbv7em-none-eabihf` keeps any path to a panic (an index out of bounds, an
//! overflow check, an `unwrap`, a division by zero, …) the link fails with an undefined
//! symbol. The entry runs [`Monitor::configure`], [`Monitor::push_block`], [`Monitor::gap`],
//! [`Monitor::finish`], [`Monitor::set_approach_speed`] (the streaming stage and the
//! per-impact analysis with every fit) and [`impact_core::solve`] (every model, exact and
//! adaptive, f32) on
//! values the optimizer cannot know: the scene, the models and the impacts go through
//! `black_box`, the samples and the block lengths are volatile reads of ADC1's data
//! register. The monitor is the board's (`impact_core::board::BoardMonitor`), with CFC and fits compiled in.
//!
//! Build: `cargo build --release -p impact-firmware --target thumbv7em-none-eabihf
//! --no-default-features --features panic-check --bin panic-check`. Nothing runs it.

#![no_std]
#![no_main]

// With `stm32` on, embassy-stm32 turns on cortex-m-rt's `device` feature and the link wants
// its interrupt vectors (whose handlers are not the pipeline's business).
#[cfg(any(feature = "stm32", feature = "emulator"))]
compile_error!(
    "build the panic check alone: `--no-default-features --features panic-check --bin panic-check`"
);

use core::hint::black_box;

use cortex_m_rt::entry;
use impact_core::model::{Hertz, KelvinVoigt, Linear, Nonlinear, TwoPhase};
use impact_core::signal::cfc::Cfc;
use impact_core::{
    solve, Approach, Calibration, FitSet, Impact, ImpactReport, Model, Monitor, Scene, Settings,
};
use static_cell::ConstStaticCell;

extern "C" {
    /// Defined nowhere, on purpose: a reachable panic makes the link fail.
    fn __pipeline_can_panic() -> !;
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    // SAFETY: never called in a build that links (the symbol does not exist).
    unsafe { __pipeline_can_panic() }
}

/// The board's monitor (its pre-trigger ring and capture length).
static MONITOR: ConstStaticCell<impact_core::board::BoardMonitor> =
    ConstStaticCell::new(Monitor::unconfigured());

/// STM32F407 ADC1 data register: a source of values the compiler cannot know.
const ADC1_DR: *const u32 = 0x4001_204C as *const u32;

fn unknown() -> u32 {
    // SAFETY: an aligned, always-readable peripheral register (nothing runs this binary).
    unsafe { core::ptr::read_volatile(ADC1_DR) }
}

/// A user's band (`spec.band`), so that its look-ups are linked and checked too.
static BAND: [impact_core::spec::BandPoint; 4] = {
    use impact_core::spec::BandPoint;
    [
        BandPoint {
            u: -0.4,
            lower: -0.2,
            upper: 0.2,
        },
        BandPoint {
            u: 0.0,
            lower: -0.2,
            upper: 0.4,
        },
        BandPoint {
            u: 1.0,
            lower: -0.2,
            upper: 1.2,
        },
        BandPoint {
            u: 1.1,
            lower: -0.2,
            upper: 0.2,
        },
    ]
};

/// A scene like the board's, with the CFC filters and every fit on; `black_box` makes every
/// field unknown, so all variants and values are possible.
fn scene() -> Scene {
    black_box(Scene {
        calibration: Calibration {
            gain_m_s2_per_count: 1600.0 / 4096.0,
            sample_rate_hz: 500_000.0,
        },
        mass_kg: Some(0.06),
        approach: Approach::Speed { v0_m_s: 1.3357 },
        trigger_m_s2: 10.0,
        edge_m_s2: 2.0,
        hold_s: 2e-3,
        max_impact_s: 1.0,
        settle_s: 0.05,
        clip_counts: (0, 4095),
        cfc: Some(Cfc::Cfc1000),
        // (Unknown after `black_box` too: the low-pass's path is linked as the CFC's is.)
        lowpass: None,
        trigger_cfc: Some(Cfc::Cfc1000),
        fits: FitSet::all(),
        // Vertical, so that the gravity shift of the kinematics is linked in too.
        gravity_m_s2: black_box(impact_core::consts::STANDARD_GRAVITY as f32),
        vertical: true,
        v0_every: black_box(false),
        train: Some(impact_core::Train::new()),
        spectrum: Some(impact_core::signal::spectrum::SpectrumSettings::new()),
        spec: Some(impact_core::spec::Spec {
            shape: impact_core::spec::Shape::Trapezoid {
                rise: 0.1,
                fall: 0.1,
            },
            peak_m_s2: 500.0,
            duration_s: 0.011,
            tolerance: impact_core::spec::Tolerance {
                band: 0.2,
                outside: 0.2,
                slack: 0.1,
                delta_v: 0.15,
                before: 0.4,
                after: 0.1,
                watch: 1.1,
            },
            band: Some(&BAND),
        }),
        waveform_every: 1,
        target: None,
    })
}

fn models() -> [Model<f32>; 5] {
    black_box([
        Model::Hertz(Hertz { k: 1e7 }),
        Model::Linear(Linear { k: 1e5 }),
        Model::KelvinVoigt(KelvinVoigt { k: 1e5, c: 10.0 }),
        Model::TwoPhase(TwoPhase {
            kc: 1e5,
            kr: 2e5,
            c: 10.0,
            permanent_m: None,
        }),
        Model::Nonlinear(Nonlinear {
            k: 1e5,
            c: 0.1,
            n: 1.5,
        }),
    ])
}

#[entry]
fn main() -> ! {
    // `try_take`, not `take`: the latter panics when called twice.
    let Some(monitor) = MONITOR.try_take() else {
        loop {
            cortex_m::asm::wfi();
        }
    };
    let mut out = |r: &ImpactReport| {
        black_box(r);
    };
    let mut block = [0i16; 256];
    loop {
        match unknown() & 7 {
            0 => {
                let _ = black_box(monitor.configure(scene()));
            }
            1 => monitor.finish(&mut out),
            // A loss of any size, anywhere (the firmware's gap events).
            3 => monitor.gap(u64::from(unknown()), &mut out),
            // A light gate's reading, any value.
            4 => monitor.set_approach_speed(Some(f32::from_bits(unknown()))),
            // Any frame of any window at any averaging (the waveforms sent off the board).
            5 => {
                let n = (unknown() as usize).min(block.len());
                let mut frame = [0i16; impact_core::waveform::FRAME_LEN];
                let _ = black_box(impact_core::waveform::frame(
                    block.get(..n).unwrap_or(&[]),
                    unknown() as u16,
                    unknown() as usize,
                    &mut frame,
                ));
            }
            2 => {
                let impact = black_box(Impact::new(0.06f32, 1.3357));
                for model in models() {
                    let _ = black_box(solve(&model, &impact, &Settings::exact()));
                    let _ = black_box(solve(&model, &impact, &Settings::adaptive(black_box(1e-6))));
                }
            }
            _ => {
                let n = (unknown() as usize).min(block.len());
                for x in block.iter_mut() {
                    *x = unknown() as i16;
                }
                monitor.push_block(block.get(..n).unwrap_or(&[]), &mut out);
            }
        }
    }
}
