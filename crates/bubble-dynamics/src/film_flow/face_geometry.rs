//! One face's share of the grid's constants, which every face reads: the passes over
//! the cells and edges inside the faces stream these where they streamed six faces'.
//!
//! Why one face serves all six: the cube-sphere is symmetric under the cube's rotations,
//! each of which carries face 0 onto another face and its cells and interior edges, as
//! [`FaceLayout`] numbers them, onto the cells and edges at the same place there. A
//! scalar (an area, a length) is therefore the same on every face, and a vector (an
//! edge's normal) has the same components in each face's own frame ([`FACE_BASES`]: its
//! major, `s` and `t` axes); the grid, built face by face in floating point, agrees to
//! rounding: every face's values are face 0's within 1e-14 of each array's largest at
//! n = 1, 5, 16 and 64, the centres' normal gradient within 5e-14, its terms being
//! differences of nearby unit vectors over their distance
//! (`tests::every_faces_constants_are_face_0s`). The cells' areas are face 0's bit for
//! bit. The seam edges lie between two faces and keep their own values.
//!
//! What it saves: at n = 64 a per-edge array is 0.4 MB and a per-cell one 0.2 MB, and
//! the core's L2 is 1 MB, so each pass streamed its constants from beyond it; a face's
//! are a sixth of that, and stay in L2 from one pass to the next.

use glam::DVec3;

use super::grid::{CubeSphere, FACE_BASES, FaceLayout};

/// Face 0's cells' and interior edges' constants, and the seam edges' own.
///
/// # Guarantees
/// - `area_sr[y·n + x]` is the area of cell `(x, y)` of every face, to rounding (the
///   same bits: [`CubeSphere::areas_sr`] takes it from `(n, x, y)` alone); likewise its
///   inverse.
/// - Each [`EdgeConstant`] and [`EdgeVector`] holds, at an interior edge's place on its
///   face ([`FaceLayout::on_face`]), that edge's value on every face, to rounding.
#[derive(Clone, Debug, Default)]
pub(crate) struct FaceGeometry {
    /// Face 0's cells' areas, sr, `y·n + x`.
    pub(crate) area_sr: Vec<f64>,
    /// Their inverses, per sr.
    pub(crate) inverse_area_per_sr: Vec<f64>,
    /// Face 0's cells' centres' components along its major, `s` and `t` axes, `y·n + x`
    /// (against a world vector taken into each face's frame, [`to_face_frame`]).
    pub(crate) centre: [Vec<f64>; 3],
    /// Face 0's cells' left x-edges' lengths, rad, one a cell (`y·n + x`, 0 at `x = 0`):
    /// a face's x-edges are `n − 1` a row, so only so do they read as one slice along a
    /// [`super::sides::CellSpan`] ([`super::fluxes::span_sides_on_face`]).
    pub(crate) x_length: Vec<f64>,
    /// [`EdgeArrays::length`](super::grid::EdgeArrays::length).
    pub(crate) length: EdgeConstant,
    /// [`EdgeArrays::inverse_dual_length`](super::grid::EdgeArrays::inverse_dual_length).
    pub(crate) inverse_dual_length: EdgeConstant,
    /// [`EdgeArrays::inverse_normal_dual_length`](super::grid::EdgeArrays::inverse_normal_dual_length).
    pub(crate) inverse_normal_dual_length: EdgeConstant,
    /// [`EdgeArrays::length_per_smaller_area`](super::grid::EdgeArrays::length_per_smaller_area).
    pub(crate) length_per_smaller_area: EdgeConstant,
    /// [`EdgeArrays::normal`](super::grid::EdgeArrays::normal).
    pub(crate) normal: EdgeVector,
    /// [`EdgeArrays::centre_gradient`](super::grid::EdgeArrays::centre_gradient).
    pub(crate) centre_gradient: EdgeVector,
    /// [`EdgeArrays::centre_normal_gradient`](super::grid::EdgeArrays::centre_normal_gradient).
    pub(crate) centre_normal_gradient: EdgeVector,
}

/// A per-edge constant as the edge passes read it: face 0's interior edges' values,
/// which every face's runs read, and the seam edges' own.
#[derive(Clone, Debug, Default)]
pub(crate) struct EdgeConstant {
    /// Face 0's interior edges' values, in the order of [`FaceLayout::on_face`].
    pub(crate) face: Vec<f64>,
    /// The seam edges' values, from [`FaceLayout::first_seam_edge`] on.
    pub(crate) seams: Vec<f64>,
}

/// A per-edge vector as the edge passes read it: face 0's interior edges' components in
/// its own frame, which every face's runs read against a world vector taken into their
/// face's frame ([`to_face_frame`]), and the seam edges' world components.
#[derive(Clone, Debug, Default)]
pub(crate) struct EdgeVector {
    /// Face 0's interior edges' components along its major, `s` and `t` axes, in the
    /// order of [`FaceLayout::on_face`].
    pub(crate) face: [Vec<f64>; 3],
    /// The seam edges' world x, y and z, from [`FaceLayout::first_seam_edge`] on.
    pub(crate) seams: [Vec<f64>; 3],
}

/// `world`'s components along face `face`'s major, `s` and `t` axes: exact (the axes
/// are unit vectors along the world's axes).
#[inline(always)]
pub(crate) fn to_face_frame(face: usize, world: DVec3) -> DVec3 {
    let (major, s, t) = FACE_BASES[face];
    let along = |axis: glam::IVec3| world.dot(axis.as_dvec3());
    DVec3::new(along(major), along(s), along(t))
}

impl FaceGeometry {
    /// Face 0's constants of `grid`, and its seams'.
    pub(crate) fn new(grid: &CubeSphere) -> Self {
        Self::of_face(grid, 0)
    }

    /// Face `face`'s constants of `grid` in its own frame, and the seams' (the tests
    /// compare each face's with face 0's).
    fn of_face(grid: &CubeSphere, face: usize) -> Self {
        let (layout, ea) = (grid.layout(), grid.edge_arrays());
        let on_face = face * layout.n * layout.n..(face + 1) * layout.n * layout.n;
        let cells = |all: &[f64]| all[on_face.clone()].to_vec();
        let scalar = |all: &[f64]| EdgeConstant::of_face(layout, face, all);
        let vector = |all: &[DVec3]| EdgeVector::of_face(layout, face, all);
        let centres = grid.centres()[on_face.clone()].iter();
        let centres: Vec<DVec3> = centres.map(|&c| to_face_frame(face, c)).collect();
        let length = scalar(&ea.length);
        Self {
            area_sr: cells(grid.areas_sr()),
            inverse_area_per_sr: cells(grid.inverse_areas_per_sr()),
            centre: std::array::from_fn(|k| centres.iter().map(|c| c[k]).collect()),
            x_length: x_edges_by_cell(layout.n, &length.face),
            length,
            inverse_dual_length: scalar(&ea.inverse_dual_length),
            inverse_normal_dual_length: scalar(&ea.inverse_normal_dual_length),
            length_per_smaller_area: scalar(&ea.length_per_smaller_area),
            normal: vector(&ea.normal),
            centre_gradient: vector(&ea.centre_gradient),
            centre_normal_gradient: vector(&ea.centre_normal_gradient),
        }
    }
}

/// Face 0's x-edges' values of `face_edges` (in the order of [`FaceLayout::on_face`]),
/// one a cell: its left x-edge's, 0 at `x = 0`.
fn x_edges_by_cell(n: usize, face_edges: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; n * n];
    for y in 0..n {
        let row = &face_edges[y * (n - 1)..(y + 1) * (n - 1)];
        out[y * n + 1..(y + 1) * n].copy_from_slice(row);
    }
    out
}

impl EdgeConstant {
    /// Face `face`'s interior edges' values of the per-edge array `all`, and the seams'.
    fn of_face(layout: FaceLayout, face: usize, all: &[f64]) -> Self {
        Self {
            face: layout.face_edges(face).map(|e| all[e]).collect(),
            seams: all[layout.first_seam_edge()..].to_vec(),
        }
    }
}

impl EdgeVector {
    /// Face `face`'s interior edges' vectors of `all` in its frame, and the seams' in the
    /// world's.
    fn of_face(layout: FaceLayout, face: usize, all: &[DVec3]) -> Self {
        let local: Vec<DVec3> = layout
            .face_edges(face)
            .map(|e| to_face_frame(face, all[e]))
            .collect();
        let seams = &all[layout.first_seam_edge()..];
        Self {
            face: std::array::from_fn(|k| local.iter().map(|v| v[k]).collect()),
            seams: std::array::from_fn(|k| seams.iter().map(|v| v[k]).collect()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The first element of `b` (another face's) off `a`'s (face 0's) by more than
    /// `tolerance` of `largest`, if any.
    fn first_off(what: &str, [a, b]: [&[f64]; 2], largest: f64, tolerance: f64) -> Option<String> {
        assert_eq!(a.len(), b.len(), "{what}: lengths");
        let off = |(i, (x, y)): (usize, (&f64, &f64))| {
            let off = (x - y).abs() / largest;
            (off > tolerance).then(|| format!("{what}[{i}]: {y} against face 0's {x} ({off:e})"))
        };
        a.iter().zip(b).enumerate().find_map(off)
    }

    /// The largest magnitude in `values`.
    fn largest<'a>(values: impl IntoIterator<Item = &'a f64>) -> f64 {
        values.into_iter().fold(0.0, |m: f64, x| m.max(x.abs()))
    }

    /// Every array of `a` (face 0's) against `b`'s (another face's): scalars within
    /// 1e-14 of their array's largest, vectors' components within 1e-14 of the vectors'
    /// largest, but the centres' normal gradient within 5e-14: it is a difference of two
    /// terms each a difference of unit vectors about a cell apart times the inverse of
    /// that distance (`1/(d cos θ)` and `tan θ/l`, tens at n = 64), which carry the
    /// unit vectors' rounding up by as much (2e-14 at n = 64).
    fn differences(a: &FaceGeometry, b: &FaceGeometry) -> Vec<String> {
        let scalars = |g: &FaceGeometry| {
            [
                ("area", g.area_sr.clone()),
                ("inverse area", g.inverse_area_per_sr.clone()),
                ("x length", g.x_length.clone()),
                ("length", g.length.face.clone()),
                ("inverse dual length", g.inverse_dual_length.face.clone()),
                (
                    "inverse normal dual",
                    g.inverse_normal_dual_length.face.clone(),
                ),
                ("length per area", g.length_per_smaller_area.face.clone()),
            ]
        };
        let vectors = |g: &FaceGeometry| {
            [
                ("centre", g.centre.clone()),
                ("normal", g.normal.face.clone()),
                ("centre gradient", g.centre_gradient.face.clone()),
                (
                    "centre normal gradient",
                    g.centre_normal_gradient.face.clone(),
                ),
            ]
        };
        let mut off = Vec::new();
        for ((what, x), (_, y)) in scalars(a).iter().zip(&scalars(b)) {
            off.extend(first_off(what, [x, y], largest(x), 1e-14));
        }
        for ((what, x), (_, y)) in vectors(a).iter().zip(&vectors(b)) {
            let scale = largest(x.iter().flatten());
            let tolerance = if *what == "centre normal gradient" {
                5e-14
            } else {
                1e-14
            };
            for k in 0..3 {
                let what = format!("{what}.{k}");
                off.extend(first_off(&what, [&x[k], &y[k]], scale, tolerance));
            }
        }
        off
    }

    #[test]
    fn every_faces_constants_are_face_0s() {
        for n in [1, 5, 16, 64] {
            let grid = CubeSphere::new(n);
            let first = FaceGeometry::of_face(&grid, 0);
            assert_eq!(first.length.face.len(), 2 * n * (n - 1), "n = {n}");
            for face in 1..6 {
                let other = FaceGeometry::of_face(&grid, face);
                let off = differences(&first, &other);
                assert!(off.is_empty(), "n = {n}, face {face}: {off:#?}");
                assert_eq!(
                    first.area_sr, other.area_sr,
                    "n = {n}, face {face}: areas' bits"
                );
            }
        }
    }

    #[test]
    fn a_world_vector_in_a_faces_frame_dots_as_in_the_world() {
        let g = DVec3::new(0.3, -9.81, 0.7);
        for (face, &(major, s, t)) in FACE_BASES.iter().enumerate() {
            let v = DVec3::new(0.2, -0.5, 0.9);
            let world = major.as_dvec3() * v.x + s.as_dvec3() * v.y + t.as_dvec3() * v.z;
            assert_eq!(to_face_frame(face, world), v, "face {face}");
            assert!((to_face_frame(face, g).dot(v) - g.dot(world)).abs() < 1e-14);
        }
    }
}
