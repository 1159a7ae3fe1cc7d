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

/// `z[i] = back·z32[i]` (widened to `f64`) over the first `4⌊len/4⌋` elements, and four
/// running sums of `r[i]·z[i]` as [`dot_lanes`] sums: the conversion and the dot
/// product that reads it in one pass, the same bits with AVX2 as without.
///
/// # Panics
/// If the slices differ in length.
#[inline(always)]
pub(crate) fn widen_and_dot_lanes(back: f64, z32: &[f32], r: &[f64], z: &mut [f64]) -> [f64; 4] {
    assert!(
        z32.len() == r.len() && r.len() == z.len(),
        "slices of different lengths"
    );
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") && !portable_only() {
        // SAFETY: the processor supports AVX2, checked just above.
        return unsafe { widen_and_dot_lanes_avx2(back, z32, r, z) };
    }
    let mut lanes = [0.0; 4];
    let chunks = z.chunks_exact_mut(4).zip(z32.chunks_exact(4));
    for ((zs, ws), rs) in chunks.zip(r.chunks_exact(4)) {
        for k in 0..4 {
            zs[k] = back * f64::from(ws[k]);
            lanes[k] += rs[k] * zs[k];
        }
    }
    lanes
}

/// [`widen_and_dot_lanes`] in AVX2 registers.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn widen_and_dot_lanes_avx2(back: f64, z32: &[f32], r: &[f64], z: &mut [f64]) -> [f64; 4] {
    use std::arch::x86_64::{
        _mm_loadu_ps, _mm256_add_pd, _mm256_cvtps_pd, _mm256_loadu_pd, _mm256_mul_pd,
        _mm256_set1_pd, _mm256_setzero_pd, _mm256_storeu_pd,
    };
    let (back, mut sum) = (_mm256_set1_pd(back), _mm256_setzero_pd());
    let chunks = z.chunks_exact_mut(4).zip(z32.chunks_exact(4));
    for ((zs, ws), rs) in chunks.zip(r.chunks_exact(4)) {
        // SAFETY: each chunk holds four numbers, the unaligned loads' and store's width.
        unsafe {
            let zi = _mm256_mul_pd(back, _mm256_cvtps_pd(_mm_loadu_ps(ws.as_ptr())));
            _mm256_storeu_pd(zs.as_mut_ptr(), zi);
            sum = _mm256_add_pd(sum, _mm256_mul_pd(_mm256_loadu_pd(rs.as_ptr()), zi));
        }
    }
    let mut lanes = [0.0; 4];
    // SAFETY: `lanes` holds four `f64`s, the unaligned store's width.
    unsafe { _mm256_storeu_pd(lanes.as_mut_ptr(), sum) };
    lanes
}
