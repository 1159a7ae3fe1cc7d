//! Output buffers that outlive their arrays: a large grid's `R` and `T` are written into
//! buffers kept from earlier calls, so a repeated call touches memory already mapped.
//!
//! Measured (docs/performance.md): a fresh 8 MB output costs the kernel's zeroing of each
//! new page on first touch, and glibc hands a large block back to the system on `free`
//! (then `calloc` zeroes it again), together about as much as computing the 1 M-point grid.
//! A buffer lent to a numpy array returns here when the array is garbage; the pool keeps
//! at most [`MAX_BUFFERS`] buffers and [`MAX_POOLED_BYTES`] in all, each of at least
//! [`MIN_POOLED_BYTES`], and drops the rest. Every element of a lent buffer is written by
//! its call before the array is returned, so what an earlier call left there never shows.

use std::sync::Mutex;

use numpy::ndarray::ArrayViewMut1;
use numpy::{IntoPyArray, PyArray1};
use pyo3::prelude::*;

/// Buffers smaller than this are allocated and freed as usual (cheap at that size).
pub(crate) const MIN_POOLED_BYTES: usize = 1 << 20;
/// The most bytes the pool keeps between calls.
pub(crate) const MAX_POOLED_BYTES: usize = 64 << 20;
/// The most buffers the pool keeps between calls (a call's `R` and `T`, and its previous
/// call's, still alive while the next one runs).
pub(crate) const MAX_BUFFERS: usize = 4;

/// Idle buffers, each fully initialised over its length.
static POOL: Mutex<Vec<Vec<f64>>> = Mutex::new(Vec::new());

/// A buffer of at least `len` initialised f64s (contents unspecified: the caller overwrites
/// all of its first `len`): one from the pool when one fits (no larger than twice `len`),
/// else a fresh zeroed one.
pub(crate) fn take(len: usize) -> Vec<f64> {
    let bytes = len * std::mem::size_of::<f64>();
    if bytes >= MIN_POOLED_BYTES {
        let mut pool = POOL.lock().unwrap_or_else(|e| e.into_inner());
        let fit = (0..pool.len())
            .filter(|&k| pool[k].len() >= len && pool[k].len() <= 2 * len)
            .min_by_key(|&k| pool[k].len());
        if let Some(k) = fit {
            return pool.swap_remove(k);
        }
    }
    crate::zeroed(len)
}

/// Keeps `buffer` for a later [`take`] if it is large enough and the pool has room.
fn give_back(buffer: Vec<f64>) {
    let bytes = |v: &Vec<f64>| v.len() * std::mem::size_of::<f64>();
    if bytes(&buffer) < MIN_POOLED_BYTES {
        return;
    }
    let mut pool = POOL.lock().unwrap_or_else(|e| e.into_inner());
    let held: usize = pool.iter().map(bytes).sum();
    if pool.len() < MAX_BUFFERS && held + bytes(&buffer) <= MAX_POOLED_BYTES {
        pool.push(buffer);
    }
}

/// The number of buffers and bytes the pool holds now.
pub(crate) fn held() -> (usize, usize) {
    let pool = POOL.lock().unwrap_or_else(|e| e.into_inner());
    let bytes = pool
        .iter()
        .map(|v| v.len() * std::mem::size_of::<f64>())
        .sum();
    (pool.len(), bytes)
}

/// The owner of a pooled buffer while a numpy array reads it; returns it to the pool when
/// Python drops the array.
#[pyclass(module = "thinfilm._native")]
struct Lent {
    buffer: Vec<f64>,
}

impl Drop for Lent {
    fn drop(&mut self) {
        give_back(std::mem::take(&mut self.buffer));
    }
}

/// The first `len` values of `buffer` as a writable 1-d numpy array that owns the buffer
/// (pooled again when the array goes), or an ordinary owned array for a small buffer.
pub(crate) fn into_array(
    py: Python<'_>,
    mut buffer: Vec<f64>,
    len: usize,
) -> PyResult<Bound<'_, PyArray1<f64>>> {
    assert!(len <= buffer.len(), "a lent buffer holds its array");
    if buffer.len() * std::mem::size_of::<f64>() < MIN_POOLED_BYTES {
        buffer.truncate(len);
        return Ok(buffer.into_pyarray(py));
    }
    // SAFETY: the pointer covers `len` initialised f64s of `buffer`'s heap block, which
    // moves with the `Vec` into `Lent` without being reallocated, and `Lent` (the array's
    // base object) keeps it alive until numpy drops the array.
    let view = unsafe { ArrayViewMut1::from_shape_ptr(len, buffer.as_mut_ptr()) };
    let owner = Bound::new(py, Lent { buffer })?;
    // SAFETY: as above; nothing else reaches the buffer while `Lent` owns it.
    Ok(unsafe { PyArray1::borrow_from_array(&view, owner.into_any()) })
}
