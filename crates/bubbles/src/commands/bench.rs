//! `bubbles bench`: time whole frames (simulation + render) and print a breakdown.

use crate::error::{CliError, CliResult};
use crate::frame::{FrameJob, Options};
use crate::limits;
use std::time::Instant;

/// Arguments of `bubbles bench`.
#[derive(Debug, clap::Args)]
#[command(after_help = limits::HELP)]
pub struct Args {
    /// A scene file (.toml) or a built-in scene (default `paper`).
    pub scene: Option<String>,
    /// Frames timed at each size (after two warm-up frames), 1..=100000.
    #[arg(long, default_value_t = 50)]
    pub frames: u32,
    /// Image sizes to time, as WxH (repeatable; default: --width x --height when either
    /// is given, else 400x400 and 1920x1080).
    #[arg(long = "size", value_parser = parse_size)]
    pub sizes: Vec<(usize, usize)>,
    #[command(flatten)]
    pub options: Options,
}

/// Mean seconds per frame of each stage.
#[derive(Debug, Default, Clone, Copy)]
struct Breakdown {
    simulation_s: f64,
    /// The part of `simulation_s` the bubbles' film flows took (their steps' own clocks).
    film_s: f64,
    /// Baking the solver's state for the renderer: meshes, film fields, water surface.
    bake_s: f64,
    cube_maps_s: f64,
    /// Bubbles' cube maps rendered afresh per frame (CPU backend), the rest kept.
    cube_maps: Option<f64>,
    /// Triangle set-up and binning of the main view.
    setup_s: f64,
    opaque_s: f64,
    bubbles_s: f64,
    other_s: f64,
    total_s: f64,
}

/// Runs `bubbles bench`.
pub fn run(args: Args) -> CliResult {
    let sizes = match (
        args.sizes.is_empty(),
        args.options.width,
        args.options.height,
    ) {
        (false, ..) => args.sizes.clone(),
        (true, None, None) => vec![(400, 400), (1920, 1080)],
        (true, ..) => vec![args.options.size()],
    };
    if !(1..=limits::MAX_BENCH_FRAMES).contains(&args.frames) {
        return Err(CliError::input(format!(
            "--frames {} is outside 1..={} (see --help)",
            args.frames,
            limits::MAX_BENCH_FRAMES
        )));
    }
    let frames = args.frames;
    let options = args.options.real_time();
    let mut job = FrameJob::prepare(args.scene.as_deref(), &options)?;
    let mut report = String::new();
    report.push_str(&format!(
        "backend: {}, threads: {}, samples: {}, reflection: {:?}, cube-map reuse: {} texel, one solver step (dt = {:.6} s) per frame\n",
        job.backend_name(),
        rayon::current_num_threads(),
        job.settings().samples,
        job.settings().reflection,
        options.cube_map_reuse.unwrap_or(0.0),
        job.dt_s()
    ));
    report.push_str(
        "size        sim_ms  film_ms  bake_ms  cube_ms  cubes  setup_ms  opaque_ms  bubbles_ms  other_ms  frame_ms     fps\n",
    );
    for (w, h) in sizes {
        job.set_size(w, h)?;
        let b = time_frames(&mut job, frames)?;
        report.push_str(&format!(
            "{:<10} {:>7.3} {:>8.3} {:>8.3} {:>8.3} {:>6} {:>9.3} {:>10.3} {:>11.3} {:>9.3} {:>9.3} {:>7.1}\n",
            format!("{w}x{h}"),
            b.simulation_s * 1e3,
            b.film_s * 1e3,
            b.bake_s * 1e3,
            b.cube_maps_s * 1e3,
            b.cube_maps.map_or("-".to_string(), |c| format!("{c:.2}")),
            b.setup_s * 1e3,
            b.opaque_s * 1e3,
            b.bubbles_s * 1e3,
            b.other_s * 1e3,
            b.total_s * 1e3,
            1.0 / b.total_s
        ));
    }
    print!("{report}");
    Ok(())
}

fn time_frames(job: &mut FrameJob, frames: u32) -> Result<Breakdown, CliError> {
    for _ in 0..2 {
        job.step()?;
        job.render()?;
    }
    let mut sum = Breakdown::default();
    for _ in 0..frames {
        let film_before = film_step_time_s(job);
        let start = Instant::now();
        job.step()?;
        let sim = start.elapsed().as_secs_f64();
        sum.film_s += film_step_time_s(job) - film_before;
        let t = job.render()?.timings;
        let total = start.elapsed().as_secs_f64();
        let bake = job.last_bake_s();
        sum.simulation_s += sim;
        sum.bake_s += bake;
        sum.cube_maps_s += t.cube_maps_s;
        if let Some(c) = job.cube_maps_rendered() {
            *sum.cube_maps.get_or_insert(0.0) += c as f64;
        }
        sum.setup_s += t.setup_s;
        sum.opaque_s += t.opaque_s;
        sum.bubbles_s += t.bubbles_s;
        sum.other_s += total - sim - bake - t.cube_maps_s - t.setup_s - t.opaque_s - t.bubbles_s;
        sum.total_s += total;
    }
    let n = f64::from(frames);
    Ok(Breakdown {
        simulation_s: sum.simulation_s / n,
        film_s: sum.film_s / n,
        bake_s: sum.bake_s / n,
        cube_maps_s: sum.cube_maps_s / n,
        cube_maps: sum.cube_maps.map(|c| c / n),
        setup_s: sum.setup_s / n,
        opaque_s: sum.opaque_s / n,
        bubbles_s: sum.bubbles_s / n,
        other_s: sum.other_s / n,
        total_s: sum.total_s / n,
    })
}

/// Wall time the world's film stages have taken, s (its bubbles' flows step in
/// parallel: summing each bubble's own time counted them twice on two threads, and the
/// column then exceeded the simulation it is part of).
fn film_step_time_s(job: &FrameJob) -> f64 {
    job.world().film_wall_time_s()
}

fn parse_size(s: &str) -> Result<(usize, usize), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("{s:?}: expected WxH, e.g. 400x400"))?;
    let parse = |v: &str| {
        v.trim()
            .parse::<usize>()
            .ok()
            .filter(|n| (1..=limits::MAX_IMAGE_SIDE).contains(n))
    };
    match (parse(w), parse(h)) {
        (Some(w), Some(h)) => Ok((w, h)),
        _ => Err(format!(
            "{s:?}: width and height must be whole numbers in 1..={}",
            limits::MAX_IMAGE_SIDE
        )),
    }
}
