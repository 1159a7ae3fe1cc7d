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
/// Strongest slow motion: output 10 000× slower than real time (at 24 fps, 240 000
/// simulated frames per second, about what the fastest cameras film bursts with; a
/// rim moves half a film cell per sub-step, about 10 µs, so finer frames would repeat).
pub const MAX_SLOW_MOTION: f64 = 10_000.0;
/// Name of the file in a frame directory that records what the frames show.
pub const MANIFEST: &str = "animation.txt";

/// Arguments of `bubbles animate`.
#[derive(Debug, clap::Args)]
#[command(
    after_help = "Frame k shows the scene at t = k / fps (frame 0 at t = 0), \
    simulated with the scene's own solver step and rendered with --backend (the CPU \
    by default; wgpu in a build with the wgpu feature, the reference tracer too). \
    The animation has round(seconds × fps) frames, at most 10000, with seconds <= 3600 \
    and fps <= 240.\n\n\
    --start-s T simulates to T without rendering and starts there: frame k shows \
    t = T + k / (fps × K), where --slow-motion K (default 1, at most 10000) plays the \
    output K times slower than real time, and the animation has round(seconds × fps × K) \
    frames for its --seconds of simulated time (T + seconds <= 3600). With K other than \
    1 each frame shows the solver step at or before its t, and the holes of a bursting \
    film exactly at t (their rims move between steps, half a film cell at a time), so \
    `swirl --start-s 11.466 --seconds 0.007 --fps 30 --slow-motion 200` shows that \
    scene's burst (a hole opens at t = 11.467 s) in 42 frames, as high-speed video \
    does.\n\n\
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
    /// Simulated time of the first frame, s (>= 0; simulated to, not rendered).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub start_s: f64,
    /// Time scale: the output plays K times slower than real time (> 0, at most 10000).
    #[arg(
        long,
        value_name = "K",
        default_value_t = 1.0,
        allow_negative_numbers = true
    )]
    pub slow_motion: f64,
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
    let timing = Timing::checked(&args)?;
    let count = timing.count;
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
    // The last frame's time within the solver-step limit, before any file is written.
    job.check_reach(timing.frame_s(range.end - 1))?;
    let (width, height) = (job.settings().width, job.settings().height);
    let mut sink = open(
        &output,
        &args,
        &manifest,
        (width, height),
        range.end - range.start,
    )?;
    let keep = kept_frames(&output, args.resume, range.clone(), (width, height))?;
    render_frames(&mut job, &mut sink, range.clone(), &keep, &timing)?;
    let error = sink
        .finish()
        .map_err(|e| CliError::input(format!("cannot write {}: {e}", args.out.display())))?;
    eprintln!(
        "wrote frames {}..{} of {count} ({width}x{height}, {} fps{}) to {}",
        range.start,
        range.end,
        args.fps,
        slowed(&timing),
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

/// `, t = T s + k / (fps × K)` for a start or time scale other than the defaults.
fn slowed(timing: &Timing) -> String {
    if timing.start_s == 0.0 && timing.slow_motion == 1.0 {
        return String::new();
    }
    format!(
        ", t = {} s + k / {} (slow motion {}x)",
        plain(timing.start_s),
        plain(timing.frames_per_s),
        plain(timing.slow_motion)
    )
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

/// When each frame is: the checked `--start-s`, `--fps`, `--slow-motion` and the count.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Timing {
    start_s: f64,
    /// Frames per simulated second: fps × K.
    frames_per_s: f64,
    slow_motion: f64,
    count: u64,
}

impl Timing {
    /// Checks the timing flags against the limits.
    fn checked(args: &Args) -> Result<Self, CliError> {
        let (t, k) = (args.start_s, args.slow_motion);
        if !(t.is_finite() && (0.0..=MAX_SECONDS).contains(&t)) {
            return Err(CliError::input(format!(
                "--start-s {}: must be a number of seconds >= 0 and at most {MAX_SECONDS}",
                plain(t)
            )));
        }
        if !(k.is_finite() && k > 0.0 && k <= MAX_SLOW_MOTION) {
            return Err(CliError::input(format!(
                "--slow-motion {}: must be a number > 0 and at most {MAX_SLOW_MOTION}",
                plain(k)
            )));
        }
        let count = frame_count(args.seconds, args.fps, k)?;
        if t + args.seconds > MAX_SECONDS {
            return Err(CliError::input(format!(
                "--start-s {} + --seconds {} ends after {MAX_SECONDS} s",
                plain(t),
                plain(args.seconds)
            )));
        }
        Ok(Self {
            start_s: t,
            frames_per_s: args.fps * k,
            slow_motion: k,
            count,
        })
    }

    /// Simulated time of frame `k`, s.
    fn frame_s(&self, k: u64) -> f64 {
        self.start_s + k as f64 / self.frames_per_s
    }
}

/// The number of frames in `seconds` at `fps` slowed `slow_motion` times, checked against
/// the limits.
fn frame_count(seconds: f64, fps: f64, slow_motion: f64) -> Result<u64, CliError> {
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
    if slow_motion != 1.0 {
        return slowed_frame_count(seconds, fps, slow_motion);
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

/// [`frame_count`] at `fps` × `slow_motion` frames per simulated second.
fn slowed_frame_count(seconds: f64, fps: f64, slow_motion: f64) -> Result<u64, CliError> {
    let (s, f, k) = (plain(seconds), plain(fps), plain(slow_motion));
    let count = (seconds * fps * slow_motion).round();
    if count < 1.0 {
        return Err(CliError::input(format!(
            "--seconds {s} at --fps {f} and --slow-motion {k} makes no frame: give at least \
             {} seconds",
            plain(0.5 / (fps * slow_motion))
        )));
    }
    if count > MAX_FRAMES as f64 {
        return Err(CliError::input(format!(
            "--seconds {s} at --fps {f} and --slow-motion {k} makes {count} frames; at most \
             {MAX_FRAMES} are allowed"
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
/// rate, the start and time scale, and the program version. `--seconds` and `--frames`
/// are left out on purpose: frame k is the same whatever the length or the part
/// rendered. The start and time scale appear only when not the defaults, so directories
/// made before they existed still resume.
fn manifest(args: &Args) -> Result<String, CliError> {
    let scene = Scene::resolve(Some(&args.scene))?;
    let timing = if args.start_s == 0.0 && args.slow_motion == 1.0 {
        String::new()
    } else {
        format!(
            "start_s {}\nslow_motion {}\n",
            plain(args.start_s),
            plain(args.slow_motion)
        )
    };
    Ok(format!(
        "bubbles {}\nscene {}\nfps {}\n{timing}{:#?}\n{:#?}\n",
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
            "{} records another scene or other settings: use the same scene, --fps, \
             --start-s, --slow-motion and render options, or another (or emptied) directory",
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
    timing: &Timing,
) -> CliResult {
    let mut bar = Progress::frames(range.end - range.start);
    let (exposure_ev, tonemap) = (job.settings().exposure_ev, job.settings().tonemap);
    for (k, &kept) in range.zip(keep) {
        crate::signals::check()?;
        if kept {
            bar.skip(1);
            continue;
        }
        // Each frame is reached from t = 0 by whole solver steps (and, in slow motion,
        // the rims' own sub-steps, which do not depend on where they stopped before), so
        // frame k does not depend on which frames were rendered before it.
        if timing.slow_motion == 1.0 {
            job.advance_to(timing.frame_s(k), false)?;
        } else {
            job.advance_to_instant(timing.frame_s(k))?;
        }
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
        assert_eq!(frame_count(2.0, 15.0, 1.0).unwrap(), 30);
        assert_eq!(frame_count(0.1, 24.0, 1.0).unwrap(), 2);
        assert_eq!(frame_count(0.01, 30.0, 200.0).unwrap(), 60);
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
            let err = frame_count(s, f, 1.0).unwrap_err();
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
