//! `bubbles simulate` (being built; see the open issue).

use crate::error::{CliError, CliResult};

/// Arguments of `bubbles simulate`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `bubbles simulate`.
pub fn run(_args: Args) -> CliResult {
    Err(CliError::runtime("`bubbles simulate` is not built yet"))
}
