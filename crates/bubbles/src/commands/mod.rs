//! One module per subcommand, each with `Args` and `run`.

pub mod animate;
pub mod bake;
pub mod bench;
pub mod chart;
pub mod color;
pub mod compare;
pub mod fit;
pub mod reflectance;
pub mod render;
pub mod simulate;
pub mod thickness;
