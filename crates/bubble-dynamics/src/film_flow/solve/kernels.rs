//! The solve's loops over a level's split fields ([`Layout`]): the half-sweeps, the
//! operator, the halo refresh, the restriction and the coarse correction, and the
//! conjugate gradients' dot products and updates. Each is a loop over contiguous slices
//! cut to one length first (so it vectorises and checks no bounds inside), written
//! once for `f32` and `f64` ([`Real`]) as IEEE operations in a fixed order. The passes
//! that read both colours' weights (the operator, the V-cycle's rounding) take both
//! colours a block at a time ([`BLOCK`]).

use super::Real;
use super::layout::{Layout, RIGHT_W, TOP_W};
use crate::avx2::{
    F32_LANES, dot_lanes, dot_lanes_f32, subtract_and_square_lanes, widened_dot_lanes, with_avx2,
};

/// A level's edge weights once an edge: per cell its RIGHT side's weight
/// ([`RIGHT_W`]) and its TOP side's ([`TOP_W`]), the left halo column and the bottom
/// halo row holding the rim cells' LEFT and BOTTOM seam weights
/// ([`Layout::side_weights`]); zero wherever no cell reads them.
pub(super) type Stencil<T> = [Vec<T>; 2];

/// A stencil's weight as a pass in precision `T` reads it: `f64` and `f32` weights in
/// their own precision, and `f32` weights widened (exactly) into `f64`. The only `f32`
/// weights an `f64` pass reads are the V-cycle's finest ones where the system's weights
/// were given as `f32` values (the conjugate gradients then hold no `f64` copy): those
/// are held scaled by the V-cycle's power of two ([`WeightIn::SCALED`]).
pub(super) trait WeightIn<T>: Copy {
    /// Whether the weights are held scaled by a power of two `s` that the pass's mass
    /// term is not: the pass then scales the mass term by `s` and its sums back by
    /// `1/s`, each step exact, so that it gives the bits of the unscaled weights' pass.
    const SCALED: bool;
    /// The weight in `T`.
    fn read(self) -> T;
}

impl WeightIn<f64> for f64 {
    const SCALED: bool = false;
    #[inline(always)]
    fn read(self) -> f64 {
        self
    }
}

impl WeightIn<f32> for f32 {
    const SCALED: bool = false;
    #[inline(always)]
    fn read(self) -> f32 {
        self
    }
}

impl WeightIn<f64> for f32 {
    const SCALED: bool = true;
    #[inline(always)]
    fn read(self) -> f64 {
        f64::from(self)
    }
}

/// A level's edge weights as the operator reads them: the stencil, and the power of two
/// it is held scaled by where [`WeightIn::SCALED`] (unread otherwise).
pub(super) type Weighted<'a, W, T> = (&'a Stencil<W>, T);

/// The mass term's value at the positions that hold no cell: negative, where a cell's
/// is not (a mass term), so the operator can tell them apart and give them zero (their
/// weight entries hold seam weights, and their values a halo copy).
pub(super) const NOT_A_CELL: f64 = -1.0;

/// Positions a blocked pass takes of each colour in turn: a block's slices of both
/// colours (about 200 kB in `f64`) stay in L2 while the other colour reads them as
/// neighbours. Over `film_profile 64 0 9.81`'s 40 steps, 256 took 21 M instructions
/// more than 2048 (each block's slices set up anew), 4096 1.4 M fewer, the same misses.
const BLOCK: usize = 2048;

/// Slice `values[start + offset..][..len]`.
#[inline(always)]
fn shifted<T>(values: &[T], start: usize, offset: isize, len: usize) -> &[T] {
    &values[(start as isize + offset) as usize..][..len]
}

/// The four neighbour slices (LEFT, RIGHT, BOTTOM, TOP) of the `len` cells from
/// `start` of colour `c`, in `other`, the other colour's array of the field.
#[inline(always)]
fn neighbours<'a, T>(
    layout: &Layout,
    c: usize,
    (start, len): (usize, usize),
    other: &'a [T],
) -> [&'a [T]; 4] {
    let o = layout.neighbour_offsets(c);
    // Spelt out: `[0, 1, 2, 3].map(…)` was left a call of its own.
    [
        shifted(other, start, o[0], len),
        shifted(other, start, o[1], len),
        shifted(other, start, o[2], len),
        shifted(other, start, o[3], len),
    ]
}

/// The four side-weight slices (LEFT, RIGHT, BOTTOM, TOP) of the `len` cells from
/// `start` of colour `c`: a cell's LEFT and BOTTOM weights are its neighbours' RIGHT and
/// TOP entries, at the same offsets as their values.
#[inline(always)]
fn side_weights<'a, T>(
    layout: &Layout,
    c: usize,
    (start, len): (usize, usize),
    w: &'a Stencil<T>,
) -> [&'a [T]; 4] {
    let o = layout.neighbour_offsets(c);
    let own = c * layout.half + start;
    let far = (1 - c) * layout.half + start;
    let (right, top) = (&w[RIGHT_W][..], &w[TOP_W][..]);
    [
        shifted(right, far, o[0], len),
        &right[own..][..len],
        shifted(top, far, o[2], len),
        &top[own..][..len],
    ]
}

/// The positions both colours' cells lie within: the union of their sweeps (they differ
/// by at most one position at each end, a halo cell).
#[inline(always)]
fn both_sweeps(layout: &Layout) -> std::ops::Range<usize> {
    let [a, b] = &layout.sweep;
    a.start.min(b.start)..a.end.max(b.end)
}

/// Runs `pass(face, start, len)` over `range` in blocks of at most [`BLOCK`] positions;
/// `per_face`, each within one face's positions ([`Layout::face_start`]), so that a
/// field held per face can be read from face 0's ([`LevelField`]), else `face` 0 (a
/// block's unvectorised remainder costs as much as a few hundred cells: six blocks a
/// face on a coarse level cost the V-cycle 5 % more instructions). `pass` is marked
/// `#[inline(always)]`, so that it is built into the caller's AVX2 code.
#[inline(always)]
fn in_blocks(
    layout: &Layout,
    range: std::ops::Range<usize>,
    per_face: bool,
    mut pass: impl FnMut(usize, usize, usize),
) {
    let faces = if per_face { 6 } else { 1 };
    for face in 0..faces {
        let (start, end) = if per_face {
            (layout.face_start(face), layout.face_start(face + 1))
        } else {
            (range.start, range.end)
        };
        let end = end.min(range.end);
        let mut start = start.max(range.start);
        while start < end {
            let len = BLOCK.min(end - start);
            pass(face, start, len);
            start += len;
        }
    }
}

/// A field of a level as the kernels read it: whole, or `per_face`, face 0's positions
/// alone, read by every face at its own positions less [`Layout::face_start`]. The
/// finest level's mass term is held so where the system's faces are alike (every face
/// holds face 0's cell areas): a pass then streams 1/6 of the field.
#[derive(Clone, Copy)]
pub(super) struct LevelField<'a, T> {
    /// The field ([`NOT_A_CELL`] outside the cells, for a mass term).
    pub(super) values: &'a [T],
    /// Whether every face reads face 0's positions.
    pub(super) per_face: bool,
}

impl<'a, T> LevelField<'a, T> {
    /// The field at the `len` positions from split position `base`, all of face
    /// `face`.
    #[inline(always)]
    fn at(&self, layout: &Layout, face: usize, base: usize, len: usize) -> &'a [T] {
        let shift = if self.per_face {
            layout.face_start(face)
        } else {
            0
        };
        &self.values[base - shift..][..len]
    }
}

/// Splits a field into colour `c`'s array (mutable) and the other's.
#[inline(always)]
fn colours<'a, T>(field: &'a mut [T], layout: &Layout, c: usize) -> (&'a mut [T], &'a [T]) {
    let (red, black) = field[..layout.len()].split_at_mut(layout.half);
    if c == 0 { (red, black) } else { (black, red) }
}

/// Gauss–Seidel's update of every cell of colour `c` (a half-sweep):
/// `zᵢ = (rᵢ + Σ wᵢⱼ zⱼ)/dᵢ` from the other colour's values (and, through the halo,
/// the values the last refresh copied).
#[inline(always)]
pub(super) fn relax<T: Real>(
    layout: &Layout,
    c: usize,
    inv_diag: &[T],
    w: &Stencil<T>,
    r: &[T],
    z: &mut [T],
) {
    let range = layout.sweep[c].clone();
    let (start, len) = (range.start, range.len());
    let (own, other) = colours(z, layout, c);
    let (near, w) = (
        neighbours(layout, c, (start, len), other),
        side_weights(layout, c, (start, len), w),
    );
    let base = c * layout.half + start;
    let (inv_diag, r, out) = (&inv_diag[base..][..len], &r[base..][..len], &mut own[range]);
    let [n0, n1, n2, n3] = near;
    let [w0, w1, w2, w3] = w;
    for i in 0..len {
        let near = w0[i] * n0[i] + w1[i] * n1[i];
        let far = w2[i] * n2[i] + w3[i] * n3[i];
        out[i] = (r[i] + near + far) * inv_diag[i];
    }
}

/// [`relax`] of colour 0 from `z = 0`, `zᵢ = rᵢ/dᵢ`, then colour 0's halo cells
/// refreshed as from that `z`: a halo cell whose source is a colour-1 cell (where a seam
/// joins two cells of one colour) takes zero, so colour 1 need not be zeroed first.
#[inline(always)]
pub(super) fn relax_from_zero<T: Real>(layout: &Layout, inv_diag: &[T], r: &[T], z: &mut [T]) {
    let range = layout.sweep[0].clone();
    let (inv_diag, r) = (&inv_diag[range.clone()], &r[range.clone()]);
    for ((zi, ri), di) in z[range].iter_mut().zip(r).zip(inv_diag) {
        *zi = *ri * *di;
    }
    let half = layout.half;
    // SAFETY: as in `refresh`.
    for_each_copy(layout, (0, false), z, |base, halo, source| unsafe {
        *base.add(halo) = if source < half {
            *base.add(source)
        } else {
            T::ZERO
        };
    });
}

/// `out = (diag(mass) + L_w) x` (`RESIDUAL` false) or `r − (diag(mass) + L_w) x`
/// (true), as `mᵢxᵢ + Σ wᵢⱼ (xᵢ − xⱼ)`: the differences keep the result accurate where
/// the weights dwarf the mass term and `x` is nearly uniform (a stiff step's
/// surfactant). `x`'s halo must be fresh; the results outside the cells are zero (so a
/// field made from them adds nothing outside the faces to a dot product). Both colours
/// a block at a time ([`BLOCK`]): each weight entry is read once, by its cell and by the
/// neighbour across the edge, while it is in L2.
#[inline(always)]
pub(super) fn operator<T: Real, W: WeightIn<T>, const RESIDUAL: bool>(
    layout: &Layout,
    mass: LevelField<T>,
    w: Weighted<W, T>,
    r: &[T],
    x: &[T],
    out: &mut [T],
) {
    operator_blocks::<T, W, RESIDUAL>(layout, (mass, w, r), &mut [(Some(x), out)]);
}

/// `out = b − (diag(mass) + L_w) x` for each start `x` given ([`operator`]'s residual),
/// `b` held in the first output on entry (each output given a start holds `b` there and
/// takes its residual in place, the second's read from the first's `b` before the first's
/// own is written), in one pass over the system: each block's numbers are read once for
/// every start, and `b` needs no field of its own.
#[inline(always)]
pub(super) fn residuals_in_place<T: Real, W: WeightIn<T>>(
    layout: &Layout,
    (mass, w): (LevelField<T>, Weighted<W, T>),
    [x_a, x_b]: [Option<&[T]>; 2],
    [a, b_out]: [&mut [T]; 2],
) {
    let range = both_sweeps(layout);
    // Outside the cells `b` is read by no one.
    zero_outside(layout, range.clone(), a);
    zero_outside(layout, range.clone(), b_out);
    in_blocks(
        layout,
        range,
        mass.per_face,
        #[inline(always)]
        |face, start, len| {
            let at = (face, start, len);
            if let Some(x) = x_b {
                for c in 0..2 {
                    operator_run::<T, W, true, false>(layout, c, at, (mass, w, &*a), x, b_out);
                }
            }
            if let Some(x) = x_a {
                for c in 0..2 {
                    operator_run::<T, W, true, true>(layout, c, at, (mass, w, &[]), x, a);
                }
            }
        },
    );
}

/// Zero at the positions before and after `range` in each colour's array.
#[inline(always)]
fn zero_outside<T: Real>(layout: &Layout, range: std::ops::Range<usize>, out: &mut [T]) {
    for colour in out[..layout.len()].chunks_exact_mut(layout.half) {
        colour[..range.start].fill(T::ZERO);
        colour[range.end..].fill(T::ZERO);
    }
}

/// [`operator`] of each start given in `pairs` into its output (the others' outputs only
/// zeroed outside the cells), both colours a block at a time: each block's numbers are
/// read once for every start.
#[inline(always)]
fn operator_blocks<T: Real, W: WeightIn<T>, const RESIDUAL: bool>(
    layout: &Layout,
    (mass, w, r): (LevelField<T>, Weighted<W, T>, &[T]),
    pairs: &mut [(Option<&[T]>, &mut [T])],
) {
    let range = both_sweeps(layout);
    for (_, out) in pairs.iter_mut() {
        zero_outside(layout, range.clone(), out);
    }
    in_blocks(
        layout,
        range,
        mass.per_face,
        #[inline(always)]
        |face, start, len| {
            for (x, out) in pairs.iter_mut() {
                let Some(x) = x else { continue };
                for c in 0..2 {
                    let at = (face, start, len);
                    operator_run::<T, W, RESIDUAL, false>(layout, c, at, (mass, w, r), x, out);
                }
            }
        },
    );
}

/// [`operator`] at the `len` positions from `start` of colour `c`, of face `face`; the
/// residual's `b` read from `out` itself where `IN_PLACE` (`r` then unread, as it is
/// for the product, `RESIDUAL` false). Weights held scaled by `s` ([`WeightIn::SCALED`])
/// are summed with the mass term times `s` and the sum taken back by `1/s`: `s` a power
/// of two, each product and sum is `s` times the unscaled one's, to the bit.
#[inline(always)]
fn operator_run<T: Real, W: WeightIn<T>, const RESIDUAL: bool, const IN_PLACE: bool>(
    layout: &Layout,
    c: usize,
    (face, start, len): (usize, usize, usize),
    (mass, (w, scale), r): (LevelField<T>, Weighted<W, T>, &[T]),
    x: &[T],
    out: &mut [T],
) {
    let (own, other) = x[..layout.len()].split_at(layout.half);
    let (own, other) = if c == 0 { (own, other) } else { (other, own) };
    let (near, weights) = (
        neighbours(layout, c, (start, len), other),
        side_weights(layout, c, (start, len), w),
    );
    let base = c * layout.half + start;
    let (m, xs, r) = (
        mass.at(layout, face, base, len),
        &own[start..][..len],
        if IN_PLACE || !RESIDUAL {
            &[]
        } else {
            &r[base..][..len]
        },
    );
    let out = &mut out[base..][..len];
    let [n0, n1, n2, n3] = near;
    let [w0, w1, w2, w3] = weights;
    let (to, back) = (scale, T::narrow(1.0 / scale.widen()));
    for i in 0..len {
        let xi = xs[i];
        let mut sum = if W::SCALED { m[i] * to } else { m[i] } * xi;
        sum += w0[i].read() * (xi - n0[i]);
        sum += w1[i].read() * (xi - n1[i]);
        sum += w2[i].read() * (xi - n2[i]);
        sum += w3[i].read() * (xi - n3[i]);
        if W::SCALED {
            sum = sum * back;
        }
        let b = if IN_PLACE {
            out[i]
        } else if RESIDUAL {
            r[i]
        } else {
            T::ZERO
        };
        let value = if RESIDUAL { b - sum } else { sum };
        // A select, so the loop vectorises: a halo cell's weights are seam weights.
        out[i] = if m[i] >= T::ZERO { value } else { T::ZERO };
    }
}

/// A level's numbers scaled by `scale` and rounded to `f32` for the V-cycle (`mass32`,
/// and the weights into `w32` where it is given), and its inverse diagonal
/// `1/(scale·d)`, `d` the mass term plus the four side weights summed in `f64` (LEFT to
/// TOP) and rounded once; zero outside the cells. One pass over the level's numbers,
/// both colours a block at a time ([`operator`]); a mass term held `per_face` is
/// rounded on face 0 alone, and read so. Weights held scaled already
/// ([`WeightIn::SCALED`]: the V-cycle's own, `w32` then not given) are summed with the
/// mass term times `scale`, `scale·d` to the bit.
#[inline(always)]
pub(super) fn rounded_level<W: WeightIn<f64>>(
    layout: &Layout,
    scale: f64,
    (mass, w): (LevelField<f64>, &Stencil<W>),
    (mass32, mut w32): (&mut [f32], Option<&mut Stencil<f32>>),
    inv_diag: &mut [f32],
) {
    let range = both_sweeps(layout);
    let half = layout.half;
    for c in 0..2 {
        let start = c * half;
        for part in [start..start + range.start, start + range.end..start + half] {
            round_run(scale, part.clone(), mass.values, mass32);
            round_weights(scale, part.clone(), w, w32.as_deref_mut());
            inv_diag[part].fill(0.0);
        }
    }
    in_blocks(
        layout,
        range,
        mass.per_face,
        #[inline(always)]
        |face, start, len| {
            for c in 0..2 {
                let own = c * half + start..c * half + start + len;
                if !mass.per_face || face == 0 {
                    round_run(scale, own.clone(), mass.values, mass32);
                }
                round_weights(scale, own.clone(), w, w32.as_deref_mut());
                let [w0, w1, w2, w3] = side_weights(layout, c, (start, len), w);
                let m = mass.at(layout, face, own.start, len);
                let inv_diag = &mut inv_diag[own];
                for i in 0..len {
                    let (mi, ws) = (m[i], [w0[i], w1[i], w2[i], w3[i]].map(W::read));
                    let first = if W::SCALED { mi * scale } else { mi };
                    let d = first + ws[0] + ws[1] + ws[2] + ws[3];
                    // Zero outside the cells, by a select, so the loop vectorises (a
                    // halo cell's sum of seam weights, or a division by zero's
                    // infinity, is dropped, not trapped).
                    let inv = (1.0 / if W::SCALED { d } else { scale * d }) as f32;
                    inv_diag[i] = if mi >= 0.0 && d > 0.0 { inv } else { 0.0 };
                }
            }
        },
    );
}

/// Both weight fields' `range` scaled and rounded into `w32` ([`round_run`]), where it
/// is given.
#[inline(always)]
fn round_weights<W: WeightIn<f64>>(
    scale: f64,
    range: std::ops::Range<usize>,
    w: &Stencil<W>,
    w32: Option<&mut Stencil<f32>>,
) {
    if let Some(w32) = w32 {
        round_run(scale, range.clone(), &w[RIGHT_W], &mut w32[RIGHT_W]);
        round_run(scale, range, &w[TOP_W], &mut w32[TOP_W]);
    }
}

/// `out[range] = scale·values[range]` rounded to `f32`.
#[inline(always)]
fn round_run<W: WeightIn<f64>>(
    scale: f64,
    range: std::ops::Range<usize>,
    values: &[W],
    out: &mut [f32],
) {
    for (o, v) in out[range.clone()].iter_mut().zip(&values[range]) {
        *o = (scale * v.read()) as f32;
    }
}

/// Copies into the halo cells of colour `c` their sources' values.
#[inline(always)]
pub(super) fn refresh<T: Real>(layout: &Layout, c: usize, field: &mut [T]) {
    // SAFETY: `for_each_copy` passes positions inside the field; a halo cell is never a
    // source, so the read and the write do not overlap.
    for_each_copy(layout, (c, false), field, |base, halo, source| unsafe {
        *base.add(halo) = *base.add(source);
    });
}

/// Copies into the halo cells of colour `c` whose sources are cells of the other colour
/// their sources' values: after a half-sweep of that other colour, the only ones of
/// colour `c` that changed, where colour `c`'s halo was refreshed before it.
#[inline(always)]
pub(super) fn refresh_from_other<T: Real>(layout: &Layout, c: usize, field: &mut [T]) {
    // SAFETY: as in `refresh`.
    for_each_copy(layout, (c, true), field, |base, halo, source| unsafe {
        *base.add(halo) = *base.add(source);
    });
}

/// Both colours' halo cells refreshed.
#[inline(always)]
pub(super) fn refresh_all<T: Real>(layout: &Layout, field: &mut [T]) {
    refresh(layout, 0, field);
    refresh(layout, 1, field);
}

/// Each copy of colour `c`'s halo runs (`from_other`: only those whose sources are of the
/// other colour): `set(field, halo, source)` on the field's pointer and the copy's
/// positions, every one inside `field`; from the level's flat
/// list of the copies where it holds one ([`Layout::flat_halo_copies`]: the small
/// levels, whose runs' set-up would cost more than their copies).
///
/// Why raw positions: a run walks two constant strides through one array, which safe
/// slices can only do with a check a copy (the index pairs did two) or a division a run
/// (`chunks_exact`), and at the coarse levels, where a run is one to eight copies, the
/// latter costs more than the copies. The layout checked when it was built that every
/// run stays inside its `len()` ([`Layout::halo_runs`]), so checking `field` against
/// that length once makes every position of every run (and of the flat list, the same
/// copies) valid.
#[inline(always)]
fn for_each_copy<T: Copy>(
    layout: &Layout,
    (c, from_other): (usize, bool),
    field: &mut [T],
    set: impl Fn(*mut T, usize, usize),
) {
    let field = &mut field[..layout.len()];
    let base = field.as_mut_ptr();
    if !layout.flat_halo_copies(c).is_empty() {
        let flat = if from_other {
            layout.flat_halo_copies_from_other(c)
        } else {
            layout.flat_halo_copies(c)
        };
        for &[halo, source] in flat {
            set(base, halo as usize, source as usize);
        }
        return;
    }
    let runs = if from_other {
        layout.halo_runs_from_other(c)
    } else {
        layout.halo_runs(c)
    };
    for run in runs {
        let (mut halo, mut source) = (run.halo as usize, run.source as usize);
        let (halo_step, source_step) = (run.halo_step as usize, run.source_step as isize);
        for _ in 0..run.count {
            set(base, halo, source);
            // Past the last copy these may leave the field; they are not used then.
            halo = halo.wrapping_add(halo_step);
            source = source.wrapping_add_signed(source_step);
        }
    }
}

/// `coarse` = the sum of each coarse cell's four children in `fine` (the equations are
/// area-integrated), as the bottom row's pair plus the top row's; its halo untouched.
/// `row` holds one coarse row at a time.
///
/// A function of its own (built for AVX2 where the processor has it): inlined into the
/// V-cycle's, it left the V-cycle's other loops slower, 682.5 M instructions over
/// `film_profile 64 0 9.81`'s 40 steps against 662.1 M (before [`split_row`] and
/// [`add_chunk`] read their chunks whole).
#[inline(never)]
pub(super) fn restrict<T: Real>(
    fine: &Layout,
    fine_values: &[T],
    coarse: &Layout,
    out: &mut [T],
    row: &mut Vec<T>,
) {
    with_avx2(
        #[inline(always)]
        || restrict_from(fine, (fine_values, |face| face), coarse, out, row),
    );
}

/// [`restrict`] of a field that may be held per face ([`LevelField`]): every coarse
/// face from fine face 0's values where it is.
#[inline(always)]
pub(super) fn restrict_field<T: Real>(
    fine: &Layout,
    fine_values: LevelField<T>,
    coarse: &Layout,
    out: &mut [T],
    row: &mut Vec<T>,
) {
    let values = fine_values.values;
    if fine_values.per_face {
        restrict_from(fine, (values, |_| 0), coarse, out, row);
    } else {
        restrict_from(fine, (values, |face| face), coarse, out, row);
    }
}

/// [`restrict`], coarse face `face` from fine face `from(face)`'s values, a face at a
/// time as [`correct`] walks it: each row's sums formed in `row` and split into its
/// colours ([`split_row`]).
#[inline(always)]
fn restrict_from<T: Real>(
    fine: &Layout,
    (fine_values, from): (&[T], impl Fn(usize) -> usize),
    coarse: &Layout,
    out: &mut [T],
    row: &mut Vec<T>,
) {
    let (m, fine_step, coarse_step) = (coarse.m, fine.stride(), coarse.stride());
    row.resize(m, T::ZERO);
    let (lo, hi) = out[..coarse.len()].split_at_mut(coarse.half);
    for face in 0..6 {
        let [a0, b0] = fine.children_of_row(from(face), 0, 0);
        let [a1, b1] = fine.children_of_row(from(face), 0, 1);
        let first = coarse.padded_at(face, 1, 1);
        for y in 0..m {
            let s = y * fine_step;
            let (a0, b0) = (&fine_values[a0 + s..][..m], &fine_values[b0 + s..][..m]);
            let (a1, b1) = (&fine_values[a1 + s..][..m], &fine_values[b1 + s..][..m]);
            let row = &mut row[..m];
            for x in 0..m {
                row[x] = (a0[x] + b0[x]) + (a1[x] + b1[x]);
            }
            // The row's even cells in padded index `f`'s colour, its odd ones in the other.
            let f = first + y * coarse_step;
            let (even, odd) = if f & 1 == 0 {
                (&mut *lo, &mut *hi)
            } else {
                (&mut *hi, &mut *lo)
            };
            let even = &mut even[f >> 1..][..m.div_ceil(2)];
            split_row(row, even, &mut odd[(f + 1) >> 1..][..m / 2]);
        }
    }
}

/// A row's values `row[x]`: the even cells' to `even`, the odd cells' to `odd`.
#[inline(always)]
fn split_row<T: Real>(row: &[T], even: &mut [T], odd: &mut [T]) {
    let m = row.len();
    let halves = even
        .chunks_exact_mut(CHUNK / 2)
        .zip(odd.chunks_exact_mut(CHUNK / 2));
    for (v, (e, o)) in row.chunks_exact(CHUNK).zip(halves) {
        // Read whole first, as in `add_chunk`.
        let v: [T; CHUNK] = v.try_into().expect("a chunk");
        let (mut even, mut odd) = ([T::ZERO; CHUNK / 2], [T::ZERO; CHUNK / 2]);
        for i in 0..CHUNK / 2 {
            (even[i], odd[i]) = (v[2 * i], v[2 * i + 1]);
        }
        e.copy_from_slice(&even);
        o.copy_from_slice(&odd);
    }
    for x in m - m % CHUNK..m {
        if x % 2 == 0 {
            even[x / 2] = row[x];
        } else {
            odd[x / 2] = row[x];
        }
    }
}

/// The coarse level's edge weights: half the sum of the two fine edges' along each
/// coarse edge (see the module's documentation), the fine bottom one first for an
/// x-edge, the fine left one first for a y-edge. The halo's seam weights restrict alike:
/// a coarse rim cell's halo neighbour's entry is its two fine rim children's halo
/// neighbours'. A seam edge held on both of its faces sums the same two numbers on
/// each (in either order, the same bits), so the coarse matrix stays symmetric to the
/// bit.
///
/// Fine weights held scaled by `scale` ([`WeightIn::SCALED`]) are halved by
/// `0.5/scale`, a power of two: the same bits as the unscaled weights' halves.
#[inline(always)]
pub(super) fn restrict_weights<W: WeightIn<f64>>(
    fine: &Layout,
    (fine_w, scale): Weighted<W, f64>,
    coarse: &Layout,
    out: &mut Stencil<f64>,
    row: &mut Vec<f64>,
) {
    let half = if W::SCALED { 0.5 / scale } else { 0.5 };
    let m = coarse.m;
    row.resize(m + 1, 0.0);
    // A run of one colour's entries of the fine level from padded `(row, col)`: every
    // other padded cell along the row.
    let run = |k: usize, face: usize, (r, col): (usize, usize), len: usize| {
        &fine_w[k][fine.index(fine.padded_at(face, r, col))..][..len]
    };
    for face in 0..6 {
        // RIGHT entries of coarse padded row `y + 1`, columns 0 (the halo) to `m`: the
        // fine ones of padded rows `2y + 1` and `2y + 2`, columns 0, 2, …, 2m.
        for y in 0..m {
            let a = run(RIGHT_W, face, (2 * y + 1, 0), m + 1);
            let b = run(RIGHT_W, face, (2 * y + 2, 0), m + 1);
            half_sums(half, a, b, &mut row[..m + 1]);
            let first = coarse.padded_at(face, y + 1, 0);
            scatter_run(coarse, first, &row[..m + 1], &mut out[RIGHT_W]);
        }
        // TOP entries of coarse padded row `y`, 0 (the halo) to `m`, columns 1 to `m`:
        // the fine ones of padded row `2y`, columns 1, 3, … and 2, 4, ….
        for y in 0..m + 1 {
            let a = run(TOP_W, face, (2 * y, 1), m);
            let b = run(TOP_W, face, (2 * y, 2), m);
            half_sums(half, a, b, &mut row[..m]);
            let first = coarse.padded_at(face, y, 1);
            scatter_run(coarse, first, &row[..m], &mut out[TOP_W]);
        }
    }
}

/// `out[x] = half·a[x] + half·b[x]` (`half` ½, or ½ over the weights' scale).
#[inline(always)]
fn half_sums<W: WeightIn<f64>>(half: f64, a: &[W], b: &[W], out: &mut [f64]) {
    for ((o, a), b) in out.iter_mut().zip(a).zip(b) {
        *o = half * a.read() + half * b.read();
    }
}

/// A run of `len` consecutive padded cells from padded index `first`: its cells of the
/// first one's colour (the 1st, 3rd, …) and of the other colour (the 2nd, 4th, …) as
/// two slices of `field`, each consecutive in its colour's array.
#[inline(always)]
fn run_halves<'a, T>(
    layout: &Layout,
    first: usize,
    len: usize,
    field: &'a mut [T],
) -> (&'a mut [T], &'a mut [T]) {
    let half = layout.half;
    let (even, odd) = (layout.index(first), layout.index(first + 1));
    let (lo, hi) = field[..2 * half].split_at_mut(half);
    let (e, o) = if even < half {
        (&mut lo[even..], &mut hi[odd - half..])
    } else {
        (&mut hi[even - half..], &mut lo[odd..])
    };
    (&mut e[..len.div_ceil(2)], &mut o[..len / 2])
}

/// Writes `values[j]` to padded index `first + j`, for each `j`.
#[inline(always)]
pub(super) fn scatter_run<T: Real>(layout: &Layout, first: usize, values: &[T], out: &mut [T]) {
    let (even, odd) = run_halves(layout, first, values.len(), out);
    // A leading run of whole chunks by the precision's own vectorised copy where it has
    // one (`f64`'s: the compiler's were one value at a time), the rest below.
    let done = T::deinterleave(values, even, odd);
    let (values, even, odd) = (&values[done..], &mut even[done / 2..], &mut odd[done / 2..]);
    let len = values.len();
    // Eight pairs at a time in chunks of constant length, so the compiler splits them
    // with shuffles (zipped two-value chunks were left a value at a time), then the
    // rest a pair at a time.
    let pairs = len / 2;
    let mut e8 = even[..pairs].chunks_exact_mut(8);
    let mut o8 = odd[..pairs].chunks_exact_mut(8);
    let v16 = values[..2 * pairs].chunks_exact(16);
    let v_rest = v16.remainder();
    for ((e, o), v) in (&mut e8).zip(&mut o8).zip(v16) {
        for k in 0..8 {
            (e[k], o[k]) = (v[2 * k], v[2 * k + 1]);
        }
    }
    let (e_rest, o_rest) = (e8.into_remainder(), o8.into_remainder());
    for ((e, o), v) in e_rest.iter_mut().zip(o_rest).zip(v_rest.chunks_exact(2)) {
        (*e, *o) = (v[0], v[1]);
    }
    if len % 2 == 1 {
        even[len / 2] = values[len - 1];
    }
}

/// Writes a row's values `values[x]`, `x` along the row, to their positions.
#[inline(always)]
pub(super) fn scatter_row<T: Real>(
    layout: &Layout,
    face: usize,
    y: usize,
    values: &[T],
    out: &mut [T],
) {
    let m = layout.m;
    scatter_run(layout, layout.padded_at(face, y + 1, 1), &values[..m], out);
}

/// Reads a row's values, in order along the row, from their positions into `row`.
#[inline(always)]
pub(super) fn gather_row<T: Real>(
    layout: &Layout,
    face: usize,
    y: usize,
    field: &mut [T],
    row: &mut [T],
) {
    let m = layout.m;
    let (even, odd) = run_halves(layout, layout.padded_at(face, y + 1, 1), m, field);
    // As in `scatter_run`: a leading run by the precision's vectorised copy.
    let done = T::interleave(even, odd, &mut row[..m]);
    let pairs = row[done..m].chunks_exact_mut(2);
    let (rest_even, rest_odd) = (&even[done / 2..], &odd[done / 2..]);
    for ((pair, e), o) in pairs.zip(rest_even.iter()).zip(rest_odd.iter()) {
        (pair[0], pair[1]) = (*e, *o);
    }
    if m % 2 == 1 {
        row[m - 1] = even[m / 2];
    }
}

/// Values a chunk of [`correct_row`] and [`split_row`] takes: one AVX2 vector of `f32`,
/// formed from (or split into) two half vectors by shuffles.
const CHUNK: usize = 8;

/// `z += zc` at every fine cell from its coarse parent: the coarse correction, a face
/// at a time: a coarse row's fine child rows lie [`Layout::stride`] further than the
/// last row's in each colour, and its cells start at the next padded row, so a row
/// costs a few adds of set-up ([`correct_row`]). A function of its own, as [`restrict`]
/// is (inlined, 0.2 M instructions more over `film_profile 64 0 9.81`'s 40 steps).
#[inline(never)]
pub(super) fn correct(fine: &Layout, coarse: &Layout, zc: &[f32], z: &mut [f32]) {
    with_avx2(
        #[inline(always)]
        || correct_faces(fine, coarse, zc, z),
    );
}

/// [`correct`]'s loops, inlined into its AVX2 build.
#[inline(always)]
fn correct_faces(fine: &Layout, coarse: &Layout, zc: &[f32], z: &mut [f32]) {
    let (m, fine_step, coarse_step) = (coarse.m, fine.stride(), coarse.stride());
    let (c_lo, c_hi) = zc[..coarse.len()].split_at(coarse.half);
    let half = fine.half;
    let (lo, hi) = z[..fine.len()].split_at_mut(half);
    for face in 0..6 {
        // Children a0 and b1 lie in one colour, b1 after a0's run; b0 and a1 in the
        // other, a1 after b0's: their runs are cut apart by a split at the later one.
        let [a0, b0] = fine.children_of_row(face, 0, 0);
        let [a1, b1] = fine.children_of_row(face, 0, 1);
        let (first, second) = if a0 < half {
            (&mut *lo, &mut *hi)
        } else {
            (&mut *hi, &mut *lo)
        };
        let (a0, b1) = (a0 % half, b1 % half);
        let (b0, a1) = (b0 % half, a1 % half);
        let coarse_first = coarse.padded_at(face, 1, 1);
        for y in 0..m {
            let s = y * fine_step;
            let (x0, x3) = first[a0 + s..].split_at_mut(b1 - a0);
            let (x1, x2) = second[b0 + s..].split_at_mut(a1 - b0);
            let f = coarse_first + y * coarse_step;
            let (even, odd) = if f & 1 == 0 {
                (c_lo, c_hi)
            } else {
                (c_hi, c_lo)
            };
            let (even, odd) = (
                &even[f >> 1..][..m.div_ceil(2)],
                &odd[(f + 1) >> 1..][..m / 2],
            );
            let children = [&mut x0[..m], &mut x1[..m], &mut x2[..m], &mut x3[..m]];
            correct_row(even, odd, children);
        }
    }
}

/// `child += v`, read whole before it is written: the compiler cannot tell a chunk
/// from the row's other children (they are cut from one field), so element by element
/// each store might change the next load, and the adds were left one at a time.
#[inline(always)]
fn add_chunk(child: &mut [f32], v: &[f32; CHUNK]) {
    let child: &mut [f32; CHUNK] = child.try_into().expect("a chunk");
    let mut sum = *child;
    for (s, v) in sum.iter_mut().zip(v) {
        *s += *v;
    }
    *child = sum;
}

/// A coarse row's values, its even cells' `even` and its odd cells' `odd`, added to
/// each of its cells' fine children (`children`, each in order along the row).
#[inline(always)]
fn correct_row(even: &[f32], odd: &[f32], children: [&mut [f32]; 4]) {
    let [a0, b0, a1, b1] = children;
    let m = a0.len();
    let halves = even
        .chunks_exact(CHUNK / 2)
        .zip(odd.chunks_exact(CHUNK / 2));
    let chunks = a0.chunks_exact_mut(CHUNK).zip(b0.chunks_exact_mut(CHUNK));
    let chunks = chunks.zip(a1.chunks_exact_mut(CHUNK).zip(b1.chunks_exact_mut(CHUNK)));
    for ((e, o), ((a0, b0), (a1, b1))) in halves.zip(chunks) {
        let mut v = [0.0; CHUNK];
        for i in 0..CHUNK / 2 {
            (v[2 * i], v[2 * i + 1]) = (e[i], o[i]);
        }
        for child in [a0, b0, a1, b1] {
            add_chunk(child, &v);
        }
    }
    for x in m - m % CHUNK..m {
        let v = if x % 2 == 0 { even[x / 2] } else { odd[x / 2] };
        a0[x] += v;
        b0[x] += v;
        a1[x] += v;
        b1[x] += v;
    }
}

/// Lanes of the dot products' partial sums: independent adds the core can overlap (one
/// running sum waits on every add before it), in a fixed order, so results stay the same.
const LANES: usize = 4;

/// `a·b`, summed in [`LANES`] lanes ([`dot_lanes`]) and then across them, the tail
/// last.
#[inline(always)]
pub(super) fn dot(a: &[f64], b: &[f64]) -> f64 {
    let main = a.len() - a.len() % LANES;
    let lanes = dot_lanes(&a[..main], &b[..main]);
    let tail: f64 = a[main..].iter().zip(&b[main..]).map(|(x, y)| x * y).sum();
    (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]) + tail
}

/// `a·b`, `f32` fields widened to `f64` (each product exact), summed as [`dot`] sums
/// ([`widened_dot_lanes`]).
#[inline(always)]
pub(super) fn widened_dot(a: &[f32], b: &[f32]) -> f64 {
    let main = a.len() - a.len() % LANES;
    let lanes = widened_dot_lanes(&a[..main], &b[..main]);
    let mut tail = 0.0;
    for (x, y) in a[main..].iter().zip(&b[main..a.len()]) {
        tail += f64::from(*x) * f64::from(*y);
    }
    (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]) + tail
}

/// The conjugate gradients' next direction `p = back·z + β·p`, `z` widened to `f64`, or
/// `p = back·z` for the first (`beta` `None`).
#[inline(always)]
pub(super) fn update_direction<T: Real>(back: f64, z: &[T], beta: Option<f64>, p: &mut [f64]) {
    let z = &z[..p.len()];
    match beta {
        Some(beta) => {
            for (pi, zi) in p.iter_mut().zip(z) {
                *pi = back * zi.widen() + beta * *pi;
            }
        }
        None => {
            for (pi, zi) in p.iter_mut().zip(z) {
                *pi = back * zi.widen();
            }
        }
    }
}

/// `x += step·p`, `r −= step·q`, and returns `r·r`, summed as [`dot`] sums: each
/// lane's `r` squared as it is made (one pass over `r`, where the dot read it back), `x`
/// in a pass of its own (with both updated in one loop the compiler could not tell them
/// apart and kept it scalar).
#[inline(always)]
pub(super) fn update_and_norm2(
    step: f64,
    p: &[f64],
    q: &[f64],
    x: &mut [f64],
    r: &mut [f64],
) -> f64 {
    for (xi, pi) in x.iter_mut().zip(p) {
        *xi += step * pi;
    }
    let main = r.len() - r.len() % LANES;
    let (r, r_tail) = r.split_at_mut(main);
    let (q, q_tail) = q.split_at(main);
    let lanes = subtract_and_square_lanes(step, &q[..main], r);
    for (ri, qi) in r_tail.iter_mut().zip(q_tail) {
        *ri -= step * qi;
    }
    let tail: f64 = r_tail.iter().zip(r_tail.iter()).map(|(x, y)| x * y).sum();
    (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]) + tail
}

/// The `f32` iterations' first direction `p' = z' + c·p` rounded to `f32` (`z'` the
/// V-cycle's answer, `p` the last `f64` direction, `c = β/back`).
#[inline(always)]
pub(super) fn direction_from_f64(z: &[f32], c: f64, p: &[f64], out: &mut [f32]) {
    let (z, p) = (&z[..out.len()], &p[..out.len()]);
    for ((o, zi), pi) in out.iter_mut().zip(z).zip(p) {
        *o = (f64::from(*zi) + c * pi) as f32;
    }
}

/// The `f32` iterations' next direction `p' = z' + β·p'`.
#[inline(always)]
pub(super) fn update_direction_f32(beta: f32, z: &[f32], p: &mut [f32]) {
    let z = &z[..p.len()];
    for (pi, zi) in p.iter_mut().zip(z) {
        *pi = *zi + beta * *pi;
    }
}

/// `x += a·p`, each `p` widened to `f64` (exactly).
#[inline(always)]
pub(super) fn add_widened(a: f64, p: &[f32], x: &mut [f64]) {
    let p = &p[..x.len()];
    for (xi, pi) in x.iter_mut().zip(p) {
        *xi += a * f64::from(*pi);
    }
}

/// `r −= a·q` in `f32`.
#[inline(always)]
pub(super) fn subtract_scaled(a: f32, q: &[f32], r: &mut [f32]) {
    let q = &q[..r.len()];
    for (ri, qi) in r.iter_mut().zip(q) {
        *ri -= a * *qi;
    }
}

/// `a·b` of the `f32` iterations' fields, summed in `f32` in [`F32_LANES`] lanes
/// ([`dot_lanes_f32`]), then the lanes widened and summed in `f64` in order, the tail's
/// products (widened, exact) last.
#[inline(always)]
pub(super) fn dot_f32(a: &[f32], b: &[f32]) -> f64 {
    let main = a.len() - a.len() % F32_LANES;
    let lanes = dot_lanes_f32(&a[..main], &b[..main]);
    let mut sum = 0.0;
    for lane in lanes {
        sum += f64::from(lane);
    }
    for (x, y) in a[main..].iter().zip(&b[main..a.len()]) {
        sum += f64::from(*x) * f64::from(*y);
    }
    sum
}
