//! `bubbles reflectance` (being built; see the open issue).

use crate::error::{CliError, CliResult};

/// Arguments of `bubbles reflectance`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `bubbles reflectance`.
pub fn run(_args: Args) -> CliResult {
    Err(CliError::runtime("`bubbles reflectance` is not built yet"))
}
