//! Thickness maps from RGB photos of soap films: `thinfilm`'s exact forward model from
//! thickness to colour, turned around.
//!
//! A colour matches many thicknesses (one per interference order). The inverse resolves
//! that ambiguity with the physics of films rather than pixel by pixel:
//! - thickness varies continuously, so the map is grown over the pixel grid from its
//!   smoothest pixels outwards, each pixel taking the colour match nearest the thickness
//!   its labelled neighbours predict (quality-guided growth, as in phase unwrapping);
//! - each connected region's order as a whole is then chosen by the colour evidence of
//!   all its pixels: higher orders wash out towards white, and black film (below about
//!   30 nm) only matches order zero, so a wrong order costs colour error everywhere;
//! - the user's anchors (`x, y = nm`) fix the order of their region outright.
//!
//! Exposure and white balance come from a white region, a region of known thickness,
//! given values, or are estimated from the photo (the camera under which its colours lie
//! nearest the model's colour curve). See docs/inverse.md for the method and its limits.
//!
//! ```
//! use film_inverse::{Calibration, Camera, FilmModel, Photo, Settings, recover};
//! use thinfilm::Illuminant;
//! let model = FilmModel::soap(&Illuminant::D65.spectrum());
//! // A 64 × 1 photo of a film thickening from 100 to 415 nm, exposed at 5.
//! let camera = Camera::balanced(5.0);
//! let truth: Vec<f64> = (0..64).map(|x| 100.0 + 5.0 * x as f64).collect();
//! let px: Vec<u8> = truth
//!     .iter()
//!     .flat_map(|&h| camera.encode(model.rgb_exact(h, 1.0)).map(|v| (v * 255.0).round() as u8))
//!     .collect();
//! let photo = Photo::try_from_srgb8(64, 1, &px).unwrap();
//! let settings = Settings { calibration: Calibration::Given(camera), ..Settings::default() };
//! let map = recover(&photo, &model, &settings).unwrap();
//! assert_eq!(map.summary.fitted, 64);
//! assert!(map.thickness_nm.iter().zip(&truth).all(|(h, t)| (f64::from(*h) - t).abs() < 5.0));
//! ```

mod camera;
mod error;
mod finish;
mod fold;
mod model;
mod photo;
mod settings;
pub mod synth;
mod unwrap;

pub use camera::{Camera, EncodedTable};
pub use error::InverseError;
pub use model::{
    ColourTable, FilmModel, MAX_THICKNESS_NM, MIN_THICKNESS_NM, STEP_NM, TABLE_STEP_NM,
};
pub use photo::{MAX_PIXELS, Photo};
pub use settings::{ANGLE_ROWS, Anchor, Calibration, MIN_COS, Rect, Settings, Viewing};
pub use unwrap::RegionReport;

/// What became of a pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Status {
    /// A thickness was recovered.
    Fitted,
    /// A channel was at the format's maximum: the colour is unknown.
    Saturated,
    /// Left out by the mask or the geometry (outside the sphere, too grazing).
    Excluded,
    /// No film thickness explains the colour within the residual bound (background,
    /// glints, dirt): no thickness is given.
    Unexplained,
    /// Colours that film explains, in a patch (cut off by masked or unexplained pixels)
    /// too small, or too pale, for its fringe order to be known: no thickness.
    Ambiguous,
}

/// The recovered map and everything measured along the way.
#[derive(Clone, Debug)]
pub struct ThicknessMap {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Thickness (nm) per pixel, row-major; 0 where `status` is not [`Status::Fitted`].
    pub thickness_nm: Vec<f32>,
    /// One-sigma uncertainty (nm); 0 where not fitted.
    pub uncertainty_nm: Vec<f32>,
    /// ΔE2000 between the photo and the re-rendered colour; 0 where not fitted.
    pub residual_de: Vec<f32>,
    /// The colour the map predicts, sRGB-encoded in [0, 1]; the photo's own colour where
    /// not fitted.
    pub rerender: Vec<[f32; 3]>,
    /// What became of each pixel.
    pub status: Vec<Status>,
    /// Totals.
    pub summary: Summary,
}

/// Totals of a recovery.
#[derive(Clone, Debug, PartialEq)]
pub struct Summary {
    /// The camera used.
    pub camera: Camera,
    /// How it was found: `given`, `white region`, `reference region` or `estimated`.
    pub calibration: &'static str,
    /// Pixels given a thickness.
    pub fitted: usize,
    /// Pixels left out as saturated.
    pub saturated: usize,
    /// Pixels left out by the mask or the geometry.
    pub excluded: usize,
    /// Pixels whose colour no thickness explains.
    pub unexplained: usize,
    /// Pixels in patches too small or too pale to place.
    pub ambiguous: usize,
    /// Mean ΔE2000 residual over fitted pixels.
    pub residual_mean_de: f64,
    /// 95th-percentile ΔE2000 residual over fitted pixels.
    pub residual_p95_de: f64,
    /// Largest ΔE2000 residual over fitted pixels.
    pub residual_max_de: f64,
    /// Noise per encoded channel implied by the fits (RMS).
    pub noise_encoded: f64,
    /// Thinnest fitted pixel (nm).
    pub thickness_min_nm: f64,
    /// Median fitted thickness (nm).
    pub thickness_median_nm: f64,
    /// Thickest fitted pixel (nm).
    pub thickness_max_nm: f64,
    /// Median one-sigma uncertainty (nm).
    pub uncertainty_median_nm: f64,
    /// The regions grown and their order decisions.
    pub regions: RegionReport,
}

/// Recovers the thickness map of `photo`.
///
/// # Errors
/// A setting out of range or not matching the photo's size, a calibration region that is
/// saturated or too dark to calibrate, a photo whose usable pixels are mostly saturated,
/// or a photo with no usable pixel.
pub fn recover(
    photo: &Photo,
    model: &FilmModel,
    settings: &Settings,
) -> Result<ThicknessMap, InverseError> {
    let (width, height) = (photo.width(), photo.height());
    settings.check(width, height, model.thickness_max_nm())?;
    let cos = settings.cos_of(width, height);
    let state = initial_state(photo, settings, &cos)?;
    let table = colour_table(model, &cos, &state);
    let rows: Vec<u16> = cos
        .iter()
        .map(|c| c.map_or(0, |c| table.row_of(f64::from(c)).round() as u16))
        .collect();
    let (camera, calibration) = calibrate(photo, &table, &rows, &state, settings)?;
    let encoded = EncodedTable::new(&table, &camera);
    let step = settings.smoothness_nm / TABLE_STEP_NM;
    let prior = (0.02f32 * 0.02) / (step * step) as f32;
    let mut grower = unwrap::Grower::new(
        &encoded,
        photo.encoded(),
        &rows,
        width as usize,
        state,
        prior,
    );
    let anchors: Vec<(usize, f32)> = settings
        .anchors
        .iter()
        .map(|a| {
            (
                a.y as usize * width as usize + a.x as usize,
                (a.thickness_nm / TABLE_STEP_NM) as f32,
            )
        })
        .collect();
    let mut regions = grower.resolve(&anchors);
    let folds = grower.refold();
    (regions.refolded, regions.lost) = (folds.moved, folds.lost);
    let tables = finish::Tables {
        encoded: &encoded,
        linear: &table,
        camera,
        calibration,
    };
    Ok(finish::finish_map(
        photo, settings, &tables, &cos, &grower, regions,
    ))
}

/// Each pixel's starting state; refuses a photo with nothing to fit or mostly saturated.
fn initial_state(
    photo: &Photo,
    settings: &Settings,
    cos: &[Option<f32>],
) -> Result<Vec<u8>, InverseError> {
    let state: Vec<u8> = (0..photo.len())
        .map(|p| {
            let masked = settings.mask.as_ref().is_some_and(|m| !m[p]);
            if masked || cos[p].is_none() {
                unwrap::EXCLUDED
            } else if photo.saturated()[p] {
                unwrap::SATURATED
            } else {
                unwrap::FREE
            }
        })
        .collect();
    let saturated = state.iter().filter(|&&s| s == unwrap::SATURATED).count();
    let free = state.iter().filter(|&&s| s == unwrap::FREE).count();
    if free == 0 && saturated == 0 {
        return Err(InverseError::Photo(
            "no pixel is left to fit: the mask or the geometry excludes the whole photo".into(),
        ));
    }
    if saturated > free {
        return Err(InverseError::Photo(format!(
            "the photo is saturated: {saturated} of {} usable pixels have a channel at the format's maximum; take it with a shorter exposure",
            saturated + free
        )));
    }
    Ok(state)
}

/// The colour table over the range of cos θ the usable pixels need.
fn colour_table(model: &FilmModel, cos: &[Option<f32>], state: &[u8]) -> ColourTable {
    let (lo, hi) = cos
        .iter()
        .zip(state)
        .filter(|(_, s)| **s == unwrap::FREE)
        .filter_map(|(c, _)| *c)
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), c| {
            (lo.min(c), hi.max(c))
        });
    let (lo, hi) = if lo <= hi {
        (f64::from(lo), f64::from(hi))
    } else {
        (1.0, 1.0)
    };
    ColourTable::build(model, lo, hi, ANGLE_ROWS)
}

/// The camera, by the settings' method.
fn calibrate(
    photo: &Photo,
    table: &ColourTable,
    rows: &[u16],
    state: &[u8],
    settings: &Settings,
) -> Result<(Camera, &'static str), InverseError> {
    let width = photo.width();
    match &settings.calibration {
        Calibration::Given(c) => Ok((*c, "given")),
        Calibration::White(r) => {
            let mean = region_mean(photo, r, state, "white region")?;
            let camera = Camera {
                exposure: mean[1],
                gains: [mean[0] / mean[1], 1.0, mean[2] / mean[1]],
            };
            camera.check().map(|()| (camera, "white region"))
        }
        Calibration::Known(r, nm) => {
            let mean = region_mean(photo, r, state, "reference region")?;
            let row: f64 =
                r.pixels(width).map(|p| f64::from(rows[p])).sum::<f64>() / f64::from(r.w * r.h);
            let m = table.sample(*nm, row);
            if m.iter().any(|&v| v < 1e-3) || mean.iter().any(|&v| v < 1e-3) {
                return Err(InverseError::Photo(format!(
                    "the reference region at {nm} nm is too dark to calibrate with (model colour {:.4}, {:.4}, {:.4}; photo mean {:.4}, {:.4}, {:.4}, linear): black film fixes the order but not the exposure; use a thicker region, --white or a given exposure",
                    m[0], m[1], m[2], mean[0], mean[1], mean[2]
                )));
            }
            let k = [0, 1, 2].map(|c| mean[c] / m[c]);
            let camera = Camera {
                exposure: k[1],
                gains: [k[0] / k[1], 1.0, k[2] / k[1]],
            };
            camera.check().map(|()| (camera, "reference region"))
        }
        Calibration::Auto => Ok((auto_camera(photo, table, rows, state), "estimated")),
    }
}

/// Mean linear colour of a region, refusing one that is saturated or black.
fn region_mean(
    photo: &Photo,
    r: &Rect,
    state: &[u8],
    what: &str,
) -> Result<[f64; 3], InverseError> {
    let mut sum = [0.0; 3];
    for p in r.pixels(photo.width()) {
        if state[p] == unwrap::SATURATED {
            return Err(InverseError::Photo(format!(
                "the {what} has a saturated pixel at ({}, {}): its true colour is unknown",
                p % photo.width() as usize,
                p / photo.width() as usize
            )));
        }
        let v = photo.linear(p);
        (0..3).for_each(|c| sum[c] += v[c]);
    }
    let mean = sum.map(|s| s / f64::from(r.w * r.h));
    if mean.iter().any(|&v| v < 1e-4) {
        return Err(InverseError::Photo(format!(
            "the {what} is black in a channel (mean linear {:.2e}, {:.2e}, {:.2e}): it cannot fix the camera",
            mean[0], mean[1], mean[2]
        )));
    }
    Ok(mean)
}

/// Estimates the camera from up to 2048 usable pixels spread evenly over the photo.
fn auto_camera(photo: &Photo, table: &ColourTable, rows: &[u16], state: &[u8]) -> Camera {
    let usable: Vec<usize> = (0..photo.len())
        .filter(|&p| state[p] == unwrap::FREE)
        .collect();
    let stride = usable.len().div_ceil(2048).max(1);
    let samples: Vec<camera::Sample> = usable
        .iter()
        .step_by(stride)
        .map(|&p| camera::Sample {
            encoded: photo.encoded()[p],
            row: usize::from(rows[p]),
        })
        .collect();
    let mut brightness: Vec<f64> = samples
        .iter()
        .map(|s| {
            s.encoded
                .iter()
                .map(|&v| thinfilm::colorspace::srgb_decode(f64::from(v)))
                .fold(0.0, f64::max)
        })
        .collect();
    brightness.sort_by(f64::total_cmp);
    let p99 = brightness
        .get(brightness.len() * 99 / 100)
        .copied()
        .unwrap_or(1.0)
        .max(1e-4);
    camera::estimate(table, &samples, p99)
}
