//! `--backend reference`: the spectral reference tracer behind the same frame job, with
//! its own options and a progress bar with an ETA.

use crate::error::CliError;
use crate::limits;
use crate::scene::values::plain;
use raster::{Frame, RenderScene, RenderSettings};
use reference_tracer::{FilmSpec, ReferenceSettings, Reflections, render_reference_counted};

/// Options of the reference backend (ignored by the CPU backend).
#[derive(Debug, Clone, clap::Args)]
pub struct ReferenceOptions {
    /// Reference: camera rays per pixel along each axis to start with (the pixel gets the
    /// square); pixels whose estimate is not yet within --ref-tolerance get twice as many,
    /// and so on.
    #[arg(long, default_value_t = 4)]
    pub ref_samples: u32,
    /// Reference: most camera rays one pixel may get (--ref-samples² disables refinement).
    #[arg(long, default_value_t = 1024)]
    pub ref_max_samples: u32,
    /// Reference: a pixel is done when the standard error of its mean, estimated from four
    /// blocks of its rays, is at most this ΔE2000 as displayed.
    #[arg(long, default_value_t = 0.15)]
    pub ref_tolerance: f64,
    /// Reference: point-sample the checkers instead of box-filtering them over each ray's
    /// footprint (the reference before 2026-11-25).
    #[arg(long)]
    pub ref_point_textures: bool,
    /// Reference: films a path may meet before further films are passed straight through.
    #[arg(long, default_value_t = 8)]
    pub ref_depth: u32,
    /// Reference: drop a beam whose largest factor is below this.
    #[arg(long, default_value_t = 1e-4)]
    pub ref_min_weight: f64,
    /// Reference: wavelength spacing in nm (10 nm: 48 wavelengths).
    #[arg(long, default_value_t = 10.0)]
    pub ref_step_nm: f64,
    /// Reference: average s and p at every film instead of carrying both.
    #[arg(long)]
    pub ref_unpolarised: bool,
    /// Reference: carry RGB (films projected as the LUT bakes them) instead of spectra.
    #[arg(long)]
    pub ref_rgb: bool,
    /// Reference: seed of the pixel-sample jitter.
    #[arg(long, default_value_t = 0)]
    pub ref_seed: u64,
    /// Reference: reflected rays traced (the truth), traced through no films, or cast from
    /// the bubble's centre through no films (the cube map's viewpoint).
    #[arg(long, value_enum, default_value_t = RefReflections::Traced)]
    pub ref_reflections: RefReflections,
}

/// Where the reference's reflected rays start and what they see.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum RefReflections {
    /// From the hit point, seeing every film.
    Traced,
    /// From the hit point, through all films.
    NoFilms,
    /// From the bubble's centre, through all films (a perfect dynamic cube map).
    Centre,
}

impl Default for ReferenceOptions {
    fn default() -> Self {
        let d = ReferenceSettings::default();
        Self {
            ref_samples: d.samples_per_side,
            ref_max_samples: d.max_samples,
            ref_tolerance: d.tolerance_de,
            ref_point_textures: !d.filter_textures,
            ref_depth: d.max_depth,
            ref_min_weight: d.min_weight,
            ref_step_nm: d.step_nm,
            ref_unpolarised: false,
            ref_rgb: false,
            ref_seed: d.seed,
            ref_reflections: RefReflections::Traced,
        }
    }
}

impl ReferenceOptions {
    /// The tracer's settings at the frame's size.
    pub fn settings(&self, frame: &RenderSettings) -> ReferenceSettings {
        ReferenceSettings {
            width: frame.width,
            height: frame.height,
            samples_per_side: self.ref_samples,
            max_samples: self.ref_max_samples,
            tolerance_de: self.ref_tolerance,
            filter_textures: !self.ref_point_textures,
            exposure_ev: frame.exposure_ev,
            tonemap: frame.tonemap,
            max_depth: self.ref_depth,
            min_weight: self.ref_min_weight,
            step_nm: self.ref_step_nm,
            polarised: !self.ref_unpolarised,
            spectral: !self.ref_rgb,
            reflections: match self.ref_reflections {
                RefReflections::Traced => Reflections::Traced,
                RefReflections::NoFilms => Reflections::NoFilms,
                RefReflections::Centre => Reflections::FromCentre,
            },
            seed: self.ref_seed,
        }
    }
}

/// Refuses settings whose worst-case work passes [`limits::MAX_REFERENCE_FILM_HITS`],
/// naming the estimate and the flags that set it.
pub fn check_work(settings: &ReferenceSettings) -> Result<(), CliError> {
    let hits = limits::reference_film_hits(
        settings.width,
        settings.height,
        settings.max_samples,
        settings.max_depth,
    );
    if hits <= limits::MAX_REFERENCE_FILM_HITS {
        return Ok(());
    }
    Err(CliError::input(format!(
        "--backend reference at {}x{} with --ref-max-samples {} and --ref-depth {} may trace \
         up to {} film hits (pixels × max samples × (2^(depth+1) − 1)), over the limit of {}: \
         lower --ref-depth, --ref-max-samples or the size",
        settings.width,
        settings.height,
        settings.max_samples,
        settings.max_depth,
        plain(hits),
        plain(limits::MAX_REFERENCE_FILM_HITS)
    )))
}

/// Traces one frame, with a progress bar on stderr when `progress` is set.
pub fn render(
    scene: &RenderScene,
    spec: &FilmSpec,
    settings: &ReferenceSettings,
    progress: bool,
) -> Result<Frame, CliError> {
    let bar = if progress {
        indicatif::ProgressBar::new(settings.height as u64)
    } else {
        indicatif::ProgressBar::hidden()
    };
    if let Ok(style) = indicatif::ProgressStyle::with_template(
        "reference {bar:40} {pos}/{len} rows, {elapsed} elapsed, ETA {eta}",
    ) {
        bar.set_style(style);
    }
    let start = std::time::Instant::now();
    let (frame, rays) = render_reference_counted(scene, spec, settings, &|| bar.inc(1))
        .map_err(|e| CliError::input(format!("reference: {e}")))?;
    bar.finish_and_clear();
    if progress {
        eprintln!(
            "reference: traced {}x{} in {:.2} s on {} threads, {:.1} rays per pixel on \
             average (at most {}; {} pixels stopped at the cap unconverged)",
            settings.width,
            settings.height,
            start.elapsed().as_secs_f64(),
            rayon::current_num_threads(),
            rays.mean,
            rays.max,
            rays.unconverged
        );
    }
    Ok(frame)
}
