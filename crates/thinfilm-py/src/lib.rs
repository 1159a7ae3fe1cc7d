//! The native half of the `thinfilm` Python package: flat, equally long f64 arrays in,
//! arrays out. Broadcasting and shapes are done in `python/thinfilm/__init__.py`.
//!
//! Every call copies its inputs, releases the GIL and computes in parallel (rayon), so
//! other Python threads run meanwhile; every bad value raises `ValueError` naming it. The
//! film grid's large outputs are written into buffers kept between calls (`pool.rs`).

mod inverse;
mod outer;
mod pool;

use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use rayon::prelude::*;
use thinfilm::airy::ThinFilm;
use thinfilm::colorspace::{SRGB_FROM_XYZ, apply, srgb_encode};
use thinfilm::dispersion::RefractiveIndex;
use thinfilm::grid::{FilmGrid, Polarisation as GridPol};
use thinfilm::{Complex64, Incidence, Layer, Observer, OpticsError, SpectralIntegrator, Stack};

/// Points per rayon task: small enough to balance, large enough to amortise.
const CHUNK: usize = 1024;

type Pair<'py> = (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>);
type Triple<'py> = (
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
);

pub(crate) fn value_error(err: OpticsError) -> PyErr {
    PyValueError::new_err(err.to_string())
}

fn copy(array: &PyReadonlyArray1<'_, f64>) -> Vec<f64> {
    array.as_array().iter().copied().collect()
}

#[derive(Clone, Copy)]
enum Pol {
    S,
    P,
    Mean,
}

pub(crate) fn pol_from(name: &str) -> PyResult<Pol> {
    match name {
        "s" => Ok(Pol::S),
        "p" => Ok(Pol::P),
        "u" => Ok(Pol::Mean),
        other => Err(PyValueError::new_err(format!(
            "pol = '{other}' is not one of 's', 'p', 'u'"
        ))),
    }
}

pub(crate) fn grid_pol(pol: Pol) -> GridPol {
    match pol {
        Pol::S => GridPol::S,
        Pol::P => GridPol::P,
        Pol::Mean => GridPol::Unpolarised,
    }
}

fn pick(pol: Pol, resp: thinfilm::fresnel::Response) -> (f64, f64) {
    match pol {
        Pol::S => (resp.r_s, resp.t_s),
        Pol::P => (resp.r_p, resp.t_p),
        Pol::Mean => (resp.r(), resp.t()),
    }
}

/// `(R, T)` of each point by `f`, in parallel, or the first point's error.
fn par_rt(
    len: usize,
    f: impl Fn(usize) -> Result<(f64, f64), OpticsError> + Sync,
) -> Result<(Vec<f64>, Vec<f64>), OpticsError> {
    let pairs: Vec<(f64, f64)> = (0..len)
        .into_par_iter()
        .with_min_len(CHUNK)
        .map(&f)
        .collect::<Result<_, _>>()?;
    Ok(pairs.into_iter().unzip())
}

/// `(R, T)` of a stack (`n` from the incidence medium to the substrate, `d_nm` the inner
/// layers, `coherent` one flag per inner layer: `false` adds its intensities) at each
/// `(wavelength_nm[i], angle_deg[i])`.
#[pyfunction]
#[pyo3(signature = (n, d_nm, wavelength_nm, angle_deg, pol, coherent))]
fn rt<'py>(
    py: Python<'py>,
    n: Vec<Complex64>,
    d_nm: Vec<f64>,
    wavelength_nm: PyReadonlyArray1<'py, f64>,
    angle_deg: PyReadonlyArray1<'py, f64>,
    pol: &str,
    coherent: Vec<bool>,
) -> PyResult<Pair<'py>> {
    let pol = pol_from(pol)?;
    let stack = stack_from(n, d_nm, coherent)?;
    let (wl, angle) = (copy(&wavelength_nm), copy(&angle_deg));
    let (r, t) = py
        .allow_threads(|| {
            par_rt(wl.len(), |i| {
                let incidence = Incidence::try_from_angle_deg(angle[i])?;
                Ok(pick(pol, stack.try_response_at(wl[i], incidence)?))
            })
        })
        .map_err(value_error)?;
    Ok((r.into_pyarray(py), t.into_pyarray(py)))
}

/// The stack of `rt`'s arguments, with errors naming the bad argument.
pub(crate) fn stack_from(
    n: Vec<Complex64>,
    d_nm: Vec<f64>,
    coherent: Vec<bool>,
) -> PyResult<Stack> {
    if n.len() != d_nm.len() + 2 {
        return Err(PyValueError::new_err(format!(
            "n has {} media and d_nm {} thicknesses: n needs len(d_nm) + 2 (both semi-infinite ends)",
            n.len(),
            d_nm.len()
        )));
    }
    let n0 = n[0];
    if n0.im != 0.0 {
        return Err(PyValueError::new_err(format!(
            "n[0] = {n0} must be real: the incidence medium cannot absorb"
        )));
    }
    if coherent.len() != d_nm.len() {
        return Err(PyValueError::new_err(format!(
            "coherent has {} flags and d_nm {} thicknesses: one flag per inner layer",
            coherent.len(),
            d_nm.len()
        )));
    }
    let layers = n[1..n.len() - 1]
        .iter()
        .zip(&d_nm)
        .zip(&coherent)
        .map(|((&index, &d), &coherent)| Layer {
            coherent,
            ..Layer::new(index, d)
        })
        .collect();
    Stack::new(n0.re, layers, n[n.len() - 1]).map_err(value_error)
}

/// The film's index (checked with the outside medium) and copies of the three arrays.
fn film_inputs(
    thickness_nm: &PyReadonlyArray1<'_, f64>,
    angle_deg: &PyReadonlyArray1<'_, f64>,
    wavelength_nm: &PyReadonlyArray1<'_, f64>,
    n_film: f64,
    n_outside: f64,
) -> PyResult<(RefractiveIndex, Vec<f64>, Vec<f64>, Vec<f64>)> {
    let film_index = RefractiveIndex::constant(n_film).map_err(value_error)?;
    ThinFilm::new(n_outside, film_index, n_outside.into(), 0.0).map_err(value_error)?;
    Ok((
        film_index,
        copy(thickness_nm),
        copy(angle_deg),
        copy(wavelength_nm),
    ))
}

/// `(R, T)` of symmetric films `n_outside | n_film | n_outside`, all arrays equally long.
#[pyfunction]
fn film_rt<'py>(
    py: Python<'py>,
    thickness_nm: PyReadonlyArray1<'py, f64>,
    angle_deg: PyReadonlyArray1<'py, f64>,
    wavelength_nm: PyReadonlyArray1<'py, f64>,
    n_film: f64,
    n_outside: f64,
) -> PyResult<Pair<'py>> {
    let (film_index, d, angle, wl) =
        film_inputs(&thickness_nm, &angle_deg, &wavelength_nm, n_film, n_outside)?;
    let (r, t) = py
        .allow_threads(|| {
            par_rt(d.len(), |i| {
                let film = ThinFilm::symmetric(n_outside, film_index, d[i]);
                let incidence = Incidence::try_from_angle_deg(angle[i])?;
                Ok(pick(Pol::Mean, film.try_response_at(wl[i], incidence)?))
            })
        })
        .map_err(value_error)?;
    Ok((r.into_pyarray(py), t.into_pyarray(py)))
}

/// [`film_rt`] on thinfilm's f32 batch kernel (within 2e-7 of the exact sum): each chunk's
/// valid points go through the kernel; a point the kernel cannot take (a value f32 cannot
/// hold, or any bad value) takes the exact path, which computes it or names what is wrong.
#[pyfunction]
fn film_rt_fast<'py>(
    py: Python<'py>,
    thickness_nm: PyReadonlyArray1<'py, f64>,
    angle_deg: PyReadonlyArray1<'py, f64>,
    wavelength_nm: PyReadonlyArray1<'py, f64>,
    n_film: f64,
    n_outside: f64,
) -> PyResult<Pair<'py>> {
    let (film_index, d, angle, wl) =
        film_inputs(&thickness_nm, &angle_deg, &wavelength_nm, n_film, n_outside)?;
    let film = FastFilm {
        n_outside,
        film_index,
        n_film_f32: n_film as f32,
    };
    let (r, t) = py
        .allow_threads(|| {
            let chunks = (0..d.len())
                .step_by(CHUNK)
                .collect::<Vec<_>>()
                .into_par_iter()
                .map(|start| {
                    let end = (start + CHUNK).min(d.len());
                    film.chunk(&d[start..end], &angle[start..end], &wl[start..end])
                })
                .collect::<Result<Vec<_>, _>>()?;
            Ok::<_, OpticsError>(chunks.into_iter().flatten().unzip())
        })
        .map_err(value_error)?;
    Ok((
        Vec::<f64>::into_pyarray(r, py),
        Vec::<f64>::into_pyarray(t, py),
    ))
}

/// A symmetric film's constants for [`film_rt_fast`].
#[derive(Clone, Copy)]
struct FastFilm {
    n_outside: f64,
    film_index: RefractiveIndex,
    n_film_f32: f32,
}

impl FastFilm {
    /// `(R, T)` of one chunk of points.
    fn chunk(&self, d: &[f64], angle: &[f64], wl: &[f64]) -> Result<Vec<(f64, f64)>, OpticsError> {
        let mut out = vec![(0.0, 0.0); d.len()];
        let (mut idx, mut d32, mut cos32, mut wl32) = (vec![], vec![], vec![], vec![]);
        for i in 0..d.len() {
            match self.kernel_input(d[i], angle[i], wl[i]) {
                Some((dd, c, w)) => {
                    idx.push(i);
                    d32.push(dd);
                    cos32.push(c);
                    wl32.push(w);
                }
                None => out[i] = self.exact(d[i], angle[i], wl[i])?,
            }
        }
        let (mut r, mut t) = (vec![0.0f32; idx.len()], vec![0.0f32; idx.len()]);
        let n_out = self.n_outside as f32;
        thinfilm::batch::try_reflectance_transmittance(
            n_out,
            self.n_film_f32,
            &d32,
            &cos32,
            &wl32,
            &mut r,
            &mut t,
        )?;
        for (k, &i) in idx.iter().enumerate() {
            out[i] = (f64::from(r[k]), f64::from(t[k]));
        }
        Ok(out)
    }

    /// The point as the kernel's f32 inputs, or `None` when it is invalid or f32 cannot
    /// hold it (the exact path then decides).
    fn kernel_input(&self, d: f64, angle: f64, wl: f64) -> Option<(f32, f32, f32)> {
        let cos = Incidence::try_from_angle_deg(angle).ok()?.cos();
        self.film_index.try_n_at(wl).ok()?;
        let (d32, wl32) = (d as f32, wl as f32);
        let fits = |v: f32| v.is_finite() && (v == 0.0 || v.is_normal());
        (d >= 0.0 && fits(d32) && fits(wl32) && wl32 > 0.0).then_some((d32, cos as f32, wl32))
    }

    fn exact(&self, d: f64, angle: f64, wl: f64) -> Result<(f64, f64), OpticsError> {
        let film = ThinFilm::new(self.n_outside, self.film_index, self.n_outside.into(), d)?;
        let incidence = Incidence::try_from_angle_deg(angle)?;
        Ok(pick(Pol::Mean, film.try_response_at(wl, incidence)?))
    }
}

/// `(R, T)` of the symmetric film on the outer product `thickness_nm × angle_deg ×
/// wavelength_nm`, flattened thickness-major (or angle-major, `(angle, thickness,
/// wavelength)`, with `angle_major`): [`thinfilm::grid::FilmGrid`] computes the Fresnel
/// terms once per (angle, wavelength), then the rows in parallel, exact or (`fast`) on its
/// f32 kernel.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn film_rt_grid<'py>(
    py: Python<'py>,
    thickness_nm: PyReadonlyArray1<'py, f64>,
    angle_deg: PyReadonlyArray1<'py, f64>,
    wavelength_nm: PyReadonlyArray1<'py, f64>,
    n_film: f64,
    n_outside: f64,
    pol: &str,
    angle_major: bool,
    fast: bool,
) -> PyResult<Pair<'py>> {
    let pol = grid_pol(pol_from(pol)?);
    let (d, angle, wl) = (copy(&thickness_nm), copy(&angle_deg), copy(&wavelength_nm));
    let (r, t) = py
        .allow_threads(|| {
            let grid = FilmGrid::try_new(n_outside, n_film, &angle, &wl)?;
            let len = d.len() * grid.len();
            let (mut r, mut t) = (pool::take(len), pool::take(len));
            let order = if angle_major {
                RunOrder::AngleMajor
            } else {
                RunOrder::ThicknessMajor
            };
            let out = (&mut r[..len], &mut t[..len]);
            fill_film_grid(&grid, &d, wl.len(), order, pol, fast, out)?;
            Ok::<_, OpticsError>(((r, len), (t, len)))
        })
        .map_err(value_error)?;
    Ok((
        pool::into_array(py, r.0, r.1)?,
        pool::into_array(py, t.0, t.1)?,
    ))
}

/// How a film grid's output is laid out: `(angle, thickness, wavelength)` or
/// `(thickness, angle, wavelength)`, wavelength fastest either way.
#[derive(Clone, Copy)]
enum RunOrder {
    AngleMajor,
    ThicknessMajor,
}

/// The fewest points a task of a film grid takes.
const MIN_TASK_POINTS: usize = 8192;

/// Fills `r` and `t` (the whole grid in `order`) run by run, a run being one thickness at
/// one angle over every wavelength, exact or (`fast`) on the f32 kernel; runs are grouped
/// into about sixteen tasks a thread, so that a busy core delays the call by a small task,
/// not by a share of the grid.
fn fill_film_grid(
    grid: &FilmGrid,
    d: &[f64],
    width: usize,
    order: RunOrder,
    pol: GridPol,
    fast: bool,
    (r, t): (&mut [f64], &mut [f64]),
) -> Result<(), OpticsError> {
    if r.is_empty() {
        return Ok(());
    }
    let angles = grid.len() / width;
    let runs = r.len() / width;
    let tasks = 16 * rayon::current_num_threads();
    let per_task = runs
        .div_ceil(tasks)
        .max(MIN_TASK_POINTS.div_ceil(width))
        .min(runs);
    r.par_chunks_mut(per_task * width)
        .zip(t.par_chunks_mut(per_task * width))
        .enumerate()
        .try_for_each(|(task, (r, t))| {
            let runs_r = r.chunks_mut(width).zip(t.chunks_mut(width));
            for (k, (r, t)) in (task * per_task..).zip(runs_r) {
                let (a, thickness) = match order {
                    RunOrder::AngleMajor => (k / d.len(), d[k % d.len()]),
                    RunOrder::ThicknessMajor => (k % angles, d[k / angles]),
                };
                if fast {
                    grid.try_fill_cells_fast(thickness, a * width, pol, r, t)?;
                } else {
                    grid.try_fill_cells(thickness, a * width, pol, r, t)?;
                }
            }
            Ok(())
        })
}

/// Checks the stack of a fit: `n` one longer than `d_nm` at both ends, `layer` an inner
/// layer, a real incidence medium.
fn check_fit_stack(n: &[Complex64], d_nm: &[f64], layer: usize) -> PyResult<()> {
    if n.len() != d_nm.len() + 2 {
        return Err(PyValueError::new_err(format!(
            "n has {} media and d_nm {} thicknesses: n needs len(d_nm) + 2",
            n.len(),
            d_nm.len()
        )));
    }
    if layer >= d_nm.len() {
        return Err(PyValueError::new_err(format!(
            "layer = {layer} names no inner layer: d_nm has {} (0-based)",
            d_nm.len()
        )));
    }
    if n[0].im != 0.0 {
        return Err(PyValueError::new_err(format!(
            "n[0] = {} must be real: the incidence medium cannot absorb",
            n[0]
        )));
    }
    Ok(())
}

/// The stack `n`, `d_nm` with inner layer `layer` of thickness `d` and index `index`.
fn stack_with_layer(
    n: &[Complex64],
    d_nm: &[f64],
    layer: usize,
    d: f64,
    index: thinfilm::IndexModel,
) -> Result<Stack, OpticsError> {
    let layers = (n[1..n.len() - 1].iter().zip(d_nm).enumerate())
        .map(|(k, (&own, &thickness))| {
            if k == layer {
                Layer::new(index.clone(), d)
            } else {
                Layer::new(own, thickness)
            }
        })
        .collect();
    Stack::new(n[0].re, layers, n[n.len() - 1])
}

/// The thickness and Cauchy index `a + b/λ²` of inner layer `layer` fitted together (see
/// `thinfilm::fit::cauchy`): for the thickness, `a` and `b` in turn `(value, low, high,
/// sigma, systematic)`, then the offset and the rms residual.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn fit_thickness_cauchy<'py>(
    py: Python<'py>,
    wavelength_nm: PyReadonlyArray1<'py, f64>,
    reflectance: PyReadonlyArray1<'py, f64>,
    n: Vec<Complex64>,
    d_nm: Vec<f64>,
    layer: usize,
    angle_deg: f64,
    thickness_range_nm: (f64, f64),
    a_range: (f64, f64),
    b_range_nm2: (f64, f64),
    wavelength_uncertainty_nm: f64,
) -> PyResult<[f64; 17]> {
    check_fit_stack(&n, &d_nm, layer)?;
    let incidence = Incidence::try_from_angle_deg(angle_deg).map_err(value_error)?;
    let (wl, r) = (copy(&wavelength_nm), copy(&reflectance));
    let model =
        |d: f64, index: RefractiveIndex| stack_with_layer(&n, &d_nm, layer, d, index.into());
    let fit = py
        .allow_threads(|| {
            thinfilm::fit::fit_thickness_and_index(
                model,
                &thinfilm::fit::Measurement {
                    wavelength_nm: &wl,
                    reflectance: &r,
                    incidence,
                    wavelength_uncertainty_nm,
                },
                thickness_range_nm.0,
                thickness_range_nm.1,
                thinfilm::fit::CauchyRange {
                    a: [a_range.0, a_range.1],
                    b_nm2: [b_range_nm2.0, b_range_nm2.1],
                },
            )
        })
        .map_err(value_error)?;
    Ok(fit.values())
}

/// The thickness of inner layer `layer` of the stack `n`, `d_nm` fitted to a measured
/// spectrum (see `thinfilm::fit`): `(thickness, low, high, sigma, systematic, offset,
/// rms residual, runner-up thickness, runner-up rms)`.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn fit_thickness<'py>(
    py: Python<'py>,
    wavelength_nm: PyReadonlyArray1<'py, f64>,
    reflectance: PyReadonlyArray1<'py, f64>,
    n: Vec<Complex64>,
    d_nm: Vec<f64>,
    layer: usize,
    angle_deg: f64,
    min_nm: f64,
    max_nm: f64,
    wavelength_uncertainty_nm: f64,
) -> PyResult<[f64; 9]> {
    check_fit_stack(&n, &d_nm, layer)?;
    let incidence = Incidence::try_from_angle_deg(angle_deg).map_err(value_error)?;
    let (wl, r) = (copy(&wavelength_nm), copy(&reflectance));
    let own = thinfilm::IndexModel::from(n[layer + 1]);
    let model = |d: f64| stack_with_layer(&n, &d_nm, layer, d, own.clone());
    let fit = py
        .allow_threads(|| {
            thinfilm::fit::fit_thickness(
                model,
                &thinfilm::fit::Measurement {
                    wavelength_nm: &wl,
                    reflectance: &r,
                    incidence,
                    wavelength_uncertainty_nm,
                },
                thinfilm::fit::Search {
                    min_nm,
                    max_nm,
                    n_max: n[layer + 1].re,
                },
            )
        })
        .map_err(value_error)?;
    Ok(fit.values())
}

/// `(R, T, error bound)` of the stack `n`, `d_nm` whose inner layer `layer` is graded:
/// `kind` "linear" or "exponential" from `front` to `back` over `d_nm[layer]`, or "table"
/// with `table` rows `(z_nm, n, k)` (its last z is the thickness); each point sliced until
/// the Richardson error estimate is within `tolerance` (see `thinfilm::graded`).
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn graded_rt<'py>(
    py: Python<'py>,
    n: Vec<Complex64>,
    d_nm: Vec<f64>,
    layer: usize,
    kind: &str,
    front: Complex64,
    back: Complex64,
    table: Vec<(f64, f64, f64)>,
    wavelength_nm: PyReadonlyArray1<'py, f64>,
    angle_deg: PyReadonlyArray1<'py, f64>,
    pol: &str,
    tolerance: f64,
) -> PyResult<Triple<'py>> {
    use thinfilm::graded::{GradedLayer, Profile};
    let pol = pol_from(pol)?;
    if n.len() != d_nm.len() + 2 || layer >= d_nm.len() {
        return Err(PyValueError::new_err(format!(
            "n has {} media, d_nm {} thicknesses and layer = {layer}: n needs len(d_nm) + 2 \
             and layer an index into d_nm",
            n.len(),
            d_nm.len()
        )));
    }
    if n[0].im != 0.0 {
        return Err(PyValueError::new_err(format!(
            "n[0] = {} must be real: the incidence medium cannot absorb",
            n[0]
        )));
    }
    let (profile, thickness) = match kind {
        "linear" => (Profile::Linear { front, back }, d_nm[layer]),
        "exponential" => {
            if front.im != 0.0 || back.im != 0.0 {
                return Err(PyValueError::new_err(format!(
                    "an exponential profile is real: front = {front}, back = {back}"
                )));
            }
            (
                Profile::Exponential {
                    front: front.re,
                    back: back.re,
                },
                d_nm[layer],
            )
        }
        "table" => {
            let text: String = std::iter::once("z_nm,n,k".to_string())
                .chain(table.iter().map(|(z, n, k)| format!("{z:?},{n:?},{k:?}")))
                .collect::<Vec<_>>()
                .join("\n");
            Profile::from_csv(&text).map_err(value_error)?
        }
        other => {
            return Err(PyValueError::new_err(format!(
                "profile kind = '{other}' is not 'linear', 'exponential' or 'table'"
            )));
        }
    };
    let graded = GradedLayer::try_new(profile, thickness).map_err(value_error)?;
    let stack_with = |slices: Vec<Layer>| {
        let mut layers = Vec::new();
        for (k, (&index, &d)) in n[1..n.len() - 1].iter().zip(&d_nm).enumerate() {
            if k == layer {
                layers.extend(slices.iter().cloned());
            } else {
                layers.push(Layer::new(index, d));
            }
        }
        Stack::new(n[0].re, layers, n[n.len() - 1])
    };
    let (wl, angle) = (copy(&wavelength_nm), copy(&angle_deg));
    let out: Vec<(f64, f64, f64)> = py
        .allow_threads(|| {
            (0..wl.len())
                .into_par_iter()
                .map(|i| {
                    let incidence = Incidence::try_from_angle_deg(angle[i])?;
                    let c = graded.converged_response(stack_with, wl[i], incidence, tolerance)?;
                    let (r, t) = pick(pol, c.response);
                    Ok((r, t, c.error_bound))
                })
                .collect::<Result<_, OpticsError>>()
        })
        .map_err(value_error)?;
    let (mut r, mut t, mut e) = (vec![], vec![], vec![]);
    for (a, b, c) in out {
        r.push(a);
        t.push(b);
        e.push(c);
    }
    Ok((r.into_pyarray(py), t.into_pyarray(py), e.into_pyarray(py)))
}

/// A zeroed output buffer; on Linux a large one asks for transparent huge pages before it
/// is first touched, so that filling it costs a few page faults rather than one per 4 KiB
/// (measured: touching 16 MB of fresh pages took longer than computing the 1 M-point grid).
pub(crate) fn zeroed(len: usize) -> Vec<f64> {
    let v = vec![0.0; len];
    #[cfg(target_os = "linux")]
    {
        const HUGE: usize = 2 << 20;
        let bytes = len * std::mem::size_of::<f64>();
        if bytes >= 2 * HUGE {
            let start = v.as_ptr() as usize;
            let aligned = start.next_multiple_of(HUGE);
            let end = (start + bytes) / HUGE * HUGE;
            if end > aligned {
                // SAFETY: the range lies inside `v`'s allocation, which outlives the call;
                // madvise only changes how the kernel backs the pages, never their contents
                // (fresh zero pages stay zero), and its failure is harmless.
                unsafe {
                    libc::madvise(
                        aligned as *mut libc::c_void,
                        end - aligned,
                        libc::MADV_HUGEPAGE,
                    );
                }
            }
        }
    }
    v
}

/// XYZ (perfect reflector at Y = 1) of soap films in air, flattened `[x0, y0, z0, x1, ...]`.
#[pyfunction]
fn film_xyz<'py>(
    py: Python<'py>,
    thickness_nm: PyReadonlyArray1<'py, f64>,
    angle_deg: PyReadonlyArray1<'py, f64>,
    n_film: f64,
    illuminant: &str,
    observer: &str,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let film_index = RefractiveIndex::constant(n_film).map_err(value_error)?;
    let observer = Observer::from_name(observer).ok_or_else(|| {
        PyValueError::new_err(format!("observer = {observer:?} is not '1931' or '1964'"))
    })?;
    let light = thinfilm::Illuminant::from_name(illuminant)
        .map_err(|e| PyValueError::new_err(format!("illuminant = {illuminant:?}: {e}")))?;
    // 2 nm as the CLI: within 1e-4 ΔE2000 of the 1 nm CIE sum for daylight.
    let integrator = SpectralIntegrator::new(observer, &light.spectrum(), 2.0)
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    let (d, angle) = (copy(&thickness_nm), copy(&angle_deg));
    let xyz: Vec<[f64; 3]> = py
        .allow_threads(|| {
            (0..d.len())
                .into_par_iter()
                .with_min_len(64)
                .map(|i| {
                    let film = ThinFilm::symmetric(1.0, film_index, d[i]);
                    let incidence = Incidence::try_from_angle_deg(angle[i])?;
                    // Checked here so that `film_xyz` (cell means near grazing, where the
                    // film's spectral lines are too narrow to sample) cannot panic.
                    film.try_response_at(550.0, incidence)?;
                    Ok(integrator.film_xyz_at(&film, incidence))
                })
                .collect::<Result<_, OpticsError>>()
        })
        .map_err(value_error)?;
    Ok(xyz
        .into_iter()
        .flatten()
        .collect::<Vec<f64>>()
        .into_pyarray(py))
}

/// sRGB-encoded colours in [0, 1] (clamped) of flattened XYZ triples (D65 white at Y = 1).
#[pyfunction]
fn xyz_to_srgb<'py>(
    py: Python<'py>,
    xyz: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let flat = copy(&xyz);
    if let Some(bad) = flat.iter().find(|v| !v.is_finite()) {
        return Err(PyValueError::new_err(format!(
            "xyz holds {bad}, not a finite number"
        )));
    }
    let out: Vec<f64> = flat
        .chunks_exact(3)
        .flat_map(|c| {
            apply(&SRGB_FROM_XYZ, [c[0], c[1], c[2]]).map(|v| srgb_encode(v.clamp(0.0, 1.0)))
        })
        .collect();
    Ok(out.into_pyarray(py))
}

/// `(buffers, bytes)` the output pool holds between calls (see `pool.rs`), for the tests.
#[pyfunction]
fn pool_held() -> (usize, usize) {
    pool::held()
}

/// The native module `thinfilm._native`.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(rt, m)?)?;
    m.add_function(wrap_pyfunction!(outer::rt_outer, m)?)?;
    m.add_function(wrap_pyfunction!(film_rt, m)?)?;
    m.add_function(wrap_pyfunction!(film_rt_fast, m)?)?;
    m.add_function(wrap_pyfunction!(film_rt_grid, m)?)?;
    m.add_function(wrap_pyfunction!(fit_thickness, m)?)?;
    m.add_function(wrap_pyfunction!(fit_thickness_cauchy, m)?)?;
    m.add_function(wrap_pyfunction!(graded_rt, m)?)?;
    m.add_function(wrap_pyfunction!(film_xyz, m)?)?;
    m.add_function(wrap_pyfunction!(xyz_to_srgb, m)?)?;
    m.add_function(wrap_pyfunction!(inverse::thickness_from_rgb, m)?)?;
    m.add_function(wrap_pyfunction!(pool_held, m)?)?;
    Ok(())
}
