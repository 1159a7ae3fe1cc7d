//! `bubbles chart` (being built; see the open issue).

use crate::error::{CliError, CliResult};

/// Arguments of `bubbles chart`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `bubbles chart`.
pub fn run(_args: Args) -> CliResult {
    Err(CliError::runtime("`bubbles chart` is not built yet"))
}
