//! `bubbles color` (being built; see the open issue).

use crate::error::{CliError, CliResult};

/// Arguments of `bubbles color`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `bubbles color`.
pub fn run(_args: Args) -> CliResult {
    Err(CliError::runtime("`bubbles color` is not built yet"))
}
