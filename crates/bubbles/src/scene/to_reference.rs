//! Scene → the reference tracer's [`reference_tracer::FilmSpec`]: the film, the
//! reference illuminant and each light's own spectrum, as the LUT bake sees them.

use super::Scene;
use crate::error::CliError;
use reference_tracer::FilmSpec;

/// The medium around the bubbles: the LUT bakes against air.
const N_AIR: f64 = 1.0;

impl Scene {
    /// The film description for the reference; `lights` are the scene's raster lights
    /// (their `light_lut` indices name the bake's lights, whose spectra are used).
    pub fn film_spec(&self, lights: &[raster::Light]) -> Result<FilmSpec, CliError> {
        let config = self.bake_config()?;
        let light_spectra = lights
            .iter()
            .map(|l| {
                l.light_lut
                    .and_then(|j| config.lights().get(j))
                    .map(|light| light.spectrum().clone())
            })
            .collect();
        Ok(FilmSpec {
            n_outside: N_AIR,
            n_film: *config.film_index(),
            observer: config.observer(),
            reference: config.reference().spectrum().clone(),
            light_spectra,
        })
    }
}
