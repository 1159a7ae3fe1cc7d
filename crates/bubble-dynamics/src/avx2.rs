//! Hot loops compiled for AVX2 where the processor has it: [`with_avx2`] runs a closure
//! inside a function built with the feature, so what the closure inlines is built so too
//! (the film's solve). The triangle pass keeps a named `#[target_feature]` function
//! (`FaceForces::accumulate_avx2`): run through a closure here its block loops compiled to
//! 1.7× the instructions.
//!
//! The loops it runs are IEEE additions and multiplications in a fixed order: no fused
//! multiply-add is enabled and the compiler reorders no floating-point sum, so AVX2 and
//! the portable build (SSE2) give the same bits; AVX2 has four `f64` lanes an instruction
//! where SSE2 has two. Tests switch AVX2 off on their thread ([`set_portable_only`]) and
//! compare the two.

#[cfg(test)]
thread_local! {
    static PORTABLE_ONLY: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// Whether [`with_avx2`] must run the portable code (only tests ask it to).
#[inline(always)]
fn portable_only() -> bool {
    #[cfg(test)]
    return PORTABLE_ONLY.get();
    #[cfg(not(test))]
    false
}

/// Runs `f` compiled for AVX2 where the processor has it, else as built; both give the
/// same bits (see the module's documentation).
#[inline(always)]
pub(crate) fn with_avx2<R>(f: impl FnOnce() -> R) -> R {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") && !portable_only() {
        // SAFETY: the processor supports AVX2, checked just above.
        return unsafe { run_avx2(f) };
    }
    f()
}

/// `f()` compiled with AVX2 (what `f` inlines is compiled so too).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn run_avx2<R>(f: impl FnOnce() -> R) -> R {
    f()
}

/// Makes [`with_avx2`] run the portable code on this thread (`true`) or not (`false`).
#[cfg(test)]
pub(crate) fn set_portable_only(portable: bool) {
    PORTABLE_ONLY.set(portable);
}

/// Four running sums of `a[i]·b[i]`, lane `k` over the `i ≡ k (mod 4)` in increasing
/// order, over the first `4⌊len/4⌋` elements: the same bits with AVX2 (one instruction a
/// chunk, where the compiler's own vectorisation of the portable loop shuffled two lanes
/// at a time) as without.
///
/// # Panics
/// If the slices differ in length.
#[inline(always)]
pub(crate) fn dot_lanes(a: &[f64], b: &[f64]) -> [f64; 4] {
    assert_eq!(a.len(), b.len(), "dot of slices of different lengths");
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") && !portable_only() {
        // SAFETY: the processor supports AVX2, checked just above.
        return unsafe { dot_lanes_avx2(a, b) };
    }
    let mut lanes = [0.0; 4];
    for (x, y) in a.chunks_exact(4).zip(b.chunks_exact(4)) {
        for k in 0..4 {
            lanes[k] += x[k] * y[k];
        }
    }
    lanes
}

/// [`dot_lanes`] in AVX2 registers.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn dot_lanes_avx2(a: &[f64], b: &[f64]) -> [f64; 4] {
    use std::arch::x86_64::{_mm256_add_pd, _mm256_loadu_pd, _mm256_mul_pd, _mm256_setzero_pd};
    let mut sum = _mm256_setzero_pd();
    for (x, y) in a.chunks_exact(4).zip(b.chunks_exact(4)) {
        // SAFETY: each chunk holds four `f64`s, the unaligned loads' width.
        let (x, y) = unsafe { (_mm256_loadu_pd(x.as_ptr()), _mm256_loadu_pd(y.as_ptr())) };
        sum = _mm256_add_pd(sum, _mm256_mul_pd(x, y));
    }
    let mut lanes = [0.0; 4];
    // SAFETY: `lanes` holds four `f64`s, the unaligned store's width.
    unsafe { std::arch::x86_64::_mm256_storeu_pd(lanes.as_mut_ptr(), sum) };
    lanes
}

/// `r[i] −= step·q[i]` over the first `4⌊len/4⌋` elements, and four running sums of the
/// new `r[i]²` as [`dot_lanes`] sums: the same bits with AVX2 as without.
///
/// # Panics
/// If the slices differ in length.
#[inline(always)]
pub(crate) fn subtract_and_square_lanes(step: f64, q: &[f64], r: &mut [f64]) -> [f64; 4] {
    assert_eq!(q.len(), r.len(), "update of slices of different lengths");
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") && !portable_only() {
        // SAFETY: the processor supports AVX2, checked just above.
        return unsafe { subtract_and_square_lanes_avx2(step, q, r) };
    }
    let mut lanes = [0.0; 4];
    for (rs, qs) in r.chunks_exact_mut(4).zip(q.chunks_exact(4)) {
        for k in 0..4 {
            rs[k] -= step * qs[k];
            lanes[k] += rs[k] * rs[k];
        }
    }
    lanes
}

/// [`subtract_and_square_lanes`] in AVX2 registers.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn subtract_and_square_lanes_avx2(step: f64, q: &[f64], r: &mut [f64]) -> [f64; 4] {
    use std::arch::x86_64::{
        _mm256_add_pd, _mm256_loadu_pd, _mm256_mul_pd, _mm256_set1_pd, _mm256_setzero_pd,
        _mm256_storeu_pd, _mm256_sub_pd,
    };
    let (step, mut sum) = (_mm256_set1_pd(step), _mm256_setzero_pd());
    for (rs, qs) in r.chunks_exact_mut(4).zip(q.chunks_exact(4)) {
        // SAFETY: each chunk holds four `f64`s, the unaligned loads' and store's width.
        unsafe {
            let (ri, qi) = (_mm256_loadu_pd(rs.as_ptr()), _mm256_loadu_pd(qs.as_ptr()));
            let next = _mm256_sub_pd(ri, _mm256_mul_pd(step, qi));
            _mm256_storeu_pd(rs.as_mut_ptr(), next);
            sum = _mm256_add_pd(sum, _mm256_mul_pd(next, next));
        }
    }
    let mut lanes = [0.0; 4];
    // SAFETY: `lanes` holds four `f64`s, the unaligned store's width.
    unsafe { _mm256_storeu_pd(lanes.as_mut_ptr(), sum) };
    lanes
}

/// Four running sums of `a[i]·b[i]`, both widened from `f32` to `f64` (each product
/// exact), as [`dot_lanes`] sums, over the first `4⌊len/4⌋` elements: the solve's `r·z`
/// read from the `f32` preconditioner's right-hand side and answer, both still in cache;
/// the same bits with AVX2 as without.
///
/// # Panics
/// If the slices differ in length.
#[inline(always)]
pub(crate) fn widened_dot_lanes(a: &[f32], b: &[f32]) -> [f64; 4] {
    assert_eq!(a.len(), b.len(), "slices of different lengths");
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") && !portable_only() {
        // SAFETY: the processor supports AVX2, checked just above.
        return unsafe { widened_dot_lanes_avx2(a, b) };
    }
    let mut lanes = [0.0; 4];
    for (x, y) in a.chunks_exact(4).zip(b.chunks_exact(4)) {
        for k in 0..4 {
            lanes[k] += f64::from(x[k]) * f64::from(y[k]);
        }
    }
    lanes
}

/// [`widened_dot_lanes`] in AVX2 registers.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn widened_dot_lanes_avx2(a: &[f32], b: &[f32]) -> [f64; 4] {
    use std::arch::x86_64::{
        _mm_loadu_ps, _mm256_add_pd, _mm256_cvtps_pd, _mm256_mul_pd, _mm256_setzero_pd,
        _mm256_storeu_pd,
    };
    let mut sum = _mm256_setzero_pd();
    for (x, y) in a.chunks_exact(4).zip(b.chunks_exact(4)) {
        // SAFETY: each chunk holds four numbers, the unaligned loads' width.
        unsafe {
            let x = _mm256_cvtps_pd(_mm_loadu_ps(x.as_ptr()));
            let y = _mm256_cvtps_pd(_mm_loadu_ps(y.as_ptr()));
            sum = _mm256_add_pd(sum, _mm256_mul_pd(x, y));
        }
    }
    let mut lanes = [0.0; 4];
    // SAFETY: `lanes` holds four `f64`s, the unaligned store's width.
    unsafe { _mm256_storeu_pd(lanes.as_mut_ptr(), sum) };
    lanes
}

/// Lanes of [`dot_lanes_f32`]: four AVX2 vectors of eight `f32`s, four independent
/// chains of adds (one vector's chain waits four cycles an add).
pub(crate) const F32_LANES: usize = 32;

/// [`F32_LANES`] running sums of `a[i]·b[i]` in `f32`, lane `k` over the
/// `i ≡ k (mod 32)` in increasing order, over the first `32⌊len/32⌋` elements: the
/// conjugate gradients' `f32` iterations' dot products (a lane sums about 800 terms at
/// n = 64, each rounding within 6e-8 of the lane, far below what the products weigh: the
/// directions' steps and the residual's norm to a few millionths). The same bits with
/// AVX2 as without.
///
/// # Panics
/// If the slices differ in length.
#[inline(always)]
pub(crate) fn dot_lanes_f32(a: &[f32], b: &[f32]) -> [f32; F32_LANES] {
    assert_eq!(a.len(), b.len(), "dot of slices of different lengths");
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") && !portable_only() {
        // SAFETY: the processor supports AVX2, checked just above.
        return unsafe { dot_lanes_f32_avx2(a, b) };
    }
    let mut lanes = [0.0; F32_LANES];
    for (x, y) in a.chunks_exact(F32_LANES).zip(b.chunks_exact(F32_LANES)) {
        for k in 0..F32_LANES {
            lanes[k] += x[k] * y[k];
        }
    }
    lanes
}

/// [`dot_lanes_f32`] in AVX2 registers.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn dot_lanes_f32_avx2(a: &[f32], b: &[f32]) -> [f32; F32_LANES] {
    use std::arch::x86_64::{
        __m256, _mm256_add_ps, _mm256_loadu_ps, _mm256_mul_ps, _mm256_setzero_ps, _mm256_storeu_ps,
    };
    let mut sums: [__m256; 4] = [_mm256_setzero_ps(); 4];
    for (x, y) in a.chunks_exact(F32_LANES).zip(b.chunks_exact(F32_LANES)) {
        for (j, sum) in sums.iter_mut().enumerate() {
            // SAFETY: each chunk holds 32 numbers, four loads of eight each.
            let (x, y) = unsafe {
                (
                    _mm256_loadu_ps(x.as_ptr().add(8 * j)),
                    _mm256_loadu_ps(y.as_ptr().add(8 * j)),
                )
            };
            *sum = _mm256_add_ps(*sum, _mm256_mul_ps(x, y));
        }
    }
    let mut lanes = [0.0; F32_LANES];
    for (j, sum) in sums.iter().enumerate() {
        // SAFETY: `lanes` holds 32 numbers, four stores of eight each.
        unsafe { _mm256_storeu_ps(lanes.as_mut_ptr().add(8 * j), *sum) };
    }
    lanes
}

/// Values [`deinterleave_f64`] and [`interleave_f64`] take a chunk: two AVX2 vectors
/// of `f64`.
const PAIRS_CHUNK: usize = 8;

/// `even[k] = values[2k]` and `odd[k] = values[2k + 1]` over the first chunks of
/// [`PAIRS_CHUNK`] values that all three slices hold; returns how many values that was.
/// With AVX2 two loads, two unpacks, two lane permutes and two stores a chunk, where the
/// compiler left the `f64` copies one at a time (the split layout's scatters: each
/// face row's cells to its two colours); copies, so the same bits either way.
#[inline(always)]
pub(crate) fn deinterleave_f64(values: &[f64], even: &mut [f64], odd: &mut [f64]) -> usize {
    let half = PAIRS_CHUNK / 2;
    let chunks = (values.len() / PAIRS_CHUNK)
        .min(even.len() / half)
        .min(odd.len() / half);
    let done = chunks * PAIRS_CHUNK;
    let (values, even, odd) = (&values[..done], &mut even[..done / 2], &mut odd[..done / 2]);
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") && !portable_only() {
        // SAFETY: the processor supports AVX2, checked just above.
        unsafe { deinterleave_f64_avx2(values, even, odd) };
        return done;
    }
    let halves = even.chunks_exact_mut(half).zip(odd.chunks_exact_mut(half));
    for (v, (e, o)) in values.chunks_exact(PAIRS_CHUNK).zip(halves) {
        for k in 0..half {
            (e[k], o[k]) = (v[2 * k], v[2 * k + 1]);
        }
    }
    done
}

/// [`deinterleave_f64`]'s chunks in AVX2 registers (the slices cut to whole chunks).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn deinterleave_f64_avx2(values: &[f64], even: &mut [f64], odd: &mut [f64]) {
    use std::arch::x86_64::{
        _mm256_loadu_pd, _mm256_permute4x64_pd, _mm256_storeu_pd, _mm256_unpackhi_pd,
        _mm256_unpacklo_pd,
    };
    let half = PAIRS_CHUNK / 2;
    let halves = even.chunks_exact_mut(half).zip(odd.chunks_exact_mut(half));
    for (v, (e, o)) in values.chunks_exact(PAIRS_CHUNK).zip(halves) {
        // SAFETY: each chunk holds eight values and each half four, the loads' and
        // stores' widths.
        unsafe {
            let a = _mm256_loadu_pd(v.as_ptr());
            let b = _mm256_loadu_pd(v.as_ptr().add(half));
            // [v0 v4 v2 v6] and [v1 v5 v3 v7], their middle lanes swapped.
            let (lo, hi) = (_mm256_unpacklo_pd(a, b), _mm256_unpackhi_pd(a, b));
            _mm256_storeu_pd(e.as_mut_ptr(), _mm256_permute4x64_pd(lo, 0b11_01_10_00));
            _mm256_storeu_pd(o.as_mut_ptr(), _mm256_permute4x64_pd(hi, 0b11_01_10_00));
        }
    }
}

/// `out[2k] = even[k]` and `out[2k + 1] = odd[k]` over the first chunks of
/// [`PAIRS_CHUNK`] values that all three slices hold; returns how many values that was:
/// [`deinterleave_f64`]'s inverse (the split layout's gathers).
#[inline(always)]
pub(crate) fn interleave_f64(even: &[f64], odd: &[f64], out: &mut [f64]) -> usize {
    let half = PAIRS_CHUNK / 2;
    let chunks = (out.len() / PAIRS_CHUNK)
        .min(even.len() / half)
        .min(odd.len() / half);
    let done = chunks * PAIRS_CHUNK;
    let (even, odd, out) = (&even[..done / 2], &odd[..done / 2], &mut out[..done]);
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") && !portable_only() {
        // SAFETY: the processor supports AVX2, checked just above.
        unsafe { interleave_f64_avx2(even, odd, out) };
        return done;
    }
    let halves = even.chunks_exact(half).zip(odd.chunks_exact(half));
    for (v, (e, o)) in out.chunks_exact_mut(PAIRS_CHUNK).zip(halves) {
        for k in 0..half {
            (v[2 * k], v[2 * k + 1]) = (e[k], o[k]);
        }
    }
    done
}

/// [`interleave_f64`]'s chunks in AVX2 registers (the slices cut to whole chunks).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn interleave_f64_avx2(even: &[f64], odd: &[f64], out: &mut [f64]) {
    use std::arch::x86_64::{
        _mm256_loadu_pd, _mm256_permute4x64_pd, _mm256_storeu_pd, _mm256_unpackhi_pd,
        _mm256_unpacklo_pd,
    };
    let half = PAIRS_CHUNK / 2;
    let halves = even.chunks_exact(half).zip(odd.chunks_exact(half));
    for (v, (e, o)) in out.chunks_exact_mut(PAIRS_CHUNK).zip(halves) {
        // SAFETY: each chunk holds eight values and each half four, the loads' and
        // stores' widths.
        unsafe {
            // [e0 e2 e1 e3] and [o0 o2 o1 o3]: their unpacks are the pairs in order.
            let e = _mm256_permute4x64_pd(_mm256_loadu_pd(e.as_ptr()), 0b11_01_10_00);
            let o = _mm256_permute4x64_pd(_mm256_loadu_pd(o.as_ptr()), 0b11_01_10_00);
            _mm256_storeu_pd(v.as_mut_ptr(), _mm256_unpacklo_pd(e, o));
            _mm256_storeu_pd(v.as_mut_ptr().add(half), _mm256_unpackhi_pd(e, o));
        }
    }
}

/// For each of a cell's four sides, the other three, in the order of the four.
pub(crate) const OTHERS: [[usize; 3]; 4] = [[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]];

/// The weights of a group of four cells in [`coriolis_row`]: per other side `k`, per
/// side `i`, per cell (index `(4k + i)·4 + cell`), so that a group's twelve weight
/// vectors are read from one base.
pub(crate) const QUAD_WEIGHTS: usize = 48;

/// The first cells of a row of `n` cells' groups of four in [`coriolis_row`]: every
/// fourth, then the last four again where `n` is not a multiple of four (the cells taken
/// twice get the same terms twice), or one group of all `n` where `n < 4`.
pub(crate) fn quad_starts(n: usize) -> impl Iterator<Item = usize> {
    (0..n / 4)
        .map(|g| 4 * g)
        .chain((n % 4 != 0).then(|| n.saturating_sub(4)))
}

/// A row of `n` cells' terms of their sides' rates into `out` (per side: bottom, left,
/// right, top): side `i`'s `Σ_k w[k][i] (ζ_i + ζ_o) u_o` over the other sides
/// `o = OTHERS[i][k]`, summed in `k` order, each side's `ζ` the sum of its two corners'
/// (from `z`, the row's bottom and top vertices, `n + 1` each), `u` the bottom sides'
/// velocities, the left and right sides' (`n + 1`: cell `x`'s left is `x`, its right
/// `x + 1`) and the top sides', `w` the groups' weights as [`QUAD_WEIGHTS`] lays them
/// out. The same bits with AVX2 (explicit, from five input bases: the compiler's loop
/// over twelve weight arrays and eight shifted slices ran out of registers) as without.
///
/// # Panics
/// If the slices' lengths do not fit `n`, or `w` is short of the groups' weights.
#[inline(always)]
pub(crate) fn coriolis_row(w: &[f64], z: [&[f64]; 2], u: [&[f64]; 3], out: [&mut [f64]; 4]) {
    let n = u[0].len();
    let fits = z.iter().all(|s| s.len() == n + 1) && u[1].len() == n + 1 && u[2].len() == n;
    assert!(
        fits && out.iter().all(|s| s.len() == n),
        "row slices do not fit"
    );
    assert!(w.len() >= n.div_ceil(4) * QUAD_WEIGHTS, "short of weights");
    #[cfg(target_arch = "x86_64")]
    if n >= 4 && std::arch::is_x86_feature_detected!("avx2") && !portable_only() {
        // SAFETY: the processor supports AVX2, checked just above.
        return unsafe { coriolis_row_avx2(w, z, u, out) };
    }
    let ([zb, zt], [ub, ux, ut]) = (z, u);
    let [ob, ol, or, ot] = out;
    for (wq, start) in w.chunks_exact(QUAD_WEIGHTS).zip(quad_starts(n)) {
        for x in start..(start + 4).min(n) {
            let c = [zb[x], zb[x + 1], zt[x], zt[x + 1]];
            let z = [c[0] + c[1], c[0] + c[2], c[1] + c[3], c[2] + c[3]];
            let v = [ub[x], ux[x], ux[x + 1], ut[x]];
            let wk = |k: usize, i: usize| wq[(4 * k + i) * 4 + x - start];
            let rate = |i: usize| {
                let [a, b, c] = OTHERS[i];
                let t0 = wk(0, i) * (z[i] + z[a]) * v[a];
                let t1 = wk(1, i) * (z[i] + z[b]) * v[b];
                let t2 = wk(2, i) * (z[i] + z[c]) * v[c];
                t0 + t1 + t2
            };
            (ob[x], ol[x], or[x], ot[x]) = (rate(0), rate(1), rate(2), rate(3));
        }
    }
}

/// [`coriolis_row`] in AVX2 registers, four cells an instruction (`n ≥ 4`).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn coriolis_row_avx2(w: &[f64], z: [&[f64]; 2], u: [&[f64]; 3], out: [&mut [f64]; 4]) {
    use std::arch::x86_64::{_mm256_add_pd, _mm256_loadu_pd, _mm256_mul_pd, _mm256_storeu_pd};
    let n = u[0].len();
    let ([zb, zt], [ub, ux, ut]) = (z.map(<[f64]>::as_ptr), u.map(<[f64]>::as_ptr));
    let out = out.map(<[f64]>::as_mut_ptr);
    let quad = |wq: &[f64], x: usize| {
        // SAFETY: `x + 4 ≤ n` (`n ≥ 4`), the slices are as long as `coriolis_row` checked
        // (`n + 1` where read at `x + 1`) and `wq` holds `QUAD_WEIGHTS`: every load and
        // store is in bounds.
        unsafe {
            let ld = |p: *const f64, at: usize| _mm256_loadu_pd(p.wrapping_add(at));
            let (c0, c1, c2, c3) = (ld(zb, x), ld(zb, x + 1), ld(zt, x), ld(zt, x + 1));
            let z = [
                _mm256_add_pd(c0, c1),
                _mm256_add_pd(c0, c2),
                _mm256_add_pd(c1, c3),
                _mm256_add_pd(c2, c3),
            ];
            let v = [ld(ub, x), ld(ux, x), ld(ux, x + 1), ld(ut, x)];
            let wk = |k: usize, i: usize| ld(wq.as_ptr(), (4 * k + i) * 4);
            for (i, o) in out.iter().enumerate() {
                let [a, b, d] = OTHERS[i];
                let t0 = _mm256_mul_pd(_mm256_mul_pd(wk(0, i), _mm256_add_pd(z[i], z[a])), v[a]);
                let t1 = _mm256_mul_pd(_mm256_mul_pd(wk(1, i), _mm256_add_pd(z[i], z[b])), v[b]);
                let t2 = _mm256_mul_pd(_mm256_mul_pd(wk(2, i), _mm256_add_pd(z[i], z[d])), v[d]);
                let rate = _mm256_add_pd(_mm256_add_pd(t0, t1), t2);
                _mm256_storeu_pd(o.wrapping_add(x), rate);
            }
        }
    };
    let mut quads = w.chunks_exact(QUAD_WEIGHTS);
    for (x, wq) in (0..n / 4).map(|g| 4 * g).zip(&mut quads) {
        quad(wq, x);
    }
    if n % 4 != 0 {
        quad(quads.next().expect("the last group's weights"), n - 4);
    }
}
