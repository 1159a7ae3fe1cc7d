//! Synthetic-photo scenarios shared by the accuracy tests: a known thickness field is
//! photographed through the exact spectrum and a faulty camera, then recovered.

#![allow(dead_code)]

use film_inverse::synth::{self, CameraModel};
use film_inverse::{
    Calibration, Camera, FilmModel, Photo, Settings, Status, ThicknessMap, recover,
};

/// Errors of a recovery against the truth.
#[derive(Debug, Clone, Copy)]
pub struct Errors {
    /// RMS thickness error (nm) over fitted pixels that are not order errors.
    pub rms_nm: f64,
    /// Fraction of fitted pixels off by more than 100 nm (half an order).
    pub order_errors: f64,
    /// Fraction of usable pixels fitted.
    pub fitted: f64,
    /// Fraction of fitted pixels whose error is within 2 sigma of their uncertainty.
    pub within_2_sigma: f64,
}

/// Compares a map with the truth.
pub fn errors(map: &ThicknessMap, truth: &[f32]) -> Errors {
    let (mut sum2, mut ok, mut wrong, mut covered, mut fitted) =
        (0.0, 0usize, 0usize, 0usize, 0usize);
    for (p, t) in truth.iter().enumerate() {
        if map.status[p] != Status::Fitted {
            continue;
        }
        fitted += 1;
        let e = f64::from(map.thickness_nm[p] - t);
        if e.abs() > 100.0 {
            wrong += 1;
        } else {
            sum2 += e * e;
            ok += 1;
        }
        if e.abs() <= 2.0 * f64::from(map.uncertainty_nm[p]) {
            covered += 1;
        }
    }
    let usable = map
        .status
        .iter()
        .filter(|s| **s != Status::Excluded)
        .count();
    Errors {
        rms_nm: (sum2 / ok.max(1) as f64).sqrt(),
        order_errors: wrong as f64 / fitted.max(1) as f64,
        fitted: fitted as f64 / usable.max(1) as f64,
        within_2_sigma: covered as f64 / fitted.max(1) as f64,
    }
}

/// The generator's settings for one photo.
#[derive(Debug, Clone, Copy)]
pub struct Shot {
    /// Exposure error: the true exposure is the nominal one times `1 + exposure_error`.
    pub exposure_error: f64,
    /// White-balance error: red gain `1 + wb`, blue gain `1 − wb`.
    pub wb: f64,
    /// Shot noise at full scale.
    pub noise: f64,
    /// Noise seed.
    pub seed: u64,
}

/// The standard shot: +10 % exposure, ±5 % white balance, 2 % noise, 8 bits.
pub const STANDARD: Shot = Shot {
    exposure_error: 0.10,
    wb: 0.05,
    noise: 0.02,
    seed: 7,
};

/// Photographs `truth` (seen at `cos`) with `shot`: the true camera and the photo.
pub fn photograph(
    model: &FilmModel,
    truth: &[f32],
    cos: &[f32],
    width: u32,
    shot: Shot,
) -> (Camera, Photo) {
    let nominal = synth::nominal_exposure(model);
    let camera = Camera {
        exposure: nominal * (1.0 + shot.exposure_error),
        gains: [1.0 + shot.wb, 1.0, 1.0 - shot.wb],
    };
    let colours = synth::film_colours(model, truth, cos, true);
    let px = synth::photograph8(
        &colours,
        &CameraModel {
            camera,
            noise: shot.noise,
            seed: shot.seed,
        },
    );
    let height = (truth.len() / width as usize) as u32;
    (camera, Photo::try_from_srgb8(width, height, &px).unwrap())
}

/// Recovers a photo with automatic calibration, or with the nominal camera (which is off
/// by the shot's exposure and white-balance errors) when `given` is set.
pub fn recover_with(
    model: &FilmModel,
    photo: &Photo,
    settings: Settings,
    given: bool,
) -> ThicknessMap {
    let settings = if given {
        Settings {
            calibration: Calibration::Given(Camera::balanced(synth::nominal_exposure(model))),
            ..settings
        }
    } else {
        settings
    };
    recover(photo, model, &settings).unwrap()
}
