//! The CPU sorted-triangle blend renderer for thin-film soap bubbles (seed 000 §4), the
//! specification the other backends are measured against, with its wgpu port in [`gpu`]
//! (the `wgpu` cargo feature).
//!
//! It draws a [`RenderScene`] (the scene crate, `render_scene`, re-exported here) with
//! baked [`FilmTables`]. A frame ([`Renderer::render`]):
//! 1. the opaque scene — [`Environment`], optional [`Ground`] plane, [`Object`]s lit by
//!    [`Light`]s and by the environment's [`Irradiance`] — rasterised with a depth buffer into an HDR sample buffer;
//! 2. per bubble, a dynamic [`CubeMap`] of that scene from the bubble's centre
//!    ([`ReflectionMode::DynamicCubeMap`]), or the environment / a [`SphereMap`] instead;
//! 3. bubbles sorted far to near, each drawn back faces then front faces with
//!    `dest = dest ⊙ T(d, cos θ) + R(d, cos θ) ⊙ env(reflect) + Σ light highlights`;
//! 4. samples averaged into a linear [`Frame`], written as tone-mapped PNG or EXR.
//!
//! Rasterisation (`raster`) uses fixed-point edge functions with a top-left fill rule, near-plane
//! and guard-band clipping, and perspective-correct attributes. Rows are split into
//! strips (`strip`) rendered in parallel with rayon by the passes (`passes`); output is
//! bit-identical at any thread count. What each pixel must equal (shading, LUT and cube-map
//! sampling, highlights, tone curve) lives in the scene crate, shared with [`gpu`].

#![warn(missing_docs)]

mod cube_reuse;
pub mod gpu;
mod passes;
mod raster;
mod renderer;
mod strip;

pub use cube_reuse::CubeMapReuse;
pub use renderer::Renderer;

pub use render_scene::{
    BubbleFilm, BubbleMesh, Camera, CubeMap, DEFAULT_NEAR_M, Environment, FilmField, FilmSample,
    FilmTables, Frame, FrameTimings, Ground, Irradiance, Light, Lut, MAX_FACE_SIZE,
    MAX_FILM_THICKNESS_NM, MAX_IMAGE_SIDE, Mat3, Material, Object, PartialShading, Pattern,
    ReflectionFilter, ReflectionMode, ReflectionParallax, RenderError, RenderScene, RenderSettings,
    SAMPLE_COUNTS, Sky, SphereMap, Texture, ToneMap, TriMesh, Vec3, WATER_IOR, WaterSurface,
    linear_to_srgb, refract, sphere_map_direction, sphere_map_uv, tone_map,
};
