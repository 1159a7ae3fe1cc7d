//! `bubbles bake` (being built; see the open issue).

use crate::error::{CliError, CliResult};

/// Arguments of `bubbles bake`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `bubbles bake`.
pub fn run(_args: Args) -> CliResult {
    Err(CliError::runtime("`bubbles bake` is not built yet"))
}
