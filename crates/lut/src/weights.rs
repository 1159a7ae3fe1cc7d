//! Spectral weights for the fused bake kernel: one `(λ_k, n_film(λ_k), W_k)` list per
//! table, so that a texel is `Σ_k W_k · R(d, cos θ, λ_k)` in one pass.

use thinfilm::cells::CellWeights;
use thinfilm::colorspace::{SRGB_FROM_XYZ, apply};
use thinfilm::integrate::SpectralIntegrator;

use crate::BakeConfig;

/// The inputs of one table's kernel call, in f32 as the kernel takes them.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Pass {
    /// The integration wavelengths in full precision, for the record in `lut.json`.
    pub wavelength_nm_f64: Vec<f64>,
    pub wavelength_nm: Vec<f32>,
    pub n_film: Vec<f32>,
    pub weights: Vec<[f32; 3]>,
    /// The same weights over cells, for the texels whose spectral lines are too narrow to
    /// sample (`thinfilm::cells`); `None` without an even grid.
    pub cells: Option<CellPass>,
}

/// A pass in cell form: cell means plus the emission lines sampled at their wavelength.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct CellPass {
    /// The integrator's cells (for the thickness from which they are used).
    pub cells: CellWeights,
    pub n_film_edge: Vec<f64>,
    pub n_film_cell: Vec<f64>,
    pub weights: Vec<[f32; 3]>,
    /// The lines alone, as a point pass (empty for a continuous spectrum).
    pub lines: Box<Pass>,
}

/// The wavelengths at which `integrator` weighs anything (zero-weight samples, e.g. the
/// whole grid for a pure line spectrum, would only cost time).
pub(crate) fn sample_wavelengths(
    integrator: &SpectralIntegrator,
) -> impl Iterator<Item = f64> + '_ {
    integrator
        .wavelengths_nm()
        .iter()
        .zip(integrator.weights())
        .filter(|(_, w)| w.iter().any(|&c| c != 0.0))
        .map(|(&wavelength_nm, _)| wavelength_nm)
}

/// Linear-sRGB colour of a perfect reflector under the integrator's light (its Y is 1).
pub(crate) fn linear_srgb_white(integrator: &SpectralIntegrator) -> [f64; 3] {
    let xyz = integrator.weights().iter().fold([0.0; 3], |acc, w| {
        [acc[0] + w[0], acc[1] + w[1], acc[2] + w[2]]
    });
    apply(&SRGB_FROM_XYZ, xyz)
}

/// Builds a pass from per-sample linear-sRGB weights, dropping zero-weight samples.
fn pass(config: &BakeConfig, integrator: &SpectralIntegrator, scale: [f64; 3]) -> Pass {
    let samples = integrator.wavelengths_nm().iter().zip(integrator.weights());
    let mut out = point_pass(config, samples, scale);
    out.cells = integrator.cells().map(|cells| {
        let n_at = |w: &f64| config.film_index.n_at(*w);
        CellPass {
            cells: cells.clone(),
            n_film_edge: cells.edges_nm.iter().map(n_at).collect(),
            n_film_cell: cells.centres_nm.iter().map(n_at).collect(),
            weights: cells.weights.iter().map(|w| rgb_weight(w, scale)).collect(),
            lines: Box::new(point_pass(
                config,
                cells.line_nm.iter().zip(&cells.line_weights),
                scale,
            )),
        }
    });
    out
}

/// A point pass over `(wavelength, XYZ weight)` samples, without cells.
fn point_pass<'a>(
    config: &BakeConfig,
    samples: impl Iterator<Item = (&'a f64, &'a [f64; 3])>,
    scale: [f64; 3],
) -> Pass {
    let mut out = Pass {
        wavelength_nm_f64: Vec::new(),
        wavelength_nm: Vec::new(),
        n_film: Vec::new(),
        weights: Vec::new(),
        cells: None,
    };
    for (&wavelength_nm, w) in samples {
        if w.iter().all(|&c| c == 0.0) {
            continue;
        }
        out.wavelength_nm_f64.push(wavelength_nm);
        out.wavelength_nm.push(wavelength_nm as f32);
        out.n_film
            .push(config.film_index.n_at(wavelength_nm) as f32);
        out.weights.push(rgb_weight(w, scale));
    }
    out
}

/// Linear-sRGB weight of an XYZ weight, scaled channel by channel, in f32.
fn rgb_weight(xyz: &[f64; 3], scale: [f64; 3]) -> [f32; 3] {
    let rgb = apply(&SRGB_FROM_XYZ, *xyz);
    std::array::from_fn(|c| (rgb[c] * scale[c]) as f32)
}

/// The reflectivity pass: weights divided channel by channel by the reference white, so
/// that `R ≡ 1` gives exactly (1, 1, 1) in exact arithmetic.
pub(crate) fn reflectivity_pass(config: &BakeConfig) -> Pass {
    let integrator = config
        .integrator(&config.reference)
        .expect("BakeConfig guarantees the reference integrates");
    let white = linear_srgb_white(&integrator);
    pass(config, &integrator, white.map(|c| 1.0 / c))
}

/// The light-source pass of `config.lights[k]`: linear sRGB, the light itself at Y = 1.
pub(crate) fn light_pass(config: &BakeConfig, k: usize) -> Pass {
    let integrator = config
        .integrator(&config.lights[k])
        .expect("BakeConfig guarantees every light integrates");
    pass(config, &integrator, [1.0; 3])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Light;
    use thinfilm::colorspace::XYZ_FROM_SRGB;
    use thinfilm::illuminant::Illuminant;

    fn flat(pass: &Pass, reflectance: f32) -> [f32; 3] {
        pass.weights.iter().fold([0.0; 3], |acc, w| {
            std::array::from_fn(|c| acc[c] + w[c] * reflectance)
        })
    }

    #[test]
    fn flat_reflectors_map_to_grey_of_their_reflectance_under_any_reference() {
        for reference in [
            Illuminant::D65,
            Illuminant::A,
            Illuminant::F11,
            Illuminant::E,
        ] {
            let config = BakeConfig::builder()
                .reference(Light::illuminant(reference))
                .build()
                .unwrap();
            let pass = reflectivity_pass(&config);
            for reflectance in [1.0f32, 0.04] {
                let rgb = flat(&pass, reflectance);
                for c in rgb {
                    let diff = c - reflectance;
                    assert!(
                        diff.abs() < 2e-6 * 1f32.max(reflectance),
                        "{reference:?}: {c} vs {reflectance}, off by {diff:e}"
                    );
                }
            }
        }
    }

    #[test]
    fn a_perfect_mirror_shows_each_light_at_luminance_one() {
        let lights = [Illuminant::Sodium, Illuminant::A, Illuminant::F11]
            .map(Light::illuminant)
            .to_vec();
        let config = BakeConfig::builder().lights(lights).build().unwrap();
        for k in 0..3 {
            let rgb = flat(&light_pass(&config, k), 1.0).map(f64::from);
            let y = apply(&XYZ_FROM_SRGB, rgb)[1];
            assert!(
                (y - 1.0).abs() < 1e-6,
                "light {k}: Y = {y}, off by {:e}",
                y - 1.0
            );
        }
    }

    #[test]
    fn a_line_light_keeps_only_its_lines() {
        let config = BakeConfig::default();
        let pass = light_pass(&config, 0);
        assert_eq!(pass.wavelength_nm, [589.0, 589.6]);
        assert_eq!(pass.n_film, [1.33, 1.33]);
    }
}
