//! What a `bubbles` frame is, and what each of its pixels must equal: the scene model and
//! the shading formulas that every renderer backend reads.
//!
//! Three backends draw a [`RenderScene`] with its [`FilmTables`] under [`RenderSettings`]
//! into a linear [`Frame`]: the CPU sorted-triangle renderer (`raster`, the
//! specification), its wgpu port (`raster::gpu`) and the spectral reference tracer
//! (`reference-tracer`). This crate is what they share:
//! - the scene: [`Camera`] and its per-pixel [`camera::View`], [`Environment`] and
//!   [`Irradiance`], [`Ground`], [`Object`]s and their one tessellation ([`tessellate`]),
//!   [`Light`]s, [`BubbleMesh`]es with their drawing order ([`bubble_order`]) and film
//!   fields ([`FilmField`]), the
//!   [`WaterSurface`], [`Texture`]s, [`SphereMap`]s and [`CubeMap`]s;
//! - the per-pixel formulas: opaque [`shading`], the LUT lookup ([`lut_sampler`]), cube-map
//!   sampling and its footprint filter ([`cubemap`], [`lod`]), a bubble's [`reflection`]
//!   with its [`parallax`] correction and light [`highlight`], the ground plane per view ([`ground_view`]), the water's
//!   Fresnel blend ([`water_shading`]) and the tone curve ([`frame`]);
//! - [`shader_constants`]: every CPU-defined constant a shader sees, in one list.
//!
//! It holds no pixel loop, no thread pool and no GPU code. A scene validates on its own
//! ([`RenderScene::validate`]); the film tables are checked against it apart
//! ([`FilmTables::validate_for`]).

#![warn(missing_docs)]

pub mod bubble_order;
pub mod camera;
pub mod cubemap;
pub mod environment;
mod error;
pub mod film_field;
pub mod frame;
pub mod ground_view;
pub mod highlight;
pub mod index_f32;
pub mod irradiance;
pub mod lod;
pub mod lut_sampler;
mod material;
pub mod mesh;
mod obj;
pub mod parallax;
pub mod reflection;
mod scene;
pub mod settings;
pub mod shader_constants;
pub mod shading;
pub mod spheremap;
pub mod tessellate;
pub mod texture;
pub mod water;
pub mod water_shading;

pub use camera::{Camera, DEFAULT_NEAR_M};
pub use cubemap::{CubeMap, MAX_FACE_SIZE};
pub use environment::{Environment, Sky};
pub use error::RenderError;
pub use film_field::{BubbleFilm, FilmField, FilmSample, MAX_FILM_THICKNESS_NM};
pub use frame::{
    Frame, FrameTimings, Srgb8Encoder, TONE_MAP_LANES, linear_to_srgb, linear_to_srgb8_reference,
    tone_map, tone_map_lanes,
};
pub use glam::{Mat3, Vec3};
pub use irradiance::Irradiance;
pub use lut::Lut;
pub use material::{Material, Pattern};
pub use mesh::TriMesh;
pub use scene::{BubbleMesh, FilmTables, Ground, Light, Object, RenderScene};
pub use settings::{
    MAX_IMAGE_SIDE, PartialShading, ReflectionFilter, ReflectionMode, ReflectionParallax,
    RenderSettings, SAMPLE_COUNTS, ToneMap,
};
pub use spheremap::SphereMap;
pub use texture::Texture;
pub use water::{WATER_IOR, WaterSurface, refract, sphere_map_direction, sphere_map_uv};
