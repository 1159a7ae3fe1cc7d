//! The wgpu backend (cargo feature `wgpu`): a headless device and the GPU passes built so far.
//!
//! The CPU backend is the specification. Constants the two must share (today the tone
//! curve and the sRGB encoding) are injected into the WGSL from the Rust constants, never
//! retyped; see `shader_source`.

mod context;
mod error;
mod shader_source;
mod tonemap;

pub use context::{Gpu, GpuOptions};
pub use error::GpuError;
