//! Bakes, exports and samples the (thickness, cos θ) textures of seed 000 §4.2.
//!
//! Data flows thinfilm → lut → raster: this crate turns spectral film optics into
//! small RGB tables that a renderer samples per pixel.
//!
//! ```no_run
//! let set = lut::bake(&lut::BakeConfig::default());
//! let rgb = set.reflectivity.sample(550.0, 0.8);
//! set.save(std::path::Path::new("luts"), &lut::Format::DEFAULT)?;
//! let back = lut::LutSet::load(std::path::Path::new("luts"))?;
//! assert_eq!(back.reflectivity, set.reflectivity);
//! # let _ = rgb;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod accuracy;
mod bake;
mod checksum;
pub mod config;
mod format;
mod json_layout;
mod load;
mod meta;
mod save;
mod set;
mod table;
mod weights;

pub use bake::{bake, bake_point_sampled, bake_with_progress, progress_rows, spectral_samples};
pub use config::{BakeConfig, BakeConfigBuilder, ConfigError, Light};
pub use format::{Format, UnknownFormat};
pub use load::LoadError;
pub use meta::{COLOR_SPACE, FORMAT_VERSION, LutMeta};
pub use save::{DESCRIPTION_FILE, SaveError};
pub use set::{LutSet, is_valid_light_name, light_stem};
pub use table::{Lut, LutError, MAX_SIDE};
