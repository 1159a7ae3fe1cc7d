//! Per-edge volumes applied to the cells, cell by cell: each cell gathers its four
//! sides' volumes, where an edge-by-edge pass scattered each volume into both its cells
//! through index arrays (which no compiler vectorises). Inside the faces the cells come
//! a face at a time ([`CellSpan`]) read as slices, the x-edges' volumes first spread to
//! one a cell ([`GatherScratch`]); the rim's cells take the same arithmetic through
//! [`CellSides`]' tables. Every edge's volume is still one number, taken from one cell
//! and given to the other, so what moves is conserved to rounding.

use super::flow::MAX_OUTFLOW_FRACTION;
use super::grid::CubeSphere;
use super::sides::{CellSides, CellSpan, INFLOW};
use crate::avx2::with_avx2;

/// Buffers of the gathers, kept from pass to pass.
#[derive(Clone, Debug, Default)]
pub(crate) struct GatherScratch {
    /// Per cell: the volume on its left x-edge (its right one is the next cell's), for
    /// the cells inside the faces: a face's x-edges are `n − 1` a row, so only so do they
    /// read as one slice along a [`CellSpan`].
    x_volume: Vec<f64>,
    /// Per cell: its factor as a donor ([`apply_limited`]).
    pub(crate) ratio: Vec<f64>,
    /// The rim's values in its order ([`RimValues`]).
    rim: RimValues,
}

/// The limited apply's values on the rim, gathered in the rim's order so that its
/// arithmetic runs on slices (through the tables cell by cell it cost about 150
/// instructions a rim cell, as much as all the cells inside the faces).
#[derive(Clone, Debug, Default)]
struct RimValues {
    /// Per side: the volume.
    volume: [Vec<f64>; 4],
    /// Per side: the neighbour's factor as a donor.
    across: [Vec<f64>; 4],
    /// The cells' values before the apply (the spans overwrite those among theirs).
    value: Vec<f64>,
    /// The cells' own factors as donors.
    ratio: Vec<f64>,
    /// The cells' values after the apply.
    next: Vec<f64>,
}

/// Spreads a per-edge array's values on the x-edges of the faces' inside rows to one a
/// cell (each cell's left edge), into `x_volume`.
#[inline(always)]
pub(crate) fn spread_x_volumes(sides: &CellSides, volume: &[f64], x_volume: &mut Vec<f64>) {
    let n = sides.n();
    x_volume.resize(6 * n * n, 0.0);
    for face in 0..6 {
        for y in 1..n.saturating_sub(1) {
            let row = face * n * n + y * n;
            let first = face * n * (n - 1) + y * (n - 1);
            x_volume[row + 1..row + n].copy_from_slice(&volume[first..first + n - 1]);
        }
    }
}

/// A per-edge array's values on the four sides along a span (a volume's with
/// [`INFLOW`]'s signs), each `span.len` long: the x-edges' from `x_volume`
/// ([`spread_x_volumes`]), the y-edges' from `volume`.
#[inline(always)]
pub(crate) fn span_sides<'a>(
    sides: &CellSides,
    span: &CellSpan,
    x_volume: &'a [f64],
    volume: &'a [f64],
) -> [&'a [f64]; 4] {
    let (start, len, n) = (span.start, span.len, span.n());
    let bottom = sides.layout.y_edge_of_cell(start);
    [
        &x_volume[start..start + len],
        &x_volume[start + 1..start + 1 + len],
        &volume[bottom..bottom + len],
        &volume[bottom + n..bottom + n + len],
    ]
}

/// A per-edge grid constant's values on the four sides along a span, each `span.len`
/// long, from face 0's ([`super::face_geometry`]): the x-edges' from `x_face`, one a
/// cell (`FaceGeometry::x_length`'s layout), the y-edges' from `face_edges`, face 0's
/// interior edges' values ([`super::grid::FaceLayout::on_face`]).
#[inline(always)]
pub(crate) fn span_sides_on_face<'a>(
    span: &CellSpan,
    x_face: &'a [f64],
    face_edges: &'a [f64],
) -> [&'a [f64]; 4] {
    let (len, n) = (span.len, span.n());
    let start = span.start % (n * n);
    // Face 0's y-edge below cell `start`: after its `n·(n − 1)` x-edges.
    let bottom = n * (n - 1) + start - n;
    [
        &x_face[start..start + len],
        &x_face[start + 1..start + 1 + len],
        &face_edges[bottom..bottom + len],
        &face_edges[bottom + n..bottom + n + len],
    ]
}

/// A cell's net inflow from its sides' volumes `v` with signs `inflow`.
#[inline(always)]
fn net(v: [f64; 4], inflow: [f64; 4]) -> f64 {
    (inflow[0] * v[0] + inflow[1] * v[1]) + (inflow[2] * v[2] + inflow[3] * v[3])
}

/// Each cell's net inflow of the per-edge volumes `volume` (positive from an edge's `a`
/// cell to its `b` cell), into `out`: `Σ volume` over the edges it is `b` of, less over
/// those it is `a` of.
pub(crate) fn net_inflow(
    sides: &CellSides,
    volume: &[f64],
    out: &mut Vec<f64>,
    scratch: &mut GatherScratch,
) {
    // Every entry is written below: the buffer needs its length, not a fill.
    out.resize(6 * sides.n() * sides.n(), 0.0);
    let x_volume = &mut scratch.x_volume;
    with_avx2(
        #[inline(always)]
        || {
            spread_x_volumes(sides, volume, x_volume);
            // A face at a time; its rim cells, among the span's, are redone below.
            for span in sides.face_spans() {
                let [v0, v1, v2, v3] = span_sides(sides, &span, x_volume, volume);
                let o = &mut out[span.cells()];
                let len = o.len();
                let (v0, v1, v2, v3) = (&v0[..len], &v1[..len], &v2[..len], &v3[..len]);
                for i in 0..len {
                    o[i] = net([v0[i], v1[i], v2[i], v3[i]], INFLOW);
                }
            }
            let rim = sides.rim();
            for (i, &c) in rim.cells.iter().enumerate() {
                out[c as usize] = net(rim.at_edges(i, volume), rim.inflow(i));
            }
        },
    )
}

/// Moves `values` (a content per area, per cell) by the per-edge volumes `scale·volume`
/// (per R², positive from `a` to `b`), each donor giving at most
/// [`MAX_OUTFLOW_FRACTION`] of its content (`values` then stays ≥ 0); `ratio` is scratch.
/// The faces' cells read face 0's areas, the same on every face
/// ([`super::face_geometry`]), the rim's its table's.
pub(crate) fn apply_limited(
    sides: &CellSides,
    grid: &CubeSphere,
    volume: &[f64],
    scale: f64,
    values: &mut [f64],
    scratch: &mut GatherScratch,
) {
    let GatherScratch {
        x_volume,
        ratio,
        rim,
    } = scratch;
    ratio.resize(values.len(), 0.0);
    let fg = grid.face_geometry();
    let (areas, per_area) = (&fg.area_sr[..], &fg.inverse_area_per_sr[..]);
    with_avx2(
        #[inline(always)]
        || {
            spread_x_volumes(sides, volume, x_volume);
            let volumes = (&x_volume[..], volume);
            outflow_ratios(sides, areas, values, volumes, scale, (ratio, rim));
            gather_limited(sides, per_area, volumes, scale, ratio, (values, rim));
        },
    )
}

/// A cell's factor `budget/outflow` where its outflow over its sides (volumes `v`, signs
/// `inflow`, times `scale`) would pass its budget, a fraction of its content `area·x`
/// (1 elsewhere: multiplying by it then changes nothing).
#[inline(always)]
fn outflow_factor(v: [f64; 4], inflow: [f64; 4], scale: f64, area: f64, x: f64) -> f64 {
    let given = |k: usize| {
        let out = -inflow[k] * v[k];
        if out > 0.0 { out } else { 0.0 }
    };
    let outflow = scale * ((given(0) + given(1)) + (given(2) + given(3)));
    let budget = MAX_OUTFLOW_FRACTION * area * x;
    if outflow > budget {
        budget / outflow
    } else {
        1.0
    }
}

/// Every cell's [`outflow_factor`] into `out` (`areas`: face 0's).
#[inline(always)]
fn outflow_ratios(
    sides: &CellSides,
    areas: &[f64],
    values: &[f64],
    (x_volume, volume): (&[f64], &[f64]),
    scale: f64,
    (out, rim_values): (&mut [f64], &mut RimValues),
) {
    // A face at a time; its rim cells, among the span's, are redone below.
    for span in sides.face_spans() {
        let [v0, v1, v2, v3] = span_sides(sides, &span, x_volume, volume);
        let o = &mut out[span.cells()];
        let len = o.len();
        let (v0, v1, v2, v3) = (&v0[..len], &v1[..len], &v2[..len], &v3[..len]);
        let (a, x) = (span.on_face(areas), &values[span.cells()]);
        let (a, x) = (&a[..len], &x[..len]);
        for i in 0..len {
            o[i] = outflow_factor([v0[i], v1[i], v2[i], v3[i]], INFLOW, scale, a[i], x[i]);
        }
    }
    let rim = sides.rim();
    let m = rim.cells.len();
    rim_values.gather(sides, volume, values);
    let RimValues {
        volume: [v0, v1, v2, v3],
        value,
        ratio,
        ..
    } = rim_values;
    let (v0, v1, v2, v3) = (&v0[..m], &v1[..m], &v2[..m], &v3[..m]);
    let [s0, s1, s2, s3] = rim.inflows();
    let (area, value) = (&rim.area[..m], &value[..m]);
    ratio.resize(m, 0.0);
    let ratio = &mut ratio[..m];
    for i in 0..m {
        let (v, inflow) = ([v0[i], v1[i], v2[i], v3[i]], [s0[i], s1[i], s2[i], s3[i]]);
        ratio[i] = outflow_factor(v, inflow, scale, area[i], value[i]);
    }
    for (&c, &r) in rim.cells.iter().zip(&*ratio) {
        out[c as usize] = r;
    }
}

/// A cell's gain from its sides' volumes `v` (signs `inflow`), each cut by its donor's
/// factor: the neighbour's (`across`) for what flows in, the cell's own (`own`) for what
/// flows out.
#[inline(always)]
fn gained(v: [f64; 4], inflow: [f64; 4], across: [f64; 4], own: f64) -> f64 {
    let moved = |k: usize| {
        let m = inflow[k] * v[k];
        m * if m > 0.0 { across[k] } else { own }
    };
    (moved(0) + moved(1)) + (moved(2) + moved(3))
}

/// Every cell gathers its sides' volumes, each cut by its donor's factor (`per_area`:
/// face 0's).
#[inline(always)]
fn gather_limited(
    sides: &CellSides,
    per_area: &[f64],
    (x_volume, volume): (&[f64], &[f64]),
    scale: f64,
    ratio: &[f64],
    (values, rim_values): (&mut [f64], &mut RimValues),
) {
    // The spans add to the rim cells among theirs what is not theirs: the rim's values
    // as they were are in `rim_values` (gathered with the outflow factors).
    for span in sides.face_spans() {
        let len = span.len;
        let [v0, v1, v2, v3] = span_sides(sides, &span, x_volume, volume);
        let (v0, v1, v2, v3) = (&v0[..len], &v1[..len], &v2[..len], &v3[..len]);
        let [r0, r1, r2, r3]: [&[f64]; 4] = std::array::from_fn(|k| &ratio[span.neighbours(k)]);
        let (r0, r1, r2, r3) = (&r0[..len], &r1[..len], &r2[..len], &r3[..len]);
        let (own, pa) = (&ratio[span.cells()], span.on_face(per_area));
        let (own, pa) = (&own[..len], &pa[..len]);
        let x = &mut values[span.cells()];
        for i in 0..len {
            let v = [v0[i], v1[i], v2[i], v3[i]];
            let across = [r0[i], r1[i], r2[i], r3[i]];
            x[i] += scale * gained(v, INFLOW, across, own[i]) * pa[i];
        }
    }
    let rim = sides.rim();
    let m = rim.cells.len();
    let r = rim_values;
    rim.gather_neighbours(ratio, &mut r.across);
    let [v0, v1, v2, v3] = &r.volume;
    let (v0, v1, v2, v3) = (&v0[..m], &v1[..m], &v2[..m], &v3[..m]);
    let [a0, a1, a2, a3] = &r.across;
    let (a0, a1, a2, a3) = (&a0[..m], &a1[..m], &a2[..m], &a3[..m]);
    let [s0, s1, s2, s3] = rim.inflows();
    let (own, pa, value) = (&r.ratio[..m], &rim.inverse_area[..m], &r.value[..m]);
    r.next.resize(m, 0.0);
    let next = &mut r.next[..m];
    for i in 0..m {
        let (v, inflow) = ([v0[i], v1[i], v2[i], v3[i]], [s0[i], s1[i], s2[i], s3[i]]);
        let across = [a0[i], a1[i], a2[i], a3[i]];
        next[i] = value[i] + scale * gained(v, inflow, across, own[i]) * pa[i];
    }
    for (&c, &x) in rim.cells.iter().zip(&*next) {
        values[c as usize] = x;
    }
}

impl RimValues {
    /// The rim's volumes and values before the apply.
    #[inline(always)]
    fn gather(&mut self, sides: &CellSides, volume: &[f64], values: &[f64]) {
        let rim = sides.rim();
        rim.gather_edges(volume, &mut self.volume);
        rim.gather_cells(values, &mut self.value);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::film_flow::CubeSphere;

    /// Against the edge-by-edge scatter it replaces.
    #[test]
    fn net_inflow_is_the_scatter_of_the_volumes() {
        let grid = CubeSphere::new(5);
        let sides = CellSides::new(&grid);
        let ea = grid.edge_arrays();
        let volume: Vec<f64> = (0..ea.cells.len())
            .map(|e| ((e * 37) % 11) as f64 - 5.0)
            .collect();
        let mut want = vec![0.0; grid.cells()];
        for ([a, b], v) in ea.cells.iter().zip(&volume) {
            want[*a as usize] -= v;
            want[*b as usize] += v;
        }
        let mut got = vec![f64::NAN; 3];
        net_inflow(&sides, &volume, &mut got, &mut GatherScratch::default());
        assert_eq!(got, want);
    }

    /// Against the edge-by-edge scatter of the limited volumes: each donor's factor from
    /// its summed outflow, each volume cut by its donor's factor.
    #[test]
    fn apply_limited_is_the_scatter_of_the_limited_volumes() {
        for n in [3, 6] {
            let grid = CubeSphere::new(n);
            let sides = CellSides::new(&grid);
            let ea = grid.edge_arrays();
            let (areas, per_area) = (grid.areas_sr(), grid.inverse_areas_per_sr());
            let volume: Vec<f64> = (0..ea.cells.len())
                .map(|e| (((e * 53) % 17) as f64 - 8.0) * 1e-1)
                .collect();
            let values: Vec<f64> = (0..grid.cells()).map(|c| 1.0 + (c % 7) as f64).collect();
            let scale = 0.3;
            let mut outflow = vec![0.0; grid.cells()];
            for ([a, b], v) in ea.cells.iter().zip(&volume) {
                let donor = if *v > 0.0 { *a } else { *b } as usize;
                outflow[donor] += scale * v.abs();
            }
            let factor: Vec<f64> = (0..grid.cells())
                .map(|c| {
                    let budget = MAX_OUTFLOW_FRACTION * areas[c] * values[c];
                    if outflow[c] > budget {
                        budget / outflow[c]
                    } else {
                        1.0
                    }
                })
                .collect();
            assert!(factor.iter().any(|&f| f < 1.0), "n {n}: no donor limited");
            let mut want = values.clone();
            for ([a, b], v) in ea.cells.iter().zip(&volume) {
                let (a, b) = (*a as usize, *b as usize);
                let moved = scale * v * factor[if *v > 0.0 { a } else { b }];
                want[a] -= moved * per_area[a];
                want[b] += moved * per_area[b];
            }
            let mut got = values.clone();
            let mut scratch = GatherScratch::default();
            apply_limited(&sides, &grid, &volume, scale, &mut got, &mut scratch);
            for (c, (g, w)) in got.iter().zip(&want).enumerate() {
                assert!(
                    (g - w).abs() < 1e-12 * w.abs(),
                    "n {n} cell {c}: {g} against {w}"
                );
            }
        }
    }

    /// The limited apply conserves the content and keeps it ≥ 0 however large the
    /// volumes.
    #[test]
    fn limited_volumes_conserve_the_content_and_empty_no_cell() {
        let grid = CubeSphere::new(6);
        let sides = CellSides::new(&grid);
        let ea = grid.edge_arrays();
        let volume: Vec<f64> = (0..ea.cells.len())
            .map(|e| ((e * 53) % 17) as f64 - 8.0)
            .collect();
        let mut values: Vec<f64> = (0..grid.cells()).map(|c| 1.0 + (c % 7) as f64).collect();
        let content = |v: &[f64]| {
            v.iter()
                .zip(grid.areas_sr())
                .map(|(x, a)| x * a)
                .sum::<f64>()
        };
        let before = content(&values);
        let mut scratch = GatherScratch::default();
        apply_limited(&sides, &grid, &volume, 0.3, &mut values, &mut scratch);
        let change = (content(&values) - before) / before;
        assert!(change.abs() < 1e-14, "content changed by {change:.3e}");
        let least = values.iter().copied().fold(f64::INFINITY, f64::min);
        assert!(least >= 0.0, "a cell went to {least}");
        assert!(
            scratch.ratio.iter().any(|&r| r < 1.0),
            "no donor was limited: the test is idle"
        );
    }
}
