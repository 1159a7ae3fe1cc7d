//! The wgpu backend (cargo feature `wgpu`): `GpuRenderer` draws a [`render_scene::RenderScene`]
//! headless, as seed 000 §4.4 on the GPU: per-bubble dynamic cube maps, the opaque scene
//! with a depth buffer into a multisampled linear HDR target, bubbles sorted far to near
//! (back faces, then front faces) in a multiplicative and an additive blend pass, then
//! the resolve and the tone-map pass.
//!
//! Bubbles with a film field (`BubbleMesh::film`) are drawn as the CPU draws them: every
//! distinct field's bordered faces (`FilmField::bordered`) sit in one Rg32Float data
//! texture of `[thickness_nm, coverage]`, each bubble vertex carries its material direction
//! and its field's (first texel, face size), and the bubble fragment shader ports
//! `FilmField::sample` with `textureLoad` (`film_sample`), shades with the field's thickness and blends by the
//! coverage `c`: `1 − T' = c·(1 − T)`, `add' = c·add`; `c = 0` leaves the pixel as it is.
//!
//! `GpuRenderer::for_window` opens the device for a window instead, and
//! `GpuRenderer::present` puts each frame on it (`present`): tone-mapped and upscaled
//! straight into the surface texture, the overlay blended on top, nothing read back.
//!
//! A water surface (`RenderScene::water`) is drawn as the CPU draws it: its triangles join
//! the opaque pass (`fs_water`, a port of `WaterShading::radiance`), and with dynamic cube
//! maps its reflections come from six more faces rendered from the eye mirrored in its
//! rest plane, the bubbles (sorted for that eye) blended into them; bubbles' own cube maps
//! do not see the water, as on the CPU.
//!
//! The CPU backend is the specification: every shader function names the Rust function it
//! ports. Constants the two must share (tone curve, sRGB encoding, highlight filter, tag
//! bits) are injected into the WGSL from the Rust constants, never retyped; see
//! `shader_source`. Sorting, side classification and tessellation come from the scene crate
//! (`render_scene::bubble_order`, `render_scene::tessellate`), as the CPU renderer's do.
//!
//! **Invariant:** this module imports the scene crate and never the CPU renderer's modules
//! (`tests/layout.rs` checks it). Its pure-CPU half (`scene_data`, `water_data`,
//! `bytes`, `shader_source`, `error`) compiles without the feature, so `cargo test` checks the generated WGSL with naga and
//! the packed struct sizes against it without a GPU or wgpu.

mod bytes;
#[cfg(feature = "wgpu")]
mod context;
mod error;
#[cfg(test)]
mod naga_layout;
#[cfg(feature = "wgpu")]
mod pipelines;
#[cfg(feature = "wgpu")]
mod present;
#[cfg(feature = "wgpu")]
mod renderer;
mod scene_data;
mod shader_source;
#[cfg(feature = "wgpu")]
mod tonemap;
mod water_data;

#[cfg(feature = "wgpu")]
pub use context::{Gpu, GpuOptions};
pub use error::GpuError;
#[cfg(feature = "wgpu")]
pub use present::{Overlay, WindowSurface};
#[cfg(feature = "wgpu")]
pub use renderer::GpuRenderer;
