//! Scene → the baked film tables (`lut`) and the lights' RGB radiance.

use super::Scene;
use super::schema::LightSpec;
use crate::error::CliError;
use lut::{BakeConfig, LutSet};
use thinfilm::cmf::Observer;
use thinfilm::colorspace::{SRGB_FROM_XYZ, apply};
use thinfilm::dispersion::RefractiveIndex;
use thinfilm::illuminant::Illuminant;
use thinfilm::integrate::{DEFAULT_STEP_NM, SpectralIntegrator};
use thinfilm::spectrum::Spectrum;

impl Scene {
    /// The scene's lights as `lut` lights, deduplicated by name, in first-use order.
    fn lut_lights(&self) -> Result<Vec<lut::Light>, CliError> {
        let mut lights: Vec<lut::Light> = Vec::new();
        for spec in &self.file.lights {
            let light = self.lut_light(&spec.spectrum)?;
            if !lights.iter().any(|l| l.name() == light.name()) {
                lights.push(light);
            }
        }
        Ok(lights)
    }

    fn lut_light(&self, spectrum: &str) -> Result<lut::Light, CliError> {
        match Illuminant::from_name(spectrum) {
            Ok(illuminant) => Ok(lut::Light::illuminant(illuminant)),
            Err(unknown) if !spectrum.ends_with(".csv") => Err(CliError::input(format!(
                "{}: light spectrum: {unknown} (or give a .csv path)",
                self.origin
            ))),
            Err(_) => lut::Light::try_from_csv_path(&self.path(spectrum))
                .map_err(|e| CliError::input(format!("{}: {e}", self.origin))),
        }
    }

    /// The bake configuration for this scene's film and lights, at the default table size.
    pub fn bake_config(&self) -> Result<BakeConfig, CliError> {
        self.bake_config_sized(lut::config::DEFAULT_WIDTH, lut::config::DEFAULT_HEIGHT)
    }

    /// The bake configuration with tables of `width` thickness columns × `height` cos θ rows.
    pub fn bake_config_sized(&self, width: usize, height: usize) -> Result<BakeConfig, CliError> {
        let film = &self.file.film;
        let index = match film.dispersion.as_str() {
            "none" => RefractiveIndex::Constant(film.n_film.get()),
            "water" => RefractiveIndex::Water,
            other => {
                return Err(CliError::input(format!(
                    "{}: film dispersion {other:?}: use \"none\" or \"water\"",
                    self.origin
                )));
            }
        };
        let reference = self.lut_light(&film.illuminant)?;
        BakeConfig::builder()
            .resolution(width, height)
            .film_index(index)
            .reference(reference)
            .lights(self.lut_lights()?)
            .build()
            .map_err(|e| CliError::input(format!("{}: {e}", self.origin)))
    }

    /// Bakes the film tables for this scene, `width × height` texels each.
    pub fn bake_tables(&self, width: usize, height: usize) -> Result<LutSet, CliError> {
        Ok(lut::bake(&self.bake_config_sized(width, height)?))
    }

    /// The renderer's lights: radiance is the spectrum's colour at the given luminance,
    /// and each light points at its own light-source table in `tables`.
    pub fn raster_lights(&self, tables: &LutSet) -> Result<Vec<raster::Light>, CliError> {
        self.file
            .lights
            .iter()
            .map(|spec| self.raster_light(spec, tables))
            .collect()
    }

    fn raster_light(&self, spec: &LightSpec, tables: &LutSet) -> Result<raster::Light, CliError> {
        let light = self.lut_light(&spec.spectrum)?;
        let index = tables.lights.iter().position(|(n, _)| n == light.name());
        let rgb = light_rgb(light.spectrum()).map_err(|e| {
            CliError::input(format!("{}: light {}: {e}", self.origin, spec.spectrum))
        })?;
        let luminance = spec.luminance.get();
        let p = spec.position_m.get();
        Ok(raster::Light {
            position: raster::Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32),
            radius_m: spec.radius_m.get() as f32,
            // Opaque surfaces see the in-gamut colour; bubbles the light's own table.
            radiance: super::to_raster::in_gamut_rgb(rgb).map(|c| (c * luminance) as f32),
            light_lut: index,
        })
    }
}

/// Linear sRGB of a light with luminance 1.
fn light_rgb(spectrum: &Spectrum) -> Result<[f64; 3], String> {
    let integrator = SpectralIntegrator::new(Observer::Cie1931, spectrum, DEFAULT_STEP_NM)
        .map_err(|e| e.to_string())?;
    Ok(apply(&SRGB_FROM_XYZ, integrator.white_xyz()))
}
