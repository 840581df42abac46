//! What the figures draw from: the signal the pipeline analysed, each impact's window, and
//! its filtered trace (a CFC's or the low-pass's) by the analysis's own filter.

use impact_core::signal::window_filter::WindowFilter;
use impact_core::ImpactReport;

/// What the impact figure draws from: the signal the pipeline analysed (the counts times
/// the gain, so that `impact analyze` and `impact log` on the board's waveforms draw the
/// same), at the scene's rate.
pub struct Signal<'a> {
    /// Sample rate, Hz (the scene's, an `f32`).
    pub rate_hz: f64,
    /// The body's mass, kg, if known.
    pub mass_kg: Option<f64>,
    /// A force channel (`--units n`, a `force_n` column): the mass its values in N were
    /// divided by into m/s² (the body's, else 1 kg), by which the figure draws them in N.
    pub force_kg: Option<f64>,
    /// The recording's time of stream sample 0, s (a board's log: 0), for times said on the
    /// recording's clock.
    pub t0_s: f64,
    /// Acceleration of stream sample `i`, m/s² (`None` where it is not known).
    pub accel_m_s2: Box<dyn Fn(u64) -> Option<f64> + 'a>,
    /// The figure's title: what was drawn (file, channel, filter).
    pub title: String,
    /// The analysis's window filter (a CFC or the low-pass), if any, and the samples its
    /// capture held on either side of the contact (`Scene::padding_samples`): the filtered
    /// trace is drawn from the same samples.
    pub filter: Option<(WindowFilter, u64)>,
}

/// The samples the figure draws of impact `r` at `rate_hz`: from two before first touch to
/// four past separation, `(first, count)`.
pub fn window(r: &ImpactReport, rate_hz: f64) -> (u64, u64) {
    let start = ((r.start_s * rate_hz).floor().max(0.0) as u64).saturating_sub(2);
    let len = ((f64::from(r.duration_s) * rate_hz).ceil().max(0.0) as u64 + 4).max(4);
    (start, len)
}

/// The samples a capture held of impact `r` with `padding` samples on either side of its
/// contact (`Scene::padding_samples`): from `padding` before the onset to `padding` past
/// separation or the window's end, whichever is later, `(first, count)`.
fn held(r: &ImpactReport, rate_hz: f64, padding: u64) -> (u64, u64) {
    let first = r.start_sample.saturating_sub(padding);
    let separation = ((r.start_s + f64::from(r.duration_s)) * rate_hz)
        .floor()
        .max(0.0) as u64;
    let end = r.end_sample.max(separation.saturating_add(padding));
    (first, end.saturating_sub(first))
}

/// The samples a figure of impact `r` reads (for a recording read in passes, the last pass
/// keeps just these): its [`window`] and, with `padding` (`Scene::padding_samples`), the
/// samples its capture held, which its CFC-filtered trace and a specification's band are drawn
/// from, `(first, count)`.
pub fn read_window(r: &ImpactReport, rate_hz: f64, padding: u64) -> (u64, u64) {
    let (a, n) = window(r, rate_hz);
    if padding == 0 {
        return (a, n);
    }
    let (b, m) = held(r, rate_hz, padding);
    let first = a.min(b);
    (first, (a + n).max(b + m) - first)
}

/// Impact `r`'s acceleration above its baseline (m/s²) filtered by the analysis's window
/// filter, as the analysis filtered it: the same sections run forward and back in `f32`
/// (`Designed::phaseless_f32`) over the samples its capture held (from the start of the
/// recording, or to its end, where those come first), `(first sample, values)`. `None` without
/// a filter, when the analysis had no filtered peak (too little signal around the contact: the
/// report's `cfc_window` flag), or when the signal does not hold those samples (a board's
/// windows, which are the impact's window only).
pub fn filtered(signal: &Signal, r: &ImpactReport) -> Option<(u64, Vec<f64>)> {
    let (kind, padding) = signal.filter?;
    r.filtered_peak_acceleration_m_s2?;
    let section = kind.design(signal.rate_hz)?;
    let (first, n) = held(r, signal.rate_hz, padding);
    let base = f64::from(r.baseline_m_s2);
    let mut a: Vec<f32> = (first..first + n)
        .map_while(|i| (signal.accel_m_s2)(i).map(|v| (v - base) as f32))
        .collect();
    // The contact and one padding past it must be there (the recording may end sooner
    // than the window's end: the capture ended there too).
    let contact_end = ((r.start_s + f64::from(r.duration_s)) * signal.rate_hz).floor() as u64;
    if first + (a.len() as u64) < contact_end.saturating_add(padding).min(first + n) {
        return None;
    }
    section.phaseless_f32(&mut a);
    Some((first, a.into_iter().map(f64::from).collect()))
}
