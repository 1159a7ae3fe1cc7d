//! The scene's opaque objects and light spheres as the one set of world-space triangles
//! every backend draws.

use glam::Vec3;

use crate::shader_constants::EMISSIVE;
use crate::{Material, Object, RenderScene, TriMesh};

/// Attributes per vertex: normal x, y, z and texture u, v.
pub const ATTRS: usize = 5;

/// Slices and stacks of a tessellated [`Object::Sphere`].
pub const SPHERE_SEGMENTS: (usize, usize) = (48, 24);
/// Slices and stacks of a drawn light sphere.
pub const LIGHT_SEGMENTS: (usize, usize) = (16, 8);

/// World-space opaque triangles with a material tag each.
#[derive(Debug, Clone, Default)]
pub struct Geometry {
    /// Vertex positions in metres.
    pub positions: Vec<Vec3>,
    /// Per vertex: normal x, y, z and texture u, v.
    pub attrs: Vec<[f32; ATTRS]>,
    /// Vertex indices per triangle.
    pub triangles: Vec<[u32; 3]>,
    /// Per triangle: the material index, or [`EMISSIVE`] with a light's index.
    pub tags: Vec<u32>,
}

impl Geometry {
    /// Empties it, keeping its allocations.
    pub fn clear(&mut self) {
        self.positions.clear();
        self.attrs.clear();
        self.triangles.clear();
        self.tags.clear();
    }

    /// Appends `mesh`'s triangles with material `tag`.
    pub fn push(&mut self, mesh: &TriMesh, tag: u32) {
        let base = self.positions.len() as u32;
        self.positions.extend_from_slice(&mesh.positions);
        for (k, n) in mesh.normals.iter().enumerate() {
            let uv = mesh.uvs.get(k).copied().unwrap_or([0.0; 2]);
            self.attrs.push([n.x, n.y, n.z, uv[0], uv[1]]);
        }
        for t in &mesh.triangles {
            self.triangles.push(t.map(|i| i + base));
            self.tags.push(tag);
        }
    }
}

/// Fills `objects` and `light_spheres` with the scene's world-space triangles (both
/// backends draw these same triangles); returns the material table `objects`' tags index.
pub fn tessellate<'s>(
    scene: &'s RenderScene,
    objects: &mut Geometry,
    light_spheres: &mut Geometry,
) -> Vec<&'s Material> {
    objects.clear();
    light_spheres.clear();
    let mut materials = Vec::with_capacity(scene.objects.len());
    for (k, object) in scene.objects.iter().enumerate() {
        materials.push(object.material());
        let tag = k as u32;
        match object {
            Object::Sphere {
                center, radius_m, ..
            } => {
                let (s, r) = SPHERE_SEGMENTS;
                objects.push(&TriMesh::uv_sphere(*center, *radius_m, s, r), tag);
            }
            Object::Box {
                center,
                half_extents_m,
                ..
            } => objects.push(&TriMesh::cuboid(*center, *half_extents_m), tag),
            Object::Mesh { mesh, .. } => objects.push(mesh, tag),
        }
    }
    for (k, light) in scene.lights.iter().enumerate() {
        let (s, r) = LIGHT_SEGMENTS;
        let mesh = TriMesh::uv_sphere(light.position, light.radius_m, s, r);
        light_spheres.push(&mesh, EMISSIVE | k as u32);
    }
    materials
}
