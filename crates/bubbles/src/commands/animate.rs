//! `bubbles animate`: simulate a scene and render every output frame to numbered PNGs,
//! one animated PNG or a GIF preview, with a progress bar, resume and frame ranges.

mod apng;
mod gif;
mod resume;
pub(crate) mod sink;

use crate::error::{CliError, CliResult};
use crate::frame::progress::Progress;
use crate::frame::{FrameJob, Options};
use crate::scene::Scene;
use crate::scene::values::plain;
use sink::{Output, Rgb8, Sink};
use std::ops::Range;
use std::path::{Path, PathBuf};

/// Most frames one animation may have (so no input runs for ever).
pub const MAX_FRAMES: u64 = 10_000;
/// Longest animation, simulated seconds.
pub const MAX_SECONDS: f64 = 3600.0;
/// Highest frame rate, frames per second.
pub const MAX_FPS: f64 = 240.0;
/// Name of the file in a frame directory that records what the frames show.
pub const MANIFEST: &str = "animation.txt";

/// Arguments of `bubbles animate`.
#[derive(Debug, clap::Args)]
#[command(
    after_help = "Frame k shows the scene at t = k / fps (frame 0 at t = 0), \
    simulated with the scene's own solver step and rendered with the CPU backend. \
    The animation has round(seconds × fps) frames, at most 10000, with seconds <= 3600 \
    and fps <= 240.\n\n\
    --out DIR writes DIR/frame_00000.png, … each through a temporary file renamed into \
    place, so an interrupted run leaves only whole frames, and DIR/animation.txt records \
    the scene and settings and a checksum per frame (a DIR made with other settings, or \
    holding frames without it, is refused). --resume checks and decodes the frames in DIR \
    and renders only those missing, damaged or of another size, after removing stale \
    temporaries; --frames A..B renders frames A to B − 1 only. Both give frames \
    byte-identical to those of one uninterrupted run, so one animation can be split \
    across machines (e.g. a Slurm array job, one --frames range per task).\n\n\
    --out PATH.apng or PATH.png writes one animated PNG: the exact 8-bit frames. \
    --out PATH.gif writes a preview with a 256-colour palette per frame (NeuQuant, \
    Floyd–Steinberg dithered): fine interference fringes lose colour steps, so use APNG or \
    frames for the real thing; the mean CIEDE2000 against the exact frames is printed."
)]
pub struct Args {
    /// A scene file (.toml) or a built-in scene: `wind`, `plane-collision`,
    /// `bubble-collision`, `demo`, `demo-white`, `pond`, `swirl`, `paper`, `white-furnace`.
    pub scene: String,
    /// Length of the animation, simulated seconds (> 0, at most 3600).
    #[arg(long, allow_negative_numbers = true)]
    pub seconds: f64,
    /// Frames per second (> 0, at most 240).
    #[arg(long, default_value_t = 15.0, allow_negative_numbers = true)]
    pub fps: f64,
    /// A directory for frame_00000.png …, or one file: PATH.apng / PATH.png (animated PNG,
    /// exact) or PATH.gif (256-colour preview).
    #[arg(long)]
    pub out: PathBuf,
    /// Render only frames A..B (A included, B excluded, counted from 0).
    #[arg(long, value_name = "A..B")]
    pub frames: Option<String>,
    /// Keep the whole frames already in the output directory; render only the missing or
    /// damaged ones.
    #[arg(long)]
    pub resume: bool,
    /// GIF only: no error diffusion (flat palette colours, visible bands in fringes).
    #[arg(long)]
    pub no_dither: bool,
    #[command(flatten)]
    pub options: Options,
}

/// Runs `bubbles animate`.
pub fn run(args: Args) -> CliResult {
    crate::signals::install();
    let count = frame_count(args.seconds, args.fps)?;
    let range = match &args.frames {
        Some(text) => parse_range(text, count)?,
        None => 0..count,
    };
    let output = Output::from_path(&args.out).map_err(CliError::input)?;
    if args.resume && !matches!(output, Output::Dir(_)) {
        return Err(CliError::input(format!(
            "--resume needs a frame directory as --out, not the file {}",
            args.out.display()
        )));
    }
    check_output(&output)?;
    let manifest = manifest(&args)?;
    let mut job = FrameJob::prepare(Some(&args.scene), &args.options)?;
    let (width, height) = (job.settings().width, job.settings().height);
    let mut sink = open(
        &output,
        &args,
        &manifest,
        (width, height),
        range.end - range.start,
    )?;
    let keep = kept_frames(&output, args.resume, range.clone(), (width, height))?;
    render_frames(&mut job, &mut sink, range.clone(), &keep, &args)?;
    let error = sink
        .finish()
        .map_err(|e| CliError::input(format!("cannot write {}: {e}", args.out.display())))?;
    eprintln!(
        "wrote frames {}..{} of {count} ({width}x{height}, {} fps) to {}",
        range.start,
        range.end,
        args.fps,
        args.out.display()
    );
    if let Some(e) = error {
        eprintln!(
            "GIF palette error: mean CIEDE2000 {:.2}, max {:.1} against the exact frames",
            e.mean(),
            e.max()
        );
    }
    Ok(())
}

/// Refuses, before any work, an output that cannot be created where it is named.
fn check_output(output: &Output) -> CliResult {
    match output {
        Output::Dir(dir) => crate::output::check_dir("--out", dir),
        Output::Apng(path) | Output::Gif(path) => crate::output::check_file("--out", path),
    }
}

/// One flag per frame of `range`: whether a resumed frame directory already holds it
/// whole (after its stale temporaries are removed); none without `--resume`.
fn kept_frames(
    output: &Output,
    resume: bool,
    range: Range<u64>,
    size: (usize, usize),
) -> Result<Vec<bool>, CliError> {
    match (output, resume) {
        (Output::Dir(dir), true) => {
            resume::remove_stale_temporaries(dir);
            resume::whole_frames(dir, range, size)
        }
        _ => Ok(vec![false; (range.end - range.start) as usize]),
    }
}

/// The number of frames in `seconds` at `fps`, checked against the limits.
fn frame_count(seconds: f64, fps: f64) -> Result<u64, CliError> {
    let (s, f) = (plain(seconds), plain(fps));
    if !(seconds.is_finite() && seconds > 0.0 && seconds <= MAX_SECONDS) {
        return Err(CliError::input(format!(
            "--seconds {s}: must be a number > 0 and at most {MAX_SECONDS}"
        )));
    }
    if !(fps.is_finite() && fps > 0.0 && fps <= MAX_FPS) {
        return Err(CliError::input(format!(
            "--fps {f}: must be a number > 0 and at most {MAX_FPS}"
        )));
    }
    let count = (seconds * fps).round();
    if count < 1.0 {
        // round(seconds × fps) >= 1 needs seconds >= 0.5 / fps.
        let needed = 0.5 / fps;
        let hint = if needed <= MAX_SECONDS {
            format!("give at least {} seconds at this rate", plain(needed))
        } else {
            format!(
                "even {MAX_SECONDS} seconds make none, so --fps must be at least 1/{}",
                2.0 * MAX_SECONDS
            )
        };
        return Err(CliError::input(format!(
            "--seconds {s} at --fps {f} makes no frame: {hint}"
        )));
    }
    if count > MAX_FRAMES as f64 {
        return Err(CliError::input(format!(
            "--seconds {s} at --fps {f} makes {count} frames; at most {MAX_FRAMES} are allowed"
        )));
    }
    Ok(count as u64)
}

/// Parses `A..B` and checks `A < B <= count`.
fn parse_range(text: &str, count: u64) -> Result<Range<u64>, CliError> {
    let bad = |why: &str| CliError::input(format!("--frames {text}: {why}"));
    let (a, b) = text
        .split_once("..")
        .ok_or_else(|| bad("write A..B, e.g. 0..30 (B excluded)"))?;
    let number = |s: &str| {
        s.trim()
            .parse::<u64>()
            .map_err(|_| bad(&format!("{s:?} is not a frame number")))
    };
    let (a, b) = (number(a)?, number(b)?);
    if a >= b {
        return Err(bad("A must be less than B (B is excluded)"));
    }
    if b > count {
        return Err(bad(&format!(
            "the animation has frames 0..{count} only (B is excluded)"
        )));
    }
    Ok(a..b)
}

/// What the frames depend on: the scene's contents, the renderer options, the frame
/// rate and the program version. `--seconds` and `--frames` are left out on purpose:
/// frame k is the same whatever the length or the part rendered.
fn manifest(args: &Args) -> Result<String, CliError> {
    let scene = Scene::resolve(Some(&args.scene))?;
    Ok(format!(
        "bubbles {}\nscene {}\nfps {}\n{:#?}\n{:#?}\n",
        env!("CARGO_PKG_VERSION"),
        scene.origin,
        args.fps,
        args.options,
        scene.file
    ))
}

/// Opens the output, checking early (before any rendering) that it can be written.
fn open(
    output: &Output,
    args: &Args,
    manifest: &str,
    (width, height): (usize, usize),
    frames: u64,
) -> Result<Sink, CliError> {
    let unwritable = |e: String| CliError::input(format!("--out {}: {e}", args.out.display()));
    match output {
        Output::Dir(dir) => {
            open_dir(dir, manifest).map_err(unwritable)?;
            Ok(Sink::Dir(dir.clone()))
        }
        Output::Apng(path) => {
            let frames = u32::try_from(frames).map_err(|e| unwritable(e.to_string()))?;
            apng::ApngSink::create(path, width as u32, height as u32, frames, args.fps)
                .map(Sink::Apng)
                .map_err(unwritable)
        }
        Output::Gif(path) => gif::GifSink::create(path, width, height, args.fps, !args.no_dither)
            .map(Sink::Gif)
            .map_err(unwritable),
    }
}

/// Creates the frame directory and records the manifest; refuses a directory whose
/// frames were made from another scene or with other settings, so that frames of two
/// animations never mix (several `--frames` runs of one animation share it).
fn open_dir(dir: &Path, manifest: &str) -> Result<(), String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create the directory: {e}"))?;
    let path = dir.join(MANIFEST);
    if let Ok(existing) = std::fs::read_to_string(&path) {
        // The settings, then one checksum line per frame written.
        let frames_only = |rest: &str| rest.lines().all(|l| l.starts_with("frame "));
        if existing.strip_prefix(manifest).is_some_and(frames_only) {
            return Ok(());
        }
        return Err(format!(
            "{} records another scene or other settings: use the same scene, --fps and \
             render options, or another (or emptied) directory",
            path.display()
        ));
    }
    if resume::has_frames(dir) {
        return Err(format!(
            "holds frames but no {MANIFEST}, so what they show is unknown: use another \
             (or emptied) directory"
        ));
    }
    let tmp = sink::temporary_beside(&path)?;
    std::fs::write(tmp.path(), manifest).map_err(|e| format!("cannot write {MANIFEST}: {e}"))?;
    tmp.persist(&path)
        .map(drop)
        .map_err(|e| format!("cannot write {MANIFEST}: {}", e.error))
}

/// Simulates and renders frames `range` into `sink`, skipping those `keep` marks (one
/// flag per frame of `range`: whole frames found on resume).
fn render_frames(
    job: &mut FrameJob,
    sink: &mut Sink,
    range: Range<u64>,
    keep: &[bool],
    args: &Args,
) -> CliResult {
    let mut bar = Progress::frames(range.end - range.start);
    let (exposure_ev, tonemap) = (job.settings().exposure_ev, job.settings().tonemap);
    for (k, &kept) in range.zip(keep) {
        crate::signals::check()?;
        if kept {
            bar.skip(1);
            continue;
        }
        // Each frame is reached from t = 0 by whole solver steps, so frame k does not
        // depend on which frames were rendered before it.
        job.advance_to(k as f64 / args.fps, false)?;
        let frame = job.render()?;
        crate::signals::check()?;
        let rgb = Rgb8 {
            width: frame.width(),
            height: frame.height(),
            bytes: frame.to_srgb8(exposure_ev, tonemap),
        };
        sink.push(k, &rgb)
            .map_err(|e| CliError::input(format!("frame {k}: {e}")))?;
        bar.inc(1);
    }
    bar.finish();
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_count_rounds_seconds_times_fps() {
        assert_eq!(frame_count(2.0, 15.0).unwrap(), 30);
        assert_eq!(frame_count(0.1, 24.0).unwrap(), 2);
    }

    #[test]
    fn frame_count_rejects_zero_negative_and_endless_input() {
        for (s, f, key) in [
            (1.0, 0.0, "--fps 0"),
            (-1.0, 15.0, "--seconds -1"),
            (f64::NAN, 15.0, "--seconds NaN"),
            (1.0, f64::INFINITY, "--fps inf"),
            (0.01, 15.0, "makes no frame"),
            (3600.0, 240.0, "at most 10000"),
        ] {
            let err = frame_count(s, f).unwrap_err();
            assert_eq!(err.exit_code(), 2);
            assert!(err.to_string().contains(key), "{err} lacks {key}");
        }
    }

    #[test]
    fn ranges_are_half_open_and_inside_the_animation() {
        assert_eq!(parse_range("3..7", 30).unwrap(), 3..7);
        assert_eq!(parse_range("0..30", 30).unwrap(), 0..30);
        for bad in ["7..3", "5..5", "0..31", "a..b", "3-7", "..4"] {
            let err = parse_range(bad, 30).unwrap_err();
            assert_eq!(err.exit_code(), 2);
            assert!(err.to_string().contains(bad), "{err}");
        }
    }
}
