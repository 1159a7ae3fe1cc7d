//! Spectral integration: reflectance × illuminant × colour-matching functions → XYZ.
//!
//! XYZ = ∫ R(λ) E(λ) x̄(λ) dλ / ∫ E(λ) ȳ(λ) dλ, so a perfect reflector (R ≡ 1)
//! has Y = 1. The reference is the CIE's 1 nm summation over 360–830 nm.
//!
//! A [`SpectralIntegrator`] reduces that to `XYZ = Σₖ wₖ R(λₖ)` over a few
//! sample wavelengths λₖ. Its weights are not point samples of E·x̄: each is the
//! 1 nm sum of E·x̄ against the basis function of sample k of an interpolant of R
//! (see [`Quadrature`]), so the only error left is that of interpolating R
//! between samples. Emission lines enter as exact delta terms at their own
//! wavelength: `wₗ = P·x̄(λₗ)`.

use std::fmt;

use crate::cells::CellWeights;
use crate::cmf::Observer;
use crate::spectrum::Spectrum;

/// The default sample spacing (with [`DEFAULT_QUADRATURE`]): 55 samples, the
/// coarsest whole-nanometre step that keeps a soap film's colour within
/// ΔE2000 ≤ 0.1 of the 1 nm reference for thickness 0–2000 nm and angles 0–75°
/// (D65, CIE 1931; max 0.050 measured, 0.087 at 9 nm); see `tests/colour_accuracy.rs`
/// and docs/physics.md. The grid divides 360–830 nm evenly, so the actual
/// spacing is 470/59 ≈ 7.97 nm.
pub const DEFAULT_STEP_NM: f64 = 8.0;

/// Smallest accepted step: the colour-matching functions are tabulated at 1 nm.
pub const MIN_STEP_NM: f64 = 1.0;
/// Largest accepted step.
pub const MAX_STEP_NM: f64 = 50.0;

/// How reflectance is reconstructed between sample wavelengths.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Quadrature {
    /// Point samples: `wₖ = E(λₖ)·x̄(λₖ)·step`, normalised over the same samples
    /// (the classic "sample every 10 nm" method; shown for comparison).
    PointSample,
    /// R piecewise linear between samples (hat basis functions).
    Linear,
    /// R piecewise cubic through the four nearest samples (Lagrange; the
    /// stencil shifts inwards at the ends of 360–830 nm). A few weights may be
    /// slightly negative; their sum is still exact.
    Cubic,
    /// R piecewise quintic through the six nearest samples (Lagrange).
    Quintic,
}

/// The default reconstruction of [`SpectralIntegrator::new`].
pub const DEFAULT_QUADRATURE: Quadrature = Quadrature::Cubic;

/// Why an integrator could not be built.
#[derive(Clone, Debug, PartialEq)]
pub enum IntegrateError {
    /// The step is not finite or is outside [`MIN_STEP_NM`, `MAX_STEP_NM`].
    BadStep {
        /// The step given.
        step_nm: f64,
    },
    /// The illuminant has no power the observer can see (∫E ȳ dλ = 0).
    NoVisiblePower,
}

impl fmt::Display for IntegrateError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::BadStep { step_nm } => write!(
                f,
                "step_nm {step_nm} must be between {MIN_STEP_NM} and {MAX_STEP_NM} nm"
            ),
            Self::NoVisiblePower => f.write_str(
                "illuminant has no power between 360 and 830 nm where the observer sees",
            ),
        }
    }
}

impl std::error::Error for IntegrateError {}

/// Precomputed wavelengths and XYZ weights for one observer and illuminant.
#[derive(Clone, Debug, PartialEq)]
pub struct SpectralIntegrator {
    wavelength_nm: Vec<f64>,
    weight: Vec<[f64; 3]>,
    white_xyz: [f64; 3],
    cells: Option<CellWeights>,
}

impl SpectralIntegrator {
    /// An integrator with [`DEFAULT_QUADRATURE`] at `step_nm`.
    ///
    /// # Errors
    /// As [`SpectralIntegrator::with_quadrature`].
    pub fn new(
        observer: Observer,
        illuminant: &Spectrum,
        step_nm: f64,
    ) -> Result<SpectralIntegrator, IntegrateError> {
        Self::with_quadrature(observer, illuminant, step_nm, DEFAULT_QUADRATURE)
    }

    /// An integrator with the given quadrature. Interpolating quadratures sample
    /// 360–830 nm evenly at the largest spacing ≤ `step_nm`; point sampling
    /// samples every `step_nm` from 360 nm.
    ///
    /// # Errors
    /// [`IntegrateError::BadStep`] if `step_nm` is not finite or outside
    /// [`MIN_STEP_NM`, `MAX_STEP_NM`]; [`IntegrateError::NoVisiblePower`] if the
    /// illuminant is dark between 360 and 830 nm.
    ///
    /// # Guarantees
    /// Wavelengths are strictly increasing and every weight triple is non-zero;
    /// `white_xyz()[1] == 1` up to rounding.
    pub fn with_quadrature(
        observer: Observer,
        illuminant: &Spectrum,
        step_nm: f64,
        quadrature: Quadrature,
    ) -> Result<SpectralIntegrator, IntegrateError> {
        if !(MIN_STEP_NM..=MAX_STEP_NM).contains(&step_nm) {
            return Err(IntegrateError::BadStep { step_nm });
        }
        let (mut samples, grid) = match quadrature {
            Quadrature::PointSample => (point_weights(observer, illuminant, step_nm), None),
            Quadrature::Linear | Quadrature::Cubic | Quadrature::Quintic => {
                let (samples, spacing_nm) =
                    basis_weights(observer, illuminant, step_nm, quadrature);
                (samples, Some(spacing_nm))
            }
        };
        let nodes = samples.len();
        samples.extend(
            illuminant
                .lines()
                .iter()
                .map(|&(w, p)| (w, observer.cmf(w).map(|c| c * p))),
        );
        let norm = match quadrature {
            Quadrature::PointSample => samples.iter().map(|s| s.1[1]).sum(),
            _ => reference_norm(observer, illuminant),
        };
        if !(norm.is_finite() && norm > 0.0) {
            return Err(IntegrateError::NoVisiblePower);
        }
        let normalised = |s: &(f64, [f64; 3])| (s.0, s.1.map(|c| c / norm));
        let cells = grid.map(|spacing_nm| {
            let node_weights: Vec<[f64; 3]> =
                samples[..nodes].iter().map(|s| normalised(s).1).collect();
            let lines = samples[nodes..].iter().map(normalised).collect();
            CellWeights::from_grid(Observer::MIN_NM, spacing_nm, &node_weights, lines)
        });
        Ok(Self::from_samples(samples, norm, cells))
    }

    /// Sorts, merges coincident wavelengths, drops zero weights and normalises.
    fn from_samples(
        mut samples: Vec<(f64, [f64; 3])>,
        norm: f64,
        cells: Option<CellWeights>,
    ) -> SpectralIntegrator {
        samples.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut merged: Vec<(f64, [f64; 3])> = Vec::with_capacity(samples.len());
        for (w, v) in samples {
            match merged.last_mut() {
                Some((last, acc)) if *last == w => (0..3).for_each(|c| acc[c] += v[c]),
                _ => merged.push((w, v)),
            }
        }
        let (wavelength_nm, weight): (Vec<f64>, Vec<[f64; 3]>) = merged
            .into_iter()
            .filter(|(_, v)| v.iter().any(|&c| c != 0.0))
            .map(|(w, v)| (w, v.map(|c| c / norm)))
            .unzip();
        let white_xyz = weight.iter().fold([0.0; 3], |acc, v| {
            [acc[0] + v[0], acc[1] + v[1], acc[2] + v[2]]
        });
        SpectralIntegrator {
            wavelength_nm,
            weight,
            white_xyz,
            cells,
        }
    }

    /// The wavelengths at which reflectance is sampled, strictly increasing;
    /// emission lines appear at their exact wavelength.
    pub fn wavelengths_nm(&self) -> &[f64] {
        &self.wavelength_nm
    }

    /// XYZ weights, one per wavelength: `XYZ = Σₖ weights[k]·R(λₖ)`.
    pub fn weights(&self) -> &[[f64; 3]] {
        &self.weight
    }

    /// XYZ of a surface with spectral reflectance `reflectance(λ_nm)`.
    pub fn xyz(&self, mut reflectance: impl FnMut(f64) -> f64) -> [f64; 3] {
        let mut xyz = [0.0; 3];
        for (&w, k) in self.wavelength_nm.iter().zip(&self.weight) {
            let r = reflectance(w);
            xyz[0] += k[0] * r;
            xyz[1] += k[1] * r;
            xyz[2] += k[2] * r;
        }
        xyz
    }

    /// XYZ from reflectance already sampled at [`SpectralIntegrator::wavelengths_nm`].
    ///
    /// # Panics
    /// If `reflectance.len()` differs from the number of wavelengths.
    pub fn xyz_from_samples(&self, reflectance: &[f64]) -> [f64; 3] {
        assert_eq!(
            reflectance.len(),
            self.weight.len(),
            "one reflectance sample per integrator wavelength"
        );
        let mut i = reflectance.iter();
        self.xyz(|_| *i.next().unwrap_or(&0.0))
    }

    /// XYZ of a perfect reflector (R ≡ 1); its Y is 1.
    pub fn white_xyz(&self) -> [f64; 3] {
        self.white_xyz
    }

    /// The same weights over cells around the grid's nodes, for films whose spectral lines
    /// are too narrow to sample ([`crate::cells`]); `None` for point sampling.
    pub fn cells(&self) -> Option<&CellWeights> {
        self.cells.as_ref()
    }
}

/// ∫E ȳ dλ: the CIE 1 nm summation of the continuous part plus the lines'
/// delta terms.
fn reference_norm(observer: Observer, illuminant: &Spectrum) -> f64 {
    let continuous: f64 = observer
        .table_1nm()
        .iter()
        .enumerate()
        .map(|(j, c)| illuminant.value_at(Observer::MIN_NM + j as f64) * c[1])
        .sum();
    let lines: f64 = illuminant
        .lines()
        .iter()
        .map(|&(w, p)| p * observer.cmf(w)[1])
        .sum();
    continuous + lines
}

/// Point samples `E(λₖ) x̄(λₖ) step` on the grid 360, 360 + step, … ≤ 830 nm.
fn point_weights(observer: Observer, illuminant: &Spectrum, step_nm: f64) -> Vec<(f64, [f64; 3])> {
    let count = ((Observer::MAX_NM - Observer::MIN_NM) / step_nm + 1e-9).floor() as usize + 1;
    (0..count)
        .map(|k| {
            let w = Observer::MIN_NM + k as f64 * step_nm;
            let e = illuminant.value_at(w) * step_nm;
            (w, observer.cmf(w).map(|c| c * e))
        })
        .collect()
}

/// Weights of an interpolating basis: each 1 nm term E(λⱼ)x̄(λⱼ) of the CIE sum
/// is shared among the samples whose basis functions are non-zero at λⱼ.
///
/// The samples divide 360–830 nm evenly, at the largest spacing ≤ `step_nm`, so
/// none lies outside the range where the CMFs (and validated dispersion models)
/// are defined; near the ends the stencil shifts inwards instead of padding.
fn basis_weights(
    observer: Observer,
    illuminant: &Spectrum,
    step_nm: f64,
    quadrature: Quadrature,
) -> (Vec<(f64, [f64; 3])>, f64) {
    let span = Observer::MAX_NM - Observer::MIN_NM;
    let intervals = ((span / step_nm - 1e-9).ceil() as usize).max(1);
    let spacing_nm = span / intervals as f64;
    let points = quadrature.points().min(intervals + 1);
    let mut weight = vec![[0.0; 3]; intervals + 1];
    for (j, c) in observer.table_1nm().iter().enumerate() {
        let e = illuminant.value_at(Observer::MIN_NM + j as f64);
        if e == 0.0 {
            continue;
        }
        let t = j as f64 / spacing_nm;
        let k = (t.floor() as usize).min(intervals - 1);
        // Centre the stencil on interval k, shifted to stay inside the grid.
        let first = (k + 1)
            .saturating_sub(points / 2)
            .min(intervals + 1 - points);
        for (node, b) in lagrange_basis(first, points, t) {
            (0..3).for_each(|i| weight[node][i] += b * e * c[i]);
        }
    }
    let samples = weight
        .into_iter()
        .enumerate()
        .map(|(k, v)| (Observer::MIN_NM + span * k as f64 / intervals as f64, v))
        .collect();
    (samples, spacing_nm)
}

impl Quadrature {
    /// How many samples the interpolant of R uses on each interval.
    fn points(self) -> usize {
        match self {
            Quadrature::PointSample => 1,
            Quadrature::Linear => 2,
            Quadrature::Cubic => 4,
            Quadrature::Quintic => 6,
        }
    }
}

/// The Lagrange basis polynomials of the nodes `first..first + points` (in units
/// of the spacing) evaluated at `t`, as `(node, value)`.
fn lagrange_basis(first: usize, points: usize, t: f64) -> impl Iterator<Item = (usize, f64)> {
    let nodes = first..first + points;
    nodes.clone().map(move |i| {
        let value = nodes
            .clone()
            .filter(|&j| j != i)
            .map(|j| (t - j as f64) / (i as f64 - j as f64))
            .product();
        (i, value)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::illuminant::Illuminant;

    #[test]
    fn step_outside_range_is_rejected() {
        let d65 = Illuminant::D65.spectrum();
        for bad in [0.0, 0.5, 51.0, f64::NAN, f64::INFINITY, -5.0] {
            let e = SpectralIntegrator::new(Observer::Cie1931, &d65, bad).unwrap_err();
            assert!(e.to_string().contains(&format!("{bad}")), "{e}");
        }
    }

    #[test]
    fn dark_illuminant_is_rejected() {
        let uv = Spectrum::try_from_samples(vec![300.0, 350.0], vec![1.0, 1.0]).unwrap();
        assert_eq!(
            SpectralIntegrator::new(Observer::Cie1931, &uv, 5.0),
            Err(IntegrateError::NoVisiblePower)
        );
    }

    #[test]
    fn lagrange_bases_are_partitions_of_unity_and_reproduce_polynomials() {
        for points in [2, 4, 6] {
            for i in 0..=20 {
                let t = 3.0 + f64::from(i) / 10.0;
                let b: Vec<(usize, f64)> = lagrange_basis(2, points, t).collect();
                let sum: f64 = b.iter().map(|b| b.1).sum();
                assert!(
                    (sum - 1.0).abs() < 1e-13,
                    "{points} points, t = {t}: sum {sum}"
                );
                let degree = points as i32 - 1;
                let p: f64 = b.iter().map(|&(k, v)| v * (k as f64).powi(degree)).sum();
                let diff = (p - t.powi(degree)).abs();
                assert!(diff < 1e-9, "{points} points, t = {t}: |diff| {diff:e}");
            }
        }
    }

    #[test]
    fn samples_stay_inside_the_cmf_range() {
        let d65 = Illuminant::D65.spectrum();
        for q in [Quadrature::Linear, Quadrature::Cubic, Quadrature::Quintic] {
            for step in [1.0, 3.7, 8.0, 10.0, 50.0] {
                let i =
                    SpectralIntegrator::with_quadrature(Observer::Cie1931, &d65, step, q).unwrap();
                let w = i.wavelengths_nm();
                assert!(w[0] >= Observer::MIN_NM && w[w.len() - 1] <= Observer::MAX_NM);
                assert!(
                    w.windows(2)
                        .all(|p| p[1] - p[0] <= step + 1e-9 && p[1] > p[0])
                );
                assert!((i.white_xyz()[1] - 1.0).abs() < 1e-14, "{q:?} {step}");
            }
        }
    }
}
