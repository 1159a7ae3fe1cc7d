//! One frame's work shared by `render` and `bench`: scene → solver → tables → renderer.

pub mod gpu;
mod options;
pub mod progress;
pub mod reference;
mod settings;

pub use options::{Backend, Options, PartialShading, Reflection, Tone};
use settings::{check_memory, lut_size, settings};

use crate::error::CliError;
use crate::scene::values::plain;
use crate::scene::{Scene, bubble_meshes};
use bubble_dynamics::{BubbleParams, Event, World};
use lut::LutSet;
use raster::{Camera, CubeMapReuse, FilmTables, Frame, RenderScene, RenderSettings, Renderer};

/// The CPU renderer with `--partial-shading`, `--reflection-origin` and
/// `--cube-map-reuse` applied.
fn renderer(options: &Options) -> Result<Renderer, CliError> {
    let mut renderer = Renderer::new();
    renderer.set_cube_map_reuse(cube_map_reuse(options)?);
    renderer.set_reflection_parallax(options.reflection_origin.parallax());
    renderer.set_partial_shading(match options.partial_shading {
        PartialShading::PerSurface => raster::PartialShading::PerSurface,
        PartialShading::PerTriangle => raster::PartialShading::PerTriangle,
    });
    Ok(renderer)
}

/// `--cube-map-reuse`, checked (off when not given).
fn cube_map_reuse(options: &Options) -> Result<CubeMapReuse, CliError> {
    let Some(texels) = options.cube_map_reuse else {
        return Ok(CubeMapReuse::OFF);
    };
    CubeMapReuse::new(texels).ok_or_else(|| {
        CliError::input(format!(
            "--cube-map-reuse {texels} is outside 0..={} texels",
            CubeMapReuse::MAX_TEXELS
        ))
    })
}

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
    /// Wall time the last [`FrameJob::render`] took to bake the solver's state for the
    /// renderer, s.
    bake_s: f64,
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
            Backend::Reference => {
                reference::check_work(&options.reference.settings(&settings))?;
                Some(scene.film_spec(&render_scene.lights)?)
            }
        };
        let gpu = match options.backend {
            Backend::Wgpu => Some(gpu::GpuBackend::open(options.reflection_origin.parallax())?),
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
            renderer: renderer(options)?,
            water,
            bake_s: 0.0,
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

    /// How many bubbles' dynamic cube maps the last CPU frame rendered afresh (the others
    /// were kept, `--cube-map-reuse`); `None` for the other backends.
    pub fn cube_maps_rendered(&self) -> Option<usize> {
        (self.gpu.is_none() && self.film_spec.is_none()).then(|| self.renderer.cube_maps_rendered())
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
        crate::signals::check()
    }

    /// Refuses, before any work, a `time_s` beyond the solver-step limit from here.
    pub fn check_reach(&self, time_s: f64) -> Result<(), CliError> {
        let what = format!("advancing to t = {} s", plain(time_s));
        let (now_s, dt_s) = (self.world.time_s(), self.world.dt_s());
        self.scene.check_steps(&what, now_s, time_s, dt_s)
    }

    /// Advances the simulation to the last step at or before `time_s`, then the rims of
    /// any bursting film to `time_s` itself (`World::advance_rims_to`): a burst's rims
    /// cross a bubble within a few steps, and slow motion shows them between steps.
    pub fn advance_to_instant(&mut self, time_s: f64) -> Result<(), CliError> {
        if !(time_s.is_finite() && time_s >= 0.0) {
            return Err(CliError::input(format!(
                "--start-s {}: must be a finite number of seconds >= 0",
                plain(time_s)
            )));
        }
        self.check_reach(time_s)?;
        let target = progress::steps_by(&self.world, time_s);
        let failed = |e| CliError::runtime(format!("simulation failed: {e}"));
        progress::advance_world_steps(&mut self.world, target, &mut progress::Progress::off())
            .map_err(failed)?;
        crate::signals::check()?;
        self.world.advance_rims_to(time_s).map_err(failed)
    }

    /// One solver step.
    pub fn step(&mut self) -> Result<(), CliError> {
        self.world
            .step()
            .map(drop)
            .map_err(|e| crate::scene::sim_error(&self.scene, e))
    }

    /// Wall time the last [`FrameJob::render`] spent baking the solver's state into the
    /// renderer's scene (bubble meshes, their film fields as cube-map textures, the water
    /// surface), s.
    pub fn last_bake_s(&self) -> f64 {
        self.bake_s
    }

    /// The solver's time step, in seconds.
    pub fn dt_s(&self) -> f64 {
        self.world.dt_s()
    }

    /// The current state ready for a renderer: the bubbles and the water at the solver's
    /// time, with the tables and settings (for a renderer the job does not own: the
    /// viewer's window presenter). Times the bake ([`FrameJob::last_bake_s`]).
    pub fn frame_inputs(&mut self) -> (&RenderScene, &FilmTables, &RenderSettings) {
        let bake_start = std::time::Instant::now();
        self.render_scene.bubbles = bubble_meshes(&self.world);
        if let (Some(surface), Some(out)) = (&mut self.water, &mut self.render_scene.water) {
            let mesh = surface.evaluate(self.world.time_s());
            out.positions.clone_from(&mesh.positions);
            out.normals.clone_from(&mesh.normals);
            if out.triangles.len() != mesh.triangles.len() {
                out.triangles.clone_from(&mesh.triangles);
            }
        }
        self.bake_s = bake_start.elapsed().as_secs_f64();
        (&self.render_scene, &self.tables, &self.settings)
    }

    /// The scene's file or built-in name, for messages (the wgpu viewer's).
    #[cfg(feature = "wgpu")]
    pub fn origin(&self) -> String {
        self.scene.origin.clone()
    }

    /// Renders the current state: the bubbles and the water at the solver's time.
    pub fn render(&mut self) -> Result<&Frame, CliError> {
        self.frame_inputs();
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

    /// Renders the current state with the CPU backend while the solver takes `steps`
    /// more steps on the other core: the frame shows the state before those steps, one
    /// frame behind the solver (the live viewer's pipeline, where the solver and the
    /// renderer otherwise wait on each other). Returns the frame, what the steps brought
    /// (bursts) and the wall time they took, s.
    ///
    /// The reference and wgpu backends step first and then render the stepped state.
    pub fn render_while_stepping(
        &mut self,
        steps: u32,
    ) -> Result<(&Frame, Vec<Event>, f64), CliError> {
        if self.film_spec.is_some() || self.gpu.is_some() {
            let (events, sim_s) = self.step_timed(steps)?;
            return Ok((self.render()?, events, sim_s));
        }
        self.frame_inputs();
        let (world, renderer) = (&mut self.world, &mut self.renderer);
        let (scene, tables, settings) = (&self.render_scene, &self.tables, &self.settings);
        let ((events, sim_s), frame) = rayon::join(
            || step_world(world, steps),
            || renderer.render(scene, tables, settings).map(drop),
        );
        frame.map_err(|e| CliError::input(format!("{}: {e}", self.scene.origin)))?;
        Ok((self.renderer.frame(), events?, sim_s))
    }

    /// Takes `steps` solver steps; returns what they brought (bursts) and their wall
    /// time, s.
    pub fn step_timed(&mut self, steps: u32) -> Result<(Vec<Event>, f64), CliError> {
        let (events, sim_s) = step_world(&mut self.world, steps);
        Ok((events?, sim_s))
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
        let bubbles = &self.scene.file.bubbles;
        let grid = crate::scene::default_film_grid(bubbles);
        bubbles
            .first()
            .map(|b| crate::scene::bubble_params(b, grid))
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

/// Takes `steps` solver steps; returns their events (or the first failure) and their wall
/// time, s.
fn step_world(world: &mut World, steps: u32) -> (Result<Vec<Event>, CliError>, f64) {
    let start = std::time::Instant::now();
    let mut events = Vec::new();
    for _ in 0..steps {
        match world.step() {
            Ok(more) => events.extend(more),
            Err(e) => {
                let failed = CliError::runtime(format!("simulation failed: {e}"));
                return (Err(failed), start.elapsed().as_secs_f64());
            }
        }
    }
    (Ok(events), start.elapsed().as_secs_f64())
}
