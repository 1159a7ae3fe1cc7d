//! The passes of one thickness-transport sub-step ([`super::transport`]), cell by cell
//! and edge by edge in the face-structured layout: inside a face each pass reads its
//! neighbours and edges as slices, which vectorise; the cells on a face's rim and the
//! seam edges take the same arithmetic through [`CellSides`]' tables.
//!
//! 1. [`limited_rises`]: each cell's rise to each side's midpoint (its Green–Gauss
//!    gradient, in its tangent plane, dotted with the reach), Barth–Jespersen limited.
//! 2. [`volumes`]: the volume across each edge, each part upwind along its own
//!    characteristic.
//! 3. [`outflow_ratios`]: each donor's factor that keeps its outflow within its budget.
//! 4. [`apply`]: each cell gathers its four limited volumes.
//!
//! A cell gathers from its four sides where the edge-by-edge passes scattered into both
//! cells: every edge's volume is still one number, subtracted from one cell and added to
//! the other, so the liquid is conserved to rounding.

use super::compare::{larger, smaller};
use super::flow::MAX_OUTFLOW_FRACTION;
use super::grid::{CubeSphere, EdgeArrays};
use super::sides::{BOTTOM, CellSides, IS_A, LEFT, RIGHT, TOP};

/// The transport's weights, fixed by the grid.
#[derive(Clone, Debug)]
pub(crate) struct UpwindGeometry {
    /// Each cell's sides.
    pub(crate) sides: CellSides,
    /// `rise[k][j][c]`: the weight of `h_c + h_j` (`j` the cell across side `j`) in the
    /// rise of cell `c`'s thickness to the midpoint of its side `k`: the Green–Gauss
    /// gradient `Σ ± n l (h_c + h_j)/2 / A`, projected onto the cell's tangent plane and
    /// dotted with the reach `midpoint − centre`, is linear in the face values, so one
    /// weight per pair of sides stands for the gradient's three components and its
    /// projection.
    rise: [[Vec<f64>; 4]; 4],
}

impl UpwindGeometry {
    /// Derives the weights from `grid`.
    pub(crate) fn new(grid: &CubeSphere) -> Self {
        let sides = CellSides::new(grid);
        let ea = grid.edge_arrays();
        let cells = grid.cells();
        let mut rise: [[Vec<f64>; 4]; 4] =
            std::array::from_fn(|_| std::array::from_fn(|_| vec![0.0; cells]));
        let inverse_areas = grid.inverse_areas_per_sr();
        for (c, centre) in grid.centres().iter().enumerate() {
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
        Self { sides, rise }
    }

    fn n(&self) -> usize {
        self.sides.n()
    }
}

/// One cell's four limited rises from its thickness `h`, its neighbours' `nb` (in side
/// order) and its weights `w[k][j]`.
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
/// least of the four sides' `min(1, room/rise)`, for two divisions where each side took
/// one.
#[inline(always)]
fn cell_limited_rises(h: f64, nb: [f64; 4], w: [[f64; 4]; 4]) -> [f64; 4] {
    let rise: [f64; 4] = std::array::from_fn(|k| {
        (w[k][0] * (h + nb[0]) + w[k][1] * (h + nb[1]))
            + (w[k][2] * (h + nb[2]) + w[k][3] * (h + nb[3]))
    });
    let phi = limiter(h, nb, rise);
    rise.map(|r| r * phi)
}

/// The Barth–Jespersen factor of a cell of thickness `h` with neighbours `nb` and rises
/// `rise` ([`cell_limited_rises`]).
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
    let up_factor = if up > 0.0 {
        smaller((hi - h) / up, 1.0)
    } else {
        1.0
    };
    let down_factor = if down < 0.0 {
        smaller((lo - h) / down, 1.0)
    } else {
        1.0
    };
    larger(smaller(up_factor, down_factor), 0.0)
}

/// Every cell's limited rise to each side, `out[k][c]`, m.
// Inlined into the sub-step's `with_avx2` closure, so compiled for AVX2 there.
#[inline(always)]
pub(crate) fn limited_rises(geo: &UpwindGeometry, h: &[f64], out: &mut [Vec<f64>; 4]) {
    for o in out.iter_mut() {
        o.resize(h.len(), 0.0);
    }
    let n = geo.n();
    let sides = &geo.sides;
    let weights = |c: usize| std::array::from_fn(|k| std::array::from_fn(|j| geo.rise[k][j][c]));
    for_rim_cells(n, |c| {
        let nb = sides.neighbour[c].map(|j| h[j as usize]);
        let r = cell_limited_rises(h[c], nb, weights(c));
        for (o, r) in out.iter_mut().zip(r) {
            o[c] = r;
        }
    });
    if n < 3 {
        return;
    }
    let [o0, o1, o2, o3] = out;
    for face in 0..6 {
        for y in 1..n - 1 {
            let start = face * n * n + y * n + 1;
            let cells = start..start + n - 2;
            let outs = [
                &mut o0[cells.clone()],
                &mut o1[cells.clone()],
                &mut o2[cells.clone()],
                &mut o3[cells.clone()],
            ];
            rises_run(geo, h, cells, n, outs);
        }
    }
}

/// [`cell_limited_rises`] over a run of cells inside a face, as slices: each side's
/// rises in a loop of their own, then the limit (one loop over all sixteen weights kept
/// the compiler from vectorising it: it spilled them to the stack cell by cell).
#[inline(always)]
fn rises_run(
    geo: &UpwindGeometry,
    h: &[f64],
    cells: std::ops::Range<usize>,
    n: usize,
    mut out: [&mut [f64]; 4],
) {
    let len = cells.len();
    let (s, e) = (cells.start, cells.end);
    let centre = &h[s..e];
    let nb = [
        &h[s - 1..e - 1],
        &h[s + 1..e + 1],
        &h[s - n..e - n],
        &h[s + n..e + n],
    ];
    for (k, o) in out.iter_mut().enumerate() {
        let w = &geo.rise[k];
        rise_run(
            [&w[0][s..e], &w[1][s..e], &w[2][s..e], &w[3][s..e]],
            centre,
            nb,
            o,
        );
    }
    let [o0, o1, o2, o3] = out;
    let (o0, o1, o2, o3) = (
        &mut o0[..len],
        &mut o1[..len],
        &mut o2[..len],
        &mut o3[..len],
    );
    let [l, r, d, u] = nb.map(|x| &x[..len]);
    for i in 0..len {
        let rise = [o0[i], o1[i], o2[i], o3[i]];
        let phi = limiter(centre[i], [l[i], r[i], d[i], u[i]], rise);
        (o0[i], o1[i], o2[i], o3[i]) = (rise[0] * phi, rise[1] * phi, rise[2] * phi, rise[3] * phi);
    }
}

/// One side's rises over a run: `Σ_j w_j (h + h_j)`.
#[inline(always)]
fn rise_run(w: [&[f64]; 4], h: &[f64], nb: [&[f64]; 4], out: &mut [f64]) {
    let len = out.len();
    let (w0, w1, w2, w3) = (&w[0][..len], &w[1][..len], &w[2][..len], &w[3][..len]);
    let (l, r, d, u, h) = (
        &nb[0][..len],
        &nb[1][..len],
        &nb[2][..len],
        &nb[3][..len],
        &h[..len],
    );
    for i in 0..len {
        let c = h[i];
        out[i] =
            (w0[i] * (c + l[i]) + w1[i] * (c + r[i])) + (w2[i] * (c + d[i]) + w3[i] * (c + u[i]));
    }
}

/// What moves liquid across the edges: the surfaces' speed, the drainage's coefficient
/// and the step over the radius.
#[derive(Clone, Copy)]
pub(crate) struct EdgeSpeeds<'a> {
    /// Per edge: the surfaces' speed, m/s.
    pub(crate) u: &'a [f64],
    /// Per edge: the drainage speed's coefficient over `h²`, s⁻¹·m⁻¹.
    pub(crate) drain_rate: &'a [f64],
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
    // The clamp by comparisons: `clamp` tests for NaN and its bounds' order.
    let clamped = |x: f64| {
        if x < lo {
            lo
        } else if x > hi {
            hi
        } else {
            x
        }
    };
    let (face_a, face_b) = (clamped(ha + ra), clamped(hb + rb));
    let plug = if u >= 0.0 { face_a } else { face_b };
    let drain = if c >= 0.0 { face_a } else { face_b };
    (u * plug + c * drain * drain * drain) * l * dt_per_r
}

/// The volume across every edge over the sub-step, into `volume` (per R², m × sr).
// Inlined into the sub-step's `with_avx2` closure, so compiled for AVX2 there.
#[inline(always)]
pub(crate) fn volumes(
    geo: &UpwindGeometry,
    ea: &EdgeArrays,
    h: &[f64],
    rise: &[Vec<f64>; 4],
    speeds: EdgeSpeeds,
    volume: &mut Vec<f64>,
) {
    volume.resize(ea.cells.len(), 0.0);
    let n = geo.n();
    let layout = geo.sides.layout;
    let per_edge = [speeds.u, speeds.drain_rate, &ea.length[..]];
    // A face's x-edges row by row (a row's cells are consecutive), then all its y-edges
    // at once (cell `b` is `a + n` throughout).
    for face in 0..6 {
        for y in 0..n {
            let a = face * n * n + y * n;
            let first = face * n * (n - 1) + y * (n - 1);
            volumes_run(
                per_edge,
                speeds.dt_per_r,
                first,
                n - 1,
                h,
                [a, a + 1],
                [&rise[RIGHT], &rise[LEFT]],
                volume,
            );
        }
        let first = 6 * n * (n - 1) + face * n * (n - 1);
        let a = face * n * n;
        volumes_run(
            per_edge,
            speeds.dt_per_r,
            first,
            n * (n - 1),
            h,
            [a, a + n],
            [&rise[TOP], &rise[BOTTOM]],
            volume,
        );
    }
    let seams = layout.first_seam_edge()..ea.cells.len();
    for (e, [ka, kb]) in seams.zip(&geo.sides.seam_sides) {
        let [a, b] = ea.cells[e].map(|c| c as usize);
        let rises = [rise[*ka as usize][a], rise[*kb as usize][b]];
        let speed = [speeds.u[e], speeds.drain_rate[e], ea.length[e]];
        volume[e] = edge_volume([h[a], h[b]], rises, speed, speeds.dt_per_r);
    }
}

/// [`edge_volume`] over `len` consecutive edges from `first` whose `a` and `b` cells run
/// consecutively from `start[0]` and `start[1]`.
#[allow(clippy::too_many_arguments)] // the run's two cells, edges and rises
#[inline(always)]
fn volumes_run(
    [u, c, l]: [&[f64]; 3],
    dt_per_r: f64,
    first: usize,
    len: usize,
    h: &[f64],
    [a, b]: [usize; 2],
    [rise_a, rise_b]: [&[f64]; 2],
    volume: &mut [f64],
) {
    let edges = first..first + len;
    let (u, c, l, out) = (
        &u[edges.clone()],
        &c[edges.clone()],
        &l[edges.clone()],
        &mut volume[edges],
    );
    let (ha, hb) = (&h[a..a + len], &h[b..b + len]);
    let (ra, rb) = (&rise_a[a..a + len], &rise_b[b..b + len]);
    for i in 0..len {
        out[i] = edge_volume([ha[i], hb[i]], [ra[i], rb[i]], [u[i], c[i], l[i]], dt_per_r);
    }
}

/// Each cell's outflow over its four sides from their volumes `v` (positive from the
/// side's `a` cell to its `b` cell).
#[inline(always)]
fn outflow(v: [f64; 4], is_a: [bool; 4]) -> f64 {
    let out = |k: usize| larger(if is_a[k] { v[k] } else { -v[k] }, 0.0);
    (out(0) + out(1)) + (out(2) + out(3))
}

/// The factor by which a donor's volumes are cut so that it gives at most
/// [`MAX_OUTFLOW_FRACTION`] of its content: 1 where it gives less.
#[inline(always)]
fn ratio(outflow: f64, area: f64, h: f64) -> f64 {
    let budget = MAX_OUTFLOW_FRACTION * area * h;
    if outflow > budget {
        budget / outflow
    } else {
        1.0
    }
}

/// Every cell's outflow factor into `out`.
// Inlined into the sub-step's `with_avx2` closure, so compiled for AVX2 there.
#[inline(always)]
pub(crate) fn outflow_ratios(
    geo: &UpwindGeometry,
    areas: &[f64],
    h: &[f64],
    volume: &[f64],
    out: &mut Vec<f64>,
) {
    out.resize(h.len(), 0.0);
    let sides = &geo.sides;
    let n = geo.n();
    let mut one_cell = |c: usize| {
        let v = sides.edge[c].map(|e| volume[e as usize]);
        out[c] = ratio(outflow(v, sides.is_a[c]), areas[c], h[c]);
    };
    for_rim_cells(n, &mut one_cell);
    if n < 3 {
        return;
    }
    let layout = sides.layout;
    for face in 0..6 {
        for y in 1..n - 1 {
            let s = face * n * n + y * n + 1;
            let len = n - 2;
            let [left, right, bottom, top] = side_edge_starts(layout, s, n);
            let v = [
                &volume[left..left + len],
                &volume[right..right + len],
                &volume[bottom..bottom + len],
                &volume[top..top + len],
            ];
            let (a, hh, o) = (&areas[s..s + len], &h[s..s + len], &mut out[s..s + len]);
            for i in 0..len {
                o[i] = ratio(outflow(v.map(|v| v[i]), IS_A), a[i], hh[i]);
            }
        }
    }
}

/// The first edge on each side (in side order) of the run of cells from `s` inside a
/// face: each side's edges are then consecutive along the run.
fn side_edge_starts(layout: super::grid::FaceLayout, s: usize, n: usize) -> [usize; 4] {
    [
        layout.x_edge_of_cell(s),
        layout.x_edge_of_cell(s + 1),
        layout.y_edge_of_cell(s),
        layout.y_edge_of_cell(s + n),
    ]
}

/// Calls `f` on every cell with a side on a face's rim (the ones the structured runs
/// leave out), in increasing order.
#[inline(always)]
fn for_rim_cells(n: usize, mut f: impl FnMut(usize)) {
    for face in 0..6 {
        for y in 0..n {
            let row = face * n * n + y * n;
            if y == 0 || y + 1 >= n || n < 3 {
                (row..row + n).for_each(&mut f);
            } else {
                f(row);
                f(row + n - 1);
            }
        }
    }
}

/// A cell's change of thickness from its sides' volumes `v`, the sides' donors' factors
/// `ratio_a`/`ratio_b` (of each side's `a` and `b` cells), over its area.
#[inline(always)]
fn gathered(v: [f64; 4], ratio_a: [f64; 4], ratio_b: [f64; 4], is_a: [bool; 4]) -> f64 {
    let moved = |k: usize| {
        let m = v[k] * if v[k] >= 0.0 { ratio_a[k] } else { ratio_b[k] };
        if is_a[k] { -m } else { m }
    };
    (moved(0) + moved(1)) + (moved(2) + moved(3))
}

/// Every cell gathers its sides' limited volumes into its thickness.
// Inlined into the sub-step's `with_avx2` closure, so compiled for AVX2 there.
#[inline(always)]
pub(crate) fn apply(
    geo: &UpwindGeometry,
    per_area: &[f64],
    volume: &[f64],
    ratio: &[f64],
    h: &mut [f64],
) {
    let sides = &geo.sides;
    let n = geo.n();
    let mut one_cell = |c: usize| {
        let v = sides.edge[c].map(|e| volume[e as usize]);
        let is_a = sides.is_a[c];
        let across = sides.neighbour[c].map(|j| ratio[j as usize]);
        let (mut ra, mut rb) = (across, across);
        for k in 0..4 {
            if is_a[k] {
                ra[k] = ratio[c]
            } else {
                rb[k] = ratio[c]
            }
        }
        h[c] += gathered(v, ra, rb, is_a) * per_area[c];
    };
    for_rim_cells(n, &mut one_cell);
    if n < 3 {
        return;
    }
    let layout = sides.layout;
    for face in 0..6 {
        for y in 1..n - 1 {
            let s = face * n * n + y * n + 1;
            let len = n - 2;
            let [left, right, bottom, top] = side_edge_starts(layout, s, n);
            let v = [
                &volume[left..left + len],
                &volume[right..right + len],
                &volume[bottom..bottom + len],
                &volume[top..top + len],
            ];
            let own = &ratio[s..s + len];
            let nb = [
                &ratio[s - 1..s - 1 + len],
                &ratio[s + 1..s + 1 + len],
                &ratio[s - n..s - n + len],
                &ratio[s + n..s + n + len],
            ];
            let (pa, hh) = (&per_area[s..s + len], &mut h[s..s + len]);
            for i in 0..len {
                // The left and bottom sides' `a` cell is the neighbour; right and top, this cell.
                let ra = [nb[0][i], own[i], nb[2][i], own[i]];
                let rb = [own[i], nb[1][i], own[i], nb[3][i]];
                hh[i] += gathered(v.map(|v| v[i]), ra, rb, IS_A) * pa[i];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// The rises the weights give against the gradient taken directly: Green–Gauss over
    /// the cell's edges, projected, dotted with the reach.
    #[test]
    fn the_rise_weights_give_the_projected_green_gauss_gradient() {
        let grid = CubeSphere::new(6);
        let geo = UpwindGeometry::new(&grid);
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
            let nb = geo.sides.neighbour[c].map(|j| h[j as usize]);
            for k in 0..4 {
                let e = geo.sides.edge[c][k] as usize;
                let want = g.dot(ea.reach[e][usize::from(!geo.sides.is_a[c][k])]);
                let got: f64 = (0..4).map(|j| geo.rise[k][j][c] * (h[c] + nb[j])).sum();
                worst = worst.max((got - want).abs());
            }
        }
        assert!(worst < 1e-12, "worst rise difference {worst:.3e}");
    }
}
