//! `tactile check SCENARIO [--set ...]`: is the scenario valid, what exactly would
//! run (every default filled in, the `--set`s applied), how long it takes and how
//! much it writes, before anything starts.

use clap::Args;
use std::path::PathBuf;
use tactile_launch::error::Error;
use tactile_launch::estimate::report;
use tactile_launch::{load_scenario, parse_sets};

/// Arguments of `tactile check`.
#[derive(Debug, Args)]
pub struct CheckArgs {
    /// Scenario file (TOML); without it, the built-in paper scenario.
    pub scenario: Option<PathBuf>,
    /// Override one scenario value, KEY=VALUE (repeatable), as `tactile run` does.
    #[arg(long, value_name = "KEY=VALUE")]
    pub set: Vec<String>,
}

/// `tactile check`: the resolved scenario on stdout, the estimates on stderr.
pub fn main(args: &CheckArgs) -> Result<(), Error> {
    let sets = parse_sets(&args.set)?;
    let loaded = load_scenario(args.scenario.as_deref(), &sets)?;
    let s = &loaded.scenario;
    tactile_launch::out!("{}", s.resolved(&loaded.base_dir).to_toml());
    for line in report(&loaded) {
        tactile_launch::noteln!("{line}");
    }
    Ok(())
}
