//! Pure-CPU sorted-triangle blend renderer for thin-film soap bubbles (seed 000 §4).
//!
//! Knows triangles, textures and blending; takes bubble meshes with per-vertex thickness
//! and baked [`lut::Lut`] tables. It knows no physics.
//!
//! A frame ([`Renderer::render`]):
//! 1. the opaque scene — [`Environment`], optional [`Ground`] plane, [`Object`]s lit by
//!    [`Light`]s and by the environment's [`Irradiance`] — rasterised with a depth buffer into an HDR sample buffer;
//! 2. per bubble, a dynamic [`CubeMap`] of that scene from the bubble's centre
//!    ([`ReflectionMode::DynamicCubeMap`]), or the environment / a [`SphereMap`] instead;
//! 3. bubbles sorted far to near, each drawn back faces then front faces with
//!    `dest = dest ⊙ T(d, cos θ) + R(d, cos θ) ⊙ env(reflect) + Σ light highlights`;
//! 4. samples averaged into a linear [`Frame`], written as tone-mapped PNG or EXR.
//!
//! Rasterisation uses fixed-point edge functions with a top-left fill rule, near-plane
//! and guard-band clipping, and perspective-correct attributes. Rows are split into
//! strips rendered in parallel with rayon; output is bit-identical at any thread count.
//! A GPU backend could sit behind a cargo feature and reuse the scene types unchanged.

#![warn(missing_docs)]

mod camera;
mod cubemap;
mod environment;
mod error;
mod frame;
#[cfg(feature = "wgpu")]
pub mod gpu;
mod ground;
mod index_f32;
mod irradiance;
mod lod;
mod lut_sampler;
mod mesh;
mod obj;
mod passes;
mod raster;
pub mod reference;
mod renderer;
mod scene;
mod settings;
mod shading;
mod sky_span;
mod spheremap;
mod texture;
mod water;
mod water_pass;

pub use camera::{Camera, DEFAULT_NEAR_M};
pub use cubemap::{CubeMap, MAX_FACE_SIZE};
pub use environment::{Environment, Sky};
pub use error::RenderError;
pub use frame::{Frame, FrameTimings, linear_to_srgb, tone_map};
pub use glam::{Mat3, Vec3};
pub use irradiance::Irradiance;
pub use lut::Lut;
pub use mesh::TriMesh;
pub use renderer::Renderer;
pub use scene::{BubbleMesh, FilmTables, Ground, Light, Material, Object, Pattern, RenderScene};
pub use settings::{
    MAX_IMAGE_SIDE, PartialShading, ReflectionFilter, ReflectionMode, RenderSettings,
    SAMPLE_COUNTS, ToneMap,
};
pub use spheremap::SphereMap;
pub use texture::Texture;
pub use water::{WATER_IOR, WaterSurface, refract, sphere_map_direction, sphere_map_uv};
