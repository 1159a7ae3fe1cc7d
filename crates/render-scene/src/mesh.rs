//! [`TriMesh`]: indexed triangles with per-vertex normals (and optional UVs), plus the
//! tessellations of the analytic objects.

use glam::Vec3;

use crate::RenderError;

/// An indexed triangle mesh with per-vertex normals; `uvs` is empty or one per vertex.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TriMesh {
    /// Vertex positions in metres.
    pub positions: Vec<Vec3>,
    /// Unit vertex normals, pointing out of the surface.
    pub normals: Vec<Vec3>,
    /// Texture coordinates (u right, v down), or empty.
    pub uvs: Vec<[f32; 2]>,
    /// Vertex indices of each triangle.
    pub triangles: Vec<[u32; 3]>,
}

impl TriMesh {
    /// A UV sphere of `segments` slices around Y and `rings` stacks (clamped to ≥ 3 and ≥ 2).
    pub fn uv_sphere(center: Vec3, radius_m: f32, segments: usize, rings: usize) -> TriMesh {
        let segments = segments.max(3);
        let rings = rings.max(2);
        let mut mesh = TriMesh::default();
        for j in 0..=rings {
            let theta = std::f32::consts::PI * j as f32 / rings as f32;
            for i in 0..=segments {
                let phi = std::f32::consts::TAU * i as f32 / segments as f32;
                let n = Vec3::new(
                    theta.sin() * phi.cos(),
                    theta.cos(),
                    -theta.sin() * phi.sin(),
                );
                mesh.positions.push(center + n * radius_m);
                mesh.normals.push(n);
                mesh.uvs
                    .push([i as f32 / segments as f32, j as f32 / rings as f32]);
            }
        }
        let row = segments as u32 + 1;
        for j in 0..rings as u32 {
            for i in 0..segments as u32 {
                let a = j * row + i;
                let b = a + row;
                if j != 0 {
                    mesh.triangles.push([a, b, a + 1]);
                }
                if j + 1 != rings as u32 {
                    mesh.triangles.push([a + 1, b, b + 1]);
                }
            }
        }
        mesh
    }

    /// An axis-aligned box with flat faces and one UV square per face.
    pub fn cuboid(center: Vec3, half_extents_m: Vec3) -> TriMesh {
        let mut mesh = TriMesh::default();
        for axis in 0..3 {
            for sign in [1.0f32, -1.0] {
                let mut n = Vec3::ZERO;
                n[axis] = sign;
                // Any unit u ⟂ n gives u × (n × u) = n, so the quads wind outwards.
                let helper = if axis == 1 { Vec3::Z } else { Vec3::Y };
                let u = helper.cross(n);
                let v = n.cross(u);
                let base = mesh.positions.len() as u32;
                for (du, dv) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                    let p = n + u * du + v * dv;
                    mesh.positions.push(center + p * half_extents_m);
                    mesh.normals.push(n);
                    mesh.uvs.push([(du + 1.0) * 0.5, (1.0 - dv) * 0.5]);
                }
                mesh.triangles.push([base, base + 1, base + 2]);
                mesh.triangles.push([base, base + 2, base + 3]);
            }
        }
        mesh
    }

    /// Checks lengths, indices and finiteness; `what` names the mesh in the error.
    pub fn validate(&self, what: &str) -> Result<(), RenderError> {
        let n = self.positions.len();
        if self.normals.len() != n || !(self.uvs.is_empty() || self.uvs.len() == n) {
            return Err(RenderError::scene(
                what,
                format!(
                    "{n} positions but {} normals and {} uvs",
                    self.normals.len(),
                    self.uvs.len()
                ),
            ));
        }
        check_vertices(what, &self.positions, &self.normals)?;
        if let Some(k) = self
            .uvs
            .iter()
            .position(|uv| !(uv[0].is_finite() && uv[1].is_finite()))
        {
            return Err(RenderError::scene(
                format!("{what}, vertex {k}"),
                format!("uv {:?} is not finite", self.uvs[k]),
            ));
        }
        check_triangles(what, &self.triangles, n)
    }
}

/// Rejects non-finite positions or normals, naming the vertex.
pub(crate) fn check_vertices(
    what: &str,
    positions: &[Vec3],
    normals: &[Vec3],
) -> Result<(), RenderError> {
    for (k, (p, n)) in positions.iter().zip(normals).enumerate() {
        if !(p.is_finite() && n.is_finite()) {
            return Err(RenderError::scene(
                format!("{what}, vertex {k}"),
                format!("position {p} and normal {n} must be finite"),
            ));
        }
    }
    Ok(())
}

/// Rejects out-of-range indices, naming the triangle.
pub(crate) fn check_triangles(
    what: &str,
    triangles: &[[u32; 3]],
    vertices: usize,
) -> Result<(), RenderError> {
    for (k, t) in triangles.iter().enumerate() {
        if t.iter().any(|&i| i as usize >= vertices) {
            return Err(RenderError::scene(
                format!("{what}, triangle {k}"),
                format!("indices {t:?} exceed the {vertices} vertices"),
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Signed volume by the divergence theorem: positive iff triangles wind outwards.
    fn volume(mesh: &TriMesh) -> f32 {
        mesh.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }

    #[test]
    fn cuboid_is_closed_outward_and_has_the_right_volume() {
        let mesh = TriMesh::cuboid(Vec3::new(1.0, 2.0, 3.0), Vec3::new(0.5, 1.0, 1.5));
        mesh.validate("box").unwrap();
        let v = volume(&mesh);
        assert!((v - 6.0).abs() < 1e-4, "volume off by {}", v - 6.0);
        for t in &mesh.triangles {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            let geometric = (b - a).cross(c - a);
            assert!(
                geometric.dot(mesh.normals[t[0] as usize]) > 0.0,
                "face {t:?} winds inwards"
            );
        }
    }

    #[test]
    fn uv_sphere_volume_approaches_the_ball() {
        let mesh = TriMesh::uv_sphere(Vec3::new(0.0, 1.0, 0.0), 2.0, 64, 32);
        mesh.validate("sphere").unwrap();
        let want = 4.0 / 3.0 * std::f32::consts::PI * 8.0;
        let v = volume(&mesh);
        assert!(
            v > 0.0 && (v - want).abs() / want < 0.01,
            "volume {v}, ball {want}"
        );
    }

    #[test]
    fn validate_names_the_bad_element() {
        let mut mesh = TriMesh::cuboid(Vec3::ZERO, Vec3::ONE);
        mesh.triangles[3][1] = 99;
        let e = mesh.validate("box").unwrap_err().to_string();
        assert!(e.contains("triangle 3"), "{e}");
        let mut mesh = TriMesh::cuboid(Vec3::ZERO, Vec3::ONE);
        mesh.positions[5].y = f32::NAN;
        let e = mesh.validate("box").unwrap_err().to_string();
        assert!(e.contains("vertex 5"), "{e}");
    }
}
