//! `bubbles bench` (being built; see the open issue).

use crate::error::{CliError, CliResult};

/// Arguments of `bubbles bench`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `bubbles bench`.
pub fn run(_args: Args) -> CliResult {
    Err(CliError::runtime("`bubbles bench` is not built yet"))
}
