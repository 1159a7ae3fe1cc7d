//! [`Reflection`]: where a bubble's reflected rays read their radiance, and how cube maps
//! are filtered (the GPU's `reflection` ports [`Reflection::sample`]).

use glam::Vec3;

use crate::{CubeMap, Environment, ReflectionFilter, SphereMap};

/// Where one bubble's reflections come from.
#[derive(Debug, Clone, Copy)]
pub enum Reflection<'a> {
    /// A dynamic cube map.
    Cube(&'a CubeMap),
    /// The environment itself.
    Env(&'a Environment),
    /// A sphere map.
    Sphere(&'a SphereMap),
}

impl Reflection<'_> {
    /// Radiance along unit `dir`; cube maps are filtered by `derivatives`, the change of
    /// the direction per pixel along x and y, unless `filter` asks for the single
    /// bilinear tap.
    #[inline]
    pub fn sample(&self, dir: Vec3, derivatives: [Vec3; 2], filter: ReflectionFilter) -> [f32; 3] {
        let cube: &CubeMap = match *self {
            Self::Cube(c) | Self::Env(Environment::CubeFaces(c)) => c,
            Self::Env(e) => return e.radiance(dir),
            Self::Sphere(s) => return s.sample(dir),
        };
        match filter {
            ReflectionFilter::Footprint => cube.sample_footprint(dir, derivatives),
            ReflectionFilter::Bilinear => cube.sample(dir),
        }
    }

    /// Whether the lookup uses a footprint (so the shader should compute one).
    #[inline]
    pub fn is_cube(&self) -> bool {
        matches!(self, Self::Cube(_) | Self::Env(Environment::CubeFaces(_)))
    }
}
