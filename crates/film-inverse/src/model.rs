//! The forward model: a film's colour against thickness and viewing angle, in the
//! white-balanced linear RGB a camera records (a perfect mirror of the light is `[1, 1, 1]`).

use crate::error::{InverseError, short};
use rayon::prelude::*;
use thinfilm::colorspace::{SRGB_FROM_XYZ, apply};
use thinfilm::{Observer, RefractiveIndex, SpectralIntegrator, Spectrum};

/// Spectral sample spacing (nm) of the forward model: fine enough for films to 5 µm
/// under line-rich lamps (the CLI's `color` uses the same).
pub const STEP_NM: f64 = 2.0;
/// Thickness spacing (nm) of the colour table.
pub const TABLE_STEP_NM: f64 = 1.0;
/// The thickest film a map may hold (nm): beyond, colours are washed out to white.
pub const MAX_THICKNESS_NM: f64 = 5000.0;
/// The smallest supported thickness range (nm).
pub const MIN_THICKNESS_NM: f64 = 50.0;

/// A film seen in reflection: `n_outside | n_film | n_outside`, lit by one illuminant.
#[derive(Clone, Debug)]
pub struct FilmModel {
    n_outside: f64,
    n_film: RefractiveIndex,
    integrator: SpectralIntegrator,
    thickness_max_nm: f64,
}

impl FilmModel {
    /// A validated model.
    ///
    /// # Errors
    /// `thickness_max_nm` outside [[`MIN_THICKNESS_NM`], [`MAX_THICKNESS_NM`]], `n_outside`
    /// not in [1e-3, 10], a film index that is not defined over the visible range or not
    /// above `n_outside` there (a film of lower index than its surroundings), or an
    /// illuminant with no visible power.
    ///
    /// # Guarantees
    /// Every table built from the model is finite.
    pub fn try_new(
        n_outside: f64,
        n_film: RefractiveIndex,
        illuminant: &Spectrum,
        observer: Observer,
        thickness_max_nm: f64,
    ) -> Result<FilmModel, InverseError> {
        if !(MIN_THICKNESS_NM..=MAX_THICKNESS_NM).contains(&thickness_max_nm) {
            return Err(InverseError::Setting {
                name: "thickness_max_nm",
                value: short(thickness_max_nm),
                allowed: format!("{MIN_THICKNESS_NM} to {MAX_THICKNESS_NM} nm"),
            });
        }
        if !(1e-3..=10.0).contains(&n_outside) {
            return Err(InverseError::Setting {
                name: "n_outside",
                value: short(n_outside),
                allowed: "1e-3 to 10".into(),
            });
        }
        let integrator = SpectralIntegrator::new(observer, illuminant, STEP_NM)
            .map_err(|e| InverseError::Optics(format!("illuminant: {e}")))?;
        for &w in integrator.wavelengths_nm() {
            let n = n_film
                .try_n_at(w)
                .map_err(|e| InverseError::Optics(format!("film index: {e}")))?;
            if !(n > n_outside && n <= 10.0) {
                return Err(InverseError::Optics(format!(
                    "film index {} at {w} nm must lie above n_outside {} and at most 10: the inverse models films denser than their surroundings",
                    short(n),
                    short(n_outside)
                )));
            }
        }
        Ok(FilmModel {
            n_outside,
            n_film,
            integrator,
            thickness_max_nm,
        })
    }

    /// A soap film (index 1.33) in air under `illuminant`, CIE 1931 observer, to 1500 nm.
    ///
    /// # Panics
    /// If the illuminant has no visible power.
    pub fn soap(illuminant: &Spectrum) -> FilmModel {
        FilmModel::try_new(
            1.0,
            RefractiveIndex::SOAP,
            illuminant,
            Observer::Cie1931,
            1500.0,
        )
        .expect("a soap film under a visible illuminant is valid")
    }

    /// The thickest film the model covers (nm).
    pub fn thickness_max_nm(&self) -> f64 {
        self.thickness_max_nm
    }

    /// The thickest film the colour table holds (nm): a fifth beyond
    /// [`FilmModel::thickness_max_nm`], so that a film near the top of the range is not
    /// pinned to the table's end (fits there may exceed the range by up to a fifth).
    pub fn table_max_nm(&self) -> f64 {
        self.thickness_max_nm * 1.2
    }

    /// Index outside the film.
    pub fn n_outside(&self) -> f64 {
        self.n_outside
    }

    /// The film's index model.
    pub fn n_film(&self) -> RefractiveIndex {
        self.n_film
    }

    /// The spectral integrator (illuminant × observer).
    pub fn integrator(&self) -> &SpectralIntegrator {
        &self.integrator
    }

    /// White-balanced linear RGB of a film `thickness_nm` thick seen at `cos_theta`,
    /// exact in f64 (Airy, cell-mean integration): the independent path the table is
    /// tested against and the synthetic photos are made with.
    pub fn rgb_exact(&self, thickness_nm: f64, cos_theta: f64) -> [f64; 3] {
        let film = thinfilm::ThinFilm {
            n_outside: self.n_outside,
            n_film: self.n_film,
            n_substrate: thinfilm::Complex64::new(self.n_outside, 0.0),
            thickness_nm: thickness_nm.max(0.0),
        };
        self.balanced(self.integrator.film_xyz(&film, cos_theta.clamp(0.0, 1.0)))
    }

    /// XYZ (perfect reflector at Y = 1) to white-balanced linear RGB.
    fn balanced(&self, xyz: [f64; 3]) -> [f64; 3] {
        let white = apply(&SRGB_FROM_XYZ, self.integrator.white_xyz());
        let rgb = apply(&SRGB_FROM_XYZ, xyz);
        [0, 1, 2].map(|c| rgb[c] / white[c])
    }

    /// One table row: the colours at `cos_theta` of every thickness sample.
    fn row(&self, cos_theta: f64, thickness_nm: &[f32]) -> Vec<[f32; 3]> {
        let wavelength_nm: Vec<f32> = self
            .integrator
            .wavelengths_nm()
            .iter()
            .map(|&w| w as f32)
            .collect();
        let n_film: Vec<f32> = self
            .integrator
            .wavelengths_nm()
            .iter()
            .map(|&w| self.n_film.n_at(w) as f32)
            .collect();
        let weights: Vec<[f32; 3]> = self
            .integrator
            .weights()
            .iter()
            .map(|w| w.map(|c| c as f32))
            .collect();
        let mut xyz = vec![[0.0f32; 3]; thickness_nm.len()];
        thinfilm::batch::weighted_reflectance_row(
            self.n_outside as f32,
            cos_theta as f32,
            &wavelength_nm,
            &n_film,
            &weights,
            thickness_nm,
            &mut xyz,
        );
        xyz.iter()
            .map(|v| self.balanced(v.map(f64::from)).map(|c| c as f32))
            .collect()
    }
}

/// The model's colours on a grid of thickness (every [`TABLE_STEP_NM`] from 0) × cos θ.
///
/// # Guarantees
/// At least one row and two thickness samples; every value finite.
#[derive(Clone, Debug)]
pub struct ColourTable {
    len: usize,
    cos_lo: f64,
    cos_hi: f64,
    rows: usize,
    rgb: Vec<[f32; 3]>,
}

impl ColourTable {
    /// The table over `[cos_lo, cos_hi]` in `rows` evenly spaced rows (one row when
    /// `rows == 1` or the range is empty, at `cos_hi`).
    ///
    /// # Panics
    /// If the range is not within [0, 1] or `rows` is 0.
    pub fn build(model: &FilmModel, cos_lo: f64, cos_hi: f64, rows: usize) -> ColourTable {
        assert!(rows > 0 && 0.0 <= cos_lo && cos_lo <= cos_hi && cos_hi <= 1.0);
        let rows = if cos_hi - cos_lo < 1e-6 { 1 } else { rows };
        let len = (model.table_max_nm() / TABLE_STEP_NM).round() as usize + 1;
        let thickness: Vec<f32> = (0..len)
            .map(|i| (i as f64 * TABLE_STEP_NM) as f32)
            .collect();
        let mut table = ColourTable {
            len,
            cos_lo,
            cos_hi,
            rows,
            rgb: Vec::new(),
        };
        let row_rgb: Vec<Vec<[f32; 3]>> = (0..rows)
            .into_par_iter()
            .map(|r| model.row(table.row_cos(r), &thickness))
            .collect();
        table.rgb = row_rgb.concat();
        table
    }

    /// Thickness samples per row.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the table is empty (never: see the guarantees).
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Number of cos θ rows.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// cos θ of row `r`.
    pub fn row_cos(&self, r: usize) -> f64 {
        if self.rows == 1 {
            self.cos_hi
        } else {
            self.cos_lo + (self.cos_hi - self.cos_lo) * r as f64 / (self.rows - 1) as f64
        }
    }

    /// Row position of `cos_theta` (fractional, clamped to the table).
    pub fn row_of(&self, cos_theta: f64) -> f64 {
        if self.rows == 1 {
            0.0
        } else {
            let t = (cos_theta - self.cos_lo) / (self.cos_hi - self.cos_lo);
            (t.clamp(0.0, 1.0) * (self.rows - 1) as f64).max(0.0)
        }
    }

    /// The colours of row `r`.
    pub fn row(&self, r: usize) -> &[[f32; 3]] {
        &self.rgb[r * self.len..(r + 1) * self.len]
    }

    /// All rows, row-major.
    pub fn values(&self) -> &[[f32; 3]] {
        &self.rgb
    }

    /// The colour at `thickness_nm` and fractional row `row`, interpolated bilinearly.
    pub fn sample(&self, thickness_nm: f64, row: f64) -> [f64; 3] {
        sample_bilinear(
            &self.rgb,
            self.len,
            self.rows,
            thickness_nm / TABLE_STEP_NM,
            row,
        )
    }
}

/// Bilinear interpolation in a row-major table of `rows` × `len` colours at fractional
/// sample `i` and row `r` (both clamped).
pub(crate) fn sample_bilinear(
    values: &[[f32; 3]],
    len: usize,
    rows: usize,
    i: f64,
    r: f64,
) -> [f64; 3] {
    let i = i.clamp(0.0, (len - 1) as f64);
    let r = r.clamp(0.0, (rows - 1) as f64);
    let (i0, r0) = (i.floor() as usize, r.floor() as usize);
    let (i1, r1) = ((i0 + 1).min(len - 1), (r0 + 1).min(rows - 1));
    let (fi, fr) = (i - i0 as f64, r - r0 as f64);
    let at = |r: usize, i: usize| values[r * len + i].map(f64::from);
    let lerp = |a: [f64; 3], b: [f64; 3], t: f64| [0, 1, 2].map(|c| a[c] + (b[c] - a[c]) * t);
    lerp(
        lerp(at(r0, i0), at(r0, i1), fi),
        lerp(at(r1, i0), at(r1, i1), fi),
        fr,
    )
}
