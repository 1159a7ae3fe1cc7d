//! How the renderer draws a [`WaterSurface`]: its triangles join the opaque pass with the
//! [`WATER`] tag and are shaded by [`WaterShading`]; in dynamic cube-map mode its
//! reflections come from one cube map per frame rendered from the mirror image of the
//! eye in the rest plane.
//!
//! Why the mirrored eye: for the flat surface, the ray reflected at any point is exactly
//! the ray from the mirrored eye through that point, so the cube map is a true planar
//! mirror at every pixel (no parallax error, unlike a map centred on the pond), and waves
//! perturb it through their normals. The price: the map sees the world from below the
//! water, so the ground plane is left out of it (a ground at or above the mirrored eye
//! would cover every upward ray; reflected, it shows only at grazing angles anyway), and
//! objects under the water would wrongly appear in reflections.

use glam::Vec3;
use rayon::prelude::*;
use render_scene::camera::View;
use render_scene::cubemap::FACE_BASES;
use render_scene::shader_constants::WATER;
use render_scene::water::FresnelTable;
use render_scene::water_shading::{WaterReflection, WaterShading};
use render_scene::{
    CubeMap, Irradiance, ReflectionMode, RenderScene, RenderSettings, WaterSurface,
};

use super::bubble::{BubbleCtx, setup_bubble_tris};
use super::opaque::OpaqueCtx;
use crate::raster::{ClipVertex, SamplePattern, SetupTri, append_in_order, setup_triangle};
use crate::strip::{Bins, STRIP_ROWS};

/// Clips and sets up the water's triangles for `view`, tagged [`WATER`], appending them to
/// `out` in the mesh's order; `chunks` holds each chunk's set-up between frames.
///
/// In parallel: the pond's 131 k triangles took a fifth of its frame on one thread. Chunks
/// are set up apart and copied into `out` in chunk order, so the result does not depend
/// on the thread count.
pub(crate) fn setup_water(
    water: &WaterSurface,
    view: &View,
    out: &mut Vec<SetupTri>,
    chunks: &mut Vec<Vec<SetupTri>>,
) {
    chunks.resize_with(water.triangles.len().div_ceil(WATER_CHUNK), Vec::new);
    water
        .triangles
        .par_chunks(WATER_CHUNK)
        .zip(chunks.par_iter_mut())
        .for_each(|(tris, chunk)| {
            chunk.clear();
            for t in tris {
                setup_water_triangle(water, view, t, chunk);
            }
        });
    append_in_order(out, chunks);
}

/// Water triangles set up per parallel task.
const WATER_CHUNK: usize = 4096;

/// Clips and sets up water triangle `t` (mesh indices) into `out`.
#[inline]
fn setup_water_triangle(water: &WaterSurface, view: &View, t: &[u32; 3], out: &mut Vec<SetupTri>) {
    let tri = t.map(|i| {
        let (p, n) = (water.positions[i as usize], water.normals[i as usize]);
        let [x, y, w] = view.clip(p);
        ClipVertex {
            x,
            y,
            w,
            attrs: [n.x, n.y, n.z, 0.0, 0.0, 0.0],
        }
    });
    setup_triangle(view, tri, WATER, 0.0, |s| out.push(s));
}

/// One cube face's buffers, reused across frames.
#[derive(Debug, Clone, Default)]
struct FaceScratch {
    tris: Vec<SetupTri>,
    bins: Bins,
    bubble_tris: Vec<SetupTri>,
    /// Each bubble's triangles, set up in parallel before joining `bubble_tris`.
    layers: Vec<Vec<SetupTri>>,
    bubble_bins: Bins,
    depth: Vec<f32>,
}

/// The water's per-frame state kept by the renderer: Fresnel tables and reflection cube map.
#[derive(Debug, Default)]
pub(crate) struct WaterPass {
    tables: Option<(f32, FresnelTable, FresnelTable)>,
    cube: Option<CubeMap>,
    faces: Vec<FaceScratch>,
}

impl WaterPass {
    /// Builds the Fresnel tables (from air, from water) for index `ior`, unless they are
    /// already for it.
    pub fn prepare_tables(&mut self, ior: f32) {
        if self.tables.as_ref().is_none_or(|(n, ..)| *n != ior) {
            self.tables = Some((
                ior,
                FresnelTable::new(1.0, ior),
                FresnelTable::new(ior, 1.0),
            ));
        }
    }

    /// How `surface` is shaded this frame: reflections from the water cube map, the
    /// environment or the sphere map (in the camera's view space), as `settings` choose.
    ///
    /// # Panics
    /// If [`WaterPass::prepare_tables`] was not called first.
    pub fn shading<'a>(
        &'a self,
        surface: &'a WaterSurface,
        scene: &'a RenderScene,
        settings: &'a RenderSettings,
        ambient: &Irradiance,
    ) -> WaterShading<'a> {
        let (_, from_air, from_water) = self.tables.as_ref().expect("tables prepared");
        let env = WaterReflection::Env(&scene.environment);
        let reflection = match &settings.reflection {
            ReflectionMode::DynamicCubeMap { .. } => {
                self.cube.as_ref().map_or(env, WaterReflection::Cube)
            }
            ReflectionMode::StaticEnvironment => env,
            ReflectionMode::SphereMap(map) => {
                WaterReflection::Sphere(map, scene.camera.world_from_eye().transpose())
            }
        };
        WaterShading {
            surface,
            from_air,
            from_water,
            reflection,
            floor_ambient: ambient.diffuse(Vec3::Y),
        }
    }

    /// The reflection cube map of the last frame, if one was rendered.
    pub fn cube(&self) -> Option<&CubeMap> {
        self.cube.as_ref()
    }

    /// Renders the reflection cube map from the eye mirrored in the water's rest plane:
    /// opaque geometry from `opaque_setup`, the sky from `env_cube` when given, and the
    /// bubbles blended over it with `bubbles`' tables and reflections.
    pub fn render_cube(
        &mut self,
        scene: &RenderScene,
        face_size: usize,
        opaque: &OpaqueCtx<'_>,
        bubbles: &BubbleCtx<'_>,
        env_cube: Option<&CubeMap>,
        opaque_setup: &(dyn Fn(&View, &mut Vec<SetupTri>) + Sync),
    ) {
        let Some(water) = &scene.water else {
            return;
        };
        let cube = match &mut self.cube {
            Some(c) if c.face_size() == face_size => c,
            slot => slot.insert(CubeMap::black(face_size)),
        };
        self.faces.resize_with(6, FaceScratch::default);
        let eye = scene.camera.eye();
        let mirrored = Vec3::new(eye.x, 2.0 * water.rest_height_m - eye.y, eye.z);
        let m = face_size + 2;
        let jobs: Vec<_> = cube
            .faces_mut()
            .zip(self.faces.iter_mut())
            .enumerate()
            .collect();
        jobs.into_par_iter().for_each(|(j, (texels, scratch))| {
            let (major, s_axis, t_axis) = FACE_BASES[j];
            let wide = m as f32 / face_size as f32;
            let view = View::new(
                mirrored,
                [major, s_axis, -t_axis],
                (wide, wide),
                (m, m),
                scene.camera.near_m(),
            );
            let strips = m.div_ceil(STRIP_ROWS);
            scratch.tris.clear();
            opaque_setup(&view, &mut scratch.tris);
            scratch.bins.build(&scratch.tris, strips);
            scratch.bubble_tris.clear();
            setup_bubble_tris(scene, &view, &mut scratch.bubble_tris, &mut scratch.layers);
            scratch.bubble_bins.build(&scratch.bubble_tris, strips);
            scratch.depth.resize(m * m, 0.0);
            let pattern = SamplePattern::new(1);
            let face_opaque = OpaqueCtx {
                view,
                pattern,
                sky_texels: env_cube.map(|c| c.face(j)),
                ground: None,
                water: None,
                tris: &scratch.tris,
                bins: &scratch.bins,
                ..*opaque
            };
            let face_bubbles = BubbleCtx {
                view,
                pattern,
                tris: &scratch.bubble_tris,
                bins: &scratch.bubble_bins,
                ..*bubbles
            };
            let rows = STRIP_ROWS * m;
            texels
                .par_chunks_mut(rows)
                .zip(scratch.depth.par_chunks_mut(rows))
                .enumerate()
                .for_each(|(s, (color, depth))| {
                    face_opaque.render_strip(s, color, depth);
                    face_bubbles.render_strip(s, color, depth);
                });
        });
        // The water reads level 0 only; the chain keeps the public map consistent.
        if let Some(c) = &mut self.cube {
            c.build_mips();
        }
    }
}
