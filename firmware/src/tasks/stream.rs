//! Stream task (middle priority): runs impact-core's streaming stage ([`impact_core::Stream`],
//! the same code as the host's `impact analyze`) over the sample blocks, captures each impact
//! into a free slot of the capture queue for the analysis task, and tells the reporter what it
//! reports itself: impacts that found no free slot, a heartbeat per second of signal, the end
//! of the stream. It never waits for the analysis or the reporter while samples come.

use defmt::error;
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::signal::Signal;
use embassy_time::Instant;
use impact_core::{Counters, ImpactReport, Scene, Sink, Stream};
use static_cell::ConstStaticCell;

use crate::queues::{
    CaptureSender, FromStream, FwCapture, Heartbeat, SampleReceiver, SourceEvent, StreamEnd, Tally,
    CAPTURE_LEN, FROM_STREAM, PRE_TRIGGER_LEN,
};

/// The firmware's streaming stage.
pub type FwStream = Stream<PRE_TRIGGER_LEN>;

/// A light gate (or anything else that measures the approach speed) signals it here, m/s; the
/// stream uses it from the next block on, for the impacts that end after it.
pub static APPROACH_SPEED: Signal<CriticalSectionRawMutex, f32> = Signal::new();

/// Whether the stream may wait for the analysis.
#[derive(Clone, Copy, PartialEq, Eq, defmt::Format)]
pub enum Backpressure {
    /// Never (a live source): an impact that finds no free capture slot is reported from its
    /// streaming fields alone.
    Never,
    /// Before each impact, wait for a free capture slot (the emulator's lossless replay:
    /// every impact analysed, as on the host).
    #[cfg_attr(not(feature = "emulator"), allow(dead_code))]
    WaitForCapture,
}

/// What the stream task keeps besides the stream itself.
struct Run {
    tally: Tally,
    next_seq: u32,
    /// A heartbeat every this many samples (one second of signal).
    heartbeat_every: u64,
    next_heartbeat: u64,
    /// Ticks spent in the streaming stage: since the last heartbeat, and in all.
    busy_window: u64,
    busy_total: u64,
    window_start: Instant,
    started: Instant,
    /// Skipped-impact reports that found the reporter's queue full.
    reports_dropped: u32,
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
            reports_dropped: 0,
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

    fn heartbeat(&self, s: &FwStream, busy_permille: u32) -> Heartbeat {
        Heartbeat {
            tally: self.tally,
            counters: s.counters(),
            rate_hz: s.scene().calibration.sample_rate_hz,
            busy_permille,
            armed: s.is_armed(),
            in_impact: s.in_impact(),
            reports_dropped: self.reports_dropped,
        }
    }

    /// The heartbeat due after this block, if any (it restarts the busy window).
    fn due_heartbeat(&mut self, s: &FwStream) -> Option<Heartbeat> {
        let counters: Counters = s.counters();
        if counters.samples < self.next_heartbeat {
            return None;
        }
        self.next_heartbeat = counters.samples + self.heartbeat_every;
        let now = Instant::now();
        let elapsed = now.saturating_duration_since(self.window_start).as_ticks();
        let busy = permille(self.busy_window, elapsed);
        self.busy_window = 0;
        self.window_start = now;
        Some(self.heartbeat(s, busy))
    }

    fn summary(&self, s: &FwStream) -> Heartbeat {
        let elapsed = Instant::now()
            .saturating_duration_since(self.started)
            .as_ticks();
        self.heartbeat(s, permille(self.busy_total, elapsed))
    }
}

fn permille(part: u64, whole: u64) -> u32 {
    part.saturating_mul(1000)
        .checked_div(whole)
        .map_or(0, |p| p.min(1000) as u32)
}

/// The stream's sink: capture slots from the queue to the analysis task; impacts without a
/// slot go straight to the reporter.
struct QueueSink<'a> {
    captures: &'a mut CaptureSender,
    reports_dropped: &'a mut u32,
}

impl Sink<CAPTURE_LEN> for QueueSink<'_> {
    fn buffer(&mut self) -> Option<&mut FwCapture> {
        self.captures.try_send()
    }

    fn captured(&mut self, _scene: &Scene) {
        self.captures.send_done();
    }

    fn skipped(&mut self, report: &ImpactReport) {
        if FROM_STREAM.try_send(FromStream::Skipped(*report)).is_err() {
            *self.reports_dropped = self.reports_dropped.saturating_add(1);
            error!(
                "impact {}: its report was dropped (the reporter is behind)",
                report.index
            );
        }
    }
}

/// Runs the streaming stage over the blocks until the source ends.
#[embassy_executor::task]
pub async fn stream(
    scene: Scene,
    backpressure: Backpressure,
    mut samples: SampleReceiver,
    mut captures: CaptureSender,
    feed_watchdog: fn(),
) {
    // A compile-time value in its static: the ring (8 KiB) is never built on the stack. (The
    // placeholder scene is not all zeros, so this one static is in `.data`.)
    static STREAM: ConstStaticCell<FwStream> = ConstStaticCell::new(FwStream::unconfigured());
    let mut run = Run::new(scene.calibration.sample_rate_hz);
    let Some(s) = STREAM.try_take() else {
        error!("stream: started twice");
        return;
    };
    if let Err(e) = s.configure_for(scene, CAPTURE_LEN) {
        error!("stream: scene rejected: {}", e);
        let last = run.summary(s);
        FROM_STREAM
            .send(FromStream::End {
                last,
                end: StreamEnd::Failed,
            })
            .await;
        return;
    }
    super::reporter::log_scene(s.scene());

    loop {
        if let Some(v0) = APPROACH_SPEED.try_take() {
            s.set_approach_speed(Some(v0));
        }
        // The block is read in its queue slot, which goes back to the source as soon as
        // the stream has seen it.
        let event = samples.receive().await;
        // Blocks keep coming: the firmware runs (the board's watchdog resets it otherwise).
        feed_watchdog();
        let since = Instant::now();
        let mut dropped = 0u32;
        let end = match event {
            SourceEvent::Block(block) => {
                run.count(block.seq, block.samples());
                let mut sink = QueueSink {
                    captures: &mut captures,
                    reports_dropped: &mut dropped,
                };
                if block.lost_before > 0 {
                    s.gap(u64::from(block.lost_before), &mut sink);
                }
                match backpressure {
                    Backpressure::Never => s.push_block(block.samples(), &mut sink),
                    Backpressure::WaitForCapture => {
                        // Up to each impact's end, then wait for a free slot for the next
                        // one (only the wait matters; the slot is taken when an impact
                        // starts): several impacts in one block are all analysed.
                        let mut rest = block.samples();
                        while !rest.is_empty() {
                            if !s.in_impact() {
                                let _ = captures.send().await;
                            }
                            let mut sink = QueueSink {
                                captures: &mut captures,
                                reports_dropped: &mut dropped,
                            };
                            let used = s.push_to_impact_end(rest, &mut sink);
                            rest = rest.get(used..).unwrap_or(&[]);
                        }
                    }
                }
                None
            }
            SourceEvent::End { end, lost } => {
                let mut sink = QueueSink {
                    captures: &mut captures,
                    reports_dropped: &mut dropped,
                };
                s.gap(u64::from(*lost), &mut sink);
                s.finish(&mut sink);
                Some(*end)
            }
        };
        samples.receive_done();
        run.busy(since);
        run.reports_dropped = run.reports_dropped.saturating_add(dropped);
        match end {
            None => {
                if let Some(h) = run.due_heartbeat(s) {
                    // Heartbeats may be dropped if the reporter falls behind (counted).
                    if FROM_STREAM.try_send(FromStream::Heartbeat(h)).is_err() {
                        super::reporter::count_dropped_heartbeat();
                    }
                }
            }
            Some(end) => {
                let last = run.summary(s);
                FROM_STREAM.send(FromStream::End { last, end }).await;
                return;
            }
        }
    }
}
