//! `impact simulate`: one impact of a contact model, on a wall or a target, as a table or
//! JSON.

use crate::simulate::{self, SimulateArgs, SimulateError};

/// Runs `impact simulate`.
pub fn run(args: &SimulateArgs) -> Result<(), SimulateError> {
    fn json<T: serde::Serialize>(v: &T) -> Result<String, SimulateError> {
        Ok(serde_json::to_string(v)?)
    }
    match simulate::run_any(args)? {
        simulate::Outcome::Wall(report) if args.json => crate::outln!("{}", json(&report)?),
        simulate::Outcome::Wall(report) => crate::out!("{}", simulate::table(&report)),
        simulate::Outcome::Target(report) if args.json => crate::outln!("{}", json(&*report)?),
        simulate::Outcome::Target(report) => {
            crate::out!("{}", simulate::two_body::table(&report))
        }
    }
    Ok(())
}
