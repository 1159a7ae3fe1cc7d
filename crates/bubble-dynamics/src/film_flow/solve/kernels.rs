//! The solve's loops over a level's split fields ([`Layout`]): the half-sweeps, the
//! operator, the halo refresh, the restriction and the coarse correction, and the
//! conjugate gradients' dot products and updates. Each is a loop over contiguous slices
//! cut to one length first (so it vectorises and checks no bounds inside), written
//! once for `f32` and `f64` ([`Real`]) as IEEE operations in a fixed order.

use super::Real;
use super::layout::Layout;
use crate::avx2::{dot_lanes, subtract_and_square_lanes, widen_and_dot_lanes};

/// Per side, a level's edge weights as a field: each cell's weight of the edge on that
/// side (zero at the halo cells).
pub(super) type Stencil<T> = [Vec<T>; 4];

/// Slice `values[start + offset..][..len]`.
#[inline(always)]
fn shifted<T>(values: &[T], start: usize, offset: isize, len: usize) -> &[T] {
    &values[(start as isize + offset) as usize..][..len]
}

/// The four neighbour slices and the four weight slices of the cells at `range` of
/// colour `c` (`own` is the colour's array, `other` the other's).
#[inline(always)]
fn around<'a, T>(
    layout: &Layout,
    c: usize,
    other: &'a [T],
    w: &'a Stencil<T>,
) -> ([&'a [T]; 4], [&'a [T]; 4]) {
    let range = layout.sweep[c].clone();
    let (start, len) = (range.start, range.len());
    let o = layout.neighbour_offsets(c);
    let base = c * layout.half + start;
    (
        [
            shifted(other, start, o[0], len),
            shifted(other, start, o[1], len),
            shifted(other, start, o[2], len),
            shifted(other, start, o[3], len),
        ],
        [
            &w[0][base..][..len],
            &w[1][base..][..len],
            &w[2][base..][..len],
            &w[3][base..][..len],
        ],
    )
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
    let (near, w) = around(layout, c, other, w);
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
    let half = layout.half as u32;
    for &[halo, source] in &layout.halos[0] {
        z[halo as usize] = if source < half {
            z[source as usize]
        } else {
            T::ZERO
        };
    }
}

/// `out = (diag(mass) + L_w) x` (`RESIDUAL` false) or `r − (diag(mass) + L_w) x`
/// (true), as `mᵢxᵢ + Σ wᵢⱼ (xᵢ − xⱼ)`: the differences keep the result accurate where
/// the weights dwarf the mass term and `x` is nearly uniform (a stiff step's
/// surfactant). `x`'s halo must be fresh; the halo cells' results are zero (so a
/// field made from them adds nothing outside the faces to a dot product).
#[inline(always)]
pub(super) fn operator<T: Real, const RESIDUAL: bool>(
    layout: &Layout,
    mass: &[T],
    w: &Stencil<T>,
    r: &[T],
    x: &[T],
    out: &mut [T],
) {
    for c in 0..2 {
        let range = layout.sweep[c].clone();
        let (start, len) = (range.start, range.len());
        let (own, other) = x[..layout.len()].split_at(layout.half);
        let (own, other) = if c == 0 { (own, other) } else { (other, own) };
        let (near, w) = around(layout, c, other, w);
        let base = c * layout.half + start;
        let (m, xs, r) = (&mass[base..][..len], &own[range], &r[base..][..len]);
        let colour = &mut out[c * layout.half..][..layout.half];
        colour[..start].fill(T::ZERO);
        colour[start + len..].fill(T::ZERO);
        let out = &mut colour[start..][..len];
        let [n0, n1, n2, n3] = near;
        let [w0, w1, w2, w3] = w;
        for i in 0..len {
            let xi = xs[i];
            let mut sum = m[i] * xi;
            sum += w0[i] * (xi - n0[i]);
            sum += w1[i] * (xi - n1[i]);
            sum += w2[i] * (xi - n2[i]);
            sum += w3[i] * (xi - n3[i]);
            out[i] = if RESIDUAL { r[i] - sum } else { sum };
        }
    }
}

/// Copies into the halo cells of colour `c` their sources' values.
#[inline(always)]
pub(super) fn refresh<T: Real>(layout: &Layout, c: usize, field: &mut [T]) {
    for &[halo, source] in &layout.halos[c] {
        field[halo as usize] = field[source as usize];
    }
}

/// Both colours' halo cells refreshed.
#[inline(always)]
pub(super) fn refresh_all<T: Real>(layout: &Layout, field: &mut [T]) {
    refresh(layout, 0, field);
    refresh(layout, 1, field);
}

/// `coarse` = the sum of each coarse cell's four children in `fine` (the equations are
/// area-integrated), as the bottom row's pair plus the top row's; its halo untouched.
/// `row` holds one coarse row at a time.
#[inline(always)]
pub(super) fn restrict<T: Real>(
    fine: &Layout,
    fine_values: &[T],
    coarse: &Layout,
    out: &mut [T],
    row: &mut Vec<T>,
) {
    let m = coarse.m;
    row.resize(m, T::ZERO);
    for face in 0..6 {
        for y in 0..m {
            let [a0, b0] = fine.children_of_row(face, y, 0);
            let [a1, b1] = fine.children_of_row(face, y, 1);
            let (a0, b0) = (&fine_values[a0..][..m], &fine_values[b0..][..m]);
            let (a1, b1) = (&fine_values[a1..][..m], &fine_values[b1..][..m]);
            let row = &mut row[..m];
            for x in 0..m {
                row[x] = (a0[x] + b0[x]) + (a1[x] + b1[x]);
            }
            scatter_row(coarse, face, y, row, out);
        }
    }
}

/// The coarse level's edge weights per side: half the sum of the two fine edges' along
/// each coarse side (see the module's documentation). An edge's two cells sum the same
/// two numbers, so the coarse matrix stays symmetric to the bit.
#[inline(always)]
pub(super) fn restrict_weights(
    fine: &Layout,
    fine_w: &Stencil<f64>,
    coarse: &Layout,
    out: &mut Stencil<f64>,
    row: &mut Vec<f64>,
) {
    let m = coarse.m;
    row.resize(m, 0.0);
    // Per side: which fine row (0 bottom, 1 top) and which child of the pair (0 left,
    // 1 right) give its two fine edges.
    const FROM: [[(usize, usize); 2]; 4] = [
        [(0, 0), (1, 0)], // LEFT: the left children of both rows
        [(0, 1), (1, 1)], // RIGHT: the right children of both rows
        [(0, 0), (0, 1)], // BOTTOM: the bottom row's pair
        [(1, 0), (1, 1)], // TOP: the top row's pair
    ];
    for face in 0..6 {
        for y in 0..m {
            let rows = [0, 1].map(|j| fine.children_of_row(face, y, j));
            for (k, [(ja, ia), (jb, ib)]) in FROM.into_iter().enumerate() {
                let a = &fine_w[k][rows[ja][ia]..][..m];
                let b = &fine_w[k][rows[jb][ib]..][..m];
                let row = &mut row[..m];
                for x in 0..m {
                    row[x] = 0.5 * a[x] + 0.5 * b[x];
                }
                scatter_row(coarse, face, y, row, &mut out[k]);
            }
        }
    }
}

/// A coarse row's cells of colour `even`'s (cells 0, 2, …) and of colour `odd`'s (cells
/// 1, 3, …) as two slices of `field` ([`Layout::row_start`]).
#[inline(always)]
fn row_halves<'a, T>(
    layout: &Layout,
    face: usize,
    y: usize,
    field: &'a mut [T],
) -> (&'a mut [T], &'a mut [T]) {
    let (m, half) = (layout.m, layout.half);
    let [even, odd] = layout.row_start(face, y);
    let (lo, hi) = field[..2 * half].split_at_mut(half);
    let (e, o) = if even < half {
        (&mut lo[even..], &mut hi[odd - half..])
    } else {
        (&mut hi[even - half..], &mut lo[odd..])
    };
    (&mut e[..m.div_ceil(2)], &mut o[..m / 2])
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
    let values = &values[..m];
    let (even, odd) = row_halves(layout, face, y, out);
    let pairs = values.chunks_exact(2);
    for ((e, o), pair) in even.iter_mut().zip(odd.iter_mut()).zip(pairs) {
        (*e, *o) = (pair[0], pair[1]);
    }
    if m % 2 == 1 {
        even[m / 2] = values[m - 1];
    }
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
    let (even, odd) = row_halves(layout, face, y, field);
    let pairs = row[..m].chunks_exact_mut(2);
    for ((pair, e), o) in pairs.zip(even.iter()).zip(odd.iter()) {
        (pair[0], pair[1]) = (*e, *o);
    }
    if m % 2 == 1 {
        row[m - 1] = even[m / 2];
    }
}

/// `z += zc` at every fine cell from its coarse parent: the coarse correction.
#[inline(always)]
pub(super) fn correct(
    fine: &Layout,
    coarse: &Layout,
    zc: &mut [f32],
    z: &mut [f32],
    row: &mut Vec<f32>,
) {
    let m = coarse.m;
    row.resize(m, 0.0);
    for face in 0..6 {
        for y in 0..m {
            gather_row(coarse, face, y, zc, row);
            for j in 0..2 {
                for start in fine.children_of_row(face, y, j) {
                    for (zi, v) in z[start..][..m].iter_mut().zip(row.iter()) {
                        *zi += *v;
                    }
                }
            }
        }
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

/// `z = back·z32` (widened to `f64`) and returns `r·z`, summed as [`dot`] sums, in one
/// pass.
#[inline(always)]
pub(super) fn widen_and_dot(back: f64, z32: &[f32], r: &[f64], z: &mut [f64]) -> f64 {
    let main = r.len() - r.len() % LANES;
    let lanes = widen_and_dot_lanes(back, &z32[..main], &r[..main], &mut z[..main]);
    let mut tail = 0.0;
    for ((zi, wi), ri) in z[main..].iter_mut().zip(&z32[main..]).zip(&r[main..]) {
        *zi = back * f64::from(*wi);
        tail += ri * *zi;
    }
    (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]) + tail
}

/// `x += step·p`, `r −= step·q`, and returns `r·r`, summed as [`dot`] sums: each lane's
/// `r` squared as it is made (one pass over `r`, where the dot read it back), `x` in a
/// pass of its own (with both updated in one loop the compiler could not tell them
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
