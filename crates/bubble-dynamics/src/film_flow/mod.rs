//! The living film: thickness, surfactant and velocity on a cube-sphere grid much finer
//! than the particle mesh, moved by gravity, Marangoni stress, the sheet's viscosity,
//! drainage, the air's shear and evaporation (docs/dynamics.md, "Film flow").

pub(crate) mod advect;
mod burst;
mod capillary;
mod cell_map;
mod compare;
mod face_geometry;
pub(crate) mod face_rows;
mod flow;
mod fluxes;
pub mod grid;
mod marangoni;
mod meniscus;
pub(crate) mod on_bubble;
mod sides;
pub mod solve;
mod thermal;
mod transport;
mod upwind;
mod viscosity;

pub use burst::{BLACK_RELAX_S, BurstParams, Hole, RIM_CELLS_PER_SUBSTEP};
pub use cell_map::CellMap;
pub use flow::{FilmFlow, FilmGradient, FlowParams, Forcing};
pub use grid::CubeSphere;
pub use meniscus::Meniscus;
pub use solve::{Hierarchy, SolveLimits, SolveReport};
pub use thermal::ThermalParams;
