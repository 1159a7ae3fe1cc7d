//! Particle/mesh soap-bubble dynamics (seed 000 §3, after Durikovic 2001), with the
//! thickness behaviour of seed 001, in SI units throughout.
//!
//! Independent of optics: it knows meshes, forces and film thickness, never colour.
//! A bubble is an icosphere whose vertices are particles (seed 000 eq. 1):
//! film tension −T ∂A/∂x (exact area gradient), isothermal gas pressure Δp ∂V/∂x (exact
//! volume gradient), gravity and hydrostatic buoyancy, drag against a wind field,
//! damping, and collisions. Film thickness follows seed 000 eq. 2 with per-vertex film
//! mass, which drains downhill, swirls, evaporates, and bursts the bubble when too thin.
//! The model, parameters and measured figures are in `docs/dynamics.md`.
//!
//! ```
//! use bubble_dynamics::{BubbleParams, Collider, World, WorldParams};
//! use glam::DVec3;
//!
//! let params = WorldParams { colliders: vec![Collider::ground(0.0)], ..WorldParams::default() };
//! let bubble = BubbleParams { center_m: DVec3::new(0.0, 0.3, 0.0), subdivisions: 2, ..BubbleParams::default() };
//! let mut world = World::try_new(params, vec![bubble]).unwrap();
//! world.advance(0.05).unwrap();
//! let b = &world.bubbles()[0];
//! assert!(b.velocity_m_per_s().y < 0.0); // falling
//! assert!((b.pressure_excess_pa() - 4.0 * 0.025 / b.radius_m()).abs() < 0.05);
//! ```

mod avx2;
#[cfg(test)]
mod bits;
mod bubble;
mod collide;
mod collider;
mod dynamics;
mod error;
mod exp;
mod film;
pub mod film_flow;
pub mod geometry;
pub mod icosphere;
mod params;
mod rng;
mod topology;
mod validate;
mod wind;
mod world;

pub use bubble::{Bubble, FilmField, rest_pressure_excess_pa};
pub use collider::{Collider, DEFAULT_FRICTION, DEFAULT_RESTITUTION};
pub use error::{Divergence, ParamError, SimError};
pub use params::{
    AIR_MOLAR_MASS_KG_PER_MOL, BubbleParams, GAS_CONSTANT_J_PER_MOL_K, Integrator, MAX_FILM_GRID,
    MAX_WARMING_K, MassDistribution, STANDARD_GRAVITY_M_PER_S2, STANDARD_PRESSURE_PA, WorldParams,
};
pub use topology::{Edge, Topology};
pub use wind::{Gusts, Wind, WindFn};
pub use world::{Event, World};

pub use glam::DVec3;
