//! Bakes, exports and samples the (thickness, cos θ) textures of seed 000 §4.2.
//!
//! Data flows thinfilm → lut → raster: this crate turns spectral film optics into
//! small RGB tables that a renderer samples per pixel.

mod table;

pub use table::{Lut, LutError};
