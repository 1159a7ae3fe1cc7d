//! The window: winit events in, [`ViewState`] updated, the solver stepped at its fixed
//! step against the wall clock, each frame drawn by the [`Presenter`] (the CPU renderer
//! through softbuffer, or the GPU straight into a wgpu surface).

use super::controls::{self, Command, Input, Orbit, ReflectionKey, ViewState};
use super::keys::map_key;
use super::present::Presenter;
use super::scale::ResolutionScale;
use super::{Args, CONTROLS};
use crate::error::{CliError, CliResult};
use crate::frame::{Backend, FrameJob, Options, Reflection};
use bubble_dynamics::Event;
use glam::Vec3;
use raster::FrameTimings;
use std::collections::VecDeque;
use std::fmt::Write as _;
use std::num::NonZeroU32;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};
use winit::application::ApplicationHandler;
use winit::dpi::{PhysicalPosition, PhysicalSize};
use winit::event::{ElementState, KeyEvent, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::PhysicalKey;
use winit::window::{Window, WindowId};

/// Solver steps allowed per displayed frame; beyond it the simulation runs in slow
/// motion rather than spiralling (each late frame asking for ever more steps).
const MAX_STEPS_PER_FRAME: u32 = 8;
/// Wall-clock time folded in per frame at most (a stall must not replay seconds).
const MAX_FRAME_S: f64 = 0.25;
/// A press that moves less than this many pixels is a click, not a drag.
const CLICK_SLOP_PX: f64 = 3.0;
/// Speed a poke gives the bubble as a whole, m/s (impulse = this × its mass).
const POKE_SPEED_M_PER_S: f64 = 0.4;
/// Speed a blown bubble leaves with, m/s, and its distance from the eye as a fraction of
/// the eye–target distance.
const BLOW_SPEED_M_PER_S: f64 = 0.15;
const BLOW_DISTANCE: f64 = 0.45;
/// How long an event stays in the overlay.
const EVENT_LIFETIME: Duration = Duration::from_secs(6);

/// Opens the window and runs until Escape or close.
pub fn run(mut args: Args) -> CliResult {
    // The job renders on the CPU; a GPU presenter brings its own device (one made for the
    // window's surface), so the job must not open a headless one too.
    let backend = args.options.backend;
    if backend == Backend::Wgpu {
        args.options.backend = Backend::Cpu;
    }
    let job = FrameJob::prepare(args.scene.as_deref(), &args.options.real_time())?;
    let event_loop =
        EventLoop::new().map_err(|e| CliError::input(format!("cannot open the display: {e}")))?;
    event_loop.set_control_flow(ControlFlow::Poll);
    let mut app = App::new(job, args, backend)?;
    event_loop
        .run_app(&mut app)
        .map_err(|e| CliError::runtime(format!("window event loop failed: {e}")))?;
    app.error.map_or(Ok(()), Err)
}

struct Gfx {
    window: Arc<Window>,
    presenter: Presenter,
    /// The presenter's name for the overlay (kept: it does not change).
    name: String,
    size: (u32, u32),
}

#[derive(Default)]
struct Pointer {
    at: PhysicalPosition<f64>,
    left: bool,
    right: bool,
    shift: bool,
    pressed_at: PhysicalPosition<f64>,
    dragged: bool,
}

#[derive(Default, Clone, Copy)]
struct Stats {
    sim_s: f64,
    cube_s: f64,
    opaque_s: f64,
    bubbles_s: f64,
    /// The GPU presenter's encoding (CPU) and GPU time.
    setup_s: f64,
    gpu_s: f64,
    frame_s: f64,
    slow_motion: bool,
}

/// `--quit-after-s`: when to quit, and the frames drawn since the first.
struct QuitAfter {
    after_s: f64,
    first: Option<Instant>,
    frames: u64,
    totals: FrameTotals,
}

/// Sums over the frames drawn, for `--quit-after-s`'s breakdown of the mean frame.
#[derive(Default)]
struct FrameTotals {
    sim_s: f64,
    bake_s: f64,
    render_s: f64,
    frame_s: f64,
    steps: u64,
    slow_motion_frames: u64,
    /// Whether the solver ran alongside the render (the CPU presenter), not before it.
    sim_alongside: bool,
}

impl Stats {
    /// Folds one frame into the overlay's running averages (weight 0.1 for the new frame).
    fn mix(&mut self, sim_s: f64, t: &FrameTimings, frame_s: f64) {
        let mix = |old: &mut f64, new: f64| {
            *old = if *old == 0.0 {
                new
            } else {
                *old + 0.1 * (new - *old)
            }
        };
        mix(&mut self.sim_s, sim_s);
        mix(&mut self.cube_s, t.cube_maps_s);
        mix(&mut self.opaque_s, t.opaque_s);
        mix(&mut self.bubbles_s, t.bubbles_s);
        mix(&mut self.setup_s, t.setup_s);
        mix(&mut self.gpu_s, t.resolve_s);
        mix(&mut self.frame_s, frame_s);
    }
}

impl FrameTotals {
    /// Adds one frame: its solver and bake times, render phases, whole time, solver steps
    /// and whether it fell into slow motion.
    fn add(
        &mut self,
        [sim_s, bake_s]: [f64; 2],
        t: &FrameTimings,
        frame_s: f64,
        (steps, slow): (u32, bool),
    ) {
        self.sim_s += sim_s;
        self.bake_s += bake_s;
        self.render_s += t.total_s();
        self.frame_s += frame_s;
        self.steps += u64::from(steps);
        self.slow_motion_frames += u64::from(slow);
    }

    /// The mean frame on one line: solver, the solver's state baked for the renderer, the
    /// render (its phases' sum) and the rest (tone mapping, upscaling, overlay, presenting).
    /// A solver that ran alongside the render is not part of the frame's sum.
    fn summary(&self, frames: u64) -> String {
        let n = frames.max(1) as f64;
        let ms = |s: f64| s / n * 1e3;
        let (when, in_sum) = if self.sim_alongside {
            (" alongside the render", 0.0)
        } else {
            ("", self.sim_s)
        };
        format!(
            "view: mean frame {:.1} ms: sim {:.1} ms{when} ({:.1} steps, slow motion in {} of \
             {frames} frames), bake {:.1} ms, render {:.1} ms, the rest {:.1} ms (tone map, \
             upscale, overlay, present)",
            ms(self.frame_s),
            ms(self.sim_s),
            self.steps as f64 / n,
            self.slow_motion_frames,
            ms(self.bake_s),
            ms(self.render_s),
            ms(self.frame_s - in_sum - self.bake_s - self.render_s)
        )
    }
}

struct App {
    job: FrameJob,
    options: Options,
    state: ViewState,
    scale: ResolutionScale,
    gfx: Option<Gfx>,
    pointer: Pointer,
    last_frame: Option<Instant>,
    behind_s: f64,
    stats: Stats,
    events: VecDeque<(String, Instant)>,
    error: Option<CliError>,
    /// `--backend`: the presenter asked for.
    backend: Backend,
    /// Why the wgpu presenter could not open, shown at the top of the overlay.
    fallback: Option<String>,
    /// Keys pressed and not yet released.
    held_keys: std::collections::HashSet<PhysicalKey>,
    quit_after: Option<QuitAfter>,
    /// The overlay's text, rewritten each frame into the same allocation.
    overlay: String,
}

impl App {
    fn new(job: FrameJob, args: Args, backend: Backend) -> Result<App, CliError> {
        let cam = job.camera();
        let target = Vec3::from_array(job.scene_target_m().map(|v| v as f32));
        let orbit = Orbit::from_eye(cam.eye(), target, cam.vfov_deg())
            .ok_or_else(|| CliError::input("camera: eye and target coincide"))?;
        let reflection = match job.settings().reflection {
            raster::ReflectionMode::StaticEnvironment => ReflectionKey::Static,
            raster::ReflectionMode::SphereMap(_) => ReflectionKey::SphereMap,
            _ => ReflectionKey::Dynamic,
        };
        let state = ViewState::new(orbit, reflection, job.settings().samples);
        Ok(App {
            job,
            options: args.options,
            state,
            scale: ResolutionScale::new(args.target_fps, args.fixed_scale),
            gfx: None,
            pointer: Pointer::default(),
            last_frame: None,
            behind_s: 0.0,
            stats: Stats::default(),
            events: VecDeque::new(),
            error: None,
            backend,
            fallback: None,
            held_keys: Default::default(),
            quit_after: args.quit_after_s.map(|after_s| QuitAfter {
                after_s,
                first: None,
                frames: 0,
                totals: FrameTotals::default(),
            }),
            overlay: String::new(),
        })
    }

    fn fail(&mut self, event_loop: &ActiveEventLoop, err: CliError) {
        self.error = Some(err);
        event_loop.exit();
    }

    fn note(&mut self, text: String) {
        eprintln!("view: {text}");
        self.events.push_back((text, Instant::now()));
        while self.events.len() > 4 {
            self.events.pop_front();
        }
    }

    fn window_size(&self) -> (f32, f32) {
        self.gfx
            .as_ref()
            .map_or((1.0, 1.0), |g| (g.size.0 as f32, g.size.1 as f32))
    }

    fn input(&mut self, event_loop: &ActiveEventLoop, input: Input) {
        let (w, h) = self.window_size();
        let result = match self.state.apply(input, h) {
            Command::None => Ok(()),
            Command::Quit => {
                event_loop.exit();
                Ok(())
            }
            Command::Blow => {
                self.blow();
                Ok(())
            }
            Command::Poke { x_px, y_px } => {
                self.poke(x_px, y_px, w, h);
                Ok(())
            }
            Command::Step => self.step_once(),
            Command::Reset => self.reset(),
            Command::Screenshot => self.screenshot(),
            Command::Settings => self.apply_settings(),
            Command::Wind => self.apply_wind(),
        };
        if let Err(err) = result {
            self.fail(event_loop, err);
        }
    }

    fn blow(&mut self) {
        let Some(template) = self.job.bubble_template() else {
            self.note("this scene has no bubble to copy".into());
            return;
        };
        let cam = self.job.camera();
        let forward = cam.forward().as_dvec3();
        let distance = f64::from(self.state.orbit.distance_m) * BLOW_DISTANCE;
        let params = bubble_dynamics::BubbleParams {
            center_m: cam.eye().as_dvec3() + forward * distance,
            velocity_m_per_s: forward * BLOW_SPEED_M_PER_S,
            ..template
        };
        match self.job.world_mut().try_add_bubble(params) {
            Ok(id) => self.note(format!("blew bubble {id}")),
            Err(e) => self.note(format!("no room to blow: {e}")),
        }
    }

    fn poke(&mut self, x: f32, y: f32, w: f32, h: f32) {
        let cam = self.job.camera();
        let ray = controls::pixel_ray(&cam, x, y, w, h);
        let world = self.job.world();
        let spheres: Vec<(Vec3, f32)> = world
            .bubbles()
            .iter()
            .map(|b| (b.center_m().as_vec3(), b.radius_m() as f32))
            .collect();
        let Some((index, t)) = controls::pick_sphere(cam.eye(), ray, &spheres) else {
            return;
        };
        let b = &world.bubbles()[index];
        let (id, mass) = (b.id(), b.inertial_mass_kg());
        let point = (cam.eye() + ray * t).as_dvec3();
        let impulse = ray.as_dvec3() * (POKE_SPEED_M_PER_S * mass);
        if self.job.world_mut().poke(id, point, impulse) {
            self.note(format!("poked bubble {id}"));
        }
    }

    fn step_once(&mut self) -> CliResult {
        let events = self.job.step_events()?;
        self.report(&events);
        Ok(())
    }

    fn reset(&mut self) -> CliResult {
        self.job.reset()?;
        self.apply_wind()?;
        self.behind_s = 0.0;
        self.note("reset".into());
        Ok(())
    }

    fn apply_wind(&mut self) -> CliResult {
        let wind = self.state.wind_m_per_s().as_dvec3();
        self.job
            .world_mut()
            .set_uniform_wind_m_per_s(wind)
            .map_err(|e| CliError::runtime(format!("wind: {e}")))?;
        let text = if self.state.wind_on {
            format!(
                "wind {:.2} m/s towards ({:.2}, {:.2}, {:.2})",
                wind.length(),
                wind.x,
                wind.y,
                wind.z
            )
        } else {
            "wind off".to_string()
        };
        self.note(text);
        Ok(())
    }

    fn apply_settings(&mut self) -> CliResult {
        self.options.reflection = Some(match self.state.reflection {
            ReflectionKey::Dynamic => Reflection::Dynamic,
            ReflectionKey::Static => Reflection::Static,
            ReflectionKey::SphereMap => Reflection::SphereMap,
        });
        self.options.samples = Some(self.state.samples());
        self.job.set_options(&self.options)?;
        self.note(format!(
            "reflections {:?}, {} sample(s)",
            self.state.reflection,
            self.state.samples()
        ));
        Ok(())
    }

    fn screenshot(&mut self) -> CliResult {
        let path = next_screenshot_path();
        let Some(gfx) = self.gfx.as_mut() else {
            return Ok(());
        };
        let (w, h) = gfx.presenter.screenshot(&mut self.job, &path)?;
        self.note(format!("saved {} ({w}x{h})", path.display()));
        Ok(())
    }

    /// The solver steps that catch up with the wall clock, at its fixed step (at most
    /// [`MAX_STEPS_PER_FRAME`]; beyond that the view falls into slow motion).
    fn steps_due(&mut self, now: Instant) -> u32 {
        let elapsed = self
            .last_frame
            .map_or(0.0, |t| (now - t).as_secs_f64().min(MAX_FRAME_S));
        self.last_frame = Some(now);
        if self.state.paused {
            self.behind_s = 0.0;
            return 0;
        }
        self.behind_s += elapsed;
        let dt = self.job.dt_s();
        let mut steps = 0;
        while self.behind_s >= dt && steps < MAX_STEPS_PER_FRAME {
            self.behind_s -= dt;
            steps += 1;
        }
        self.stats.slow_motion = self.behind_s >= dt;
        if self.stats.slow_motion {
            self.behind_s = 0.0;
        }
        steps
    }

    fn report(&mut self, events: &[Event]) {
        for e in events {
            let Event::Burst {
                bubble_id,
                time_s,
                min_thickness_nm,
                ..
            } = e;
            self.note(format!(
                "bubble {bubble_id} burst at t = {time_s:.2} s (film {min_thickness_nm:.0} nm); space blows a new one"
            ));
        }
    }

    fn redraw(&mut self) -> CliResult {
        let Some((win_w, win_h)) = self.gfx.as_ref().map(|g| g.size) else {
            return Ok(());
        };
        let start = Instant::now();
        let steps = self.steps_due(start);
        if let Some(camera) = self.state.orbit.camera() {
            self.job.set_camera(camera);
        }
        let (iw, ih) = self.scale.internal_size(win_w as usize, win_h as usize);
        self.job.set_size(iw, ih)?;
        let has_overlay = self.write_overlay(iw, ih);
        let Some(gfx) = self.gfx.as_mut() else {
            return Ok(());
        };
        let overlay = has_overlay.then_some(self.overlay.as_str());
        // The CPU presenter renders while the solver steps on the other core; the GPU
        // presenter steps first.
        let (t, events, sim_s) =
            gfx.presenter
                .draw_while_stepping(&mut self.job, (win_w, win_h), overlay, steps)?;
        let alongside = !gfx.presenter.is_gpu();
        self.report(&events);
        self.scale.update(t.total_s() as f32);
        let frame_s = start.elapsed().as_secs_f64();
        if let Some(q) = &mut self.quit_after {
            let bake_s = self.job.last_bake_s();
            q.totals.sim_alongside = alongside;
            let motion = (steps, self.stats.slow_motion);
            (q.totals).add([sim_s, bake_s], &t, frame_s, motion);
        }
        self.stats.mix(sim_s, &t, frame_s);
        Ok(())
    }

    /// Counts a frame for `--quit-after-s`; past the time, prints the mean rate on stderr
    /// and quits.
    fn count_frame(&mut self, event_loop: &ActiveEventLoop) {
        let Some(q) = &mut self.quit_after else {
            return;
        };
        let now = Instant::now();
        let first = *q.first.get_or_insert(now);
        q.frames += 1;
        let elapsed_s = (now - first).as_secs_f64();
        if elapsed_s < q.after_s {
            return;
        }
        let presenter = self.gfx.as_ref().map_or("", |g| g.name.as_str());
        let (iw, ih) = (self.job.settings().width, self.job.settings().height);
        // The first frame starts the clock, so `frames - 1` frames fill `elapsed_s`.
        eprintln!(
            "view: {} frames in {elapsed_s:.2} s: {:.1} fps ({presenter}, last frame {iw}x{ih}, \
             scale {:.0}%)",
            q.frames - 1,
            (q.frames - 1) as f64 / elapsed_s.max(1e-9),
            self.scale.scale() * 100.0
        );
        eprintln!("{}", q.totals.summary(q.frames));
        event_loop.exit();
    }

    /// A key press becomes an input once: a toggle ignores auto-repeat and a second press
    /// of a key still held. Under Xvfb, winit sometimes reports one press of a
    /// character key twice before its release, which flipped the overlay back off.
    fn keyboard(&mut self, event_loop: &ActiveEventLoop, event: &KeyEvent) {
        let held = match event.state {
            ElementState::Pressed => !self.held_keys.insert(event.physical_key),
            ElementState::Released => {
                self.held_keys.remove(&event.physical_key);
                return;
            }
        };
        if let Some(key) = map_key(&event.logical_key)
            && (key.repeats() || !(event.repeat || held))
        {
            self.input(event_loop, Input::Key(key));
        }
    }

    /// Writes the overlay's text into `self.overlay` (its allocation reused from frame to
    /// frame); false when there is none to draw.
    fn write_overlay(&mut self, iw: usize, ih: usize) -> bool {
        let now = Instant::now();
        self.events.retain(|(_, at)| now - *at < EVENT_LIFETIME);
        let mut text = std::mem::take(&mut self.overlay);
        text.clear();
        if let Some(why) = &self.fallback {
            let _ = writeln!(text, "wgpu failed, drawing on the cpu: {why}");
        }
        if self.state.overlay {
            self.write_stats(&mut text, iw, ih);
        }
        if self.state.help {
            text += CONTROLS;
        }
        self.overlay = text;
        !self.overlay.is_empty()
    }

    /// The F overlay: rate, frame-time breakdown, scale, bubbles, settings and events.
    fn write_stats(&self, text: &mut String, iw: usize, ih: usize) {
        let s = self.stats;
        let world = self.job.world();
        let (gpu, presenter) = self
            .gfx
            .as_ref()
            .map_or((false, ""), |g| (g.presenter.is_gpu(), g.name.as_str()));
        let _ = writeln!(
            text,
            "fps {:.1}  frame {:.1} ms",
            1.0 / s.frame_s.max(1e-9),
            s.frame_s * 1e3
        );
        let _ = if gpu {
            writeln!(
                text,
                "sim {:.1}  encode {:.1}  gpu {:.1} ms",
                s.sim_s * 1e3,
                s.setup_s * 1e3,
                s.gpu_s * 1e3
            )
        } else {
            writeln!(
                text,
                "sim {:.1}  cube {:.1}  opaque {:.1}  bubbles {:.1} ms",
                s.sim_s * 1e3,
                s.cube_s * 1e3,
                s.opaque_s * 1e3,
                s.bubbles_s * 1e3
            )
        };
        let _ = writeln!(
            text,
            "scale {:.0}% ({}) {iw}x{ih}{}",
            self.scale.scale() * 100.0,
            if self.scale.is_fixed() {
                "fixed"
            } else {
                "adaptive"
            },
            if self.scale.scale() < 1.0 {
                " upscaled"
            } else {
                ""
            }
        );
        let _ = writeln!(
            text,
            "bubbles {}  t {:.2} s{}{}",
            world.bubbles().len(),
            world.time_s(),
            if self.state.paused { "  paused" } else { "" },
            if s.slow_motion { "  slow motion" } else { "" }
        );
        let _ = writeln!(
            text,
            "reflect {:?}  samples {}",
            self.state.reflection,
            self.state.samples()
        );
        let _ = writeln!(text, "backend {presenter}");
        for (e, _) in &self.events {
            let _ = writeln!(text, "{e}");
        }
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.gfx.is_some() {
            return;
        }
        let s = self.job.settings();
        let attrs = Window::default_attributes()
            .with_title("bubbles view (H: help)")
            .with_inner_size(PhysicalSize::new(s.width as u32, s.height as u32));
        let gfx = event_loop
            .create_window(attrs)
            .map_err(|e| e.to_string())
            .and_then(|window| {
                let window = Arc::new(window);
                let presenter = self.presenter(&window)?;
                Ok(Gfx {
                    window,
                    name: presenter.name(),
                    presenter,
                    size: (0, 0),
                })
            });
        match gfx {
            Ok(gfx) => {
                self.gfx = Some(gfx);
                self.resize();
            }
            Err(e) => self.fail(
                event_loop,
                CliError::runtime(format!("cannot open a window: {e}")),
            ),
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        match event {
            WindowEvent::CloseRequested => self.input(event_loop, Input::Close),
            WindowEvent::Resized(_) => self.resize(),
            WindowEvent::RedrawRequested => match self.redraw() {
                Ok(()) => self.count_frame(event_loop),
                Err(err) => self.fail(event_loop, err),
            },
            WindowEvent::KeyboardInput { event, .. } => self.keyboard(event_loop, &event),
            // A release that happens elsewhere never arrives: forget what was held.
            WindowEvent::Focused(false) => self.held_keys.clear(),
            WindowEvent::ModifiersChanged(m) => self.pointer.shift = m.state().shift_key(),
            WindowEvent::MouseInput { state, button, .. } => {
                self.mouse_button(event_loop, state, button)
            }
            WindowEvent::CursorMoved { position, .. } => self.cursor_moved(event_loop, position),
            WindowEvent::MouseWheel { delta, .. } => {
                let lines = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => (p.y / 40.0) as f32,
                };
                self.input(event_loop, Input::Wheel { lines });
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, _: &ActiveEventLoop) {
        if let Some(gfx) = &self.gfx {
            gfx.window.request_redraw();
        }
    }
}

impl App {
    /// The presenter `--backend` asks for on `window`: with `wgpu`, the GPU one, or where it
    /// cannot open (no adapter, no surface), the CPU one, said once on stderr and kept at
    /// the top of the overlay.
    fn presenter(&mut self, window: &Arc<Window>) -> Result<Presenter, String> {
        if self.backend == Backend::Wgpu {
            match self.gpu_presenter(window) {
                Ok(p) => {
                    eprintln!("view: --backend wgpu: drawing with {}", p.name());
                    return Ok(p);
                }
                Err(why) => {
                    eprintln!("view: --backend wgpu: {why}; drawing on the CPU instead");
                    self.fallback = Some(why);
                }
            }
        }
        Presenter::cpu(window)
    }

    #[cfg(feature = "wgpu")]
    fn gpu_presenter(&self, window: &Arc<Window>) -> Result<Presenter, String> {
        let parallax = self.options.reflection_origin.parallax();
        super::gpu::GpuPresenter::open(window, parallax)
            .map(|p| Presenter::Gpu(Box::new(p)))
            .map_err(|e| e.to_string())
    }

    /// Unreachable: `bubbles view` refuses `--backend wgpu` in a build without it.
    #[cfg(not(feature = "wgpu"))]
    fn gpu_presenter(&self, _: &Arc<Window>) -> Result<Presenter, String> {
        Err("this bubbles was built without the wgpu backend".into())
    }

    fn resize(&mut self) {
        let Some(gfx) = self.gfx.as_mut() else { return };
        let size = gfx.window.inner_size();
        let (Some(w), Some(h)) = (NonZeroU32::new(size.width), NonZeroU32::new(size.height)) else {
            return;
        };
        if gfx.size != (size.width, size.height) && gfx.presenter.resize(w, h) {
            gfx.size = (size.width, size.height);
        }
    }

    fn mouse_button(
        &mut self,
        event_loop: &ActiveEventLoop,
        state: ElementState,
        button: MouseButton,
    ) {
        let pressed = state == ElementState::Pressed;
        let p = &mut self.pointer;
        match button {
            MouseButton::Left => p.left = pressed,
            MouseButton::Right => p.right = pressed,
            _ => return,
        }
        if pressed {
            p.pressed_at = p.at;
            p.dragged = false;
        } else if button == MouseButton::Left && !p.dragged {
            let (x, y) = (p.at.x as f32, p.at.y as f32);
            self.input(event_loop, Input::Click { x_px: x, y_px: y });
        }
    }

    fn cursor_moved(&mut self, event_loop: &ActiveEventLoop, at: PhysicalPosition<f64>) {
        let p = &mut self.pointer;
        let (dx, dy) = (at.x - p.at.x, at.y - p.at.y);
        p.at = at;
        if !(p.left || p.right) {
            return;
        }
        let travel = (at.x - p.pressed_at.x).hypot(at.y - p.pressed_at.y);
        p.dragged |= travel >= CLICK_SLOP_PX;
        if p.dragged {
            let pan = p.right || p.shift;
            self.input(
                event_loop,
                Input::Drag {
                    dx_px: dx as f32,
                    dy_px: dy as f32,
                    pan,
                },
            );
        }
    }
}

/// The first `bubbles-view-NNNN.png` in the working directory that does not exist yet.
fn next_screenshot_path() -> PathBuf {
    (1..)
        .map(|n| PathBuf::from(format!("bubbles-view-{n:04}.png")))
        .find(|p| !p.exists())
        .expect("fewer than usize::MAX screenshots")
}
