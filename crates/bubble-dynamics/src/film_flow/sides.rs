//! Each cell's four sides in its face's own directions, for the passes that work cell by
//! cell in the face-structured layout ([`FaceLayout`]): inside a face a cell's
//! neighbours and edges sit at fixed offsets, read as slices; the cells on a face's rim
//! look theirs up here.
//!
//! Why cell by cell: an edge-by-edge pass scatters into both cells through index arrays,
//! which no compiler vectorises; a cell that gathers its four sides from slices does.

use std::ops::Range;

use glam::DVec3;

use super::face_geometry::{EdgeConstant, EdgeVector, to_face_frame};
use super::grid::{CubeSphere, FACE_BASES, FaceLayout};
use crate::avx2::with_avx2;

/// The side towards −x in the face's own coordinates (the cell's x-edge).
pub(crate) const LEFT: usize = 0;
/// The side towards +x (the next cell's x-edge).
pub(crate) const RIGHT: usize = 1;
/// The side towards −y (the cell's y-edge).
pub(crate) const BOTTOM: usize = 2;
/// The side towards +y (the y-edge of the cell above).
pub(crate) const TOP: usize = 3;
/// Inside a face, the sign of each side's volume in the cell's inflow (a volume is
/// positive from an edge's `a` cell to its `b` cell; the cell is the `a` cell of its right
/// and top edges): a sign multiplies exactly, so the gathers need no branch.
pub(crate) const INFLOW: [f64; 4] = [1.0, -1.0, 1.0, -1.0];

/// Every cell's neighbour and edge on each side, and every edge in runs.
///
/// # Guarantees
/// - `neighbour[c][k]` and `edge[c][k]` are the cell across side `k` of cell `c` and the
///   edge between them; `is_a[c][k]` says whether `c` is that edge's `a` cell.
/// - Inside a face these follow [`FaceLayout`]: `c ∓ 1` and `c ∓ n` across the x and y
///   sides, with the signs [`INFLOW`].
/// - `edge_runs` holds every edge inside a face once, face by face, each run with
///   the side it is of its `a` cells and of its `b` cells; [`CellSides::seams`] the seam
///   edges, from [`FaceLayout::first_seam_edge`] on.
#[derive(Clone, Debug)]
pub(crate) struct CellSides {
    /// The grid's layout.
    pub(crate) layout: FaceLayout,
    /// Per cell and side: the cell across it.
    pub(crate) neighbour: Vec<[u32; 4]>,
    /// Per cell and side: the edge.
    pub(crate) edge: Vec<[u32; 4]>,
    /// Per cell and side: whether the cell is the edge's `a` cell.
    pub(crate) is_a: Vec<[bool; 4]>,
    /// The cells inside the faces as runs, one a face row ([`CellRun`]).
    pub(crate) cell_runs: Vec<CellRun>,
    /// The cells on the faces' rims (a side on a seam), in increasing order: the runs
    /// leave them out, and passes take them one by one through the tables (as runs of
    /// one they cost as much as the whole inside, each run's slices set up for a cell).
    pub(crate) rim_cells: Vec<u32>,
    /// The rim cells' tables side by side, in the order of `rim_cells` ([`Rim`]).
    rim_tables: RimTables,
    /// Every edge inside a face once, as runs face by face: each face row's x-edges,
    /// then the face's y-edges ([`EdgeRun`]).
    pub(crate) edge_runs: Vec<EdgeRun>,
    /// The seam edges' cells and sides ([`Seams`]).
    seam_tables: SeamTables,
    /// Per face, the seam edges around it, counted from the first ([`Pads`]): on its
    /// cells' left sides (by row), their right sides, their bottom sides (by column),
    /// their top sides, `n` each.
    pads: Vec<u32>,
    /// Per face and side, its pads' sign ([`Pads`]).
    pad_signs: Vec<f64>,
    /// Every rim cell's sides on a seam ([`RimSeamSide`]).
    rim_seam_sides: Vec<RimSeamSide>,
    /// The same as flat places ([`Self::rim_seam_copies`]).
    rim_seam_copies: Vec<[u32; 2]>,
    /// Where each face row's rim cells start among a face's ([`Self::rim_of_row`]),
    /// and the face's count after the last.
    rim_rows: Vec<u32>,
}

/// The seam edges along one side of a face ([`CellSides::face_pads`]): which seam edges
/// (from the first), and the sign that turns their values, positive from an edge's `a`
/// cell to its `b`, into ones positive towards the face's +x or +y, as the face's own
/// edges' are: one for the side (a seam's edges all run one way), so a pass copies a
/// side's pads in a loop of a load, a multiplication and a store: about 3 instructions
/// a pad, where a sign a pad took 12.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Pads<'a> {
    /// The seam edges, counted from [`FaceLayout::first_seam_edge`].
    pub(crate) seams: &'a [u32],
    /// ±1.
    pub(crate) sign: f64,
}

/// A rim cell's side on a seam, and the cell across it (on another face's rim), both as
/// places in [`CellSides::rim_cells`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct RimSeamSide {
    /// The rim cell's place.
    pub(crate) rim: u32,
    /// Its side on the seam.
    pub(crate) side: u8,
    /// The place of the cell across.
    pub(crate) across: u32,
}

/// Per seam edge, in the edges' order: its `a` and `b` cells and the side it is of each.
#[derive(Clone, Debug, Default)]
struct SeamTables {
    /// Each seam edge's `a` cell.
    a: Vec<u32>,
    /// Each seam edge's `b` cell.
    b: Vec<u32>,
    /// The side each seam edge is of its `a` cell and of its `b` cell.
    sides: Vec<[u8; 2]>,
    /// Each seam edge's `a` and `b` cells' places in [`CellSides::rim_cells`] (a seam
    /// joins two rim cells): where their values are in the rim's order.
    rim: Vec<[u32; 2]>,
}

/// The seam edges as one block, numbered on from `start`, their cells through tables:
/// as runs of one edge each they cost a pass about a hundred instructions an edge, its
/// slices set up for one edge; a pass now walks them in one loop, per-edge arrays cut
/// to the block once.
#[derive(Clone, Copy)]
pub(crate) struct Seams<'a> {
    /// The first seam edge.
    pub(crate) start: usize,
    /// How many.
    pub(crate) len: usize,
    /// Each seam edge's `a` cell.
    a: &'a [u32],
    /// Each seam edge's `b` cell.
    b: &'a [u32],
    /// The side each is of its `a` cell and of its `b` cell.
    sides: &'a [[u8; 2]],
    /// Each one's `a` and `b` cells' places in the rim's order.
    rim: &'a [[u32; 2]],
}

/// A stretch of edges an edge pass walks in one loop, its per-edge arrays as slices: a
/// face's run ([`EdgeRun`]) or the seams ([`Seams`], their cells' values gathered first,
/// [`SeamEnds`]).
pub(crate) trait EdgeBlock: Copy {
    /// The first edge (the others follow it).
    fn first(&self) -> usize;
    /// How many edges.
    fn count(&self) -> usize;
    /// A per-edge array's values along the block, `count()` long.
    #[inline(always)]
    fn values<'a, T>(&self, per_edge: &'a [T]) -> &'a [T] {
        &per_edge[self.first()..self.first() + self.count()]
    }
    /// A per-edge array's values along the block, to write.
    #[inline(always)]
    fn values_mut<'a, T>(&self, per_edge: &'a mut [T]) -> &'a mut [T] {
        &mut per_edge[self.first()..self.first() + self.count()]
    }
    /// A grid constant's values along the block, `count()` long: a run's from face 0's
    /// at the run's place on its face (the faces are congruent,
    /// [`super::face_geometry`]), the seams' their own.
    fn constant<'a>(&self, c: &'a EdgeConstant) -> &'a [f64];
    /// A grid vector's components along the block, each `count()` long, in the frame of
    /// [`Self::frame`]: a run's face 0's in that face's frame, the seams' in the world's.
    fn vector<'a>(&self, v: &'a EdgeVector) -> [&'a [f64]; 3];
    /// The world vector `world` in the frame of [`Self::vector`]'s components: a run's
    /// face's, the world's for the seams.
    fn frame(&self, world: DVec3) -> DVec3;
}

impl EdgeBlock for EdgeRun {
    #[inline(always)]
    fn first(&self) -> usize {
        self.start
    }
    #[inline(always)]
    fn count(&self) -> usize {
        self.len
    }
    #[inline(always)]
    fn constant<'a>(&self, c: &'a EdgeConstant) -> &'a [f64] {
        &c.face[self.on_face..self.on_face + self.len]
    }
    #[inline(always)]
    fn vector<'a>(&self, v: &'a EdgeVector) -> [&'a [f64]; 3] {
        let [x, y, z] = &v.face;
        let along = self.on_face..self.on_face + self.len;
        [&x[along.clone()], &y[along.clone()], &z[along]]
    }
    #[inline(always)]
    fn frame(&self, world: DVec3) -> DVec3 {
        to_face_frame(self.face, world)
    }
}

impl EdgeBlock for Seams<'_> {
    #[inline(always)]
    fn first(&self) -> usize {
        self.start
    }
    #[inline(always)]
    fn count(&self) -> usize {
        self.len
    }
    #[inline(always)]
    fn constant<'a>(&self, c: &'a EdgeConstant) -> &'a [f64] {
        &c.seams[..self.len]
    }
    #[inline(always)]
    fn vector<'a>(&self, v: &'a EdgeVector) -> [&'a [f64]; 3] {
        let [x, y, z] = &v.seams;
        [&x[..self.len], &y[..self.len], &z[..self.len]]
    }
    #[inline(always)]
    fn frame(&self, world: DVec3) -> DVec3 {
        world
    }
}

/// Buffers of the seam edges' end values: a cell field's values at their `a` cells and
/// at their `b` cells, gathered so that a pass takes the seams as one run.
#[derive(Clone, Debug, Default)]
pub(crate) struct SeamEnds {
    /// Per field: the values at the `a` cells.
    a: [Vec<f64>; 2],
    /// Per field: the values at the `b` cells.
    b: [Vec<f64>; 2],
}

impl SeamEnds {
    /// `field`'s values at the seams' `a` and `b` cells.
    pub(crate) fn gather(&mut self, seams: Seams, field: &[f64]) -> [&[f64]; 2] {
        let [a] = self.gather_many(seams, [field]);
        a
    }

    /// Each of `fields`' values at the seams' `a` and `b` cells (at most two fields).
    pub(crate) fn gather_many<const K: usize>(
        &mut self,
        seams: Seams,
        fields: [&[f64]; K],
    ) -> [[&[f64]; 2]; K] {
        let (a, b) = (&mut self.a, &mut self.b);
        for (k, field) in fields.iter().enumerate() {
            gather(field, seams.a, &mut a[k]);
            gather(field, seams.b, &mut b[k]);
        }
        std::array::from_fn(|k| [&a[k][..], &b[k][..]])
    }

    /// `field`'s values at the seams' `a` and `b` cells, and those of the rim's fields
    /// `per_side[k]` (in the rim's order, [`CellSides::rim_cells`]) for the side `k`
    /// each edge is of that cell (the transport's limited rises, which only the rim
    /// keeps whole: a face's are taken just before its runs).
    pub(crate) fn gather_with_rim_sides(
        &mut self,
        seams: Seams,
        field: &[f64],
        per_side: &[Vec<f64>; 4],
    ) -> [[&[f64]; 2]; 2] {
        let ([a0, a1], [b0, b1]) = (&mut self.a, &mut self.b);
        gather(field, seams.a, a0);
        gather(field, seams.b, b0);
        // Written in place (pushed, they took four times the instructions).
        let m = seams.len;
        a1.resize(m, 0.0);
        b1.resize(m, 0.0);
        let (a1, b1) = (&mut a1[..m], &mut b1[..m]);
        for i in 0..m {
            let ([ra, rb], [ka, kb]) = (seams.rim_ends(i), seams.sides(i));
            (a1[i], b1[i]) = (per_side[ka][ra], per_side[kb][rb]);
        }
        [[&a0[..], &b0[..]], [&a1[..], &b1[..]]]
    }
}

impl Seams<'_> {
    /// Seam edge `i`'s `a` and `b` cells.
    #[cfg(test)]
    pub(crate) fn cells(&self, i: usize) -> [usize; 2] {
        [self.a[i] as usize, self.b[i] as usize]
    }

    /// A cell field's values at seam edge `i`'s `a` and `b` cells.
    #[inline(always)]
    pub(crate) fn ends(&self, i: usize, cells: &[f64]) -> [f64; 2] {
        [cells[self.a[i] as usize], cells[self.b[i] as usize]]
    }

    /// The side seam edge `i` is of its `a` cell and of its `b` cell.
    #[inline(always)]
    pub(crate) fn sides(&self, i: usize) -> [usize; 2] {
        self.sides[i].map(usize::from)
    }

    /// Seam edge `i`'s `a` and `b` cells' places in the rim's order
    /// ([`CellSides::rim_cells`]).
    #[inline(always)]
    pub(crate) fn rim_ends(&self, i: usize) -> [usize; 2] {
        self.rim[i].map(|r| r as usize)
    }
}

/// The rim cells' neighbours, edges and inflow signs, one array a side in the order of
/// [`CellSides::rim_cells`]: a rim pass reads each in order (the per-cell tables put a
/// cell's four sides together, which a pass over the rim strides through).
#[derive(Clone, Debug, Default)]
struct RimTables {
    /// Per side: each rim cell's neighbour.
    neighbour: [Vec<u32>; 4],
    /// Per side: each rim cell's edge.
    edge: [Vec<u32>; 4],
    /// Per side: the sign of a volume across it in the cell's inflow.
    inflow: [Vec<f64>; 4],
    /// Each rim cell's inverse area, per sr: a table in the rim's order instead of a
    /// gather from the grid's, which touched a cache line a cell down the faces' sides.
    inverse_area: Vec<f64>,
}

/// [`RimTables`] as slices of one length, so that a pass indexes them without checks.
#[derive(Clone, Copy)]
pub(crate) struct Rim<'a> {
    /// The rim cells.
    pub(crate) cells: &'a [u32],
    /// Per side: each rim cell's neighbour.
    neighbour: [&'a [u32]; 4],
    /// Per side: each rim cell's edge.
    edge: [&'a [u32]; 4],
    /// Per side: the sign of a volume across it in the cell's inflow.
    inflow: [&'a [f64]; 4],
    /// Each rim cell's inverse area, per sr.
    pub(crate) inverse_area: &'a [f64],
}

impl Rim<'_> {
    /// A per-edge array's values on rim cell `i`'s four sides.
    #[inline(always)]
    pub(crate) fn at_edges(&self, i: usize, per_edge: &[f64]) -> [f64; 4] {
        let e = &self.edge;
        let at = |k: usize| per_edge[e[k][i] as usize];
        [at(0), at(1), at(2), at(3)]
    }

    /// A cell field's values at rim cell `i`'s four neighbours.
    #[inline(always)]
    pub(crate) fn at_neighbours(&self, i: usize, per_cell: &[f64]) -> [f64; 4] {
        let nb = &self.neighbour;
        let at = |k: usize| per_cell[nb[k][i] as usize];
        [at(0), at(1), at(2), at(3)]
    }

    /// The signs of rim cell `i`'s sides' volumes in its inflow.
    #[inline(always)]
    pub(crate) fn inflow(&self, i: usize) -> [f64; 4] {
        let s = &self.inflow;
        [s[0][i], s[1][i], s[2][i], s[3][i]]
    }

    /// A cell field's values at the neighbours of the rim cells at places `at`, in the
    /// rim's order, into `out[k]`.
    #[inline(always)]
    pub(crate) fn gather_neighbours(
        &self,
        per_cell: &[f64],
        at: Range<usize>,
        out: &mut [Vec<f64>; 4],
    ) {
        for (o, cells) in out.iter_mut().zip(self.neighbour) {
            gather(per_cell, &cells[at.clone()], o);
        }
    }

    /// A cell field's values at the rim cells at places `at`, in the rim's order, into
    /// `out`.
    #[inline(always)]
    pub(crate) fn gather_cells(&self, per_cell: &[f64], at: Range<usize>, out: &mut Vec<f64>) {
        gather(per_cell, &self.cells[at], out);
    }
}

/// `values` at `at`, in order, into `out` (written in place: `extend` took twice the
/// instructions).
#[inline(always)]
fn gather(values: &[f64], at: &[u32], out: &mut Vec<f64>) {
    out.resize(at.len(), 0.0);
    // Four at a time: the loop's own count and branch once for four loads.
    let quads = out.chunks_exact_mut(4).zip(at.chunks_exact(4));
    for (o, j) in quads {
        for k in 0..4 {
            o[k] = values[j[k] as usize];
        }
    }
    let whole = at.len() / 4 * 4;
    for (o, &j) in out[whole..].iter_mut().zip(&at[whole..]) {
        *o = values[j as usize];
    }
}

/// Consecutive cells inside a face: their neighbours and edges on each side are
/// consecutive too, and their sides' volumes flow in with the signs [`INFLOW`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct CellRun {
    /// The first cell.
    pub(crate) start: usize,
    /// How many cells.
    pub(crate) len: usize,
    /// On each side, the first cell's neighbour.
    pub(crate) neighbour: [usize; 4],
    /// On each side, the first cell's edge.
    pub(crate) edge: [usize; 4],
}

// The passes take the inside a face at a time ([`CellSpan`]); the runs stay to tell the
// rim from the inside, and the tests check the tables against them.
#[cfg(test)]
impl CellRun {
    /// The run's cells.
    pub(crate) fn cells(&self) -> std::ops::Range<usize> {
        self.start..self.start + self.len
    }
}

/// A face's interior rows as one stretch of consecutive cells, from its first interior
/// cell to its last: the rim cells at the rows' ends lie among them. Inside the stretch
/// every cell's neighbours sit at `∓1` and `∓n` (for a rim cell those are not its
/// neighbours but are cells), so a pass that reads only its cells' neighbours, not their
/// edges (the x-edges are `n − 1` a row), can take a face as one run and then redo the
/// rim through the tables: one run a face instead of one a row.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct CellSpan {
    /// The first cell.
    pub(crate) start: usize,
    /// How many cells.
    pub(crate) len: usize,
    /// Cells along a face edge.
    n: usize,
}

impl CellSpan {
    /// The span's cells.
    pub(crate) fn cells(&self) -> std::ops::Range<usize> {
        self.start..self.start + self.len
    }

    /// Cells along a face edge.
    pub(crate) fn n(&self) -> usize {
        self.n
    }

    /// A per-cell grid constant of face 0 (`n²` long) along the span: the same cells'
    /// values on every face, to rounding ([`super::face_geometry`]).
    #[inline(always)]
    pub(crate) fn on_face<'a>(&self, per_face: &'a [f64]) -> &'a [f64] {
        let first = self.start % (self.n * self.n);
        &per_face[first..first + self.len]
    }

    /// The cells at the layout's offset on side `k` from the span's cells.
    pub(crate) fn neighbours(&self, k: usize) -> std::ops::Range<usize> {
        let first = match k {
            LEFT => self.start - 1,
            RIGHT => self.start + 1,
            BOTTOM => self.start - self.n,
            _ => self.start + self.n,
        };
        first..first + self.len
    }
}

/// Consecutive edges whose `a` cells and `b` cells are consecutive too.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct EdgeRun {
    /// The first edge.
    pub(crate) start: usize,
    /// How many edges.
    pub(crate) len: usize,
    /// The first edge's `a` cell.
    pub(crate) a: usize,
    /// The first edge's `b` cell.
    pub(crate) b: usize,
    /// The side the edges are of their `a` cells and of their `b` cells.
    pub(crate) sides: [usize; 2],
    /// The face the run lies on.
    pub(crate) face: usize,
    /// The first edge's place among its face's interior edges ([`FaceLayout::on_face`]):
    /// where the run's constants start in face 0's ([`EdgeBlock::constant`]).
    pub(crate) on_face: usize,
}

impl EdgeRun {
    /// The run's edges.
    pub(crate) fn edges(&self) -> std::ops::Range<usize> {
        self.start..self.start + self.len
    }

    /// The run's `a` cells.
    pub(crate) fn a_cells(&self) -> std::ops::Range<usize> {
        self.a..self.a + self.len
    }

    /// The run's `b` cells.
    pub(crate) fn b_cells(&self) -> std::ops::Range<usize> {
        self.b..self.b + self.len
    }

    /// A cell field's values at the run's `a` cells and at its `b` cells.
    #[inline(always)]
    pub(crate) fn ends<'a>(&self, cells: &'a [f64]) -> (&'a [f64], &'a [f64]) {
        (&cells[self.a_cells()], &cells[self.b_cells()])
    }

    /// An x-run of `n − 1` edges taken as `n`, where its values' place (`out` long) has
    /// room and its last `b` cell is not the field's last (`cells` long), for a pass that
    /// reads per-edge arrays and writes only its values
    /// ([`super::fluxes::EdgeValues::run`]): a whole number of vectors where `n` is a
    /// multiple of four (the `n − 1` left a scalar remainder of three edges, about 190
    /// instructions a row in the thickness transport at n = 64). The extra edge reads the
    /// next row's first x-edge's values and end cells (the y-edges' first after a face's
    /// last row), and its value lands in the window's next pad, written after it.
    #[inline(always)]
    pub(crate) fn padded(self, out: usize, cells: usize) -> Self {
        let len = self.len + 1;
        if self.sides[0] == RIGHT && out >= len && self.b + len <= cells {
            Self { len, ..self }
        } else {
            self
        }
    }

    /// A per-edge array's values along the run, to write.
    #[inline(always)]
    pub(crate) fn along_mut<'a>(&self, per_edge: &'a mut [f64]) -> &'a mut [f64] {
        &mut per_edge[self.edges()]
    }
}

impl CellSides {
    /// Derives the tables from `grid`.
    ///
    /// # Panics
    /// If a cell's edges do not lie one on each side (the grid is not a cube-sphere).
    pub(crate) fn new(grid: &CubeSphere) -> Self {
        let layout = grid.layout();
        let cells = grid.cells();
        let mut neighbour = vec![[u32::MAX; 4]; cells];
        let mut edge = vec![[u32::MAX; 4]; cells];
        let mut is_a = vec![[false; 4]; cells];
        let mut seams = SeamTables::default();
        for (e, ge) in grid.edges().iter().enumerate() {
            let mut sides = [0u8; 2];
            for (end, (c, other)) in [(ge.a, ge.b), (ge.b, ge.a)].into_iter().enumerate() {
                let k = side_towards(grid, c as usize, ge.midpoint);
                let c = c as usize;
                assert_eq!(edge[c][k], u32::MAX, "cell {c}: two edges on side {k}");
                (neighbour[c][k], edge[c][k], is_a[c][k]) = (other, e as u32, end == 0);
                sides[end] = k as u8;
            }
            if e >= layout.first_seam_edge() {
                seams.a.push(ge.a);
                seams.b.push(ge.b);
                seams.sides.push(sides);
            }
        }
        let mut sides = Self {
            layout,
            neighbour,
            edge,
            is_a,
            cell_runs: Vec::new(),
            rim_cells: Vec::new(),
            rim_tables: RimTables::default(),
            edge_runs: Vec::new(),
            seam_tables: seams,
            pads: Vec::new(),
            pad_signs: Vec::new(),
            rim_seam_sides: Vec::new(),
            rim_seam_copies: Vec::new(),
            rim_rows: Vec::new(),
        };
        (sides.cell_runs, sides.rim_cells) = sides.find_cell_runs();
        sides.rim_tables = sides.rim_tables(grid);
        sides.edge_runs = face_edge_runs(grid);
        sides.seams_on_the_rim();
        sides
    }

    /// The tables that place the seam edges among the rim's cells: each seam's ends'
    /// places in the rim's order, each face's [`Pads`], the rim's [`RimSeamSide`]s; and
    /// where each face row's rim cells are.
    ///
    /// # Panics
    /// If a face's outer side is not on a seam, or its seam's edges do not all run the
    /// same way, or a seam's cell is not on the rim.
    fn seams_on_the_rim(&mut self) {
        let (n, first_seam) = (self.n(), self.layout.first_seam_edge());
        let mut place = vec![u32::MAX; self.neighbour.len()];
        for (i, &c) in self.rim_cells.iter().enumerate() {
            place[c as usize] = i as u32;
        }
        let t = &mut self.seam_tables;
        t.rim =
            t.a.iter()
                .zip(&t.b)
                .map(|(&a, &b)| [a, b].map(|c| place[c as usize]))
                .collect();
        assert!(
            t.rim.iter().flatten().all(|&r| r != u32::MAX),
            "a seam off the rim"
        );
        let mut pads = Vec::with_capacity(24 * n);
        for face in 0..6 {
            let outer = |side: usize, i: usize| match side {
                LEFT => i * n,
                RIGHT => i * n + n - 1,
                BOTTOM => i,
                _ => (n - 1) * n + i,
            };
            for side in [LEFT, RIGHT, BOTTOM, TOP] {
                let sign_of = |c: usize| self.inflow(c)[side] * INFLOW[side];
                let sign = sign_of(face * n * n + outer(side, 0));
                for i in 0..n {
                    let c = face * n * n + outer(side, i);
                    let e = self.edge[c][side] as usize;
                    assert!(e >= first_seam, "cell {c}: side {side} is not on a seam");
                    assert_eq!(sign_of(c), sign, "cell {c}: side {side} runs the other way");
                    pads.push((e - first_seam) as u32);
                }
                self.pad_signs.push(sign);
            }
        }
        self.pads = pads;
        let face_rim = &self.rim_cells[..self.rim_cells.len() / 6];
        self.rim_rows = (0..=n)
            .map(|y| face_rim.partition_point(|&c| (c as usize) < y * n) as u32)
            .collect();
        for (i, &c) in self.rim_cells.iter().enumerate() {
            for side in 0..4 {
                let c = c as usize;
                if self.edge[c][side] as usize >= first_seam {
                    let across = place[self.neighbour[c][side] as usize];
                    let (rim, side) = (i as u32, side as u8);
                    self.rim_seam_sides.push(RimSeamSide { rim, side, across });
                }
            }
        }
        let m = self.rim_cells.len() as u32;
        self.rim_seam_copies = (self.rim_seam_sides.iter())
            .map(|s| [u32::from(s.side) * m + s.rim, s.across])
            .collect();
    }

    /// The cells inside the faces as [`CellRun`]s, one a face row, and the rim's cells.
    fn find_cell_runs(&self) -> (Vec<CellRun>, Vec<u32>) {
        let n = self.n();
        let (mut runs, mut rim) = (Vec::new(), Vec::new());
        for face in 0..6 {
            for y in 0..n {
                let row = face * n * n + y * n;
                if y == 0 || y + 1 >= n || n < 3 {
                    rim.extend((row..row + n).map(|c| c as u32));
                    continue;
                }
                rim.push(row as u32);
                let c = row + 1;
                runs.push(CellRun {
                    start: c,
                    len: n - 2,
                    neighbour: self.neighbour[c].map(|j| j as usize),
                    edge: self.edge[c].map(|e| e as usize),
                });
                rim.push((row + n - 1) as u32);
            }
        }
        (runs, rim)
    }

    /// The rim cells' tables side by side ([`RimTables`]), their areas from `grid`.
    fn rim_tables(&self, grid: &CubeSphere) -> RimTables {
        let rim = &self.rim_cells;
        let at_rim = |cells: &[f64]| rim.iter().map(|&c| cells[c as usize]).collect();
        let side = |table: &[[u32; 4]], k: usize| -> Vec<u32> {
            rim.iter().map(|&c| table[c as usize][k]).collect()
        };
        RimTables {
            neighbour: std::array::from_fn(|k| side(&self.neighbour, k)),
            edge: std::array::from_fn(|k| side(&self.edge, k)),
            inflow: std::array::from_fn(|k| {
                rim.iter().map(|&c| self.inflow(c as usize)[k]).collect()
            }),
            inverse_area: at_rim(grid.inverse_areas_per_sr()),
        }
    }

    /// The rim cells and their tables as slices of one length ([`Rim`]).
    #[inline(always)]
    pub(crate) fn rim(&self) -> Rim<'_> {
        let (t, m) = (&self.rim_tables, self.rim_cells.len());
        let [n0, n1, n2, n3] = &t.neighbour;
        let [e0, e1, e2, e3] = &t.edge;
        let [s0, s1, s2, s3] = &t.inflow;
        Rim {
            cells: &self.rim_cells[..m],
            neighbour: [&n0[..m], &n1[..m], &n2[..m], &n3[..m]],
            edge: [&e0[..m], &e1[..m], &e2[..m], &e3[..m]],
            inflow: [&s0[..m], &s1[..m], &s2[..m], &s3[..m]],
            inverse_area: &t.inverse_area[..m],
        }
    }

    /// Each face's [`CellSpan`] (none where a face has no interior, `n < 3`).
    pub(crate) fn face_spans(&self) -> impl Iterator<Item = CellSpan> {
        let n = self.n();
        let len = (n * n).saturating_sub(2 * n + 2);
        let spans = (0..6).map(move |face| CellSpan {
            start: face * n * n + n + 1,
            len,
            n,
        });
        spans.filter(|span| span.len > 0)
    }

    /// Row `y`'s x-edges on face `face` as a run (`n − 1` of them).
    #[inline(always)]
    pub(crate) fn x_run(&self, face: usize, y: usize) -> EdgeRun {
        let n = self.n();
        let a = face * n * n + y * n;
        EdgeRun {
            start: face * n * (n - 1) + y * (n - 1),
            len: n - 1,
            a,
            b: a + 1,
            sides: [RIGHT, LEFT],
            face,
            on_face: y * (n - 1),
        }
    }

    /// The y-edges below rows `rows` (from row 1 on) on face `face` as a run (`n` a row:
    /// their `b` cells are the rows').
    #[inline(always)]
    pub(crate) fn y_run(&self, face: usize, rows: std::ops::Range<usize>) -> EdgeRun {
        let n = self.n();
        let below = rows.start - 1;
        let a = face * n * n + below * n;
        EdgeRun {
            start: 6 * n * (n - 1) + face * n * (n - 1) + below * n,
            len: rows.len() * n,
            a,
            b: a + n,
            sides: [TOP, BOTTOM],
            face,
            on_face: n * (n - 1) + below * n,
        }
    }

    /// Face row `y`'s rim cells' places among a face's ([`Self::rim_per_face`]): the
    /// whole of the first and last rows, the ends of the others.
    #[inline(always)]
    pub(crate) fn rim_of_row(&self, y: usize) -> std::ops::Range<usize> {
        self.rim_rows[y] as usize..self.rim_rows[y + 1] as usize
    }

    /// The seam edges around face `face` ([`Pads`]): on its cells' left sides (by row),
    /// right sides, bottom sides (by column) and top sides, `n` each.
    #[inline(always)]
    pub(crate) fn face_pads(&self, face: usize) -> [Pads<'_>; 4] {
        let n = self.n();
        let pads = &self.pads[4 * n * face..4 * n * (face + 1)];
        [0, 1, 2, 3].map(|k| Pads {
            seams: &pads[k * n..(k + 1) * n],
            sign: self.pad_signs[4 * face + k],
        })
    }

    /// How many rim cells each face has, `m`: face `f`'s are the places `f·m..(f + 1)·m`
    /// of [`Self::rim_cells`], and face 0's cell numbers are also every face's rim
    /// cells' places on their face (each face's rim lists its cells at the same places).
    pub(crate) fn rim_per_face(&self) -> usize {
        self.rim_cells.len() / 6
    }

    /// Every rim cell's sides on a seam ([`RimSeamSide`]): the tests' (the passes take
    /// [`Self::rim_seam_copies`]).
    #[cfg(test)]
    pub(crate) fn rim_seam_sides(&self) -> &[RimSeamSide] {
        &self.rim_seam_sides
    }

    /// [`Self::rim_seam_sides`] as flat places `[to, from]`: `to` the side's in a table
    /// of the rim's values side by side (`side·M + rim`, `M` the rim's cells), `from`
    /// the cell across's in the rim's order; a copy of a factor a side is then a load and
    /// a store, about 4 instructions (through the side's table first, 10).
    pub(crate) fn rim_seam_copies(&self) -> &[[u32; 2]] {
        &self.rim_seam_copies
    }

    /// The sign of each side's volume in cell `c`'s inflow (as [`INFLOW`] inside a face).
    pub(crate) fn inflow(&self, c: usize) -> [f64; 4] {
        self.is_a[c].map(|a| if a { -1.0 } else { 1.0 })
    }

    /// Cells along a face edge.
    pub(crate) fn n(&self) -> usize {
        self.layout.n
    }

    /// The seam edges as one block ([`Seams`]).
    #[inline(always)]
    pub(crate) fn seams(&self) -> Seams<'_> {
        let (t, len) = (&self.seam_tables, self.seam_tables.a.len());
        Seams {
            start: self.layout.first_seam_edge(),
            len,
            a: &t.a[..len],
            b: &t.b[..len],
            sides: &t.sides[..len],
            rim: &t.rim[..len],
        }
    }

    /// Runs `pass` on every edge run ([`Self::edge_runs`]: the seams are not among
    /// them, [`Self::seams`]), compiled for AVX2 where the
    /// processor has it (a `#[inline(always)]` closure is compiled so with it).
    #[inline(always)]
    pub(crate) fn for_each_edge_run(&self, mut pass: impl FnMut(EdgeRun)) {
        with_avx2(
            #[inline(always)]
            || {
                for &run in &self.edge_runs {
                    pass(run);
                }
            },
        )
    }
}

/// The edges inside the faces as [`EdgeRun`]s: each face row's x-edges, then that
/// face's y-edges, face by face.
///
/// Why face by face: an edge pass reads its cells' values at both ends, and in the
/// grid's edge order (every face's x-edges, then every face's y-edges) it read each
/// cell field twice from beyond L2 (0.2 MB a field at n = 64); a face's y-edges right
/// after its x-edges find the face's cells (32 KB a field) still in L2.
fn face_edge_runs(grid: &CubeSphere) -> Vec<EdgeRun> {
    let layout = grid.layout();
    let n = layout.n;
    let mut runs = Vec::new();
    for face in 0..6 {
        for y in 0..n {
            let a = face * n * n + y * n;
            let start = face * n * (n - 1) + y * (n - 1);
            let sides = [RIGHT, LEFT];
            runs.push(EdgeRun {
                start,
                len: n - 1,
                a,
                b: a + 1,
                sides,
                face,
                on_face: y * (n - 1),
            });
        }
        let a = face * n * n;
        let start = 6 * n * (n - 1) + face * n * (n - 1);
        let sides = [TOP, BOTTOM];
        runs.push(EdgeRun {
            start,
            len: n * (n - 1),
            a,
            b: a + n,
            sides,
            face,
            on_face: n * (n - 1),
        });
    }
    runs.retain(|r| r.len > 0);
    runs
}

/// The side of cell `c` that the direction `towards` (an edge midpoint) lies beyond, in
/// the face's own coordinates.
fn side_towards(grid: &CubeSphere, c: usize, towards: glam::DVec3) -> usize {
    let n = grid.face_size();
    let (major, su, tv) = FACE_BASES[c / (n * n)];
    let (major, su, tv) = (major.as_dvec3(), su.as_dvec3(), tv.as_dvec3());
    let local = |d: glam::DVec3| glam::DVec2::new(d.dot(su), d.dot(tv)) / d.dot(major);
    let offset = local(towards) - local(grid.centres()[c]);
    if offset.x.abs() > offset.y.abs() {
        if offset.x < 0.0 { LEFT } else { RIGHT }
    } else if offset.y < 0.0 {
        BOTTOM
    } else {
        TOP
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A padded x-run is one edge longer, its first `n − 1` edges and ends the run's,
    /// the extra one the next x-edge between the row's last cell and the next one; not
    /// on the field's last row, nor a y-run, nor where its values' place has no room.
    #[test]
    fn a_padded_x_run_takes_the_next_edge_where_it_can() {
        let n = 5;
        let sides = CellSides::new(&CubeSphere::new(n));
        let cells = 6 * n * n;
        for (face, y) in [(0, 0), (2, 3), (5, n - 2)] {
            let run = sides.x_run(face, y);
            let padded = run.padded(n, cells);
            assert_eq!(padded.len, n, "face {face} row {y}");
            assert_eq!(
                (padded.start, padded.a, padded.b),
                (run.start, run.a, run.b)
            );
            assert_eq!(
                padded.b + n - 1,
                face * n * n + (y + 1) * n,
                "the next row's first"
            );
        }
        let last = sides.x_run(5, n - 1);
        assert_eq!(last.padded(n, cells).len, n - 1, "the field's last row");
        assert_eq!(sides.x_run(1, 2).padded(n - 1, cells).len, n - 1, "no room");
        let below = sides.y_run(1, 1..3);
        assert_eq!(below.padded(4 * n, cells).len, below.len, "a y-run");
    }

    #[test]
    fn inside_a_face_the_sides_sit_at_the_layouts_offsets() {
        for n in [1, 3, 8] {
            let grid = CubeSphere::new(n);
            let sides = CellSides::new(&grid);
            let layout = grid.layout();
            for c in 0..grid.cells() {
                assert!(sides.edge[c].iter().all(|&e| e != u32::MAX), "cell {c}");
                let (x, y) = (c % n, (c / n) % n);
                if x >= 1 {
                    assert_eq!(sides.edge[c][LEFT] as usize, layout.x_edge_of_cell(c));
                    assert_eq!(sides.neighbour[c][LEFT] as usize, c - 1);
                }
                if x + 1 < n {
                    assert_eq!(sides.edge[c][RIGHT] as usize, layout.x_edge_of_cell(c + 1));
                }
                if y >= 1 {
                    assert_eq!(sides.edge[c][BOTTOM] as usize, layout.y_edge_of_cell(c));
                    assert_eq!(sides.neighbour[c][BOTTOM] as usize, c - n);
                }
                if y + 1 < n {
                    assert_eq!(sides.edge[c][TOP] as usize, layout.y_edge_of_cell(c + n));
                }
                if x >= 1 && y >= 1 && x + 1 < n && y + 1 < n {
                    assert_eq!(sides.inflow(c), INFLOW, "cell {c}");
                }
            }
            assert_eq!(sides.seams().len, 12 * n);
            assert_eq!(sides.seams().start, layout.first_seam_edge());
            runs_cover_everything_once(&grid, &sides);
            spans_hold_every_inside_cell_with_its_neighbours(&sides);
        }
    }

    /// The rim's tables: each face row's rim cells (the whole first and last rows, the
    /// ends of the others) at the places `rim_of_row` gives, every face alike; each seam's
    /// ends' places; each pad's seam edge on its face's outer side, its sign the cell's
    /// inflow's against the inside's; each rim cell's sides on a seam and the cell across.
    #[test]
    fn the_rims_tables_place_its_cells_and_seams() {
        for n in [1, 2, 3, 8] {
            let grid = CubeSphere::new(n);
            let sides = CellSides::new(&grid);
            let m = sides.rim_per_face();
            for face in 0..6 {
                for y in 0..n {
                    let xs: Vec<usize> = if y == 0 || y + 1 == n {
                        (0..n).collect()
                    } else {
                        vec![0, n - 1]
                    };
                    let at = sides.rim_of_row(y);
                    let cells = &sides.rim_cells[face * m + at.start..face * m + at.end];
                    let want: Vec<u32> = xs
                        .iter()
                        .map(|x| (face * n * n + y * n + x) as u32)
                        .collect();
                    assert_eq!(cells, &want[..], "n = {n}, face {face}, row {y}");
                }
                let first_seam = sides.layout.first_seam_edge();
                let [left, right, bottom, top] = sides.face_pads(face);
                for i in 0..n {
                    let outer = [
                        (left, i * n, LEFT),
                        (right, i * n + n - 1, RIGHT),
                        (bottom, i, BOTTOM),
                        (top, (n - 1) * n + i, TOP),
                    ];
                    for (pads, c, k) in outer {
                        let c = face * n * n + c;
                        let seam = pads.seams[i] as usize;
                        assert_eq!(seam + first_seam, sides.edge[c][k] as usize);
                        assert_eq!(pads.sign, sides.inflow(c)[k] * INFLOW[k], "cell {c}");
                    }
                }
            }
            let seams = sides.seams();
            for i in 0..seams.len {
                let places = seams.rim_ends(i).map(|p| sides.rim_cells[p] as usize);
                assert_eq!(places, seams.cells(i), "n = {n}, seam {i}");
            }
            let first_seam = sides.layout.first_seam_edge();
            let on_seam = |c: &u32| {
                sides.edge[*c as usize]
                    .iter()
                    .filter(|&&e| e as usize >= first_seam)
                    .count()
            };
            let on_seams: usize = sides.rim_cells.iter().map(on_seam).sum();
            assert_eq!(sides.rim_seam_sides().len(), on_seams, "n = {n}");
            for s in sides.rim_seam_sides() {
                let (c, k) = (
                    sides.rim_cells[s.rim as usize] as usize,
                    usize::from(s.side),
                );
                let across = sides.rim_cells[s.across as usize];
                assert_eq!(sides.neighbour[c][k], across, "n = {n}, cell {c} side {k}");
            }
            let m = sides.rim_cells.len();
            let copies = sides.rim_seam_sides().iter().map(|s| {
                [usize::from(s.side) * m + s.rim as usize, s.across as usize].map(|p| p as u32)
            });
            assert!(
                copies.eq(sides.rim_seam_copies().iter().copied()),
                "n = {n}"
            );
        }
    }

    /// Every cell of a row run lies in a face span, with the neighbours the span gives it
    /// its own, and whatever else a span holds is on the rim.
    fn spans_hold_every_inside_cell_with_its_neighbours(sides: &CellSides) {
        let spans: Vec<CellSpan> = sides.face_spans().collect();
        let mut inside = 0;
        for span in &spans {
            for (i, c) in span.cells().enumerate() {
                let in_run = sides.cell_runs.iter().any(|r| r.cells().contains(&c));
                if !in_run {
                    assert!(sides.rim_cells.contains(&(c as u32)), "cell {c}");
                    continue;
                }
                inside += 1;
                for k in 0..4 {
                    let nb = span.neighbours(k).start + i;
                    assert_eq!(nb, sides.neighbour[c][k] as usize, "cell {c} side {k}");
                }
            }
        }
        let runs: usize = sides.cell_runs.iter().map(|r| r.len).sum();
        assert_eq!(inside, runs);
    }

    /// Every cell lies in exactly one run or on the rim, every edge inside a face in
    /// exactly one run, and what a run says of its members' sides and ends is what the
    /// tables say.
    fn runs_cover_everything_once(grid: &CubeSphere, sides: &CellSides) {
        let mut cells: Vec<usize> = sides.cell_runs.iter().flat_map(|r| r.cells()).collect();
        cells.extend(sides.rim_cells.iter().map(|&c| c as usize));
        cells.sort_unstable();
        assert_eq!(cells, (0..grid.cells()).collect::<Vec<_>>());
        for run in &sides.cell_runs {
            for (i, c) in run.cells().enumerate() {
                for k in 0..4 {
                    assert_eq!(run.neighbour[k] + i, sides.neighbour[c][k] as usize);
                    assert_eq!(run.edge[k] + i, sides.edge[c][k] as usize);
                }
                assert_eq!(sides.inflow(c), INFLOW, "cell {c}");
            }
        }
        let mut edges: Vec<usize> = sides.edge_runs.iter().flat_map(|r| r.edges()).collect();
        let seams = sides.seams();
        edges.extend(seams.start..seams.start + seams.len);
        edges.sort_unstable();
        assert_eq!(edges, (0..grid.edges().len()).collect::<Vec<_>>());
        let ea = grid.edge_arrays();
        for i in 0..seams.len {
            let e = seams.start + i;
            let [a, b] = seams.cells(i);
            assert_eq!(ea.cells[e], [a as u32, b as u32], "seam edge {e}");
            let [ka, kb] = seams.sides(i);
            assert_eq!(sides.edge[a][ka] as usize, e, "seam edge {e}: side of a");
            assert_eq!(sides.edge[b][kb] as usize, e, "seam edge {e}: side of b");
        }
        for run in &sides.edge_runs {
            let place = (run.face, run.on_face);
            assert_eq!(
                grid.layout().on_face(run.start),
                place,
                "run at {}",
                run.start
            );
            for (i, e) in run.edges().enumerate() {
                assert_eq!(
                    ea.cells[e],
                    [(run.a + i) as u32, (run.b + i) as u32],
                    "edge {e}"
                );
                let [ka, kb] = run.sides;
                assert_eq!(sides.edge[run.a + i][ka] as usize, e, "edge {e}: side of a");
                assert_eq!(sides.edge[run.b + i][kb] as usize, e, "edge {e}: side of b");
            }
        }
    }
}
