//! A level's cells laid out for the solve: each face padded by a ring of halo cells
//! (copies of the neighbouring faces' cells), its rows an odd stride apart, and the
//! whole level split by the parity of the padded index into two colour arrays.
//!
//! Why: with an odd stride a cell's four neighbours in the padded level have the other
//! parity, so they lie in the other colour's array at four offsets that are the same
//! for every cell of the level. A Gauss–Seidel half-sweep over one colour, the operator
//! and the residual are then each one loop over contiguous slices (no neighbour
//! indices, no rim cells taken one by one, no runs to set up), and the restriction and
//! the coarse correction walk face rows whose children are contiguous too.
//!
//! The halo is refreshed by runs ([`HaloRun`]): a face's side's halo cells of one
//! colour, and their sources along the neighbouring face's side, lie a constant step
//! apart in the split arrays, so each side and colour is one strided copy loop; on the
//! small levels, whose runs are short, by a flat list of the same copies
//! ([`FLAT_HALO_UP_TO`]).

use std::ops::Range;

use super::super::sides::{BOTTOM, CellSides, LEFT, RIGHT, TOP};

/// Of a level's two weight fields, the one holding each cell's RIGHT side's weight (and,
/// at the left halo column, the rim cells' LEFT seam weights).
pub(super) const RIGHT_W: usize = 0;
/// The one holding each cell's TOP side's weight (and, at the bottom halo row, the rim
/// cells' BOTTOM seam weights).
pub(super) const TOP_W: usize = 1;

/// The largest face size whose halo is refreshed copy by copy
/// ([`Layout::flat_halo_copies`]) rather than by runs: a run of `m/2` copies costs a
/// set-up of several copies' instructions, which on the small levels outweighs the
/// copies. Over `film_profile 64 0 9.81`'s 40 steps (bit-identical), against runs
/// everywhere's 677.1 M instructions and 14.04 M LL misses: up to 8, 674.3 M; up to 16,
/// 670.3 M and 14.06 M; up to 32, 668.4 M and 14.08 M; up to 64, 667.2 M but 14.16 M
/// (the finest level's pairs streamed).
pub(super) const FLAT_HALO_UP_TO: usize = 32;

/// A run of halo copies: `count` halo cells of one colour along one side of a face, at
/// `halo + i·halo_step` in the split arrays, each taking the value at
/// `source + i·source_step`.
///
/// Why runs: along a face's side the halo cells of one colour are every other padded
/// cell, and their sources every other cell along the neighbouring face's side, so both
/// advance by a constant step in the split arrays (a padded step of ±2 along a row,
/// ±`2·stride` along a column: ±1 or ±`stride` positions in one colour's array). A refresh is then a few tight loops
/// rather than a list of index pairs, each loaded and bounds-checked per copy.
///
/// # Guarantees
/// - `halo_step ≥ 1` and `count ≥ 1`; every position of the run lies in the split arrays.
/// - A run's sources all have one colour (a step of 2 padded cells keeps the parity).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct HaloRun {
    /// The first halo cell's position.
    pub(super) halo: u32,
    /// The step between consecutive halo cells' positions.
    pub(super) halo_step: u32,
    /// The first source's position.
    pub(super) source: u32,
    /// The step between consecutive sources' positions (negative where the neighbouring
    /// face's side runs the other way).
    pub(super) source_step: i32,
    /// The number of copies.
    pub(super) count: u32,
}

impl HaloRun {
    /// The run's copies, `[halo, source]` positions, in order.
    pub(super) fn copies(&self) -> impl Iterator<Item = [u32; 2]> + '_ {
        (0..self.count).map(|i| {
            let halo = self.halo + i * self.halo_step;
            let source = self.source as i64 + i64::from(i) * i64::from(self.source_step);
            [halo, source as u32]
        })
    }
}

/// A level's padded, colour-split layout.
///
/// # Guarantees
/// - `stride` is odd, so the padded index `f` of a cell and of each neighbour differ in
///   parity; colour `f & 1` holds it at [`Layout::index`]`(f)` = `(f & 1)·half + f/2`.
/// - [`Layout::sweep`]`[c]` covers every interior cell of colour `c`, and its
///   [`Layout::neighbour_offsets`] stay inside the other colour's array over it.
#[derive(Clone, Debug)]
pub(super) struct Layout {
    /// Cells along a face's side.
    pub(super) m: usize,
    /// Padded row length, odd: `m + 2` or `m + 3`.
    stride: usize,
    /// Padded cells of one face: `(m + 2)·stride`.
    face_len: usize,
    /// Length of each colour's array.
    pub(super) half: usize,
    /// Per colour, the positions in its array a sweep computes (its interior cells and
    /// the halo cells between them, whose results the next halo refresh overwrites).
    pub(super) sweep: [Range<usize>; 2],
    /// Each cell's position in the split arrays, in the grid's numbering
    /// (`face·m² + y·m + x`).
    pub(super) position: Vec<u32>,
    /// Per colour of the halo cell: the runs of copies that refresh the halo cells of
    /// that colour, one a face's side (see [`HaloRun`]); private, as the refresh relies
    /// on every position in them being inside the level ([`Layout::halo_runs`]).
    halos: [Vec<HaloRun>; 2],
    /// Per colour of the halo cell, where the level's runs are short (a face of at most
    /// [`FLAT_HALO_UP_TO`] cells), the same copies one by one as `[halo, source]`
    /// positions (empty elsewhere): a copy then costs a pair's load, where a run's set-up
    /// costs as much as several copies. Private, as [`Layout::halos`] is.
    flat_halos: [Vec<[u32; 2]>; 2],
    /// Per colour, how many of its [`Layout::halos`] (they come first) and of its copies
    /// (in [`Layout::flat_halos`], first too) take their values from the other colour's
    /// cells: after a half-sweep of that other colour, the only stale ones of this colour.
    from_other: [usize; 2],
    flat_from_other: [usize; 2],
    /// Per cell in the grid's numbering, the cell across each side.
    pub(super) neighbour: Vec<[u32; 4]>,
}

impl Layout {
    /// The layout of a level of `m` cells a face whose cells have the neighbours
    /// `neighbour` (per cell in the grid's numbering, per side [`LEFT`]…[`TOP`]).
    ///
    /// # Panics
    /// If `neighbour` does not hold `6·m²` cells.
    pub(super) fn new(m: usize, neighbour: Vec<[u32; 4]>) -> Self {
        assert_eq!(
            neighbour.len(),
            6 * m * m,
            "neighbours of a level of face {m}"
        );
        let stride = if m % 2 == 0 { m + 3 } else { m + 2 };
        let face_len = (m + 2) * stride;
        let half = (6 * face_len).div_ceil(2);
        let first = stride + 1;
        let last = 5 * face_len + m * stride + m;
        // Each colour's first and last interior cell (the first two and the last two
        // interior cells have both parities).
        let sweep = [0, 1].map(|c| {
            let lo = if first & 1 == c { first } else { first + 1 };
            let hi = if last & 1 == c { last } else { last - 1 };
            (lo >> 1)..(hi >> 1) + 1
        });
        let mut layout = Self {
            m,
            stride,
            face_len,
            half,
            sweep,
            position: Vec::with_capacity(6 * m * m),
            halos: [Vec::new(), Vec::new()],
            flat_halos: [Vec::new(), Vec::new()],
            from_other: [0, 0],
            flat_from_other: [0, 0],
            neighbour,
        };
        for c in 0..6 * m * m {
            let p = layout.index(layout.padded(c));
            layout.position.push(p as u32);
        }
        layout.halos = layout.runs_of_halo_copies();
        // Each colour's runs from the other colour's cells first (a run's sources have
        // one colour; the order of the copies is free, as no halo cell is a source).
        for c in 0..2 {
            let half = layout.half as u32;
            let from_other = |run: &HaloRun| (run.source >= half) != (c == 1);
            layout.halos[c].sort_by_key(|run| !from_other(run));
            layout.from_other[c] = layout.halos[c].iter().filter(|r| from_other(r)).count();
        }
        let len = layout.len() as i64;
        for run in layout.halos.iter().flatten() {
            let last = i64::from(run.count) - 1;
            let halo_end = i64::from(run.halo) + last * i64::from(run.halo_step);
            let source_end = i64::from(run.source) + last * i64::from(run.source_step);
            assert!(
                run.count >= 1 && halo_end < len && (0..len).contains(&source_end),
                "halo run {run:?} outside a level of length {len}"
            );
        }
        if m <= FLAT_HALO_UP_TO {
            layout.flat_halos = layout
                .halos
                .each_ref()
                .map(|runs| runs.iter().flat_map(HaloRun::copies).collect());
        }
        layout.flat_from_other = [0, 1].map(|c| {
            let runs = &layout.halos[c][..layout.from_other[c]];
            runs.iter().map(|run| run.count as usize).sum()
        });
        layout
    }

    /// The runs of copies that refresh the halo cells of colour `c`.
    ///
    /// # Guarantees
    /// Every halo and source position of every run is below [`Layout::len`] (checked
    /// when the layout was built; the kernels index by them unchecked); no halo cell is
    /// a source.
    pub(super) fn halo_runs(&self, c: usize) -> &[HaloRun] {
        &self.halos[c]
    }

    /// The first of [`Layout::halo_runs`]`(c)`, those whose sources are cells of the other
    /// colour (as [`Layout::halo_runs`]).
    pub(super) fn halo_runs_from_other(&self, c: usize) -> &[HaloRun] {
        &self.halos[c][..self.from_other[c]]
    }

    /// The first of [`Layout::flat_halo_copies`]`(c)`, those whose sources are cells of
    /// the other colour (as [`Layout::flat_halo_copies`]).
    pub(super) fn flat_halo_copies_from_other(&self, c: usize) -> &[[u32; 2]] {
        let copies = &self.flat_halos[c];
        &copies[..self.flat_from_other[c].min(copies.len())]
    }

    /// The copies of [`Layout::halo_runs`] one by one, `[halo, source]`, where the level
    /// holds them so (a face of at most [`FLAT_HALO_UP_TO`] cells; else empty).
    ///
    /// # Guarantees
    /// As [`Layout::halo_runs`]: every position is below [`Layout::len`].
    pub(super) fn flat_halo_copies(&self, c: usize) -> &[[u32; 2]] {
        &self.flat_halos[c]
    }

    /// The layout of the grid `sides` describes.
    pub(super) fn of_grid(sides: &CellSides) -> Self {
        Self::new(sides.n(), sides.neighbour.clone())
    }

    /// The layout of the level coarser than this one (`m` halved).
    ///
    /// # Panics
    /// If `m` is odd.
    pub(super) fn coarser(&self) -> Self {
        let (m, half_m) = (self.m, self.m / 2);
        assert!(
            m % 2 == 0,
            "a level of odd face size {m} has no coarser one"
        );
        let parent = |c: usize| {
            let (face, rest) = (c / (m * m), c % (m * m));
            face * half_m * half_m + (rest / m / 2) * half_m + (rest % m) / 2
        };
        let mut neighbour = vec![[0u32; 4]; 6 * half_m * half_m];
        for (c, sides) in neighbour.iter_mut().enumerate() {
            let (face, rest) = (c / (half_m * half_m), c % (half_m * half_m));
            let child = face * m * m + 2 * (rest / half_m) * m + 2 * (rest % half_m);
            // A child on each side: the bottom-left one for LEFT and BOTTOM, the
            // top-right one for RIGHT and TOP.
            let far = child + m + 1;
            for (k, from) in [(LEFT, child), (BOTTOM, child), (RIGHT, far), (TOP, far)] {
                sides[k] = parent(self.neighbour[from][k] as usize) as u32;
            }
        }
        Self::new(half_m, neighbour)
    }

    /// Padded index of cell `c` (grid numbering).
    fn padded(&self, c: usize) -> usize {
        let m = self.m;
        let (face, rest) = (c / (m * m), c % (m * m));
        face * self.face_len + (rest / m + 1) * self.stride + rest % m + 1
    }

    /// Padded row length, odd: a face row's step in padded indices, and two rows' step in
    /// each colour's array.
    pub(super) fn stride(&self) -> usize {
        self.stride
    }

    /// Position in the split arrays of padded index `f`.
    pub(super) fn index(&self, f: usize) -> usize {
        (f & 1) * self.half + (f >> 1)
    }

    /// The first position of face `face` in each colour's array (`face` 6: the end):
    /// where a face's padded cells have an even count, the same in both colours, and
    /// every face's cells lie at face 0's positions plus this
    /// ([`Layout::faces_alike`]).
    pub(super) fn face_start(&self, face: usize) -> usize {
        face * self.face_len / 2
    }

    /// Whether every face's cells lie in both colours' arrays at face 0's positions plus
    /// [`Layout::face_start`]: a face's padded cells have an even count (`m` even).
    pub(super) fn faces_alike(&self) -> bool {
        self.face_len % 2 == 0
    }

    /// Padded index of face `face`'s padded row `row`, column `col` (row and column 0 are
    /// the halo before the face's first row and column).
    pub(super) fn padded_at(&self, face: usize, row: usize, col: usize) -> usize {
        face * self.face_len + row * self.stride + col
    }

    /// Of cell `c` (grid numbering), per side [`LEFT`]…[`TOP`], the weight field
    /// ([`RIGHT_W`] or [`TOP_W`]) and the position in it that hold that side's weight: the
    /// cell's own entry for RIGHT and TOP, its left or lower neighbour's in the padded
    /// level (a halo cell on the rim) for LEFT and BOTTOM.
    pub(super) fn side_weights(&self, c: usize) -> [(usize, usize); 4] {
        let f = self.padded(c);
        [
            (RIGHT_W, self.index(f - 1)),
            (RIGHT_W, self.index(f)),
            (TOP_W, self.index(f - self.stride)),
            (TOP_W, self.index(f)),
        ]
    }

    /// Whether position `p` of the split arrays holds a cell (not a halo or padding cell).
    #[cfg(test)]
    pub(super) fn is_cell(&self, p: usize) -> bool {
        self.position.contains(&(p as u32))
    }

    /// Length of a field on the level: both colours' arrays.
    pub(super) fn len(&self) -> usize {
        2 * self.half
    }

    /// For cells of colour `c`, the offsets of their LEFT, RIGHT, BOTTOM and TOP
    /// neighbours in the other colour's array, relative to their own position in theirs.
    pub(super) fn neighbour_offsets(&self, c: usize) -> [isize; 4] {
        let (up, down) = (self.stride.div_ceil(2) as isize, (self.stride / 2) as isize);
        if c == 0 {
            [-1, 0, -up, down]
        } else {
            [0, 1, -down, up]
        }
    }

    /// The halo runs by the colour of the halo cell: along each side of each face, each
    /// rim cell's halo neighbour across the seam takes that neighbour's value; the
    /// copies of one colour along one side, in order along it, merged into runs of
    /// constant steps (one a side and colour, where the seams are regular, as they are:
    /// a run is only cut where the steps change).
    fn runs_of_halo_copies(&self) -> [Vec<HaloRun>; 2] {
        let m = self.m;
        let step = [-1, 1, -(self.stride as isize), self.stride as isize];
        let mut runs: [Vec<HaloRun>; 2] = [Vec::new(), Vec::new()];
        for face in 0..6 {
            for (k, &step) in step.iter().enumerate() {
                let mut open: [Option<HaloRun>; 2] = [None, None];
                for i in 0..m {
                    // The i-th rim cell along side k.
                    let (x, y) = match k {
                        LEFT => (0, i),
                        RIGHT => (m - 1, i),
                        BOTTOM => (i, 0),
                        _ => (i, m - 1),
                    };
                    let c = face * m * m + y * m + x;
                    let halo = (self.padded(c) as isize + step) as usize;
                    let source = self.padded(self.neighbour[c][k] as usize);
                    let (halo_at, source_at) = (self.index(halo), self.index(source));
                    let colour = halo & 1;
                    match &mut open[colour] {
                        Some(run) if run.count == 1 && halo_at > run.halo as usize => {
                            run.halo_step = (halo_at - run.halo as usize) as u32;
                            run.source_step = (source_at as i64 - i64::from(run.source)) as i32;
                            run.count = 2;
                        }
                        Some(run)
                            if run.count > 1
                                && halo_at as i64
                                    == i64::from(run.halo)
                                        + i64::from(run.count * run.halo_step)
                                && source_at as i64
                                    == i64::from(run.source)
                                        + i64::from(run.count) * i64::from(run.source_step) =>
                        {
                            run.count += 1;
                        }
                        slot => {
                            runs[colour].extend(slot.take());
                            *slot = Some(HaloRun {
                                halo: halo_at as u32,
                                halo_step: 1,
                                source: source_at as u32,
                                source_step: 1,
                                count: 1,
                            });
                        }
                    }
                }
                for (colour, run) in open.into_iter().enumerate() {
                    runs[colour].extend(run);
                }
            }
        }
        runs
    }

    /// The halo copies, one by one, by the colour of the halo cell: each rim cell's halo neighbour on
    /// a side across a seam takes that neighbour's value.
    #[cfg(test)]
    fn halo_copies(&self) -> [Vec<[u32; 2]>; 2] {
        let m = self.m;
        let step = [-1, 1, -(self.stride as isize), self.stride as isize];
        let mut halos = [Vec::new(), Vec::new()];
        for c in 0..6 * m * m {
            let (x, y) = (c % m, (c / m) % m);
            let on_rim = [x == 0, x + 1 == m, y == 0, y + 1 == m];
            for k in 0..4 {
                if !on_rim[k] {
                    continue;
                }
                let halo = (self.padded(c) as isize + step[k]) as usize;
                let source = self.padded(self.neighbour[c][k] as usize);
                let pair = [self.index(halo) as u32, self.index(source) as u32];
                halos[halo & 1].push(pair);
            }
        }
        halos
    }

    /// The first fine row pair of the coarse cells of coarse face `face`, row `y`
    /// (0-based), as the fine level lays it out: for fine row `2y + j`, the positions of
    /// the children `(2x, ·)` and `(2x + 1, ·)` of coarse cell `x = 0` (consecutive
    /// coarse cells' children follow at consecutive positions in each colour).
    pub(super) fn children_of_row(&self, face: usize, y: usize, j: usize) -> [usize; 2] {
        let f = face * self.face_len + (2 * y + j + 1) * self.stride + 1;
        [self.index(f), self.index(f + 1)]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::film_flow::grid::CubeSphere;

    /// Every cell reads, at its four neighbour offsets in the other colour's array, the
    /// grid's neighbour on that side: the cell itself inside a face, or a halo cell
    /// whose refresh copies that neighbour; and its LEFT and BOTTOM weights at the same
    /// positions of the weight fields, where inside a face the neighbour keeps that
    /// edge's weight as its own RIGHT or TOP one; on every level of the hierarchy's sizes.
    #[test]
    fn each_cell_reads_its_grid_neighbours_through_the_offsets_and_the_halo() {
        for n in [1, 2, 3, 6, 16] {
            let sides = CellSides::new(&CubeSphere::new(n));
            let mut level = Layout::of_grid(&sides);
            loop {
                let mut copies = std::collections::HashMap::new();
                for [halo, source] in level.halos.iter().flatten().flat_map(HaloRun::copies) {
                    assert!(copies.insert(halo, source).is_none(), "halo {halo} twice");
                }
                for (c, &p) in level.position.iter().enumerate() {
                    let p = p as usize;
                    let colour = p / level.half;
                    let at = p % level.half;
                    assert!(level.sweep[colour].contains(&at), "n {n} cell {c}");
                    let offsets = level.neighbour_offsets(colour);
                    let weights = level.side_weights(c);
                    for (k, offset) in offsets.into_iter().enumerate() {
                        let read = (1 - colour) * level.half + (at as isize + offset) as usize;
                        let read = read as u32;
                        let value_of = copies.get(&read).copied().unwrap_or(read);
                        let j = level.neighbour[c][k] as usize;
                        let expected = level.position[j];
                        assert_eq!(value_of, expected, "m {} cell {c} side {k}", level.m);
                        // The side's weight: the cell's own entry, or the entry at the
                        // position its neighbour's value is read from, which is the
                        // neighbour's own entry for the same edge inside a face, a
                        // halo cell's across a seam.
                        let field = [RIGHT_W, RIGHT_W, TOP_W, TOP_W][k];
                        let own = [read as usize, p, read as usize, p][k];
                        assert_eq!(weights[k], (field, own), "m {} cell {c} side {k}", level.m);
                        if k == LEFT || k == BOTTOM {
                            let back = [RIGHT, LEFT, TOP, BOTTOM][k];
                            let inside = read == expected;
                            assert_eq!(inside, !copies.contains_key(&read), "cell {c} side {k}");
                            if inside {
                                assert_eq!(level.side_weights(j)[back], weights[k], "cell {c}");
                            }
                        }
                    }
                }
                if level.m % 2 == 1 || level.m <= 1 {
                    break;
                }
                level = level.coarser();
            }
        }
    }

    /// A refresh of either colour, whether copy by copy ([`Layout::flat_halo_copies`], on
    /// a face of at most [`FLAT_HALO_UP_TO`] cells) or by runs, leaves each halo cell of
    /// that colour its source's value and every other position as it was (a refresh
    /// from the other colour: each whose source is of the other colour), on every
    /// level of the hierarchy's sizes; and the levels up to that size hold their copies
    /// one by one, the others not.
    #[test]
    fn a_refresh_copies_each_halo_cells_source() {
        for n in [1, 3, 6, 16, 64] {
            let sides = CellSides::new(&CubeSphere::new(n));
            let mut level = Layout::of_grid(&sides);
            loop {
                for colour in 0..2 {
                    let flat = !level.flat_halo_copies(colour).is_empty();
                    assert_eq!(flat, level.m <= FLAT_HALO_UP_TO, "m {}", level.m);
                    let mut field: Vec<f32> = (0..level.len()).map(|p| p as f32 + 0.5).collect();
                    let mut expected = field.clone();
                    for [halo, source] in &level.halo_copies()[colour] {
                        expected[*halo as usize] = expected[*source as usize];
                    }
                    let mut from_other = field.clone();
                    super::super::kernels::refresh(&level, colour, &mut field);
                    assert_eq!(field, expected, "n {n} m {} colour {colour}", level.m);
                    let mut expected = from_other.clone();
                    for [halo, source] in &level.halo_copies()[colour] {
                        if (*source as usize >= level.half) != (colour == 1) {
                            expected[*halo as usize] = expected[*source as usize];
                        }
                    }
                    super::super::kernels::refresh_from_other(&level, colour, &mut from_other);
                    assert_eq!(from_other, expected, "n {n} m {} colour {colour}", level.m);
                }
                if level.m % 2 == 1 || level.m <= 1 {
                    break;
                }
                level = level.coarser();
            }
        }
    }

    /// The halo runs make exactly the copies that the one-by-one list makes (each halo
    /// cell once, from the same source, in the same colour's list), on every level of
    /// the hierarchy's sizes; and a side's copies of one colour make one run, as the
    /// steps along a seam are constant.
    #[test]
    fn halo_runs_make_the_copies_one_by_one() {
        for n in [1, 2, 3, 5, 6, 16, 64] {
            let sides = CellSides::new(&CubeSphere::new(n));
            let mut level = Layout::of_grid(&sides);
            loop {
                let singles = level.halo_copies();
                for (colour, mut expected) in singles.into_iter().enumerate() {
                    let mut from_runs: Vec<[u32; 2]> = level.halos[colour]
                        .iter()
                        .flat_map(HaloRun::copies)
                        .collect();
                    from_runs.sort_unstable();
                    expected.sort_unstable();
                    assert_eq!(from_runs, expected, "n {n} m {} colour {colour}", level.m);
                    for run in &level.halos[colour] {
                        assert!(run.count >= 1 && run.halo_step >= 1, "{run:?}");
                        let last = run.copies().last().expect("a copy");
                        assert!(last.iter().all(|&p| (p as usize) < level.len()), "{run:?}");
                        let half = level.half as u32;
                        for [halo, source] in run.copies() {
                            assert!(
                                !level.is_cell(halo as usize) && level.is_cell(source as usize)
                            );
                        }
                        assert!(run.copies().all(|[_, s]| (s < half) == (run.source < half)));
                    }
                    assert!(
                        level.halos[colour].len() <= 24,
                        "n {n} m {} colour {colour}: {} runs",
                        level.m,
                        level.halos[colour].len()
                    );
                }
                if level.m % 2 == 1 || level.m <= 1 {
                    break;
                }
                level = level.coarser();
            }
        }
    }
}
