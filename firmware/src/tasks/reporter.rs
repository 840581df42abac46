//! Reporter task (middle priority, beside the stream): logs the impacts (analysed ones from the analysis task,
//! skipped ones from the stream task, merged back into index order), the heartbeats and the
//! summary as defmt lines in a fixed, machine-parseable `name key=value ...` format
//! (documented in docs/board.md and parsed back by the host's `impact log` /
//! `impact emulate`), warns when reports stop coming, and hands the end of a finite stream to
//! the board (which, in the emulator, exits QEMU with the run's status).
//!
//! * `impact ...`: one line per impact, every field of [`ImpactReport`] and the report's
//!   latency;
//! * `heartbeat ...`: once per second of signal;
//! * `summary ...`: at the end of a finite stream (the emulator's replay).
//!
//! Floats go over the wire as their IEEE bits (`{=f32}`, `{=f64}`); the host's decoder prints
//! them as the shortest decimal that parses back to the same bits, so the host reads back
//! exactly the values the firmware computed.

use core::sync::atomic::{AtomicU32, Ordering};

use defmt::{error, info, warn};
use embassy_futures::select::{select3, Either3};
use embassy_time::{Duration, Instant, Timer};
use heapless::Vec;
use impact_core::{Approach, ImpactReport, Scene};

use impact_firmware::selftest::{Judge, Measured, Outcome, Played, Verdict};

use crate::queues::{FromStream, Heartbeat, StreamEnd, ANALYSED, FROM_STREAM};
use crate::source::sender::{SAMPLE_CLOCK, SOURCE_STATS};

/// Impacts held back while an earlier one is still being analysed (~1 KiB each: beyond, the
/// lowest goes out anyway and the broken order is counted, `reports_out_of_order`).
const REORDER_LEN: usize = 4;

/// Warn when no report has arrived for this long (heartbeats come once per second of signal).
const SILENCE_WARNING: Duration = Duration::from_secs(3);

static HEARTBEATS_DROPPED: AtomicU32 = AtomicU32::new(0);

/// Counts a heartbeat the monitor could not queue (the reporter was behind).
pub fn count_dropped_heartbeat() {
    HEARTBEATS_DROPPED.fetch_add(1, Ordering::Relaxed);
}

/// Prints impacts in index order: one that arrives before an earlier one (a skipped impact
/// overtaking one still in analysis) waits here. If the buffer fills, the lowest held one
/// goes out anyway and the broken order is counted.
struct Order {
    next: u32,
    held: Vec<ImpactReport, REORDER_LEN>,
    printed: u64,
    out_of_order: u32,
    /// The bring-up self-test's judge, when it runs.
    selftest: Option<Judge>,
}

impl Order {
    const fn new(selftest: Option<Judge>) -> Self {
        Self {
            next: 0,
            held: Vec::new(),
            printed: 0,
            out_of_order: 0,
            selftest,
        }
    }

    fn accept(&mut self, r: ImpactReport) {
        if r.index > self.next {
            if self.held.is_full() {
                self.release_lowest();
            }
            if self.held.push(r).is_ok() {
                self.flush();
                return;
            }
        } else if r.index < self.next {
            // Its successors went out while it was awaited.
            self.out_of_order = self.out_of_order.saturating_add(1);
        }
        self.print(&r);
        self.flush();
    }

    fn print(&mut self, r: &ImpactReport) {
        log_impact(r);
        if let Some(s) = &r.spectrum {
            log_spectrum(r.index, s);
        }
        if let Some(v) = &r.verdict {
            log_verdict(r.index, v);
        }
        if let Some(judge) = &mut self.selftest {
            selftest(judge, r);
        }
        self.printed += 1;
        if r.index >= self.next {
            self.next = r.index.wrapping_add(1);
        }
    }

    /// Prints the held impacts that are next in line.
    fn flush(&mut self) {
        while let Some(at) = self.held.iter().position(|h| h.index == self.next) {
            let r = self.held.swap_remove(at);
            self.print(&r);
        }
    }

    /// Gives up waiting for `next`: prints the lowest held impact.
    fn release_lowest(&mut self) {
        let lowest = self
            .held
            .iter()
            .enumerate()
            .min_by_key(|(_, h)| h.index)
            .map(|(i, _)| i);
        if let Some(at) = lowest {
            let r = self.held.swap_remove(at);
            self.out_of_order = self.out_of_order.saturating_add(1);
            self.print(&r);
            self.flush();
        }
    }

    /// Prints everything held.
    fn drain(&mut self) {
        while !self.held.is_empty() {
            self.release_lowest();
        }
    }
}

/// Logs reports until the end of the stream, then tells the board how it went; judges each
/// against the pulse the self-test played when `selftest` is given.
#[embassy_executor::task]
pub async fn reporter(end_of_stream: fn(bool) -> !, selftest: Option<Played>) {
    let started = Instant::now();
    let mut order = Order::new(selftest.map(Judge::new));
    let mut end: Option<(Heartbeat, StreamEnd)> = None;
    let success = loop {
        if let Some((last, stream_end)) = end {
            // Every impact the stream saw has been printed (or its report was dropped).
            if order.printed + u64::from(last.reports_dropped) >= last.counters.impacts {
                order.drain();
                if let Some(v) = order.selftest.as_mut().and_then(Judge::at_end) {
                    log_selftest_verdict(&v);
                }
                let elapsed = started.elapsed().as_millis();
                break summarize(&last, stream_end, order.out_of_order, elapsed);
            }
        }
        match select3(
            ANALYSED.receive(),
            FROM_STREAM.receive(),
            Timer::after(SILENCE_WARNING),
        )
        .await
        {
            Either3::First(r) | Either3::Second(FromStream::Skipped(r)) => order.accept(r),
            Either3::Second(FromStream::Heartbeat(h)) => {
                log_heartbeat(&h);
                // The self-test's pulses that never came (no jumper, a dead DAC) fail it by
                // its deadline: a board's stream never ends to say so.
                let samples = h.counters.samples;
                if let Some(v) = order.selftest.as_mut().and_then(|j| j.deadline(samples)) {
                    log_selftest_verdict(&v);
                }
            }
            Either3::Second(FromStream::End { last, end: e }) => end = Some((last, e)),
            // Nothing for a while: what is held goes out (an analysis is taking long).
            Either3::Third(()) if !order.held.is_empty() => order.drain(),
            Either3::Third(()) => warn!(
                "no report for {} ms; source: {}",
                SILENCE_WARNING.as_millis(),
                SOURCE_STATS.snapshot()
            ),
        }
    };
    end_of_stream(success);
}

/// The `impact` line: every field of the report, in its order, kinematics and fits
/// flattened under the names of `impact analyze --csv`; `none` for an absent value; then the
/// time from the end of the impact's hold to now (`none` unless the source runs in real
/// time).
fn log_impact(r: &ImpactReport) {
    let k = r.kinematics;
    let tp = r.fits.two_phase;
    let nl = r.fits.nonlinear;
    let hz = r.fits.hertz;
    let b = r.bounce;
    info!(
        "impact seq={=u32} index={=u32} status={=str} analysis={=str} clipped={=bool} flags={=u16} start_sample={=u64} end_sample={=u64} start_s={=f64} peak_time_s={=f64} peak_acceleration_m_s2={=f32} peak_force_n={} delta_v_m_s={} duration_s={=f32} baseline_m_s2={=f32} fwhm_s={} filtered_peak_acceleration_m_s2={} filtered_fwhm_s={} decimation={=u32} impact_velocity_m_s={} crush_time_s={} max_deformation_m={} rebound_velocity_m_s={} cor={} separation_deformation_m={} permanent_deformation_m={} absorbed_energy_j={} two_phase_kc_n_m={} two_phase_kr_n_m={} two_phase_c_n_s_m={} two_phase_permanent_deformation_m={} two_phase_residual={} nonlinear_k={} nonlinear_c_s_m={} nonlinear_exponent={} nonlinear_residual={} hertz_k={} hertz_residual={} bounce_number={} flight_s={} v0_flight_m_s={} v0_rebound_m_s={} landing_height_m={} report_latency_s={}",
        crate::logger::next_seq(),
        r.index,
        r.status.name(),
        r.analysis.name(),
        r.clipped,
        r.flags.0,
        r.start_sample,
        r.end_sample,
        r.start_s,
        r.peak_time_s,
        r.peak_acceleration_m_s2,
        Opt(r.peak_force_n),
        Opt(r.delta_v_m_s),
        r.duration_s,
        r.baseline_m_s2,
        Opt(r.fwhm_s),
        Opt(r.filtered_peak_acceleration_m_s2),
        Opt(r.filtered_fwhm_s),
        r.decimation,
        Opt(k.map(|k| k.impact_velocity_m_s)),
        Opt(k.and_then(|k| k.crush_time_s)),
        Opt(k.and_then(|k| k.max_deformation_m)),
        Opt(k.map(|k| k.rebound_velocity_m_s)),
        Opt(k.map(|k| k.cor)),
        Opt(k.and_then(|k| k.separation_deformation_m)),
        Opt(k.and_then(|k| k.permanent_deformation_m)),
        Opt(k.and_then(|k| k.absorbed_energy_j)),
        Opt(tp.map(|t| t.kc_n_m)),
        Opt(tp.map(|t| t.kr_n_m)),
        Opt(tp.map(|t| t.c_n_s_m)),
        Opt(tp.map(|t| t.permanent_m)),
        Opt(tp.map(|t| t.residual)),
        Opt(nl.map(|t| t.k)),
        Opt(nl.map(|t| t.c_s_m)),
        Opt(nl.map(|t| t.n)),
        Opt(nl.map(|t| t.residual)),
        Opt(hz.map(|t| t.k)),
        Opt(hz.map(|t| t.residual)),
        Opt(b.map(|b| b.number)),
        Opt(b.map(|b| b.flight_s)),
        Opt(b.map(|b| b.v0_flight_m_s)),
        Opt(b.and_then(|b| b.v0_rebound_m_s)),
        Opt(b.map(|b| b.landing_height_m)),
        Opt(SAMPLE_CLOCK.since_sample_s(r.end_sample)),
    );
}

/// The `srs` line after an impact's line when the scene asks for spectra: the bands' SRS and
/// PVSS as comma-separated lists (band `k` at `1000 × 2^(j/n)` Hz from `first_hz`).
fn log_spectrum(index: u32, s: &impact_core::report::Spectrum) {
    let n = usize::from(s.bands).min(s.srs_m_s2.len());
    info!(
        "srs seq={=u32} index={=u32} bands={=u8} first_hz={=f32} bands_per_octave={=u8} damping={=f32} from_sample={=u64} to_sample={=u64} half_sine_amplitude_m_s2={} half_sine_duration_s={} srs_m_s2={} pvss_m_s={}",
        crate::logger::next_seq(),
        index,
        s.bands,
        s.first_hz,
        s.bands_per_octave,
        s.damping,
        s.from_sample,
        s.to_sample,
        Opt(s.half_sine.map(|h| h.0)),
        Opt(s.half_sine.map(|h| h.1)),
        List(&s.srs_m_s2[..n]),
        List(&s.pvss_m_s[..n]),
    );
}

/// The `spec` line after an impact's line when the scene specifies a pulse: its verdict (times
/// in s from the stream's first sample), or why there is none.
fn log_verdict(
    index: u32,
    v: &Result<impact_core::spec::verdict::Verdict, impact_core::spec::verdict::Missing>,
) {
    match v {
        Ok(v) => info!(
            "spec seq={=u32} index={=u32} pass={=bool} band_pass={=bool} delta_v_pass={=bool} margin={=f32} worst_s={=f64} worst_m_s2={=f32} limit_m_s2={=f32} delta_v_m_s={=f32} start_s={=f64}",
            crate::logger::next_seq(),
            index,
            v.pass,
            v.band_pass,
            v.delta_v_pass,
            v.margin,
            v.worst_s,
            v.worst_m_s2,
            v.limit_m_s2,
            v.delta_v_m_s,
            v.start_s,
        ),
        Err(m) => info!(
            "spec seq={=u32} index={=u32} pass=none reason={=str}",
            crate::logger::next_seq(),
            index,
            m.name(),
        ),
    }
}

/// The self-test's judgement of one report: a `selftest` line for a judged pulse (measured
/// beside played), and the verdict after the last (docs/board.md, "Bring-up self-test").
fn selftest(judge: &mut Judge, r: &ImpactReport) {
    let measured = Measured {
        whole: r.status == impact_core::Status::Complete && !r.clipped,
        start_s: r.start_s,
        peak_m_s2: r.peak_acceleration_m_s2,
        fwhm_s: r.fwhm_s,
    };
    let Outcome::Judged(c, verdict) = judge.judge(measured) else {
        return;
    };
    let played = judge.played();
    info!(
        "selftest pulse={=u32} index={=u32} pass={=bool} status={=str} clipped={=bool} peak_m_s2={=f32} played_peak_m_s2={=f32} peak_pass={=bool} fwhm_s={} played_fwhm_s={=f32} fwhm_pass={=bool} rate_hz={} played_rate_hz={=f32} rate_pass={=bool} vdda_v={}",
        c.number,
        r.index,
        c.pass,
        r.status.name(),
        r.clipped,
        c.measured.peak_m_s2,
        played.peak_m_s2,
        c.peak_pass,
        Opt(c.measured.fwhm_s),
        played.fwhm_s,
        c.fwhm_pass,
        Opt(c.rate_hz),
        played.rate_hz,
        c.rate_pass,
        Opt(played.vdda_v),
    );
    if let Some(v) = verdict {
        log_selftest_verdict(&v);
    }
}

fn log_selftest_verdict(v: &Verdict) {
    info!(
        "selftest_result pass={=bool} passed={=u32} judged={=u32} pulses={=u32}",
        v.pass,
        v.passed,
        v.judged,
        impact_firmware::selftest::PULSES
    );
    let pulses = impact_firmware::selftest::PULSES;
    if v.pass {
        info!(
            "self-test PASS: {=u32} of {=u32} pulses as played",
            v.passed, v.judged
        );
    } else if v.judged < pulses {
        error!(
            "self-test FAIL: {=u32} of {=u32} pulses came ({=u32} as played): check the jumper from PA4 to PA1",
            v.judged,
            pulses,
            v.passed
        );
    } else {
        error!(
            "self-test FAIL: {=u32} of {=u32} pulses as played (see the selftest lines)",
            v.passed, pulses
        );
    }
}

/// Values separated by commas, no spaces (one `key=value` token).
struct List<'a>(&'a [f32]);

impl defmt::Format for List<'_> {
    fn format(&self, f: defmt::Formatter<'_>) {
        for (k, v) in self.0.iter().enumerate() {
            if k > 0 {
                defmt::write!(f, ",");
            }
            defmt::write!(f, "{=f32}", v);
        }
    }
}

/// Deepest stack use so far and the stack's size, bytes; an error line if it reached the
/// bottom of its region (one word more would have faulted).
fn stack() -> (u32, u32) {
    let size = crate::stack::size_bytes() as u32;
    match crate::stack::peak_bytes() {
        Some((peak, reached_bottom)) => {
            if reached_bottom {
                error!("stack overflow: the stack reached the bottom of its region");
            }
            (peak as u32, size)
        }
        None => (0, size),
    }
}

fn log_heartbeat(h: &Heartbeat) {
    let source = SOURCE_STATS.snapshot();
    let (stack_peak, stack_size) = stack();
    info!(
        "heartbeat seq={=u32} samples={=u64} rate_hz={=f32} blocks={=u32} busy_permille={=u32} overruns={=u32} blocks_lost={=u32} blocks_missing={=u32} samples_lost={=u64} gaps={=u64} source_errors={=u32} impacts={=u64} incomplete={=u64} analyses_skipped={=u64} level_changes={=u64} reports_dropped={=u32} heartbeats_dropped={=u32} lines_dropped={=u32} armed={=bool} in_impact={=bool} stack_peak_bytes={=u32} stack_size_bytes={=u32}",
        crate::logger::next_seq(),
        h.counters.samples,
        h.rate_hz,
        h.tally.blocks,
        h.busy_permille,
        source.overruns,
        source.blocks_lost,
        h.tally.blocks_missing,
        h.counters.samples_lost,
        h.counters.gaps,
        source.errors,
        h.counters.impacts,
        h.counters.incomplete,
        h.counters.analyses_skipped,
        h.counters.level_changes,
        h.reports_dropped,
        HEARTBEATS_DROPPED.load(Ordering::Relaxed),
        crate::logger::frames_dropped(),
        h.armed,
        h.in_impact,
        stack_peak,
        stack_size,
    );
}

/// Logs the `summary` line; returns whether the run succeeded.
fn summarize(h: &Heartbeat, end: StreamEnd, out_of_order: u32, elapsed_ms: u64) -> bool {
    let source = SOURCE_STATS.snapshot();
    let success = end == StreamEnd::Complete && source.errors == 0 && h.reports_dropped == 0;
    let end_name = match end {
        StreamEnd::Complete => "complete",
        StreamEnd::Failed => "failed",
    };
    // blocks_missing should equal blocks_lost (both count the same drops, one at each end of
    // the queue); both are shown so that a mismatch is visible.
    if h.counters.samples_lost > 0 || h.tally.blocks_missing > 0 {
        warn!("samples were lost (see samples_lost, gaps, blocks_lost, overruns)");
    }
    let (stack_peak, stack_size) = stack();
    info!(
        "summary seq={=u32} result={=str} end={=str} samples={=u64} rate_hz={=f32} blocks={=u32} impacts={=u64} incomplete={=u64} analyses_skipped={=u64} level_changes={=u64} min={=i16} max={=i16} sum={=i64} samples_lost={=u64} gaps={=u64} blocks_lost={=u32} blocks_missing={=u32} overruns={=u32} source_errors={=u32} reports_dropped={=u32} reports_out_of_order={=u32} heartbeats_dropped={=u32} lines_dropped={=u32} busy_permille={=u32} elapsed_ms={=u64} stack_peak_bytes={=u32} stack_size_bytes={=u32}",
        crate::logger::next_seq(),
        if success { "ok" } else { "failed" },
        end_name,
        h.counters.samples,
        h.rate_hz,
        h.tally.blocks,
        h.counters.impacts,
        h.counters.incomplete,
        h.counters.analyses_skipped,
        h.counters.level_changes,
        h.tally.min,
        h.tally.max,
        h.tally.sum,
        h.counters.samples_lost,
        h.counters.gaps,
        source.blocks_lost,
        h.tally.blocks_missing,
        source.overruns,
        source.errors,
        h.reports_dropped,
        out_of_order,
        HEARTBEATS_DROPPED.load(Ordering::Relaxed),
        crate::logger::frames_dropped(),
        h.busy_permille,
        elapsed_ms,
        stack_peak,
        stack_size
    );
    if !success {
        error!("run failed (see the summary)");
    }
    success
}

/// `none` or the value, for optional fields in the log lines.
pub struct Opt<T>(pub Option<T>);

impl defmt::Format for Opt<f32> {
    fn format(&self, f: defmt::Formatter<'_>) {
        match self.0 {
            Some(v) => defmt::write!(f, "{=f32}", v),
            None => defmt::write!(f, "none"),
        }
    }
}

impl defmt::Format for Opt<u32> {
    fn format(&self, f: defmt::Formatter<'_>) {
        match self.0 {
            Some(v) => defmt::write!(f, "{=u32}", v),
            None => defmt::write!(f, "none"),
        }
    }
}

/// Logs the scene in use as one `scene ...` line (the format is in docs/board.md).
pub fn log_scene(scene: &Scene) {
    let (v0, drop_height) = match scene.approach {
        Approach::Unknown => (None, None),
        Approach::Speed { v0_m_s } => (Some(v0_m_s), None),
        Approach::DropHeight { height_m } => (scene.v0_m_s(), Some(height_m)),
    };
    let fits = &scene.fits;
    // The pulse the board judges, whole: the host draws its band from this, not from its own
    // command line.
    let spec = scene.spec.as_ref();
    let t = spec.map(|s| s.tolerance);
    let (rise, fall) = match spec.map(|s| s.shape) {
        Some(impact_core::spec::Shape::Trapezoid { rise, fall }) => (Some(rise), Some(fall)),
        _ => (None, None),
    };
    let band = spec.and_then(|s| s.band);
    info!(
        "scene rate_hz={=f32} gain_m_s2_per_count={=f32} mass_kg={} v0_m_s={} drop_height_m={} trigger_m_s2={=f32} edge_m_s2={=f32} hold_s={=f32} max_impact_s={=f32} settle_s={=f32} clip_low={=i16} clip_high={=i16} cfc={} trigger_cfc={} lowpass_order={} lowpass_cutoff_hz={} two_phase={=bool} nonlinear={=bool} fit_exponent={=bool} exponent={=f32} hertz={=bool} train={=str} gravity_m_s2={} max_flight_s={} srs={=bool} wave_every={=u16} v0_every={=bool} spec={=str} spec_peak_m_s2={} spec_duration_s={} spec_band={} spec_outside={} spec_slack={} spec_dv={} spec_before={} spec_after={} spec_watch={} spec_rise={} spec_fall={} spec_band_u={} spec_band_lower={} spec_band_upper={} target_mass_kg={} target_stiffness_n_m={} target_damping_n_s_m={} target_space={}",
        scene.calibration.sample_rate_hz,
        scene.calibration.gain_m_s2_per_count,
        Opt(scene.mass_kg),
        Opt(v0),
        Opt(drop_height),
        scene.trigger_m_s2,
        scene.edge_m_s2,
        scene.hold_s,
        scene.max_impact_s,
        scene.settle_s,
        scene.clip_counts.0,
        scene.clip_counts.1,
        Opt(scene.cfc.map(|c| c.class())),
        Opt(scene.trigger_cfc.map(|c| c.class())),
        Opt(scene.lowpass.map(|l| u32::from(l.order))),
        Opt(scene.lowpass.map(|l| l.cutoff_hz)),
        fits.two_phase,
        fits.nonlinear,
        fits.fit_exponent,
        fits.nonlinear_exponent,
        fits.hertz,
        scene.train.map_or("none", |t| t.speed.name()),
        // Gravity in the contact: `none` for a horizontal strike.
        Opt(scene.contact_gravity_m_s2()),
        Opt(scene.train.map(|t| t.max_flight_s)),
        scene.spectrum.is_some(),
        scene.waveform_every,
        scene.v0_every,
        spec.map_or("none", |s| s.shape.name()),
        Opt(spec.map(|s| s.peak_m_s2)),
        Opt(spec.map(|s| s.duration_s)),
        Opt(t.map(|t| t.band)),
        Opt(t.map(|t| t.outside)),
        Opt(t.map(|t| t.slack)),
        Opt(t.map(|t| t.delta_v)),
        Opt(t.map(|t| t.before)),
        Opt(t.map(|t| t.after)),
        Opt(t.map(|t| t.watch)),
        Opt(rise),
        Opt(fall),
        BandColumn(band, |p| p.u),
        BandColumn(band, |p| p.lower),
        BandColumn(band, |p| p.upper),
        // The target the kinematics are relative to (`none`: a rigid, fixed barrier).
        Opt(scene.target.and_then(|t| t.spring_mass()).map(|t| t.mass_kg)),
        Opt(scene.target.and_then(|t| t.spring_mass()).map(|t| t.stiffness_n_m)),
        Opt(scene.target.and_then(|t| t.spring_mass()).map(|t| t.damping_n_s_m)),
        // Or a state space (`none` for a spring–mass or none).
        TargetSpace(scene.target.and_then(|t| t.state_space())),
    );
}

/// A state-space target as a comma-separated list: its order `n`, `A` row by row, `B`, `C`
/// (the displacement's row, then the velocity's); `none` without one.
struct TargetSpace(Option<&'static impact_core::two_body::Target<f32>>);

impl defmt::Format for TargetSpace {
    fn format(&self, f: defmt::Formatter<'_>) {
        let Some(t) = self.0 else {
            defmt::write!(f, "none");
            return;
        };
        let n = t.n.min(impact_core::two_body::MAX_STATES);
        defmt::write!(f, "{=u32}", n as u32);
        for v in t.entries() {
            defmt::write!(f, ",{=f32}", *v);
        }
    }
}

/// One column of a user's band as a comma-separated list (`none` without a band).
struct BandColumn(
    Option<&'static [impact_core::spec::BandPoint]>,
    fn(&impact_core::spec::BandPoint) -> f32,
);

impl defmt::Format for BandColumn {
    fn format(&self, f: defmt::Formatter<'_>) {
        match self.0 {
            None => defmt::write!(f, "none"),
            Some(rows) => {
                for (k, row) in rows.iter().enumerate() {
                    if k > 0 {
                        defmt::write!(f, ",");
                    }
                    defmt::write!(f, "{=f32}", (self.1)(row));
                }
            }
        }
    }
}
