//! The film's surface grid: a gnomonic cube-sphere on the unit sphere, laid out as an
//! OpenGL cube map (faces +X, −X, +Y, −Y, +Z, −Z; texel `face·n² + y·n + x`), so the
//! renderer can read the field as a cube-map texture without resampling.
//!
//! Finite volumes on a C-grid: scalars (thickness, surfactant) live on cells, the film's
//! tangential velocity as its component normal to each cell edge. Every grid line of a
//! gnomonic cube-sphere is a great circle, so edges are exact arcs; cell areas are exact
//! spherical areas.

use std::collections::HashMap;

use glam::{DMat3, DVec3, IVec3};

use super::compare::larger;
use super::face_geometry::FaceGeometry;
use crate::avx2::with_avx2;

/// Major axis, `s` axis and `t` axis of each face (OpenGL cube-map order).
pub const FACE_BASES: [(IVec3, IVec3, IVec3); 6] = [
    (IVec3::X, IVec3::NEG_Z, IVec3::NEG_Y),
    (IVec3::NEG_X, IVec3::Z, IVec3::NEG_Y),
    (IVec3::Y, IVec3::X, IVec3::Z),
    (IVec3::NEG_Y, IVec3::X, IVec3::NEG_Z),
    (IVec3::Z, IVec3::X, IVec3::NEG_Y),
    (IVec3::NEG_Z, IVec3::NEG_X, IVec3::NEG_Y),
];

/// One cell edge: the arc between two grid vertices, shared by cells `a` and `b`.
#[derive(Clone, Copy, Debug)]
pub struct GridEdge {
    /// The cell the normal points away from.
    pub a: u32,
    /// The cell the normal points into.
    pub b: u32,
    /// The vertex at the tail of the edge tangent `midpoint × normal`.
    pub v0: u32,
    /// The vertex at its head.
    pub v1: u32,
    /// Unit tangent normal to the edge at its midpoint, from `a` towards `b`.
    pub normal: DVec3,
    /// Unit direction of the edge's midpoint.
    pub midpoint: DVec3,
    /// Arc length of the edge on the unit sphere, rad.
    pub length: f64,
    /// Arc length between the centres of `a` and `b`, rad.
    pub dual_length: f64,
}

/// The edges' numbers the film step reads every step, as compact arrays (struct of
/// arrays, index = edge index): a pass over the edges then streams the 8–24 bytes it uses
/// an edge instead of the 80 of a whole [`GridEdge`]. Derived once from the edges. The
/// passes over the edges inside the faces read face 0's share of the ones they use, which
/// serves every face (module `face_geometry`); the seams and the other passes read these.
#[derive(Clone, Debug, Default)]
pub struct EdgeArrays {
    /// `[a, b]`: the cells the edge's normal points from and into.
    pub cells: Vec<[u32; 2]>,
    /// `[v0, v1]`: the grid vertices at the edge's tail and head.
    pub vertices: Vec<[u32; 2]>,
    /// Arc length of the edge, rad.
    pub length: Vec<f64>,
    /// Arc length between the centres of its cells, rad.
    pub dual_length: Vec<f64>,
    /// `1/length`, per rad: the passes over the edges multiply where they divided (a
    /// division takes several multiplies' time).
    pub inverse_length: Vec<f64>,
    /// `1/dual_length`, per rad.
    pub inverse_dual_length: Vec<f64>,
    /// `1/(dual_length·cos θ)`, per rad, θ the angle between the line of centres and the
    /// edge's normal (up to 30° near the cube's corners): the centre difference's weight
    /// in the gradient along the normal, [`CubeSphere::normal_gradient`].
    pub inverse_normal_dual_length: Vec<f64>,
    /// `tan θ/length`, per rad: the weight of the difference along the edge (its head
    /// vertex's value less its tail's) taken off that gradient, so that it is along the
    /// normal and not along the line of centres.
    pub cross_per_length: Vec<f64>,
    /// `length/min(area_a, area_b)`, per rad: a speed times this and a step, per R, is the
    /// fraction of the smaller cell's content the edge can carry (a Courant number).
    pub length_per_smaller_area: Vec<f64>,
    /// `(centre_b − centre_a)/dual_length`, per rad: `G·` this is the discrete gradient
    /// across the edge of a linear potential `G·x` (gravity, the wind's potential flow)
    /// with the two-point gradient ([`FilmGradient::TwoPoint`](super::FilmGradient::TwoPoint)).
    pub centre_gradient: Vec<DVec3>,
    /// The normal gradient ([`CubeSphere::normal_gradient`]) of the cell centres, per
    /// rad: the same with [`FilmGradient::Normal`](super::FilmGradient::Normal), so that a
    /// discrete Marangoni gradient along the normal can balance it exactly.
    pub centre_normal_gradient: Vec<DVec3>,
    /// Unit tangent normal to the edge at its midpoint, from `a` towards `b`.
    pub normal: Vec<DVec3>,
    /// `midpoint − centre_a` and `midpoint − centre_b`: how far a cell's value is carried
    /// to the edge by its gradient.
    pub reach: Vec<[DVec3; 2]>,
}

impl EdgeArrays {
    fn new(
        edges: &[GridEdge],
        centres: &[DVec3],
        areas_sr: &[f64],
        to_vertices: &VertexInterpolation,
    ) -> Self {
        let centre = |c: u32| centres[c as usize];
        let smaller_area = |e: &GridEdge| areas_sr[e.a as usize].min(areas_sr[e.b as usize]);
        let skew: Vec<[f64; 2]> = edges.iter().map(|e| skew_weights(e, centres)).collect();
        let at_vertex = |v: u32| to_vertices.apply_vec(v as usize, centres);
        Self {
            inverse_normal_dual_length: skew.iter().map(|w| w[0]).collect(),
            cross_per_length: skew.iter().map(|w| w[1]).collect(),
            length_per_smaller_area: edges.iter().map(|e| e.length / smaller_area(e)).collect(),
            cells: edges.iter().map(|e| [e.a, e.b]).collect(),
            vertices: edges.iter().map(|e| [e.v0, e.v1]).collect(),
            length: edges.iter().map(|e| e.length).collect(),
            dual_length: edges.iter().map(|e| e.dual_length).collect(),
            inverse_length: edges.iter().map(|e| 1.0 / e.length).collect(),
            inverse_dual_length: edges.iter().map(|e| 1.0 / e.dual_length).collect(),
            centre_gradient: edges
                .iter()
                .map(|e| (centre(e.b) - centre(e.a)) / e.dual_length)
                .collect(),
            centre_normal_gradient: edges
                .iter()
                .zip(&skew)
                .map(|(e, [along, cross])| {
                    (centre(e.b) - centre(e.a)) * along
                        - (at_vertex(e.v1) - at_vertex(e.v0)) * cross
                })
                .collect(),
            normal: edges.iter().map(|e| e.normal).collect(),
            reach: edges
                .iter()
                .map(|e| [e.midpoint - centre(e.a), e.midpoint - centre(e.b)])
                .collect(),
        }
    }
}

/// `g·v` for the vector `v` given by its components `xyz` at index `i`, in the order
/// of `DVec3::dot` (the same bits).
#[inline(always)]
pub(crate) fn dot_at(g: DVec3, [x, y, z]: [&[f64]; 3], i: usize) -> f64 {
    (g.x * x[i] + g.y * y[i]) + g.z * z[i]
}

/// A gnomonic cube-sphere of `6·n²` cells on the unit sphere.
///
/// # Guarantees
/// - `n >= 1`; cell `face·n² + y·n + x` covers `s ∈ [2x/n − 1, 2(x+1)/n − 1]` and likewise
///   `t` for `y` on face `face`;
/// - the cell areas sum to 4π (to rounding) and every edge joins two distinct cells.
#[derive(Clone, Debug)]
pub struct CubeSphere {
    n: usize,
    centres: Vec<DVec3>,
    areas_sr: Vec<f64>,
    edges: Vec<GridEdge>,
    edge_arrays: EdgeArrays,
    vertex_areas_sr: Vec<f64>,
    inverse_areas_per_sr: Vec<f64>,
    inverse_vertex_areas_per_sr: Vec<f64>,
    to_vertices: VertexInterpolation,
    /// Face 0's constants, which every face's passes read ([`FaceGeometry`]).
    face: FaceGeometry,
}

/// Per grid vertex: the cells around it (three at a cube corner, the first repeated with
/// weight 0) and weights summing to 1 that carry a field linear in the vertex's tangent
/// plane to its value there (least-norm weights: ¼ each where the four centres form a
/// parallelogram).
#[derive(Clone, Debug, Default)]
struct VertexInterpolation {
    cells: Vec<[u32; 4]>,
    weights: Vec<[f64; 4]>,
}

impl VertexInterpolation {
    fn new(corners: &[[u32; 4]], centres: &[DVec3], vertices: &[DVec3]) -> Self {
        let mut around: Vec<Vec<u32>> = vec![Vec::new(); vertices.len()];
        for (cell, ids) in corners.iter().enumerate() {
            for &v in ids {
                around[v as usize].push(cell as u32);
            }
        }
        let mut cells = Vec::with_capacity(vertices.len());
        let mut weights = Vec::with_capacity(vertices.len());
        for (v, ring) in vertices.iter().zip(&around) {
            assert!(
                (3..=4).contains(&ring.len()),
                "a vertex of {} cells",
                ring.len()
            );
            let w = linear_exact_weights(*v, ring, centres);
            cells.push(std::array::from_fn(|k| ring[k.min(ring.len() - 1)]));
            weights.push(std::array::from_fn(
                |k| if k < ring.len() { w[k] } else { 0.0 },
            ));
        }
        Self { cells, weights }
    }

    fn apply(&self, v: usize, values: &[f64]) -> f64 {
        let (c, w) = (&self.cells[v], &self.weights[v]);
        (0..4).map(|k| w[k] * values[c[k] as usize]).sum()
    }

    fn apply_vec(&self, v: usize, values: &[DVec3]) -> DVec3 {
        let (c, w) = (&self.cells[v], &self.weights[v]);
        (0..4).map(|k| w[k] * values[c[k] as usize]).sum()
    }
}

/// Least-norm weights over the cells `ring` around vertex `v`, summing to 1, whose mix of
/// the centres' gnomonic projections onto `v`'s tangent plane is `v` itself.
fn linear_exact_weights(v: DVec3, ring: &[u32], centres: &[DVec3]) -> Vec<f64> {
    let side = if v.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
    let e1 = side.cross(v).normalize();
    let e2 = v.cross(e1);
    let rows: Vec<DVec3> = ring
        .iter()
        .map(|&c| {
            let p = centres[c as usize] / centres[c as usize].dot(v) - v;
            DVec3::new(1.0, p.dot(e1), p.dot(e2))
        })
        .collect();
    // w = Mᵀ (M Mᵀ)⁻¹ (1, 0, 0) with M's columns the rows above.
    let normal = rows.iter().fold(DMat3::ZERO, |m, r| {
        m + DMat3::from_cols(*r * r.x, *r * r.y, *r * r.z)
    });
    let lambda = normal.inverse() * DVec3::X;
    rows.iter().map(|r| r.dot(lambda)).collect()
}

/// `[1/(d cos θ), tan θ/l]` of edge `e`: θ the angle at its midpoint between the line of
/// centres (its tangential part) and the normal, positive towards the head vertex.
fn skew_weights(e: &GridEdge, centres: &[DVec3]) -> [f64; 2] {
    let chord = centres[e.b as usize] - centres[e.a as usize];
    let along = (chord - chord.dot(e.midpoint) * e.midpoint).normalize();
    let tangent = e.midpoint.cross(e.normal);
    let (cos, sin) = (along.dot(e.normal), along.dot(tangent));
    [1.0 / (e.dual_length * cos), sin / cos / e.length]
}

impl CubeSphere {
    /// Builds the grid with `n × n` cells a face.
    ///
    /// # Panics
    /// If `n == 0` or `n > 4096`.
    pub fn new(n: usize) -> Self {
        assert!(
            (1..=4096).contains(&n),
            "cube-sphere face size {n} not in 1..=4096"
        );
        let mut vertex_ids: HashMap<IVec3, u32> = HashMap::new();
        let mut vertex_dirs: Vec<DVec3> = Vec::new();
        let mut corner = |p: IVec3| -> u32 {
            *vertex_ids.entry(p).or_insert_with(|| {
                vertex_dirs.push(p.as_dvec3().normalize());
                (vertex_dirs.len() - 1) as u32
            })
        };
        let cells = 6 * n * n;
        let mut centres = Vec::with_capacity(cells);
        let mut areas_sr = Vec::with_capacity(cells);
        let mut cell_corners = Vec::with_capacity(cells);
        for (face, &(major, su, tv)) in FACE_BASES.iter().enumerate() {
            // Grid points as exact integers on the cube of half-side n, so the points a face
            // shares with its neighbour are the same key.
            let point = |i: usize, j: usize| {
                major * n as i32 + su * (2 * i as i32 - n as i32) + tv * (2 * j as i32 - n as i32)
            };
            for y in 0..n {
                for x in 0..n {
                    let ids = [
                        corner(point(x, y)),
                        corner(point(x + 1, y)),
                        corner(point(x + 1, y + 1)),
                        corner(point(x, y + 1)),
                    ];
                    cell_corners.push(ids);
                    centres.push(texel_direction(n, face, x, y));
                    areas_sr.push(gnomonic_area(n, x, y));
                }
            }
        }
        let mut vertex_areas_sr = vec![0.0; vertex_dirs.len()];
        for (ids, area) in cell_corners.iter().zip(&areas_sr) {
            for &v in ids {
                vertex_areas_sr[v as usize] += area / 4.0;
            }
        }
        let edges = build_edges(&cell_corners, &centres, &vertex_dirs);
        let to_vertices = VertexInterpolation::new(&cell_corners, &centres, &vertex_dirs);
        let edge_arrays = EdgeArrays::new(&edges, &centres, &areas_sr, &to_vertices);
        let inverse = |areas: &[f64]| areas.iter().map(|a| 1.0 / a).collect();
        let mut grid = Self {
            n,
            inverse_areas_per_sr: inverse(&areas_sr),
            inverse_vertex_areas_per_sr: inverse(&vertex_areas_sr),
            centres,
            areas_sr,
            edges,
            edge_arrays,
            vertex_areas_sr,
            to_vertices,
            face: FaceGeometry::default(),
        };
        grid.face = FaceGeometry::new(&grid);
        grid
    }

    /// Each grid vertex's value of the cell field `values`, linear-exact, into `out`.
    pub fn cells_to_vertices(&self, values: &[f64], out: &mut Vec<f64>) {
        out.clear();
        out.extend((0..self.vertex_areas_sr.len()).map(|v| self.to_vertices.apply(v, values)));
    }

    /// The gradient of the cell field `values` along edge `e`'s normal, per rad, from
    /// its cells' values and its vertices' (`at_vertices`, from [`Self::cells_to_vertices`]):
    /// `(φ_b − φ_a)/(d cos θ) − (tan θ/l)(φ_v1 − φ_v0)`. The two-point difference alone is
    /// the gradient along the line of centres, up to 30° off the normal near the cube's
    /// corners: an error that does not fall with the cells' size.
    pub fn normal_gradient(&self, e: usize, values: &[f64], at_vertices: &[f64]) -> f64 {
        let ea = &self.edge_arrays;
        let ([a, b], [v0, v1]) = (ea.cells[e], ea.vertices[e]);
        let across = values[b as usize] - values[a as usize];
        let along = at_vertices[v1 as usize] - at_vertices[v0 as usize];
        across * ea.inverse_normal_dual_length[e] - along * ea.cross_per_length[e]
    }

    /// Where the face-structured passes find each face's interior edges.
    pub fn layout(&self) -> FaceLayout {
        FaceLayout { n: self.n }
    }

    /// Cells along a face edge.
    pub fn face_size(&self) -> usize {
        self.n
    }

    /// Number of cells, `6·n²`.
    pub fn cells(&self) -> usize {
        self.centres.len()
    }

    /// Unit direction of each cell's centre.
    pub fn centres(&self) -> &[DVec3] {
        &self.centres
    }

    /// Area of each cell on the unit sphere, sr.
    pub fn areas_sr(&self) -> &[f64] {
        &self.areas_sr
    }

    /// The cell edges.
    pub fn edges(&self) -> &[GridEdge] {
        &self.edges
    }

    /// The edges' numbers as compact per-edge arrays.
    pub fn edge_arrays(&self) -> &EdgeArrays {
        &self.edge_arrays
    }

    /// Face 0's constants, which serve every face ([`FaceGeometry`]).
    pub(crate) fn face_geometry(&self) -> &FaceGeometry {
        &self.face
    }

    /// The largest `|u|·length/min(area_a, area_b)` over the edges, for edge speeds `u`
    /// (m/s, one an edge): times a step over the radius, the largest fraction of a cell
    /// any edge carries (a Courant number). Each face's x-edges and y-edges read face 0's
    /// `length/min(area)` (the same on every face, module `face_geometry`), the seams
    /// their own.
    pub fn fastest_crossing(&self, u_m_per_s: &[f64]) -> f64 {
        let layout = self.layout();
        let per_area = &self.face.length_per_smaller_area;
        let m = layout.n * (layout.n - 1);
        let (x_edges, y_edges) = per_area.face.split_at(m);
        let seams = layout.first_seam_edge();
        // Plain loops: through iterator adaptors the blocks' loop left the AVX2 function
        // and took twice the instructions.
        with_avx2(
            #[inline(always)]
            || {
                let u = u_m_per_s;
                let mut fastest = fastest_of(&u[seams..], &per_area.seams);
                for f in 0..6 {
                    let x = fastest_of(&u[f * m..], x_edges);
                    let y = fastest_of(&u[(6 + f) * m..], y_edges);
                    fastest = larger(larger(x, y), fastest);
                }
                fastest
            },
        )
    }

    /// Dual area of each grid vertex (a quarter of each cell around it), sr.
    pub fn vertex_areas_sr(&self) -> &[f64] {
        &self.vertex_areas_sr
    }

    /// `1/area` of each cell, per sr.
    pub fn inverse_areas_per_sr(&self) -> &[f64] {
        &self.inverse_areas_per_sr
    }

    /// `1/area` of each grid vertex's dual cell, per sr.
    pub fn inverse_vertex_areas_per_sr(&self) -> &[f64] {
        &self.inverse_vertex_areas_per_sr
    }
}

/// The largest `|u[i]|·per_area[i]` over `per_area`'s length, in four running maxima in
/// chunks of four, which vectorise (a maximum is exact in any order; NaN skipped, as
/// `f64::max` does).
#[inline(always)]
fn fastest_of(u: &[f64], per_area: &[f64]) -> f64 {
    let n = per_area.len();
    let u = &u[..n];
    let mut lanes = [0.0; 4];
    for (u, a) in u.chunks_exact(4).zip(per_area.chunks_exact(4)) {
        for k in 0..4 {
            lanes[k] = larger(u[k].abs() * a[k], lanes[k]);
        }
    }
    let rest = (n / 4 * 4..n).map(|i| u[i].abs() * per_area[i]);
    let fastest = rest.fold(0.0, |a, b| larger(b, a));
    lanes.into_iter().fold(fastest, |a, b| larger(b, a))
}

/// Cell of the `n/2` grid holding cell `cell` of the `n` grid (same face, halved x, y).
///
/// # Panics
/// If `n` is odd.
pub fn parent_cell(n: usize, cell: usize) -> usize {
    assert!(n % 2 == 0, "a grid of odd face size {n} has no parent");
    let (face, rest) = (cell / (n * n), cell % (n * n));
    let (y, x) = (rest / n, rest % n);
    let m = n / 2;
    face * m * m + (y / 2) * m + x / 2
}

/// Unit centre direction of cell `(x, y)` of face `face` on a grid of `n` cells a face.
pub fn texel_direction(n: usize, face: usize, x: usize, y: usize) -> DVec3 {
    let (major, su, tv) = FACE_BASES[face];
    let s = (x as f64 + 0.5) / n as f64 * 2.0 - 1.0;
    let t = (y as f64 + 0.5) / n as f64 * 2.0 - 1.0;
    (major.as_dvec3() + su.as_dvec3() * s + tv.as_dvec3() * t).normalize()
}

/// Exact solid angle of the gnomonic cell `(x, y)`: the area element (1 + s² + t²)^(−3/2)
/// integrates to atan(st/√(1 + s² + t²)).
fn gnomonic_area(n: usize, x: usize, y: usize) -> f64 {
    let f = |s: f64, t: f64| (s * t / (1.0 + s * s + t * t).sqrt()).atan();
    let c = |i: usize| i as f64 / n as f64 * 2.0 - 1.0;
    let (s0, s1, t0, t1) = (c(x), c(x + 1), c(y), c(y + 1));
    f(s1, t1) - f(s0, t1) - f(s1, t0) + f(s0, t0)
}

/// Great-circle angle between two unit directions, rad.
pub(crate) fn arc(a: DVec3, b: DVec3) -> f64 {
    a.cross(b).length().atan2(a.dot(b))
}

/// The edges of the cells, in the order cells first name them.
fn build_edges(corners: &[[u32; 4]], centres: &[DVec3], vertices: &[DVec3]) -> Vec<GridEdge> {
    let mut first_cell: HashMap<(u32, u32), u32> = HashMap::new();
    let mut edges = Vec::with_capacity(corners.len() * 2);
    for (cell, ids) in corners.iter().enumerate() {
        for k in 0..4 {
            let (p, q) = (ids[k], ids[(k + 1) % 4]);
            let key = (p.min(q), p.max(q));
            match first_cell.remove(&key) {
                None => {
                    first_cell.insert(key, cell as u32);
                }
                Some(a) => edges.push(edge(a, cell as u32, key, centres, vertices)),
            }
        }
    }
    assert!(first_cell.is_empty(), "cube-sphere edges left unpaired");
    let n = (((corners.len() / 6) as f64).sqrt().round()) as usize;
    edges.sort_by_key(|e| structured_key(n, e.a as usize, e.b as usize));
    edges
}

/// Where edge `a → b` goes in the face-structured edge order ([`FaceLayout`]): a face's
/// interior x-edges row by row, then its interior y-edges row by row, then the seams
/// between faces in the order they were found.
fn structured_key(n: usize, a: usize, b: usize) -> (u8, usize) {
    if a / (n * n) != b / (n * n) {
        (2, 0)
    } else if b == a + 1 {
        (0, FaceLayout { n }.x_edge_of_cell(b))
    } else {
        (1, FaceLayout { n }.y_edge_of_cell(b))
    }
}

/// The face-structured numbering of a cube-sphere's edges: within a face, the interior
/// edges lie in rows in the order of the cells they join, so a pass over a face's
/// interior reads each neighbour and each edge as a contiguous slice (and vectorises)
/// where the edge-by-edge passes gather and scatter through index arrays.
///
/// # Guarantees
/// - The x-edge of cell `(face, y, x)`, `x ≥ 1`, joins `(face, y, x − 1)` (`a`) to it
///   (`b`), at [`FaceLayout::x_edge_of_cell`]; the x-edges of one row are consecutive.
/// - Its y-edge, `y ≥ 1`, joins `(face, y − 1, x)` (`a`) to it (`b`), at
///   [`FaceLayout::y_edge_of_cell`]; the y-edges of one row are consecutive.
/// - The `12·n` seam edges come last, from [`FaceLayout::first_seam_edge`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FaceLayout {
    /// Cells along a face edge.
    pub n: usize,
}

impl FaceLayout {
    /// The x-edge whose `b` cell is `cell` (`x ≥ 1`).
    pub fn x_edge_of_cell(self, cell: usize) -> usize {
        let n = self.n;
        let (face, y, x) = (cell / (n * n), (cell / n) % n, cell % n);
        debug_assert!(x >= 1, "cell {cell} has no x-edge inside its face");
        face * n * (n - 1) + y * (n - 1) + x - 1
    }

    /// The y-edge whose `b` cell is `cell` (`y ≥ 1`).
    pub fn y_edge_of_cell(self, cell: usize) -> usize {
        let n = self.n;
        let face = cell / (n * n);
        debug_assert!(
            (cell / n) % n >= 1,
            "cell {cell} has no y-edge inside its face"
        );
        6 * n * (n - 1) + face * n * (n - 1) + cell % (n * n) - n
    }

    /// The first seam edge (between two faces).
    pub fn first_seam_edge(self) -> usize {
        12 * self.n * (self.n - 1)
    }

    /// Face `face`'s interior edges, in the order of their places on it
    /// ([`Self::on_face`]): its x-edges, then its y-edges.
    pub fn face_edges(self, face: usize) -> impl Iterator<Item = usize> {
        let m = self.n * (self.n - 1);
        (face * m..(face + 1) * m).chain(6 * m + face * m..6 * m + (face + 1) * m)
    }

    /// Interior edge `e`'s face and its place among that face's interior edges: an
    /// x-edge's place is its number less its face's first x-edge's, a y-edge's that of
    /// its face's first y-edge plus the face's `n·(n − 1)` x-edges. Edges at one place
    /// on different faces are the same edge turned by the cube's rotations.
    pub fn on_face(self, e: usize) -> (usize, usize) {
        let m = self.n * (self.n - 1);
        debug_assert!(e < 12 * m, "edge {e} is a seam");
        if e < 6 * m {
            (e / m, e % m)
        } else {
            ((e - 6 * m) / m, m + (e - 6 * m) % m)
        }
    }
}

fn edge(a: u32, b: u32, (p, q): (u32, u32), centres: &[DVec3], vertices: &[DVec3]) -> GridEdge {
    let (ca, cb) = (centres[a as usize], centres[b as usize]);
    let (vp, vq) = (vertices[p as usize], vertices[q as usize]);
    let mut normal = vp.cross(vq).normalize();
    if normal.dot(cb - ca) < 0.0 {
        normal = -normal;
    }
    let tangent = (vp + vq).normalize().cross(normal);
    let (v0, v1) = if (vq - vp).dot(tangent) > 0.0 {
        (p, q)
    } else {
        (q, p)
    };
    GridEdge {
        a,
        b,
        v0,
        v1,
        normal,
        midpoint: (vp + vq).normalize(),
        length: arc(vp, vq),
        dual_length: arc(ca, cb),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interior_edges_lie_in_rows_at_their_structured_index() {
        for n in [1, 2, 5, 16] {
            let g = CubeSphere::new(n);
            let (layout, edges) = (g.layout(), g.edges());
            for cell in 0..g.cells() {
                let (x, y) = (cell % n, (cell / n) % n);
                if x >= 1 {
                    let e = &edges[layout.x_edge_of_cell(cell)];
                    assert_eq!(
                        (e.a as usize, e.b as usize),
                        (cell - 1, cell),
                        "n {n} x-edge"
                    );
                }
                if y >= 1 {
                    let e = &edges[layout.y_edge_of_cell(cell)];
                    assert_eq!(
                        (e.a as usize, e.b as usize),
                        (cell - n, cell),
                        "n {n} y-edge"
                    );
                }
            }
            let seams = &edges[layout.first_seam_edge()..];
            assert_eq!(seams.len(), 12 * n, "n {n}");
            assert!(
                seams
                    .iter()
                    .all(|e| e.a as usize / (n * n) != e.b as usize / (n * n))
            );
        }
    }

    #[test]
    fn an_interior_edges_place_on_its_face_is_where_face_edges_lists_it() {
        for n in [1, 2, 5] {
            let layout = FaceLayout { n };
            let mut all: Vec<usize> = Vec::new();
            for face in 0..6 {
                for (place, e) in layout.face_edges(face).enumerate() {
                    assert_eq!(layout.on_face(e), (face, place), "n {n} edge {e}");
                    all.push(e);
                }
            }
            all.sort_unstable();
            assert_eq!(
                all,
                (0..layout.first_seam_edge()).collect::<Vec<_>>(),
                "n {n}"
            );
        }
    }

    #[test]
    fn areas_sum_to_the_sphere_and_edges_pair_every_cell_side() {
        for n in [1, 2, 3, 8, 17] {
            let g = CubeSphere::new(n);
            let total: f64 = g.areas_sr().iter().sum();
            assert!(
                (total - 4.0 * std::f64::consts::PI).abs() < 1e-12,
                "n {n}: {total}"
            );
            assert_eq!(g.edges().len(), 12 * n * n, "n {n}");
            assert_eq!(g.vertex_areas_sr().len(), 6 * n * n + 2, "n {n}");
            let mut sides = vec![0; g.cells()];
            for e in g.edges() {
                assert_ne!(e.a, e.b);
                sides[e.a as usize] += 1;
                sides[e.b as usize] += 1;
                assert!(e.normal.dot(g.centres()[e.a as usize]).abs() < 1.0);
            }
            assert!(sides.iter().all(|&s| s == 4), "n {n}");
        }
    }

    #[test]
    fn parent_cells_cover_their_children() {
        let (fine, coarse) = (CubeSphere::new(8), CubeSphere::new(4));
        let mut area = vec![0.0; coarse.cells()];
        for c in 0..fine.cells() {
            area[parent_cell(8, c)] += fine.areas_sr()[c];
            let d = fine.centres()[c].dot(coarse.centres()[parent_cell(8, c)]);
            assert!(d > (0.3f64).cos(), "cell {c} far from its parent");
        }
        for (a, b) in area.iter().zip(coarse.areas_sr()) {
            assert!((a - b).abs() < 1e-14, "{a} vs {b}");
        }
    }

    /// Largest error, over the edges, of a gradient `gradient(edge, field, at_vertices)`
    /// of the cell samples of `g·x` against `g·n` at the edge's midpoint, relative to |g|.
    fn worst_gradient_error(
        n: usize,
        gradient: impl Fn(&CubeSphere, usize, &[f64], &[f64]) -> f64,
    ) -> f64 {
        let grid = CubeSphere::new(n);
        let g = DVec3::new(0.3, -0.5, 0.8);
        let field: Vec<f64> = grid.centres().iter().map(|c| g.dot(*c)).collect();
        let mut at_vertices = Vec::new();
        grid.cells_to_vertices(&field, &mut at_vertices);
        grid.edges()
            .iter()
            .enumerate()
            .map(|(k, e)| (gradient(&grid, k, &field, &at_vertices) - g.dot(e.normal)).abs())
            .fold(0.0, f64::max)
            / g.length()
    }

    #[test]
    fn the_normal_gradient_of_a_linear_field_converges_where_the_two_point_one_does_not() {
        let two_point = |g: &CubeSphere, k: usize, f: &[f64], _: &[f64]| {
            let ([a, b], d) = (g.edge_arrays().cells[k], g.edge_arrays().dual_length[k]);
            (f[b as usize] - f[a as usize]) / d
        };
        let normal = |g: &CubeSphere, k: usize, f: &[f64], v: &[f64]| g.normal_gradient(k, f, v);
        let old: Vec<f64> = [8, 16, 32]
            .map(|n| worst_gradient_error(n, two_point))
            .to_vec();
        let new: Vec<f64> = [8, 16, 32]
            .map(|n| worst_gradient_error(n, normal))
            .to_vec();
        eprintln!("worst gradient error at n = 8, 16, 32: two-point {old:?}, normal {new:?}");
        assert!(old[2] > 0.1, "the two-point gradient's skew error: {old:?}");
        assert!(
            new[1] / new[2] > 1.8,
            "normal gradient not converging: {new:?}"
        );
        assert!(new[2] < 0.01, "normal gradient error at n = 32: {new:?}");
    }

    #[test]
    fn the_centre_normal_gradient_is_the_normal_gradient_of_the_centres() {
        let grid = CubeSphere::new(8);
        let g = DVec3::new(-0.2, 0.7, 0.4);
        let field: Vec<f64> = grid.centres().iter().map(|c| g.dot(*c)).collect();
        let mut at_vertices = Vec::new();
        grid.cells_to_vertices(&field, &mut at_vertices);
        for (k, c) in grid.edge_arrays().centre_normal_gradient.iter().enumerate() {
            let want = grid.normal_gradient(k, &field, &at_vertices);
            assert!(
                (g.dot(*c) - want).abs() < 1e-12,
                "edge {k}: {} vs {want}",
                g.dot(*c)
            );
        }
    }
}
