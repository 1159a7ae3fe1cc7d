//! Hot loops compiled for AVX2 where the processor has it: [`with_avx2`] runs a closure
//! inside a function built with the feature, so what the closure inlines is built so too
//! (the film's solve). The triangle pass keeps a named `#[target_feature]` function
//! (`FaceForces::accumulate_avx2`): run through a closure here its block loops compiled to
//! 1.7× the instructions.
//!
//! The loops it runs are IEEE additions and multiplications in a fixed order: no fused
//! multiply-add is enabled and the compiler reorders no floating-point sum, so AVX2 and
//! the portable build (SSE2) give the same bits; AVX2 has four `f64` lanes an instruction
//! where SSE2 has two. Tests switch AVX2 off on their thread (`set_portable_only`, a
//! test-only function) and compare the two.
//!
//! The explicit SIMD of the crate lives here: the dot products' and Coriolis rows' lanes
//! below, and [`advect_face`], an advection stage's face in AVX2 registers.

#[cfg(target_arch = "x86_64")]
pub(crate) mod advect_face;

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

/// Whether the processor has AVX2 and [`with_avx2`] would use it: for kernels that
/// take their own AVX2 path inside it.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(crate) fn has_avx2() -> bool {
    std::arch::is_x86_feature_detected!("avx2") && !portable_only()
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

/// The pairs `[i, o]` of a cell's four sides (`i < o`), in the order of their weights in
/// [`coriolis_row`]: the term of side `o` in side `i`'s rate and that of side `i` in side
/// `o`'s are one weight of opposite signs.
pub(crate) const PAIRS: [[usize; 2]; 6] = [[0, 1], [0, 2], [0, 3], [1, 2], [1, 3], [2, 3]];

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
    let done = whole_chunks(PAIRS_CHUNK, values.len(), [even.len(), odd.len()]);
    let (values, even, odd) = (&values[..done], &mut even[..done / 2], &mut odd[..done / 2]);
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") && !portable_only() {
        // SAFETY: the processor supports AVX2, checked just above.
        unsafe { deinterleave_f64_avx2(values, even, odd) };
        return done;
    }
    deinterleave_portable(PAIRS_CHUNK, values, even, odd);
    done
}

/// How many leading values fill whole chunks of `chunk` in a run of `len` and, at half
/// a chunk each, in both halves `halves` long: what the (de)interleaves take.
#[inline(always)]
fn whole_chunks(chunk: usize, len: usize, halves: [usize; 2]) -> usize {
    let half = chunk / 2;
    let chunks = (len / chunk).min(halves[0] / half).min(halves[1] / half);
    chunks * chunk
}

/// The deinterleaves' portable loop over `values` cut to whole chunks of `chunk`:
/// `even[k] = values[2k]`, `odd[k] = values[2k + 1]`.
#[inline(always)]
fn deinterleave_portable<T: Copy>(chunk: usize, values: &[T], even: &mut [T], odd: &mut [T]) {
    let half = chunk / 2;
    let halves = even.chunks_exact_mut(half).zip(odd.chunks_exact_mut(half));
    for (v, (e, o)) in values.chunks_exact(chunk).zip(halves) {
        for k in 0..half {
            (e[k], o[k]) = (v[2 * k], v[2 * k + 1]);
        }
    }
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

/// Values [`deinterleave_f32`] takes a chunk: two AVX2 vectors of `f32`.
const PAIRS_CHUNK_F32: usize = 16;

/// [`deinterleave_f64`] for `f32` values, in chunks of [`PAIRS_CHUNK_F32`]: with AVX2
/// two loads, two shuffles, two lane permutes and two stores a chunk (the compiler's
/// copies of the `f32` weights the Marangoni step gives the solve took 1.7 instructions
/// a value); copies, so the same bits either way.
#[inline(always)]
pub(crate) fn deinterleave_f32(values: &[f32], even: &mut [f32], odd: &mut [f32]) -> usize {
    let done = whole_chunks(PAIRS_CHUNK_F32, values.len(), [even.len(), odd.len()]);
    let (values, even, odd) = (&values[..done], &mut even[..done / 2], &mut odd[..done / 2]);
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") && !portable_only() {
        // SAFETY: the processor supports AVX2, checked just above.
        unsafe { deinterleave_f32_avx2(values, even, odd) };
        return done;
    }
    deinterleave_portable(PAIRS_CHUNK_F32, values, even, odd);
    done
}

/// [`deinterleave_f32`]'s chunks in AVX2 registers (the slices cut to whole chunks).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn deinterleave_f32_avx2(values: &[f32], even: &mut [f32], odd: &mut [f32]) {
    use std::arch::x86_64::{
        _mm256_castpd_ps, _mm256_castps_pd, _mm256_loadu_ps, _mm256_permute4x64_pd,
        _mm256_shuffle_ps, _mm256_storeu_ps,
    };
    let half = PAIRS_CHUNK_F32 / 2;
    let halves = even.chunks_exact_mut(half).zip(odd.chunks_exact_mut(half));
    for (v, (e, o)) in values.chunks_exact(PAIRS_CHUNK_F32).zip(halves) {
        // SAFETY: each chunk holds sixteen values and each half eight, the loads' and
        // stores' widths.
        unsafe {
            let a = _mm256_loadu_ps(v.as_ptr());
            let b = _mm256_loadu_ps(v.as_ptr().add(half));
            // Per 128-bit lane [a0 a2 b0 b2 | a4 a6 b4 b6] and [a1 a3 b1 b3 | a5 a7 b5 b7]:
            // their middle 64-bit pairs swapped.
            let lo = _mm256_castps_pd(_mm256_shuffle_ps(a, b, 0b10_00_10_00));
            let hi = _mm256_castps_pd(_mm256_shuffle_ps(a, b, 0b11_01_11_01));
            let lo = _mm256_castpd_ps(_mm256_permute4x64_pd(lo, 0b11_01_10_00));
            let hi = _mm256_castpd_ps(_mm256_permute4x64_pd(hi, 0b11_01_10_00));
            _mm256_storeu_ps(e.as_mut_ptr(), lo);
            _mm256_storeu_ps(o.as_mut_ptr(), hi);
        }
    }
}

/// `out[2k] = even[k]` and `out[2k + 1] = odd[k]` over the first chunks of
/// [`PAIRS_CHUNK`] values that all three slices hold; returns how many values that was:
/// [`deinterleave_f64`]'s inverse (the split layout's gathers).
#[inline(always)]
pub(crate) fn interleave_f64(even: &[f64], odd: &[f64], out: &mut [f64]) -> usize {
    let half = PAIRS_CHUNK / 2;
    let done = whole_chunks(PAIRS_CHUNK, out.len(), [even.len(), odd.len()]);
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

/// The weights of a group of four cells in [`coriolis_row`]: per pair of sides `p`
/// ([`PAIRS`]), per cell (index `4p + cell`), so that a group's six weight vectors are
/// read from one base.
pub(crate) const QUAD_WEIGHTS: usize = 24;

/// The first cells of a row of `n` cells' groups of four in [`coriolis_row`]: every
/// fourth, then the last four again where `n` is not a multiple of four (the cells taken
/// twice get the same terms twice), or one group of all `n` where `n < 4`.
pub(crate) fn quad_starts(n: usize) -> impl Iterator<Item = usize> {
    (0..n / 4)
        .map(|g| 4 * g)
        .chain((n % 4 != 0).then(|| n.saturating_sub(4)))
}

/// A row of `n` cells' terms of their sides' rates into `out` (per side: bottom, left,
/// right, top), each times its side's weight in the energy norm: with `P_io = w_io (ζ_i +
/// ζ_o)` for each pair `[i, o]` of [`PAIRS`] (`w` its weight, each side's `ζ` the sum of
/// its two corners' from `z`, the row's bottom and top vertices, `n + 1` each) and `u_s`
/// side `s`'s velocity (`u`: the bottom sides', the left and right sides' (`n + 1`: cell
/// `x`'s left is `x`, its right `x + 1`) and the top sides'), the bottom's
/// `(P₀₁u₁ + P₀₂u₂) + P₀₃u₃`, the left's `(P₁₂u₂ − P₀₁u₀) + P₁₃u₃`, the right's
/// `(P₂₃u₃ − P₀₂u₀) − P₁₂u₁` and the top's `((0 − P₀₃u₀) − P₁₃u₁) − P₂₃u₂`: an
/// antisymmetric form, six weights where twelve were read. `w` holds the groups' weights
/// as [`QUAD_WEIGHTS`] lays them out. The same bits with AVX2 (explicit, from five input
/// bases: the compiler's loop over the weight arrays and eight shifted slices ran out of
/// registers) as without.
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
            let p: [f64; 6] = std::array::from_fn(|q| {
                let [i, o] = PAIRS[q];
                wq[4 * q + x - start] * (z[i] + z[o])
            });
            let t = |q: usize, side: usize| p[q] * v[side];
            ob[x] = (t(0, 1) + t(1, 2)) + t(2, 3);
            ol[x] = (t(3, 2) - t(0, 0)) + t(4, 3);
            or[x] = (t(5, 3) - t(1, 0)) - t(3, 1);
            ot[x] = ((0.0 - t(2, 0)) - t(4, 1)) - t(5, 2);
        }
    }
}

/// [`coriolis_row`] in AVX2 registers, four cells an instruction (`n ≥ 4`).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn coriolis_row_avx2(w: &[f64], z: [&[f64]; 2], u: [&[f64]; 3], out: [&mut [f64]; 4]) {
    let n = u[0].len();
    let (z, u) = (z.map(<[f64]>::as_ptr), u.map(<[f64]>::as_ptr));
    let out = out.map(<[f64]>::as_mut_ptr);
    // Each group's weights from the row's base: `w` holds `⌈n/4⌉` groups' (checked by
    // `coriolis_row`).
    let groups = n / 4;
    for g in 0..groups {
        // SAFETY: `4g + 4 ≤ n`, the slices are as long as `coriolis_row` checked and
        // group `g`'s weights are within `w`.
        unsafe { coriolis_quad(w.as_ptr().wrapping_add(g * QUAD_WEIGHTS), z, u, out, 4 * g) };
    }
    if n % 4 != 0 {
        // SAFETY: as above, for the last four cells (`n ≥ 4`) and the last group.
        let wq = w.as_ptr().wrapping_add(groups * QUAD_WEIGHTS);
        unsafe { coriolis_quad(wq, z, u, out, n - 4) };
    }
}

/// [`coriolis_row`]'s terms of cells `x..x + 4` in AVX2 registers ([`coriolis_terms`])
/// into `out` (bottom, left, right, top), as [`coriolis_row`] lays them out.
///
/// # Safety
/// As [`coriolis_terms`], and each of `out` holds `x + 4`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
pub(crate) unsafe fn coriolis_quad(
    wq: *const f64,
    z: [*const f64; 2],
    u: [*const f64; 3],
    out: [*mut f64; 4],
    x: usize,
) {
    // SAFETY: the caller's promise.
    unsafe {
        let (terms, _) = coriolis_terms(wq, z, u, x);
        for (o, t) in out.into_iter().zip(terms) {
            std::arch::x86_64::_mm256_storeu_pd(o.add(x), t);
        }
    }
}

/// [`coriolis_row`]'s terms of cells `x..x + 4` in AVX2 registers (bottom, left, right,
/// top), from a group's weights `wq` ([`QUAD_WEIGHTS`]), the row's vertices `z` (bottom,
/// top) and its velocities `u` (bottom, left and right, top); and the cells' velocities
/// it read (bottom, left, right, top), for a caller that moves those edges.
///
/// # Safety
/// The processor has AVX2; `wq` holds [`QUAD_WEIGHTS`] values, `z` and `u[1]` hold
/// `x + 5` and the others `x + 4`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
pub(crate) unsafe fn coriolis_terms(
    wq: *const f64,
    [zb, zt]: [*const f64; 2],
    [ub, ux, ut]: [*const f64; 3],
    x: usize,
) -> (
    [std::arch::x86_64::__m256d; 4],
    [std::arch::x86_64::__m256d; 4],
) {
    use std::arch::x86_64::{
        _mm256_add_pd, _mm256_loadu_pd, _mm256_mul_pd, _mm256_setzero_pd, _mm256_sub_pd,
    };
    // SAFETY: every load is in bounds (the caller's promise).
    unsafe {
        let ld = |p: *const f64, at: usize| _mm256_loadu_pd(p.add(at));
        let (c0, c1, c2, c3) = (ld(zb, x), ld(zb, x + 1), ld(zt, x), ld(zt, x + 1));
        let z = [
            _mm256_add_pd(c0, c1),
            _mm256_add_pd(c0, c2),
            _mm256_add_pd(c1, c3),
            _mm256_add_pd(c2, c3),
        ];
        let v = [ld(ub, x), ld(ux, x), ld(ux, x + 1), ld(ut, x)];
        let p: [_; 6] = std::array::from_fn(|q| {
            let [i, o] = PAIRS[q];
            _mm256_mul_pd(ld(wq, 4 * q), _mm256_add_pd(z[i], z[o]))
        });
        let t = |q: usize, side: usize| _mm256_mul_pd(p[q], v[side]);
        let (add, sub) = (_mm256_add_pd, _mm256_sub_pd);
        let terms = [
            add(add(t(0, 1), t(1, 2)), t(2, 3)),
            add(sub(t(3, 2), t(0, 0)), t(4, 3)),
            sub(sub(t(5, 3), t(1, 0)), t(3, 1)),
            sub(sub(sub(_mm256_setzero_pd(), t(2, 0)), t(4, 1)), t(5, 2)),
        ];
        (terms, v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bits::differing_bits;

    /// A repeatable number in `[-0.5, 0.5)` for `i`.
    fn rough(i: usize) -> f64 {
        ((i * 7919 + 13) % 1000) as f64 * 1e-3 - 0.5
    }

    /// A row of `n` cells' inputs to [`coriolis_row`] from `seed`: weights, vertices and
    /// velocities.
    fn row_inputs(n: usize, seed: usize) -> (Vec<f64>, [Vec<f64>; 2], [Vec<f64>; 3]) {
        let v = |len: usize, k: usize| (0..len).map(|i| rough(seed + 1000 * k + i)).collect();
        let w = v(n.div_ceil(4) * QUAD_WEIGHTS, 0);
        (
            w,
            [v(n + 1, 1), v(n + 1, 2)],
            [v(n, 3), v(n + 1, 4), v(n, 5)],
        )
    }

    /// [`coriolis_row`] of the inputs, portable or not.
    fn run_row(w: &[f64], z: &[Vec<f64>; 2], u: &[Vec<f64>; 3], portable: bool) -> Vec<f64> {
        let n = u[0].len();
        let mut out = vec![vec![0.0; n]; 4];
        let [ob, ol, or, ot] = &mut out[..] else {
            unreachable!()
        };
        set_portable_only(portable);
        coriolis_row(w, [&z[0], &z[1]], [&u[0], &u[1], &u[2]], [ob, ol, or, ot]);
        set_portable_only(false);
        out.concat()
    }

    /// The AVX2 row gives the portable row's bits: rows of 4 to 64 cells, whole groups of
    /// four and not.
    #[test]
    fn the_avx2_coriolis_row_gives_the_portable_bits() {
        for n in [4, 5, 7, 8, 13, 64] {
            let (w, z, u) = row_inputs(n, n);
            let (fast, plain) = (run_row(&w, &z, &u, false), run_row(&w, &z, &u, true));
            assert!(plain.iter().any(|&r| r != 0.0), "n {n}: no terms");
            let differ = differing_bits(&fast, &plain);
            assert_eq!(differ, 0, "n {n}: terms differ");
        }
    }

    /// The antisymmetric row is, to rounding, each side's sum over the other three of
    /// `w[i][o] (ζ_i + ζ_o) u_o` with twelve weights, `w[o][i]` minus `w[i][o]` for each
    /// pair (what the weights were before the energy norm's weights were taken out of
    /// them): rows of 1 to 13 cells.
    #[test]
    fn the_coriolis_row_is_the_twelve_weight_sum() {
        for n in [1, 3, 5, 13] {
            let (w, z, u) = row_inputs(n, 3 * n);
            let got = run_row(&w, &z, &u, false);
            let quads: Vec<usize> = quad_starts(n).collect();
            for x in 0..n {
                // The last group that holds cell `x`, as the row takes it.
                let g = quads.iter().rposition(|&s| s <= x).expect("a group");
                let lane = x - quads[g];
                let c = [z[0][x], z[0][x + 1], z[1][x], z[1][x + 1]];
                let zeta = [c[0] + c[1], c[0] + c[2], c[1] + c[3], c[2] + c[3]];
                let v = [u[0][x], u[1][x], u[1][x + 1], u[2][x]];
                let mut weight = [[0.0; 4]; 4];
                for (q, [i, o]) in PAIRS.into_iter().enumerate() {
                    weight[i][o] = w[g * QUAD_WEIGHTS + 4 * q + lane];
                    weight[o][i] = -weight[i][o];
                }
                for i in 0..4 {
                    let want: f64 = (0..4)
                        .filter(|&o| o != i)
                        .map(|o| weight[i][o] * (zeta[i] + zeta[o]) * v[o])
                        .sum();
                    let got = got[i * n + x];
                    assert!(
                        (got - want).abs() <= 1e-14,
                        "n {n}, cell {x}, side {i}: {got} against {want}"
                    );
                }
            }
        }
    }
}
