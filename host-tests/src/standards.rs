//! The shock-test standards whose tolerances `--spec` applies (`standard=`), and the SRS
//! tolerance `impact report --srs-required` judges by, each number as docs/standards.md gives
//! it with its source.

use impact_core::spec::Tolerance;

/// A standard's tolerances, as docs/standards.md gives them with their sources.
pub struct Standard {
    /// Its name in `standard=`.
    pub name: &'static str,
    /// How the reports and the table name it.
    pub title: &'static str,
    pub tolerance: Tolerance,
    /// A trapezoid's rise and fall, × the duration, when the spec does not give them.
    pub ramp: f32,
    /// The pulse shapes it specifies (`--spec`'s names).
    pub shapes: &'static [&'static str],
    /// Another reading of its Δv tolerance found in a public source, and which: the verdict
    /// says whether the velocity change passes under it too.
    pub delta_v_other: Option<(f32, &'static str)>,
    /// Where each of its numbers comes from, and how directly.
    pub sources: &'static [Source],
}

/// How directly a number was read (docs/standards.md, "Where every number comes from").
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Confidence {
    /// Read in the standard's text.
    Quoted,
    /// From a public transcription of the standard, named.
    Secondary,
    /// The standard's figure as commonly drawn; not read in its text here.
    Recalled,
}

impl Confidence {
    pub fn name(self) -> &'static str {
        match self {
            Confidence::Quoted => "quoted",
            Confidence::Secondary => "secondary",
            Confidence::Recalled => "recalled",
        }
    }
}

/// One number of a standard (its `--spec` key), its source and how directly it was read.
pub struct Source {
    pub key: &'static str,
    pub confidence: Confidence,
    pub from: &'static str,
}

const fn source(key: &'static str, confidence: Confidence, from: &'static str) -> Source {
    Source {
        key,
        confidence,
        from,
    }
}

use Confidence::{Quoted, Recalled, Secondary};

/// MIL-STD-202H Method 213's Figure 2 note on the velocity change's window.
const WINDOW_202H: &str =
    "MIL-STD-202H Method 213, Figure 2 note: \"from .4D before the pulse to .1D beyond the pulse\"";
/// eplik82/shock_test's transcription of MIL-STD-810H Figure 516.8-5 (`src/shock.cpp`).
const EPLIK_810H: &str =
    "eplik82/shock_test (src/shock.cpp), transcribing MIL-STD-810H Figure 516.8-5";
/// A trapezoid's rise and fall in IEC 60068-2-27's Figure 3.
const RAMP_IEC: &str = "IEC 60068-2-27:2008 Figure 3, as commonly drawn";

/// The standards `standard=` names (the first is the default).
pub const STANDARDS: [Standard; 3] = [
    Standard {
        name: "iec-60068-2-27",
        title: "IEC 60068-2-27:2008",
        tolerance: Tolerance {
            band: 0.2,
            outside: 0.2,
            slack: 0.1,
            delta_v: 0.15,
            before: 0.4,
            after: 0.1,
            watch: 1.1,
        },
        ramp: 0.1,
        shapes: &["half-sine", "sawtooth", "trapezoid"],
        delta_v_other: None,
        sources: &[
            source("band", Recalled, "IEC 60068-2-27:2008 Figures 1-3, as commonly drawn"),
            source("outside", Recalled, "IEC 60068-2-27:2008 Figures 1-3, as commonly drawn"),
            source("slack", Recalled, "the widened band of IEC 60068-2-27:2008's figures (its width not read)"),
            source("dv", Recalled, "IEC 60068-2-27:2008 (medium confidence; the 1987 edition: ±10 %)"),
            source("before", Quoted, WINDOW_202H),
            source("after", Quoted, WINDOW_202H),
            source("watch", Recalled, "IEC 60068-2-27:2008: a monitoring time of about 2.5 D (low confidence)"),
            source("rise, fall", Recalled, RAMP_IEC),
        ],
    },
    Standard {
        name: "mil-std-810h",
        title: "MIL-STD-810H Method 516.8",
        tolerance: Tolerance {
            band: 0.2,
            outside: 0.2,
            slack: 0.1,
            delta_v: 0.1,
            before: 0.4,
            after: 0.1,
            watch: 1.0,
        },
        ramp: 0.1,
        shapes: &["half-sine", "sawtooth", "trapezoid"],
        delta_v_other: Some((
            0.2,
            "a public transcription of MIL-STD-810H Figure 516.8-5's key reads ±20 % (unconfirmed)",
        )),
        sources: &[
            source("band", Secondary, EPLIK_810H),
            source("outside", Secondary, EPLIK_810H),
            source("slack", Secondary, EPLIK_810H),
            source("dv", Recalled, "MIL-STD-810E's text: \"within the limits of Vi ± 0.1 Vi\" (810H's figure key read as ±20 % in a transcription: both readings are shown)"),
            source("before", Quoted, WINDOW_202H),
            source("after", Quoted, WINDOW_202H),
            source("watch", Secondary, "MIL-STD-810H Figure 516.8-5: T1 ≥ 2.4 TD (eplik82/shock_test)"),
            source("rise, fall", Recalled, RAMP_IEC),
        ],
    },
    Standard {
        name: "mil-std-202h",
        title: "MIL-STD-202H Method 213",
        tolerance: Tolerance {
            band: 0.2,
            outside: 0.2,
            slack: 0.1,
            delta_v: 0.1,
            before: 0.4,
            after: 0.1,
            watch: 1.0,
        },
        ramp: 0.1,
        shapes: &["half-sine", "sawtooth"],
        delta_v_other: None,
        sources: &[
            source("band", Recalled, "MIL-STD-202H Method 213 Figures 213-1 and 213-2, as commonly drawn"),
            source("outside", Recalled, "MIL-STD-202H Method 213 Figures 213-1 and 213-2, as commonly drawn"),
            source("slack", Secondary, EPLIK_810H),
            source("dv", Recalled, "MIL-STD-202: ±10 %"),
            source("before", Quoted, WINDOW_202H),
            source("after", Quoted, WINDOW_202H),
            source("watch", Quoted, "MIL-STD-202H Method 213: \"an oscillogram … about 3D long with the pulse approximately in the center\""),
        ],
    },
];

/// The standard of this name.
pub fn by_name(name: &str) -> Option<&'static Standard> {
    STANDARDS.iter().find(|s| s.name == name)
}

/// The title of a standard's name (the name itself for `custom`).
pub fn title(name: &str) -> &str {
    STANDARDS
        .iter()
        .find(|s| s.name == name)
        .map_or(name, |s| s.title)
}

/// The SRS tolerance of MIL-STD-810H Method 516.8 (docs/standards.md gives its source): the
/// measured SRS within −1.5 dB and +3 dB of the required one, dB (20 log10 of the ratio).
pub const SRS_TOLERANCE_DB: (f64, f64) = (-1.5, 3.0);

/// Where [`SRS_TOLERANCE_DB`] comes from, as the report names it.
pub const SRS_TOLERANCE_SOURCE: &str = "MIL-STD-810H Method 516.8";
