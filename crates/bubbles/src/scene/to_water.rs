//! Scene → `water::Surface` (the geometry) and `raster::WaterSurface` (its optics).

use super::Scene;
use super::schema::WaterSpec;
use crate::error::CliError;
use crate::limits;
use raster::WaterSurface;
use water::{Grid, Perturbation, Ripple, Surface, WaterError, Wave};

impl Scene {
    /// The water's geometry, if the scene has water: its grid and perturbations, evaluated
    /// at any time by [`Surface::evaluate`].
    pub fn water_surface(&self) -> Result<Option<Surface>, CliError> {
        let Some(w) = &self.file.water else {
            return Ok(None);
        };
        let count = w.waves.len() + w.ripples.len();
        if count > limits::MAX_WATER_PERTURBATIONS {
            return Err(CliError::input(format!(
                "{}: water has {count} waves and ripples, above the limit of {} (see --help)",
                self.origin,
                limits::MAX_WATER_PERTURBATIONS
            )));
        }
        let error = |e: WaterError| CliError::input(format!("{}: {e}", self.origin));
        let grid = Grid::try_new(
            w.min_m.map(|v| v.get()),
            w.max_m.map(|v| v.get()),
            w.slices.map(|s| s.get() as usize),
            w.rest_height_m.get(),
        )
        .map_err(error)?;
        Ok(Some(Surface::new(grid, perturbations(w).map_err(error)?)))
    }

    /// The water's optics with an empty mesh (filled each frame from [`Scene::water_surface`]).
    pub fn water_optics(&self) -> Result<Option<WaterSurface>, CliError> {
        let Some(w) = &self.file.water else {
            return Ok(None);
        };
        Ok(Some(WaterSurface {
            positions: Vec::new(),
            normals: Vec::new(),
            triangles: Vec::new(),
            rest_height_m: w.rest_height_m.get() as f32,
            ior: w.ior.get() as f32,
            floor_depth_m: w.floor_depth_m.get() as f32,
            floor: self.material(&w.floor)?,
            absorption_per_m: w.absorption_per_m.get().map(|c| c as f32),
        }))
    }
}

/// The waves then the ripples, as the water crate's perturbations.
fn perturbations(w: &WaterSpec) -> Result<Vec<Perturbation>, WaterError> {
    let waves = w.waves.iter().map(|s| {
        Wave::try_new(
            s.amplitude_m.get(),
            s.wavelength_m.get(),
            s.direction.get(),
            s.omega_rad_per_s.map(|v| v.get()),
        )
        .map(Perturbation::Wave)
    });
    let ripples = w.ripples.iter().map(|s| {
        Ripple::try_new(
            s.amplitude_m.get(),
            s.wavelength_m.get(),
            s.center_m.map(|v| v.get()),
            s.omega_rad_per_s.map(|v| v.get()),
            [
                s.decay_per_m.map_or(0.0, |v| v.get()),
                s.decay_per_s.map_or(0.0, |v| v.get()),
            ],
        )
        .map(Perturbation::Ripple)
    });
    waves.chain(ripples).collect()
}
