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
}

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
    },
];

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
