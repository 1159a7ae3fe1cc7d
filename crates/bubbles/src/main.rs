//! `bubbles`: soap bubbles with real thin-film optics.

mod commands;
mod csv_table;
mod error;
mod frame;
mod input;
mod limits;
mod output;
mod scene;
mod signals;
#[cfg(feature = "view")]
mod view;

use clap::{Parser, Subcommand};

/// Soap bubbles with real thin-film optics.
#[derive(Debug, Parser)]
#[command(name = "bubbles", version, about, long_about = None, after_help = limits::HELP)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Thin-film reflectance and transmittance, spectral, from CSV on stdin or flags.
    Reflectance(commands::reflectance::Args),
    /// Fit a film's (or one stack layer's) thickness to a measured reflectance spectrum.
    Fit(commands::fit::Args),
    /// CIE colour of a soap film, from CSV `thickness_nm,angle_deg` on stdin.
    Color(commands::color::Args),
    /// Draw the interference colour chart (colour against thickness) to a PNG.
    Chart(commands::chart::Args),
    /// Bake the (thickness, cos θ) textures to EXR/PNG with a JSON description.
    Bake(commands::bake::Args),
    /// Simulate a scene's bubbles and print their state as JSON.
    Simulate(commands::simulate::Args),
    /// Simulate, then render a scene to PNG or EXR.
    Render(commands::render::Args),
    /// Time the frame and print a breakdown.
    Bench(commands::bench::Args),
    /// Simulate and render an animation: PNG frames, an animated PNG or a GIF preview.
    Animate(commands::animate::Args),
    /// CIEDE2000 between two images: mean, 95th percentile, maximum, optional heat map.
    Compare(commands::compare::Args),
    /// A film's thickness map from a photo of it: EXR map, uncertainty, residual, figures.
    Thickness(commands::thickness::Args),
    /// Open a live window on the scene (simulated in real time, CPU-rendered).
    #[cfg(feature = "view")]
    #[command(after_help = view::CONTROLS)]
    View(view::Args),
}

fn main() -> std::process::ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Reflectance(args) => commands::reflectance::run(args),
        Command::Fit(args) => commands::fit::run(args),
        Command::Color(args) => commands::color::run(args),
        Command::Chart(args) => commands::chart::run(args),
        Command::Bake(args) => commands::bake::run(args),
        Command::Simulate(args) => commands::simulate::run(args),
        Command::Render(args) => commands::render::run(args),
        Command::Bench(args) => commands::bench::run(args),
        Command::Animate(args) => commands::animate::run(args),
        Command::Compare(args) => commands::compare::run(args),
        Command::Thickness(args) => commands::thickness::run(args),
        #[cfg(feature = "view")]
        Command::View(args) => view::run(args),
    };
    match result {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(err) => {
            eprintln!("error: {err}");
            std::process::ExitCode::from(err.exit_code())
        }
    }
}
