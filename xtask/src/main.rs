//! `cargo xtask`: figures, benches and checks.

use std::process::{Command, ExitCode};

const USAGE: &str = "usage: cargo xtask <figures|bench|ci>
  figures  regenerate the PNG figures under docs/figures/
  bench    run the criterion benches of every crate
  ci       run what .ci/run runs (fmt, clippy, tests)";

fn main() -> ExitCode {
    let task = std::env::args().nth(1);
    let ok = match task.as_deref() {
        Some("figures") => figures(),
        Some("bench") => cargo(&["bench", "--workspace"]),
        Some("ci") => ci(),
        _ => {
            eprintln!("{USAGE}");
            return ExitCode::from(2);
        }
    };
    if ok { ExitCode::SUCCESS } else { ExitCode::FAILURE }
}

/// Runs cargo with `args` from the workspace root, returning whether it succeeded.
fn cargo(args: &[&str]) -> bool {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    eprintln!("$ cargo {}", args.join(" "));
    Command::new(cargo)
        .args(args)
        .current_dir(root)
        .status()
        .is_ok_and(|s| s.success())
}

fn ci() -> bool {
    cargo(&["fmt", "--all", "--check"])
        && cargo(&["clippy", "--workspace", "--all-targets", "--", "-D", "warnings"])
        && cargo(&["test", "--workspace"])
}

fn figures() -> bool {
    std::fs::create_dir_all("docs/figures").is_ok()
        && cargo(&["run", "--release", "-p", "bubbles", "--", "chart", "--out", "docs/figures/chart.png"])
}
