//! Runs a closure on a pool of a chosen size (the thread-count determinism tests; apart from
//! `common`, which the integration tests share without depending on rayon).

/// Runs `f` on a pool of `threads` rayon threads.
pub fn on_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}
