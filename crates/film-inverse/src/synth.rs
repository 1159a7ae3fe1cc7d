//! Synthetic photos of films of known thickness, for tests, benches and the docs: the
//! exact spectrum through a camera with exposure and white-balance errors, shot noise
//! and 8-bit quantisation. Everything is seeded, so a photo can be made again.

use crate::camera::Camera;
use crate::model::{ColourTable, FilmModel};
use crate::{Status, ThicknessMap};
use rayon::prelude::*;

/// SplitMix64: a small, well-mixed generator, seeded per pixel so that photos made in
/// parallel are the same at any thread count.
#[derive(Clone, Debug)]
pub struct Rng(u64);

impl Rng {
    /// A generator from `seed`.
    pub fn new(seed: u64) -> Rng {
        Rng(seed)
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in (0, 1].
    pub fn uniform(&mut self) -> f64 {
        ((self.next_u64() >> 11) + 1) as f64 / (1u64 << 53) as f64
    }

    /// Standard normal (Box–Muller).
    pub fn normal(&mut self) -> f64 {
        let (u, v) = (self.uniform(), self.uniform());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }
}

/// A vertical film draining under gravity, `width × height`: black film (12 nm) at the
/// top, thickening downwards to `max_nm` at the bottom (h ∝ depth^0.75, the shape of a
/// draining film's profile), its fringes waved sideways as convection bends them.
/// Continuous everywhere.
pub fn draining_film(width: u32, height: u32, max_nm: f64) -> Vec<f32> {
    const BLACK_NM: f64 = 12.0;
    let (w, h) = (f64::from(width), f64::from(height.max(2)));
    (0..height)
        .flat_map(|y| (0..width).map(move |x| (x, y)))
        .map(|(x, y)| {
            let (u, v) = (f64::from(x) / w, f64::from(y) / (h - 1.0));
            let depth = (v + 0.04 * (std::f64::consts::TAU * (2.0 * u + 1.5 * v)).sin() * v)
                .clamp(0.0, 1.0);
            (BLACK_NM + (max_nm - BLACK_NM) * depth.powf(0.75)) as f32
        })
        .collect()
}

/// How the synthetic camera errs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraModel {
    /// The camera's true response.
    pub camera: Camera,
    /// Shot noise: the standard deviation of a linear value `v` is `noise · √v`, so
    /// `noise` is the fraction of full scale at full scale.
    pub noise: f64,
    /// Seed of the noise.
    pub seed: u64,
}

/// The exposure that puts the brightest colour of films up to the model's thickness,
/// seen head-on, at 90 % of full scale.
pub fn nominal_exposure(model: &FilmModel) -> f64 {
    let table = ColourTable::build(model, 1.0, 1.0, 1);
    let brightest = table
        .values()
        .iter()
        .flat_map(|m| m.iter().copied())
        .fold(0.0f32, f32::max);
    0.9 / f64::from(brightest)
}

/// The film's white-balanced linear colours at each pixel: exact (Airy, f64) or from
/// the f32 colour table (bilinear, for large photos).
pub fn film_colours(
    model: &FilmModel,
    thickness_nm: &[f32],
    cos: &[f32],
    exact: bool,
) -> Vec<[f64; 3]> {
    assert_eq!(thickness_nm.len(), cos.len(), "one cos θ per pixel");
    if exact {
        return thickness_nm
            .par_iter()
            .zip(cos)
            .map(|(&h, &c)| model.rgb_exact(f64::from(h), f64::from(c)))
            .collect();
    }
    let lo = cos.iter().copied().fold(1.0f32, f32::min);
    let table = ColourTable::build(model, f64::from(lo), 1.0, 256);
    thickness_nm
        .par_iter()
        .zip(cos)
        .map(|(&h, &c)| table.sample(f64::from(h), table.row_of(f64::from(c))))
        .collect()
}

/// An 8-bit sRGB photo (interleaved RGB) of `colours` through `camera`.
pub fn photograph8(colours: &[[f64; 3]], camera: &CameraModel) -> Vec<u8> {
    colours
        .par_iter()
        .enumerate()
        .flat_map_iter(|(i, m)| {
            let mut rng = Rng::new(camera.seed ^ (i as u64).wrapping_mul(0xD1B5_4A32_D192_ED03));
            let linear = [0, 1, 2].map(|c| {
                let v = camera.camera.exposure * camera.camera.gains[c] * m[c];
                v + camera.noise * v.max(0.0).sqrt() * rng.normal()
            });
            linear.map(|v| {
                (thinfilm::colorspace::srgb_encode(v.clamp(0.0, 1.0)) * 255.0).round() as u8
            })
        })
        .collect()
}

/// A recovered map's errors against the thickness it was made from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MapErrors {
    /// RMS error (nm) over fitted pixels that are not order errors.
    pub rms_nm: f64,
    /// Fraction of fitted pixels more than 100 nm (half an order) off.
    pub order_errors: f64,
    /// Fraction of the pixels not excluded (saturated ones included) that were fitted.
    pub fitted: f64,
    /// Fraction of fitted pixels whose error is within 2 σ of their uncertainty.
    pub within_2_sigma: f64,
}

/// Compares `map` with the `truth` (nm per pixel) it was recovered from.
///
/// # Panics
/// If `truth` is not one value per pixel of the map.
pub fn errors(map: &ThicknessMap, truth: &[f32]) -> MapErrors {
    assert_eq!(
        truth.len(),
        map.status.len(),
        "one true thickness per pixel"
    );
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
    MapErrors {
        rms_nm: (sum2 / ok.max(1) as f64).sqrt(),
        order_errors: wrong as f64 / fitted.max(1) as f64,
        fitted: fitted as f64 / usable.max(1) as f64,
        within_2_sigma: covered as f64 / fitted.max(1) as f64,
    }
}
