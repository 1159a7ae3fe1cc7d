//! Synthetic-photo scenarios shared by the accuracy tests: a known thickness field is
//! photographed through the exact spectrum and a faulty camera, then recovered.

#![allow(dead_code)]

use film_inverse::synth::{self, CameraModel};
use film_inverse::{Calibration, Camera, FilmModel, Photo, Settings, ThicknessMap, recover};

pub use film_inverse::synth::{MapErrors as Errors, errors};

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
