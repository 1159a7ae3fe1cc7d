//! [`Environment`]: radiance arriving from infinitely far away, and the procedural [`Sky`].

use std::path::Path;

use glam::Vec3;

use crate::{CubeMap, RenderError, Texture};

/// A procedural sky: a zenith-to-horizon gradient, a ground colour below the horizon and
/// an optional sun disc. All colours are linear RGB radiance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sky {
    /// Radiance straight up.
    pub zenith_rgb: [f32; 3],
    /// Radiance at the horizon.
    pub horizon_rgb: [f32; 3],
    /// Radiance straight down (seen where no ground plane covers it).
    pub nadir_rgb: [f32; 3],
    /// Direction towards the sun (need not be unit length).
    pub sun_direction: Vec3,
    /// Radiance of the sun disc; zero for no sun.
    pub sun_rgb: [f32; 3],
    /// Angular radius of the sun disc, in degrees.
    pub sun_radius_deg: f32,
}

impl Default for Sky {
    /// A clear blue daytime sky without a sun disc.
    fn default() -> Self {
        Self {
            zenith_rgb: [0.12, 0.28, 0.75],
            horizon_rgb: [0.75, 0.85, 1.0],
            nadir_rgb: [0.25, 0.22, 0.2],
            sun_direction: Vec3::new(0.3, 0.8, 0.5),
            sun_rgb: [0.0; 3],
            sun_radius_deg: 0.27,
        }
    }
}

impl Sky {
    /// Radiance seen along `dir` (any length; zero reads as straight up).
    #[inline]
    pub fn radiance(&self, dir: Vec3) -> [f32; 3] {
        let d = dir.normalize_or(Vec3::Y);
        let mut out = self.gradient(d.y);
        if self.sun_rgb != [0.0; 3] {
            let sun = self.sun_direction.normalize_or(Vec3::Y);
            if d.dot(sun) >= self.sun_radius_deg.to_radians().cos() {
                for (o, s) in out.iter_mut().zip(self.sun_rgb) {
                    *o += s;
                }
            }
        }
        out
    }

    /// The sky without its sun, along a unit direction whose y component is `y`.
    #[inline(always)]
    pub fn gradient(&self, y: f32) -> [f32; 3] {
        // Both branches are cheap and pure, so a loop over `y` vectorises with a select.
        if y >= 0.0 {
            // Cubic falloff keeps the horizon band bright and narrow, like a real clear sky.
            let s = 1.0 - y;
            lerp3(self.zenith_rgb, self.horizon_rgb, s * s * s)
        } else {
            lerp3(self.horizon_rgb, self.nadir_rgb, (-y * 10.0).min(1.0))
        }
    }

    fn validate(&self) -> Result<(), RenderError> {
        for (name, c) in [
            ("zenith_rgb", self.zenith_rgb),
            ("horizon_rgb", self.horizon_rgb),
            ("nadir_rgb", self.nadir_rgb),
            ("sun_rgb", self.sun_rgb),
        ] {
            check_rgb(&format!("sky {name}"), c)?;
        }
        if !(self.sun_direction.is_finite() && self.sun_radius_deg.is_finite()) {
            return Err(RenderError::scene(
                "sky sun",
                format!(
                    "direction {} and radius {} deg must be finite",
                    self.sun_direction, self.sun_radius_deg
                ),
            ));
        }
        Ok(())
    }
}

/// Radiance arriving from infinitely far away, by direction (world space, Y up).
#[derive(Debug, Clone, PartialEq)]
pub enum Environment {
    /// The procedural [`Sky`].
    Sky(Sky),
    /// The same radiance in every direction (a white furnace when white).
    Uniform([f32; 3]),
    /// A latitude-longitude image; see [`Texture::sample_equirect`] for the mapping.
    Equirect(Texture),
    /// A six-face cube map (OpenGL face layout).
    CubeFaces(CubeMap),
}

impl Environment {
    /// Radiance seen along `dir` (any length).
    #[inline]
    pub fn radiance(&self, dir: Vec3) -> [f32; 3] {
        match self {
            Self::Sky(sky) => sky.radiance(dir),
            Self::Uniform(rgb) => *rgb,
            Self::Equirect(tex) => tex.sample_equirect(dir),
            Self::CubeFaces(cube) => cube.sample(dir),
        }
    }

    /// Loads a latitude-longitude panorama (PNG or EXR); errors name the path.
    pub fn load_equirect(path: impl AsRef<Path>) -> Result<Self, RenderError> {
        Texture::load(path).map(Self::Equirect)
    }

    /// Loads six cube faces in the order +X, −X, +Y, −Y, +Z, −Z; errors name the path.
    pub fn load_cube_faces<P: AsRef<Path>>(paths: [P; 6]) -> Result<Self, RenderError> {
        CubeMap::load_faces(paths).map(Self::CubeFaces)
    }

    /// Mean radiance over the sphere of directions (a fixed 4096-direction quadrature):
    /// a fair ambient term for lit surfaces.
    pub fn average_radiance(&self) -> [f32; 3] {
        const N: usize = 4096;
        let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
        let mut sum = [0.0f64; 3];
        for k in 0..N {
            let y = 1.0 - (k as f32 + 0.5) * 2.0 / N as f32;
            let r = (1.0 - y * y).max(0.0).sqrt();
            let phi = golden * k as f32;
            let c = self.radiance(Vec3::new(r * phi.cos(), y, r * phi.sin()));
            for (s, v) in sum.iter_mut().zip(c) {
                *s += f64::from(v);
            }
        }
        sum.map(|s| (s / N as f64) as f32)
    }

    /// Checks every colour is finite and non-negative.
    pub fn validate(&self) -> Result<(), RenderError> {
        match self {
            Self::Sky(sky) => sky.validate(),
            Self::Uniform(rgb) => check_rgb("uniform environment", *rgb),
            // Textures and cube maps are validated when built.
            Self::Equirect(_) | Self::CubeFaces(_) => Ok(()),
        }
    }
}

/// Rejects a colour that is not finite and non-negative.
pub(crate) fn check_rgb(what: &str, rgb: [f32; 3]) -> Result<(), RenderError> {
    if rgb.iter().all(|c| c.is_finite() && *c >= 0.0) {
        Ok(())
    } else {
        Err(RenderError::scene(
            what,
            format!("{rgb:?} must be finite and non-negative"),
        ))
    }
}

/// `a·(1 − t) + b·t`, exact at both ends.
#[inline]
pub(crate) fn lerp3(a: [f32; 3], b: [f32; 3], t: f32) -> [f32; 3] {
    let s = 1.0 - t;
    [
        a[0] * s + b[0] * t,
        a[1] * s + b[1] * t,
        a[2] * s + b[2] * t,
    ]
}

impl CubeMap {
    /// Renders an environment into a cube map of `face_size²` faces (borders included).
    pub fn from_environment(env: &Environment, face_size: usize) -> Result<Self, RenderError> {
        Self::from_radiance(face_size, |dir| env.radiance(dir))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sky_hits_its_key_colours() {
        let sky = Sky::default();
        assert_eq!(sky.radiance(Vec3::Y), sky.zenith_rgb);
        assert_eq!(sky.radiance(Vec3::X), sky.horizon_rgb);
        assert_eq!(sky.radiance(-Vec3::Y), sky.nadir_rgb);
        assert_eq!(sky.radiance(Vec3::ZERO), sky.zenith_rgb);
    }

    #[test]
    fn sun_disc_adds_its_radiance_inside_only() {
        let sky = Sky {
            sun_rgb: [100.0; 3],
            sun_direction: Vec3::new(0.0, 1.0, 1.0),
            sun_radius_deg: 1.0,
            ..Sky::default()
        };
        let at_sun = sky.radiance(Vec3::new(0.0, 1.0, 1.0));
        let beside = sky.radiance(Vec3::new(0.0, 1.0, 1.1));
        assert!(
            at_sun[0] > 100.0 && beside[0] < 2.0,
            "{at_sun:?} {beside:?}"
        );
    }

    #[test]
    fn average_of_uniform_is_itself() {
        let env = Environment::Uniform([0.5, 1.0, 2.0]);
        let avg = env.average_radiance();
        for (a, b) in avg.iter().zip([0.5, 1.0, 2.0]) {
            assert!((a - b).abs() < 1e-6, "off by {}", a - b);
        }
    }

    #[test]
    fn average_of_half_bright_sphere_is_half() {
        let sky = Sky {
            zenith_rgb: [1.0; 3],
            horizon_rgb: [1.0; 3],
            nadir_rgb: [1.0; 3],
            ..Sky::default()
        };
        let avg = Environment::Sky(sky).average_radiance();
        assert!((avg[0] - 1.0).abs() < 1e-3, "off by {}", avg[0] - 1.0);
        // Zenith-only sky: ∫ (1 − y)³ over the upper hemisphere, mean over the sphere = 1/8.
        let sky = Sky {
            zenith_rgb: [0.0; 3],
            horizon_rgb: [1.0; 3],
            nadir_rgb: [0.0; 3],
            ..Sky::default()
        };
        let avg = Environment::Sky(sky).average_radiance();
        // Upper half: mean of (1−y)³ for y uniform in [0,1] is 1/4; lower half near 0 except the
        // horizon band ∫₀^0.1 (1 − 10 s) ds = 0.05 → (0.25 + 0.05) / 2 = 0.15.
        assert!((avg[0] - 0.15).abs() < 2e-3, "off by {}", avg[0] - 0.15);
    }
}
