//! Procedural water surfaces after seed 002 (Oliveira, "Refractive Texture Mapping"):
//! a flat grid of `n × m` slices perturbed by a sum of directional sine waves and
//! circular ripples (seed 002 equations 4–6), with vertex normals.
//!
//! Geometry only: this crate knows nothing of light or rendering. Heights are `y`
//! (up), the rest plane is `y = rest_height_m`, and the grid spans X and Z.
//!
//! ```
//! use water::{Grid, Perturbation, Surface, Wave};
//!
//! let grid = Grid::try_new([-1.0, -1.0], [1.0, 1.0], [64, 64], 0.0).unwrap();
//! let wave = Wave::try_new(0.01, 0.5, [1.0, 1.0], None).unwrap();
//! let mut surface = Surface::new(grid, vec![Perturbation::Wave(wave)]);
//! let mesh = surface.evaluate(0.25);
//! assert_eq!(mesh.positions.len(), 65 * 65);
//! assert!((mesh.normals[0].length() - 1.0).abs() < 1e-5);
//! ```

#![warn(missing_docs)]

mod dispersion;
mod error;
mod grid;
mod perturbation;
mod surface;

pub use dispersion::{
    GRAVITY_M_PER_S2, WATER_DENSITY_KG_PER_M3, WATER_SURFACE_TENSION_N_PER_M,
    deep_water_omega_rad_per_s,
};
pub use error::WaterError;
pub use glam::Vec3;
pub use grid::Grid;
pub use perturbation::{Perturbation, Ripple, Wave};
pub use surface::{Surface, WaterMesh, face_averaged_normals};
