//! Particle/mesh soap-bubble dynamics (seed 000 §3, after Durikovic 2001).
//!
//! Independent of optics: it knows meshes, forces and film thickness, never colour.
