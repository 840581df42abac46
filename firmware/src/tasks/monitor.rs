//! Monitor task: runs impact-core's streaming pipeline ([`impact_core::Monitor`], the same code
//! as the host's `impact analyze`) over the sample blocks, and hands one report per impact, a
//! heartbeat per second of signal and the end-of-stream summary to the reporter.

use defmt::error;
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::signal::Signal;
use embassy_time::Instant;
use impact_core::monitor::Counters;
use impact_core::{ImpactReport, Monitor, Scene};
use static_cell::ConstStaticCell;

use super::reporter::{Heartbeat, Report, Tally};
use super::{SampleReceiver, SourceEvent, StreamEnd, REPORTS};

/// Pre-trigger ring (and baseline window), samples: the host's value.
pub const PRE_TRIGGER_LEN: usize = 4096;

/// Capture length, samples: 16384 (32.8 ms at 500 kS/s, enough for the seed bench's ~24 ms
/// contact plus the hold). The capture (i16) and its acceleration (f32) take 96 KiB of the
/// F407's 128 KiB; see firmware/README.md for the RAM budget.
#[cfg(feature = "stm32")]
pub const CAPTURE_LEN: usize = 16384;

/// Capture length, samples: the host's (`impact analyze`'s `HostMonitor`), so that emulated
/// and host reports agree bit for bit even for long impacts (768 KiB: the emulator's RAM
/// region is QEMU's 4 MiB, see firmware/emulator/board-memory.x).
#[cfg(feature = "emulator")]
pub const CAPTURE_LEN: usize = 131072;

/// The firmware's monitor.
pub type FwMonitor = Monitor<PRE_TRIGGER_LEN, CAPTURE_LEN>;

/// Impacts one block can finish that are queued for the reporter; more are counted as
/// dropped (an impact lasts at least the hold time, so one block of 256 finishes at most a
/// few).
const IMPACTS_PER_BLOCK: usize = 4;

/// A light gate (or anything else that measures the approach speed) signals it here, m/s; the
/// monitor uses it from the next block on, for the impacts that end after it.
pub static APPROACH_SPEED: Signal<CriticalSectionRawMutex, f32> = Signal::new();

/// What the monitor task keeps besides the monitor itself.
struct Run {
    tally: Tally,
    next_seq: u32,
    /// A heartbeat every this many samples (one second of signal).
    heartbeat_every: u64,
    next_heartbeat: u64,
    /// Ticks spent in the pipeline: since the last heartbeat, and in all.
    busy_window: u64,
    busy_total: u64,
    window_start: Instant,
    started: Instant,
    impacts_dropped: u32,
}

impl Run {
    fn new(rate_hz: f32) -> Self {
        let every = if rate_hz >= 1.0 { rate_hz as u64 } else { 1 };
        let now = Instant::now();
        Self {
            tally: Tally::new(),
            next_seq: 0,
            heartbeat_every: every,
            next_heartbeat: every,
            busy_window: 0,
            busy_total: 0,
            window_start: now,
            started: now,
            impacts_dropped: 0,
        }
    }

    /// Counts block `seq` and its samples.
    fn count(&mut self, seq: u32, samples: &[i16]) {
        let tally = &mut self.tally;
        // A gap in the sequence numbers is blocks lost between the source and here.
        tally.blocks_missing = tally
            .blocks_missing
            .wrapping_add(seq.wrapping_sub(self.next_seq));
        self.next_seq = seq.wrapping_add(1);
        tally.blocks = tally.blocks.wrapping_add(1);
        tally.samples += samples.len() as u64;
        // The core's stride statistics (SIMD on the Cortex-M4), a stride at a time.
        for stride in samples.chunks(impact_core::signal::baseline::STRIDE) {
            let s = impact_core::signal::baseline::Stats::of(stride);
            tally.min = tally.min.min(s.min);
            tally.max = tally.max.max(s.max);
            tally.sum = tally.sum.wrapping_add(i64::from(s.sum));
        }
    }

    fn busy(&mut self, since: Instant) {
        let ticks = Instant::now().saturating_duration_since(since).as_ticks();
        self.busy_window += ticks;
        self.busy_total += ticks;
    }

    fn heartbeat(&self, counters: Counters, m: &FwMonitor, busy_permille: u32) -> Heartbeat {
        Heartbeat {
            tally: self.tally,
            counters,
            rate_hz: m.scene().calibration.sample_rate_hz,
            busy_permille,
            armed: m.is_armed(),
            in_impact: m.in_impact(),
            impacts_dropped: self.impacts_dropped,
        }
    }

    /// The heartbeat due after this block, if any (it restarts the busy window).
    fn due_heartbeat(&mut self, m: &FwMonitor) -> Option<Heartbeat> {
        let counters = m.counters();
        if counters.samples < self.next_heartbeat {
            return None;
        }
        self.next_heartbeat = counters.samples + self.heartbeat_every;
        let now = Instant::now();
        let elapsed = now.saturating_duration_since(self.window_start).as_ticks();
        let busy = permille(self.busy_window, elapsed);
        self.busy_window = 0;
        self.window_start = now;
        Some(self.heartbeat(counters, m, busy))
    }

    fn summary(&self, m: &FwMonitor) -> Heartbeat {
        let elapsed = Instant::now()
            .saturating_duration_since(self.started)
            .as_ticks();
        self.heartbeat(m.counters(), m, permille(self.busy_total, elapsed))
    }
}

fn permille(part: u64, whole: u64) -> u32 {
    part.saturating_mul(1000)
        .checked_div(whole)
        .map_or(0, |p| p.min(1000) as u32)
}

/// Queues the impacts one block finished; waits for room, so that none is lost while the
/// reporter catches up (it only formats a defmt frame).
async fn forward(pending: &mut heapless::Vec<ImpactReport, IMPACTS_PER_BLOCK>) {
    for r in pending.iter() {
        REPORTS.send(Report::Impact(*r)).await;
    }
    pending.clear();
}

/// Runs the pipeline over the blocks until the source ends, reporting through [`REPORTS`].
#[embassy_executor::task]
pub async fn monitor(scene: Scene, mut samples: SampleReceiver) {
    // Built at compile time into its static: the buffers are far too big for the stack, and
    // `Monitor::new` would build the monitor on the stack and move it.
    static MONITOR: ConstStaticCell<FwMonitor> = ConstStaticCell::new(FwMonitor::unconfigured());
    let mut run = Run::new(scene.calibration.sample_rate_hz);
    let Some(m) = MONITOR.try_take() else {
        error!("monitor: started twice");
        return;
    };
    if let Err(e) = m.configure(scene) {
        error!("monitor: scene rejected: {}", e);
        let last = run.summary(m);
        REPORTS
            .send(Report::End {
                last,
                end: StreamEnd::Failed,
            })
            .await;
        return;
    }
    crate::scene::log(m.scene());

    let mut pending = heapless::Vec::<ImpactReport, IMPACTS_PER_BLOCK>::new();
    loop {
        if let Some(v0) = APPROACH_SPEED.try_take() {
            m.set_approach_speed(Some(v0));
        }
        // The block is read in its queue slot, which goes back to the source as soon as
        // the pipeline has seen it.
        let end = match samples.receive().await {
            SourceEvent::Block(block) => {
                let samples = block.samples();
                run.count(block.seq, samples);
                let since = Instant::now();
                let mut dropped = 0u32;
                m.push_block(samples, &mut |r: &ImpactReport| {
                    if pending.push(*r).is_err() {
                        dropped += 1;
                    }
                });
                run.busy(since);
                (None, dropped)
            }
            SourceEvent::End(end) => (Some(*end), 0),
        };
        samples.receive_done();
        match end {
            (None, dropped) => {
                if dropped > 0 {
                    run.impacts_dropped = run.impacts_dropped.saturating_add(dropped);
                    error!(
                        "monitor: {} impact reports dropped (too many in one block)",
                        dropped
                    );
                }
                forward(&mut pending).await;
                if let Some(h) = run.due_heartbeat(m) {
                    // Heartbeats may be dropped if the reporter falls behind (counted); impact
                    // reports and the summary never are.
                    if REPORTS.try_send(Report::Heartbeat(h)).is_err() {
                        super::reporter::count_dropped_heartbeat();
                    }
                }
            }
            (Some(end), _) => {
                let since = Instant::now();
                let mut dropped = 0u32;
                m.finish(&mut |r: &ImpactReport| {
                    if pending.push(*r).is_err() {
                        dropped += 1;
                    }
                });
                run.busy(since);
                run.impacts_dropped = run.impacts_dropped.saturating_add(dropped);
                forward(&mut pending).await;
                let last = run.summary(m);
                REPORTS.send(Report::End { last, end }).await;
                return;
            }
        }
    }
}
