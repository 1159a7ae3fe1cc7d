//! One frame's work shared by `render` and `bench`: scene → solver → tables → renderer.

mod gpu;
pub mod progress;
pub mod reference;

use crate::error::CliError;
use crate::limits;
use crate::scene::schema::RenderSpec;
use crate::scene::values::{Exposure, Num, plain};
use crate::scene::{Scene, bubble_meshes};
use bubble_dynamics::{BubbleParams, Event, World};
use lut::LutSet;
use raster::{
    Camera, FilmTables, Frame, ReflectionMode, RenderScene, RenderSettings, Renderer,
    SAMPLE_COUNTS, SphereMap, ToneMap,
};
use std::sync::Arc;

/// Renderer options shared by `render` and `bench` (flags override the scene's `[render]`).
#[derive(Debug, Clone, Default, clap::Args)]
pub struct Options {
    /// Image width in pixels, 1..=16384 (default 800).
    #[arg(long)]
    pub width: Option<usize>,
    /// Image height in pixels, 1..=16384 (default 600).
    #[arg(long)]
    pub height: Option<usize>,
    /// Anti-aliasing samples per pixel: 1, 4, 8, 9 or 16 (default: the scene's, else 4).
    #[arg(long)]
    pub samples: Option<u32>,
    /// Rendering backend: the real-time CPU rasteriser, the same frame on the GPU through
    /// wgpu (needs a build with `--features wgpu`), or the spectral reference tracer.
    #[arg(long, value_enum, default_value_t = Backend::Cpu)]
    pub backend: Backend,
    #[command(flatten)]
    pub reference: reference::ReferenceOptions,
    /// Bubble reflections: dynamic cube maps, the static environment, or a sphere map (seed 002).
    #[arg(long, value_enum)]
    pub reflection: Option<Reflection>,
    /// Face size of the dynamic cube maps, 1..=1024 texels (default: the scene's, else 128).
    #[arg(long)]
    pub cube_map_size: Option<usize>,
    /// Film-table columns over thickness, 2..=16384 (default: the scene's, else 4096).
    #[arg(long)]
    pub lut_thickness_samples: Option<usize>,
    /// Film-table rows over cos θ, 2..=1024 (default: the scene's, else 128).
    #[arg(long)]
    pub lut_angle_samples: Option<usize>,
    /// CPU backend: how a bubble pixel a triangle covers only in part is shaded: once per
    /// bubble layer (about a third fewer shadings), or once per triangle, as the wgpu backend
    /// does (to compare the two backends like for like).
    #[arg(long, value_enum, default_value_t = PartialShading::PerSurface)]
    pub partial_shading: PartialShading,
    /// Exposure multiplier applied before tone mapping (default: the scene's, else 1).
    #[arg(long)]
    pub exposure: Option<f64>,
    /// Tone curve for PNG output (default: the scene's, else aces).
    #[arg(long, value_enum)]
    pub tonemap: Option<Tone>,
}

impl Options {
    /// `--width` and `--height`, or 800 × 600.
    pub fn size(&self) -> (usize, usize) {
        (self.width.unwrap_or(800), self.height.unwrap_or(600))
    }
}

/// Rendering backends.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum Backend {
    /// The pure-CPU sorted-triangle renderer.
    #[default]
    Cpu,
    /// The same pipeline on the GPU through wgpu (Vulkan; a build with `--features wgpu`).
    Wgpu,
    /// The spectral reference ray tracer (slow; the truth the CPU backend is measured against).
    Reference,
}

/// Where bubble reflections come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Reflection {
    /// A cube map of the scene rendered from each bubble's centre, every frame.
    Dynamic,
    /// The environment alone (fastest; no ground or objects in reflections).
    Static,
    /// A sphere map made from the environment (seed 002).
    SphereMap,
}

/// How the CPU backend shades partly covered bubble pixels (`raster::PartialShading`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum PartialShading {
    /// Once per pixel and bubble layer, shared by neighbouring triangles.
    #[default]
    PerSurface,
    /// Once per triangle (the wgpu backend's rule).
    PerTriangle,
}

/// Tone curves.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Tone {
    /// Hill's ACES fit.
    Aces,
    /// x / (1 + x).
    Reinhard,
    /// Clamp to [0, 1].
    Clamp,
}

/// The CPU renderer with `--partial-shading` applied.
fn renderer(options: &Options) -> Renderer {
    let mut renderer = Renderer::new();
    renderer.set_partial_shading(match options.partial_shading {
        PartialShading::PerSurface => raster::PartialShading::PerSurface,
        PartialShading::PerTriangle => raster::PartialShading::PerTriangle,
    });
    renderer
}

/// Size of the sphere map made from the environment in sphere-map mode.
const SPHERE_MAP_SIZE: usize = 512;

/// A scene ready to simulate and render, frame after frame.
pub struct FrameJob {
    scene: Scene,
    world: World,
    render_scene: RenderScene,
    tables: FilmTables,
    settings: RenderSettings,
    renderer: Renderer,
    /// The wgpu renderer when `--backend wgpu`.
    gpu: Option<gpu::GpuBackend>,
    /// The film for the reference backend; `None` for the CPU backend.
    film_spec: Option<reference_tracer::FilmSpec>,
    reference: reference::ReferenceOptions,
    reference_frame: Frame,
    /// The water's geometry, evaluated at the solver's time each frame.
    water: Option<water::Surface>,
}

impl FrameJob {
    /// Loads the scene, builds the world, bakes the tables and checks the settings.
    pub fn prepare(scene_arg: Option<&str>, options: &Options) -> Result<Self, CliError> {
        Self::from_scene(Scene::resolve(scene_arg)?, options)
    }

    /// [`FrameJob::prepare`] for a scene already parsed.
    pub fn from_scene(scene: Scene, options: &Options) -> Result<Self, CliError> {
        scene.check_limits()?;
        let world = scene.dynamics_world()?;
        let (width, height) = lut_size(&scene, options)?;
        let luts = scene.bake_tables(width, height)?;
        let mut render_scene = scene.render_scene()?;
        render_scene.lights = scene.raster_lights(&luts)?;
        render_scene.water = scene.water_optics()?;
        let water = scene.water_surface()?;
        if water.is_some() && options.backend == Backend::Reference {
            return Err(CliError::input(format!(
                "{}: the reference backend does not draw water yet: use --backend cpu",
                scene.origin
            )));
        }
        let settings = settings(&scene, &render_scene, options)?;
        let film_spec = match options.backend {
            Backend::Cpu | Backend::Wgpu => None,
            Backend::Reference => Some(scene.film_spec(&render_scene.lights)?),
        };
        let gpu = match options.backend {
            Backend::Wgpu => Some(gpu::GpuBackend::open()?),
            Backend::Cpu | Backend::Reference => None,
        };
        Ok(Self {
            gpu,
            film_spec,
            reference: options.reference.clone(),
            reference_frame: Frame::default(),
            tables: film_tables(luts),
            scene,
            world,
            render_scene,
            settings,
            renderer: renderer(options),
            water,
        })
    }

    /// The scene's own `time_s`.
    pub fn scene_time_s(&self) -> f64 {
        self.scene.file.time_s.get()
    }

    /// Simulated time so far, in seconds.
    pub fn time_s(&self) -> f64 {
        self.world.time_s()
    }

    /// Dynamic cube maps a frame renders: one per bubble, one for the water.
    fn cube_maps(&self) -> usize {
        self.bubble_count() + usize::from(self.water.is_some())
    }

    /// Number of bubbles still alive.
    pub fn bubble_count(&self) -> usize {
        self.world.bubbles().len()
    }

    /// The backend in use, for reports (`"wgpu on <adapter>"` for the GPU backend).
    pub fn backend_name(&self) -> String {
        match (&self.gpu, &self.film_spec) {
            (Some(gpu), _) => format!("wgpu on {}", gpu.adapter_name()),
            (None, Some(_)) => "reference".to_string(),
            (None, None) => "cpu".to_string(),
        }
    }

    /// The render settings in force.
    pub fn settings(&self) -> &RenderSettings {
        &self.settings
    }

    /// Advances the simulation to `time_s` (the step nearest it), with a progress bar on
    /// stderr when asked and the solver takes more than about a second.
    pub fn advance_to(&mut self, time_s: f64, show_progress: bool) -> Result<(), CliError> {
        if !(time_s.is_finite() && time_s >= 0.0) {
            return Err(CliError::input(format!(
                "--time-s {}: must be a finite number of seconds >= 0",
                plain(time_s)
            )));
        }
        let what = format!("advancing to t = {} s", plain(time_s));
        let (now_s, dt_s) = (self.world.time_s(), self.world.dt_s());
        self.scene.check_steps(&what, now_s, time_s, dt_s)?;
        let steps = progress::steps_to(&self.world, time_s).saturating_sub(self.world.steps());
        let mut bar = if show_progress {
            progress::Progress::steps(steps)
        } else {
            progress::Progress::off()
        };
        progress::advance_world(&mut self.world, time_s, &mut bar)
            .map_err(|e| CliError::runtime(format!("simulation failed: {e}")))?;
        bar.finish();
        Ok(())
    }

    /// One solver step.
    pub fn step(&mut self) -> Result<(), CliError> {
        self.world
            .step()
            .map(drop)
            .map_err(|e| crate::scene::sim_error(&self.scene, e))
    }

    /// The solver's time step, in seconds.
    pub fn dt_s(&self) -> f64 {
        self.world.dt_s()
    }

    /// Renders the current state: the bubbles and the water at the solver's time.
    pub fn render(&mut self) -> Result<&Frame, CliError> {
        self.render_scene.bubbles = bubble_meshes(&self.world);
        if let (Some(surface), Some(out)) = (&mut self.water, &mut self.render_scene.water) {
            let mesh = surface.evaluate(self.world.time_s());
            out.positions.clone_from(&mesh.positions);
            out.normals.clone_from(&mesh.normals);
            if out.triangles.len() != mesh.triangles.len() {
                out.triangles.clone_from(&mesh.triangles);
            }
        }
        if let Some(spec) = &self.film_spec {
            let settings = self.reference.settings(&self.settings);
            self.reference_frame = reference::render(&self.render_scene, spec, &settings, true)?;
            return Ok(&self.reference_frame);
        }
        if let Some(gpu) = &mut self.gpu {
            return gpu
                .render(&self.render_scene, &self.tables, &self.settings)
                .map_err(|e| CliError::input(format!("{}: {e}", self.scene.origin)));
        }
        self.renderer
            .render(&self.render_scene, &self.tables, &self.settings)
            .map_err(|e| CliError::input(format!("{}: {e}", self.scene.origin)))
    }

    /// One solver step, returning what happened (bursts).
    pub fn step_events(&mut self) -> Result<Vec<Event>, CliError> {
        self.world
            .step()
            .map_err(|e| CliError::runtime(format!("simulation failed: {e}")))
    }

    /// The solver's world, for changes between steps (wind, new bubbles, pokes).
    pub fn world_mut(&mut self) -> &mut World {
        &mut self.world
    }

    /// The solver's world.
    pub fn world(&self) -> &World {
        &self.world
    }

    /// Rebuilds the world from the scene, back to t = 0.
    pub fn reset(&mut self) -> Result<(), CliError> {
        self.world = self.scene.dynamics_world()?;
        Ok(())
    }

    /// The scene's first bubble (a template for blowing new ones), if it has any.
    pub fn bubble_template(&self) -> Option<BubbleParams> {
        self.scene
            .file
            .bubbles
            .first()
            .map(crate::scene::bubble_params)
    }

    /// The camera in force.
    pub fn camera(&self) -> Camera {
        self.render_scene.camera
    }

    /// Replaces the camera.
    pub fn set_camera(&mut self, camera: Camera) {
        self.render_scene.camera = camera;
    }

    /// The scene's camera target, m.
    pub fn scene_target_m(&self) -> [f64; 3] {
        self.scene.file.camera.target_m.get()
    }

    /// Rebuilds the settings from new options (keeps the scene's values where a flag is unset).
    pub fn set_options(&mut self, options: &Options) -> Result<(), CliError> {
        self.settings = settings(&self.scene, &self.render_scene, options)?;
        Ok(())
    }

    /// Replaces the image size (for benchmarks at several sizes).
    ///
    /// # Errors
    /// When the new size's buffers pass the memory limit.
    pub fn set_size(&mut self, width: usize, height: usize) -> Result<(), CliError> {
        check_memory(self.cube_maps(), &self.settings, width, height)?;
        self.settings.width = width;
        self.settings.height = height;
        Ok(())
    }
}

/// The renderer's tables. A soap film is lossless, so `lut` bakes `T = 1 − R` and the
/// renderer derives the same value from `R` itself: leaving the transmittance table out
/// halves the table memory read per fragment (a cache-bound cost) with identical output.
fn film_tables(luts: LutSet) -> FilmTables {
    FilmTables {
        reflectivity: luts.reflectivity,
        transmittance: None,
        lights: luts.lights.into_iter().map(|(_, lut)| lut).collect(),
    }
}

fn settings(
    scene: &Scene,
    render_scene: &RenderScene,
    o: &Options,
) -> Result<RenderSettings, CliError> {
    let r = &scene.file.render;
    let reflection = match (o.reflection, r.reflection.as_deref()) {
        (Some(Reflection::Dynamic), _) | (None, None | Some("dynamic")) => {
            ReflectionMode::DynamicCubeMap {
                face_size: cube_map_size(o, r)?,
            }
        }
        (Some(Reflection::Static), _) | (None, Some("static")) => ReflectionMode::StaticEnvironment,
        (Some(Reflection::SphereMap), _) | (None, Some("sphere-map")) => {
            let map = SphereMap::from_environment(
                &render_scene.environment,
                SPHERE_MAP_SIZE,
                raster::Mat3::IDENTITY,
            )
            .map_err(|e| CliError::input(e.to_string()))?;
            ReflectionMode::SphereMap(Arc::new(map))
        }
        (None, Some(other)) => {
            return Err(CliError::input(format!(
                "{}: render.reflection {other:?}: use dynamic, static or sphere-map",
                scene.origin
            )));
        }
    };
    let tonemap = match (o.tonemap, r.tonemap.as_deref()) {
        (Some(Tone::Aces), _) | (None, None | Some("aces")) => ToneMap::AcesFitted,
        (Some(Tone::Reinhard), _) | (None, Some("reinhard")) => ToneMap::Reinhard,
        (Some(Tone::Clamp), _) | (None, Some("clamp")) => ToneMap::Clamp,
        (None, Some(other)) => {
            return Err(CliError::input(format!(
                "{}: render.tonemap {other:?}: use aces, reinhard or clamp",
                scene.origin
            )));
        }
    };
    let exposure = match o.exposure {
        Some(e) => Num::<Exposure>::try_new(e)
            .map_err(|m| CliError::input(format!("--exposure {}: {m}", plain(e))))?
            .get(),
        None => r.exposure.map_or(1.0, Num::get),
    };
    let (width, height) = o.size();
    for (flag, side) in [("--width", width), ("--height", height)] {
        check_side(flag, side)?;
    }
    let settings = RenderSettings {
        width,
        height,
        samples: samples(scene, o, r)?,
        reflection,
        exposure_ev: exposure.log2() as f32,
        tonemap,
        draw_lights: true,
    };
    settings
        .validate()
        .map_err(|e| CliError::input(e.to_string()))?;
    // One cube map per bubble, and one for the water's reflections.
    let cube_maps = scene.file.bubbles.len() + usize::from(scene.file.water.is_some());
    check_memory(cube_maps, &settings, width, height)?;
    Ok(settings)
}

/// The cube-map face size from `--cube-map-size`, else `[render] cube_map_size`, else 128.
fn cube_map_size(o: &Options, r: &RenderSpec) -> Result<usize, CliError> {
    match o.cube_map_size {
        Some(s) if (1..=limits::MAX_CUBE_MAP_SIZE).contains(&s) => Ok(s),
        Some(s) => Err(CliError::input(format!(
            "--cube-map-size {s} is outside 1..={} texels (see --help)",
            limits::MAX_CUBE_MAP_SIZE
        ))),
        None => Ok(r.cube_map_size.map_or(128, |s| s.get() as usize)),
    }
}

/// The film tables' size: each side from its flag, else `[render]`, else `lut`'s default;
/// refused when the tables (one per distinct light spectrum, plus the reflectivity) would
/// pass the memory limit.
fn lut_size(scene: &Scene, o: &Options) -> Result<(usize, usize), CliError> {
    let r = &scene.file.render;
    let side = |flag: Option<usize>, name: &str, max: usize, key: Option<u32>, default: usize| {
        match flag {
            Some(v) if (2..=max).contains(&v) => Ok(v),
            Some(v) => Err(CliError::input(format!(
                "--{name} {v} is outside 2..={max} (see --help)"
            ))),
            None => Ok(key.map_or(default, |k| k as usize)),
        }
    };
    let width = side(
        o.lut_thickness_samples,
        "lut-thickness-samples",
        limits::MAX_LUT_THICKNESS_SAMPLES,
        r.lut_thickness_samples.map(|c| c.get()),
        lut::config::DEFAULT_WIDTH,
    )?;
    let height = side(
        o.lut_angle_samples,
        "lut-angle-samples",
        limits::MAX_LUT_ANGLE_SAMPLES,
        r.lut_angle_samples.map(|c| c.get()),
        lut::config::DEFAULT_HEIGHT,
    )?;
    let tables = 1 + scene.file.lights.len();
    let bytes = limits::lut_bytes(width, height, tables);
    if bytes > limits::MEMORY_BUDGET_BYTES {
        return Err(CliError::input(format!(
            "{tables} film tables of {width}x{height} (lut_thickness_samples x lut_angle_samples) need {:.2} GiB, above the {} GiB limit (see --help)",
            bytes as f64 / f64::from(1u32 << 30),
            limits::MEMORY_BUDGET_BYTES >> 30
        )));
    }
    Ok((width, height))
}

/// Samples per pixel from `--samples`, else `[render] samples`, else 4.
fn samples(scene: &Scene, o: &Options, r: &RenderSpec) -> Result<u32, CliError> {
    let (value, key) = match (o.samples, r.samples) {
        (Some(s), _) => (s, "--samples".to_string()),
        (None, Some(s)) => (s.get(), format!("{}: render.samples =", scene.origin)),
        (None, None) => return Ok(4),
    };
    if SAMPLE_COUNTS.contains(&value) {
        Ok(value)
    } else {
        Err(CliError::input(format!(
            "{key} {value} must be one of {SAMPLE_COUNTS:?}"
        )))
    }
}

/// Refuses an image side outside `1..=MAX_IMAGE_SIDE`, naming the flag.
pub fn check_side(flag: &str, side: usize) -> Result<(), CliError> {
    if (1..=limits::MAX_IMAGE_SIDE).contains(&side) {
        Ok(())
    } else {
        Err(CliError::input(format!(
            "{flag} {side} is outside 1..={} pixels (see --help)",
            limits::MAX_IMAGE_SIDE
        )))
    }
}

fn check_memory(
    bubbles: usize,
    settings: &RenderSettings,
    width: usize,
    height: usize,
) -> Result<(), CliError> {
    let cube = match settings.reflection {
        ReflectionMode::DynamicCubeMap { face_size } => Some(face_size),
        _ => None,
    };
    crate::scene::check_memory(bubbles, cube, width, height, settings.samples)
}
