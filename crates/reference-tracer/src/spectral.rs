//! The wavelength grid the reference carries, the film description ([`FilmSpec`]) and
//! the conversions from spectra to the CPU backend's linear RGB.

use thinfilm::colorspace::{SRGB_FROM_XYZ, XYZ_FROM_SRGB, apply};
use thinfilm::{Observer, RefractiveIndex, SpectralIntegrator, Spectrum};

use render_scene::RenderError;

/// Most wavelengths a path carries (a 5 nm grid over 360–830 nm plus a few lines).
pub const MAX_WAVELENGTHS: usize = 112;

/// What the reference needs to know about the film and the light that the RGB scene
/// does not say: indices, the illuminant RGB white stands for, the observer and the
/// lights' own spectra.
#[derive(Debug, Clone, PartialEq)]
pub struct FilmSpec {
    /// Real index of the medium around the bubbles (air: 1).
    pub n_outside: f64,
    /// Index of the film, possibly dispersive.
    pub n_film: RefractiveIndex,
    /// Colour-matching functions.
    pub observer: Observer,
    /// The illuminant that RGB (1, 1, 1) stands for (the LUT's reference light).
    pub reference: Spectrum,
    /// Per [`render_scene::Light`] of the scene, by index: its emission spectrum (any scale: the
    /// light's luminance comes from its RGB radiance), or `None` to upsample its RGB.
    pub light_spectra: Vec<Option<Spectrum>>,
}

/// The wavelengths a path carries and what a unit spectral factor at each adds to the
/// CPU backend's linear RGB.
#[derive(Debug, Clone)]
pub(crate) struct Grid {
    pub wavelength_nm: Vec<f64>,
    /// Linear RGB of a unit factor times the reference illuminant, divided channel by
    /// channel by the reference white (as the LUT's reflectivity pass does), so that a
    /// flat factor of 1 is exactly (1, 1, 1).
    pub reference_rgb: Vec<[f64; 3]>,
}

impl Grid {
    /// The reference illuminant's quadrature at `step_nm` (`thinfilm`'s cubic rule).
    pub fn try_new(
        observer: Observer,
        reference: &Spectrum,
        step_nm: f64,
    ) -> Result<Grid, RenderError> {
        let integrator = SpectralIntegrator::new(observer, reference, step_nm)
            .map_err(|e| RenderError::scene("reference illuminant", e.to_string()))?;
        if integrator.wavelengths_nm().len() > MAX_WAVELENGTHS {
            return Err(RenderError::setting(
                "step_nm",
                step_nm,
                "a step giving at most 112 wavelengths (>= 5 nm)",
            ));
        }
        let white = apply(&SRGB_FROM_XYZ, integrator.white_xyz());
        let reference_rgb = integrator
            .weights()
            .iter()
            .map(|w| {
                let rgb = apply(&SRGB_FROM_XYZ, *w);
                [0, 1, 2].map(|c| rgb[c] / white[c])
            })
            .collect();
        Ok(Grid {
            wavelength_nm: integrator.wavelengths_nm().to_vec(),
            reference_rgb,
        })
    }

    /// Number of wavelengths.
    pub fn len(&self) -> usize {
        self.wavelength_nm.len()
    }

    /// Per grid wavelength, the linear RGB a unit factor of `spectrum`'s emission adds,
    /// scaled so that the light itself has luminance `luminance`. Lines and samples off
    /// the grid are shared between the two nearest grid wavelengths (linear interpolation
    /// of the path's factor).
    pub fn emitter_rgb(
        &self,
        observer: Observer,
        spectrum: &Spectrum,
        step_nm: f64,
        luminance: f64,
    ) -> Result<Vec<[f64; 3]>, RenderError> {
        let integrator = SpectralIntegrator::new(observer, spectrum, step_nm)
            .map_err(|e| RenderError::scene("light spectrum", e.to_string()))?;
        let mut out = vec![[0.0; 3]; self.len()];
        for (&w, xyz) in integrator.wavelengths_nm().iter().zip(integrator.weights()) {
            let rgb = apply(&SRGB_FROM_XYZ, *xyz).map(|c| c * luminance);
            for (k, share) in self.neighbours(w) {
                for c in 0..3 {
                    out[k][c] += share * rgb[c];
                }
            }
        }
        Ok(out)
    }

    /// The grid wavelengths around `w` and their linear-interpolation weights.
    fn neighbours(&self, w: f64) -> [(usize, f64); 2] {
        let g = &self.wavelength_nm;
        let i = g.partition_point(|&x| x <= w);
        if i == 0 {
            return [(0, 1.0), (0, 0.0)];
        }
        if i == g.len() {
            return [(i - 1, 1.0), (i - 1, 0.0)];
        }
        let t = (w - g[i - 1]) / (g[i] - g[i - 1]);
        [(i - 1, 1.0 - t), (i, t)]
    }
}

/// Luminance Y of a linear sRGB colour.
pub(crate) fn luminance(rgb: [f32; 3]) -> f64 {
    apply(&XYZ_FROM_SRGB, rgb.map(f64::from))[1]
}

#[cfg(test)]
mod tests {
    use super::*;
    use thinfilm::Illuminant;

    #[test]
    fn flat_factor_is_white_and_an_emitter_has_its_luminance() {
        let d65 = Illuminant::D65.spectrum();
        let grid = Grid::try_new(Observer::Cie1931, &d65, 10.0).unwrap();
        let white = grid
            .reference_rgb
            .iter()
            .fold([0.0; 3], |a, w| [a[0] + w[0], a[1] + w[1], a[2] + w[2]]);
        for c in white {
            assert!((c - 1.0).abs() < 1e-12, "white channel off by {}", c - 1.0);
        }
        let sodium = Illuminant::from_name("sodium").unwrap().spectrum();
        let rgb = grid
            .emitter_rgb(Observer::Cie1931, &sodium, 10.0, 3.0)
            .unwrap();
        let sum = rgb
            .iter()
            .fold([0.0; 3], |a, w| [a[0] + w[0], a[1] + w[1], a[2] + w[2]]);
        let y = apply(&XYZ_FROM_SRGB, sum)[1];
        assert!((y - 3.0).abs() < 1e-9, "luminance {y}");
        assert!(sum[0] > sum[2], "sodium is orange: {sum:?}");
    }
}
