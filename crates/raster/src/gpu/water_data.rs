//! The water surface as the shaders read it (`fs_water`): its triangles as object vertices
//! tagged [`WATER`], the WGSL `Water` uniform and the two Fresnel tables. Pure CPU code.

// Without the `wgpu` feature only the naga layout test uses this module.
#![cfg_attr(not(feature = "wgpu"), allow(dead_code))]

use render_scene::shader_constants::WATER;
use render_scene::water::FresnelTable;
use render_scene::{ReflectionMode, RenderScene, WaterSurface};

use super::bytes::Bytes;

/// `Water.reflection` of the cube map seen from the mirrored eye (`water_cube`).
pub(super) const WATER_REFLECTION_CUBE: u32 = 0;
/// `Water.reflection` of the environment alone.
pub(super) const WATER_REFLECTION_ENVIRONMENT: u32 = 1;
/// `Water.reflection` of the sphere map read through the camera's view space.
pub(super) const WATER_REFLECTION_SPHERE_MAP: u32 = 2;
/// Bytes of the WGSL `Water` uniform.
pub(super) const WATER_UNIFORM_BYTES: u64 = 5 * 16;

/// Everything the water's fragment shader reads, packed.
#[derive(Debug, Default)]
pub(super) struct WaterData {
    /// The surface's vertices as object vertices (position, normal, tag [`WATER`], uv 0),
    /// as raster's `setup_water` sets them up.
    pub vertices: Vec<u8>,
    /// The triangles' vertex indices (u32), three a triangle: indexed, the vertex stage
    /// runs once per vertex rather than six times (pond: 66 049 vertices, 131 072
    /// triangles).
    pub indices: Vec<u8>,
    /// Indices in [`WaterData::indices`].
    pub index_count: u32,
    /// The WGSL `Water` uniform.
    pub uniform: Vec<u8>,
    /// `R(cos θ)` from air into water, then from water into air: each
    /// `FresnelTable::samples`, `FRESNEL_STEPS + 1` f32s.
    pub fresnel: Vec<u8>,
}

impl WaterData {
    /// Packs `water` of `scene`, its reflections as `reflection` chooses (as raster's
    /// `WaterPass::shading`), its floor being material `floor_material`.
    pub(super) fn new(
        water: &WaterSurface,
        scene: &RenderScene,
        reflection: &ReflectionMode,
        floor_material: u32,
    ) -> WaterData {
        let mut vertices = Bytes::default();
        for (p, n) in water.positions.iter().zip(&water.normals) {
            vertices.f32(p.x).f32(p.y).f32(p.z);
            vertices.f32(n.x).f32(n.y).f32(n.z);
            vertices.u32(WATER).f32(0.0).f32(0.0);
        }
        let indices: Vec<u8> = water
            .triangles
            .iter()
            .flatten()
            .flat_map(|i| i.to_le_bytes())
            .collect();
        let (kind, face_size) = match reflection {
            ReflectionMode::DynamicCubeMap { face_size } => (WATER_REFLECTION_CUBE, *face_size),
            ReflectionMode::StaticEnvironment => (WATER_REFLECTION_ENVIRONMENT, 0),
            ReflectionMode::SphereMap(_) => (WATER_REFLECTION_SPHERE_MAP, 0),
        };
        let mut uniform = Bytes::default();
        uniform.vec4(water.absorption_per_m, water.ior);
        uniform
            .f32(water.floor_height_m())
            .u32(floor_material)
            .u32(kind)
            .u32(face_size as u32);
        // The sphere map is read through seed 002's view space (raster's `WaterPass`).
        let eye_from_world = scene.camera.world_from_eye().transpose();
        for row in 0..3 {
            uniform.vec4(eye_from_world.row(row).to_array(), 0.0);
        }
        debug_assert_eq!(uniform.0.len() as u64, WATER_UNIFORM_BYTES);
        let mut fresnel = Bytes::default();
        for table in [
            FresnelTable::new(1.0, water.ior),
            FresnelTable::new(water.ior, 1.0),
        ] {
            for &r in table.samples() {
                fresnel.f32(r);
            }
        }
        WaterData {
            index_count: (water.triangles.len() * 3) as u32,
            indices,
            vertices: vertices.0,
            uniform: uniform.0,
            fresnel: fresnel.0,
        }
    }
}
