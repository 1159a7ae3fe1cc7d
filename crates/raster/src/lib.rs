//! Pure-CPU sorted-triangle blend renderer.
//!
//! Knows triangles, textures and blending; takes bubble meshes with per-vertex
//! thickness and a baked [`lut::Lut`]. It knows no physics.
