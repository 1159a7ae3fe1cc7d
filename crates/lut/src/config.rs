//! [`BakeConfig`]: what to bake, validated, with the documented defaults.

use std::fmt;
use std::path::Path;

use thinfilm::cmf::Observer;
use thinfilm::dispersion::RefractiveIndex;
use thinfilm::illuminant::Illuminant;
use thinfilm::integrate::{MAX_STEP_NM, MIN_STEP_NM, SpectralIntegrator};
use thinfilm::spectrum::Spectrum;

use crate::MAX_SIDE;
use crate::set::is_valid_light_name;
use crate::weights::{linear_srgb_white, sample_wavelengths};

/// Default number of thickness columns: the thickness axis sets the lookup error, and
/// 4096 over 4000 nm (0.98 nm per column, as 2048 over 2000 nm) keeps the reflectivity
/// within the published ΔE00 bound (docs/lut.md).
pub const DEFAULT_WIDTH: usize = 4096;
/// Default number of cos θ rows: more rows barely change the error above grazing.
pub const DEFAULT_HEIGHT: usize = 128;
/// Default thickness of the last column, in nm: the one definition of the thickness range
/// used by the tables, `bubbles chart` and the OBJ export. Seed 000's Fig. 2 stops at
/// 2000 nm, but films drain thicker (2731 nm in `paper` at t = 0.5 s); beyond 4000 nm the
/// reflected colour stays within ΔE76 1 of the thick-film (incoherent) limit at every
/// angle up to 75°, even exposed so the reflection is white (docs/rendering.md), so the
/// renderer's clamp at the last column no longer shows.
pub const DEFAULT_THICKNESS_MAX_NM: f32 = 4000.0;
/// Default spacing of the integration wavelengths, in nm.
pub const DEFAULT_STEP_NM: f64 = 5.0;
/// Refractive index on both sides of the film: air.
pub const N_OUTSIDE: f64 = 1.0;
/// Largest accepted texel count of one table (a 8192 × 8192 table is 768 MiB).
pub const MAX_TEXELS: usize = 1 << 26;
/// Largest accepted thickness range, in nm (100 µm: far past any visible interference).
pub const MAX_THICKNESS_NM: f32 = 100_000.0;
/// Accepted integration steps, in nm (the integrator's limits).
pub const STEP_RANGE_NM: std::ops::RangeInclusive<f64> = MIN_STEP_NM..=MAX_STEP_NM;
/// Smallest linear-sRGB channel a reference white may have: reflectivity is divided by it.
pub const MIN_WHITE_CHANNEL: f64 = 0.05;

/// A light: a name (used in file names) and its spectral power distribution.
#[derive(Debug, Clone, PartialEq)]
pub struct Light {
    name: String,
    spectrum: Spectrum,
}

impl Light {
    /// A built-in illuminant, named as [`Illuminant::name`] (`d65`, `sodium`, …).
    pub fn illuminant(illuminant: Illuminant) -> Self {
        Self {
            name: illuminant.name().to_owned(),
            spectrum: illuminant.spectrum(),
        }
    }

    /// A light called `name` emitting `spectrum`.
    ///
    /// # Guarantees
    /// The name is 1 to 64 ASCII letters, digits, `_` or `-`, so it is a safe file name.
    pub fn try_new(name: &str, spectrum: Spectrum) -> Result<Self, ConfigError> {
        if !is_valid_light_name(name) {
            return Err(ConfigError::LightName(name.to_owned()));
        }
        Ok(Self {
            name: name.to_owned(),
            spectrum,
        })
    }

    /// Reads a CSV spectrum (header `wavelength_nm,value`, then one sample per line; see
    /// `Spectrum::from_csv_str`) and names it after the file
    /// stem, with characters unsafe in file names replaced by `_`.
    pub fn try_from_csv_path(path: &Path) -> Result<Self, ConfigError> {
        let spectrum = Spectrum::from_csv_path(path).map_err(|e| ConfigError::Spectrum {
            path: path.display().to_string(),
            message: e.to_string(),
        })?;
        let stem = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        Self::try_new(&file_safe_name(&stem), spectrum)
    }

    /// The light's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The light's spectral power distribution.
    pub fn spectrum(&self) -> &Spectrum {
        &self.spectrum
    }
}

/// `stem` with every character outside `[A-Za-z0-9_-]` replaced by `_`, cut to 64 bytes.
fn file_safe_name(stem: &str) -> String {
    let safe: String = stem
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' {
                c
            } else {
                '_'
            }
        })
        .take(64)
        .collect();
    if safe.is_empty() {
        "custom".into()
    } else {
        safe
    }
}

/// Why a bake configuration was refused.
#[derive(Debug, Clone, PartialEq)]
pub enum ConfigError {
    /// A side is outside `2..=16384` or the table has more than [`MAX_TEXELS`] texels.
    Resolution {
        /// Requested columns.
        width: usize,
        /// Requested rows.
        height: usize,
    },
    /// The thickness range is not finite, not positive, or above [`MAX_THICKNESS_NM`].
    ThicknessMax(f32),
    /// The integration step is outside [`STEP_RANGE_NM`].
    Step(f64),
    /// The film index model is invalid, or not finite or below the outside index at some
    /// integration wavelength.
    FilmIndex(String),
    /// A light name is unsafe as a file name.
    LightName(String),
    /// Two lights share a name.
    DuplicateLight(String),
    /// A spectrum file could not be read or parsed.
    Spectrum {
        /// The file.
        path: String,
        /// The parser's message (with the line number).
        message: String,
    },
    /// A light cannot be integrated (e.g. it emits nothing visible).
    Light {
        /// The light's name.
        name: String,
        /// Why.
        message: String,
    },
    /// The reference white has a linear-sRGB channel too small to divide by.
    ReferenceWhite {
        /// The light's name.
        name: String,
        /// Its linear-sRGB colour at Y = 1.
        rgb: [f64; 3],
    },
}

impl fmt::Display for ConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Resolution { width, height } => write!(
                f,
                "resolution {width}x{height} is invalid: each side must be in 2..={MAX_SIDE} and the table at most {MAX_TEXELS} texels"
            ),
            Self::ThicknessMax(d) => write!(
                f,
                "thickness range 0..{d} nm is invalid: the maximum must be > 0 and <= {MAX_THICKNESS_NM} nm"
            ),
            Self::Step(step) => write!(
                f,
                "integration step {step} nm is invalid: it must be in {}..={} nm",
                STEP_RANGE_NM.start(),
                STEP_RANGE_NM.end()
            ),
            Self::FilmIndex(message) => write!(f, "film index: {message}"),
            Self::LightName(name) => write!(
                f,
                "light name {name:?} is invalid: use 1 to 64 ASCII letters, digits, '_' or '-'"
            ),
            Self::DuplicateLight(name) => write!(f, "light {name:?} is given twice"),
            Self::Spectrum { path, message } => write!(f, "spectrum file {path}: {message}"),
            Self::Light { name, message } => write!(f, "light {name:?}: {message}"),
            Self::ReferenceWhite { name, rgb } => write!(
                f,
                "light {name:?} cannot be the reference white: its linear sRGB ({:.3}, {:.3}, {:.3}) has a channel below {MIN_WHITE_CHANNEL}",
                rgb[0], rgb[1], rgb[2]
            ),
        }
    }
}

impl std::error::Error for ConfigError {}

/// A validated description of one bake.
///
/// # Guarantees
/// - `2 <= width, height <= 16384` and `width · height <= MAX_TEXELS`;
/// - `0 < thickness_max_nm <= MAX_THICKNESS_NM`;
/// - `step_nm` lies in [`STEP_RANGE_NM`];
/// - the film index model is valid, finite and `>= N_OUTSIDE` at every integration wavelength;
/// - every light integrates to a finite colour with Y > 0 and has a unique, file-safe name;
/// - the reference white's linear-sRGB channels are all `>= MIN_WHITE_CHANNEL`.
#[derive(Debug, Clone, PartialEq)]
pub struct BakeConfig {
    pub(crate) width: usize,
    pub(crate) height: usize,
    pub(crate) thickness_max_nm: f32,
    pub(crate) film_index: RefractiveIndex,
    pub(crate) observer: Observer,
    pub(crate) step_nm: f64,
    pub(crate) reference: Light,
    pub(crate) lights: Vec<Light>,
}

impl Default for BakeConfig {
    /// 4096 × 128 texels over 0–4000 nm, soap film index, CIE 1931 observer, 5 nm step,
    /// D65 reference white, one light-source table for the sodium lamp.
    fn default() -> Self {
        Self::builder()
            .build()
            .expect("the documented defaults are valid")
    }
}

impl BakeConfig {
    /// A builder starting from the documented defaults.
    pub fn builder() -> BakeConfigBuilder {
        BakeConfigBuilder {
            config: BakeConfig {
                width: DEFAULT_WIDTH,
                height: DEFAULT_HEIGHT,
                thickness_max_nm: DEFAULT_THICKNESS_MAX_NM,
                film_index: RefractiveIndex::SOAP,
                observer: Observer::Cie1931,
                step_nm: DEFAULT_STEP_NM,
                reference: Light::illuminant(Illuminant::D65),
                lights: vec![Light::illuminant(Illuminant::Sodium)],
            },
        }
    }

    /// A builder starting from this configuration.
    pub fn to_builder(&self) -> BakeConfigBuilder {
        BakeConfigBuilder {
            config: self.clone(),
        }
    }

    /// Number of thickness columns.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Number of cos θ rows.
    pub fn height(&self) -> usize {
        self.height
    }

    /// Thickness of the last column, in nm.
    pub fn thickness_max_nm(&self) -> f32 {
        self.thickness_max_nm
    }

    /// The film's refractive index.
    pub fn film_index(&self) -> &RefractiveIndex {
        &self.film_index
    }

    /// The CIE observer.
    pub fn observer(&self) -> Observer {
        self.observer
    }

    /// Spacing of the integration wavelengths, in nm.
    pub fn step_nm(&self) -> f64 {
        self.step_nm
    }

    /// The white light the reflectivity and transmittance tables are normalised to.
    pub fn reference(&self) -> &Light {
        &self.reference
    }

    /// The lights that get a light-source table, in order.
    pub fn lights(&self) -> &[Light] {
        &self.lights
    }

    /// The spectral integrator of `light` under this configuration's observer and step.
    pub(crate) fn integrator(&self, light: &Light) -> Result<SpectralIntegrator, ConfigError> {
        SpectralIntegrator::new(self.observer, light.spectrum(), self.step_nm).map_err(|e| {
            ConfigError::Light {
                name: light.name().to_owned(),
                message: e.to_string(),
            }
        })
    }

    fn validate(&self) -> Result<(), ConfigError> {
        let sides = 2..=MAX_SIDE;
        if !sides.contains(&self.width)
            || !sides.contains(&self.height)
            || self.width * self.height > MAX_TEXELS
        {
            return Err(ConfigError::Resolution {
                width: self.width,
                height: self.height,
            });
        }
        let d = self.thickness_max_nm;
        if !(d.is_finite() && d > 0.0 && d <= MAX_THICKNESS_NM) {
            return Err(ConfigError::ThicknessMax(d));
        }
        if !STEP_RANGE_NM.contains(&self.step_nm) {
            return Err(ConfigError::Step(self.step_nm));
        }
        self.validate_lights()
    }

    fn validate_lights(&self) -> Result<(), ConfigError> {
        for (k, light) in self.lights.iter().enumerate() {
            if self.lights[..k].iter().any(|l| l.name == light.name) {
                return Err(ConfigError::DuplicateLight(light.name.clone()));
            }
        }
        self.film_index
            .validate()
            .map_err(|e| ConfigError::FilmIndex(e.to_string()))?;
        for light in std::iter::once(&self.reference).chain(&self.lights) {
            let integrator = self.integrator(light)?;
            for wavelength_nm in sample_wavelengths(&integrator) {
                let n = self
                    .film_index
                    .try_n_at(wavelength_nm)
                    .map_err(|e| ConfigError::FilmIndex(e.to_string()))?;
                if n < N_OUTSIDE {
                    return Err(ConfigError::FilmIndex(format!(
                        "{n} at {wavelength_nm} nm is below the outside index {N_OUTSIDE}"
                    )));
                }
            }
        }
        let rgb = linear_srgb_white(&self.integrator(&self.reference)?);
        if rgb.iter().any(|&c| c.is_nan() || c < MIN_WHITE_CHANNEL) {
            return Err(ConfigError::ReferenceWhite {
                name: self.reference.name.clone(),
                rgb,
            });
        }
        Ok(())
    }
}

/// Sets the fields of a [`BakeConfig`]; [`BakeConfigBuilder::build`] validates them.
#[derive(Debug, Clone)]
pub struct BakeConfigBuilder {
    config: BakeConfig,
}

impl BakeConfigBuilder {
    /// Columns (thickness samples) and rows (cos θ samples).
    pub fn resolution(mut self, width: usize, height: usize) -> Self {
        self.config.width = width;
        self.config.height = height;
        self
    }

    /// Thickness of the last column, in nm.
    pub fn thickness_max_nm(mut self, thickness_max_nm: f32) -> Self {
        self.config.thickness_max_nm = thickness_max_nm;
        self
    }

    /// The film's refractive index, with or without dispersion.
    pub fn film_index(mut self, film_index: RefractiveIndex) -> Self {
        self.config.film_index = film_index;
        self
    }

    /// The CIE observer.
    pub fn observer(mut self, observer: Observer) -> Self {
        self.config.observer = observer;
        self
    }

    /// Spacing of the integration wavelengths, in nm.
    pub fn step_nm(mut self, step_nm: f64) -> Self {
        self.config.step_nm = step_nm;
        self
    }

    /// The white light the reflectivity and transmittance tables are normalised to.
    pub fn reference(mut self, reference: Light) -> Self {
        self.config.reference = reference;
        self
    }

    /// The lights that get a light-source table (replacing the default sodium lamp).
    pub fn lights(mut self, lights: Vec<Light>) -> Self {
        self.config.lights = lights;
        self
    }

    /// Checks every guarantee of [`BakeConfig`].
    pub fn build(self) -> Result<BakeConfig, ConfigError> {
        self.config.validate()?;
        Ok(self.config)
    }
}
