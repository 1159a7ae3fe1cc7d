//! The spectral reference ray tracer: the same [`RenderScene`] and camera as the CPU
//! backend (`raster`), traced exactly, to measure what the real-time approximations cost.
//!
//! It reads the scene crate (`render_scene`: the model, and the opaque shading
//! functions) and `thinfilm` (the exact film), never the rasterizer.
//!
//! Per pixel, at least `samples_per_side²` camera rays on an Owen-scrambled Sobol net
//! ([`sampling`]), then twice as many, and so on, until the standard error of the pixel's
//! mean, from the spread of four blocks of its rays, is within `tolerance_de` (ΔE2000, as
//! displayed) or `max_samples` is reached: rays go
//! where the image is not yet converged. Each ray carries its differentials, so textures
//! are box-filtered over the patch its sample stands for. Every choice is per pixel and
//! from the seed, so the image is the same at any thread count. A ray meets
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
mod sampling;
mod spectral;
mod trace;
mod upsample;

use rayon::prelude::*;

pub use spectral::{FilmSpec, MAX_WAVELENGTHS};

use geometry::Geometry;
use render_scene::camera::View;
use render_scene::{Frame, MAX_IMAGE_SIDE, RenderError, RenderScene, ToneMap, Vec3, tone_map};
use spectral::{Grid, luminance};
use thinfilm::colorspace::{XYZ_FROM_SRGB, apply};
use thinfilm::{Lab, ciede2000, lab_from_xyz};
use trace::{Beam, Ray, Tracer};
use upsample::Uplift;

/// How the reference traces.
#[derive(Debug, Clone, PartialEq)]
pub struct ReferenceSettings {
    /// Image width in pixels.
    pub width: usize,
    /// Image height in pixels.
    pub height: usize,
    /// Camera rays per pixel along each axis at the start (the pixel gets its square);
    /// also the texture filter's cell: a ray stands for `1/samples_per_side` of a pixel.
    pub samples_per_side: u32,
    /// Most camera rays per pixel: the count doubles until the pixel converges or this is hit.
    pub max_samples: u32,
    /// A pixel is done when the standard error of its mean, estimated from four blocks of
    /// its rays, is at most this ΔE2000, as displayed (`exposure_ev`, `tonemap`).
    pub tolerance_de: f64,
    /// Box-filter checkers over each ray's footprint (true), or point-sample them.
    pub filter_textures: bool,
    /// Exposure the image will be displayed at (for the convergence test only).
    pub exposure_ev: f32,
    /// Tone curve the image will be displayed with (for the convergence test only).
    pub tonemap: ToneMap,
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
    /// Seed of the per-pixel scrambling of the sample positions.
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
    /// 400 × 400, 16 to 1024 rays per pixel to a standard error of ΔE 0.15 (ACES, 0 EV),
    /// filtered textures, depth 8, cut-off 1e-4, 10 nm, polarised, spectral.
    fn default() -> Self {
        Self {
            width: 400,
            height: 400,
            samples_per_side: 4,
            max_samples: 1024,
            tolerance_de: 0.15,
            filter_textures: true,
            exposure_ev: 0.0,
            tonemap: ToneMap::AcesFitted,
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
        let base = self.samples_per_side * self.samples_per_side;
        if !(base..=MAX_SAMPLES).contains(&self.max_samples) {
            return Err(RenderError::setting(
                "max_samples",
                self.max_samples,
                "samples_per_side² ..= 65536",
            ));
        }
        if self.tolerance_de.is_nan() || self.tolerance_de < 0.0 {
            return Err(RenderError::setting(
                "tolerance_de",
                self.tolerance_de,
                "a ΔE2000 >= 0",
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

/// Most camera rays one pixel may get.
pub const MAX_SAMPLES: u32 = 65536;

/// Renders `scene` with the reference tracer; `on_row` is called once per finished row
/// (from any thread), for progress.
pub fn render_reference(
    scene: &RenderScene,
    spec: &FilmSpec,
    settings: &ReferenceSettings,
    on_row: &(dyn Fn() + Sync),
) -> Result<Frame, RenderError> {
    render_reference_counted(scene, spec, settings, on_row).map(|(frame, _)| frame)
}

/// How many camera rays the adaptive loop gave the pixels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RayCount {
    /// Mean camera rays per pixel.
    pub mean: f64,
    /// The most any pixel got.
    pub max: u32,
    /// Pixels that reached `max_samples` with a standard error still above the tolerance.
    pub unconverged: usize,
}

/// [`render_reference`], also saying how many rays went where.
pub fn render_reference_counted(
    scene: &RenderScene,
    spec: &FilmSpec,
    settings: &ReferenceSettings,
    on_row: &(dyn Fn() + Sync),
) -> Result<(Frame, RayCount), RenderError> {
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
    let rows: Vec<Vec<Pixel>> = (0..settings.height)
        .into_par_iter()
        .map(|y| {
            let row = (0..settings.width)
                .map(|x| pixel(&tracer, &view, x, y))
                .collect();
            on_row();
            row
        })
        .collect();
    let pixels: Vec<Pixel> = rows.into_iter().flatten().collect();
    let count = RayCount {
        mean: pixels.iter().map(|p| f64::from(p.rays)).sum::<f64>() / pixels.len() as f64,
        max: pixels.iter().map(|p| p.rays).max().unwrap_or(0),
        unconverged: pixels.iter().filter(|p| !p.converged).count(),
    };
    let rgb = pixels.into_iter().map(|p| p.rgb).collect();
    // Validated sides are non-zero and every row holds `width` pixels.
    let frame = Frame::try_from_rgb(settings.width, settings.height, rgb)
        .ok_or_else(|| RenderError::scene("reference", "frame size mismatch".to_string()))?;
    Ok((frame, count))
}

/// A finished pixel: its colour, the rays it took and whether it met the tolerance.
struct Pixel {
    rgb: [f32; 3],
    rays: u32,
    converged: bool,
}

/// The pixel's mean over rays `0..n`, doubling `n` from `samples_per_side²` until the
/// standard error of the mean, estimated from four consecutive blocks of its rays, is
/// within the tolerance, or `max_samples`. Each block is itself a scrambled net (see
/// [`sampling`]), so their spread is that of independent stratified estimates.
fn pixel(tracer: &Tracer<'_>, view: &View, x: usize, y: usize) -> Pixel {
    let s = tracer.settings;
    let sample = |range: std::ops::Range<u32>| Block {
        sum: sum_rays(tracer, view, (x, y), range.clone()),
        rays: range.len() as u32,
    };
    let split = |from: u32, to: u32| {
        [
            sample(from..from + (to - from) / 2),
            sample(from + (to - from) / 2..to),
        ]
    };
    let mut n = s.samples_per_side * s.samples_per_side;
    let [q0, q1] = split(0, n / 2);
    let [q2, q3] = split(n / 2, n);
    let mut blocks = [q0, q1, q2, q3];
    loop {
        let total = blocks.iter().fold(Block::EMPTY, |a, b| a.plus(b));
        let converged = standard_error(s, &blocks, &total).is_some_and(|e| e <= s.tolerance_de);
        if converged || n >= s.max_samples {
            // Out-of-gamut colours stay negative, as in the LUT path; the tone curve clamps them.
            return Pixel {
                rgb: total.mean().map(|c| c as f32),
                rays: n,
                converged: converged || n < 4,
            };
        }
        let next = n.saturating_mul(2).min(s.max_samples);
        let [q2, q3] = split(n, next);
        blocks = [
            blocks[0].plus(&blocks[1]),
            blocks[2].plus(&blocks[3]),
            q2,
            q3,
        ];
        n = next;
    }
}

/// The summed radiance of some of a pixel's rays.
#[derive(Debug, Clone, Copy)]
struct Block {
    sum: [f64; 3],
    rays: u32,
}

impl Block {
    const EMPTY: Block = Block {
        sum: [0.0; 3],
        rays: 0,
    };

    fn plus(&self, other: &Block) -> Block {
        Block {
            sum: [0, 1, 2].map(|c| self.sum[c] + other.sum[c]),
            rays: self.rays + other.rays,
        }
    }

    fn mean(&self) -> [f64; 3] {
        self.sum.map(|c| c / f64::from(self.rays.max(1)))
    }
}

/// The standard error of the pixel's mean in displayed ΔE2000, from the spread of four
/// block means about it: `sqrt(Σ ΔE² / (4 · 3))`; `None` while a block is empty.
fn standard_error(s: &ReferenceSettings, blocks: &[Block; 4], total: &Block) -> Option<f64> {
    if blocks.iter().any(|b| b.rays == 0) {
        return None;
    }
    let centre = displayed(s, total.mean());
    let spread: f64 = blocks
        .iter()
        .map(|b| ciede2000(displayed(s, b.mean()), centre).powi(2))
        .sum();
    Some((spread / 12.0).sqrt())
}

/// The sum of the radiance along the pixel's rays `range` (indices into its sequence).
fn sum_rays(
    tracer: &Tracer<'_>,
    view: &View,
    (x, y): (usize, usize),
    range: std::ops::Range<u32>,
) -> [f64; 3] {
    let s = tracer.settings;
    let unit = Beam::unit();
    // A ray stands for a 1/samples_per_side pixel cell: its texture filter's width.
    let cell = 1.0 / s.samples_per_side as f32;
    let axes = [view.right * view.x_per_px, -view.up * view.y_per_px].map(|a| a * cell);
    let mut sum = [0.0f64; 3];
    for i in range {
        let (u, v) = sampling::pixel_point(s.seed, x, y, i);
        let raw = view.ray(x as f32 + u, y as f32 + v);
        let dir = raw.normalize();
        // d(raw/|raw|) = (d − (d·dir) dir) / |raw|: the unit direction across the cell.
        let d_dir = axes.map(|d| (d - dir * d.dot(dir)) / raw.length());
        let ray = Ray {
            origin: view.eye,
            dir,
            d_origin: [Vec3::ZERO; 2],
            d_dir,
        };
        let mut out = [0.0; 3];
        tracer.trace(&ray, &unit, s.max_depth, None, &mut out);
        for c in 0..3 {
            sum[c] += out[c];
        }
    }
    sum
}

/// CIELAB of a linear colour after the exposure and tone curve (white = sRGB white).
fn displayed(s: &ReferenceSettings, rgb: [f64; 3]) -> Lab {
    let scale = s.exposure_ev.exp2();
    let mapped = tone_map(rgb.map(|c| c as f32 * scale), s.tonemap).map(f64::from);
    let white = apply(&XYZ_FROM_SRGB, [1.0; 3]);
    lab_from_xyz(apply(&XYZ_FROM_SRGB, mapped), white)
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
