//! Per-edge values (volumes, fluxes) gathered by the cells, a band of face rows at a
//! time: a pass that gives each edge's value ([`EdgeValues`]) fills a band's edges into a
//! small window laid out by the band's cells, the seam edges around the face padded on
//! ([`FaceWindow`]), and the cells gather their four sides from it as slices a row or
//! two behind, while it is in cache. The bands advance on all six faces together, so
//! the face-0 constants of a band (the faces share them, [`super::face_geometry`]) are
//! read once and reused by the other five faces from cache.
//!
//! Why so: the passes wrote each edge's value to a per-edge array (0.4 MB at n = 64) and
//! gathered it back from beyond the core's 1 MB L2, the x-edges spread to one a cell on
//! the way (a face's are `n − 1` a row). Taken a face at a time instead, a face's
//! scratch and its share of the constants (over 1 MB for the thickness transport) did
//! not fit in L2 either; a row at a time, each row's slices cost more to set up than
//! its cells to compute. Every edge's value is still one number, taken from one cell
//! and given to the other, so what moves is conserved to rounding, and each cell sums
//! its sides in the order it did (the same bits).
//!
//! The limited apply ([`apply_limited`]) needs each donor's factor from all its sides
//! before a cell can gather its neighbours': a face's cells take theirs from the rows
//! around, but a rim cell's neighbour across a seam lies on another face, so the rim's
//! gathers wait until every face's factors are in ([`RimValues`]).

use std::ops::Range;

use super::flow::MAX_OUTFLOW_FRACTION;
use super::grid::CubeSphere;
use super::sides::{CellSides, CellSpan, EdgeRun, INFLOW, Seams};
use crate::avx2::with_avx2;

/// Face rows a band takes ([`FaceWindow`]).
///
/// Why 16: the bigger a band, the fewer its set-ups and carried rows, but the more of
/// the face-0 constants (the thickness transport's, about 13 KB a row at n = 64) it
/// reads for the six faces to reuse from L2. At n = 64, 8, 12, 16 and 32 rows gave 758,
/// 751, 746 and 740 M instructions and 22.65, 22.70, 22.76 and 22.95 M LL misses over
/// 40 steps (`film_profile 64 0 9.81`, before the transport's Courant number joined its
/// first sub-step); 16 keeps a band's constants at 0.2 MB at n = 64 and 0.4 MB at
/// n = 128. A constant: taken from `n` at run time, the bands' loops no longer
/// vectorised (850 M instructions at 32 rows).
pub(crate) const BAND: usize = 16;

/// Rows a band's window keeps from the band before: the limited apply gathers a row
/// two behind the edges just in, from the factors of the rows either side.
const BEHIND: usize = 3;

/// A pass that gives a value to every edge (a volume, a flux), a run of edges at a time,
/// for the gathers by bands ([`net_inflow`], [`apply_limited`]): they ask for the seam
/// edges' values first, then, face by face for each band of [`BAND`] rows from the
/// first, for the band's rows ([`Self::rows`]), each row's x-edges
/// ([`CellSides::x_run`]) and the y-edges below the band's rows ([`CellSides::y_run`]).
/// `cells` is the cell field the gather moves or the values are taken from: when a pass
/// is asked for a band, the gather has changed no cell of it or of the two rows before
/// it, nor any rim cell.
pub(crate) trait EdgeValues {
    /// The seam edges' values into `out` (`seams.len` long); asked first.
    fn seams(&mut self, seams: Seams, cells: &[f64], out: &mut [f64]);
    /// Readies face `face`'s band of rows `rows` before its runs (the thickness
    /// transport takes their limited rises here); nothing by default.
    #[inline(always)]
    fn rows(&mut self, _face: usize, _rows: Range<usize>, _cells: &[f64]) {}
    /// `run`'s values into `out` (`run.len` long, or longer: an x-run's has one place
    /// more, which a pass may fill with anything, so as to run a whole number of vectors
    /// where `n` is a multiple of four: the window's next left pad, written after it);
    /// `rows` are the face rows of its `b` cells.
    fn run(&mut self, run: EdgeRun, rows: Range<usize>, cells: &[f64], out: &mut [f64]);
}

/// A per-edge array's values as an [`EdgeValues`] (the tests' volumes); NaN into any
/// place of `out` past the run's, as a padded pass may put anything there.
#[cfg(test)]
pub(crate) struct FromArray<'a>(pub(crate) &'a [f64]);

#[cfg(test)]
impl EdgeValues for FromArray<'_> {
    #[inline(always)]
    fn seams(&mut self, seams: Seams, _cells: &[f64], out: &mut [f64]) {
        out.copy_from_slice(&self.0[seams.start..seams.start + seams.len]);
    }
    #[inline(always)]
    fn run(&mut self, run: EdgeRun, _rows: Range<usize>, _cells: &[f64], out: &mut [f64]) {
        let (values, extra) = out.split_at_mut(run.len);
        values.copy_from_slice(&self.0[run.edges()]);
        extra.fill(f64::NAN);
    }
}

/// Buffers of the gathers, kept from pass to pass.
#[derive(Clone, Debug, Default)]
pub(crate) struct GatherScratch {
    /// The window on the band being filled ([`FaceWindow`]), which the faces take in
    /// turn.
    window: FaceWindow,
    /// What each face's window carries from one band to the next ([`Carried`]).
    carried: [Carried; 6],
    /// The seam edges' values, from the first seam edge on.
    seams: Vec<f64>,
    /// The seam edges' values around each face, signed as the face's own
    /// ([`CellSides::face_pads`]): per face, per side, `n`.
    pads: Vec<f64>,
    /// The rim's values in its order, kept until every face's factors are in
    /// ([`RimValues`]).
    rim: RimValues,
    /// A stretch of a face's rows' net inflows ([`net_inflow`]), `(BAND + 1)·n`.
    inflow: Vec<f64>,
}

/// The bands of rows of a face of `n` rows, in order.
#[inline(always)]
pub(crate) fn bands(n: usize) -> impl Iterator<Item = Range<usize>> {
    (0..n).step_by(BAND).map(move |b| b..(b + BAND).min(n))
}

/// The rows whose cells have all four sides in once `band`'s edges are: up to the one
/// before its last (that row's top sides are the next band's), to the end on the last.
#[inline(always)]
fn sided(band: &Range<usize>, n: usize) -> Range<usize> {
    let end = if band.end == n { n } else { band.end - 1 };
    band.start.saturating_sub(1)..end
}

/// The rows whose cells' neighbours have their factors once `band`'s edges are in
/// (one row behind [`sided`]).
#[inline(always)]
fn gatherable(band: &Range<usize>, n: usize) -> Range<usize> {
    let end = if band.end == n { n } else { band.end - 2 };
    band.start.saturating_sub(2)..end
}

/// A face's window on its rows around the band being filled: the band's and the
/// [`BEHIND`] rows before, their edge values positive towards the face's +x or +y (an
/// interior edge's `a` cell is the one towards −x or −y), the seam edges around the
/// face padded on, and their cells' factors as donors; window row `w` is face row
/// `first − BEHIND + w`, and a stretch of rows reads each side as one slice. One window
/// serves the six faces in turn, each face's rows before the band [`Carried`] from its
/// band before: six windows were 200 KB and left L2 between passes.
#[derive(Clone, Debug, Default)]
struct FaceWindow {
    /// The band's first row.
    first: usize,
    /// Left sides, `n` a row: cell `(i, ·)` of window row `w` at `w·n + i` (`i = 0`: the
    /// left pad), and one more: so `[1..]` is the rows' cells' right sides, but for each
    /// row's last cell, whose is in `right`.
    left: Vec<f64>,
    /// Each window row's last cell's right side (its right pad).
    right: Vec<f64>,
    /// Bottom sides, `n` a row, one row more than the window's (its last row's tops):
    /// so `[n..]` is the rows' top sides.
    bottom: Vec<f64>,
    /// Factors, `n` a row, cell `i` of window row `w` at `1 + w·n + i`, one guard at
    /// each end: so the cells' left and right neighbours' are slices too (the rows' end
    /// cells, on the rim, read their row's neighbours' there, and are redone).
    ratio: Vec<f64>,
}

/// A face's [`FaceWindow`] rows kept from one band to the next: the [`BEHIND`] rows
/// before the next band's, in the window's layout.
#[derive(Clone, Debug, Default)]
struct Carried {
    /// Their left sides.
    left: Vec<f64>,
    /// Their last cells' right sides.
    right: Vec<f64>,
    /// Their bottom sides.
    bottom: Vec<f64>,
    /// Their cells' factors.
    ratio: Vec<f64>,
}

/// Rows in a window.
const WINDOW: usize = BEHIND + BAND;

impl FaceWindow {
    /// Sized for faces of `n × n` cells.
    fn resize(&mut self, n: usize) {
        self.left.resize(WINDOW * n + 1, 0.0);
        self.right.resize(WINDOW, 0.0);
        self.bottom.resize((WINDOW + 1) * n, 0.0);
        self.ratio.resize(WINDOW * n + 2, 0.0);
    }

    /// Face row `y`'s window row.
    #[inline(always)]
    fn w(&self, y: usize) -> usize {
        y + BEHIND - self.first
    }

    /// Readies the window for a face's `band`: the rows before it from `carried` (none
    /// before the first band).
    #[inline(always)]
    fn start(&mut self, n: usize, band: &Range<usize>, carried: &Carried) {
        if band.start > 0 {
            let kept = 0..BEHIND * n;
            self.left[kept.clone()].copy_from_slice(&carried.left);
            self.bottom[kept.clone()].copy_from_slice(&carried.bottom);
            self.ratio[1..1 + kept.end].copy_from_slice(&carried.ratio);
            self.right[..BEHIND].copy_from_slice(&carried.right);
        }
        self.first = band.start;
    }

    /// Keeps the window's last [`BEHIND`] rows in `carried` for the face's next band
    /// (all bands but the last are [`BAND`] rows; nothing after the last).
    #[inline(always)]
    fn carry(&self, n: usize, band: &Range<usize>, carried: &mut Carried) {
        if band.end < n {
            let kept = BAND * n..WINDOW * n;
            carried.left.clear();
            carried.left.extend_from_slice(&self.left[kept.clone()]);
            carried.bottom.clear();
            carried.bottom.extend_from_slice(&self.bottom[kept.clone()]);
            carried.ratio.clear();
            carried
                .ratio
                .extend_from_slice(&self.ratio[1 + kept.start..1 + kept.end]);
            carried.right.clear();
            carried.right.extend_from_slice(&self.right[BAND..WINDOW]);
        }
    }

    /// Face `face`'s band `band` of edge values from `pass`, its seam sides from the
    /// face's `pads` (`[left, right, bottom, top]`, `n` each): each row's x-edges' and
    /// left and right pads', the y-edges' below the rows (the bottom pads' below row 0),
    /// and the top pads' above the last row.
    #[inline(always)]
    fn fill(
        &mut self,
        (n, sides): (usize, &CellSides),
        (face, band): (usize, Range<usize>),
        (pass, cells): (&mut impl EdgeValues, &[f64]),
        [left, right, bottom, top]: [&[f64]; 4],
    ) {
        pass.rows(face, band.clone(), cells);
        let (w0, w1) = (self.w(band.start), self.w(band.end));
        if n > 1 {
            // Each row's right sides, and the next row's left pad, written after.
            let outs = self.left[w0 * n + 1..w1 * n + 1].chunks_exact_mut(n);
            for (y, out) in band.clone().zip(outs) {
                pass.run(sides.x_run(face, y), y..y + 1, cells, out);
            }
        }
        // The pads after the runs, a side at a time (row by row between the runs, with
        // each row's places, they took about 20 instructions a row more).
        let pads = self.left[w0 * n..w1 * n].iter_mut().step_by(n);
        for (pad, &value) in pads.zip(&left[band.clone()]) {
            *pad = value;
        }
        self.right[w0..w1].copy_from_slice(&right[band.clone()]);
        let inside = band.start.max(1)..band.end;
        if band.start == 0 {
            let w = self.w(0);
            self.bottom[w * n..(w + 1) * n].copy_from_slice(bottom);
        }
        if !inside.is_empty() {
            let (w0, w1) = (self.w(inside.start), self.w(inside.end));
            let out = &mut self.bottom[w0 * n..w1 * n];
            pass.run(sides.y_run(face, inside.clone()), inside, cells, out);
        }
        if band.end == n {
            let w = self.w(n);
            self.bottom[w * n..(w + 1) * n].copy_from_slice(top);
        }
    }
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

/// Each cell's net inflow of the values `pass` gives the edges from `cells` (positive
/// from an edge's `a` cell to its `b` cell): `Σ value` over the edges it is `b` of, less
/// over those it is `a` of, a stretch of a face's rows at a time into a buffer of the
/// stretch's, which `finish(pass, face, rows, inflow)` then takes (`rows.len()·n` of
/// them, the rows' cells in order) while it is in L1.
///
/// Why a stretch's buffer, not a field's: the field was written cold every pass (3072
/// lines at n = 64, a write miss each), where `finish` can write its result into a field
/// the pass has just read (the Marangoni correction's surfactant after the step, in place
/// of the solution it read): the bands ask the pass for no value from a cell of rows
/// `finish` has taken, but a padded x-run's extra edge's (a face's last row's reads the
/// next face's first cell), whose value is dropped ([`EdgeRun::padded`]).
// Inlined into the callers, so `pass` and `finish` compile into the AVX2 closure.
#[inline(always)]
pub(crate) fn net_inflow<P: EdgeValues>(
    sides: &CellSides,
    (pass, cells): (&mut P, &[f64]),
    scratch: &mut GatherScratch,
    mut finish: impl FnMut(&mut P, usize, Range<usize>, &[f64]),
) {
    let n = sides.n();
    let GatherScratch {
        window,
        carried,
        seams,
        pads,
        inflow,
        ..
    } = scratch;
    window.resize(n);
    // Every entry a stretch takes is written before `finish` reads it: the buffer needs
    // its length, not a fill.
    inflow.resize((BAND + 1) * n, 0.0);
    with_avx2(
        #[inline(always)]
        || {
            seam_values(sides, (pass, cells), (seams, pads));
            for band in bands(n) {
                for (face, carried) in carried.iter_mut().enumerate() {
                    let pads = face_pads(pads, n, face);
                    window.start(n, &band, carried);
                    window.fill((n, sides), (face, band.clone()), (pass, cells), pads);
                    let rows = sided(&band, n);
                    let o = &mut inflow[..rows.len() * n];
                    window.net_inflow(n, &rows, o);
                    window.carry(n, &band, carried);
                    finish(pass, face, rows, o);
                }
            }
        },
    )
}

/// The seam edges' values from `pass` into `seams`, and as each face's pads into `pads`
/// (per face, per side, `n`: [`CellSides::face_pads`]).
#[inline(always)]
fn seam_values(
    sides: &CellSides,
    (pass, cells): (&mut impl EdgeValues, &[f64]),
    (seams, pads): (&mut Vec<f64>, &mut Vec<f64>),
) {
    let block = sides.seams();
    seams.resize(block.len, 0.0);
    pass.seams(block, cells, &mut seams[..block.len]);
    let n = sides.n();
    pads.resize(6 * 4 * n, 0.0);
    // Side by side (flattened, the four sides' iterator took 38 instructions a pad).
    for (face, out) in pads.chunks_exact_mut(4 * n).enumerate() {
        for (out, side) in out.chunks_exact_mut(n).zip(sides.face_pads(face)) {
            let sign = side.sign;
            for (o, &seam) in out.iter_mut().zip(side.seams) {
                *o = seams[seam as usize] * sign;
            }
        }
    }
}

/// Face `face`'s pads' values from [`seam_values`]' `pads`, `[left, right, bottom,
/// top]`.
#[inline(always)]
fn face_pads(pads: &[f64], n: usize, face: usize) -> [&[f64]; 4] {
    let first = face * 4 * n;
    let pads = &pads[first..first + 4 * n];
    let (left, rest) = pads.split_at(n);
    let (right, rest) = rest.split_at(n);
    let (bottom, top) = rest.split_at(n);
    [left, right, bottom, top]
}

/// Moves `values` (a content per area, per cell) by the per-edge volumes `scale·v`
/// (per R², positive from `a` to `b`) that `pass` gives from them, each donor giving at
/// most [`MAX_OUTFLOW_FRACTION`] of its content (`values` then stays ≥ 0), in place
/// ([`apply_limited_to`]).
// Inlined into the callers, so `pass` compiles into the AVX2 closure.
#[inline(always)]
pub(crate) fn apply_limited(
    sides: &CellSides,
    grid: &CubeSphere,
    pass: &mut impl EdgeValues,
    scale: f64,
    values: &mut [f64],
    scratch: &mut GatherScratch,
) {
    apply_limited_to(sides, grid, pass, scale, values, scratch);
}

/// The field a limited apply moves: changed in place (`[f64]`), or read from one slice
/// and written into another ([`OutOfPlace`]), either thinned as it is written
/// ([`Thinned`]).
pub(crate) trait Moved {
    /// The values before the apply: the apply reads none it has changed.
    fn before(&self) -> &[f64];
    /// Cells `at`'s new values (`len` of them): each `then` of its value before plus
    /// `gain(i)`, `i` counted from `at`.
    fn add_then(
        &mut self,
        at: usize,
        len: usize,
        gain: impl Fn(usize) -> f64,
        then: impl Fn(f64) -> f64,
    );
    /// Cell `c`'s new value.
    fn set(&mut self, c: usize, value: f64);

    /// Cells `at`'s new values (`len` of them): each its value before plus `gain(i)`.
    #[inline(always)]
    fn add(&mut self, at: usize, len: usize, gain: impl Fn(usize) -> f64) {
        self.add_then(at, len, gain, |v| v);
    }
}

impl Moved for [f64] {
    #[inline(always)]
    fn before(&self) -> &[f64] {
        self
    }

    #[inline(always)]
    fn add_then(
        &mut self,
        at: usize,
        len: usize,
        gain: impl Fn(usize) -> f64,
        then: impl Fn(f64) -> f64,
    ) {
        for (i, x) in self[at..at + len].iter_mut().enumerate() {
            *x = then(*x + gain(i));
        }
    }

    #[inline(always)]
    fn set(&mut self, c: usize, value: f64) {
        self[c] = value;
    }
}

/// A field a limited apply reads from `before` and writes, every value, into `after`
/// (as long), which it reads not.
///
/// Why: the thickness transport's first sub-step runs out of place, so the thickness it
/// started from is still there should the Courant number it takes ask for more
/// sub-steps; in place, it was copied aside every step (0.2 MB at n = 64) for that rare
/// case.
pub(crate) struct OutOfPlace<'a> {
    /// The values before.
    pub(crate) before: &'a [f64],
    /// The values after.
    pub(crate) after: &'a mut [f64],
}

impl Moved for OutOfPlace<'_> {
    #[inline(always)]
    fn before(&self) -> &[f64] {
        self.before
    }

    #[inline(always)]
    fn add_then(
        &mut self,
        at: usize,
        len: usize,
        gain: impl Fn(usize) -> f64,
        then: impl Fn(f64) -> f64,
    ) {
        let (x, out) = (&self.before[at..at + len], &mut self.after[at..at + len]);
        for i in 0..len {
            out[i] = then(x[i] + gain(i));
        }
    }

    #[inline(always)]
    fn set(&mut self, c: usize, value: f64) {
        self.after[c] = value;
    }
}

/// A field (in place or [`OutOfPlace`]) a limited apply moves, each new value then
/// thinned by `by` and kept ≥ 0 (`(x − by).max(0)`, as a pass of its own would after
/// the apply).
///
/// Why: the film's uniform evaporation was a pass of its own over the thickness right
/// after the capillary smoothing's last apply (1.7 M instructions over 40 steps at
/// n = 64); inside the apply's gather it costs a subtraction and a maximum a cell. Where
/// the smoothing joins the thickness transport's out-of-place sub-step, the evaporation
/// rides in that apply.
pub(crate) struct Thinned<'a, M: Moved + ?Sized> {
    /// The values.
    pub(crate) values: &'a mut M,
    /// What each new value loses.
    pub(crate) by: f64,
}

impl<M: Moved + ?Sized> Moved for Thinned<'_, M> {
    #[inline(always)]
    fn before(&self) -> &[f64] {
        self.values.before()
    }

    #[inline(always)]
    fn add_then(
        &mut self,
        at: usize,
        len: usize,
        gain: impl Fn(usize) -> f64,
        then: impl Fn(f64) -> f64,
    ) {
        let by = self.by;
        self.values
            .add_then(at, len, gain, |v| then((v - by).max(0.0)));
    }

    #[inline(always)]
    fn set(&mut self, c: usize, value: f64) {
        self.values.set(c, (value - self.by).max(0.0));
    }
}

/// [`apply_limited`] on a [`Moved`] field: in place, or out of place.
// Inlined into the callers, so `pass` compiles into the AVX2 closure.
#[inline(always)]
pub(crate) fn apply_limited_to(
    sides: &CellSides,
    grid: &CubeSphere,
    pass: &mut impl EdgeValues,
    scale: f64,
    values: &mut (impl Moved + ?Sized),
    scratch: &mut GatherScratch,
) {
    let GatherScratch {
        window,
        carried,
        seams,
        pads,
        rim,
        ..
    } = scratch;
    let n = sides.n();
    let fg = grid.face_geometry();
    let (areas, per_area) = (&fg.area_sr[..], &fg.inverse_area_per_sr[..]);
    window.resize(n);
    rim.resize(sides.rim_cells.len());
    with_avx2(
        #[inline(always)]
        || {
            seam_values(sides, (pass, values.before()), (seams, pads));
            for band in bands(n) {
                for (face, carried) in carried.iter_mut().enumerate() {
                    let pads = face_pads(pads, n, face);
                    window.start(n, &band, carried);
                    let before = values.before();
                    window.fill((n, sides), (face, band.clone()), (pass, before), pads);
                    let first = face * n * n;
                    let before = &before[first..first + n * n];
                    let rows = sided(&band, n);
                    let cells = rows.start * n..rows.end * n;
                    let row_cells = (&areas[cells.clone()], &before[cells]);
                    window.outflow_ratios(n, &rows, row_cells, scale);
                    let rows = gatherable(&band, n);
                    rim.keep((sides, face), &rows, window, before);
                    let rows = (first, rows);
                    window.gather_inside(n, rows, per_area, scale, values);
                    window.carry(n, &band, carried);
                }
            }
            rim.apply(sides, scale, values);
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

/// The cells of face rows `rows` in a window's layout: their sides from `left` and
/// `bottom` ([`FaceWindow`]) between window rows `w0` and `w1`, each row's last cell's
/// right side wrong (it is the window's `right`).
#[inline(always)]
fn window_sides<'a>(
    left: &'a [f64],
    bottom: &'a [f64],
    n: usize,
    (w0, w1): (usize, usize),
) -> [&'a [f64]; 4] {
    let (a, b) = (w0 * n, w1 * n);
    [
        &left[a..b],
        &left[a + 1..b + 1],
        &bottom[a..b],
        &bottom[a + n..b + n],
    ]
}

impl FaceWindow {
    /// The net inflow of face rows `rows`' cells into `out` (`rows.len()·n`).
    #[inline(always)]
    fn net_inflow(&self, n: usize, rows: &Range<usize>, out: &mut [f64]) {
        let (w0, w1) = (self.w(rows.start), self.w(rows.end));
        let [v0, v1, v2, v3] = window_sides(&self.left, &self.bottom, n, (w0, w1));
        let o = &mut out[..v0.len()];
        for i in 0..o.len() {
            o[i] = net([v0[i], v1[i], v2[i], v3[i]], INFLOW);
        }
        // Each row's last cell again, its right side from `right` (as in
        // `outflow_ratios`).
        let sides = v0
            .chunks_exact(n)
            .zip(v2.chunks_exact(n))
            .zip(v3.chunks_exact(n));
        for ((o, ((l, b), t)), &r) in o.chunks_exact_mut(n).zip(sides).zip(&self.right[w0..w1]) {
            o[n - 1] = net([l[n - 1], r, b[n - 1], t[n - 1]], INFLOW);
        }
    }

    /// Face rows `rows`' cells' [`outflow_factor`]s, rim and all, into the window
    /// (`areas`: face 0's rows'; `values`: the rows').
    #[inline(always)]
    fn outflow_ratios(
        &mut self,
        n: usize,
        rows: &Range<usize>,
        (areas, values): (&[f64], &[f64]),
        scale: f64,
    ) {
        let (w0, w1) = (self.w(rows.start), self.w(rows.end));
        let [v0, v1, v2, v3] = window_sides(&self.left, &self.bottom, n, (w0, w1));
        let o = &mut self.ratio[1 + w0 * n..1 + w1 * n];
        let (a, x) = (&areas[..o.len()], &values[..o.len()]);
        for i in 0..o.len() {
            let v = [v0[i], v1[i], v2[i], v3[i]];
            o[i] = outflow_factor(v, INFLOW, scale, a[i], x[i]);
        }
        // Each row's last cell again, its right side from `right`: the rows as exact
        // chunks (row by row through the window's places, about 20 instructions a row
        // more).
        let sides = v0
            .chunks_exact(n)
            .zip(v2.chunks_exact(n))
            .zip(v3.chunks_exact(n));
        let cells = o
            .chunks_exact_mut(n)
            .zip(a.chunks_exact(n))
            .zip(x.chunks_exact(n));
        for ((((o, a), x), ((l, b), t)), &r) in cells.zip(sides).zip(&self.right[w0..w1]) {
            let v = [l[n - 1], r, b[n - 1], t[n - 1]];
            o[n - 1] = outflow_factor(v, INFLOW, scale, a[n - 1], x[n - 1]);
        }
    }

    /// Face rows `rows`' cells off the first and last rows gather their sides' volumes,
    /// each cut by its donor's factor (`per_area`: face 0's; `values`: the field, the
    /// face's cells from `first` on).
    ///
    /// The rows' end cells, on the rim, gather too, wrongly (their sides across the
    /// seams are not their neighbours'): [`RimValues::keep`] kept their values before,
    /// and [`RimValues::apply`] gathers them from those. So the rows run as one loop.
    #[inline(always)]
    fn gather_inside(
        &self,
        n: usize,
        (first, rows): (usize, Range<usize>),
        per_area: &[f64],
        scale: f64,
        values: &mut (impl Moved + ?Sized),
    ) {
        let rows = rows.start.max(1)..rows.end.min(n.saturating_sub(1));
        if rows.is_empty() {
            return;
        }
        let (w0, w1) = (self.w(rows.start), self.w(rows.end));
        let [v0, v1, v2, v3] = window_sides(&self.left, &self.bottom, n, (w0, w1));
        let (a, b) = (w0 * n, w1 * n);
        let r = &self.ratio;
        let (own, r0, r1) = (&r[1 + a..1 + b], &r[a..b], &r[a + 2..b + 2]);
        let (r2, r3) = (&r[1 + a - n..1 + b - n], &r[1 + a + n..1 + b + n]);
        let cells = rows.start * n..rows.end * n;
        let pa = &per_area[cells.clone()];
        let len = pa.len();
        let (v0, v1, v2, v3) = (&v0[..len], &v1[..len], &v2[..len], &v3[..len]);
        let (own, r0, r1, r2, r3) = (&own[..len], &r0[..len], &r1[..len], &r2[..len], &r3[..len]);
        values.add(
            first + cells.start,
            len,
            #[inline(always)]
            |i| {
                let v = [v0[i], v1[i], v2[i], v3[i]];
                let across = [r0[i], r1[i], r2[i], r3[i]];
                scale * gained(v, INFLOW, across, own[i]) * pa[i]
            },
        );
    }
}

/// The limited apply's values on the rim, in its order ([`CellSides::rim_cells`]), kept
/// band by band until every face's factors are in: a rim cell's neighbour across a seam
/// is on another face.
#[derive(Clone, Debug, Default)]
struct RimValues {
    /// Per side: the volume, positive towards the face's +x or +y (as [`FaceWindow`]).
    volume: [Vec<f64>; 4],
    /// Per side, side `k`'s from `k·m` on (`m` the rim's cells): the neighbour's factor
    /// as a donor; one table, so the seams' sides are filled by flat places
    /// ([`CellSides::rim_seam_copies`]).
    across: Vec<f64>,
    /// The cells' own factors as donors.
    ratio: Vec<f64>,
    /// The cells' values before the apply (after it, in [`Self::apply`]).
    value: Vec<f64>,
}

impl RimValues {
    /// Sized for `m` rim cells.
    fn resize(&mut self, m: usize) {
        for v in &mut self.volume {
            v.resize(m, 0.0);
        }
        self.across.resize(4 * m, 0.0);
        self.ratio.resize(m, 0.0);
        self.value.resize(m, 0.0);
    }

    /// Face `face`'s rows `rows`' rim cells' volumes, factors and values, and their
    /// neighbours' factors on the face (those across a seam wait for [`Self::apply`]),
    /// from the face's `window` (the rows and those either side have their factors) and
    /// `values`: the whole of the first and last rows ([`Self::keep_row`]), the ends of
    /// the others ([`Self::keep_ends`]).
    #[inline(always)]
    fn keep(
        &mut self,
        (sides, face): (&CellSides, usize),
        rows: &Range<usize>,
        window: &FaceWindow,
        values: &[f64],
    ) {
        let n = sides.n();
        let ends = rows.start.max(1)..rows.end.min(n.saturating_sub(1));
        if !ends.is_empty() {
            let place = face * sides.rim_per_face() + sides.rim_of_row(ends.start).start;
            self.keep_ends(n, (place, ends), window, values);
        }
        if rows.contains(&0) {
            self.keep_row((sides, face), 0, window, values);
        }
        if n > 1 && rows.contains(&(n - 1)) {
            self.keep_row((sides, face), n - 1, window, values);
        }
    }

    /// [`Self::keep`] for face row `y`, the first or the last: all its cells are on the
    /// rim.
    #[inline(always)]
    fn keep_row(
        &mut self,
        (sides, face): (&CellSides, usize),
        y: usize,
        window: &FaceWindow,
        values: &[f64],
    ) {
        let n = sides.n();
        let place = face * sides.rim_per_face() + sides.rim_of_row(y).start;
        let w = window.w(y);
        let [l, r, b, t] = window_sides(&window.left, &window.bottom, n, (w, w + 1));
        let ratio = &window.ratio[w * n..];
        // A side on a seam takes its row's factors here and its neighbour's in `apply`.
        let below = if y > 0 {
            &window.ratio[(w - 1) * n..]
        } else {
            ratio
        };
        let above = if y + 1 < n { &ratio[n..] } else { ratio };
        let value = &values[y * n..(y + 1) * n];
        // Cell `x`'s volumes, its neighbours' factors, its own and its value.
        let v = [l, r, b, t];
        let across = [
            &ratio[..n],
            &ratio[2..n + 2],
            &below[1..n + 1],
            &above[1..n + 1],
        ];
        let (at, m) = (place..place + n, self.ratio.len());
        for k in 0..4 {
            self.volume[k][at.clone()].copy_from_slice(v[k]);
            let at = k * m + at.start..k * m + at.end;
            self.across[at].copy_from_slice(across[k]);
        }
        self.volume[1][place + n - 1] = window.right[w];
        self.ratio[at.clone()].copy_from_slice(&ratio[1..n + 1]);
        self.value[at].copy_from_slice(value);
    }

    /// [`Self::keep`] for face rows `rows`, off the first and last (`n ≥ 3`), whose two
    /// end cells are the rim's places from `place` on, two a row: each kept value a loop
    /// over the rows, from its window array shifted to the row's first cell's: about 45
    /// instructions a row, where each row's slices and places set up one by one cost
    /// about 190.
    #[inline(always)]
    fn keep_ends(
        &mut self,
        n: usize,
        (place, rows): (usize, Range<usize>),
        window: &FaceWindow,
        values: &[f64],
    ) {
        let len = rows.len();
        let kept = place..place + 2 * len;
        let first = window.w(rows.start);
        let w = first * n;
        let (left, bottom, ratio) = (&window.left, &window.bottom, &window.ratio);
        let [v0, v1, v2, v3] = self.volume.each_mut().map(|v| &mut v[kept.clone()]);
        row_ends(v0, &left[w..], n, len);
        row_ends(v2, &bottom[w..], n, len);
        row_ends(v3, &bottom[w + n..], n, len);
        // Right sides: the first cell's is its neighbour's left, the last cell's its
        // window row's right pad.
        let right = &window.right[first..first + len];
        let left = left[w + 1..w + 1 + len * n].chunks_exact(n);
        for ((v, row), &pad) in v1.chunks_exact_mut(2).zip(left).zip(right) {
            (v[0], v[1]) = (row[0], pad);
        }
        let m = self.ratio.len();
        let mut across = self
            .across
            .chunks_exact_mut(m)
            .map(|a| &mut a[kept.clone()]);
        let mut next = || across.next().expect("four sides");
        let [a0, a1, a2, a3] = [next(), next(), next(), next()];
        row_ends(a0, &ratio[w..], n, len);
        row_ends(a1, &ratio[w + 2..], n, len);
        row_ends(a2, &ratio[w + 1 - n..], n, len);
        row_ends(a3, &ratio[w + 1 + n..], n, len);
        row_ends(&mut self.ratio[kept.clone()], &ratio[w + 1..], n, len);
        row_ends(&mut self.value[kept], &values[rows.start * n..], n, len);
    }

    /// The rim cells' neighbours' factors across the seams, then their gathers into
    /// `values`, from their values before: the new values taken in the rim's order in a
    /// loop that vectorises (in place of the values before), then set cell by cell (in
    /// one scalar loop with the sets, the gathers took about 21 instructions a cell
    /// more).
    #[inline(always)]
    fn apply(&mut self, sides: &CellSides, scale: f64, values: &mut (impl Moved + ?Sized)) {
        for &[to, from] in sides.rim_seam_copies() {
            self.across[to as usize] = self.ratio[from as usize];
        }
        let rim = sides.rim();
        let m = rim.cells.len();
        let [v0, v1, v2, v3] = self.volume.each_ref().map(|v| &v[..m]);
        let (a0, rest) = self.across.split_at(m);
        let (a1, rest) = rest.split_at(m);
        let (a2, a3) = rest.split_at(m);
        let [a0, a1, a2, a3] = [a0, a1, a2, a3].map(|a| &a[..m]);
        let (own, pa, value) = (
            &self.ratio[..m],
            &rim.inverse_area[..m],
            &mut self.value[..m],
        );
        for i in 0..m {
            let v = [v0[i], v1[i], v2[i], v3[i]];
            let across = [a0[i], a1[i], a2[i], a3[i]];
            value[i] += scale * gained(v, INFLOW, across, own[i]) * pa[i];
        }
        for (&c, &value) in rim.cells.iter().zip(&*value) {
            values.set(c as usize, value);
        }
    }
}

/// Each of the first `rows` rows of `n` values in `from`: its first and last value into
/// `to`, two a row.
#[inline(always)]
fn row_ends(to: &mut [f64], from: &[f64], n: usize, rows: usize) {
    // Exact chunks: each row `n` long, its ends' bounds checks gone.
    for (to, row) in to.chunks_exact_mut(2).zip(from[..rows * n].chunks_exact(n)) {
        (to[0], to[1]) = (row[0], row[n - 1]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::film_flow::CubeSphere;

    /// Made-up volumes, one an edge, of both signs.
    fn volumes(grid: &CubeSphere, scale: f64) -> Vec<f64> {
        let edges = grid.edge_arrays().cells.len();
        (0..edges)
            .map(|e| (((e * 53) % 17) as f64 - 8.0) * scale)
            .collect()
    }

    /// Against the edge-by-edge scatter it replaces, bit for bit (each cell sums its
    /// sides in a fixed order, exactly as the scatter's `±v` in that order), at sizes
    /// with no inside (1, 2), a one-cell inside (3), more, and three bands, the last
    /// short (rows carried from band to band).
    #[test]
    fn net_inflow_is_the_scatter_of_the_volumes() {
        for n in [1, 2, 3, 5, 2 * BAND + 3] {
            let grid = CubeSphere::new(n);
            let sides = CellSides::new(&grid);
            let ea = grid.edge_arrays();
            let volume = volumes(&grid, 1.0);
            let mut sum = vec![[0.0; 4]; grid.cells()];
            for (e, ([a, b], v)) in ea.cells.iter().zip(&volume).enumerate() {
                for (c, sign) in [(*a as usize, -1.0), (*b as usize, 1.0)] {
                    let k = sides.edge[c].iter().position(|&s| s as usize == e).unwrap();
                    sum[c][k] = sign * v;
                }
            }
            let want: Vec<f64> = sum.iter().map(|s| (s[0] + s[1]) + (s[2] + s[3])).collect();
            let mut got = vec![f64::NAN; grid.cells()];
            let mut finished = Vec::new();
            let pass = (&mut FromArray(&volume), &[][..]);
            let scratch = &mut GatherScratch::default();
            net_inflow(&sides, pass, scratch, |_, f, rows, inflow| {
                assert_eq!(inflow.len(), rows.len() * n, "n = {n}: a stretch's cells");
                let first = f * n * n + rows.start * n;
                got[first..first + inflow.len()].copy_from_slice(inflow);
                finished.extend(rows.map(|y| (f, y)));
            });
            assert_eq!(got, want, "n = {n}");
            finished.sort_unstable();
            let rows: Vec<_> = (0..6 * n).map(|r| (r / n, r % n)).collect();
            assert_eq!(finished, rows, "n = {n}: each face row finished once");
        }
    }

    /// Each donor's factor from its summed outflow (times `scale`) against its budget.
    fn donor_factors(grid: &CubeSphere, volume: &[f64], values: &[f64], scale: f64) -> Vec<f64> {
        let mut outflow = vec![0.0; grid.cells()];
        for ([a, b], v) in grid.edge_arrays().cells.iter().zip(volume) {
            let donor = if *v > 0.0 { *a } else { *b } as usize;
            outflow[donor] += scale * v.abs();
        }
        let areas = grid.areas_sr();
        (0..grid.cells())
            .map(|c| {
                let budget = MAX_OUTFLOW_FRACTION * areas[c] * values[c];
                if outflow[c] > budget {
                    budget / outflow[c]
                } else {
                    1.0
                }
            })
            .collect()
    }

    /// Against the edge-by-edge scatter of the limited volumes: each donor's factor from
    /// its summed outflow, each volume cut by its donor's factor; at sizes with no
    /// inside (1, 2), more, and three bands, the last short.
    #[test]
    fn apply_limited_is_the_scatter_of_the_limited_volumes() {
        for n in [1, 2, 3, 6, 2 * BAND + 3] {
            let grid = CubeSphere::new(n);
            let sides = CellSides::new(&grid);
            let ea = grid.edge_arrays();
            let per_area = grid.inverse_areas_per_sr();
            // About a cell's area (4π/6n² sr): enough to limit some donors at any size.
            let volume = volumes(&grid, 2.0 / (n * n) as f64);
            let values: Vec<f64> = (0..grid.cells()).map(|c| 1.0 + (c % 7) as f64).collect();
            let scale = 0.3;
            let factor = donor_factors(&grid, &volume, &values, scale);
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
            let pass = &mut FromArray(&volume);
            apply_limited(&sides, &grid, pass, scale, &mut got, &mut scratch);
            for (c, (g, w)) in got.iter().zip(&want).enumerate() {
                assert!(
                    (g - w).abs() < 1e-12 * w.abs(),
                    "n {n} cell {c}: {g} against {w}"
                );
            }
        }
    }

    /// Out of place, every value written and the same bits as in place, and the values
    /// before untouched: at sizes with no inside (1, 2), more, and three bands, the last
    /// short.
    #[test]
    fn apply_limited_out_of_place_is_in_place() {
        for n in [1, 2, 3, 6, 2 * BAND + 3] {
            let grid = CubeSphere::new(n);
            let sides = CellSides::new(&grid);
            let volume = volumes(&grid, 2.0 / (n * n) as f64);
            let values: Vec<f64> = (0..grid.cells()).map(|c| 1.0 + (c % 7) as f64).collect();
            let mut in_place = values.clone();
            let mut scratch = GatherScratch::default();
            let pass = &mut FromArray(&volume);
            apply_limited(&sides, &grid, pass, 0.3, &mut in_place, &mut scratch);
            let mut after = vec![f64::NAN; grid.cells()];
            let moved = &mut OutOfPlace {
                before: &values,
                after: &mut after,
            };
            apply_limited_to(&sides, &grid, pass, 0.3, moved, &mut scratch);
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&after), bits(&in_place), "n = {n}");
            assert_ne!(values, in_place, "n = {n}: the test is idle");
        }
    }

    /// Thinned, the same bits as the apply in place and then a pass of `(x − by).max(0)`
    /// (some cells emptied by it): at sizes with no inside (1, 2), more, and three bands,
    /// the last short.
    #[test]
    fn a_thinned_apply_is_the_apply_then_the_thinning() {
        for n in [1, 2, 3, 6, 2 * BAND + 3] {
            let grid = CubeSphere::new(n);
            let sides = CellSides::new(&grid);
            let volume = volumes(&grid, 2.0 / (n * n) as f64);
            let values: Vec<f64> = (0..grid.cells()).map(|c| 1.0 + (c % 7) as f64).collect();
            let by = 2.5;
            let mut want = values.clone();
            let mut scratch = GatherScratch::default();
            let pass = &mut FromArray(&volume);
            apply_limited(&sides, &grid, pass, 0.3, &mut want, &mut scratch);
            assert!(want.iter().any(|&x| x < by), "n = {n}: none emptied");
            want.iter_mut().for_each(|x| *x = (*x - by).max(0.0));
            let mut got = values.clone();
            let thinned = &mut Thinned {
                values: &mut got[..],
                by,
            };
            apply_limited_to(&sides, &grid, pass, 0.3, thinned, &mut scratch);
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&got), bits(&want), "n = {n}");
            // Out of place, every value written (NaN before).
            let mut after = vec![f64::NAN; values.len()];
            let moved = &mut OutOfPlace {
                before: &values,
                after: &mut after,
            };
            let thinned = &mut Thinned { values: moved, by };
            apply_limited_to(&sides, &grid, pass, 0.3, thinned, &mut scratch);
            assert_eq!(bits(&after), bits(&want), "n = {n}, out of place");
        }
    }

    /// The limited apply conserves the content and keeps it ≥ 0 however large the
    /// volumes.
    #[test]
    fn limited_volumes_conserve_the_content_and_empty_no_cell() {
        let grid = CubeSphere::new(6);
        let sides = CellSides::new(&grid);
        let volume = volumes(&grid, 1.0);
        let mut values: Vec<f64> = (0..grid.cells()).map(|c| 1.0 + (c % 7) as f64).collect();
        let content = |v: &[f64]| {
            v.iter()
                .zip(grid.areas_sr())
                .map(|(x, a)| x * a)
                .sum::<f64>()
        };
        let before = content(&values);
        let factor = donor_factors(&grid, &volume, &values, 0.3);
        let mut scratch = GatherScratch::default();
        let pass = &mut FromArray(&volume);
        apply_limited(&sides, &grid, pass, 0.3, &mut values, &mut scratch);
        let change = (content(&values) - before) / before;
        assert!(change.abs() < 1e-14, "content changed by {change:.3e}");
        let least = values.iter().copied().fold(f64::INFINITY, f64::min);
        assert!(least >= 0.0, "a cell went to {least}");
        let limited = factor.iter().filter(|&&f| f < 1.0).count();
        assert!(
            limited > grid.cells() / 4,
            "{limited} donors limited: the test is idle"
        );
    }
}
