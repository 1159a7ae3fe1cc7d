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
