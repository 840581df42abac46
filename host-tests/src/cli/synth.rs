//! `impact synth`: a model impact rendered as an accelerometer recording, written as CSV
//! (standard output or `--output`) and raw ADC codes (`--raw`).

use std::path::PathBuf;

use clap::Args;

use crate::synth::{self, SynthError};

/// `impact synth` options: the impact and the recording ([`synth::SynthArgs`]), and where
/// they go.
#[derive(Args, Debug)]
pub struct SynthCommand {
    #[command(flatten)]
    pub args: Box<synth::SynthArgs>,
    /// Write the CSV (time_s, accel_m_s2) to this file instead of standard output.
    #[arg(short = 'o', long, help_heading = "Output", value_name = "FILE.csv")]
    pub output: Option<PathBuf>,
    /// Also write the raw ADC codes as little-endian i16 to this file (`impact analyze
    /// FILE.i16 --rate ...` reads it).
    #[arg(long, help_heading = "Output", value_name = "FILE.i16")]
    pub raw: Option<PathBuf>,
}

/// Runs `impact synth`.
pub fn run(command: SynthCommand) -> Result<(), SynthError> {
    let SynthCommand { args, output, raw } = command;
    if let (Some(o), Some(r)) = (&output, &raw) {
        if o == r {
            return Err(SynthError::SameFile { path: o.clone() });
        }
    }
    // (The target's file, the one input, is never written over.)
    let inputs = (args.target.iter()).fold(crate::output::Inputs::new(), |all, t| all.with(t));
    for (option, path) in [("--output", &output), ("--raw", &raw)] {
        if let Some(path) = path {
            crate::output::check(option, path, &inputs, None)?;
        }
    }
    let rec = synth::synth(&args)?;
    if let Some((at_s, end)) = rec.ended {
        let why = match end {
            crate::drop::End::Contacts => {
                "where the body lands after the last contact modelled (--bounces)"
            }
            crate::drop::End::PadNotRecovered => {
                "after a contact the pad could not recover from before the next landing"
            }
            crate::drop::End::Rests => "where the body comes to rest on the pad",
            crate::drop::End::Duration => "at --duration",
        };
        crate::errln!("note: the recording ends at {at_s} s, {why}");
    }
    if let Some(path) = raw {
        let bytes: Vec<u8> = rec.samples.iter().flat_map(|c| c.to_le_bytes()).collect();
        crate::output::write(&path, &bytes)?;
    }
    match output {
        Some(path) => {
            crate::output::write_with(&path, |mut out| synth::write_csv(&rec, &args, &mut out))?;
        }
        None => {
            let stdout = crate::output::stdout();
            synth::write_csv(
                &rec,
                &args,
                &mut std::io::BufWriter::with_capacity(1 << 16, stdout),
            )
            .map_err(SynthError::Stdout)?;
        }
    }
    Ok(())
}
