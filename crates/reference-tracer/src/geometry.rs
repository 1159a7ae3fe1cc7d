//! The scene as the reference intersects it: bubble triangles and opaque triangles
//! (objects tessellated exactly as the CPU backend does) in two BVHs, the analytic
//! ground plane and the lights as the spheres they are.

use glam::Vec3;

use render_scene::tessellate::SPHERE_SEGMENTS;
use render_scene::{Object, RenderScene, TriMesh};

use crate::bvh::{Bvh, TriHit};

/// Shortest ray parameter counted as a hit, in metres (rays have unit direction).
pub(crate) const T_MIN_M: f32 = 1e-6;

/// What a ray hit first.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Hit {
    /// Bubble triangle `tri` (index into [`Geometry::bubble_tris`]).
    Film { tri: u32, t: f32, u: f32, v: f32 },
    /// Opaque triangle `tri` of object [`Geometry::opaque_owner`].
    Opaque { tri: u32, t: f32, u: f32, v: f32 },
    /// The ground plane.
    Ground { t: f32 },
    /// Light sphere `light`.
    Light { light: usize },
}

/// Intersectable scene.
pub(crate) struct Geometry<'a> {
    pub scene: &'a RenderScene,
    pub bubble_tris: Vec<[Vec3; 3]>,
    /// Per bubble triangle: its bubble and vertex indices.
    pub bubble_owner: Vec<(u32, [u32; 3])>,
    /// Per bubble: its centre (where the CPU backend renders its cube map from).
    pub centres: Vec<Vec3>,
    bubble_bvh: Bvh,
    pub opaque_tris: Vec<[Vec3; 3]>,
    /// Per opaque triangle: its object and vertex indices into [`Geometry::meshes`].
    pub opaque_owner: Vec<(u32, [u32; 3])>,
    pub meshes: Vec<TriMesh>,
    opaque_bvh: Bvh,
}

impl<'a> Geometry<'a> {
    /// Builds both hierarchies.
    pub fn new(scene: &'a RenderScene) -> Geometry<'a> {
        let mut bubble_tris = Vec::new();
        let mut bubble_owner = Vec::new();
        for (b, mesh) in scene.bubbles.iter().enumerate() {
            for t in &mesh.triangles {
                bubble_tris.push(t.map(|i| mesh.positions[i as usize]));
                bubble_owner.push((b as u32, *t));
            }
        }
        let meshes: Vec<TriMesh> = scene.objects.iter().map(tessellate).collect();
        let mut opaque_tris = Vec::new();
        let mut opaque_owner = Vec::new();
        for (o, mesh) in meshes.iter().enumerate() {
            for t in &mesh.triangles {
                opaque_tris.push(t.map(|i| mesh.positions[i as usize]));
                opaque_owner.push((o as u32, *t));
            }
        }
        Geometry {
            scene,
            centres: scene.bubbles.iter().map(|b| b.center()).collect(),
            bubble_bvh: Bvh::build(&bubble_tris),
            bubble_tris,
            bubble_owner,
            opaque_bvh: Bvh::build(&opaque_tris),
            opaque_tris,
            opaque_owner,
            meshes,
        }
    }

    /// The first thing along `origin + t·dir` (unit `dir`); films are skipped when
    /// `films` is false, and triangle `skip` (the film just left) always.
    pub fn closest(&self, origin: Vec3, dir: Vec3, films: bool, skip: Option<u32>) -> Option<Hit> {
        let mut best: Option<(f32, Hit)> = None;
        let consider = |best: &mut Option<(f32, Hit)>, t: f32, hit: Hit| {
            if t > T_MIN_M && best.is_none_or(|(b, _)| t < b) {
                *best = Some((t, hit));
            }
        };
        let far = f32::INFINITY;
        if let Some(TriHit { tri, t, u, v }) =
            self.opaque_bvh
                .closest(&self.opaque_tris, origin, dir, (T_MIN_M, far), None)
        {
            consider(&mut best, t, Hit::Opaque { tri, t, u, v });
        }
        if let Some(g) = &self.scene.ground {
            let t = (g.height_m - origin.y) / dir.y;
            if t.is_finite() {
                consider(&mut best, t, Hit::Ground { t });
            }
        }
        for (k, light) in self.scene.lights.iter().enumerate() {
            if let Some(t) = sphere_hit(light.position, light.radius_m, origin, dir) {
                consider(&mut best, t, Hit::Light { light: k });
            }
        }
        if films {
            let limit = best.map_or(far, |(t, _)| t);
            if let Some(TriHit { tri, t, u, v }) =
                self.bubble_bvh
                    .closest(&self.bubble_tris, origin, dir, (T_MIN_M, limit), skip)
            {
                consider(&mut best, t, Hit::Film { tri, t, u, v });
            }
        }
        best.map(|(_, h)| h)
    }
}

/// The object as the CPU backend rasterises it.
fn tessellate(object: &Object) -> TriMesh {
    match object {
        Object::Sphere {
            center, radius_m, ..
        } => TriMesh::uv_sphere(*center, *radius_m, SPHERE_SEGMENTS.0, SPHERE_SEGMENTS.1),
        Object::Box {
            center,
            half_extents_m,
            ..
        } => TriMesh::cuboid(*center, *half_extents_m),
        Object::Mesh { mesh, .. } => mesh.clone(),
    }
}

/// Nearest positive parameter where the ray (unit `dir`) meets the sphere, from outside or inside.
fn sphere_hit(center: Vec3, radius_m: f32, origin: Vec3, dir: Vec3) -> Option<f32> {
    let oc = origin - center;
    let b = oc.dot(dir);
    let c = oc.length_squared() - radius_m * radius_m;
    let disc = b * b - c;
    if disc < 0.0 {
        return None;
    }
    let root = disc.sqrt();
    [-b - root, -b + root].into_iter().find(|&t| t > T_MIN_M)
}

/// Barycentric blend of three vertex values.
#[inline]
pub(crate) fn blend<T>(values: [T; 3], u: f32, v: f32) -> T
where
    T: std::ops::Mul<f32, Output = T> + std::ops::Add<Output = T>,
{
    let [a, b, c] = values;
    a * (1.0 - u - v) + b * u + c * v
}
