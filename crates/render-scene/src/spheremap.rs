//! [`SphereMap`]: an environment stored as the image of a mirror ball (seed 002, OpenGL
//! `GL_SPHERE_MAP`), indexed by the reflected direction.
//!
//! In map space the ball is photographed from +Z looking down −Z: a reflected direction
//! `r` lands at `u = r.x / m + ½`, `v = ½ − r.y / m` with `m = 2·√(r.x² + r.y² + (r.z + 1)²)`.
//! The centre of the image reflects +Z (back at the viewer), the rim reflects −Z.

use std::path::Path;

use glam::{Mat3, Vec3};

use crate::{Environment, RenderError, Texture};

/// A sphere-map environment with its orientation in the world.
///
/// # Guarantees
/// - `world_from_map` is a rotation (orthonormal columns, determinant +1, to 1e-3).
#[derive(Debug, Clone, PartialEq)]
pub struct SphereMap {
    texture: Texture,
    map_from_world: Mat3,
}

impl SphereMap {
    /// Wraps a mirror-ball image whose map axes are the columns of `world_from_map`
    /// (use [`crate::Camera::world_from_eye`] for the classic eye-space sphere map).
    pub fn try_new(texture: Texture, world_from_map: Mat3) -> Result<Self, RenderError> {
        let ortho = world_from_map.transpose() * world_from_map;
        let err = (ortho - Mat3::IDENTITY)
            .to_cols_array()
            .iter()
            .fold(0f32, |m, e| m.max(e.abs()));
        if !(err < 1e-3 && (world_from_map.determinant() - 1.0).abs() < 1e-3) {
            return Err(RenderError::scene(
                "sphere map",
                format!("world_from_map {world_from_map} is not a rotation"),
            ));
        }
        Ok(Self {
            texture,
            map_from_world: world_from_map.transpose(),
        })
    }

    /// Loads a mirror-ball image (PNG as sRGB, EXR linear); errors name the path.
    pub fn load(path: impl AsRef<Path>, world_from_map: Mat3) -> Result<Self, RenderError> {
        Self::try_new(Texture::load(path)?, world_from_map)
    }

    /// Renders `env` into a `size × size` sphere map (texels outside the disc take the rim).
    pub fn from_environment(
        env: &Environment,
        size: usize,
        world_from_map: Mat3,
    ) -> Result<Self, RenderError> {
        if !(2..=8192).contains(&size) {
            return Err(RenderError::setting(
                "sphere map size",
                size,
                "2 ..= 8192 texels",
            ));
        }
        let mut texels = Vec::with_capacity(size * size);
        for j in 0..size {
            for i in 0..size {
                let x = 2.0 * (i as f32 + 0.5) / size as f32 - 1.0;
                let y = 1.0 - 2.0 * (j as f32 + 0.5) / size as f32;
                let r = reflected_direction(x, y);
                texels.push(env.radiance(world_from_map * r));
            }
        }
        Self::try_new(Texture::try_new(size, size, texels)?, world_from_map)
    }

    /// The mirror-ball image.
    pub fn texture(&self) -> &Texture {
        &self.texture
    }

    /// The rotation from world directions to map space (the inverse of `world_from_map`).
    pub fn map_from_world(&self) -> Mat3 {
        self.map_from_world
    }

    /// Bilinear lookup of the radiance reflected along world direction `dir` (any length).
    #[inline]
    pub fn sample(&self, dir: Vec3) -> [f32; 3] {
        let r = (self.map_from_world * dir).normalize_or(Vec3::Z);
        let m = 2.0 * (r.x * r.x + r.y * r.y + (r.z + 1.0) * (r.z + 1.0)).sqrt();
        // At r = −Z every rim point is the answer; pick the rim's right-hand side.
        let (u, v) = if m > 1e-6 {
            (r.x / m + 0.5, 0.5 - r.y / m)
        } else {
            (1.0, 0.5)
        };
        self.texture.sample_clamp(u, v)
    }
}

/// Direction reflected by a mirror ball at disc point `(x, y)` (clamped to the rim), seen along −Z.
fn reflected_direction(x: f32, y: f32) -> Vec3 {
    let r2 = x * x + y * y;
    let (x, y) = if r2 > 1.0 {
        let s = r2.sqrt().recip();
        (x * s, y * s)
    } else {
        (x, y)
    };
    let nz = (1.0 - x * x - y * y).max(0.0).sqrt();
    // r = v − 2(v·n)n with v = −Z.
    Vec3::new(2.0 * nz * x, 2.0 * nz * y, 2.0 * nz * nz - 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Sky;

    #[test]
    fn lookup_inverts_generation() {
        for &(x, y) in &[(0.0, 0.0), (0.3, -0.4), (-0.7, 0.1), (0.05, 0.9)] {
            let r = reflected_direction(x, y);
            assert!((r.length() - 1.0).abs() < 1e-5, "|r| = {}", r.length());
            let m = 2.0 * (r.x * r.x + r.y * r.y + (r.z + 1.0) * (r.z + 1.0)).sqrt();
            assert!(
                (r.x / m - x / 2.0).abs() < 1e-5 && (r.y / m - y / 2.0).abs() < 1e-5,
                "({x},{y})"
            );
        }
    }

    #[test]
    fn generated_map_reproduces_the_environment() {
        let env = Environment::Sky(Sky::default());
        let frame = Mat3::from_cols(Vec3::X, Vec3::NEG_Z, Vec3::Y);
        let map = SphereMap::from_environment(&env, 256, frame).unwrap();
        // Away from the singular rim the map should agree with the sky closely.
        for &d in &[
            Vec3::Y,
            Vec3::new(0.5, 0.3, 0.2),
            Vec3::new(-0.2, 0.9, -0.3),
            Vec3::X,
        ] {
            let want = env.radiance(d);
            let got = map.sample(d);
            for k in 0..3 {
                assert!(
                    (got[k] - want[k]).abs() < 0.02,
                    "{d}: channel {k} off by {}",
                    got[k] - want[k]
                );
            }
        }
    }

    #[test]
    fn rejects_non_rotations() {
        let tex = Texture::solid([1.0; 3]).unwrap();
        assert!(
            SphereMap::try_new(tex.clone(), Mat3::from_diagonal(Vec3::new(1.0, 1.0, -1.0)))
                .is_err()
        );
        assert!(SphereMap::try_new(tex, Mat3::from_diagonal(Vec3::splat(2.0))).is_err());
    }
}
