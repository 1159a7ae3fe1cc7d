//! Each cell's four sides in its face's own directions, for the passes that work cell by
//! cell in the face-structured layout ([`FaceLayout`]): inside a face a cell's
//! neighbours and edges sit at fixed offsets, read as slices; the cells on a face's rim
//! look theirs up here.
//!
//! Why cell by cell: an edge-by-edge pass scatters into both cells through index arrays,
//! which no compiler vectorises; a cell that gathers its four sides from slices does.

use super::grid::{CubeSphere, FACE_BASES, FaceLayout};

/// The side towards −x in the face's own coordinates (the cell's x-edge).
pub(crate) const LEFT: usize = 0;
/// The side towards +x (the next cell's x-edge).
pub(crate) const RIGHT: usize = 1;
/// The side towards −y (the cell's y-edge).
pub(crate) const BOTTOM: usize = 2;
/// The side towards +y (the y-edge of the cell above).
pub(crate) const TOP: usize = 3;
/// Whether the cell is the `a` cell (the normal points away from it) of the edge on each
/// side, inside a face.
pub(crate) const IS_A: [bool; 4] = [false, true, false, true];

/// Every cell's neighbour and edge on each side, and the sides each seam edge joins.
///
/// # Guarantees
/// - `neighbour[c][k]` and `edge[c][k]` are the cell across side `k` of cell `c` and the
///   edge between them; `is_a[c][k]` says whether `c` is that edge's `a` cell.
/// - Inside a face these follow [`FaceLayout`]: `c ∓ 1` and `c ∓ n` across the x and y
///   sides, with [`IS_A`].
/// - `seam_sides[e − first_seam_edge]` is `[side of a, side of b]` of seam edge `e`.
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
    /// Per seam edge: the side it is of its `a` cell and of its `b` cell.
    pub(crate) seam_sides: Vec<[u8; 2]>,
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
        let mut seam_sides = Vec::new();
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
                seam_sides.push(sides);
            }
        }
        Self {
            layout,
            neighbour,
            edge,
            is_a,
            seam_sides,
        }
    }

    /// Cells along a face edge.
    pub(crate) fn n(&self) -> usize {
        self.layout.n
    }
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
                    assert_eq!(sides.is_a[c], IS_A, "cell {c}");
                }
            }
            assert_eq!(sides.seam_sides.len(), 12 * n);
        }
    }
}
