//! The analysis as CSV: one row per impact, the contract's fields first (`report::FIELDS`),
//! written through `csv::Writer` (a cell quoted where it must be) with every text that came
//! from an input (a column's name) through [`text`] (no cell a spreadsheet runs as a formula).

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

/// A CSV writer of the tool's outputs: comma-separated, `\n` after each row, a cell quoted
/// only where it holds a comma, a quote or a line break; a row of another length than the
/// header written as it is (never dropped).
pub fn writer<W: Write>(out: W) -> csv::Writer<W> {
    csv::WriterBuilder::new()
        .terminator(csv::Terminator::Any(b'\n'))
        .flexible(true)
        .from_writer(out)
}

/// Text from an input (a file's or a column's name) as a cell: one that a spreadsheet would
/// read as a formula (`=`, `+`, `-`, `@`, a tab or a carriage return first) gets a `'` before
/// it, as OWASP's CSV-injection advice has it; the writer quotes the rest.
pub fn text(s: &str) -> String {
    if s.starts_with(['=', '+', '-', '@', '\t', '\r']) {
        format!("'{s}")
    } else {
        s.to_string()
    }
}

/// The columns a set of impacts needs: the contract's, then those its options add.
pub struct Columns {
    /// With --train, the bounce columns.
    train: bool,
    /// With --axes, each axis's column name.
    axes: Option<Vec<String>>,
    /// With --srs, the spectra's summary columns.
    spectrum: bool,
    /// With --spec, the verdict's columns.
    spec: bool,
    /// `impact log` of a log in which the board restarted: each impact's run.
    run: bool,
}

impl Columns {
    /// The columns of `impacts` (of analysis `a`).
    pub fn of<I>(a: &AnalysisJson, impacts: I) -> Self
    where
        I: Iterator + Clone,
        I::Item: Borrow<ImpactJson>,
    {
        let any = |f: fn(&ImpactJson) -> bool| impacts.clone().any(|i| f(i.borrow()));
        let axes = impacts.clone().find_map(|i| {
            let x = i.borrow().axes.as_ref()?;
            Some(x.axes.iter().map(|a| a.column.clone()).collect())
        });
        Self {
            train: a.train_speed.is_some(),
            axes: if any(|i| i.axes.is_some()) {
                Some(axes.unwrap_or_default())
            } else {
                None
            },
            spectrum: any(|i| i.shock_spectrum.is_some()),
            spec: any(|i| i.spec.is_some()),
            run: any(|i| i.run.is_some()),
        }
    }

    /// The header's cells.
    pub fn header(&self) -> Vec<String> {
        // The report's fields as the firmware's `impact` line names them (one list, in core).
        let mut h: Vec<String> = impact_core::report::FIELDS
            .iter()
            .map(|f| f.to_string())
            .collect();
        if self.train {
            h.extend(
                impact_core::report::BOUNCE_FIELDS
                    .iter()
                    .map(|f| f.to_string()),
            );
            h.extend(["cor_flight".into(), "cor_rebound".into()]);
        }
        // The resultant's peak and each axis's peak and Δv (named by its column).
        if let Some(names) = &self.axes {
            h.push("resultant_peak_m_s2".into());
            for n in names {
                h.push(text(&format!("{n}_peak_acceleration_m_s2")));
                h.push(text(&format!("{n}_delta_v_m_s")));
            }
        }
        if self.spectrum {
            h.extend(
                crate::report::spectrum::CSV_COLUMNS
                    .iter()
                    .map(|c| c.to_string()),
            );
        }
        // Each impact's verdict (empty cells when it could not be judged).
        if self.spec {
            h.extend(
                [
                    "spec_pass",
                    "spec_band_pass",
                    "spec_delta_v_pass",
                    "spec_margin",
                    "spec_worst_time_s",
                    "spec_worst_m_s2",
                    "spec_limit_m_s2",
                    "spec_delta_v_m_s",
                    "spec_nominal_start_s",
                    "spec_worst_limit",
                ]
                .map(String::from),
            );
            // The transverse check (IEC 60068-2-27) of the axes.
            if self.axes.is_some() {
                h.extend(
                    [
                        "spec_transverse_pass",
                        "spec_transverse_main_axis",
                        "spec_transverse_worst_fraction",
                    ]
                    .map(String::from),
                );
            }
        }
        if self.run {
            h.push("run".into());
        }
        h
    }

    /// Impact `i`'s cells, under [`Columns::header`].
    pub fn row(&self, i: &ImpactJson) -> Vec<String> {
        let o = |v: Option<f64>| v.map_or(String::new(), number);
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
            i.decimation.to_string(),
            o(i.impact_velocity_m_s),
            o(i.crush_time_s),
            o(i.max_deformation_m),
            o(i.rebound_velocity_m_s),
            o(i.cor),
            o(i.separation_deformation_m),
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
        let mut row = cells.to_vec();
        if self.train {
            let b = i.bounce.as_ref();
            row.extend([
                b.map_or(String::new(), |b| b.number.to_string()),
                o(b.map(|b| b.flight_s)),
                o(b.map(|b| b.v0_flight_m_s)),
                o(b.and_then(|b| b.v0_rebound_m_s)),
                o(b.map(|b| b.landing_height_m)),
                o(b.and_then(|b| b.cor_flight)),
                o(b.and_then(|b| b.cor_rebound)),
            ]);
        }
        if let Some(names) = &self.axes {
            let x = i.axes.as_ref();
            row.push(o(x.map(|x| x.resultant_peak_m_s2)));
            for k in 0..names.len() {
                let axis = x.and_then(|x| x.axes.get(k));
                row.push(o(axis.map(|a| a.peak_acceleration_m_s2)));
                row.push(o(axis.and_then(|a| a.delta_v_m_s)));
            }
        }
        if self.spectrum {
            row.extend(crate::report::spectrum::csv_cells(
                i.shock_spectrum.as_ref(),
            ));
        }
        if self.spec {
            let v = i.spec.as_ref().and_then(|v| v.as_ref());
            let b = |f: fn(&crate::report::spec::VerdictJson) -> bool| {
                v.map_or(String::new(), |v| f(v).to_string())
            };
            row.extend([
                b(|v| v.pass),
                b(|v| v.band_pass),
                b(|v| v.delta_v_pass),
                o(v.map(|v| v.margin)),
                o(v.map(|v| v.worst_time_s)),
                o(v.map(|v| v.worst_m_s2)),
                o(v.map(|v| v.limit_m_s2)),
                o(v.map(|v| v.delta_v_m_s)),
                o(v.map(|v| v.nominal_start_s)),
                v.map_or(String::new(), |v| match v.worst_limit {
                    crate::report::spec::Limit::Upper => "upper".into(),
                    crate::report::spec::Limit::Lower => "lower".into(),
                }),
            ]);
            if self.axes.is_some() {
                let t = v.and_then(|v| v.transverse.as_ref());
                row.extend([
                    t.map_or(String::new(), |t| t.pass.to_string()),
                    t.map_or(String::new(), |t| text(&t.main_axis)),
                    o(t.and_then(|t| t.worst())
                        .map(|w| w.fraction_of_nominal_peak)),
                ]);
            }
        }
        if self.run {
            row.push(i.run.map_or(String::new(), |r| r.to_string()));
        }
        row
    }
}

/// The CSV of `a` with `impacts` (read twice: the columns, then the rows) in place of
/// `a.impacts`, written to `out` a row at a time.
pub fn write_csv<I>(a: &AnalysisJson, impacts: I, out: &mut impl Write) -> std::io::Result<()>
where
    I: Iterator + Clone,
    I::Item: Borrow<ImpactJson>,
{
    let columns = Columns::of(a, impacts.clone());
    let mut w = writer(out);
    w.write_record(columns.header())?;
    for i in impacts {
        w.write_record(columns.row(i.borrow()))?;
    }
    w.flush()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cell_is_quoted_where_it_must_be_and_no_name_is_a_formula() {
        let mut w = writer(Vec::new());
        for cell in [
            "a,b.csv",
            "say \"x\"",
            "plain",
            "=cmd|' /C calc'!A0",
            "-2+3",
            "@SUM(1)",
        ] {
            w.write_record([text(cell), "1.5".into()]).unwrap();
        }
        let out = String::from_utf8(w.into_inner().unwrap()).unwrap();
        assert_eq!(
            out,
            "\"a,b.csv\",1.5\n\"say \"\"x\"\"\",1.5\nplain,1.5\n'=cmd|' /C calc'!A0,1.5\n'-2+3,1.5\n'@SUM(1),1.5\n"
        );
    }
}
