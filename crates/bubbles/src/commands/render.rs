//! `bubbles render` (being built; see the open issue).

use crate::error::{CliError, CliResult};

/// Arguments of `bubbles render`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `bubbles render`.
pub fn run(_args: Args) -> CliResult {
    Err(CliError::runtime("`bubbles render` is not built yet"))
}
