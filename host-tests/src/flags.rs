//! How the tool names what a user gave: the core and the readers name a parameter by its own
//! name (`mass`, `rate_hz`), the command line by its option (`--mass`, `--rate`). The one place
//! that spells them for errors: a reader's setting ([`flag`]) and a core parameter ([`fn@core`]).

use impact_io::Opt;

/// The option that gives a reading's setting.
pub fn flag(setting: Opt) -> &'static str {
    match setting {
        Opt::Rate => "--rate",
        Opt::TimeColumn => "--time-column",
        Opt::TimeUnit => "--time-unit",
        Opt::Column => "--column",
        Opt::Axes => "--axes",
        Opt::Resample => "--resample",
        Opt::RawChannels => "--raw-channels",
        Opt::RawType => "--raw-type",
        Opt::DecimalComma => "--decimal-comma",
        Opt::Delimiter => "--delimiter",
        Opt::Units => "--units",
    }
}

/// A core error as the command line says it: an invalid parameter named as its option.
pub fn core(e: impact_core::Error) -> String {
    match e {
        impact_core::Error::InvalidParameter { name, reason } => format!("--{name}: {reason}"),
        e => e.to_string(),
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_core_parameter_is_named_as_its_option() {
        let e = impact_core::Error::InvalidParameter {
            name: "mass",
            reason: "must be finite and > 0",
        };
        assert_eq!(e.to_string(), "mass: must be finite and > 0");
        assert_eq!(super::core(e), "--mass: must be finite and > 0");
    }
}
