//! The spectral reference ray tracer: the same [`RenderScene`] and camera as the CPU
//! backend (`raster`), traced exactly, to measure what the real-time approximations cost.
//!
//! It reads the scene crate (`render_scene`: the model, and the opaque shading
//! functions) and `thinfilm` (the exact film), never the rasterizer.
//!
//! Per pixel, `samples_per_side²` stratified, jittered camera rays (the jitter is a hash of
//! the seed, pixel and sample, so the image is the same at any thread count). A ray meets
//! bubble triangles (a [`bvh`] over all bubbles, normals and thickness interpolated),
//! opaque triangles (objects tessellated as the CPU backend does), the analytic ground
//! and the lights as the spheres they are. At a film the exact Airy `R` and `T`
//! (`thinfilm`, f64, s and p) at the local thickness and true angle split the beam; both
//! parts are traced on until `max_depth` films or a weight below `min_weight`. Opaque
//! surfaces are shaded by the scene crate's functions (the CPU backend's); RGB radiance is upsampled to a
//! spectrum by Smits (1999) ([`upsample`]); lights use their own spectra. The spectrum is
//! integrated to XYZ and converted to the CPU backend's linear RGB, so the result is a
//! [`Frame`] written with the same tone curve.

#![warn(missing_docs)]

mod bvh;
mod geometry;
mod spectral;
mod trace;
mod upsample;

use rayon::prelude::*;

pub use spectral::{FilmSpec, MAX_WAVELENGTHS};

use geometry::Geometry;
use render_scene::camera::View;
use render_scene::{Frame, MAX_IMAGE_SIDE, RenderError, RenderScene};
use spectral::{Grid, luminance};
use trace::{Beam, Tracer};
use upsample::Uplift;

/// How the reference traces.
#[derive(Debug, Clone, PartialEq)]
pub struct ReferenceSettings {
    /// Image width in pixels.
    pub width: usize,
    /// Image height in pixels.
    pub height: usize,
    /// Camera rays per pixel along each axis (the pixel gets its square).
    pub samples_per_side: u32,
    /// Films a path may interact with; beyond, films are passed straight through.
    pub max_depth: u32,
    /// A beam whose largest factor falls below this is dropped.
    pub min_weight: f64,
    /// Spacing of the wavelength grid in nm (10 nm: 48 wavelengths over 360–830 nm).
    pub step_nm: f64,
    /// Carry s and p separately (true), or average them at every film (false).
    pub polarised: bool,
    /// Carry spectra (true), or RGB with films projected as the LUT bakes them (false).
    pub spectral: bool,
    /// Where rays reflected off a film come from (to isolate the cube map's approximations).
    pub reflections: Reflections,
    /// Seed of the sample jitter.
    pub seed: u64,
}

/// Where a film's reflected rays start and what they see.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Reflections {
    /// Traced from the hit point, seeing every film (the truth).
    #[default]
    Traced,
    /// Traced from the hit point, passing through all films (as a cube map without bubbles).
    NoFilms,
    /// From the bubble's centre, passing through all films: the dynamic cube map's single
    /// viewpoint (seed 000 §4.2.2), at the cube map's infinite resolution.
    FromCentre,
}

impl Default for ReferenceSettings {
    /// 400 × 400, 4 × 4 samples, depth 8, cut-off 1e-4, 10 nm, polarised, spectral.
    fn default() -> Self {
        Self {
            width: 400,
            height: 400,
            samples_per_side: 4,
            max_depth: 8,
            min_weight: 1e-4,
            step_nm: 10.0,
            polarised: true,
            spectral: true,
            reflections: Reflections::Traced,
            seed: 0,
        }
    }
}

impl ReferenceSettings {
    /// Checks every field, naming the first bad one.
    pub fn validate(&self) -> Result<(), RenderError> {
        for (name, side) in [("width", self.width), ("height", self.height)] {
            if !(1..=MAX_IMAGE_SIDE).contains(&side) {
                return Err(RenderError::setting(name, side, "1 ..= 16384 pixels"));
            }
        }
        if !(1..=16).contains(&self.samples_per_side) {
            return Err(RenderError::setting(
                "samples_per_side",
                self.samples_per_side,
                "1 ..= 16",
            ));
        }
        if self.max_depth > 64 {
            return Err(RenderError::setting(
                "max_depth",
                self.max_depth,
                "0 ..= 64",
            ));
        }
        if !(0.0..1.0).contains(&self.min_weight) {
            return Err(RenderError::setting(
                "min_weight",
                self.min_weight,
                "0 <= min_weight < 1",
            ));
        }
        Ok(())
    }
}

/// Renders `scene` with the reference tracer; `on_row` is called once per finished row
/// (from any thread), for progress.
pub fn render_reference(
    scene: &RenderScene,
    spec: &FilmSpec,
    settings: &ReferenceSettings,
    on_row: &(dyn Fn() + Sync),
) -> Result<Frame, RenderError> {
    settings.validate()?;
    validate_scene(scene, spec)?;
    let grid = Grid::try_new(spec.observer, &spec.reference, settings.step_nm)?;
    check_film(spec, &grid)?;
    let uplift = Uplift::new(&grid.wavelength_nm, &grid.reference_rgb);
    let light_rgb = light_weights(scene, spec, &grid, &uplift, settings.step_nm)?;
    let tracer = Tracer {
        geo: Geometry::new(scene),
        grid,
        uplift,
        light_rgb,
        spec,
        settings,
        ambient: scene.irradiance.plus_uniform(scene.ambient_rgb),
    };
    let view = scene.camera.view(settings.width, settings.height);
    let rows: Vec<Vec<[f32; 3]>> = (0..settings.height)
        .into_par_iter()
        .map(|y| {
            let row = (0..settings.width)
                .map(|x| pixel(&tracer, &view, x, y))
                .collect();
            on_row();
            row
        })
        .collect();
    let rgb = rows.into_iter().flatten().collect();
    // Validated sides are non-zero and every row holds `width` pixels.
    Frame::try_from_rgb(settings.width, settings.height, rgb)
        .ok_or_else(|| RenderError::scene("reference", "frame size mismatch".to_string()))
}

/// The mean of the pixel's stratified samples.
fn pixel(tracer: &Tracer<'_>, view: &View, x: usize, y: usize) -> [f32; 3] {
    let s = tracer.settings;
    let n = s.samples_per_side;
    let mut sum = [0.0f64; 3];
    let unit = Beam::unit();
    for j in 0..n {
        for i in 0..n {
            let key = [x as u64, y as u64, u64::from(j * n + i)];
            let (jx, jy) = jitter(s.seed, key);
            let px = x as f32 + (i as f32 + jx) / n as f32;
            let py = y as f32 + (j as f32 + jy) / n as f32;
            let dir = view.ray(px, py).normalize();
            let mut out = [0.0; 3];
            tracer.trace(view.eye, dir, &unit, s.max_depth, None, &mut out);
            for c in 0..3 {
                sum[c] += out[c];
            }
        }
    }
    // Out-of-gamut colours stay negative, as in the LUT path; the tone curve clamps them.
    let count = f64::from(n * n);
    sum.map(|c| (c / count) as f32)
}

/// Two uniform numbers in [0, 1) from the seed and a sample key (SplitMix64).
fn jitter(seed: u64, key: [u64; 3]) -> (f32, f32) {
    let mut h = seed ^ 0x9E37_79B9_7F4A_7C15;
    for k in key {
        h = splitmix(h ^ k);
    }
    let a = splitmix(h);
    let b = splitmix(a);
    let unit = |v: u64| (v >> 40) as f32 / (1u64 << 24) as f32;
    (unit(a), unit(b))
}

fn splitmix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Scene checks shared with the CPU backend (the reference reads no film tables).
fn validate_scene(scene: &RenderScene, spec: &FilmSpec) -> Result<(), RenderError> {
    scene.validate()?;
    if spec.light_spectra.len() != scene.lights.len() {
        return Err(RenderError::scene(
            "film spec",
            format!(
                "{} light spectra for {} lights",
                spec.light_spectra.len(),
                scene.lights.len()
            ),
        ));
    }
    Ok(())
}

/// The film's indices must hold at every grid wavelength.
fn check_film(spec: &FilmSpec, grid: &Grid) -> Result<(), RenderError> {
    let film = thinfilm::ThinFilm::symmetric(spec.n_outside, spec.n_film, 0.0);
    let bad = |e: thinfilm::OpticsError| RenderError::scene("film", e.to_string());
    film.validate().map_err(bad)?;
    for &w in &grid.wavelength_nm {
        spec.n_film.try_n_at(w).map_err(bad)?;
    }
    Ok(())
}

/// Per light, the RGB per grid wavelength of its emission at its luminance.
fn light_weights(
    scene: &RenderScene,
    spec: &FilmSpec,
    grid: &Grid,
    uplift: &Uplift,
    step_nm: f64,
) -> Result<Vec<Vec<[f64; 3]>>, RenderError> {
    scene
        .lights
        .iter()
        .zip(&spec.light_spectra)
        .map(|(light, spectrum)| match spectrum {
            Some(s) => grid.emitter_rgb(spec.observer, s, step_nm, luminance(light.radiance)),
            None => {
                let mut s = vec![0.0; MAX_WAVELENGTHS];
                uplift.spectrum(light.radiance, &mut s);
                Ok(grid
                    .reference_rgb
                    .iter()
                    .zip(&s)
                    .map(|(w, v)| w.map(|c| c * v))
                    .collect())
            }
        })
        .collect()
}
