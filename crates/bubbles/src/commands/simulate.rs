//! `bubbles simulate`: run a scene's bubble dynamics and report the final state as JSON
//! or text, optionally exporting one OBJ per output frame.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use bubble_dynamics::{Bubble, DVec3, Event, SimError, World};
use serde::Serialize;

use crate::error::{CliError, CliResult};
use crate::frame::progress::{Progress, advance_world, steps_to};
use crate::limits;
use crate::scene::Scene;
use crate::scene::values::{BubbleRadius, Num, plain};

/// Thickness written as vertex colour 1.0 in exported OBJ files: the tables' range.
pub const OBJ_FULL_SCALE_NM: f64 = lut::config::DEFAULT_THICKNESS_MAX_NM as f64;

/// What `simulate` prints and writes, for its `--help`.
const ABOUT_OUTPUT: &str = "Simulates the scene's bubbles (seed 000 §3: film tension, isothermal \
    gas, gravity, buoyancy, drag, contacts, drainage) for --seconds and prints each bubble's \
    centre, volume-equivalent radius, volume, pressure excess, film thickness (min, mean, max) \
    and kinetic energy, the step count, the wall time and any burst events.\n\n\
    --export-obj DIR writes DIR/frame_00000.obj, … at --fps frames per second (the first at \
    t = 0, the last at the end). Each bubble is an object `bubble_<id>` with vertex normals; \
    each vertex line is `v x y z r g b` with r = g = b = thickness / 4000 nm (clamped to 1), the \
    vertex-colour extension that Blender, MeshLab and most OBJ readers import as a colour \
    attribute, and the exact thicknesses follow as `#thickness_nm` comment lines, in vertex \
    order (with a film flow, its field sampled where each vertex sits, as the renderers \
    sample it). Files are written to a temporary name in DIR, then renamed.\n\n\
    --export-film DIR writes, at the same frames, DIR/film_<id>_00000.exr, … for every bubble \
    with a film flow (`film_grid` > 0): the film's cube-sphere grid as a 32-bit float EXR of \
    6n × n pixels, the faces side by side in OpenGL cube-map order (+X, −X, +Y, −Y, +Z, −Z; \
    each face's rows top to bottom, its texel (x, y) at s = (x + ½)·2/n − 1, t likewise), \
    R = thickness in nm (stretched by the mesh's deformation, as renderers draw it), \
    G = coverage (1 film, 0 burst hole), B = the film's temperature above the ambient in K \
    (0 unless the bubble has `bottom_warming_k`).";

/// Arguments of `bubbles simulate`.
#[derive(Debug, clap::Args)]
#[command(after_help = format!("{}\n\n{}", ABOUT_OUTPUT, limits::HELP))]
pub struct Args {
    /// A built-in scene name (`paper`, the default: two bubbles above a plane) or a TOML path.
    pub scene: Option<String>,
    /// Simulated duration, s.
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    pub seconds: f64,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
    /// Give every bubble of the scene this rest radius, m.
    #[arg(long, allow_negative_numbers = true)]
    pub radius_m: Option<f64>,
    /// Write one OBJ file per output frame into this directory (created if missing).
    #[arg(long)]
    pub export_obj: Option<PathBuf>,
    /// Write each bubble's film-flow field as an EXR per output frame into this directory.
    #[arg(long)]
    pub export_film: Option<PathBuf>,
    /// Output frames per second for --export-obj and --export-film.
    #[arg(long, default_value_t = 30.0, allow_negative_numbers = true)]
    pub fps: f64,
}

/// Runs `bubbles simulate`.
pub fn run(args: Args) -> CliResult {
    check_args(&args)?;
    let mut scene = Scene::resolve(args.scene.as_deref())?;
    if let Some(r) = args.radius_m {
        let radius = Num::<BubbleRadius>::try_new(r).map_err(|m| radius_error(r, &m))?;
        scene
            .file
            .bubbles
            .iter_mut()
            .for_each(|b| b.radius_m = radius);
    }
    scene.check_limits()?;
    let mut world = scene.dynamics_world().map_err(|e| match args.radius_m {
        Some(r) => CliError::input(format!("with --radius-m {}: {e}", plain(r))),
        None => e,
    })?;
    check_work(&scene, &world, &args)?;
    for (flag, dir) in [
        ("--export-obj", &args.export_obj),
        ("--export-film", &args.export_film),
    ] {
        if let Some(dir) = dir {
            crate::output::check_dir(flag, dir)?;
            std::fs::create_dir_all(dir).map_err(|e| {
                CliError::input(format!(
                    "{flag} {}: cannot create directory: {e}",
                    dir.display()
                ))
            })?;
        }
    }
    if args.export_film.is_some() && world.bubbles().iter().all(|b| b.film_flow().is_none()) {
        return Err(CliError::input(format!(
            "--export-film: no bubble of {} has a film flow (give a [[bubbles]] entry film_grid = 64)",
            scene.origin
        )));
    }
    let started = Instant::now();
    let (events, frames) = simulate(&mut world, &args).map_err(|failure| match failure {
        SimFailure::Solver(e) => crate::scene::sim_error(&scene, e),
        SimFailure::Write(e) => e,
    })?;
    let report = Report::new(
        &scene.origin,
        &args,
        &world,
        &events,
        frames,
        started.elapsed().as_secs_f64(),
    );
    let text = if args.json {
        report.json()?
    } else {
        report.text()
    };
    print!("{text}");
    Ok(())
}

fn check_args(args: &Args) -> CliResult {
    if !(args.seconds.is_finite() && args.seconds >= 0.0) {
        return Err(CliError::input(format!(
            "--seconds {} must be a finite number >= 0",
            plain(args.seconds)
        )));
    }
    if let Some(r) = args.radius_m
        && let Err(m) = Num::<BubbleRadius>::try_new(r)
    {
        return Err(radius_error(r, &m));
    }
    if !(args.fps.is_finite() && args.fps > 0.0) {
        return Err(CliError::input(format!(
            "--fps {} must be a finite number > 0",
            plain(args.fps)
        )));
    }
    Ok(())
}

fn radius_error(r: f64, message: &str) -> CliError {
    CliError::input(format!("--radius-m {}: {message}", plain(r)))
}

/// Refuses `--seconds` and `--fps` that would take too many steps or write too many files.
fn check_work(scene: &Scene, world: &World, args: &Args) -> CliResult {
    let what = format!("--seconds {}", plain(args.seconds));
    scene.check_steps(&what, world.time_s(), args.seconds, world.dt_s())?;
    if args.export_obj.is_some() || args.export_film.is_some() {
        let frames = (args.seconds * args.fps + 1e-9).floor() + 1.0;
        if frames > limits::MAX_OBJ_FRAMES as f64 {
            return Err(CliError::input(format!(
                "--seconds {} at --fps {} would write {frames:.3e} OBJ files, above the limit of {} (see --help)",
                plain(args.seconds),
                plain(args.fps),
                limits::MAX_OBJ_FRAMES
            )));
        }
    }
    Ok(())
}

/// Advances the world to `--seconds`, through every output frame when exporting;
/// returns the events and the number of frames written. A progress bar shows on stderr
/// when the solver takes more than about a second.
fn simulate(world: &mut World, args: &Args) -> Result<(Vec<Event>, usize), SimFailure> {
    let mut bar = Progress::steps(steps_to(world, args.seconds));
    let result = simulate_with(world, args, &mut bar);
    bar.finish();
    result
}

fn simulate_with(
    world: &mut World,
    args: &Args,
    bar: &mut Progress,
) -> Result<(Vec<Event>, usize), SimFailure> {
    if args.export_obj.is_none() && args.export_film.is_none() {
        return Ok((advance_world(world, args.seconds, bar)?, 0));
    }
    // The last frame lands exactly on --seconds; rounding protects k/fps = seconds.
    let last = (args.seconds * args.fps + 1e-9).floor() as usize;
    let mut events = Vec::new();
    for k in 0..=last {
        events.extend(advance_world(world, k as f64 / args.fps, bar)?);
        if let Some(dir) = &args.export_obj {
            write_atomic(&dir.join(format!("frame_{k:05}.obj")), &obj_text(world, k))
                .map_err(SimFailure::Write)?;
        }
        if let Some(dir) = &args.export_film {
            write_films(world, dir, k).map_err(SimFailure::Write)?;
        }
    }
    events.extend(advance_world(world, args.seconds, bar)?);
    Ok((events, last + 1))
}

/// Why [`simulate`] stopped: the solver, or writing a frame.
enum SimFailure {
    Solver(SimError),
    Write(CliError),
}

impl From<SimError> for SimFailure {
    fn from(e: SimError) -> Self {
        Self::Solver(e)
    }
}

/// The world's bubbles as one OBJ document (see the command's help for the layout).
pub fn obj_text(world: &World, frame: usize) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "# bubbles simulate: frame {frame}, t = {:.6} s",
        world.time_s()
    );
    let _ = writeln!(
        out,
        "# vertex colour r = g = b = min(thickness_nm / {OBJ_FULL_SCALE_NM}, 1); exact values in #thickness_nm lines"
    );
    let mut base = 1;
    for bubble in world.bubbles() {
        write_bubble(&mut out, bubble, base);
        base += bubble.positions_m().len();
    }
    out
}

/// Each vertex's film thickness, nm: with a film flow, its field where the vertex sits
/// (as the renderers sample it, stretch included); else the per-vertex film's.
fn vertex_thickness_nm(bubble: &Bubble) -> Vec<f64> {
    match crate::scene::bubble_film(bubble) {
        Some(film) => film
            .material_dirs
            .iter()
            .map(|d| f64::from(film.field.sample(*d).thickness_nm))
            .collect(),
        None => bubble.thickness_nm().to_vec(),
    }
}

fn write_bubble(out: &mut String, bubble: &Bubble, base: usize) {
    let _ = writeln!(out, "o bubble_{}", bubble.id());
    let thickness_nm = vertex_thickness_nm(bubble);
    for (x, d) in bubble.positions_m().iter().zip(&thickness_nm) {
        let c = (d / OBJ_FULL_SCALE_NM).min(1.0);
        let _ = writeln!(
            out,
            "v {:.7} {:.7} {:.7} {c:.6} {c:.6} {c:.6}",
            x.x, x.y, x.z
        );
    }
    for n in bubble.vertex_normals() {
        let _ = writeln!(out, "vn {:.6} {:.6} {:.6}", n.x, n.y, n.z);
    }
    for chunk in thickness_nm.chunks(16) {
        let values: Vec<String> = chunk.iter().map(|d| format!("{d:.4}")).collect();
        let _ = writeln!(out, "#thickness_nm {}", values.join(" "));
    }
    for t in bubble.triangles() {
        let [a, b, c] = t.map(|i| i as usize + base);
        let _ = writeln!(out, "f {a}//{a} {b}//{b} {c}//{c}");
    }
}

/// Writes every film-flow bubble's field as `dir/film_<id>_<frame>.exr` (see `--help`).
fn write_films(world: &World, dir: &Path, frame: usize) -> CliResult {
    for b in world.bubbles() {
        let Some(field) = b.film_field() else {
            continue;
        };
        let n = field.face_size;
        let warmth = b.film_flow().map_or(&[][..], |f| f.temperature_excess_k());
        let mut rgb = vec![[0.0f32; 3]; 6 * n * n];
        for (cell, (h, c)) in field.thickness_nm.iter().zip(&field.coverage).enumerate() {
            let (face, rest) = (cell / (n * n), cell % (n * n));
            let (y, x) = (rest / n, rest % n);
            let kelvin = warmth.get(cell).copied().unwrap_or(0.0);
            rgb[y * 6 * n + face * n + x] = [*h as f32, *c as f32, kelvin as f32];
        }
        let image = raster::Frame::try_from_rgb(6 * n, n, rgb)
            .ok_or_else(|| CliError::runtime(format!("film grid of face size {n} has no image")))?;
        let path = dir.join(format!("film_{}_{frame:05}.exr", b.id()));
        image
            .write_exr(&path)
            .map_err(|e| CliError::input(e.to_string()))?;
    }
    Ok(())
}

/// Writes `text` to a temporary file next to `path`, then renames it over `path`.
fn write_atomic(path: &Path, text: &str) -> CliResult {
    let tmp = path.with_extension("obj.tmp");
    std::fs::write(&tmp, text)
        .and_then(|()| std::fs::rename(&tmp, path))
        .map_err(|e| {
            let _ = std::fs::remove_file(&tmp);
            CliError::input(format!("cannot write {}: {e}", path.display()))
        })
}

/// What `simulate` prints.
#[derive(Debug, Serialize)]
struct Report {
    scene: String,
    seconds: f64,
    time_s: f64,
    dt_s: f64,
    steps: u64,
    substeps_last_step: u32,
    wall_time_s: f64,
    frames_written: usize,
    bubbles: Vec<BubbleReport>,
    events: Vec<EventReport>,
}

#[derive(Debug, Serialize)]
struct BubbleReport {
    id: u64,
    center_m: [f64; 3],
    radius_m: f64,
    volume_m3: f64,
    pressure_excess_pa: f64,
    thickness_nm: ThicknessReport,
    kinetic_energy_j: f64,
}

#[derive(Debug, Serialize)]
struct ThicknessReport {
    min: f64,
    mean: f64,
    max: f64,
}

#[derive(Debug, Serialize)]
struct EventReport {
    kind: &'static str,
    bubble_id: u64,
    step: u64,
    time_s: f64,
    center_m: [f64; 3],
    radius_m: f64,
    min_thickness_nm: f64,
}

impl Report {
    fn new(
        origin: &str,
        args: &Args,
        world: &World,
        events: &[Event],
        frames: usize,
        wall_time_s: f64,
    ) -> Self {
        Self {
            scene: origin.to_string(),
            seconds: args.seconds,
            time_s: world.time_s(),
            dt_s: world.dt_s(),
            steps: world.steps(),
            substeps_last_step: world.last_substeps(),
            wall_time_s,
            frames_written: frames,
            bubbles: world.bubbles().iter().map(BubbleReport::new).collect(),
            events: events.iter().map(EventReport::new).collect(),
        }
    }

    fn json(&self) -> Result<String, CliError> {
        serde_json::to_string_pretty(self)
            .map(|s| s + "\n")
            .map_err(|e| CliError::runtime(format!("cannot encode the report: {e}")))
    }

    fn text(&self) -> String {
        let mut out = String::new();
        let _ = writeln!(
            out,
            "{}: {} steps of {:.6} s to t = {:.4} s in {:.3} s wall time",
            self.scene, self.steps, self.dt_s, self.time_s, self.wall_time_s
        );
        for b in &self.bubbles {
            let [x, y, z] = b.center_m;
            let _ = writeln!(
                out,
                "bubble {}: centre ({x:.4}, {y:.4}, {z:.4}) m, radius {:.5} m, Δp {:.4} Pa, thickness {:.1}/{:.1}/{:.1} nm (min/mean/max), KE {:.3e} J",
                b.id,
                b.radius_m,
                b.pressure_excess_pa,
                b.thickness_nm.min,
                b.thickness_nm.mean,
                b.thickness_nm.max,
                b.kinetic_energy_j
            );
        }
        for e in &self.events {
            let _ = writeln!(
                out,
                "burst: bubble {} at t = {:.4} s (step {}), thinnest film {:.2} nm",
                e.bubble_id, e.time_s, e.step, e.min_thickness_nm
            );
        }
        if self.frames_written > 0 {
            let _ = writeln!(out, "wrote {} export frames", self.frames_written);
        }
        out
    }
}

impl BubbleReport {
    fn new(b: &Bubble) -> Self {
        Self {
            id: b.id(),
            center_m: array(b.center_m()),
            radius_m: b.radius_m(),
            volume_m3: b.volume_m3(),
            pressure_excess_pa: b.pressure_excess_pa(),
            thickness_nm: ThicknessReport {
                min: b.min_thickness_nm(),
                mean: b.mean_thickness_nm(),
                max: b.max_thickness_nm(),
            },
            kinetic_energy_j: b.kinetic_energy_j(),
        }
    }
}

impl EventReport {
    fn new(event: &Event) -> Self {
        match *event {
            Event::Burst {
                bubble_id,
                step,
                time_s,
                center_m,
                radius_m,
                min_thickness_nm,
            } => Self {
                kind: "burst",
                bubble_id,
                step,
                time_s,
                center_m: array(center_m),
                radius_m,
                min_thickness_nm,
            },
        }
    }
}

fn array(v: DVec3) -> [f64; 3] {
    v.to_array()
}
