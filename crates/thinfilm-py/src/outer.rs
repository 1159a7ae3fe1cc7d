//! `rt` on wavelength and angle arrays that form an outer product, decided and shaped here
//! so that the Python side adds no broadcasting work: [`thinfilm::stack_grid::StackGrid`]
//! fills the angle × wavelength grid, rows split in spans across threads.

use numpy::{IntoPyArray, PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use rayon::prelude::*;
use thinfilm::grid::Polarisation as GridPol;
use thinfilm::stack_grid::StackGrid;
use thinfilm::{Complex64, OpticsError, Stack};

use crate::{grid_pol, pol_from, stack_from, value_error, zeroed};

/// The fewest wavelengths a task of a row takes (each folds its own span).
const SPAN: usize = 64;
/// Grids with fewer layer-points than this (about 0.3 ms of work on one core) run on the
/// calling thread: waking the pool's sleeping threads costs about as much as they save.
/// Measured on the 5-layer bench grid (26 k layer-points, docs/performance.md): called
/// right after other work, 0.20 ms on the calling thread against 0.30–0.37 ms through the
/// pool; called back to back, 0.109 against 0.087–0.104 ms.
const SEQUENTIAL_LAYER_POINTS: usize = 100_000;

type DynPair<'py> = (Bound<'py, PyArrayDyn<f64>>, Bound<'py, PyArrayDyn<f64>>);

/// How two arrays broadcast when they form an outer product.
#[derive(Debug, PartialEq)]
struct Outer {
    /// The broadcast shape.
    shape: Vec<usize>,
    /// Whether the wavelength's long axis comes before the angle's.
    wavelength_first: bool,
}

impl Outer {
    /// `Some` when each shape has at most one axis longer than 1, not the same one once
    /// right-aligned, and no axis of length 0.
    fn of(wavelength: &[usize], angle: &[usize]) -> Option<Outer> {
        let ndim = wavelength.len().max(angle.len());
        let aligned = |s: &[usize], k: usize| (k + s.len()).checked_sub(ndim).map_or(1, |i| s[i]);
        let long = |s: &[usize]| -> Option<Option<usize>> {
            let axes: Vec<usize> = (0..ndim).filter(|&k| aligned(s, k) > 1).collect();
            (axes.len() <= 1).then(|| axes.first().copied())
        };
        if wavelength.contains(&0) || angle.contains(&0) {
            return None;
        }
        let (w, a) = (long(wavelength)?, long(angle)?);
        if w.is_some() && w == a {
            return None;
        }
        let shape = (0..ndim)
            .map(|k| aligned(wavelength, k).max(aligned(angle, k)))
            .collect();
        Some(Outer {
            shape,
            wavelength_first: matches!((w, a), (Some(w), Some(a)) if w < a),
        })
    }
}

/// `(R, T)` of a stack (as `rt`) when `wavelength_nm` and `angle_deg` form an outer product,
/// shaped as they broadcast; `None` otherwise (the point-by-point path then runs).
#[pyfunction]
#[pyo3(signature = (n, d_nm, wavelength_nm, angle_deg, pol, coherent))]
pub(crate) fn rt_outer<'py>(
    py: Python<'py>,
    n: Vec<Complex64>,
    d_nm: Vec<f64>,
    wavelength_nm: PyReadonlyArrayDyn<'py, f64>,
    angle_deg: PyReadonlyArrayDyn<'py, f64>,
    pol: &str,
    coherent: Vec<bool>,
) -> PyResult<Option<DynPair<'py>>> {
    let Some(outer) = Outer::of(wavelength_nm.shape(), angle_deg.shape()) else {
        return Ok(None);
    };
    let pol = grid_pol(pol_from(pol)?);
    let stack = stack_from(n, d_nm, coherent)?;
    let wl: Vec<f64> = wavelength_nm.as_array().iter().copied().collect();
    let angle: Vec<f64> = angle_deg.as_array().iter().copied().collect();
    let (r, t) = py
        .allow_threads(|| {
            let (r, t) = fill(&stack, &angle, &wl, pol)?;
            Ok::<_, OpticsError>(if outer.wavelength_first {
                (transpose(&r, wl.len()), transpose(&t, wl.len()))
            } else {
                (r, t)
            })
        })
        .map_err(value_error)?;
    let shaped = |v: Vec<f64>| v.into_pyarray(py).reshape(outer.shape.clone());
    Ok(Some((shaped(r)?, shaped(t)?)))
}

/// `R` and `T` over `angle × wavelength`, angle-major.
fn fill(
    stack: &Stack,
    angle: &[f64],
    wl: &[f64],
    pol: GridPol,
) -> Result<(Vec<f64>, Vec<f64>), OpticsError> {
    let grid = StackGrid::try_new(stack, angle, wl)?;
    let (mut r, mut t) = (zeroed(grid.len()), zeroed(grid.len()));
    if grid.is_empty() {
        return Ok((r, t));
    }
    // Spans of a row, so that a grid of one or a few angles still fills the threads
    // (about four tasks each); whole rows where there are enough.
    let width = grid.wavelengths();
    if grid.len() * (stack.layers.len() + 1) < SEQUENTIAL_LAYER_POINTS {
        let rows = r.chunks_mut(width).zip(t.chunks_mut(width));
        for (a, (r, t)) in rows.enumerate() {
            grid.try_fill_span(a, 0, pol, r, t)?;
        }
        return Ok((r, t));
    }
    let tasks = 4 * rayon::current_num_threads();
    let span = (grid.len() / tasks).clamp(SPAN, width.max(SPAN));
    r.par_chunks_mut(width)
        .zip(t.par_chunks_mut(width))
        .enumerate()
        .try_for_each(|(a, (r, t))| {
            r.par_chunks_mut(span)
                .zip(t.par_chunks_mut(span))
                .enumerate()
                .try_for_each(|(k, (r, t))| grid.try_fill_span(a, k * span, pol, r, t))
        })?;
    Ok((r, t))
}

/// An angle-major `rows × width` grid as width-major.
fn transpose(values: &[f64], width: usize) -> Vec<f64> {
    let rows = values.len() / width;
    (0..width)
        .flat_map(|w| (0..rows).map(move |a| values[a * width + w]))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outer_products_are_recognised_with_their_shape_and_order() {
        let of = |w: &[usize], a: &[usize]| Outer::of(w, a);
        let outer = |shape: &[usize], wavelength_first| {
            Some(Outer {
                shape: shape.to_vec(),
                wavelength_first,
            })
        };
        assert_eq!(of(&[1, 471], &[11, 1]), outer(&[11, 471], false));
        assert_eq!(of(&[471, 1], &[11]), outer(&[471, 11], true));
        assert_eq!(of(&[471], &[]), outer(&[471], false));
        assert_eq!(of(&[], &[]), outer(&[], false));
        assert_eq!(of(&[5, 1, 1], &[3, 1]), outer(&[5, 3, 1], true));
        assert_eq!(of(&[471], &[471]), None, "same axis: points, not a grid");
        assert_eq!(of(&[3, 4], &[]), None, "two long axes");
        assert_eq!(of(&[0], &[3, 1]), None, "empty");
    }
}
