//! The grid's edges and vertices face by face in rows, so that the momentum passes
//! (`advect`, `viscosity`) take each face's interior as contiguous slices, where the
//! grid's own numbering reaches a cell's edges and an edge's vertices through index
//! arrays.
//!
//! The edge velocities are copied into the rows at the start of the explicit momentum
//! step and back at its end ([`FaceRows::to_rows`], [`FaceRows::to_grid`]; the viscous
//! step's last stage writes the grid's numbering itself, where it runs). An edge on a face's border is in
//! both its faces' rows, a copy each with its own orientation; every quantity of an edge
//! is kept in that copy's orientation, so a copy is the grid's value or its negation,
//! exactly (IEEE negation commutes with every rounding the passes do), and the two copies
//! stay negations or equals of each other.
//!
//! The row loops sum a vertex's circulation over its edges, and a cell's terms over its
//! sides, in one fixed order of the local sides ([`SIDES`]): the grid's own edge order
//! inside a face, as `CubeSphere::new` numbers the edges. The vertices on the faces'
//! borders, and the cells there whose edges the grid numbers in another order, are taken
//! one by one from lists in the grid's order ([`FaceRows::seam_vertices`],
//! [`FaceRows::irregular_cells`]). So each value is the same sum in the same order as a
//! pass over the grid's numbering takes it; the grid's constants in it are face 0's,
//! which every face reads ([`FaceRows`] says why), so the rows give its bits inside
//! face 0 and to rounding elsewhere. (A renumbering of the grid's edges would leave the
//! rows' sums as they are, mathematically the same.) The exceptions: the advection's
//! cell terms and the viscous step's divergences, which every cell sums in the local
//! order, those irregular cells too (`advect::AdvectionGeometry::coriolis` says why).

use glam::DVec3;

use crate::avx2::with_avx2;

use super::flow::FilmGradient;
use super::grid::{CubeSphere, FACE_BASES};

/// Which side of a cell an edge is: bottom (`t` low), left (`s` low), right, top.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Side {
    Bottom = 0,
    Left = 1,
    Right = 2,
    Top = 3,
}

/// The four sides in the local order: a cell's edges in the grid's order, inside a face.
pub(crate) const SIDES: [Side; 4] = [Side::Bottom, Side::Left, Side::Right, Side::Top];

/// A grid vertex on a face's border, its circulation taken edge by edge.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SeamVertex {
    /// Its edges in the grid's order: a local copy of each and the weight `±d` of that
    /// copy's velocity in the circulation (the sign its orientation's).
    pub(crate) edges: [(u32, f64); 4],
    /// How many of `edges` there are (3 at a cube corner).
    pub(crate) edge_count: u8,
    /// Its local copies (two on a border, three at a corner).
    pub(crate) copies: [u32; 3],
    /// How many of `copies` there are.
    pub(crate) copy_count: u8,
    /// Its first copy's place in face 0, whose scale it is finished with
    /// ([`FaceRows::seam_circulation`]).
    pub(crate) face_0_copy: u32,
}

/// An edge between two faces: its two local copies.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SeamEdge {
    /// Its cells, the lower-numbered first, each with the side of it the edge is on and
    /// that cell's face's copy of the edge.
    pub(crate) cells: [(u32, Side, u32); 2],
}

/// A cell whose edges, in the grid's order, are not in the local order [`SIDES`].
#[derive(Clone, Copy, Debug)]
pub(crate) struct IrregularCell {
    pub(crate) cell: u32,
    /// The side of each of its edges, in the grid's order.
    pub(crate) order: [Side; 4],
    /// The local edge on each of those sides.
    pub(crate) edges: [u32; 4],
}

/// The face-row numbering of a grid of `n` cells a face.
///
/// Per face `f` (cells `f·n² + y·n + x` as the grid numbers them):
/// - the X-edges (along grid lines of constant `s`), `n + 1` a row, `n` rows: X-edge
///   `(i, y)` between cells `(i − 1, y)` and `(i, y)`, its local normal towards `+s`;
/// - the Y-edges (constant `t`), `n` a row, `n + 1` rows: Y-edge `(x, j)` between cells
///   `(x, j − 1)` and `(x, j)`, its local normal towards `+t`;
/// - the vertices, `n + 1` a row: vertex `(i, j)` at the corner `(s_i, t_j)`.
///
/// A local X-edge's tangent (`midpoint × normal`) points towards `−t` (its tail `v0` the
/// upper vertex), a Y-edge's towards `+s` (its tail the left vertex): the faces' `(s, t)`
/// are left-handed seen from outside.
///
/// The grid's constants the passes read (the lengths, the vertices' areas) are face 0's
/// only, which every face reads at its own local index: the six faces are congruent under
/// the cube's rotations and each face's rows are in its own frame, so every face's
/// constants are face 0's to rounding (within 1e-14 of the largest:
/// `tests::every_faces_constants_are_face_0s`). Six faces' were streamed from beyond the
/// core's 1 MB L2 in every pass at n = 64; one face's stay in it from face to face. A
/// border edge's two copies sit at two places on face 0's border, which the face's own
/// symmetries (quarter turns, mirrors) map onto each other: each such class of places
/// shares one value ([`share_border_values`]), so the copies read the same bits and stay
/// negations or equals of each other through the viscous stages.
#[derive(Clone, Debug)]
pub(crate) struct FaceRows {
    pub(crate) n: usize,
    /// Per local edge: the grid's edge.
    pub(crate) edge: Vec<u32>,
    /// Per local edge: `true` where the grid's normal is against the local one.
    pub(crate) flipped: Vec<bool>,
    /// Per local edge: `−1` where flipped, else `1` (a value times it is the value or its
    /// negation, exactly).
    pub(crate) signs: Vec<f64>,
    /// Per local edge of face 0, which every face reads ([`FaceRows`] says why): the arc
    /// between its cells' centres, rad.
    pub(crate) dual_length: Vec<f64>,
    /// Per local edge of face 0, which every face reads: its arc length, rad.
    pub(crate) length: Vec<f64>,
    /// Per local edge of face 0, which every face reads: `1/length`, per rad.
    pub(crate) inverse_length: Vec<f64>,
    /// Per local edge of face 0, which every face reads: `1/dual_length`, per rad.
    pub(crate) inverse_dual_length: Vec<f64>,
    /// Per local vertex: the grid's vertex.
    pub(crate) vertex: Vec<u32>,
    /// Per local vertex of face 0, which every face reads: its dual area, sr.
    pub(crate) vertex_area: Vec<f64>,
    /// Per local vertex of face 0, which every face reads: `1/area`, per sr.
    pub(crate) vertex_inverse_area: Vec<f64>,
    /// The vertices on the faces' borders.
    pub(crate) seam_vertices: Vec<SeamVertex>,
    /// The edges on the faces' borders.
    pub(crate) seam_edges: Vec<SeamEdge>,
    /// The local copies of the edges on the faces' borders: each one's local edge, its
    /// grid edge and its sign against it, side by side for [`Self::to_rows`], where it
    /// read them from [`Self::edge`] and [`Self::signs`], a line of each a copy scattered
    /// over 0.6 MB at n = 64 (44 k of its 144 k LL misses over `film_profile 64 0 9.81`'s
    /// 40 steps; the momentum's 2.303 -> 2.256 M with this table, its instructions 111.7
    /// -> 111.1 M).
    pub(crate) border_edges: Vec<(u32, u32, f64)>,
    /// The cells on the faces' borders whose edges the grid numbers out of the local
    /// order.
    pub(crate) irregular_cells: Vec<IrregularCell>,
    /// Per local copy of an edge on a face's border: the halo slot of the padded cell
    /// layout ([`Self::padded_cell`]) beyond that copy's cell, and the padded cell across
    /// the edge (in the other face) whose value the slot takes.
    pub(crate) cell_halo: Vec<[u32; 2]>,
    /// The grid's centre gradients (two-point, normal) per local edge of face 0, which
    /// every face reads, by component along face 0's axes ([`face_axes`]): in its own
    /// frame every face's are face 0's to rounding, as its lengths are ([`FaceRows`];
    /// `tests::every_faces_gradients_are_face_0s`), where in the world's they differ.
    /// Taken once [`Self::add_gradient`] has asked for them.
    gradients: [std::sync::OnceLock<[Vec<f64>; 3]>; 2],
}

impl FaceRows {
    /// Local edges a face: `2n(n + 1)`, the X-edges' rows then the Y-edges'.
    pub(crate) fn edges_per_face(&self) -> usize {
        2 * self.n * (self.n + 1)
    }

    /// Local vertices a face.
    pub(crate) fn vertices_per_face(&self) -> usize {
        (self.n + 1) * (self.n + 1)
    }

    /// Local vertices in all.
    pub(crate) fn vertices(&self) -> usize {
        self.vertex.len()
    }

    /// Local X-edge `(i, y)` of face `f`.
    pub(crate) fn x_edge(&self, f: usize, i: usize, y: usize) -> usize {
        f * self.edges_per_face() + y * (self.n + 1) + i
    }

    /// Local Y-edge `(x, j)` of face `f`.
    pub(crate) fn y_edge(&self, f: usize, x: usize, j: usize) -> usize {
        f * self.edges_per_face() + self.n * (self.n + 1) + j * self.n + x
    }

    /// Local vertex `(i, j)` of face `f`.
    pub(crate) fn vertex_at(&self, f: usize, i: usize, j: usize) -> usize {
        f * self.vertices_per_face() + j * (self.n + 1) + i
    }

    /// Cells a face in the padded layout: `(n + 2)²`, the face's cells ringed by a halo.
    pub(crate) fn padded_cells_per_face(&self) -> usize {
        (self.n + 2) * (self.n + 2)
    }

    /// A face's edges, vertices and padded cells: each stage's strides between faces.
    pub(crate) fn per_face(&self) -> (usize, usize, usize) {
        (
            self.edges_per_face(),
            self.vertices_per_face(),
            self.padded_cells_per_face(),
        )
    }

    /// The padded layout's slot `(px, py)` of face `f`: cell `(px − 1, py − 1)`, or the
    /// halo where `px` or `py` is 0 or `n + 1`.
    pub(crate) fn padded_cell(&self, f: usize, px: usize, py: usize) -> usize {
        f * self.padded_cells_per_face() + py * (self.n + 2) + px
    }

    /// Cell `c`'s slot in the padded layout.
    pub(crate) fn padded_of(&self, c: usize) -> usize {
        let n = self.n;
        self.padded_cell(c / (n * n), c % n + 1, (c / n) % n + 1)
    }

    /// The local edge on side `side` of cell `c`.
    #[inline]
    pub(crate) fn cell_edge(&self, c: usize, side: Side) -> usize {
        let n = self.n;
        let (f, x, y) = (c / (n * n), c % n, (c / n) % n);
        match side {
            Side::Bottom => self.y_edge(f, x, y),
            Side::Left => self.x_edge(f, x, y),
            Side::Right => self.x_edge(f, x + 1, y),
            Side::Top => self.y_edge(f, x, y + 1),
        }
    }

    /// The local vertices at the ends of side `side` of cell `c`: its tail `v0` and head
    /// `v1` in the local orientation.
    #[inline]
    pub(crate) fn side_vertices(&self, c: usize, side: Side) -> [usize; 2] {
        let n = self.n;
        let (f, x, y) = (c / (n * n), c % n, (c / n) % n);
        let at = |i, j| self.vertex_at(f, i, j);
        match side {
            Side::Bottom => [at(x, y), at(x + 1, y)],
            Side::Left => [at(x, y + 1), at(x, y)],
            Side::Right => [at(x + 1, y + 1), at(x + 1, y)],
            Side::Top => [at(x, y + 1), at(x + 1, y + 1)],
        }
    }

    /// `±1`: local edge `k`'s orientation against the grid's.
    pub(crate) fn sign(&self, k: usize) -> f64 {
        self.signs[k]
    }

    /// The grid's edge values `grid` (in the grid's orientation) into `rows` (each copy
    /// in its own): each face's inner edges are runs of the grid's ([`FaceLayout`](super::grid::FaceLayout), checked
    /// in [`Self::new`]), copied, the faces in reverse order ([`face_order`]: the
    /// advection's first stage runs them forward); the copies on the faces' borders one
    /// by one.
    pub(crate) fn to_rows(&self, grid: &[f64], rows: &mut Vec<f64>) {
        // Every entry is written: the buffer needs its length, not a fill.
        rows.resize(self.edge.len(), 0.0);
        self.for_each_inner_run(face_order(true), |local, at| {
            rows[local.clone()].copy_from_slice(&grid[at..at + local.len()]);
        });
        for &(k, e, sign) in &self.border_edges {
            rows[k as usize] = grid[e as usize] * sign;
        }
    }

    /// The rows' edge values back into the grid's numbering and orientation (a border
    /// edge's two copies agree: its first is taken), the faces in reverse order
    /// ([`face_order`]).
    pub(crate) fn to_grid(&self, rows: &[f64], grid: &mut [f64]) {
        self.for_each_inner_run(face_order(true), |local, at| {
            grid[at..at + local.len()].copy_from_slice(&rows[local]);
        });
        for e in &self.seam_edges {
            let k = e.cells[0].2 as usize;
            grid[self.edge[k] as usize] = rows[k] * self.signs[k];
        }
    }

    /// `run(local, at)` for each run of inner local edges (a row of a face's X-edges, or
    /// a row of its Y-edges) and the grid edge its first is, face by face in the order
    /// `faces`: the grid numbers a face's inner edges in the same rows, unflipped
    /// ([`FaceLayout`](super::grid::FaceLayout)). A row is under 2 KiB up to n = 256, which `memcpy` copies with
    /// vector moves (`rep movsb` above that).
    #[inline(always)]
    fn for_each_inner_run(
        &self,
        faces: impl Iterator<Item = usize>,
        mut run: impl FnMut(std::ops::Range<usize>, usize),
    ) {
        let n = self.n;
        if n < 2 {
            return; // no inner edges
        }
        for f in faces {
            for y in 0..n {
                let k = self.x_edge(f, 1, y);
                run(k..k + n - 1, self.grid_x_run(f, y));
            }
            for j in 1..n {
                let k = self.y_edge(f, 0, j);
                run(k..k + n, self.grid_y_run(f, j));
            }
        }
    }

    /// The grid's first inner X-edge of face `f`'s row `y` (`n ≥ 2`): its X-edge `(1, y)`,
    /// [`FaceLayout::x_edge_of_cell`](super::grid::FaceLayout::x_edge_of_cell) of cell `(1, y)` without its divisions (three a
    /// row, by a number the compiler does not know).
    #[inline(always)]
    pub(crate) fn grid_x_run(&self, f: usize, y: usize) -> usize {
        let n = self.n;
        (f * n + y) * (n - 1)
    }

    /// The grid's first Y-edge of face `f`'s inner row `j` (`1 ≤ j < n`): its Y-edge
    /// `(0, j)`, [`FaceLayout::y_edge_of_cell`](super::grid::FaceLayout::y_edge_of_cell) of cell `(0, j)` without its divisions.
    #[inline(always)]
    pub(crate) fn grid_y_run(&self, f: usize, j: usize) -> usize {
        let n = self.n;
        (6 + f) * n * (n - 1) + (j - 1) * n
    }

    /// `u += dt_s·(g·c)` on every local edge, `c` its grid edge's centre gradient for
    /// `kind` (`grid`'s, from which the rows were derived) in its own orientation, to
    /// rounding ([`Gravity`]). A border edge's second copy is then its first's, or its
    /// negation, exactly ([`Self::match_seam_copies`]).
    pub(crate) fn add_gradient(
        &self,
        u: &mut [f64],
        grid: &CubeSphere,
        kind: FilmGradient,
        g: DVec3,
        dt_s: f64,
    ) {
        self.add_gravity(u, &self.gravity(grid, kind, g, dt_s));
    }

    /// `u += gravity` on every local edge ([`Self::add_gradient`]).
    pub(crate) fn add_gravity(&self, u: &mut [f64], gravity: &Gravity) {
        self.add_by_face(
            u,
            #[inline(always)]
            |f, u| gravity.add(f, 0, u),
        );
    }

    /// [`Self::add_gravity`] of gravity along the faces' axes ([`Gravity::along_axes`]):
    /// the same bits.
    pub(crate) fn add_axis_gravity(&self, u: &mut [f64], gravity: &AxisGravity) {
        self.add_by_face(
            u,
            #[inline(always)]
            |f, u| {
                let (dt, g, c) = gravity.row(f, 0, u.len());
                add_term(dt, g, c, u);
            },
        );
    }

    /// `add(f, edges)` on each face's local edges, compiled for AVX2 where the processor
    /// has it; then each border edge's second copy made its first's
    /// ([`Self::match_seam_copies`]).
    #[inline(always)]
    fn add_by_face(&self, u: &mut [f64], add: impl Fn(usize, &mut [f64])) {
        let epf = self.edges_per_face();
        with_avx2(
            #[inline(always)]
            || {
                for (f, u) in u.chunks_exact_mut(epf).enumerate() {
                    add(f, u);
                }
            },
        );
        self.match_seam_copies(u);
    }

    /// The term `dt_s·(g·c)` of [`Self::add_gradient`], for passes that add it to the
    /// edges they move. The gradients are taken into the rows the first time `kind` is
    /// asked for.
    pub(crate) fn gravity(
        &self,
        grid: &CubeSphere,
        kind: FilmGradient,
        g: DVec3,
        dt_s: f64,
    ) -> Gravity<'_> {
        let ea = grid.edge_arrays();
        let (per_edge, rows) = match kind {
            FilmGradient::TwoPoint => (&ea.centre_gradient, &self.gradients[0]),
            FilmGradient::Normal => (&ea.centre_normal_gradient, &self.gradients[1]),
        };
        let epf = self.edges_per_face();
        let [a, b, c] = rows.get_or_init(|| self.local_gradients(per_edge, 1));
        Gravity {
            dt_s,
            // Exact: each axis picks one of g's components, or its negation.
            along: std::array::from_fn(|f| face_axes(f).map(|axis| g.dot(axis))),
            components: [&a[..epf], &b[..epf], &c[..epf]],
        }
    }

    /// The centre gradients `per_edge` (per grid edge) of the first `faces` faces' local
    /// edges, each in its own orientation, by component along its face's axes
    /// ([`face_axes`]): exact (each axis picks a component, or its negation).
    fn local_gradients(&self, per_edge: &[DVec3], faces: usize) -> [Vec<f64>; 3] {
        let epf = self.edges_per_face();
        let local = |k: usize| {
            let c = per_edge[self.edge[k] as usize] * self.signs[k];
            face_axes(k / epf).map(|axis| c.dot(axis))
        };
        let along: Vec<[f64; 3]> = (0..faces * epf).map(local).collect();
        std::array::from_fn(|axis| along.iter().map(|c| c[axis]).collect())
    }

    /// Each edge on the faces' borders: its second copy set to its first, in the second's
    /// orientation (exactly: a sign is `±1`). The first is the one [`Self::to_grid`]
    /// takes.
    fn match_seam_copies(&self, u: &mut [f64]) {
        for e in &self.seam_edges {
            let [first, second] = e.cells.map(|(_, _, k)| k as usize);
            u[second] = u[first] * self.signs[first] * self.signs[second];
        }
    }

    /// Derives the numbering from `grid`'s geometry.
    ///
    /// # Panics
    /// If an edge is not on a side of its cells, or the orientations disagree.
    pub(crate) fn new(grid: &CubeSphere) -> Self {
        let mut rows = Self::with_constant_faces(grid, 1);
        let n = rows.n;
        for values in [
            &mut rows.dual_length,
            &mut rows.length,
            &mut rows.inverse_length,
            &mut rows.inverse_dual_length,
        ] {
            share_border_values(n, values);
        }
        rows
    }

    /// [`Self::new`], with the grid's constants for the first `faces` faces (one is all
    /// the passes read; the tests take six to compare them).
    fn with_constant_faces(grid: &CubeSphere, faces: usize) -> Self {
        let n = grid.face_size();
        let mut rows = Self {
            n,
            edge: Vec::new(),
            flipped: Vec::new(),
            signs: Vec::new(),
            dual_length: Vec::new(),
            length: Vec::new(),
            inverse_length: Vec::new(),
            inverse_dual_length: Vec::new(),
            vertex: Vec::new(),
            vertex_area: Vec::new(),
            vertex_inverse_area: Vec::new(),
            seam_vertices: Vec::new(),
            seam_edges: Vec::new(),
            border_edges: Vec::new(),
            irregular_cells: Vec::new(),
            cell_halo: Vec::new(),
            gradients: Default::default(),
        };
        let local_edges = 6 * rows.edges_per_face();
        rows.edge = vec![u32::MAX; local_edges];
        rows.flipped = vec![false; local_edges];
        let edges = grid.edges();
        for (e, ge) in edges.iter().enumerate() {
            let mut copies = [(0, Side::Bottom, 0); 2];
            for (copy, c) in copies.iter_mut().zip([ge.a, ge.b]) {
                let side = side_of(n, c as usize, ge.midpoint);
                let k = rows.cell_edge(c as usize, side);
                // The local normal points away from the cell on its right and top sides.
                let away = matches!(side, Side::Right | Side::Top);
                let flipped = away != (c == ge.a);
                if rows.edge[k] != u32::MAX {
                    assert_eq!(rows.edge[k], e as u32, "local edge {k} twice");
                    assert_eq!(rows.flipped[k], flipped, "local edge {k}: orientation");
                }
                rows.edge[k] = e as u32;
                rows.flipped[k] = flipped;
                *copy = (c, side, k as u32);
            }
            if copies[0].2 != copies[1].2 {
                copies.sort_by_key(|c| c.0);
                rows.seam_edges.push(SeamEdge { cells: copies });
            }
        }
        assert!(
            rows.edge.iter().all(|&e| e != u32::MAX),
            "a local edge unset"
        );
        rows.for_each_inner_run(face_order(false), |local, at| {
            for (k, e) in local.zip(at..) {
                assert_eq!(
                    rows.edge[k] as usize, e,
                    "local edge {k}: not in the layout"
                );
                assert!(!rows.flipped[k], "local edge {k}: an inner edge flipped");
            }
        });
        rows.signs = rows
            .flipped
            .iter()
            .map(|&f| if f { -1.0 } else { 1.0 })
            .collect();
        let ea = grid.edge_arrays();
        let face_edges = &rows.edge[..faces * rows.edges_per_face()];
        let local = |a: &[f64]| face_edges.iter().map(|&e| a[e as usize]).collect();
        rows.dual_length = local(&ea.dual_length);
        rows.length = local(&ea.length);
        rows.inverse_length = local(&ea.inverse_length);
        rows.inverse_dual_length = local(&ea.inverse_dual_length);
        rows.vertex = vec![u32::MAX; 6 * rows.vertices_per_face()];
        for c in 0..grid.cells() {
            for side in SIDES {
                let k = rows.cell_edge(c, side);
                let ge = &edges[rows.edge[k] as usize];
                let ends = if rows.flipped[k] {
                    [ge.v1, ge.v0]
                } else {
                    [ge.v0, ge.v1]
                };
                for (v, id) in rows.side_vertices(c, side).into_iter().zip(ends) {
                    let old = std::mem::replace(&mut rows.vertex[v], id);
                    assert!(old == u32::MAX || old == id, "local vertex {v}: two ids");
                }
            }
        }
        let face_vertices = &rows.vertex[..faces * rows.vertices_per_face()];
        let at = |a: &[f64]| face_vertices.iter().map(|&v| a[v as usize]).collect();
        rows.vertex_area = at(grid.vertex_areas_sr());
        rows.vertex_inverse_area = at(grid.inverse_vertex_areas_per_sr());
        rows.border_edges = border_edges(&rows);
        rows.cell_halo = cell_halo(&rows);
        rows.seam_vertices = seam_vertices(&rows, grid);
        rows.irregular_cells = (0..grid.cells())
            .filter_map(|c| irregular(&rows, c))
            .collect();
        rows
    }

    /// Whether local vertex `(i, j)` is on its face's border.
    fn on_border(&self, i: usize, j: usize) -> bool {
        i == 0 || j == 0 || i == self.n || j == self.n
    }

    /// The circulation `Σ ±u d` about every local vertex of the local edge velocities
    /// `u`, each then finished by `finish(circulation, scale)` with the vertex's entry of
    /// `scale` (per local vertex of face 0, which every face reads, as it does
    /// [`Self::dual_length`]), into `out`: the inner rows' as the passes take them
    /// ([`Self::face_circulation_row`], each row as a pass reaches it), then the borders'
    /// ([`Self::seam_circulation`]). The tests' whole-grid reference.
    #[cfg(test)]
    pub(crate) fn circulation(
        &self,
        u: &[f64],
        out: &mut Vec<f64>,
        scale: &[f64],
        finish: impl Fn(f64, f64) -> f64,
    ) {
        out.resize(self.vertices(), 0.0);
        let (n, epf, vpf) = (self.n, self.edges_per_face(), self.vertices_per_face());
        for f in 0..6 {
            for j in 1..n {
                let start = self.vertex_at(0, 0, j);
                let row = &mut out[f * vpf + start..][..n];
                let u = &u[f * epf..][..epf];
                self.face_circulation_row(u, j, row, &scale[start..start + n], &finish);
            }
        }
        self.seam_circulation(u, out, scale, finish);
    }

    /// The circulation `Σ ±u d` about row `j` (`1 ≤ j < n`) of one face's inner vertices,
    /// from its local edges `u`, each finished by `finish(circulation, scale)` with the
    /// vertex's entry of `scale` (the row's, from vertex `(0, j)`, per local vertex of
    /// face 0, which every face reads, as it does [`Self::dual_length`]), into `row` (`n`
    /// long). It reads X-edges `(0..n, j − 1)` and `(0..n, j)` and Y-edges
    /// `(−1..n, j)`. About an inner vertex `(i, j)` the grid's edge order is X-edge
    /// `(i, j − 1)`, Y-edges `(i − 1, j)` and `(i, j)`, X-edge `(i, j)`: the first and
    /// third run into the vertex's tail end (`−u d`), the others into its head (`+u d`).
    /// The row starts at vertex `(0, j)`, on the border: `n` vertices vectorise without a
    /// scalar tail where the `n − 1` inner ones left three. That one's value, from the
    /// Y-edge before the row's first, is junk: the caller takes the border's from
    /// [`Self::seam_circulation`].
    #[inline(always)]
    pub(crate) fn face_circulation_row(
        &self,
        u: &[f64],
        j: usize,
        row: &mut [f64],
        scale: &[f64],
        finish: impl Fn(f64, f64) -> f64,
    ) {
        let (n, w, d) = (self.n, self.n + 1, &self.dual_length);
        // The rows of face 0's constants ([`FaceRows`]), and of the face's velocities: the
        // two X-edge rows as one run and the Y-edges with the one before as another (two
        // slices each where eight took a bounds check each, in every row of every stage).
        let x = self.x_edge(0, 0, j - 1)..self.x_edge(0, 0, j + 1);
        let y = self.y_edge(0, 0, j) - 1..self.y_edge(0, n, j);
        let (ux, dx, uy, dy) = (&u[x.clone()], &d[x], &u[y.clone()], &d[y]);
        let (ub, db, ua, da) = (&ux[..n], &dx[..n], &ux[w..w + n], &dx[w..w + n]);
        let (ul, dl, ur, dr) = (&uy[..n], &dy[..n], &uy[1..], &dy[1..]);
        let (row, scale) = (&mut row[..n], &scale[..n]);
        for i in 0..n {
            // `(0 − a) + b` as `b − a`: the same bits but for a zero's sign, one operation
            // fewer a vertex.
            let z = ul[i] * dl[i] - ub[i] * db[i] - ur[i] * dr[i] + ua[i] * da[i];
            row[i] = finish(z, scale[i]);
        }
    }

    /// The circulation of the vertices on the faces' borders, finished as
    /// [`Self::face_circulation_row`] finishes an inner row's, into each copy (of `out`,
    /// per local vertex): one value, finished with the scale of its first copy's place in
    /// face 0.
    #[inline(always)]
    pub(crate) fn seam_circulation(
        &self,
        u: &[f64],
        out: &mut [f64],
        scale: &[f64],
        finish: impl Fn(f64, f64) -> f64,
    ) {
        let scale_of = |v: &SeamVertex| scale[v.face_0_copy as usize];
        for v in &self.seam_vertices {
            // All but the cube's corners have four edges and two copies: written out (the
            // same sum), where the loops over the counts cost half again as much.
            if v.edge_count == 4 && v.copy_count == 2 {
                let [(k0, w0), (k1, w1), (k2, w2), (k3, w3)] = v.edges;
                let t = [
                    u[k0 as usize] * w0,
                    u[k1 as usize] * w1,
                    u[k2 as usize] * w2,
                ];
                // From the first term, not from zero (the same bits but for a zero's sign).
                let z = t[0] + t[1] + t[2] + u[k3 as usize] * w3;
                let z = finish(z, scale_of(v));
                (out[v.copies[0] as usize], out[v.copies[1] as usize]) = (z, z);
                continue;
            }
            let mut z = 0.0;
            for &(k, w) in &v.edges[..usize::from(v.edge_count)] {
                z += u[k as usize] * w;
            }
            let z = finish(z, scale_of(v));
            for &k in &v.copies[..usize::from(v.copy_count)] {
                out[k as usize] = z;
            }
        }
    }
}

/// Gravity's `dt·(g·c)` on the local edges ([`FaceRows::gravity`]): each face takes `g`
/// into its own frame and reads face 0's gradients in face 0's ([`FaceRows::gradients`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Gravity<'a> {
    /// The step, s.
    dt_s: f64,
    /// Per face: `g` along its axes ([`face_axes`]), m/s².
    along: [[f64; 3]; 6],
    /// Face 0's gradients' components along its axes, per local edge of a face.
    components: [&'a [f64]; 3],
}

impl<'a> Gravity<'a> {
    /// `u[i] += dt·(g·c)` for the local edges `from..from + u.len()` of face `f`, as
    /// `dt·((ga·a + gb·b) + gc·c)`, or as its one term where it has one
    /// ([`Self::one_term`]).
    #[inline(always)]
    pub(crate) fn add(&self, f: usize, from: usize, u: &mut [f64]) {
        let (dt, len) = (self.dt_s, u.len());
        if let Some((gk, ck)) = self.one_term(f) {
            add_term(dt, gk, &ck[from..from + len], u);
            return;
        }
        let [ga, gb, gc] = self.along[f];
        let [a, b, c] = self.components.map(|s| &s[from..from + len]);
        for i in 0..len {
            u[i] += dt * (ga * a[i] + gb * b[i] + gc * c[i]);
        }
    }

    /// Where `g` lies along one of face `f`'s axes (gravity along the world's, as it
    /// mostly is), that axis's `g` and face 0's gradient component along it: the other
    /// terms are zeros, which leave the sum's bits as they are unless the one term is
    /// itself zero (then the velocity is kept; only a zero velocity's sign could
    /// differ). One of face 0's three gradient arrays is read where the sum read all
    /// three.
    #[inline(always)]
    fn one_term(&self, f: usize) -> Option<(f64, &'a [f64])> {
        let [ga, gb, gc] = self.along[f];
        let [a, b, c] = self.components;
        match [ga, gb, gc].map(|g| g != 0.0) {
            [true, false, false] => Some((ga, a)),
            [false, true, false] => Some((gb, b)),
            [false, false, true] => Some((gc, c)),
            _ => None,
        }
    }

    /// The gravity as one term on every face ([`Self::one_term`]), where it is.
    pub(crate) fn along_axes(&self) -> Option<AxisGravity<'a>> {
        let terms = [0, 1, 2, 3, 4, 5].map(|f| self.one_term(f));
        Some(AxisGravity {
            dt_s: self.dt_s,
            terms: terms
                .into_iter()
                .collect::<Option<Vec<_>>>()?
                .try_into()
                .ok()?,
        })
    }
}

/// `u[i] += dt·(g·c[i])`: one axis's gravity term on a row of edges, the arithmetic
/// every pass that adds it keeps (so that they give the same bits).
#[inline(always)]
fn add_term(dt_s: f64, g: f64, c: &[f64], u: &mut [f64]) {
    let c = &c[..u.len()];
    for i in 0..u.len() {
        u[i] += dt_s * (g * c[i]);
    }
}

/// Gravity along one of each face's axes ([`Gravity::along_axes`]), for passes that add
/// it to each edge as they move it: the same bits as [`Gravity::add`].
#[derive(Clone, Copy, Debug)]
pub(crate) struct AxisGravity<'a> {
    /// The step, s.
    dt_s: f64,
    /// Per face: its axis's `g`, m/s², and face 0's gradient component along it, per
    /// local edge of a face.
    terms: [(f64, &'a [f64]); 6],
}

impl<'a> AxisGravity<'a> {
    /// The step, face `f`'s `g` and its gradient component of the local edges
    /// `from..from + len`: each edge's `u` becomes `u + dt·(g·c[i])`.
    #[inline(always)]
    pub(crate) fn row(&self, f: usize, from: usize, len: usize) -> (f64, f64, &'a [f64]) {
        let (g, c) = self.terms[f];
        (self.dt_s, g, &c[from..from + len])
    }

    /// `dt·(g·c)` of face `f`'s local edge `k` (counted from the face's first): what
    /// the edge's `u` gains.
    #[inline(always)]
    pub(crate) fn term(&self, f: usize, k: usize) -> f64 {
        let (g, c) = self.terms[f];
        self.dt_s * (g * c[k])
    }
}

/// `values` (per local edge of face 0) with each edge on the face's border given the
/// value of its class's place on the left border: the `k`-th edge from either end of any
/// side is one class under the face's quarter turns and mirrors (the same number to
/// rounding). A border edge's two copies are in one class: each is as far from either
/// end of the cube's edge they lie on.
fn share_border_values(n: usize, values: &mut [f64]) {
    // Face 0's X-edge (i, y) and Y-edge (x, j), as [`FaceRows::x_edge`] and
    // [`FaceRows::y_edge`] number them.
    let x_edge = |i: usize, y: usize| y * (n + 1) + i;
    let y_edge = |x: usize, j: usize| n * (n + 1) + j * n + x;
    for k in 0..n {
        let value = values[x_edge(0, k.min(n - 1 - k))];
        let places = [x_edge(0, k), x_edge(n, k), y_edge(k, 0), y_edge(k, n)];
        for place in places {
            values[place] = value;
        }
    }
}

/// The six faces, in order or in reverse (`reverse`). The momentum's passes over the
/// faces alternate directions, so that each starts on the faces the pass before ended on,
/// whose rows are still in the core's caches (at n = 64 a face's edge rows are 66 KB, a
/// pass's whole stream several times the 1 MB L2); each face's values are the same in
/// either order.
pub(crate) fn face_order(reverse: bool) -> impl Iterator<Item = usize> {
    (0..6).map(move |f| if reverse { 5 - f } else { f })
}

/// Face `f`'s axes: its major axis, its `s` axis and its `t` axis ([`FACE_BASES`]), each
/// an integer unit vector.
fn face_axes(f: usize) -> [DVec3; 3] {
    let (major, s, t) = FACE_BASES[f];
    [major, s, t].map(|axis| axis.as_dvec3())
}

/// Each seam edge's two copies, with their grid edge and sign.
fn border_edges(rows: &FaceRows) -> Vec<(u32, u32, f64)> {
    let copies = rows
        .seam_edges
        .iter()
        .flat_map(|e| e.cells.map(|(_, _, k)| k));
    copies
        .map(|k| (k, rows.edge[k as usize], rows.signs[k as usize]))
        .collect()
}

/// Each seam edge's two copies' halo slots ([`FaceRows::cell_halo`]): beyond the copy's
/// cell across its side, the padded slot of the cell in the other face.
fn cell_halo(rows: &FaceRows) -> Vec<[u32; 2]> {
    let n = rows.n;
    let mut out = Vec::with_capacity(2 * rows.seam_edges.len());
    for e in &rows.seam_edges {
        for (mine, other) in [(0, 1), (1, 0)] {
            let (c, side, _) = e.cells[mine];
            let c = c as usize;
            let (f, px, py) = (c / (n * n), c % n + 1, (c / n) % n + 1);
            let (hx, hy) = match side {
                Side::Bottom => (px, py - 1),
                Side::Left => (px - 1, py),
                Side::Right => (px + 1, py),
                Side::Top => (px, py + 1),
            };
            let across = rows.padded_of(e.cells[other].0 as usize);
            out.push([rows.padded_cell(f, hx, hy) as u32, across as u32]);
        }
    }
    out
}

/// The vertices on the faces' borders, each with its edges in the grid's order.
fn seam_vertices(rows: &FaceRows, grid: &CubeSphere) -> Vec<SeamVertex> {
    let n = rows.n;
    let vertices = grid.vertex_areas_sr().len();
    // Each grid edge's first local copy.
    let mut copy_of = vec![u32::MAX; grid.edges().len()];
    for (k, &e) in rows.edge.iter().enumerate().rev() {
        copy_of[e as usize] = k as u32;
    }
    let mut around: Vec<Vec<(u32, f64)>> = vec![Vec::new(); vertices];
    for (e, ge) in grid.edges().iter().enumerate() {
        let k = copy_of[e];
        let d = ge.dual_length * rows.sign(k as usize);
        // Counter-clockwise about v1 seen from outside.
        around[ge.v1 as usize].push((k, d));
        around[ge.v0 as usize].push((k, -d));
    }
    let mut index = vec![usize::MAX; vertices];
    let mut seams: Vec<SeamVertex> = Vec::new();
    for f in 0..6 {
        for j in 0..=n {
            for i in (0..=n).filter(|&i| rows.on_border(i, j)) {
                let local = rows.vertex_at(f, i, j);
                let v = rows.vertex[local] as usize;
                if index[v] == usize::MAX {
                    index[v] = seams.len();
                    let ring = &around[v];
                    assert!(
                        (3..=4).contains(&ring.len()),
                        "vertex {v}: {} edges",
                        ring.len()
                    );
                    let mut edges = [(0, 0.0); 4];
                    edges[..ring.len()].copy_from_slice(ring);
                    seams.push(SeamVertex {
                        edges,
                        edge_count: ring.len() as u8,
                        copies: [0; 3],
                        copy_count: 0,
                        face_0_copy: rows.vertex_at(0, i, j) as u32,
                    });
                }
                let s = &mut seams[index[v]];
                s.copies[usize::from(s.copy_count)] = local as u32;
                s.copy_count += 1;
            }
        }
    }
    seams
}

/// Cell `c`'s edge order, where it is on its face's border and the grid's order differs
/// from the local one.
fn irregular(rows: &FaceRows, c: usize) -> Option<IrregularCell> {
    let n = rows.n;
    let (x, y) = (c % n, (c / n) % n);
    if !(x == 0 || y == 0 || x == n - 1 || y == n - 1) {
        return None;
    }
    let mut order = SIDES;
    order.sort_by_key(|&side| rows.edge[rows.cell_edge(c, side)]);
    (order != SIDES).then(|| IrregularCell {
        cell: c as u32,
        order,
        edges: order.map(|side| rows.cell_edge(c, side) as u32),
    })
}

/// Which side of cell `c` (of a grid of `n` a face) the edge with midpoint `m` is.
fn side_of(n: usize, c: usize, m: DVec3) -> Side {
    let (f, x, y) = (c / (n * n), c % n, (c / n) % n);
    let (major, su, tv) = FACE_BASES[f];
    let p = m / m.dot(major.as_dvec3());
    let cells = |v: f64| (v + 1.0) * n as f64 / 2.0;
    let (s, t) = (cells(p.dot(su.as_dvec3())), cells(p.dot(tv.as_dvec3())));
    let near = |a: f64, b: usize| (a - b as f64).abs() < 0.25;
    match () {
        () if near(s, x) => Side::Left,
        () if near(s, x + 1) => Side::Right,
        () if near(t, y) => Side::Bottom,
        () if near(t, y + 1) => Side::Top,
        () => panic!("edge at ({s}, {t}) not on a side of cell {c}"),
    }
}

#[cfg(test)]
mod tests {
    use super::super::grid::FaceLayout;
    use super::*;

    /// The rows' grid runs are the layout's edges of their first cells, at n = 2, 5
    /// and 16.
    #[test]
    fn grid_runs_are_the_layouts_edges() {
        for n in [2, 5, 16] {
            let rows = FaceRows::new(&CubeSphere::new(n));
            let layout = FaceLayout { n };
            for f in 0..6 {
                for y in 0..n {
                    let want = layout.x_edge_of_cell((f * n + y) * n + 1);
                    assert_eq!(rows.grid_x_run(f, y), want, "n {n}, face {f}, X row {y}");
                }
                for j in 1..n {
                    let want = layout.y_edge_of_cell((f * n + j) * n);
                    assert_eq!(rows.grid_y_run(f, j), want, "n {n}, face {f}, Y row {j}");
                }
            }
        }
    }

    /// Whether the grid numbers inner vertex `(i, j)`'s edges in the order the rows sum
    /// them.
    fn in_grid_order(rows: &FaceRows, f: usize, i: usize, j: usize) -> bool {
        let ids = [
            rows.x_edge(f, i, j - 1),
            rows.y_edge(f, i - 1, j),
            rows.y_edge(f, i, j),
            rows.x_edge(f, i, j),
        ]
        .map(|k| rows.edge[k]);
        ids.is_sorted()
    }

    #[test]
    fn the_rows_hold_every_edge_and_vertex_of_the_grid() {
        for n in [1, 2, 3, 8] {
            let g = CubeSphere::new(n);
            let rows = FaceRows::new(&g);
            // Edges inside a face keep the grid's normal.
            for f in 0..6 {
                for k in 1..n {
                    for m in 0..n {
                        assert!(!rows.flipped[rows.x_edge(f, k, m)], "n {n}");
                        assert!(!rows.flipped[rows.y_edge(f, m, k)], "n {n}");
                    }
                }
            }
            let mut seen = vec![0; g.edges().len()];
            rows.edge.iter().for_each(|&e| seen[e as usize] += 1);
            let seams = seen.iter().filter(|&&s| s == 2).count();
            assert!(seen.iter().all(|&s| s == 1 || s == 2), "n {n}");
            assert_eq!(seams, 12 * n, "n {n}");
            assert_eq!(rows.seam_edges.len(), 12 * n, "n {n}");
            assert_eq!(rows.seam_vertices.len(), 12 * (n - 1) + 8, "n {n}");
            // Round trip.
            let u: Vec<f64> = (0..g.edges().len()).map(|e| e as f64 - 7.5).collect();
            let (mut local, mut back) = (Vec::new(), vec![0.0; u.len()]);
            rows.to_rows(&u, &mut local);
            rows.to_grid(&local, &mut back);
            assert_eq!(u, back, "n {n}");
        }
    }

    /// The rows' circulation is the grid-numbered scatter's: bit for bit about every
    /// vertex of face 0 inside it whose edges the grid numbers in the order the rows sum
    /// them (all, as the grid numbers them now), to rounding about any other (the other
    /// faces read face 0's dual lengths and areas, and a seam vertex its first copy's
    /// place in face 0's).
    #[test]
    fn the_rows_circulation_is_the_scattered_one() {
        for n in [1, 2, 5, 16] {
            let g = CubeSphere::new(n);
            let rows = FaceRows::new(&g);
            let u: Vec<f64> = (0..g.edges().len())
                .map(|e| ((e * 7919) % 1000) as f64 * 1e-3 - 0.4)
                .collect();
            let ea = g.edge_arrays();
            let mut scale = vec![0.0; g.vertex_areas_sr().len()];
            let mut want = vec![0.0; g.vertex_areas_sr().len()];
            for ((&u, d), [v0, v1]) in u.iter().zip(&ea.dual_length).zip(&ea.vertices) {
                want[*v1 as usize] += u * d;
                want[*v0 as usize] -= u * d;
                scale[*v1 as usize] += (u * d).abs();
                scale[*v0 as usize] += (u * d).abs();
            }
            for (z, a) in want.iter_mut().zip(g.vertex_areas_sr()) {
                *z /= a * 0.3;
            }
            let (mut local, mut got) = (Vec::new(), Vec::new());
            rows.to_rows(&u, &mut local);
            rows.circulation(&local, &mut got, &rows.vertex_area, |z, a| z / (a * 0.3));
            for f in 0..6 {
                for j in 0..=n {
                    for i in 0..=n {
                        let k = rows.vertex_at(f, i, j);
                        let v = rows.vertex[k] as usize;
                        let (z, w) = (got[k], want[v]);
                        if f == 0 && !rows.on_border(i, j) && in_grid_order(&rows, f, i, j) {
                            assert_eq!(z.to_bits(), w.to_bits(), "n {n}: vertex {k}: {z} vs {w}");
                        } else {
                            let tolerance = 1e-14 * scale[v] / (g.vertex_areas_sr()[v] * 0.3);
                            assert!((z - w).abs() <= tolerance, "n {n}: vertex {k}: {z} vs {w}");
                        }
                    }
                }
            }
        }
    }

    /// Every face's own constants (at its own local indices, its border edges' not
    /// shared) against face 0's, which every face reads (its border edges' shared): within
    /// `1e-14` of the largest, at n = 1, 5, 16, 64. The viscous step's cells' inverse
    /// areas too, the grid's.
    #[test]
    fn every_faces_constants_are_face_0s() {
        for n in [1, 5, 16, 64] {
            let grid = CubeSphere::new(n);
            let (one, six) = (
                FaceRows::new(&grid),
                FaceRows::with_constant_faces(&grid, 6),
            );
            let inverse_areas = grid.inverse_areas_per_sr();
            let arrays = [
                ("dual length", &one.dual_length[..], &six.dual_length[..]),
                ("length", &one.length, &six.length),
                ("inverse length", &one.inverse_length, &six.inverse_length),
                (
                    "inverse dual length",
                    &one.inverse_dual_length,
                    &six.inverse_dual_length,
                ),
                ("vertex area", &one.vertex_area, &six.vertex_area),
                (
                    "inverse vertex area",
                    &one.vertex_inverse_area,
                    &six.vertex_inverse_area,
                ),
                ("inverse cell area", &inverse_areas[..n * n], inverse_areas),
            ];
            for (name, face_0, every) in arrays {
                assert_each_face_is(face_0, every, &format!("n = {n}, {name}"));
            }
        }
    }

    /// Every face's centre gradients (two-point, normal), in its own frame, against face
    /// 0's, which every face reads: within `1e-14` of the largest, at n = 1, 5, 16, 64;
    /// the normal gradient within `n·1e-15` where that is more (its cross term differs
    /// the vertices' interpolated centres, an edge apart, whose rounding is each face's
    /// own: over the edge's length, it grows as n, 1.5e-14 at n = 32, 2.9e-14 at 64,
    /// 1.3e-13 at 256).
    #[test]
    fn every_faces_gradients_are_face_0s() {
        for n in [1, 5, 16, 64] {
            let grid = CubeSphere::new(n);
            let rows = FaceRows::new(&grid);
            let ea = grid.edge_arrays();
            let cross_rounding = 1e-14_f64.max(1e-15 * n as f64);
            for (name, per_edge, tolerance) in [
                ("two-point", &ea.centre_gradient, 1e-14),
                ("normal", &ea.centre_normal_gradient, cross_rounding),
            ] {
                let (one, six) = (
                    rows.local_gradients(per_edge, 1),
                    rows.local_gradients(per_edge, 6),
                );
                for (axis, (face_0, every)) in one.iter().zip(&six).enumerate() {
                    let what = format!("n = {n}, {name} gradient, axis {axis}");
                    assert_each_face_within(face_0, every, tolerance, &what);
                }
            }
        }
    }

    /// The rows' gravity is the grid's `u + dt (g·c)` edge by edge, to rounding, and a
    /// border edge's copies stay alike, bit for bit: both gradients, at n = 5 and 16.
    #[test]
    fn the_rows_gradient_is_the_grids() {
        let (g, dt) = (DVec3::new(0.3, -9.81, 1.7), 0.02);
        for n in [5, 16] {
            let grid = CubeSphere::new(n);
            let rows = FaceRows::new(&grid);
            let ea = grid.edge_arrays();
            let start: Vec<f64> = (0..grid.edges().len())
                .map(|e| ((e * 7919) % 1000) as f64 * 1e-3 - 0.4)
                .collect();
            for (kind, per_edge) in [
                (FilmGradient::TwoPoint, &ea.centre_gradient),
                (FilmGradient::Normal, &ea.centre_normal_gradient),
            ] {
                let mut u = Vec::new();
                rows.to_rows(&start, &mut u);
                rows.add_gradient(&mut u, &grid, kind, g, dt);
                for e in &rows.seam_edges {
                    let [a, b] = e.cells.map(|(_, _, k)| k as usize);
                    let (ua, ub) = (u[a] * rows.sign(a), u[b] * rows.sign(b));
                    assert_eq!(
                        ua.to_bits(),
                        ub.to_bits(),
                        "n {n}, {kind:?}: copies {a}, {b}"
                    );
                }
                let mut got = vec![0.0; start.len()];
                rows.to_grid(&u, &mut got);
                for (e, ((got, u), c)) in got.iter().zip(&start).zip(per_edge).enumerate() {
                    let want = u + dt * g.dot(*c);
                    let tolerance = 1e-14 * (u.abs() + dt * g.length() * c.length());
                    assert!(
                        (got - want).abs() <= tolerance,
                        "n {n}, {kind:?}, edge {e}: {got} against {want}"
                    );
                }
            }
        }
    }

    /// Gravity along one of a face's axes, taken as its one term, gives the bits of the
    /// three terms' sum on every edge of a rough field: gravity along each world axis
    /// (every face then has one term), at n = 5 and 16.
    #[test]
    fn gravity_along_an_axis_is_the_sum_of_its_terms() {
        for n in [5, 16] {
            let grid = CubeSphere::new(n);
            let rows = FaceRows::new(&grid);
            let start: Vec<f64> = (0..rows.edge.len())
                .map(|k| ((k * 7919) % 1000) as f64 * 1e-3 - 0.4005)
                .collect();
            let epf = rows.edges_per_face();
            for g in [DVec3::X, DVec3::NEG_Y, DVec3::Z].map(|axis| axis * 9.81) {
                let gravity = rows.gravity(&grid, FilmGradient::TwoPoint, g, 0.02);
                let mut got = start.clone();
                for (f, u) in got.chunks_exact_mut(epf).enumerate() {
                    gravity.add(f, 0, u);
                }
                assert!(gravity.along_axes().is_some(), "g {g}: along an axis");
                let [a, b, c] = gravity.components;
                for (k, (got, u)) in got.iter().zip(&start).enumerate() {
                    let [ga, gb, gc] = gravity.along[k / epf];
                    let i = k % epf;
                    let want = u + 0.02 * (ga * a[i] + gb * b[i] + gc * c[i]);
                    assert_eq!(got.to_bits(), want.to_bits(), "n {n}, g {g}, edge {k}");
                }
            }
        }
    }

    /// Each of the six faces' values in `every` is `face_0`'s at the same index, within
    /// `1e-14` of the largest.
    fn assert_each_face_is(face_0: &[f64], every: &[f64], what: &str) {
        assert_each_face_within(face_0, every, 1e-14, what);
    }

    /// Each of the six faces' values in `every` is `face_0`'s at the same index, within
    /// `tolerance` of the largest.
    fn assert_each_face_within(face_0: &[f64], every: &[f64], tolerance: f64, what: &str) {
        assert_eq!(every.len(), 6 * face_0.len(), "{what}: not six faces");
        let largest = face_0.iter().fold(0.0, |m: f64, x| m.max(x.abs()));
        assert!(largest > 0.0, "{what}: all zero");
        let mut worst = 0.0_f64;
        for (k, (a, b)) in face_0.iter().cycle().zip(every).enumerate() {
            let off = (a - b).abs() / largest;
            worst = worst.max(off);
            assert!(
                off <= tolerance,
                "{what}, face {}, index {}: {b} against face 0's {a} (off by {off:e} of the \
                 largest)",
                k / face_0.len(),
                k % face_0.len()
            );
        }
        eprintln!("{what}: every face within {worst:.1e} of the largest of face 0's");
    }
}
