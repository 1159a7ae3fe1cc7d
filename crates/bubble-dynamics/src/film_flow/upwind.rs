//! The passes of one thickness-transport sub-step ([`super::transport`]), cell by cell
//! and edge by edge in the face-structured layout: inside a face each pass reads its
//! neighbours and edges as slices, which vectorise; the cells on a face's rim and the
//! seam edges take the same arithmetic through [`CellSides`]' tables.
//!
//! The sub-step is one limited apply ([`super::fluxes::apply_limited`]) of the
//! [`Volumes`], which it takes row by row:
//! 1. first the rim's limited rises ([`rim_rises`]: each cell's rise to each side's
//!    midpoint, its Green–Gauss gradient in its tangent plane dotted with the reach,
//!    Barth–Jespersen limited) and the seams' volumes;
//! 2. then, row by row on all the faces together, the row's limited rises
//!    ([`band_rises`], a band of rows at a time) and its edges' volumes, each part
//!    upwind along its own characteristic, which the rows' cells gather a row or two
//!    behind (each donor's factor that keeps its outflow within its budget, each cell's
//!    gathered volumes).
//!
//! Why by rows: the rises were four per-cell arrays (0.8 MB at n = 64) and the volumes a
//! per-edge one (0.4 MB), each written out and read back from beyond the core's 1 MB L2;
//! a face row's are 2.5 KB, and six faces' rows read one row of face 0's weights
//! (8 KB of the 0.5 MB) while it is in L1.

use std::ops::Range;

use super::capillary::Term;
use super::compare::{larger, smaller};
use super::face_geometry::FaceGeometry;
use super::fluxes::{BAND, EdgeValues};
use super::grid::CubeSphere;
use super::sides::{CellSides, EdgeBlock, EdgeRun, RIGHT, SeamEnds, Seams};
use super::transport::{Drain, Fastest, edge_speed};

/// The transport's weights, fixed by the grid: face 0's, which every face reads.
///
/// Why face 0's serve every face: the grid is symmetric under the cube's rotations and
/// the weights are taken side by side in each face's own directions, so every face's are
/// face 0's to rounding (within 3e-14 of the largest at n = 1, 5, 16 and 64:
/// `tests::every_faces_rise_weights_are_face_0s`; [`super::face_geometry`]). Six faces'
/// were 3.1 MB at n = 64, streamed from beyond the core's 1 MB L2 in every sub-step;
/// one face's are 0.5 MB.
#[derive(Clone, Debug)]
pub(crate) struct UpwindGeometry {
    /// `rise[k][j][c]`: the weight of `h_c + h_j` (`j` the cell across side `j`) in the
    /// rise of cell `c`'s thickness to the midpoint of its side `k`: the Green–Gauss
    /// gradient `Σ ± n l (h_c + h_j)/2 / A`, projected onto the cell's tangent plane and
    /// dotted with the reach `midpoint − centre`, is linear in the face values, so one
    /// weight per pair of sides stands for the gradient's three components and its
    /// projection. Face 0's cells', `n²` ([`super::sides::CellSpan::on_face`]).
    rise: [[Vec<f64>; 4]; 4],
    /// The same weights of face 0's rim cells in the rim's order
    /// ([`CellSides::rim_cells`]; every face's rim lists its cells at the same places),
    /// so that the rim's rises run on slices like the faces' (its cells' values gathered
    /// first, [`RimRises`]).
    rim_rise: [[Vec<f64>; 4]; 4],
}

/// The rim's thicknesses and rises in the rim's order ([`rim_rises`]).
#[derive(Clone, Debug, Default)]
pub(crate) struct RimRises {
    /// A face's rim cells' thicknesses.
    own: Vec<f64>,
    /// Per side: their neighbours'.
    neighbour: [Vec<f64>; 4],
    /// Per side: their limited rises.
    rise: [Vec<f64>; 4],
}

impl UpwindGeometry {
    /// Derives the weights from `grid` and its cells' `sides`.
    pub(crate) fn new(grid: &CubeSphere, sides: &CellSides) -> Self {
        Self::with_faces(grid, sides, 1)
    }

    /// [`Self::new`], with the weights of the first `faces` faces (one is all the
    /// transport reads; the tests take six to compare them).
    fn with_faces(grid: &CubeSphere, sides: &CellSides, faces: usize) -> Self {
        let ea = grid.edge_arrays();
        let n = grid.face_size();
        let cells = faces * n * n;
        let mut rise: [[Vec<f64>; 4]; 4] =
            std::array::from_fn(|_| std::array::from_fn(|_| vec![0.0; cells]));
        let inverse_areas = grid.inverse_areas_per_sr();
        for (c, centre) in grid.centres()[..cells].iter().enumerate() {
            let side_edge = |k: usize| sides.edge[c][k] as usize;
            let outward = |k: usize| if sides.is_a[c][k] { 1.0 } else { -1.0 };
            for (k, rise_k) in rise.iter_mut().enumerate() {
                let reach = ea.reach[side_edge(k)][usize::from(!sides.is_a[c][k])];
                let reach = reach - *centre * centre.dot(reach);
                for (j, rise_kj) in rise_k.iter_mut().enumerate() {
                    let e = side_edge(j);
                    let gradient = ea.normal[e] * (outward(j) * 0.5 * ea.length[e]);
                    rise_kj[c] = gradient.dot(reach) * inverse_areas[c];
                }
            }
        }
        let rim_cells = &sides.rim_cells[..sides.rim_cells.len() / 6 * faces];
        let rim = |w: &Vec<f64>| rim_cells.iter().map(|&c| w[c as usize]).collect();
        let rim_rise = std::array::from_fn(|k| std::array::from_fn(|j| rim(&rise[k][j])));
        Self { rise, rim_rise }
    }
}

/// The Barth–Jespersen factor of a cell of thickness `h` with neighbours `nb` and rises
/// `rise` to its sides' midpoints.
///
/// Barth–Jespersen: one factor for all four, the largest that carries the cell's
/// thickness to no side's midpoint outside the range of the cell and its neighbours.
/// Why: the edge's own clamp (between the two cells' values) let a thin cell beside a
/// pool tens of µm thick take a face value near the pool's, since the unlimited gradient
/// leans on the pool; its outflow, above all the drainage's `c·h³`, was then hundreds of
/// times its content, and film beside the pooled bottom of a bubble resting on the ground
/// emptied to under a nanometre and burst within a second.
///
/// The factor is `min(1, (hi − h)/(largest rise), (lo − h)/(most negative rise))`: the
/// least of the four sides' `min(1, room/rise)`, for one division where each side took
/// one. Why one: a vector division takes the divider several cycles, and two a cell
/// could keep the rises' loop waiting on it; the two ways' fractions are ordered by a
/// cross-multiplication, which orders them as their quotients do but where they lie
/// within a few units in the last place of each other (the factor then one unit off,
/// `tests::the_limiter_is_the_plain_least_room_over_rise`; `film_state_hash` kept its
/// bits at n = 32 and at `64 40`).
#[inline(always)]
fn limiter(h: f64, nb: [f64; 4], rise: [f64; 4]) -> f64 {
    let lo = smaller(smaller(smaller(nb[0], nb[1]), smaller(nb[2], nb[3])), h);
    let hi = larger(larger(larger(nb[0], nb[1]), larger(nb[2], nb[3])), h);
    let up = larger(
        larger(rise[0], rise[1]),
        larger(larger(rise[2], rise[3]), 0.0),
    );
    let down = smaller(
        smaller(rise[0], rise[1]),
        smaller(smaller(rise[2], rise[3]), 0.0),
    );
    // Each side's `room/rise` as a fraction of two numbers ≥ 0 (1/1 where nothing rises
    // that way); the smaller by a cross-multiplication, then one division where there
    // were two: `(lo − h)/down` is `(h − lo)/(−down)` exactly.
    //
    // Where nothing rises a way, not 1/1 but a fraction that gives the same bits with
    // fewer blends (`tests::the_limiter_is_the_plain_least_room_over_rise`):
    // - up, `(hi − h)/0` (`up` is then +0, never NaN): the comparison below never takes
    //   it (`≥ 0 < +0` fails), where 1/1 was taken only with the down fraction above 1,
    //   whose quotient is then ≥ 1 and the factor 1 all the same (a compare and two
    //   blends a vector fewer);
    // - down, `1/0` (`0 − down` is +0, where `−down` is −0): the up fraction is then
    //   taken wherever something rises, whose factor is its quotient where it is below 1
    //   (as when 1/1 was taken over it) and 1 elsewhere; where nothing rises either way,
    //   `1/0` is taken and the factor is 1 (a blend a vector fewer). Its room `h − lo`
    //   would not do: at a cell that is its neighbours' lowest, `0/0` would be taken
    //   over the up fraction (the comparison's tie goes to down).
    let (up_room, up_rise) = (hi - h, up);
    let down_room = if down < 0.0 { h - lo } else { 1.0 };
    let down_rise = 0.0 - down;
    let up_first = up_room * down_rise < down_room * up_rise;
    let (room, rise) = if up_first {
        (up_room, up_rise)
    } else {
        (down_room, down_rise)
    };
    // No maximum with 0: `room` is `hi − h`, `h − lo` or 1, ≥ +0 (`hi` and `lo` take `h`
    // in), and `rise` ≥ +0, so the quotient is ≥ +0 or NaN, which the minimum makes 1.
    smaller(room / rise, 1.0)
}

/// The limited rises: the rim's, kept for the sub-step (the seams' volumes read them),
/// and a face's band's, taken just before the band's volumes.
#[derive(Clone, Debug, Default)]
pub(crate) struct Rises {
    /// Per side `k`, a window of [`WINDOW`] rows of `n`: the band's rows' cells' rises
    /// to that side and the row's before, window row `w` for face row `first − 1 + w`,
    /// at `(k·WINDOW + w)·n`, m. One window serves the six faces in turn.
    rows: Vec<f64>,
    /// Per face: its band's last row's rises (`4·n`, side by side), the row before its
    /// next band.
    carried: [Vec<f64>; 6],
    /// The band's first row.
    first: usize,
    /// The rim's ([`RimRises`]).
    rim: RimRises,
}

/// Rows in the window of rises ([`Rises`]): a band's and the row before (the y-edges
/// below the band's first row read it).
const WINDOW: usize = BAND + 1;

impl Rises {
    /// Where row `y`'s cells' rises to side `k` start in `rows`.
    #[inline(always)]
    fn at(&self, n: usize, k: usize, y: usize) -> usize {
        (k * WINDOW + y + 1 - self.first) * n
    }
}

/// Every rim cell's limited rise to each side, into `rim_rises.rise[k]` in the rim's
/// order ([`CellSides::rim_cells`]), m: a face's rim at a time, its cells' values
/// gathered into buffers of a face's rim, the arithmetic on slices.
///
/// Why a face at a time: the gathered values of the whole rim were 60 KB at n = 64,
/// written cold every step; a face's stay in L1 from one face to the next.
// Inlined into the sub-step's `with_avx2` closure, so compiled for AVX2 there.
#[inline(always)]
fn rim_rises(sides: &CellSides, geo: &UpwindGeometry, h: &[f64], rim_rises: &mut RimRises) {
    let rim = sides.rim();
    let m = rim.cells.len();
    let RimRises {
        own,
        neighbour,
        rise,
    } = rim_rises;
    for r in rise.iter_mut() {
        r.resize(m, 0.0);
    }
    // Each with face 0's weights.
    let per_face = m / 6;
    let w = geo
        .rim_rise
        .each_ref()
        .map(|w| w.each_ref().map(|w| &w[..per_face]));
    for face in 0..6 {
        let at = face * per_face..(face + 1) * per_face;
        rim.gather_cells(h, at.clone(), own);
        rim.gather_neighbours(h, at.clone(), neighbour);
        let nb = neighbour.each_ref().map(|x| &x[..per_face]);
        let out = rise.each_mut().map(|r| &mut r[at.clone()]);
        rises_run(w, &own[..per_face], nb, out);
    }
}

/// Face `face`'s band `band`'s cells' limited rises to each side, into `rises`' window
/// (the row before from the face's band before), m: the inside rows in one run, their
/// end cells among the run's (their neighbours there are not theirs) then taken from the
/// rim's, as the first and last rows'.
// Inlined into the sub-step's `with_avx2` closure, so compiled for AVX2 there.
#[inline(always)]
fn band_rises(
    (sides, geo): (&CellSides, &UpwindGeometry),
    h: &[f64],
    (face, band): (usize, Range<usize>),
    rises: &mut Rises,
) {
    let n = sides.n();
    let Rises {
        rows,
        carried,
        first,
        rim,
    } = rises;
    rows.resize(4 * WINDOW * n, 0.0);
    let carried = &mut carried[face];
    let (o0, rest) = rows.split_at_mut(WINDOW * n);
    let (o1, rest) = rest.split_at_mut(WINDOW * n);
    let (o2, o3) = rest.split_at_mut(WINDOW * n);
    if band.start > 0 {
        for (o, c) in [&mut *o0, &mut *o1, &mut *o2, &mut *o3]
            .into_iter()
            .zip(carried.chunks_exact(n))
        {
            o[..n].copy_from_slice(c);
        }
    }
    *first = band.start;
    let w = |y: usize| (y + 1 - band.start) * n;
    let inside = band.start.max(1)..band.end.min(n.saturating_sub(1));
    if !inside.is_empty() {
        let cells = inside.start * n..inside.end * n;
        let first = face * n * n + cells.start;
        let len = cells.len();
        let w_kj = |k: usize, j: usize| &geo.rise[k][j][cells.clone()];
        let weights = [0, 1, 2, 3].map(|k| [w_kj(k, 0), w_kj(k, 1), w_kj(k, 2), w_kj(k, 3)]);
        let nb = [first - 1, first + 1, first - n, first + n].map(|c| &h[c..c + len]);
        let at = w(inside.start)..w(inside.start) + len;
        let out = [
            &mut o0[at.clone()],
            &mut o1[at.clone()],
            &mut o2[at.clone()],
            &mut o3[at],
        ];
        rises_run(weights, &h[first..first + len], nb, out);
    }
    // Face 0's rim cells are every face's places ([`CellSides::rim_per_face`]): a row's
    // are the whole row or its two ends ([`CellSides::rim_of_row`]), copied as such
    // (cell by cell through the rim's table, they took 30 instructions a cell), the
    // inside rows' ends a side at a time in one loop over the rows (row by row, each
    // row's slices set up four times, about 17 instructions a row more).
    let m = sides.rim_per_face();
    let outs = [&mut *o0, &mut *o1, &mut *o2, &mut *o3];
    if !inside.is_empty() {
        let (at, x) = (
            face * m + sides.rim_of_row(inside.start).start,
            w(inside.start),
        );
        let len = inside.len();
        for (o, r) in outs.into_iter().zip(&rim.rise) {
            let rows = o[x..x + len * n].chunks_exact_mut(n);
            for (o, r) in rows.zip(r[at..at + 2 * len].chunks_exact(2)) {
                (o[0], o[n - 1]) = (r[0], r[1]);
            }
        }
    }
    for y in band.clone().filter(|&y| y == 0 || y + 1 >= n) {
        let (at, x) = (face * m + sides.rim_of_row(y).start, w(y));
        for (o, r) in [&mut *o0, &mut *o1, &mut *o2, &mut *o3]
            .into_iter()
            .zip(&rim.rise)
        {
            o[x..x + n].copy_from_slice(&r[at..at + n]);
        }
    }
    if band.end < n {
        // The band's last row, the row before the next band.
        let last = w(band.end - 1);
        carried.clear();
        for o in [&*o0, &*o1, &*o2, &*o3] {
            carried.extend_from_slice(&o[last..last + n]);
        }
    }
}

/// A cell's rise to one side from that side's weights `w`, its thickness `h` and its
/// neighbours' `nb`: `Σ_j w_j (h + h_j)`.
#[inline(always)]
fn rise_of(w: [f64; 4], h: f64, nb: [f64; 4]) -> f64 {
    (w[0] * (h + nb[0]) + w[1] * (h + nb[1])) + (w[2] * (h + nb[2]) + w[3] * (h + nb[3]))
}

/// The limited rises of a stretch of cells from their weights `w[k][j]`, thicknesses
/// `centre` and neighbours' `nb`, as slices: two sides' rises in a loop of their own,
/// then the other two's with the limit (one loop over all sixteen weights kept the
/// compiler from vectorising it: it spilled them to the stack cell by cell; a loop a
/// side took each cell's four sums `h + h_j` four times where two sides share them; the
/// limit in a loop of its own stored the last two sides' rises and read them back, with
/// the thicknesses, about 3 instructions a cell more).
#[inline(always)]
fn rises_run(w: [[&[f64]; 4]; 4], centre: &[f64], nb: [&[f64]; 4], out: [&mut [f64]; 4]) {
    let len = centre.len();
    let [w0, w1, w2, w3] = w;
    let [o0, o1, o2, o3] = out;
    rise_pair([w0, w1], centre, nb, [&mut *o0, &mut *o1]);
    let (o0, o1, o2, o3) = (
        &mut o0[..len],
        &mut o1[..len],
        &mut o2[..len],
        &mut o3[..len],
    );
    let [a, b] = [w2, w3].map(|w| w.map(|w| &w[..len]));
    let [l, r, d, u] = nb.map(|x| &x[..len]);
    for i in 0..len {
        let (h, nb) = (centre[i], [l[i], r[i], d[i], u[i]]);
        let r2 = rise_of([a[0][i], a[1][i], a[2][i], a[3][i]], h, nb);
        let r3 = rise_of([b[0][i], b[1][i], b[2][i], b[3][i]], h, nb);
        let rise = [o0[i], o1[i], r2, r3];
        let phi = limiter(h, nb, rise);
        (o0[i], o1[i], o2[i], o3[i]) = (rise[0] * phi, rise[1] * phi, rise[2] * phi, rise[3] * phi);
    }
}

/// Two sides' rises over a run ([`rise_of`]), from their weights `w` (per side, per
/// neighbour), into `out` (per side).
#[inline(always)]
fn rise_pair(w: [[&[f64]; 4]; 2], h: &[f64], nb: [&[f64]; 4], out: [&mut [f64]; 2]) {
    let len = h.len();
    let [a, b] = w.map(|w| w.map(|w| &w[..len]));
    let [oa, ob] = out;
    let (oa, ob) = (&mut oa[..len], &mut ob[..len]);
    let (l, r, d, u) = (&nb[0][..len], &nb[1][..len], &nb[2][..len], &nb[3][..len]);
    for i in 0..len {
        let nb = [l[i], r[i], d[i], u[i]];
        oa[i] = rise_of([a[0][i], a[1][i], a[2][i], a[3][i]], h[i], nb);
        ob[i] = rise_of([b[0][i], b[1][i], b[2][i], b[3][i]], h[i], nb);
    }
}

/// What moves liquid across the edges: the surfaces' speed, the drainage's coefficient
/// and the step over the radius.
#[derive(Clone, Copy)]
pub(crate) struct EdgeSpeeds<'a> {
    /// Per edge: the surfaces' speed, m/s.
    pub(crate) u: &'a [f64],
    /// The drainage ([`Drain`]: its coefficient over `h²` from each edge's normal).
    pub(crate) drain: Drain,
    /// The sub-step over the sphere's radius, s/m.
    pub(crate) dt_per_r: f64,
}

/// The volume per R² (m × sr) across an edge from cell `a` (thickness `ha`, limited rise
/// `ra` towards the edge) to `b`, at surface speed `u`, drainage coefficient `c` and
/// length `l`, over `dt_per_r`.
///
/// Each part upwind along its own characteristic: the surfaces carry h at u, the drainage
/// flux c·h³ travels at 3c·h², the sign of c. One upwind choice by the sign of the summed
/// speed runs downwind wherever the surfaces move up against a film that drains down, and
/// grew odd-even stripes there.
#[inline(always)]
fn edge_volume([ha, hb]: [f64; 2], [ra, rb]: [f64; 2], [u, c, l]: [f64; 3], dt_per_r: f64) -> f64 {
    let (lo, hi) = if hb < ha { (hb, ha) } else { (ha, hb) };
    // The clamp as a maximum then a minimum, `lo` and `hi` first, which give `x` where
    // the comparison fails (NaN too): exactly `if x < lo { lo } else if x > hi { hi }
    // else { x }` (`lo ≤ hi` or one NaN), one instruction each where the nested choice
    // took five (`clamp` tests for NaN and its bounds' order).
    let clamped = |x: f64| smaller(hi, larger(lo, x));
    let (face_a, face_b) = (clamped(ha + ra), clamped(hb + rb));
    let plug = if u >= 0.0 { face_a } else { face_b };
    let drain = if c >= 0.0 { face_a } else { face_b };
    (u * plug + c * drain * drain * drain) * l * dt_per_r
}

/// The volume across every edge over a sub-step, band by band ([`EdgeValues`]): the
/// rim's limited rises with the seams', a face's band's just before its runs'.
pub(crate) struct Volumes<'a> {
    /// The cells' sides.
    pub(crate) sides: &'a CellSides,
    /// The rises' weights.
    pub(crate) geo: &'a UpwindGeometry,
    /// The grid's constants.
    pub(crate) fg: &'a FaceGeometry,
    /// What moves the liquid.
    pub(crate) speeds: EdgeSpeeds<'a>,
    /// The limited rises.
    pub(crate) rises: &'a mut Rises,
    /// The seams' ends.
    pub(crate) seam_ends: &'a mut SeamEnds,
    /// Where the Courant number is taken alongside, its fastest edge so far.
    pub(crate) fastest: Option<&'a mut Fastest>,
    /// Where the capillary smoothing joins the sub-step, its volumes' term.
    pub(crate) capillary: Option<Term<'a>>,
}

impl EdgeValues for Volumes<'_> {
    #[inline(always)]
    fn seams(&mut self, seams: Seams, h: &[f64], out: &mut [f64]) {
        let rim = &mut self.rises.rim;
        rim_rises(self.sides, self.geo, h, rim);
        let [h_ends, rises] = self.seam_ends.gather_with_rim_sides(seams, h, &rim.rise);
        let fastest = self.fastest.as_deref_mut();
        let fastest = fastest.map(|f| (f, seams.len));
        volumes_block(seams, h_ends, rises, (self.fg, self.speeds), (out, fastest));
        if let Some(term) = &self.capillary {
            let [ha, hb] = h_ends;
            let (l, per_d) = (
                seams.constant(&self.fg.length),
                seams.constant(&self.fg.inverse_dual_length),
            );
            for i in 0..seams.len {
                let ends = seams.ends(i, term.laplacian);
                out[i] += term.volume([ha[i], hb[i]], ends, [l[i], per_d[i]]);
            }
        }
    }

    #[inline(always)]
    fn rows(&mut self, face: usize, band: Range<usize>, h: &[f64]) {
        band_rises((self.sides, self.geo), h, (face, band), self.rises);
    }

    #[inline(always)]
    fn run(&mut self, run: EdgeRun, rows: Range<usize>, h: &[f64], out: &mut [f64]) {
        let (n, [ka, kb]) = (self.sides.n(), run.sides);
        let r = &*self.rises;
        // A row's x-edges join its cells from the first on to those from the second;
        // the y-edges below rows, the rows below's cells to theirs.
        let (a, b) = if ka == RIGHT {
            (r.at(n, ka, rows.start), r.at(n, kb, rows.start) + 1)
        } else {
            (r.at(n, ka, rows.start - 1), r.at(n, kb, rows.start))
        };
        let (ra, rb) = (&r.rows[a..], &r.rows[b..]);
        let edges = run.len;
        let run = run.padded(out.len(), h.len());
        let (ha, hb) = run.ends(h);
        let fastest = self.fastest.as_deref_mut();
        volumes_block(
            run,
            [ha, hb],
            [ra, rb],
            (self.fg, self.speeds),
            (out, fastest.map(|f| (f, edges))),
        );
        if let Some(term) = &self.capillary {
            let (la, lb) = run.ends(term.laplacian);
            term.block::<true>(self.fg, run, [ha, hb, la, lb], out);
        }
    }
}

/// [`Volumes`] over a block of edges, with their ends' thicknesses and rises, into
/// `out`, and their characteristic speeds into `fastest` where it is taken, the first
/// `edges` of them (an [`EdgeRun::padded`] run's extra one's zeroed: the speeds are ≥ 0 and the
/// fastest starts at 0, so it changes no maximum).
///
/// Why the speeds here: a loop of their own read the velocities, thicknesses and normals
/// again and took each edge's drainage coefficient a second time (0.12 M instructions a
/// step at n = 64), where this loop has them in registers.
#[inline(always)]
fn volumes_block(
    block: impl EdgeBlock,
    ends: [&[f64]; 2],
    rises: [&[f64]; 2],
    (fg, speeds): (&FaceGeometry, EdgeSpeeds),
    (out, fastest): (&mut [f64], Option<(&mut Fastest, usize)>),
) {
    let all = (block, ends, rises);
    match fastest {
        None => volumes_loop::<false>(all, (fg, speeds), out, &mut []),
        Some((fastest, edges)) => fastest.take(
            block.count(),
            #[inline(always)]
            |speed| {
                volumes_loop::<true>(all, (fg, speeds), out, speed);
                // One at most ([`EdgeRun::padded`]); as a store, not a fill (a call to memset).
                debug_assert!(speed.len() <= edges + 1);
                if let Some(extra) = speed.get_mut(edges) {
                    *extra = 0.0;
                }
            },
        ),
    }
}

/// [`volumes_block`]'s loop: the volumes into `out`, and where `COURANT` the edges'
/// [`edge_speed`]s into `speed` (`block.count()` long then), each from the same
/// drainage coefficient.
#[inline(always)]
fn volumes_loop<const COURANT: bool>(
    (block, [ha, hb], [ra, rb]): (impl EdgeBlock, [&[f64]; 2], [&[f64]; 2]),
    (fg, speeds): (&FaceGeometry, EdgeSpeeds),
    out: &mut [f64],
    speed: &mut [f64],
) {
    let len = block.count();
    let (u, c) = (block.values(speeds.u), speeds.drain.along(&block, fg));
    let (l, out) = (block.constant(&fg.length), &mut out[..len]);
    let (ha, hb, ra, rb) = (&ha[..len], &hb[..len], &ra[..len], &rb[..len]);
    let per_area = block.constant(&fg.length_per_smaller_area);
    let (per_area, speed) = if COURANT {
        (&per_area[..len], &mut speed[..len])
    } else {
        (&per_area[..0], &mut speed[..0])
    };
    for i in 0..len {
        let c = c.at(i);
        out[i] = edge_volume(
            [ha[i], hb[i]],
            [ra[i], rb[i]],
            [u[i], c, l[i]],
            speeds.dt_per_r,
        );
        if COURANT {
            speed[i] = edge_speed(u[i], c, ha[i], hb[i], per_area[i]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::film_flow::face_geometry::to_face_frame;
    use crate::film_flow::fluxes::{BAND, GatherScratch, net_inflow};
    use crate::film_flow::grid::dot_at;
    use glam::DVec3;

    /// An [`EdgeValues`] that keeps what another gives, by edge.
    struct Kept<'a, P> {
        /// The pass.
        pass: P,
        /// Its values by edge.
        values: &'a mut [f64],
    }

    impl<P: EdgeValues> EdgeValues for Kept<'_, P> {
        fn seams(&mut self, seams: Seams, cells: &[f64], out: &mut [f64]) {
            self.pass.seams(seams, cells, out);
            self.values[seams.start..seams.start + seams.len].copy_from_slice(out);
        }
        fn rows(&mut self, face: usize, rows: Range<usize>, cells: &[f64]) {
            self.pass.rows(face, rows, cells);
        }
        fn run(&mut self, run: EdgeRun, rows: Range<usize>, cells: &[f64], out: &mut [f64]) {
            self.pass.run(run, rows, cells, out);
            self.values[run.edges()].copy_from_slice(&out[..run.len]);
        }
    }

    /// The volumes taken band by band, each face's limited rises a band at a time and
    /// the rim's apart, against each edge's taken directly from every cell's limited
    /// rises (the same arithmetic, so the same bits): on grids of one band and of three,
    /// the last short, so that the rises carried from band to band are checked. The
    /// fastest edge taken alongside against the largest of every edge's [`edge_speed`].
    #[test]
    fn the_volumes_by_bands_are_each_edges_own() {
        for n in [5, 2 * BAND + 3] {
            let grid = CubeSphere::new(n);
            let sides = CellSides::new(&grid);
            let geo = UpwindGeometry::new(&grid, &sides);
            let (fg, ea, layout) = (grid.face_geometry(), grid.edge_arrays(), grid.layout());
            let c = grid.centres();
            let h: Vec<f64> = c
                .iter()
                .map(|c| 1.0 + 0.3 * (5.0 * c.x + 3.0 * c.y * c.z).sin())
                .collect();
            let u: Vec<f64> = (0..ea.cells.len())
                .map(|e| ((e * 37 % 23) as f64 - 11.0) * 0.01)
                .collect();
            let drain = Drain {
                drain: 0.02,
                g_eff: DVec3::new(0.3, -9.8, 0.5),
            };
            let speeds = EdgeSpeeds {
                u: &u,
                drain,
                dt_per_r: 0.4,
            };
            // Every cell's limited rises, directly.
            let rise = |cell: usize| -> [f64; 4] {
                let nb = sides.neighbour[cell].map(|j| h[j as usize]);
                let w = |k: usize, j: usize| geo.rise[k][j][cell % (n * n)];
                let r = [0, 1, 2, 3].map(|k| rise_of([0, 1, 2, 3].map(|j| w(k, j)), h[cell], nb));
                let phi = limiter(h[cell], nb, r);
                r.map(|r| r * phi)
            };
            let (mut want, mut want_fastest) = (vec![0.0; ea.cells.len()], 0.0_f64);
            for (e, [a, b]) in ea.cells.iter().enumerate() {
                let (a, b) = (*a as usize, *b as usize);
                let side = |cell: usize| {
                    sides.edge[cell]
                        .iter()
                        .position(|&x| x as usize == e)
                        .unwrap()
                };
                let (ra, rb) = (rise(a)[side(a)], rise(b)[side(b)]);
                let (l, c, per_area) = if e >= layout.first_seam_edge() {
                    let i = e - layout.first_seam_edge();
                    let normal = fg.normal.seams.each_ref().map(|x| &x[i..]);
                    let c = drain.drain * dot_at(drain.g_eff, normal, 0);
                    (fg.length.seams[i], c, fg.length_per_smaller_area.seams[i])
                } else {
                    let (face, i) = layout.on_face(e);
                    let normal = fg.normal.face.each_ref().map(|x| &x[i..]);
                    let g = to_face_frame(face, drain.g_eff);
                    let c = drain.drain * dot_at(g, normal, 0);
                    (fg.length.face[i], c, fg.length_per_smaller_area.face[i])
                };
                want[e] = edge_volume([h[a], h[b]], [ra, rb], [u[e], c, l], speeds.dt_per_r);
                want_fastest = want_fastest.max(edge_speed(u[e], c, h[a], h[b], per_area));
            }
            let mut got = vec![f64::NAN; ea.cells.len()];
            let (mut rises, mut seam_ends) = (Rises::default(), SeamEnds::default());
            let mut fastest = Fastest {
                speed: Vec::new(),
                fastest: 0.0,
            };
            let volumes = Volumes {
                sides: &sides,
                geo: &geo,
                fg,
                speeds,
                rises: &mut rises,
                seam_ends: &mut seam_ends,
                fastest: Some(&mut fastest),
                capillary: None,
            };
            let mut kept = Kept {
                pass: volumes,
                values: &mut got,
            };
            let scratch = &mut GatherScratch::default();
            net_inflow(&sides, (&mut kept, &h), scratch, |_, _, _, _| {});
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&got), bits(&want), "n = {n}");
            let fastest = fastest.fastest;
            assert_eq!(
                fastest.to_bits(),
                want_fastest.to_bits(),
                "n = {n}: fastest"
            );
        }
    }

    /// The limiter's one division against the plain factor, the least of 1 and each
    /// way's `room/rise` by a division of its own: the same bits, but where the two
    /// ways' fractions lie within a few units in the last place of each other (their
    /// order then taken from rounded products), within one unit; over made-up cells
    /// with rises every way, up only, down only and none.
    #[test]
    fn the_limiter_is_the_plain_least_room_over_rise() {
        let plain = |h: f64, nb: [f64; 4], rise: [f64; 4]| {
            let lo = nb.iter().fold(h, |m, &x| m.min(x));
            let hi = nb.iter().fold(h, |m, &x| m.max(x));
            let up = rise.iter().fold(0.0, |m: f64, &x| m.max(x));
            let down = rise.iter().fold(0.0, |m: f64, &x| m.min(x));
            let up_factor = if up > 0.0 {
                ((hi - h) / up).min(1.0)
            } else {
                1.0
            };
            let down_factor = if down < 0.0 {
                ((lo - h) / down).min(1.0)
            } else {
                1.0
            };
            (
                up_factor.min(down_factor).max(0.0),
                (hi - h) / up,
                (lo - h) / down,
            )
        };
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let (mut exact, mut limited) = (0, 0);
        let cases = 200_000;
        for case in 0..cases {
            let h = 1.0 + next();
            let nb = [next(), next(), next(), next()].map(|x| h + x);
            // Rises both ways, then only up, only down, none.
            let rise = [next(), next(), next(), next()].map(|x| match case % 4 {
                0 => x,
                1 => x.abs(),
                2 => -x.abs(),
                _ => 0.0,
            });
            let got = limiter(h, nb, rise);
            let (want, up, down) = plain(h, nb, rise);
            limited += usize::from(want < 1.0);
            if got.to_bits() == want.to_bits() {
                exact += 1;
                continue;
            }
            let near = (up - down).abs() <= 4.0 * f64::EPSILON * up.abs();
            let ulp = f64::EPSILON * want;
            assert!(
                near && (got - want).abs() <= ulp,
                "h {h}, nb {nb:?}, rise {rise:?}: {got} against {want}"
            );
        }
        assert!(
            limited > cases / 4,
            "{limited} cells limited: the test is idle"
        );
        assert!(exact > cases - 10, "{exact} of {cases} exact");
    }

    /// The rises the weights give against the gradient taken directly: Green–Gauss over
    /// the cell's edges, projected, dotted with the reach.
    #[test]
    fn the_rise_weights_give_the_projected_green_gauss_gradient() {
        let grid = CubeSphere::new(6);
        let sides = CellSides::new(&grid);
        let geo = UpwindGeometry::with_faces(&grid, &sides, 6);
        let ea = grid.edge_arrays();
        let h: Vec<f64> = grid
            .centres()
            .iter()
            .map(|c| 1.0 + 0.3 * c.x + 0.2 * c.y * c.z)
            .collect();
        let mut gradient = vec![DVec3::ZERO; grid.cells()];
        for (e, [a, b]) in ea.cells.iter().enumerate() {
            let (a, b) = (*a as usize, *b as usize);
            let flux = ea.normal[e] * (0.5 * (h[a] + h[b]) * ea.length[e]);
            gradient[a] += flux;
            gradient[b] -= flux;
        }
        let mut worst: f64 = 0.0;
        for c in 0..grid.cells() {
            let centre = grid.centres()[c];
            let g = gradient[c] * grid.inverse_areas_per_sr()[c];
            let g = g - centre * g.dot(centre);
            let nb = sides.neighbour[c].map(|j| h[j as usize]);
            for k in 0..4 {
                let e = sides.edge[c][k] as usize;
                let want = g.dot(ea.reach[e][usize::from(!sides.is_a[c][k])]);
                let got: f64 = (0..4).map(|j| geo.rise[k][j][c] * (h[c] + nb[j])).sum();
                worst = worst.max((got - want).abs());
            }
        }
        assert!(worst < 1e-12, "worst rise difference {worst:.3e}");
    }

    /// Each face's weights against face 0's, within 3e-14 of the largest of the side's
    /// four (1.4e-14 at n = 64): a rise sums them against like thicknesses, so an error
    /// in one counts against the largest (the weights across a side are a few hundredths
    /// of those along it); and each is made from the reach, midpoint less centre, a
    /// difference of unit vectors half a cell apart, which carries their rounding up by
    /// the inverse of that distance.
    #[test]
    fn every_faces_rise_weights_are_face_0s() {
        for n in [1, 5, 16, 64] {
            let grid = CubeSphere::new(n);
            let sides = CellSides::new(&grid);
            let geo = UpwindGeometry::with_faces(&grid, &sides, 6);
            for k in 0..4 {
                for (what, w) in [("rise", &geo.rise[k]), ("rim rise", &geo.rim_rise[k])] {
                    let face = w[0].len() / 6;
                    let largest = w.iter().flat_map(|w| &w[..face]);
                    let largest = largest.fold(0.0, |m: f64, x| m.max(x.abs()));
                    for (j, w) in w.iter().enumerate() {
                        let what = format!("n = {n}, {what}[{k}][{j}]");
                        assert_faces_alike(&what, w, largest);
                    }
                }
            }
        }
    }

    /// Every face's sixth of `w` is the first face's within 3e-14 of `largest`.
    fn assert_faces_alike(what: &str, w: &[f64], largest: f64) {
        let face = w.len() / 6;
        let (first, rest) = w.split_at(face);
        assert!(largest > 0.0, "{what}: no weights");
        for (i, (a, b)) in first.iter().cycle().zip(rest).enumerate() {
            let (f, at) = (1 + i / face, i % face);
            assert!(
                (a - b).abs() <= 3e-14 * largest,
                "{what}: face {f}'s [{at}] {b} against face 0's {a} (largest {largest})"
            );
        }
    }
}
