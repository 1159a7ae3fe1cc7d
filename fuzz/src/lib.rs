//! The `bubbles` CLI's scene, frame and input modules, compiled from their own sources
//! (the CLI is a binary crate) so the fuzz targets drive exactly the code users run.
#![allow(dead_code, unused_imports)]

#[path = "../../crates/bubbles/src/csv_table.rs"]
pub mod csv_table;
#[path = "../../crates/bubbles/src/error.rs"]
pub mod error;
#[path = "../../crates/bubbles/src/frame/mod.rs"]
pub mod frame;
#[path = "../../crates/bubbles/src/input.rs"]
pub mod input;
#[path = "../../crates/bubbles/src/limits.rs"]
pub mod limits;
#[path = "../../crates/bubbles/src/scene/mod.rs"]
pub mod scene;
#[path = "../../crates/bubbles/src/signals.rs"]
pub mod signals;

pub mod scenegen;
