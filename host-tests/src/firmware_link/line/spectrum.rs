//! The `srs` and `spec` lines after an impact's line: its spectra and its verdict (the
//! reporter's `log_spectrum` and `log_verdict`).

use impact_core::report::Spectrum;
use impact_core::signal::spectrum::MAX_BANDS;
use impact_core::spec::verdict::{Missing, Verdict};

use super::{Fields, LineError};

/// An `srs` line: the spectra of the impact with its `index`.
#[derive(Clone, Debug, PartialEq)]
pub struct SrsLine {
    pub index: u32,
    pub spectrum: Spectrum,
}

impl SrsLine {
    pub fn parse(f: &Fields) -> Result<Self, LineError> {
        let bands: u8 = f.num("bands")?;
        let (srs, pvss) = (list(f, "srs_m_s2")?, list(f, "pvss_m_s")?);
        let n = usize::from(bands);
        if n == 0 || n > MAX_BANDS || srs.len() != n || pvss.len() != n {
            return Err(LineError::Bands {
                bands,
                srs: srs.len(),
                pvss: pvss.len(),
            });
        }
        let mut spectrum = Spectrum {
            bands,
            first_hz: f.num("first_hz")?,
            bands_per_octave: f.num("bands_per_octave")?,
            damping: f.num("damping")?,
            srs_m_s2: [0.0; MAX_BANDS],
            pvss_m_s: [0.0; MAX_BANDS],
            half_sine: match (
                f.opt::<f32>("half_sine_amplitude_m_s2")?,
                f.opt::<f32>("half_sine_duration_s")?,
            ) {
                (Some(a), Some(d)) => Some((a, d)),
                _ => None,
            },
            from_sample: f.num("from_sample")?,
            to_sample: f.num("to_sample")?,
        };
        spectrum.srs_m_s2[..n].copy_from_slice(&srs);
        spectrum.pvss_m_s[..n].copy_from_slice(&pvss);
        Ok(Self {
            index: f.num("index")?,
            spectrum,
        })
    }
}

/// A comma-separated list of finite values >= 0.
fn list(f: &Fields, field: &'static str) -> Result<Vec<f32>, LineError> {
    f.text(field)?
        .split(',')
        .map(|v| match v.parse::<f32>() {
            Ok(x) if x.is_finite() && x >= 0.0 => Ok(x),
            _ => Err(LineError::ListValue {
                field,
                text: v.to_string(),
            }),
        })
        .collect()
}

/// Every reason a verdict can be missing: their names are the core's ([`Missing::name`]).
const MISSING: [Missing; 5] = Missing::ALL;

/// A `spec` line: the verdict of the impact with its `index`, or why there is none
/// (`pass=none reason=...`).
#[derive(Clone, Debug, PartialEq)]
pub struct SpecLine {
    pub index: u32,
    pub verdict: Result<Verdict, Missing>,
}

impl SpecLine {
    pub fn parse(f: &Fields) -> Result<Self, LineError> {
        let index: u32 = f.num("index")?;
        if f.text("pass")? == "none" {
            let reason = f.text("reason")?;
            let missing = MISSING
                .into_iter()
                .find(|m| m.name() == reason)
                .ok_or_else(|| LineError::Reason {
                    text: reason.to_string(),
                })?;
            return Ok(Self {
                index,
                verdict: Err(missing),
            });
        }
        let verdict = Verdict {
            pass: f.flag("pass")?,
            band_pass: f.flag("band_pass")?,
            delta_v_pass: f.flag("delta_v_pass")?,
            margin: f.num("margin")?,
            worst_s: f.num("worst_s")?,
            worst_m_s2: f.num("worst_m_s2")?,
            limit_m_s2: f.num("limit_m_s2")?,
            delta_v_m_s: f.num("delta_v_m_s")?,
            start_s: f.num("start_s")?,
        };
        Ok(Self {
            index,
            verdict: Ok(verdict),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_missing_reason_reads_back_by_its_name() {
        // A reason the core adds breaks this match: list it in MISSING too.
        for m in MISSING {
            match m {
                Missing::Window
                | Missing::WindowBefore
                | Missing::WindowAfter
                | Missing::Resolution
                | Missing::Overflow => {}
            }
        }
        for m in MISSING {
            let f = Fields::parse(&format!("index=4 pass=none reason={}", m.name())).unwrap();
            assert_eq!(SpecLine::parse(&f).unwrap().verdict, Err(m));
        }
        let f = Fields::parse("index=4 pass=none reason=spec-nothing").unwrap();
        assert_eq!(
            SpecLine::parse(&f).unwrap_err().to_string(),
            "reason=spec-nothing: not a reason a verdict is missing"
        );
    }
}
