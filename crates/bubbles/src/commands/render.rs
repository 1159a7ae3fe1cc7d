//! `bubbles render`: simulate a scene up to a time, then render it to PNG or EXR.

use crate::error::{CliError, CliResult};
use crate::frame::{FrameJob, Options};
use crate::limits;
use crate::scene::values::{Num, Seconds, plain};
use std::path::{Path, PathBuf};

/// Arguments of `bubbles render`.
#[derive(Debug, clap::Args)]
#[command(after_help = limits::HELP)]
pub struct Args {
    /// A scene file (.toml) or a built-in scene: `paper` (default) or `white-furnace`.
    pub scene: Option<String>,
    /// Output image: `.png` (8-bit sRGB, tone-mapped) or `.exr` (linear HDR).
    #[arg(long)]
    pub out: PathBuf,
    /// Simulated time to advance before rendering, 0..=3600 s (default: the scene's `time_s`).
    #[arg(long, allow_negative_numbers = true)]
    pub time_s: Option<f64>,
    #[command(flatten)]
    pub options: Options,
}

/// The image formats `render` writes.
enum OutputKind {
    Png,
    Exr,
}

/// Runs `bubbles render`.
pub fn run(args: Args) -> CliResult {
    crate::signals::install();
    let kind = output_kind(&args.out)?;
    crate::output::check_file("--out", &args.out)?;
    let mut job = FrameJob::prepare(args.scene.as_deref(), &args.options)?;
    let time_s = match args.time_s {
        Some(t) => Num::<Seconds>::try_new(t)
            .map_err(|m| CliError::input(format!("--time-s {}: {m}", plain(t))))?
            .get(),
        None => job.scene_time_s(),
    };
    job.advance_to(time_s, true)?;
    let (exposure_ev, tonemap) = (job.settings().exposure_ev, job.settings().tonemap);
    let bubbles = job.bubble_count();
    let time_s = job.time_s();
    let frame = job.render()?;
    crate::signals::check()?;
    let written = match kind {
        OutputKind::Png => frame.write_png(&args.out, exposure_ev, tonemap),
        OutputKind::Exr => frame.write_exr(&args.out),
    };
    // The error names the file already ("cannot write PATH: why").
    written.map_err(|e| CliError::input(e.to_string()))?;
    eprintln!(
        "wrote {} ({}x{}, {} bubble(s), t = {:.3} s)",
        args.out.display(),
        frame.width(),
        frame.height(),
        bubbles,
        time_s
    );
    Ok(())
}

fn output_kind(path: &Path) -> Result<OutputKind, CliError> {
    match path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("png") => Ok(OutputKind::Png),
        Some("exr") => Ok(OutputKind::Exr),
        _ => Err(CliError::input(format!(
            "--out {}: the file name must end in .png or .exr",
            path.display()
        ))),
    }
}
