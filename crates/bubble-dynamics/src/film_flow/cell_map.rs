//! Where each cube-sphere cell sits on the particle mesh: the rest triangle its centre's
//! ray crosses, with barycentric weights. It carries the mesh's stretch to the cells
//! (seed 000 eq. 2: thickness scales with rest area / current area) and the mesh's
//! initial thickness onto the grid.

use std::collections::HashMap;

use glam::DVec3;

/// Per cell: the triangle and the barycentric weights of its centre on the rest mesh.
#[derive(Clone, Debug)]
pub struct CellMap {
    cells: Vec<(u32, [f64; 3])>,
}

impl CellMap {
    /// Locates every direction of `centres` on the closed, star-shaped (about the origin)
    /// mesh `unit_positions`/`triangles` by walking from the previous cell's triangle.
    ///
    /// # Panics
    /// If the mesh has no triangles.
    pub fn new(centres: &[DVec3], unit_positions: &[DVec3], triangles: &[[u32; 3]]) -> Self {
        assert!(!triangles.is_empty(), "a cell map needs a mesh");
        let neighbours = triangle_neighbours(triangles);
        let mut current = 0usize;
        let cells = centres
            .iter()
            .map(|&d| {
                let found = walk(d, current, unit_positions, triangles, &neighbours)
                    .unwrap_or_else(|| search(d, unit_positions, triangles));
                current = found.0 as usize;
                found
            })
            .collect();
        Self { cells }
    }

    /// `Σ_k w_k·values[vertex_k]` at every cell.
    pub fn interpolate(&self, triangles: &[[u32; 3]], values: &[f64], out: &mut Vec<f64>) {
        out.clear();
        out.extend(self.cells.iter().map(|&(t, w)| {
            let tri = triangles[t as usize];
            (0..3).map(|k| w[k] * values[tri[k] as usize]).sum::<f64>()
        }));
    }
}

/// The triangle holding `d`, walking across the edge of the most negative weight.
fn walk(
    d: DVec3,
    start: usize,
    unit_positions: &[DVec3],
    triangles: &[[u32; 3]],
    neighbours: &[[u32; 3]],
) -> Option<(u32, [f64; 3])> {
    let mut current = start;
    for _ in 0..=triangles.len() {
        let w = ray_barycentric(d, triangles[current].map(|i| unit_positions[i as usize]));
        let (worst, value) = (0..3)
            .map(|k| (k, w[k]))
            .fold((0, f64::INFINITY), |a, b| if b.1 < a.1 { b } else { a });
        if value >= -1e-12 {
            return Some((current as u32, w));
        }
        current = neighbours[current][worst] as usize;
    }
    None
}

/// The triangle holding `d` by trying every one (the walk's fallback): the one whose
/// smallest weight is largest.
///
/// # Panics
/// If `triangles` is empty.
fn search(d: DVec3, unit_positions: &[DVec3], triangles: &[[u32; 3]]) -> (u32, [f64; 3]) {
    triangles
        .iter()
        .enumerate()
        .map(|(t, tri)| {
            (
                t as u32,
                ray_barycentric(d, tri.map(|i| unit_positions[i as usize])),
            )
        })
        .max_by(|a, b| {
            let min = |w: &[f64; 3]| w[0].min(w[1]).min(w[2]);
            min(&a.1).total_cmp(&min(&b.1))
        })
        .expect("a mesh with triangles")
}

/// Normalised weights `w` with `w·corners` on the ray through `d` (negative outside).
fn ray_barycentric(d: DVec3, [a, b, c]: [DVec3; 3]) -> [f64; 3] {
    let w = [d.dot(b.cross(c)), d.dot(c.cross(a)), d.dot(a.cross(b))];
    let sum = w[0] + w[1] + w[2];
    if d.dot(a + b + c) <= 0.0 || sum == 0.0 {
        // The triangle lies on the far side: step across its first edge.
        return [-1.0, 0.0, 0.0];
    }
    // Either winding: the weights' common sign cancels.
    w.map(|x| x / sum)
}

/// For each triangle, the triangle across the edge opposite each corner.
fn triangle_neighbours(triangles: &[[u32; 3]]) -> Vec<[u32; 3]> {
    let mut by_edge: HashMap<(u32, u32), u32> = HashMap::new();
    for (t, tri) in triangles.iter().enumerate() {
        for k in 0..3 {
            by_edge.insert((tri[(k + 1) % 3], tri[(k + 2) % 3]), t as u32);
        }
    }
    triangles
        .iter()
        .enumerate()
        .map(|(t, tri)| {
            std::array::from_fn(|k| {
                let (p, q) = (tri[(k + 1) % 3], tri[(k + 2) % 3]);
                by_edge.get(&(q, p)).copied().unwrap_or(t as u32)
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::film_flow::CubeSphere;
    use crate::icosphere;

    #[test]
    fn every_cell_lands_inside_a_triangle_and_linear_fields_interpolate_exactly() {
        let icosphere::Icosphere {
            positions,
            triangles,
        } = icosphere::icosphere(3);
        let grid = CubeSphere::new(16);
        let map = CellMap::new(grid.centres(), &positions, &triangles);
        for &(_, w) in &map.cells {
            assert!(w.iter().all(|&x| x >= -1e-12) && (w.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        }
        // A linear function of position, interpolated on the flat triangles, equals the
        // function at the point where the ray crosses the triangle.
        let f: Vec<f64> = positions.iter().map(|p| 2.0 + p.x - 0.5 * p.z).collect();
        let mut out = Vec::new();
        map.interpolate(&triangles, &f, &mut out);
        for (&(t, w), (v, d)) in map.cells.iter().zip(out.iter().zip(grid.centres())) {
            let tri = triangles[t as usize];
            let p: DVec3 = (0..3).map(|k| positions[tri[k] as usize] * w[k]).sum();
            assert!(p.normalize().dot(*d) > 1.0 - 1e-12, "point off the ray");
            assert!((v - (2.0 + p.x - 0.5 * p.z)).abs() < 1e-12);
        }
    }
}
