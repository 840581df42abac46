//! The per-impact analysis of a finished capture: width at half maximum (on the filtered
//! signal if the scene asks for a filter), and, when the approach speed is known, the
//! kinematics (crush time, deformations, COR) and the model fits. Runs once per impact,
//! wherever the capture was handed (inline on the host, in a low-priority task on the
//! firmware), in one integer pass over the capture ([`motion`]) plus the fits over a
//! few thousand points: no per-sample floating point unless a CFC filter is asked for.

use crate::capture::Capture;
#[cfg(feature = "fit")]
pub mod jump;
pub mod motion;
pub mod target;

use crate::report::motion::{motion_deviation, Frame};
use crate::report::{self, Analysis, Flags, ImpactReport, Status};
use crate::scene::Scene;
use crate::signal::baseline::Deviation;
use motion::PointsOut;

/// Points the fits see at most: a contact of 12 600 samples (the seed bench at 500 kS/s) is
/// thinned to every 6th sample, which moves no fitted value beyond its noise.
pub const MAX_FIT_POINTS: usize = 2048;

/// Scratch memory of the analysis (f32): the filtered acceleration of a capture when the
/// scene asks for a CFC, then the fit points (deformation, velocity, force, `ln x`).
/// `Workspace::new()` is all zeros, so a `static` one starts in `.bss`.
pub struct Workspace<const CAP: usize> {
    buf: [f32; CAP],
    /// The spectra's block statistics and marks, and the scene's band frequencies.
    spectrum: crate::signal::spectrum::Scratch,
}

impl<const CAP: usize> Default for Workspace<CAP> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const CAP: usize> Workspace<CAP> {
    /// Captures longer than [`motion::MAX_SAMPLES`] would overflow the exact sums.
    const CHECK: () = assert!(
        CAP <= motion::MAX_SAMPLES,
        "capture too long for the exact sums"
    );

    pub const fn new() -> Self {
        #[allow(clippy::let_unit_value)]
        let _ = Self::CHECK;
        Self {
            buf: [0.0; CAP],
            spectrum: crate::signal::spectrum::Scratch::new(),
        }
    }

    /// Makes what depends on `scene` alone before its first impact (the spectra's band
    /// frequencies at its rate: [`crate::signal::spectrum::Scratch::prepare`]). An analysis
    /// without it makes them at its first impact, with the same values.
    pub fn prepare(&mut self, scene: &Scene) {
        if let Some(settings) = &scene.spectrum {
            self.spectrum
                .prepare(settings, scene.calibration.sample_rate_hz);
        }
    }
}

/// Where `|a|` crosses `level` between samples `i` and `i + 1` (fractional sample index).
fn crossing(i: usize, y0: f32, y1: f32, level: f32) -> f32 {
    let dy = y1 - y0;
    let f = if dy == 0.0 {
        0.0
    } else {
        ((level - y0) / dy).clamp(0.0, 1.0)
    };
    i as f32 + f
}

/// Width at half of `|a(peak)|`, samples, for a window of `len` samples with `|a(i)|` given:
/// from the last sample below half before the peak to the first after it, both interpolated;
/// `None` if either side lies outside the window.
fn fwhm(len: usize, abs: impl Fn(usize) -> f32, peak: usize) -> Option<f32> {
    if peak >= len {
        return None;
    }
    let half = abs(peak) / 2.0;
    let before = (0..peak).rev().find(|&i| abs(i) < half)?;
    let left = crossing(before, abs(before), abs(before + 1), half);
    let after = (peak + 1..len).find(|&i| abs(i) < half)?;
    let right = crossing(after - 1, abs(after - 1), abs(after), half);
    Some(right - left)
}

/// Width at half of `|d(peak)|`, samples, on the raw samples (`d = W x - S`): the samples
/// below half are found by integers (`2 |d| < |d_peak|`), the two crossings interpolated in
/// `|a| = |d| per_count`; `None` if either side lies outside the capture.
fn fwhm_raw(samples: &[i16], dev: Deviation, per_count: f32, peak: usize) -> Option<f32> {
    // |d| < 2^28: twice it fits in u32.
    let d_abs = |x: i16| dev.of(x).unsigned_abs();
    let top = d_abs(*samples.get(peak)?);
    let below = |x: &i16| 2 * d_abs(*x) < top;
    let a = |i: usize| samples.get(i).map_or(0.0, |&x| d_abs(x) as f32 * per_count);
    let half = top as f32 * per_count / 2.0;
    let before = samples.get(..peak)?.iter().rposition(below)?;
    let after = peak + 1 + samples.get(peak + 1..)?.iter().position(below)?;
    let left = crossing(before, a(before), a(before + 1), half);
    let right = crossing(after - 1, a(after - 1), a(after), half);
    Some(right - left)
}

/// Values of a decimated capture a width at half maximum must span to be reported: its two
/// crossings, each within half a value of the samples', move it by at most 1/32 of itself.
pub const RESOLVED_WIDTH: f32 = 32.0;

/// A width of `w` values at `step` samples each is resolved: any width on every sample, at
/// least [`RESOLVED_WIDTH`] values on a decimated capture.
fn resolved(w: f32, step: u32) -> bool {
    step == 1 || w >= RESOLVED_WIDTH
}

/// The rate of a capture's values, Hz: the scene's, over a decimated capture's step.
fn value_rate<const CAP: usize>(capture: &Capture<CAP>, scene: &Scene) -> f32 {
    scene.calibration.sample_rate_hz / capture.step() as f32
}

/// The first sample of largest `|a|` (index and value); `(0, 0)` if every sample is 0.
fn scan_peak(a: &[f32]) -> (usize, f32) {
    a.iter().enumerate().fold((0, 0.0f32), |best, (i, &v)| {
        if libm::fabsf(v) > libm::fabsf(best.1) {
            (i, v)
        } else {
            best
        }
    })
}

/// Samples before the onset a spectrum's window starts with (the pulse's lead-in).
pub const SPECTRUM_LEAD: u64 = 64;

/// Analyses a finished capture: the streaming fields of its summary, and the analysis fields;
/// the shock spectra last (they reuse the workspace).
pub fn analyse<const CAP: usize>(
    capture: &Capture<CAP>,
    scene: &Scene,
    work: &mut Workspace<CAP>,
) -> ImpactReport {
    let mut r = analyse_kinematics(capture, capture.summary(), scene, work);
    if let Some(settings) = scene.spectrum {
        r.spectrum = spectrum(capture, scene, &settings, work);
    }
    if let Some(spec) = scene.spec {
        r.verdict = Some(verdict(capture, scene, &spec, &r, work));
    }
    r
}

/// The impact judged against the scene's specified pulse ([`crate::spec::verdict`]) on every
/// sample the capture holds (its padding around the window included), in m/s² above the
/// baseline in the direction of the impact's peak. A decimated capture is judged at its step
/// (each value at the middle of its group), where the nominal duration spans enough of them.
#[inline(never)]
fn verdict<const CAP: usize>(
    capture: &Capture<CAP>,
    scene: &Scene,
    spec: &crate::spec::Spec,
    r: &ImpactReport,
    work: &mut Workspace<CAP>,
) -> Result<crate::spec::verdict::Verdict, crate::spec::verdict::Missing> {
    use crate::spec::verdict::judge_in;
    // The verdict's tables in the workspace (the spectra are done with it).
    let scratch = &mut work.buf[..];
    let s = capture.summary();
    let samples = capture.held();
    let first = capture.held_from();
    let per_count = report::per_count(scene, s.base_n);
    let deviation = Deviation::new(s.base_sum, s.base_n);
    let sign = if r.peak_acceleration_m_s2 < 0.0 {
        -1.0
    } else {
        1.0
    };
    let rate = scene.calibration.sample_rate_hz;
    let step = capture.step();
    // Stream indices, or (decimated) the capture's values, each at the middle of its group
    // (`Capture::value_time`).
    let a = Held {
        samples,
        offset: if step == 1 { first } else { 0 },
        deviation,
        per_count,
        sign,
    };
    if step == 1 {
        return judge_in(a, rate, spec, s.peak_index, scratch);
    }
    let peak = s.peak_index.saturating_sub(first) / u64::from(step);
    let mut v = judge_in(a, value_rate(capture, scene), spec, peak, scratch)?;
    let shift = capture.value_time(0.0) / f64::from(rate);
    v.start_s += shift;
    v.worst_s += shift;
    Ok(v)
}

/// The capture's values as a verdict reads them, in m/s² in the pulse's direction: value
/// `k` at index `offset + k` (a stream index, or a decimated capture's value index).
struct Held<'a> {
    samples: &'a [i16],
    offset: u64,
    deviation: Deviation,
    per_count: f32,
    sign: f32,
}

impl Held<'_> {
    fn value(&self, x: i16) -> f32 {
        self.sign * self.deviation.of(x) as f32 * self.per_count
    }
}

impl crate::spec::record::Record for Held<'_> {
    fn at(&self, i: u64) -> Option<f32> {
        let k = usize::try_from(i.checked_sub(self.offset)?).ok()?;
        Some(self.value(*self.samples.get(k)?))
    }

    /// The capture holds its values in one piece: a run is a slice of them, converted.
    fn run(&self, from: u64, out: &mut [f32]) -> bool {
        let k = from
            .checked_sub(self.offset)
            .and_then(|k| usize::try_from(k).ok());
        let Some(src) = k.and_then(|k| self.samples.get(k..k.checked_add(out.len())?)) else {
            return false;
        };
        for (o, &x) in out.iter_mut().zip(src) {
            *o = self.value(x);
        }
        true
    }
}

/// The window from [`SPECTRUM_LEAD`] samples before the onset to the end of the capture, in
/// m/s² above the baseline, and its spectra (their scratch in the workspace, not on the
/// stack). Not inlined: its frame stays out of the kinematics'.
#[inline(never)]
fn spectrum<const CAP: usize>(
    capture: &Capture<CAP>,
    scene: &Scene,
    settings: &crate::signal::spectrum::SpectrumSettings,
    work: &mut Workspace<CAP>,
) -> Option<crate::signal::spectrum::Spectrum> {
    let s = capture.summary();
    let samples = capture.samples();
    let per_count = report::per_count(scene, s.base_n);
    let deviation = Deviation::new(s.base_sum, s.base_n);
    // (In the capture's values: a decimated capture's are `step` samples apart.)
    let step = u64::from(capture.step());
    let onset = capture.window_value_at(s.onset_index).unwrap_or(0);
    // (The lead-in in samples: as many values as cover them.)
    let skip = onset.saturating_sub(SPECTRUM_LEAD.div_ceil(step) as usize);
    let from = capture.window_from() + skip as u64 * step;
    let window = samples.get(skip..)?;
    // The whole workspace: the room beyond the window holds the decimated levels' copies.
    let Workspace { buf, spectrum } = work;
    let len = window.len().min(buf.len());
    for (slot, &x) in buf.iter_mut().zip(window) {
        *slot = deviation.of(x) as f32 * per_count;
    }
    let mut sp = crate::signal::spectrum::spectrum(
        buf,
        len,
        value_rate(capture, scene),
        settings,
        spectrum,
    )?;
    sp.from_sample = from;
    sp.to_sample = from + window.len() as u64 * step;
    Some(sp)
}

/// The acceleration of everything the capture holds filtered by the scene's window filter
/// (a CFC or the low-pass), into the workspace, and its peak within the impact's window
/// (index in the workspace, value); `None` if the filter has too little signal to settle on
/// either side of the contact (its padding: SAE J211's for a CFC) or cannot run at this rate.
///
/// Before the contact the padding is the lead-in the capture holds, or the start of the
/// recording: there the filter starts at rest on the first sample, as a filter run over the
/// whole record does. After it, the capture's tail.
#[cfg(feature = "cfc")]
fn filter<const CAP: usize>(
    capture: &Capture<CAP>,
    scene: &Scene,
    kind: crate::signal::window_filter::WindowFilter,
    work: &mut Workspace<CAP>,
) -> Option<(usize, f32)> {
    let s = capture.summary();
    let held = capture.held();
    // (In the capture's values: a decimated capture's are `step` samples apart.)
    let step = u64::from(capture.step());
    let rate = value_rate(capture, scene);
    let pad = kind.padding_samples(rate) as u64;
    let held_from = capture.held_from();
    let before = s.onset_index.saturating_sub(held_from) / step;
    let contact_end = s.separation_index.unwrap_or(s.end_index);
    let after = (held.len() as u64).saturating_sub(contact_end.saturating_sub(held_from) / step);
    let from_start = held_from == 0 && !s.cut_at_start;
    if (before < pad && !from_start) || after < pad {
        return None;
    }
    let b = kind.design(rate as f64)?;
    let a = work.buf.get_mut(..held.len())?;
    let per_count = report::per_count(scene, s.base_n);
    let deviation = Deviation::new(s.base_sum, s.base_n);
    for (slot, &x) in a.iter_mut().zip(held) {
        *slot = deviation.of(x) as f32 * per_count;
    }
    b.phaseless_f32(a);
    let lead = capture.window_lead();
    let window = a.get(lead..lead + capture.samples().len()).unwrap_or(&[]);
    let (i, v) = scan_peak(window);
    Some((lead + i, v))
}

/// A decimated capture's window as a recording at the coarser rate: value `k` of
/// [`Capture::samples`] at instant `k`, the middle of its group of `step` samples (each
/// standing for its group's interval, so the pass's sums are the samples' sums). Touch and
/// separation are carried over to that time line; the stream's online record is kept (its
/// kinematics are every sample's).
fn coarse<const CAP: usize>(
    capture: &Capture<CAP>,
    s: &crate::capture::Summary,
    scene: &Scene,
) -> (crate::capture::Summary, Scene) {
    // Stream time `t` on the window's values' time line (value 0 at instant 0).
    let lead = capture.window_lead();
    let origin = capture.value_time(lead as f64);
    let at = |t: f64| (t - origin) / f64::from(capture.step());
    let touch = at(s.onset_index as f64 + f64::from(s.touch_offset));
    let onset = libm::ceil(touch).max(0.0);
    let mut c = *s;
    c.first_index = 0;
    c.filter_lead = lead as u32;
    c.onset_index = onset as u64;
    c.touch_offset = (touch - onset) as f32;
    c.touch_reach = s.touch_reach / capture.step() as f32;
    if let Some(i) = s.separation_index {
        // The first quiet sample's instant, and the zero relative to it (as on every sample:
        // the frame keeps a separation past the capture's end within it).
        let separation = at(i as f64 + f64::from(s.separation_offset));
        let first_quiet = libm::ceil(at(i as f64)).max(onset);
        c.separation_index = Some(first_quiet as u64);
        c.separation_offset = (separation - first_quiet) as f32;
    }
    c.end_index = capture.samples().len() as u64;
    c.peak_index = capture.window_value_at(s.peak_index).unwrap_or(0) as u64;
    let mut coarse = *scene;
    coarse.calibration.sample_rate_hz = value_rate(capture, scene);
    (c, coarse)
}

/// A contact's samples from the integration's first, the kinematics' deviation and frame.
#[cfg(feature = "fit")]
struct Jump<'a> {
    samples: &'a [i16],
    motion: Deviation,
    frame: &'a Frame,
}

/// Places first touch where the force jumped at it from the compression's law
/// ([`jump::shift`]) and moves the report's start, duration, Δv and kinematics (`found`
/// with them) by it, and the fit points (the first `x.len()` of `points`). Where the
/// compression's fit ran and refused a jump's law, a line's zero the touch stood on is a
/// ramp's: the kinematics without the jump's reach ([`crate::capture::Summary::touch_reach`]). Not inlined: its frame stays out of the
/// analysis task's.
#[cfg(feature = "fit")]
#[inline(never)]
fn place_jump(
    r: &mut ImpactReport,
    scene: &Scene,
    s: &crate::capture::Summary,
    jump: Jump<'_>,
    found: &mut report::motion::Found,
    points: PointsOut<'_>,
) {
    let Jump {
        samples,
        motion,
        frame,
    } = jump;
    // Gravity's shift of the kinematics' deviation, exactly as it was taken off.
    let g_d = i64::from(Deviation::new(s.base_sum, s.base_n).of(0)) - i64::from(motion.of(0));
    let shift = match jump::shift(samples, motion, g_d, frame, found) {
        Ok(shift) => shift,
        // (A line's zero in the interval before the onset, not its middle: the fit ran from
        // there. A zero before it, where the capture starts at the onset, it did not place.)
        Err(jump::Unplaced::NotThisLaw)
            if s.touch_offset != crate::signal::power_flank::JUMP_MIDDLE
                && s.touch_offset > -1.0 =>
        {
            let mut ramp = *frame;
            ramp.touch_reach = 0.0;
            r.kinematics = None;
            report::motion::kinematics(r, scene, &ramp, found);
            return;
        }
        Err(_) => return,
    };
    let mut moved = *frame;
    let dv = shift.apply(&mut moved, found);
    // (Placed: the law's touch.)
    moved.touch_reach = 0.0;
    let dt = frame.scale.dt;
    r.start_s -= shift.s * dt;
    r.duration_s += (shift.s * dt) as f32;
    r.delta_v_m_s = r.delta_v_m_s.map(|v| v + dv as f32);
    r.kinematics = None;
    report::motion::kinematics(r, scene, &moved, found);
    for (i, (x, v)) in points.x.iter_mut().zip(points.v.iter_mut()).enumerate() {
        // (Point i: the state after sample every i, at time every i + ½.)
        let (dx, dv) = shift.at(frame, (points.every * i) as f64 + 0.5);
        *x += dx as f32;
        *v += (dv / frame.scale.v0) as f32;
    }
}

/// The analysis with the kinematics from the pass over the capture alone, the stream's
/// online sums left out: what the two are held to (they give the same bits wherever the
/// capture holds the contact at every sample; `host-tests/tests/online.rs`; on a decimated
/// capture the pass runs on the coarser values and agrees to their step). No spectra, no
/// verdict.
#[doc(hidden)]
pub fn analyse_by_pass<const CAP: usize>(
    capture: &Capture<CAP>,
    scene: &Scene,
    work: &mut Workspace<CAP>,
) -> ImpactReport {
    let mut s = *capture.summary();
    s.motion = report::motion::Record::NONE;
    analyse_kinematics(capture, &s, scene, work)
}

/// Everything but the spectra, for the capture's summary `s`. Not inlined: its frame is
/// gone before the spectra's and the verdict's. Against a target ([`Scene::target`]) the
/// kinematics are the contact's ([`target`]) or none: where the capture cannot give them
/// (it does not hold the whole contact), the impactor's own are no answer
/// ([`Flags::KINEMATICS_NOT_HELD`]).
#[inline(never)]
fn analyse_kinematics<const CAP: usize>(
    capture: &Capture<CAP>,
    s: &crate::capture::Summary,
    scene: &Scene,
    work: &mut Workspace<CAP>,
) -> ImpactReport {
    let mut relative = false;
    let mut r = report::streaming(s, scene);
    analyse_contact(&mut r, capture, s, scene, work, &mut relative);
    if scene.target.is_some() && !relative {
        report::without_target_kinematics(&mut r, true);
    }
    r
}

/// [`analyse_kinematics`]' work; `relative` set where the kinematics were made the
/// contact's against the scene's target (or found to have no stop there). Inlined: one
/// frame, one report (the report is large: its spectrum).
#[inline(always)]
fn analyse_contact<const CAP: usize>(
    r: &mut ImpactReport,
    capture: &Capture<CAP>,
    s: &crate::capture::Summary,
    scene: &Scene,
    work: &mut Workspace<CAP>,
    relative: &mut bool,
) {
    r.analysis = Analysis::Full;
    let samples = capture.samples();
    let n = samples.len();
    // A decimated capture's values are `step` samples apart (`rate` is theirs).
    let step = capture.step();
    let rate = value_rate(capture, scene);
    if step > 1 {
        r.flags.insert(Flags::DECIMATED);
        r.decimation = step;
    }
    let per_count = report::per_count(scene, s.base_n);
    let deviation = Deviation::new(s.base_sum, s.base_n);
    let raw = |i: usize| samples.get(i).map_or(0, |&x| deviation.of(x));

    // With a CFC or the low-pass, the filtered acceleration of everything held (the filter's lead-in, the
    // window, its tail) in the workspace, and its peak in the window.
    let filter_lead = s.filter_lead as usize;
    let mut filtered: Option<(usize, f32)> = None;
    #[cfg(feature = "cfc")]
    if let Some(kind) = scene.window_filter() {
        filtered = filter(capture, scene, kind, work);
        if filtered.is_none() {
            r.flags.insert(Flags::CFC_WINDOW);
        }
    }
    // The filtered peak and its width, with a CFC or the low-pass.
    if let Some((i, v)) = filtered {
        let held = capture.held().len();
        let a = work.buf.get(..held).unwrap_or(&[]);
        let width = fwhm(held, |j| a.get(j).map_or(0.0, |v| libm::fabsf(*v)), i);
        if width.is_none() {
            r.flags.insert(Flags::FILTERED_HALF_MAXIMUM_OUTSIDE);
        }
        r.filtered_fwhm_s = width.filter(|&w| resolved(w, step)).map(|w| w / rate);
        r.filtered_peak_acceleration_m_s2 = Some(v);
    }
    // The raw peak's width, always: a filter never changes an unfiltered field. (The
    // stream's peak, if the capture holds it; else the captured part's own.)
    let (raw_i, raw_a) = match capture.window_value_at(s.peak_index) {
        Some(i) if i < n => (i, r.peak_acceleration_m_s2),
        _ => (0..n).fold((0, 0.0f32), |best, i| {
            let v = raw(i) as f32 * per_count;
            if libm::fabsf(v) > libm::fabsf(best.1) {
                (i, v)
            } else {
                best
            }
        }),
    };
    let raw_width = fwhm_raw(samples, deviation, per_count, raw_i);
    r.fwhm_s = raw_width.filter(|&w| resolved(w, step)).map(|w| w / rate);
    if raw_width.is_none() {
        r.flags.insert(Flags::HALF_MAXIMUM_OUTSIDE);
    }
    // A decimated capture: the pass below runs on its values as on a recording at the
    // coarser rate ([`coarse`]); the stream's own kinematics stay where it has them.
    let view;
    let (s, scene, filter_lead) = if step > 1 {
        view = coarse(capture, s, scene);
        (&view.0, &view.1, view.0.filter_lead as usize)
    } else {
        (s, scene, filter_lead)
    };
    // The fits scale by the peak of the signal they fit.
    let (_, peak_a) = filtered.unwrap_or((raw_i, raw_a));

    // The kinematics come from the stream's online sums ([`report::streaming`]); the fit
    // points, and the kinematics where those sums lost the crush or the separation, from a
    // pass over the capture when it holds the whole, unclipped impact (the same sums: the
    // two agree to the bit where both run on every sample, to the step on a decimated
    // capture, whose contact must then span `RESOLVED_WIDTH` values).
    let whole = s.status == Status::Complete && !(s.clipped || s.cut_at_start || s.in_previous);
    let resolves = |f: &Frame| step == 1 || f.separation - f.touch >= f64::from(RESOLVED_WIDTH);
    let Some(frame) = Frame::of(s, scene, Some(n)).filter(|f| whole && resolves(f)) else {
        return;
    };
    let from_stream = s.motion.get().ok();
    let Some(onset) = s.onset_index.checked_sub(s.first_index).map(|o| o as usize) else {
        return;
    };
    let motion = motion_deviation(s.base_sum, s.base_n, scene);
    let from_onset = samples.get(onset - frame.lead as usize..).unwrap_or(&[]);
    let contact = from_onset.len();

    // The fit points, if the scene asks for fits: `points` of each of force, velocity,
    // deformation and ln x in the workspace, one every `every` samples of the contact.
    let fit_mass = scene
        .mass_kg
        .filter(|_| cfg!(feature = "fit") && scene.fits.any());
    let fit_len = contact.min(libm::ceil(frame.separation) as usize);
    let every = fit_len.div_ceil(MAX_FIT_POINTS).max(1);
    let points = match fit_mass {
        Some(_) if r.kinematics.is_some() || from_stream.is_none() || scene.target.is_some() => {
            fit_len.div_ceil(every).min(work.buf.len() / 4)
        }
        _ => 0,
    };
    // (A jump's touch is placed from the pass's samples, fits or not.)
    // (The pass gives the kinematics where the stream's sums have none.)
    let jump = s.touch_jump
        && scene.target.is_none()
        && step == 1
        && (r.kinematics.is_some() || from_stream.is_none())
        && cfg!(feature = "fit");
    if points == 0 && from_stream.is_some() && !jump && scene.target.is_none() {
        return;
    }
    let f_peak = libm::fabsf(peak_a) * fit_mass.unwrap_or(0.0);
    if points > 0 {
        let f_scale = fit_mass.unwrap_or(0.0) / f_peak;
        // With a filter the filtered acceleration fills the workspace: point i reads sample
        // filter_lead + onset + i every >= i, so compacting it forwards in place overwrites
        // nothing unread.
        let start = onset - frame.lead as usize;
        for i in 0..points {
            let j = i * every;
            let a = if filtered.is_some() {
                work.buf
                    .get(filter_lead + start + j)
                    .copied()
                    .unwrap_or(0.0)
            } else {
                from_onset.get(j).map_or(0, |&x| deviation.of(x)) as f32 * per_count
            };
            if let Some(slot) = work.buf.get_mut(i) {
                *slot = a * f_scale;
            }
        }
    }
    let (force, rest) = work.buf.split_at_mut(points);
    let (velocity, rest) = rest.split_at_mut(points);
    let (deformation, ln_x) = rest.split_at_mut(points);
    // Against a target: the contact's kinematics from a pass of their own (the body's
    // verdicts replaced; the body's own pass not run), the fit points in the contact's frame.
    // (A target without the body's mass, which the scene refuses, takes the rigid path.)
    let x_max = if let (Some(t), Some(m1)) = (scene.target, scene.mass_kg) {
        *relative = true;
        let out = (points > 0).then_some(PointsOut {
            x: &mut *deformation,
            v: &mut *velocity,
            every,
        });
        let dev = target::Deviations {
            motion,
            force: deviation,
        };
        match target::contact(r, scene, &frame, from_onset, dev, &t, m1, out) {
            Some(x_max) => x_max,
            None => return,
        }
    } else {
        let out = (points > 0).then_some(PointsOut {
            x: &mut *deformation,
            v: &mut *velocity,
            every,
        });
        let mut passed = motion::integrate(from_onset, motion, &frame, out);
        // (A decimated capture's values are means: a step at the crush is the stream's to
        // place, on every sample.)
        if let Some((crush, _)) = passed.as_mut().filter(|_| step > 1) {
            crush.beside = None;
        }
        if from_stream.is_none() {
            // The pass holds what the online sums lost.
            let Some((crush, separation)) = passed else {
                r.flags.insert(Flags::NO_STOP);
                r.flags.remove(Flags::KINEMATICS_NOT_HELD);
                return;
            };
            r.flags.remove(Flags::NO_STOP);
            r.flags.remove(Flags::KINEMATICS_NOT_HELD);
            let found = frame.found(crush, separation);
            // A force that steps at the crush: Δv takes the area the sums missed, as the
            // stream's does where its sums found it (`s.motion` holds nothing here, so no step
            // is counted twice).
            if found.step_c != 0 {
                r.flags.remove(Flags::AC_COUPLED);
                r.delta_v_m_s = report::contact_delta_v(s, scene, found.step_c, &mut r.flags);
            }
            report::motion::kinematics(r, scene, &frame, &found);
        }
        if r.kinematics.is_none() {
            return;
        }
        // The maximum deformation in f64, from whichever sums gave the kinematics.
        let found = match from_stream {
            Some(found) => Some(found),
            None => passed.map(|(crush, separation)| frame.found(crush, separation)),
        };
        let (Some(mut found), Some(_)) = (found, passed) else {
            return;
        };
        // First touch in a jump's interval, from the contact's law: the kinematics and the fit
        // points move with it.
        #[cfg(feature = "fit")]
        if jump {
            let jump = Jump {
                samples: from_onset,
                motion,
                frame: &frame,
            };
            let points = PointsOut {
                x: &mut *deformation,
                v: &mut *velocity,
                every,
            };
            place_jump(r, scene, s, jump, &mut found, points);
        }

        found.x_max
    };

    #[cfg(feature = "fit")]
    // (Not where the compression is too short for `x_m`: [`Flags::UNDERSAMPLED`].)
    if let (Some(k), Some(x_m), true) = (
        r.kinematics,
        r.kinematics.and_then(|k| k.max_deformation_m),
        points > 0,
    ) {
        use crate::fit;
        // The points were integrated in metres: scale them by the maximum deformation.
        let inv_x = (1.0 / x_max) as f32;
        for x in deformation.iter_mut() {
            *x *= inv_x;
        }
        let p = fit::Points {
            x: deformation,
            v: velocity,
            f: force,
            x_m,
            v0: k.impact_velocity_m_s,
            f_peak,
        };
        let set = &scene.fits;
        let n = (!set.fit_exponent).then_some(set.nonlinear_exponent);
        // The restitution line once, for the set and the two-phase fit.
        let line = fit::restitution(&p);
        let pad_set = fit::set(&p, line);
        r.fits = crate::report::Fits {
            two_phase: set.two_phase.then(|| fit::two_phase(&p, line)).flatten(),
            nonlinear: set.nonlinear.then(|| fit::nonlinear(&p, n, ln_x)).flatten(),
            hertz: set.hertz.then(|| fit::hertz(&p)).flatten(),
        };
        if let Some(k) = r.kinematics.as_mut() {
            k.permanent_deformation_m = pad_set;
        }
    }
}
