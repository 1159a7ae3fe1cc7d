//! One frame's work shared by `render` and `bench`: scene → solver → tables → renderer.

use crate::error::CliError;
use crate::scene::{Scene, bubble_meshes};
use bubble_dynamics::{BubbleParams, Event, World};
use lut::LutSet;
use raster::{
    Camera, FilmTables, Frame, ReflectionMode, RenderScene, RenderSettings, Renderer, SphereMap,
    ToneMap,
};
use std::sync::Arc;

/// Renderer options shared by `render` and `bench` (flags override the scene's `[render]`).
#[derive(Debug, Clone, Default, clap::Args)]
pub struct Options {
    /// Image width in pixels.
    #[arg(long, default_value_t = 800)]
    pub width: usize,
    /// Image height in pixels.
    #[arg(long, default_value_t = 600)]
    pub height: usize,
    /// Anti-aliasing samples per pixel: 1, 4, 8, 9 or 16 (default: the scene's, else 4).
    #[arg(long)]
    pub samples: Option<u32>,
    /// Rendering backend (only the CPU backend exists).
    #[arg(long, value_enum, default_value_t = Backend::Cpu)]
    pub backend: Backend,
    /// Bubble reflections: dynamic cube maps, the static environment, or a sphere map (seed 002).
    #[arg(long, value_enum)]
    pub reflection: Option<Reflection>,
    /// Face size of the dynamic cube maps, in texels (default: the scene's, else 128).
    #[arg(long)]
    pub cube_map_size: Option<usize>,
    /// Exposure multiplier applied before tone mapping (default: the scene's, else 1).
    #[arg(long)]
    pub exposure: Option<f64>,
    /// Tone curve for PNG output (default: the scene's, else aces).
    #[arg(long, value_enum)]
    pub tonemap: Option<Tone>,
}

/// Rendering backends.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum Backend {
    /// The pure-CPU sorted-triangle renderer.
    #[default]
    Cpu,
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
}

impl FrameJob {
    /// Loads the scene, builds the world, bakes the tables and checks the settings.
    pub fn prepare(scene_arg: Option<&str>, options: &Options) -> Result<Self, CliError> {
        let scene = Scene::resolve(scene_arg)?;
        let world = scene.dynamics_world()?;
        let luts = scene.bake_tables()?;
        let mut render_scene = scene.render_scene()?;
        render_scene.lights = scene.raster_lights(&luts)?;
        let settings = settings(&scene, &render_scene, options)?;
        Ok(Self {
            tables: film_tables(luts),
            scene,
            world,
            render_scene,
            settings,
            renderer: Renderer::new(),
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

    /// Number of bubbles still alive.
    pub fn bubble_count(&self) -> usize {
        self.world.bubbles().len()
    }

    /// The render settings in force.
    pub fn settings(&self) -> &RenderSettings {
        &self.settings
    }

    /// Advances the simulation to `time_s`, with a progress bar on stderr when asked.
    pub fn advance_to(&mut self, time_s: f64, progress: bool) -> Result<(), CliError> {
        if !(time_s.is_finite() && time_s >= 0.0) {
            return Err(CliError::input(format!(
                "--time-s {time_s}: must be a finite number of seconds >= 0"
            )));
        }
        let steps = ((time_s - self.world.time_s()) / self.world.dt_s())
            .ceil()
            .max(0.0) as u64;
        let bar = (progress && steps > 0).then(|| indicatif::ProgressBar::new(steps));
        while self.world.time_s() < time_s - 0.5 * self.world.dt_s() {
            self.step()?;
            if let Some(bar) = &bar {
                bar.inc(1);
            }
        }
        if let Some(bar) = bar {
            bar.finish_and_clear();
        }
        Ok(())
    }

    /// One solver step.
    pub fn step(&mut self) -> Result<(), CliError> {
        self.world
            .step()
            .map(drop)
            .map_err(|e| CliError::runtime(format!("simulation failed: {e}")))
    }

    /// The solver's time step, in seconds.
    pub fn dt_s(&self) -> f64 {
        self.world.dt_s()
    }

    /// Renders the current state.
    pub fn render(&mut self) -> Result<&Frame, CliError> {
        self.render_scene.bubbles = bubble_meshes(&self.world);
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
    pub fn set_size(&mut self, width: usize, height: usize) {
        self.settings.width = width;
        self.settings.height = height;
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
                face_size: o
                    .cube_map_size
                    .or(r.cube_map_size.map(|s| s as usize))
                    .unwrap_or(128),
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
    let exposure = o.exposure.or(r.exposure.map(|e| e.get())).unwrap_or(1.0);
    if !(exposure.is_finite() && exposure > 0.0) {
        return Err(CliError::input(format!(
            "--exposure {exposure}: must be a finite number > 0"
        )));
    }
    let settings = RenderSettings {
        width: o.width,
        height: o.height,
        samples: o.samples.or(r.samples).unwrap_or(4),
        reflection,
        exposure_ev: exposure.log2() as f32,
        tonemap,
        draw_lights: true,
    };
    settings
        .validate()
        .map_err(|e| CliError::input(e.to_string()))?;
    Ok(settings)
}
