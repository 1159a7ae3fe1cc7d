//! `thickness_from_rgb`: `film_inverse`'s thickness map of an RGB photo. Python checks the
//! shapes and dtypes and passes flat arrays; every setting is checked by `film_inverse`,
//! whose errors (each naming its value) become `ValueError`s.

use film_inverse::{
    Anchor, Calibration, Camera, FilmModel, InverseError, Photo, Rect, Settings, Status, Summary,
    ThicknessMap, Viewing,
};
use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use thinfilm::dispersion::RefractiveIndex;
use thinfilm::{Illuminant, Observer};

/// A photo's interleaved RGB values as numpy passed them (the dtype picks the format).
#[derive(FromPyObject)]
pub(crate) enum Pixels<'py> {
    /// 8-bit sRGB-encoded.
    Srgb8(PyReadonlyArray1<'py, u8>),
    /// 16-bit sRGB-encoded.
    Srgb16(PyReadonlyArray1<'py, u16>),
    /// Linear, as from an EXR.
    Linear(PyReadonlyArray1<'py, f32>),
}

/// [`Pixels`] copied out of Python, so that the photo is built without the GIL.
enum OwnedPixels {
    Srgb8(Vec<u8>),
    Srgb16(Vec<u16>),
    Linear(Vec<f32>),
}

impl Pixels<'_> {
    fn to_owned_pixels(&self) -> OwnedPixels {
        match self {
            Pixels::Srgb8(a) => OwnedPixels::Srgb8(a.as_array().iter().copied().collect()),
            Pixels::Srgb16(a) => OwnedPixels::Srgb16(a.as_array().iter().copied().collect()),
            Pixels::Linear(a) => OwnedPixels::Linear(a.as_array().iter().copied().collect()),
        }
    }
}

impl OwnedPixels {
    fn photo(&self, width: u32, height: u32) -> Result<Photo, InverseError> {
        match self {
            OwnedPixels::Srgb8(v) => Photo::try_from_srgb8(width, height, v),
            OwnedPixels::Srgb16(v) => Photo::try_from_srgb16(width, height, v),
            OwnedPixels::Linear(v) => Photo::try_from_linear(width, height, v),
        }
    }
}

/// The light: a built-in illuminant's name, or a sampled spectrum
/// `(wavelength_nm, value)`.
#[derive(FromPyObject)]
pub(crate) enum LightArg {
    /// d65, d50, a, e, f2, f11 or sodium.
    Name(String),
    /// Samples of a spectrum, wavelengths strictly increasing.
    Samples(Vec<f64>, Vec<f64>),
}

/// The film's index: a constant, or `"water"` (IAPWS dispersion).
#[derive(FromPyObject)]
pub(crate) enum IndexArg {
    /// A constant index.
    Constant(f64),
    /// A named dispersive model.
    Name(String),
}

/// The film and its light: light, film index, outside index, thickest film (nm), observer.
type FilmArgs = (LightArg, IndexArg, f64, f64, String);
/// A region `(x, y, w, h)` in pixels.
type RectArgs = (u32, u32, u32, u32);
/// The thickness map's arrays and the summary, as `thickness_from_rgb` returns them.
type MapOut<'py> = (
    Bound<'py, PyArray1<f32>>,
    Bound<'py, PyArray1<f32>>,
    Bound<'py, PyArray1<f32>>,
    Bound<'py, PyArray1<u8>>,
    Bound<'py, PyArray1<f32>>,
    Bound<'py, PyDict>,
);

fn value_error(err: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(err.to_string())
}

/// The film model from the light, index and observer arguments.
fn film_model(film: &FilmArgs) -> PyResult<FilmModel> {
    let (light, n_film, n_outside, thickness_max_nm, observer) = film;
    let spectrum = match light {
        LightArg::Name(name) => Illuminant::from_name(name)
            .map(Illuminant::spectrum)
            .map_err(|e| PyValueError::new_err(format!("illuminant = {name:?}: {e}")))?,
        LightArg::Samples(w, v) => thinfilm::Spectrum::try_from_samples(w.clone(), v.clone())
            .map_err(|e| PyValueError::new_err(format!("illuminant spectrum: {e}")))?,
    };
    let index = match n_film {
        IndexArg::Constant(n) => RefractiveIndex::constant(*n)
            .map_err(|e| PyValueError::new_err(format!("n_film = {n}: {e}")))?,
        IndexArg::Name(name) if name == "water" => RefractiveIndex::Water,
        IndexArg::Name(name) => {
            return Err(PyValueError::new_err(format!(
                "n_film = {name:?} is neither a number nor 'water'"
            )));
        }
    };
    let observer = Observer::from_name(observer).ok_or_else(|| {
        PyValueError::new_err(format!("observer = {observer:?} is not '1931' or '1964'"))
    })?;
    FilmModel::try_new(*n_outside, index, &spectrum, observer, *thickness_max_nm)
        .map_err(value_error)
}

/// The viewing geometry: a cos θ map, a sphere `(cx, cy, radius)`, or one angle.
fn viewing(
    angle_deg: f64,
    cos_map: Option<PyReadonlyArray1<'_, f32>>,
    sphere: Option<(f64, f64, f64)>,
) -> Viewing {
    match (cos_map, sphere) {
        (Some(m), _) => Viewing::CosMap(m.as_array().iter().copied().collect()),
        (None, Some((cx, cy, radius_px))) => Viewing::Sphere {
            centre_px: [cx, cy],
            radius_px,
        },
        (None, None) => Viewing::Angle(angle_deg),
    }
}

/// The calibration: a white region, a reference region of known thickness, a given
/// camera `(exposure, gains)`, or none (estimated). Python allows at most one.
fn calibration(
    white: Option<RectArgs>,
    reference: Option<(RectArgs, f64)>,
    camera: Option<(f64, [f64; 3])>,
) -> Calibration {
    let rect = |(x, y, w, h): RectArgs| Rect { x, y, w, h };
    match (white, reference, camera) {
        (Some(r), _, _) => Calibration::White(rect(r)),
        (None, Some((r, nm)), _) => Calibration::Known(rect(r), nm),
        (None, None, Some((exposure, gains))) => Calibration::Given(Camera { exposure, gains }),
        (None, None, None) => Calibration::Auto,
    }
}

/// Pixel status as a code: 0 fitted, 1 saturated, 2 excluded, 3 unexplained, 4 ambiguous.
fn status_code(s: Status) -> u8 {
    match s {
        Status::Fitted => 0,
        Status::Saturated => 1,
        Status::Excluded => 2,
        Status::Unexplained => 3,
        Status::Ambiguous => 4,
    }
}

/// Every field of the summary as a dict (the camera and region report flattened).
fn summary_dict<'py>(py: Python<'py>, s: &Summary) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("exposure", s.camera.exposure)?;
    d.set_item(
        "gains",
        (s.camera.gains[0], s.camera.gains[1], s.camera.gains[2]),
    )?;
    d.set_item("calibration", s.calibration)?;
    d.set_item("fitted", s.fitted)?;
    d.set_item("saturated", s.saturated)?;
    d.set_item("excluded", s.excluded)?;
    d.set_item("unexplained", s.unexplained)?;
    d.set_item("ambiguous", s.ambiguous)?;
    d.set_item("residual_mean_de", s.residual_mean_de)?;
    d.set_item("residual_p95_de", s.residual_p95_de)?;
    d.set_item("residual_max_de", s.residual_max_de)?;
    d.set_item("noise_encoded", s.noise_encoded)?;
    d.set_item("thickness_min_nm", s.thickness_min_nm)?;
    d.set_item("thickness_median_nm", s.thickness_median_nm)?;
    d.set_item("thickness_max_nm", s.thickness_max_nm)?;
    d.set_item("uncertainty_median_nm", s.uncertainty_median_nm)?;
    d.set_item("regions", s.regions.regions)?;
    d.set_item("regions_anchored", s.regions.anchored)?;
    d.set_item("regions_shifted", s.regions.shifted)?;
    d.set_item("regions_unplaced", s.regions.unplaced)?;
    d.set_item("regions_refolded", s.regions.refolded)?;
    d.set_item("regions_lost", s.regions.lost)?;
    Ok(d)
}

/// The map's arrays, flat (`rerender` interleaved RGB), and its summary.
fn map_out(py: Python<'_>, map: ThicknessMap) -> PyResult<MapOut<'_>> {
    let summary = summary_dict(py, &map.summary)?;
    let status: Vec<u8> = map.status.iter().map(|&s| status_code(s)).collect();
    let rerender: Vec<f32> = map.rerender.iter().flatten().copied().collect();
    Ok((
        map.thickness_nm.into_pyarray(py),
        map.uncertainty_nm.into_pyarray(py),
        map.residual_de.into_pyarray(py),
        status.into_pyarray(py),
        rerender.into_pyarray(py),
        summary,
    ))
}

/// The thickness map of a `width × height` photo (`pixels` interleaved RGB, row-major):
/// `(thickness_nm, uncertainty_nm, residual_de, status, rerender, summary)`, the arrays
/// flat and 0 where a pixel is not fitted. `camera` is `(exposure, gains)`; `cos_map` and
/// `mask` hold one value per pixel.
#[pyfunction]
#[pyo3(signature = (pixels, width, height, film, angle_deg, cos_map, sphere, white, reference,
                    camera, anchors, mask, max_residual_de, smoothness_nm))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn thickness_from_rgb<'py>(
    py: Python<'py>,
    pixels: Pixels<'py>,
    width: u32,
    height: u32,
    film: FilmArgs,
    angle_deg: f64,
    cos_map: Option<PyReadonlyArray1<'py, f32>>,
    sphere: Option<(f64, f64, f64)>,
    white: Option<RectArgs>,
    reference: Option<(RectArgs, f64)>,
    camera: Option<(f64, [f64; 3])>,
    anchors: Vec<(u32, u32, f64)>,
    mask: Option<PyReadonlyArray1<'py, bool>>,
    max_residual_de: f64,
    smoothness_nm: f64,
) -> PyResult<MapOut<'py>> {
    let settings = Settings {
        viewing: viewing(angle_deg, cos_map, sphere),
        calibration: calibration(white, reference, camera),
        anchors: anchors
            .into_iter()
            .map(|(x, y, thickness_nm)| Anchor { x, y, thickness_nm })
            .collect(),
        mask: mask.map(|m| m.as_array().iter().copied().collect()),
        max_residual_de,
        smoothness_nm,
    };
    let pixels = pixels.to_owned_pixels();
    let map = py.allow_threads(|| {
        let model = film_model(&film)?;
        let photo = pixels.photo(width, height).map_err(value_error)?;
        film_inverse::recover(&photo, &model, &settings).map_err(value_error)
    })?;
    map_out(py, map)
}
