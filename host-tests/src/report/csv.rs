//! The analysis as CSV: one row per impact, the contract's fields first (`report::FIELDS`).

use std::borrow::Borrow;
use std::io::Write;

use super::fmt::number;
use super::{AnalysisJson, ImpactJson};

/// CSV text: one row per impact.
pub fn to_csv(a: &AnalysisJson) -> String {
    let mut out = Vec::new();
    // Writing to a Vec cannot fail.
    let _ = write_csv(a, a.impacts.iter(), &mut out);
    String::from_utf8_lossy(&out).into_owned()
}

/// The CSV of `a` with `impacts` (read twice: the columns, then the rows) in place of
/// `a.impacts`, written to `out` a row at a time.
pub fn write_csv<I>(a: &AnalysisJson, impacts: I, out: &mut impl Write) -> std::io::Result<()>
where
    I: Iterator + Clone,
    I::Item: Borrow<ImpactJson>,
{
    // The report's fields as the firmware's `impact` line names them (one list, in core).
    let mut s = impact_core::report::FIELDS.join(",");
    // With --train, the bounce columns; with --srs, the spectra's summary columns.
    let with_train = a.train_speed.is_some();
    if with_train {
        s.push(',');
        s.push_str(&impact_core::report::BOUNCE_FIELDS.join(","));
        s.push_str(",cor_flight,cor_rebound");
    }
    let with_spectrum = impacts.clone().any(|i| i.borrow().shock_spectrum.is_some());
    // With --axes, the resultant's peak and each axis's peak and Δv (named by its column).
    let axis_names: Vec<String> = impacts
        .clone()
        .find_map(|i| {
            let x = i.borrow().axes.as_ref()?;
            Some(x.axes.iter().map(|a| a.column.clone()).collect())
        })
        .unwrap_or_default();
    let with_axes = impacts.clone().any(|i| i.borrow().axes.is_some());
    if with_axes {
        s.push_str(",resultant_peak_m_s2");
        for n in &axis_names {
            s.push_str(&format!(",{n}_peak_acceleration_m_s2,{n}_delta_v_m_s"));
        }
    }
    if with_spectrum {
        s.push(',');
        s.push_str(crate::report::spectrum::CSV_HEADER);
    }
    // With --spec: each impact's verdict (empty cells when it could not be judged).
    let with_spec = impacts.clone().any(|i| i.borrow().spec.is_some());
    if with_spec {
        s.push_str(",spec_pass,spec_band_pass,spec_delta_v_pass,spec_margin,spec_worst_time_s,spec_worst_m_s2,spec_limit_m_s2,spec_delta_v_m_s,spec_nominal_start_s");
    }
    // `impact log` of a log in which the board restarted: each impact's run.
    let with_run = impacts.clone().any(|i| i.borrow().run.is_some());
    if with_run {
        s.push_str(",run");
    }
    s.push('\n');
    out.write_all(s.as_bytes())?;
    let o = |v: Option<f64>| v.map_or(String::new(), number);
    for i in impacts {
        let i = i.borrow();
        let mut s = String::new();
        let tp = i.fits.two_phase.as_ref();
        let nl = i.fits.nonlinear.as_ref();
        let hz = i.fits.hertz.as_ref();
        // In the order of `report::FIELDS` (the header above).
        let cells: [String; impact_core::report::FIELDS.len()] = [
            i.index.to_string(),
            i.status.clone(),
            i.analysis.clone(),
            i.clipped.to_string(),
            i.flags.join(";"),
            i.start_sample.to_string(),
            i.end_sample.to_string(),
            number(i.start_s),
            number(i.peak_time_s),
            number(i.peak_acceleration_m_s2),
            o(i.peak_force_n),
            o(i.delta_v_m_s),
            number(i.duration_s),
            number(i.baseline_m_s2),
            o(i.fwhm_s),
            o(i.filtered_peak_acceleration_m_s2),
            o(i.filtered_fwhm_s),
            o(i.impact_velocity_m_s),
            o(i.crush_time_s),
            o(i.max_deformation_m),
            o(i.rebound_velocity_m_s),
            o(i.cor),
            o(i.permanent_deformation_m),
            o(i.absorbed_energy_j),
            o(tp.map(|t| t.kc_n_m)),
            o(tp.map(|t| t.kr_n_m)),
            o(tp.map(|t| t.c_n_s_m)),
            o(tp.map(|t| t.permanent_deformation_m)),
            o(tp.map(|t| t.residual)),
            o(nl.map(|t| t.k)),
            o(nl.map(|t| t.c_s_m)),
            o(nl.map(|t| t.exponent)),
            o(nl.map(|t| t.residual)),
            o(hz.map(|t| t.k)),
            o(hz.map(|t| t.residual)),
        ];
        s.push_str(&cells.join(","));
        if with_train {
            let b = i.bounce.as_ref();
            for cell in [
                b.map_or(String::new(), |b| b.number.to_string()),
                o(b.map(|b| b.flight_s)),
                o(b.map(|b| b.v0_flight_m_s)),
                o(b.and_then(|b| b.v0_rebound_m_s)),
                o(b.and_then(|b| b.cor_flight)),
                o(b.and_then(|b| b.cor_rebound)),
            ] {
                s.push(',');
                s.push_str(&cell);
            }
        }
        if with_axes {
            let x = i.axes.as_ref();
            s.push(',');
            s.push_str(&o(x.map(|x| x.resultant_peak_m_s2)));
            for k in 0..axis_names.len() {
                let axis = x.and_then(|x| x.axes.get(k));
                s.push(',');
                s.push_str(&o(axis.map(|a| a.peak_acceleration_m_s2)));
                s.push(',');
                s.push_str(&o(axis.and_then(|a| a.delta_v_m_s)));
            }
        }
        if with_spectrum {
            s.push(',');
            s.push_str(&crate::report::spectrum::csv_cells(
                i.shock_spectrum.as_ref(),
            ));
        }
        if with_spec {
            let v = i.spec.as_ref().and_then(|v| v.as_ref());
            let b = |f: fn(&crate::report::spec::VerdictJson) -> bool| {
                v.map_or(String::new(), |v| f(v).to_string())
            };
            for cell in [
                b(|v| v.pass),
                b(|v| v.band_pass),
                b(|v| v.delta_v_pass),
                o(v.map(|v| v.margin)),
                o(v.map(|v| v.worst_time_s)),
                o(v.map(|v| v.worst_m_s2)),
                o(v.map(|v| v.limit_m_s2)),
                o(v.map(|v| v.delta_v_m_s)),
                o(v.map(|v| v.nominal_start_s)),
            ] {
                s.push(',');
                s.push_str(&cell);
            }
        }
        if with_run {
            s.push(',');
            s.push_str(&i.run.map_or(String::new(), |r| r.to_string()));
        }
        s.push('\n');
        out.write_all(s.as_bytes())?;
    }
    Ok(())
}
