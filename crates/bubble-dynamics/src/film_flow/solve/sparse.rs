//! The coarsest level's direct solve: a sparse Cholesky factor of its matrix, the cells
//! taken in a minimum-degree order. The order and the factor's pattern (its fill
//! included) are found once a hierarchy ([`Pattern::new`]), the factor's numbers once a
//! system ([`Pattern::factor`]).
//!
//! Why sparse: a level's matrix has four neighbours a row, and in a minimum-degree order
//! its factor stays sparse: at 6·4² = 96 cells it holds 712 entries below the diagonal
//! (a dense one 4560) and takes about 4 k multiply-adds to make (a dense one 147 k). The
//! hierarchy still stops at 2 cells a face ([`COARSEST_FACE`](super::COARSEST_FACE)):
//! stopping at 4 took as many instructions but more time, the triangular solves being
//! chains of dependent operations.

use super::kernels::Stencil;
use super::layout::Layout;

/// Where an entry of the matrix goes in the factor's numbers: nowhere (the edge's entry
/// is held in the other cell's column).
const NOWHERE: u32 = u32::MAX;

/// A level's elimination order and its Cholesky factor's pattern.
///
/// # Guarantees
/// - `order` is a permutation of the level's cells; `start` is increasing, of `n + 1`
///   entries, and each column's `rows` are increasing and after the column.
/// - The pattern holds the factor's every nonzero (the elimination's fill), so that the
///   left-looking factorisation writes every update into a column's own rows.
#[derive(Clone, Debug)]
pub(super) struct Pattern {
    /// The cells (the level's grid numbering) in the order they are eliminated.
    order: Vec<u32>,
    /// Per column (in the elimination order), the cell's position in the level's split
    /// arrays (the right-hand side's and the answer's).
    at: Vec<u32>,
    /// Per column, where its entries below the diagonal start in `rows` (and the
    /// factor's numbers); `n + 1` entries.
    start: Vec<u32>,
    /// Each entry's row, in the elimination order.
    rows: Vec<u32>,
    /// Per column `j`, the entries `L[j][k]` (`k < j`) of the earlier columns, as
    /// `[entry, end of column k]`, in increasing `k` ([`Pattern::updates_start`]).
    updates: Vec<[u32; 2]>,
    /// Per column, where its updates start in `updates`; `n + 1` entries.
    updates_start: Vec<u32>,
    /// Per cell (the elimination order) and side, the entry its edge's weight goes to
    /// below the diagonal, or [`NOWHERE`] where the neighbour comes first (its column
    /// holds it).
    entry: Vec<[u32; 4]>,
}

/// A system's factor on a [`Pattern`]: the diagonal and the entries below it.
#[derive(Clone, Debug, Default)]
pub(super) struct Factor {
    /// `L[j][j]`, per column.
    diagonal: Vec<f64>,
    /// The entries below the diagonal, as [`Pattern::rows`] names them.
    values: Vec<f64>,
    /// One column's numbers while it is made, by row (a whole column's length).
    column: Vec<f64>,
}

impl Pattern {
    /// The minimum-degree order of `layout`'s cells (ties to the lower cell) and the
    /// pattern of the factor in it, from an elimination of the cells' graph.
    pub(super) fn new(layout: &Layout) -> Self {
        let n = layout.position.len();
        let mut graph: Vec<Vec<u32>> = layout
            .neighbour
            .iter()
            .enumerate()
            .map(|(c, sides)| {
                let mut adjacent: Vec<u32> =
                    sides.iter().copied().filter(|&j| j as usize != c).collect();
                adjacent.sort_unstable();
                adjacent.dedup();
                adjacent
            })
            .collect();
        let mut alive = vec![true; n];
        let mut order = Vec::with_capacity(n);
        let mut adjacent_when_eliminated = Vec::with_capacity(n);
        for _ in 0..n {
            let next = (0..n)
                .filter(|&c| alive[c])
                .min_by_key(|&c| (graph[c].len(), c))
                .expect("a cell left");
            let clique = std::mem::take(&mut graph[next]);
            for &a in &clique {
                let a = a as usize;
                let merged = &mut graph[a];
                merged.retain(|&j| j as usize != next);
                merged.extend(clique.iter().copied().filter(|&j| j as usize != a));
                merged.sort_unstable();
                merged.dedup();
            }
            alive[next] = false;
            order.push(next as u32);
            adjacent_when_eliminated.push(clique);
        }
        let mut rank = vec![0u32; n];
        for (j, &c) in order.iter().enumerate() {
            rank[c as usize] = j as u32;
        }
        let (mut start, mut rows) = (vec![0u32], Vec::new());
        for clique in &adjacent_when_eliminated {
            let mut column: Vec<u32> = clique.iter().map(|&c| rank[c as usize]).collect();
            column.sort_unstable();
            rows.extend(column);
            start.push(rows.len() as u32);
        }
        let mut by_row: Vec<Vec<[u32; 2]>> = vec![Vec::new(); n];
        for k in 0..n {
            for e in start[k]..start[k + 1] {
                by_row[rows[e as usize] as usize].push([e, start[k + 1]]);
            }
        }
        let mut updates_start = vec![0u32];
        let mut updates = Vec::new();
        for row in by_row {
            updates.extend(row);
            updates_start.push(updates.len() as u32);
        }
        let entry = order
            .iter()
            .enumerate()
            .map(|(j, &c)| {
                let column = &rows[start[j] as usize..start[j + 1] as usize];
                layout.neighbour[c as usize].map(|other| {
                    let i = rank[other as usize];
                    // Found only where the neighbour comes later (every row is).
                    column
                        .binary_search(&i)
                        .map_or(NOWHERE, |q| start[j] + q as u32)
                })
            })
            .collect();
        let at = order.iter().map(|&c| layout.position[c as usize]).collect();
        Self {
            order,
            at,
            start,
            rows,
            updates,
            updates_start,
            entry,
        }
    }

    /// Cells of the level.
    pub(super) fn cells(&self) -> usize {
        self.order.len()
    }

    /// Each column's cell's position in the level's split arrays.
    pub(super) fn positions(&self) -> &[u32] {
        &self.at
    }

    /// The factor of `scale·(diag(mass) + L_w)`, the system held in `layout`'s fields
    /// (`mass` at the cells' positions, the side weights where
    /// [`Layout::side_weights`] names), into `factor`. Left-looking: each column from
    /// its matrix entries less each earlier column's part, gathered by row in
    /// [`Factor::column`]. A pivot is kept at or above `f64::MIN_POSITIVE`.
    pub(super) fn factor(
        &self,
        layout: &Layout,
        (mass, w): (&[f64], &Stencil<f64>),
        scale: f64,
        factor: &mut Factor,
    ) {
        let n = self.cells();
        factor.diagonal.resize(n, 0.0);
        factor.values.clear();
        factor.values.resize(self.rows.len(), 0.0);
        factor.column.resize(n, 0.0);
        // The matrix: each cell's diagonal from its side weights (an edge's weight is the
        // same seen from either cell), its entries below the diagonal in its column.
        for (j, (&c, entries)) in self.order.iter().zip(&self.entry).enumerate() {
            let c = c as usize;
            let mut d = scale * mass[layout.position[c] as usize];
            for ((field, q), &e) in layout.side_weights(c).into_iter().zip(entries) {
                let wk = scale * w[field][q];
                d += wk;
                if e != NOWHERE {
                    factor.values[e as usize] -= wk;
                }
            }
            factor.diagonal[j] = d;
        }
        let Factor {
            diagonal,
            values,
            column,
        } = factor;
        for (j, pivot) in diagonal[..n].iter_mut().enumerate() {
            let own = self.start[j] as usize..self.start[j + 1] as usize;
            let rows = &self.rows[own.clone()];
            for (&i, v) in rows.iter().zip(&values[own.clone()]) {
                column[i as usize] = *v;
            }
            let mut d = *pivot;
            let updates = self.updates_start[j] as usize..self.updates_start[j + 1] as usize;
            for &[e, end] in &self.updates[updates] {
                let (e, end) = (e as usize, end as usize);
                let ljk = values[e];
                d -= ljk * ljk;
                for (&i, lik) in self.rows[e + 1..end].iter().zip(&values[e + 1..end]) {
                    column[i as usize] -= lik * ljk;
                }
            }
            let d = d.max(f64::MIN_POSITIVE).sqrt();
            *pivot = d;
            for (&i, v) in rows.iter().zip(&mut values[own]) {
                *v = column[i as usize] / d;
            }
        }
    }

    /// Solves `L Lᵀ x = b` in place in `x` (in the elimination order) with `factor`:
    /// forwards a column at a time, backwards a column of `L` (a row of `Lᵀ`) at a time.
    pub(super) fn solve(&self, factor: &Factor, x: &mut [f64]) {
        let n = self.cells();
        let (diagonal, values, x) = (&factor.diagonal[..n], &factor.values[..], &mut x[..n]);
        for j in 0..n {
            let xj = x[j] / diagonal[j];
            x[j] = xj;
            let own = self.start[j] as usize..self.start[j + 1] as usize;
            for (&i, l) in self.rows[own.clone()].iter().zip(&values[own]) {
                x[i as usize] -= l * xj;
            }
        }
        for j in (0..n).rev() {
            let own = self.start[j] as usize..self.start[j + 1] as usize;
            let mut s = x[j];
            for (&i, l) in self.rows[own.clone()].iter().zip(&values[own]) {
                s -= l * x[i as usize];
            }
            x[j] = s / diagonal[j];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::dense::{dense_cholesky, dense_solve};
    use super::*;
    use crate::film_flow::grid::CubeSphere;
    use crate::film_flow::sides::CellSides;

    /// A level of `m` cells a face with a mass term and edge weights in `layout`'s fields
    /// that differ from cell to cell and edge to edge (an edge's the same from both of
    /// its cells).
    fn system(m: usize) -> (Layout, Vec<f64>, Stencil<f64>) {
        let sides = CellSides::new(&CubeSphere::new(m));
        let layout = Layout::of_grid(&sides);
        let mut mass = vec![0.0; layout.len()];
        let mut w: Stencil<f64> = [vec![0.0; layout.len()], vec![0.0; layout.len()]];
        for c in 0..layout.position.len() {
            mass[layout.position[c] as usize] = 1.0 + (c % 7) as f64 * 0.25;
            for ((field, q), e) in layout.side_weights(c).into_iter().zip(sides.edge[c]) {
                w[field][q] = 300.0 + (e as usize * 31 % 17) as f64 * 40.0;
            }
        }
        (layout, mass, w)
    }

    /// The sparse factor solves as the dense one does, to rounding (1e-12 of the
    /// answer's largest), at 1, 2, 4 and 8 cells a face, from a right-hand side in the
    /// cells' own numbering; and its pattern is a permutation with columns in order.
    #[test]
    fn the_sparse_solve_is_the_dense_solve() {
        for m in [1, 2, 4, 8] {
            let (layout, mass, w) = system(m);
            let n = layout.position.len();
            let pattern = Pattern::new(&layout);
            let mut sorted = pattern.order.clone();
            sorted.sort_unstable();
            assert!(sorted.iter().enumerate().all(|(c, &o)| c == o as usize));
            for j in 0..n {
                let column =
                    &pattern.rows[pattern.start[j] as usize..pattern.start[j + 1] as usize];
                assert!(column.windows(2).all(|p| p[0] < p[1]));
                assert!(column.iter().all(|&i| i as usize > j));
            }
            let scale = 0.125;
            let mut factor = Factor::default();
            pattern.factor(&layout, (&mass, &w), scale, &mut factor);
            let mut dense = Vec::new();
            dense_cholesky(&layout, &mass, &w, scale, &mut dense);
            let b: Vec<f64> = (0..n).map(|c| ((c * 13) % 9) as f64 - 4.0).collect();
            let mut expected = vec![0.0; n];
            dense_solve(&dense, n, &b, &mut expected);
            let mut x: Vec<f64> = pattern.order.iter().map(|&c| b[c as usize]).collect();
            pattern.solve(&factor, &mut x);
            let largest = expected.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            for (j, &c) in pattern.order.iter().enumerate() {
                let err = (x[j] - expected[c as usize]).abs();
                assert!(err <= 1e-12 * largest, "m {m} cell {c}: {err:e}");
            }
        }
    }

    /// A minimum-degree order keeps the fill small: at 4 and 8 cells a face, 712 and
    /// 4719 entries below the diagonal (a dense factor holds 4560 and 73 536).
    #[test]
    fn the_order_keeps_the_fill_small() {
        for (m, entries) in [(4, 712), (8, 4719)] {
            let (layout, _, _) = system(m);
            assert_eq!(Pattern::new(&layout).rows.len(), entries, "m {m}");
        }
    }
}
