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
    let kind = output_kind(&args.out)?;
    check_parent_dir(&args.out)?;
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
    let written = match kind {
        OutputKind::Png => frame.write_png(&args.out, exposure_ev, tonemap),
        OutputKind::Exr => frame.write_exr(&args.out),
    };
    written.map_err(|e| CliError::input(format!("cannot write {}: {e}", args.out.display())))?;
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

/// Fails early, before minutes of work, when the output directory cannot take the file.
fn check_parent_dir(path: &Path) -> CliResult {
    let parent = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    if parent.is_dir() {
        Ok(())
    } else {
        Err(CliError::input(format!(
            "--out {}: directory {} does not exist",
            path.display(),
            parent.display()
        )))
    }
}
