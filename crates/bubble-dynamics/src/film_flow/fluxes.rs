//! Per-edge volumes applied to the cells, cell by cell: each cell gathers its four
//! sides' volumes, where an edge-by-edge pass scattered each volume into both its cells
//! through index arrays (which no compiler vectorises). Inside the faces the cells come
//! in runs ([`CellRun`]) read as slices; the rim's cells take the same arithmetic
//! through [`CellSides`]' tables. Every edge's volume is still one number, taken from
//! one cell and given to the other, so what moves is conserved to rounding.

use super::flow::MAX_OUTFLOW_FRACTION;
use super::sides::{CellRun, CellSides, INFLOW};
use crate::avx2::with_avx2;

/// The four sides' slices of a per-edge array for a run, each `run.len` long.
#[inline(always)]
pub(crate) fn side_slices<'a>(run: &CellRun, per_edge: &'a [f64]) -> [&'a [f64]; 4] {
    std::array::from_fn(|k| &per_edge[run.edges(k)])
}

/// A cell's net inflow from its sides' volumes `v` with signs `inflow`.
#[inline(always)]
fn net(v: [f64; 4], inflow: [f64; 4]) -> f64 {
    (inflow[0] * v[0] + inflow[1] * v[1]) + (inflow[2] * v[2] + inflow[3] * v[3])
}

/// Each cell's net inflow of the per-edge volumes `volume` (positive from an edge's `a`
/// cell to its `b` cell), into `out`: `Σ volume` over the edges it is `b` of, less over
/// those it is `a` of.
pub(crate) fn net_inflow(sides: &CellSides, volume: &[f64], out: &mut Vec<f64>) {
    // Every entry is written below: the buffer needs its length, not a fill.
    out.resize(6 * sides.n() * sides.n(), 0.0);
    with_avx2(
        #[inline(always)]
        || {
            for run in &sides.cell_runs {
                let [v0, v1, v2, v3] = side_slices(run, volume);
                let o = &mut out[run.cells()];
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
#[allow(clippy::too_many_arguments)] // the grid's two area arrays, the volumes, the field
pub(crate) fn apply_limited(
    sides: &CellSides,
    areas: &[f64],
    per_area: &[f64],
    volume: &[f64],
    scale: f64,
    values: &mut [f64],
    ratio: &mut Vec<f64>,
) {
    ratio.resize(values.len(), 0.0);
    with_avx2(
        #[inline(always)]
        || {
            outflow_ratios(sides, areas, values, volume, scale, ratio);
            gather_limited(sides, per_area, volume, scale, ratio, values);
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

/// Every cell's [`outflow_factor`] into `out`.
#[inline(always)]
fn outflow_ratios(
    sides: &CellSides,
    areas: &[f64],
    values: &[f64],
    volume: &[f64],
    scale: f64,
    out: &mut [f64],
) {
    for run in &sides.cell_runs {
        let [v0, v1, v2, v3] = side_slices(run, volume);
        let o = &mut out[run.cells()];
        let len = o.len();
        let (v0, v1, v2, v3) = (&v0[..len], &v1[..len], &v2[..len], &v3[..len]);
        let (a, x) = (&areas[run.cells()], &values[run.cells()]);
        let (a, x) = (&a[..len], &x[..len]);
        for i in 0..len {
            o[i] = outflow_factor([v0[i], v1[i], v2[i], v3[i]], INFLOW, scale, a[i], x[i]);
        }
    }
    let rim = sides.rim();
    for (i, &c) in rim.cells.iter().enumerate() {
        let (v, c) = (rim.at_edges(i, volume), c as usize);
        out[c] = outflow_factor(v, rim.inflow(i), scale, areas[c], values[c]);
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

/// Every cell gathers its sides' volumes, each cut by its donor's factor.
#[inline(always)]
fn gather_limited(
    sides: &CellSides,
    per_area: &[f64],
    volume: &[f64],
    scale: f64,
    ratio: &[f64],
    values: &mut [f64],
) {
    for run in &sides.cell_runs {
        let len = run.len;
        let [v0, v1, v2, v3] = side_slices(run, volume);
        let (v0, v1, v2, v3) = (&v0[..len], &v1[..len], &v2[..len], &v3[..len]);
        let [r0, r1, r2, r3]: [&[f64]; 4] = std::array::from_fn(|k| &ratio[run.neighbours(k)]);
        let (r0, r1, r2, r3) = (&r0[..len], &r1[..len], &r2[..len], &r3[..len]);
        let (own, pa) = (&ratio[run.cells()], &per_area[run.cells()]);
        let (own, pa) = (&own[..len], &pa[..len]);
        let x = &mut values[run.cells()];
        for i in 0..len {
            let v = [v0[i], v1[i], v2[i], v3[i]];
            let across = [r0[i], r1[i], r2[i], r3[i]];
            x[i] += scale * gained(v, INFLOW, across, own[i]) * pa[i];
        }
    }
    let rim = sides.rim();
    for (i, &c) in rim.cells.iter().enumerate() {
        let (v, across) = (rim.at_edges(i, volume), rim.at_neighbours(i, ratio));
        let c = c as usize;
        values[c] += scale * gained(v, rim.inflow(i), across, ratio[c]) * per_area[c];
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
        net_inflow(&sides, &volume, &mut got);
        assert_eq!(got, want);
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
        let mut ratio = Vec::new();
        let (areas, per_area) = (grid.areas_sr(), grid.inverse_areas_per_sr());
        apply_limited(
            &sides,
            areas,
            per_area,
            &volume,
            0.3,
            &mut values,
            &mut ratio,
        );
        let change = (content(&values) - before) / before;
        assert!(change.abs() < 1e-14, "content changed by {change:.3e}");
        let least = values.iter().copied().fold(f64::INFINITY, f64::min);
        assert!(least >= 0.0, "a cell went to {least}");
        assert!(
            ratio.iter().any(|&r| r < 1.0),
            "no donor was limited: the test is idle"
        );
    }
}
