//! Closed-mesh geometry: area, enclosed volume, their exact gradients, normals.
//!
//! The gradients are exact derivatives of the discrete quantities, which is what makes
//! surface tension and pressure conservative and lets a discrete mesh sit in exact
//! equilibrium (see `docs/dynamics.md`).

use glam::DVec3;

/// Twice the area vector of triangle (a, b, c): `(b − a) × (c − a)`, normal by the
/// right-hand rule, length `2·area`.
#[inline]
pub fn double_area_vector(a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    (b - a).cross(c - a)
}

/// Gradient of the area of triangle (a, b, c) with respect to `a`: `½ n̂ × (c − b)`;
/// zero for a degenerate triangle (the area is not differentiable there).
#[inline]
pub fn triangle_area_gradient(a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let n = double_area_vector(a, b, c).normalize_or_zero();
    0.5 * n.cross(c - b)
}

/// Area of each triangle in m².
pub fn face_areas_m2(positions: &[DVec3], triangles: &[[u32; 3]]) -> Vec<f64> {
    let mut out = Vec::with_capacity(triangles.len());
    face_areas_into(positions, triangles, &mut out);
    out
}

/// Area of each triangle in m², into `out` (its buffer reused).
pub(crate) fn face_areas_into(positions: &[DVec3], triangles: &[[u32; 3]], out: &mut Vec<f64>) {
    out.clear();
    out.extend(triangles.iter().map(|t| {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        0.5 * double_area_vector(a, b, c).length()
    }));
}

/// Total area of the mesh in m².
pub fn surface_area_m2(positions: &[DVec3], triangles: &[[u32; 3]]) -> f64 {
    triangles
        .iter()
        .map(|t| {
            0.5 * double_area_vector(
                positions[t[0] as usize],
                positions[t[1] as usize],
                positions[t[2] as usize],
            )
            .length()
        })
        .sum()
}

/// Mean of the vertex positions (a reference point that keeps volume sums well conditioned).
///
/// # Panics
/// If `positions` is empty.
pub fn vertex_centroid_m(positions: &[DVec3]) -> DVec3 {
    assert!(!positions.is_empty(), "vertex_centroid_m of an empty mesh");
    positions.iter().copied().sum::<DVec3>() / positions.len() as f64
}

/// Volume enclosed by a closed, outward-oriented mesh in m³ (signed: negative if inside out).
///
/// Summed as tetrahedra from the vertex centroid, so a bubble far from the origin loses
/// no digits to cancellation.
pub fn enclosed_volume_m3(positions: &[DVec3], triangles: &[[u32; 3]]) -> f64 {
    if positions.is_empty() {
        return 0.0;
    }
    let o = vertex_centroid_m(positions);
    triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| positions[i as usize] - o);
            a.dot(b.cross(c))
        })
        .sum::<f64>()
        / 6.0
}

/// Writes `∂A/∂x_i` (exact gradient of the total area) into `out`.
///
/// # Panics
/// If `out.len() != positions.len()`.
pub fn area_gradient(positions: &[DVec3], triangles: &[[u32; 3]], out: &mut [DVec3]) {
    assert_eq!(out.len(), positions.len(), "area_gradient: output length");
    out.fill(DVec3::ZERO);
    for t in triangles {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        out[t[0] as usize] += triangle_area_gradient(a, b, c);
        out[t[1] as usize] += triangle_area_gradient(b, c, a);
        out[t[2] as usize] += triangle_area_gradient(c, a, b);
    }
}

/// Writes `∂V/∂x_i = Σ_{f∋i} A_f n_f / 3` (exact gradient of the enclosed volume of a
/// closed mesh) into `out`.
///
/// # Panics
/// If `out.len() != positions.len()`.
pub fn volume_gradient(positions: &[DVec3], triangles: &[[u32; 3]], out: &mut [DVec3]) {
    assert_eq!(out.len(), positions.len(), "volume_gradient: output length");
    out.fill(DVec3::ZERO);
    for t in triangles {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        let share = double_area_vector(a, b, c) / 6.0;
        for &i in t {
            out[i as usize] += share;
        }
    }
}

/// Area-weighted vertex normals (unit length; zero where the one-ring has no area).
pub fn vertex_normals(positions: &[DVec3], triangles: &[[u32; 3]]) -> Vec<DVec3> {
    let mut normals = vec![DVec3::ZERO; positions.len()];
    for t in triangles {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        let n = double_area_vector(a, b, c);
        for &i in t {
            normals[i as usize] += n;
        }
    }
    normals.iter_mut().for_each(|n| *n = n.normalize_or_zero());
    normals
}

/// Barycentric (one-third) vertex areas in m²: each triangle gives a third of its area to
/// each corner, so they sum to the mesh area.
pub fn barycentric_vertex_areas_m2(positions: &[DVec3], triangles: &[[u32; 3]]) -> Vec<f64> {
    let mut areas = vec![0.0; positions.len()];
    for t in triangles {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        let third = double_area_vector(a, b, c).length() / 6.0;
        for &i in t {
            areas[i as usize] += third;
        }
    }
    areas
}
