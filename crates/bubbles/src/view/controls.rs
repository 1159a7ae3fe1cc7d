//! The viewer's state and what each input does to it: plain functions of (state, input),
//! tested without a window.

use glam::Vec3;
use raster::Camera;

/// Radians the camera orbits per pixel dragged.
const ORBIT_RAD_PER_PX: f32 = 0.008;
/// Pitch limit, radians (short of the poles, where the look-at basis is undefined).
const MAX_PITCH_RAD: f32 = 1.45;
/// Zoom factor per wheel line.
const ZOOM_PER_LINE: f32 = 0.9;
/// Distance range of the orbit, metres.
const DISTANCE_RANGE_M: (f32, f32) = (0.05, 20.0);
/// Wind turn per arrow key press, radians.
const WIND_TURN_RAD: f32 = 15.0 * std::f32::consts::PI / 180.0;
/// Wind strength change per +/− press (a factor) and its range, m/s.
const WIND_STEP: f32 = 1.25;
const WIND_SPEED_RANGE_M_PER_S: (f32, f32) = (0.01, 5.0);
/// Anti-aliasing sample counts that M cycles through.
pub const SAMPLE_CYCLE: [u32; 3] = [1, 4, 16];

/// Keys the viewer reacts to (window-system independent).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Key {
    /// Quit.
    Escape,
    /// Wind on/off.
    W,
    /// Turn the wind.
    Left,
    /// Turn the wind.
    Right,
    /// Tilt the wind up.
    Up,
    /// Tilt the wind down.
    Down,
    /// Stronger wind.
    Plus,
    /// Weaker wind.
    Minus,
    /// Blow a bubble.
    Space,
    /// Reflection mode 1, 2 or 3.
    Digit(u8),
    /// Cycle anti-aliasing samples.
    M,
    /// Pause.
    P,
    /// One step while paused.
    Period,
    /// Reset the scene.
    R,
    /// Overlay.
    F,
    /// Screenshot.
    S,
    /// Help.
    H,
}

impl Key {
    /// Whether holding the key down acts again at the keyboard's repeat rate: the wind's
    /// adjustments, blowing and stepping do; a toggle, a mode, a screenshot or a reset
    /// acts once per press (held, or with a press and release the system saw late, it
    /// would flip back and forth or save a burst of files).
    pub fn repeats(self) -> bool {
        matches!(
            self,
            Key::Left
                | Key::Right
                | Key::Up
                | Key::Down
                | Key::Plus
                | Key::Minus
                | Key::Space
                | Key::Period
        )
    }
}

/// One input, in window pixels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Input {
    /// A key press.
    Key(Key),
    /// The pointer moved by (dx, dy) with a button held: orbit, or pan when `pan`.
    Drag { dx_px: f32, dy_px: f32, pan: bool },
    /// Wheel lines (positive: towards the target).
    Wheel { lines: f32 },
    /// A click without a drag at (x, y).
    Click { x_px: f32, y_px: f32 },
    /// The window was closed.
    Close,
}

/// What the caller must do after an input (beyond the state change).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Command {
    /// Nothing more.
    None,
    /// Leave with exit code 0.
    Quit,
    /// Blow a bubble from the eye towards the target.
    Blow,
    /// Poke the bubble under this pixel.
    Poke { x_px: f32, y_px: f32 },
    /// One solver step (while paused).
    Step,
    /// Rebuild the scene.
    Reset,
    /// Save a screenshot.
    Screenshot,
    /// The render settings changed (reflection mode or samples).
    Settings,
    /// The steady wind changed.
    Wind,
}

/// Reflection modes the digit keys pick.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ReflectionKey {
    /// 1: dynamic cube maps.
    Dynamic,
    /// 2: static environment.
    Static,
    /// 3: sphere map.
    SphereMap,
}

/// A camera orbiting a target.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Orbit {
    /// The point looked at, m.
    pub target_m: Vec3,
    /// Eye–target distance, m.
    pub distance_m: f32,
    /// Angle about +Y, radians (0: the eye on +Z).
    pub yaw_rad: f32,
    /// Elevation of the eye above the target, radians.
    pub pitch_rad: f32,
    /// Vertical field of view, degrees.
    pub vfov_deg: f32,
}

impl Orbit {
    /// The orbit whose camera sits at `eye_m` looking at `target_m`; `None` when they coincide.
    pub fn from_eye(eye_m: Vec3, target_m: Vec3, vfov_deg: f32) -> Option<Orbit> {
        let d = eye_m - target_m;
        let distance_m = d.length();
        (distance_m > 0.0 && distance_m.is_finite()).then(|| Orbit {
            target_m,
            distance_m,
            yaw_rad: d.x.atan2(d.z),
            pitch_rad: (d.y / distance_m).clamp(-1.0, 1.0).asin(),
            vfov_deg,
        })
    }

    /// The eye position, m.
    pub fn eye_m(&self) -> Vec3 {
        let (sy, cy) = self.yaw_rad.sin_cos();
        let (sp, cp) = self.pitch_rad.sin_cos();
        self.target_m + self.distance_m * Vec3::new(cp * sy, sp, cp * cy)
    }

    /// The look-at camera; `None` only for non-finite state.
    pub fn camera(&self) -> Option<Camera> {
        Camera::try_look_at(self.eye_m(), self.target_m, Vec3::Y, self.vfov_deg).ok()
    }

    fn orbit(&mut self, dx_px: f32, dy_px: f32) {
        self.yaw_rad -= dx_px * ORBIT_RAD_PER_PX;
        self.pitch_rad =
            (self.pitch_rad + dy_px * ORBIT_RAD_PER_PX).clamp(-MAX_PITCH_RAD, MAX_PITCH_RAD);
    }

    /// Moves the target in the screen plane so the scene follows the pointer.
    fn pan(&mut self, dx_px: f32, dy_px: f32, height_px: f32) {
        let Some(cam) = self.camera() else { return };
        let m_per_px =
            2.0 * self.distance_m * (0.5 * self.vfov_deg.to_radians()).tan() / height_px.max(1.0);
        self.target_m += (-dx_px * cam.right() + dy_px * cam.up()) * m_per_px;
    }

    fn zoom(&mut self, lines: f32) {
        let d = self.distance_m * ZOOM_PER_LINE.powf(lines);
        self.distance_m = d.clamp(DISTANCE_RANGE_M.0, DISTANCE_RANGE_M.1);
    }
}

/// Everything the keys and the mouse change.
#[derive(Debug, Clone, PartialEq)]
pub struct ViewState {
    /// The camera.
    pub orbit: Orbit,
    /// Whether the steady wind blows.
    pub wind_on: bool,
    /// Horizontal direction the wind blows towards, radians about +Y (0: +X).
    pub wind_heading_rad: f32,
    /// Elevation of the wind, radians.
    pub wind_elevation_rad: f32,
    /// Wind speed, m/s.
    pub wind_speed_m_per_s: f32,
    /// Reflection mode.
    pub reflection: ReflectionKey,
    /// Index into [`SAMPLE_CYCLE`].
    pub samples_index: usize,
    /// Whether the solver is paused.
    pub paused: bool,
    /// Whether the overlay is shown.
    pub overlay: bool,
    /// Whether the help is shown.
    pub help: bool,
}

impl ViewState {
    /// The initial state around `orbit`.
    pub fn new(orbit: Orbit, reflection: ReflectionKey, samples: u32) -> ViewState {
        ViewState {
            orbit,
            wind_on: false,
            wind_heading_rad: 0.0,
            wind_elevation_rad: 0.0,
            wind_speed_m_per_s: 0.3,
            reflection,
            samples_index: SAMPLE_CYCLE.iter().position(|&s| s == samples).unwrap_or(1),
            paused: false,
            overlay: false,
            help: false,
        }
    }

    /// Anti-aliasing samples in force.
    pub fn samples(&self) -> u32 {
        SAMPLE_CYCLE[self.samples_index % SAMPLE_CYCLE.len()]
    }

    /// The steady wind the solver should see, m/s (zero when off).
    pub fn wind_m_per_s(&self) -> Vec3 {
        if !self.wind_on {
            return Vec3::ZERO;
        }
        let (sh, ch) = self.wind_heading_rad.sin_cos();
        let (se, ce) = self.wind_elevation_rad.sin_cos();
        self.wind_speed_m_per_s * Vec3::new(ce * ch, se, ce * sh)
    }

    /// Applies one input; `height_px` is the window height (for panning).
    pub fn apply(&mut self, input: Input, height_px: f32) -> Command {
        match input {
            Input::Key(key) => self.key(key),
            Input::Drag { dx_px, dy_px, pan } => {
                if pan {
                    self.orbit.pan(dx_px, dy_px, height_px);
                } else {
                    self.orbit.orbit(dx_px, dy_px);
                }
                Command::None
            }
            Input::Wheel { lines } => {
                self.orbit.zoom(lines);
                Command::None
            }
            Input::Click { x_px, y_px } => Command::Poke { x_px, y_px },
            Input::Close => Command::Quit,
        }
    }

    fn key(&mut self, key: Key) -> Command {
        let wind = |s: &mut Self, f: fn(&mut Self)| {
            f(s);
            Command::Wind
        };
        match key {
            Key::Escape => Command::Quit,
            Key::W => wind(self, |s| s.wind_on = !s.wind_on),
            Key::Left => wind(self, |s| s.wind_heading_rad -= WIND_TURN_RAD),
            Key::Right => wind(self, |s| s.wind_heading_rad += WIND_TURN_RAD),
            Key::Up => wind(self, |s| {
                s.wind_elevation_rad = (s.wind_elevation_rad + WIND_TURN_RAD).min(MAX_PITCH_RAD)
            }),
            Key::Down => wind(self, |s| {
                s.wind_elevation_rad = (s.wind_elevation_rad - WIND_TURN_RAD).max(-MAX_PITCH_RAD)
            }),
            Key::Plus => wind(self, |s| {
                s.wind_speed_m_per_s =
                    (s.wind_speed_m_per_s * WIND_STEP).min(WIND_SPEED_RANGE_M_PER_S.1)
            }),
            Key::Minus => wind(self, |s| {
                s.wind_speed_m_per_s =
                    (s.wind_speed_m_per_s / WIND_STEP).max(WIND_SPEED_RANGE_M_PER_S.0)
            }),
            Key::Space => Command::Blow,
            Key::Digit(d) => {
                let mode = match d {
                    1 => ReflectionKey::Dynamic,
                    2 => ReflectionKey::Static,
                    3 => ReflectionKey::SphereMap,
                    _ => return Command::None,
                };
                self.reflection = mode;
                Command::Settings
            }
            Key::M => {
                self.samples_index = (self.samples_index + 1) % SAMPLE_CYCLE.len();
                Command::Settings
            }
            Key::P => {
                self.paused = !self.paused;
                Command::None
            }
            Key::Period if self.paused => Command::Step,
            Key::Period => Command::None,
            Key::R => Command::Reset,
            Key::F => {
                self.overlay = !self.overlay;
                Command::None
            }
            Key::S => Command::Screenshot,
            Key::H => {
                self.help = !self.help;
                Command::None
            }
        }
    }
}

/// The first sphere (centre, radius) hit by the ray from `origin` along unit `dir`, as
/// (index, distance along the ray).
pub fn pick_sphere(origin: Vec3, dir: Vec3, spheres: &[(Vec3, f32)]) -> Option<(usize, f32)> {
    let mut best: Option<(usize, f32)> = None;
    for (i, &(c, r)) in spheres.iter().enumerate() {
        let oc = origin - c;
        let b = oc.dot(dir);
        let disc = b * b - (oc.length_squared() - r * r);
        if disc < 0.0 {
            continue;
        }
        let root = disc.sqrt();
        let t = if -b - root > 0.0 {
            -b - root
        } else {
            -b + root
        };
        if t > 0.0 && best.is_none_or(|(_, bt)| t < bt) {
            best = Some((i, t));
        }
    }
    best
}

/// The unit ray through pixel (x, y) of a `width`×`height` window (pixel centres at +0.5).
pub fn pixel_ray(camera: &Camera, x_px: f32, y_px: f32, width_px: f32, height_px: f32) -> Vec3 {
    let half_h = (0.5 * camera.vfov_deg().to_radians()).tan();
    let sx = (2.0 * x_px / width_px - 1.0) * half_h * width_px / height_px;
    let sy = (1.0 - 2.0 * y_px / height_px) * half_h;
    (camera.forward() + sx * camera.right() + sy * camera.up()).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn state() -> ViewState {
        let orbit = Orbit::from_eye(Vec3::new(0.0, 0.11, 0.42), Vec3::new(0.0, 0.075, 0.0), 38.0)
            .expect("distinct eye and target");
        ViewState::new(orbit, ReflectionKey::Dynamic, 4)
    }

    #[track_caller]
    fn assert_close(what: &str, a: Vec3, b: Vec3) {
        let d = (a - b).length();
        assert!(d < 1e-5, "{what}: {a} vs {b}, difference {d:e}");
    }

    /// A held F (or a release the X server saw late, so it auto-repeated) used to flip
    /// the overlay on and off again: the viewer's end-to-end test failed under load.
    #[test]
    fn toggles_act_once_per_press_and_adjustments_repeat() {
        for key in [
            Key::F,
            Key::H,
            Key::P,
            Key::S,
            Key::R,
            Key::W,
            Key::M,
            Key::Escape,
        ] {
            assert!(!key.repeats(), "{key:?}");
        }
        assert!(!Key::Digit(1).repeats());
        for key in [
            Key::Left,
            Key::Right,
            Key::Up,
            Key::Down,
            Key::Plus,
            Key::Minus,
        ] {
            assert!(key.repeats(), "{key:?}");
        }
    }

    #[test]
    fn the_orbit_reproduces_the_scene_camera() {
        let s = state();
        assert_close("eye", s.orbit.eye_m(), Vec3::new(0.0, 0.11, 0.42));
        let cam = s.orbit.camera().unwrap();
        let expected = Camera::look_at(
            Vec3::new(0.0, 0.11, 0.42),
            Vec3::new(0.0, 0.075, 0.0),
            Vec3::Y,
            38.0,
        );
        assert_close("forward", cam.forward(), expected.forward());
    }

    #[test]
    fn dragging_orbits_at_constant_distance_and_keeps_the_target() {
        let mut s = state();
        let before = s.orbit;
        assert_eq!(
            s.apply(
                Input::Drag {
                    dx_px: 120.0,
                    dy_px: -40.0,
                    pan: false
                },
                480.0
            ),
            Command::None
        );
        assert!((s.orbit.eye_m().distance(s.orbit.target_m) - before.distance_m).abs() < 1e-5);
        assert_eq!(s.orbit.target_m, before.target_m);
        assert!(
            s.orbit.eye_m().distance(before.eye_m()) > 0.05,
            "a drag must move the eye"
        );
        // Dragging back returns to the start (orbiting is reversible away from the poles).
        s.apply(
            Input::Drag {
                dx_px: -120.0,
                dy_px: 40.0,
                pan: false,
            },
            480.0,
        );
        assert_close("eye after drag back", s.orbit.eye_m(), before.eye_m());
    }

    #[test]
    fn pitch_stops_short_of_the_poles_so_the_camera_stays_valid() {
        let mut s = state();
        s.apply(
            Input::Drag {
                dx_px: 0.0,
                dy_px: 1e6,
                pan: false,
            },
            480.0,
        );
        assert_eq!(s.orbit.pitch_rad, MAX_PITCH_RAD);
        assert!(s.orbit.camera().is_some());
    }

    #[test]
    fn panning_moves_eye_and_target_together_in_the_screen_plane() {
        let mut s = state();
        let (eye, target) = (s.orbit.eye_m(), s.orbit.target_m);
        let forward = s.orbit.camera().unwrap().forward();
        s.apply(
            Input::Drag {
                dx_px: 30.0,
                dy_px: 10.0,
                pan: true,
            },
            480.0,
        );
        let moved = s.orbit.target_m - target;
        assert!(moved.length() > 1e-4, "pan must move the target");
        assert_close("eye follows target", s.orbit.eye_m() - eye, moved);
        assert!(
            moved.dot(forward).abs() < 1e-6,
            "pan must stay in the screen plane"
        );
    }

    #[test]
    fn the_wheel_zooms_towards_the_target_within_limits() {
        let mut s = state();
        let d0 = s.orbit.distance_m;
        s.apply(Input::Wheel { lines: 1.0 }, 480.0);
        assert!((s.orbit.distance_m - d0 * ZOOM_PER_LINE).abs() < 1e-6);
        s.apply(Input::Wheel { lines: 1e4 }, 480.0);
        assert_eq!(s.orbit.distance_m, DISTANCE_RANGE_M.0);
    }

    #[test]
    fn wind_keys_switch_turn_and_scale_the_wind() {
        let mut s = state();
        assert_eq!(s.wind_m_per_s(), Vec3::ZERO);
        assert_eq!(s.apply(Input::Key(Key::W), 1.0), Command::Wind);
        assert_close("wind along +X", s.wind_m_per_s(), Vec3::new(0.3, 0.0, 0.0));
        for _ in 0..6 {
            s.apply(Input::Key(Key::Right), 1.0);
        }
        assert_close("turned 90°", s.wind_m_per_s(), Vec3::new(0.0, 0.0, 0.3));
        s.apply(Input::Key(Key::Plus), 1.0);
        assert!((s.wind_m_per_s().length() - 0.3 * WIND_STEP).abs() < 1e-6);
        s.apply(Input::Key(Key::W), 1.0);
        assert_eq!(s.wind_m_per_s(), Vec3::ZERO);
    }

    #[test]
    fn keys_map_to_their_commands() {
        let mut s = state();
        assert_eq!(s.apply(Input::Key(Key::Escape), 1.0), Command::Quit);
        assert_eq!(s.apply(Input::Close, 1.0), Command::Quit);
        assert_eq!(s.apply(Input::Key(Key::Space), 1.0), Command::Blow);
        assert_eq!(
            s.apply(Input::Key(Key::Period), 1.0),
            Command::None,
            "a step only while paused"
        );
        s.apply(Input::Key(Key::P), 1.0);
        assert!(s.paused);
        assert_eq!(s.apply(Input::Key(Key::Period), 1.0), Command::Step);
        assert_eq!(s.apply(Input::Key(Key::Digit(3)), 1.0), Command::Settings);
        assert_eq!(s.reflection, ReflectionKey::SphereMap);
        assert_eq!(s.apply(Input::Key(Key::Digit(7)), 1.0), Command::None);
        assert_eq!(s.samples(), 4);
        s.apply(Input::Key(Key::M), 1.0);
        assert_eq!(s.samples(), 16);
        s.apply(Input::Key(Key::F), 1.0);
        s.apply(Input::Key(Key::H), 1.0);
        assert!(s.overlay && s.help);
        assert_eq!(s.apply(Input::Key(Key::R), 1.0), Command::Reset);
        assert_eq!(s.apply(Input::Key(Key::S), 1.0), Command::Screenshot);
        let click = Input::Click {
            x_px: 3.0,
            y_px: 4.0,
        };
        assert_eq!(
            s.apply(click, 1.0),
            Command::Poke {
                x_px: 3.0,
                y_px: 4.0
            }
        );
    }

    #[test]
    fn the_centre_pixel_picks_the_bubble_at_the_target_and_not_one_behind_the_eye() {
        let s = state();
        let cam = s.orbit.camera().unwrap();
        let ray = pixel_ray(&cam, 320.0, 240.0, 640.0, 480.0);
        assert_close("centre ray", ray, cam.forward());
        let behind = (cam.eye() - 0.5 * cam.forward(), 0.1);
        let front = (s.orbit.target_m, 0.03);
        let far = (s.orbit.target_m + 0.3 * cam.forward(), 0.05);
        let hit = pick_sphere(cam.eye(), ray, &[behind, far, front]);
        let (index, t) = hit.expect("the ray passes through the target");
        assert_eq!(index, 2, "nearest sphere in front of the eye");
        assert!(
            (t - (s.orbit.distance_m - 0.03)).abs() < 1e-4,
            "hit distance {t}"
        );
        let corner = pixel_ray(&cam, 0.0, 0.0, 640.0, 480.0);
        assert_eq!(pick_sphere(cam.eye(), corner, &[front]), None);
    }
}
