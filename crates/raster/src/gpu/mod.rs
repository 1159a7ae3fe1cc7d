//! The wgpu backend (cargo feature `wgpu`): [`GpuRenderer`] draws a [`crate::RenderScene`]
//! headless, as seed 000 §4.4 on the GPU: per-bubble dynamic cube maps, the opaque scene
//! with a depth buffer into a multisampled linear HDR target, bubbles sorted far to near
//! (back faces, then front faces) in a multiplicative and an additive blend pass, then
//! the resolve and the tone-map pass.
//!
//! The CPU backend is the specification: every shader function names the Rust function it
//! ports. Constants the two must share (tone curve, sRGB encoding, highlight filter, tag
//! bits) are injected into the WGSL from the Rust constants, never retyped; see
//! `shader_source`. Sorting, side classification and tessellation reuse the CPU's Rust.

mod context;
mod error;
mod pipelines;
mod renderer;
mod scene_data;
mod shader_source;
mod tonemap;

pub use context::{Gpu, GpuOptions};
pub use error::GpuError;
pub use renderer::GpuRenderer;
