//! Fitting one layer's thickness to a measured reflectance spectrum.
//!
//! The model is any stack with one unknown thickness (`model(d)` builds it: a free film,
//! or a film on a substrate) plus a constant offset `c` (stray light, a dark level):
//! `R_model(λ; d) + c`. For each trial `d` the best `c` is the mean residual, so the
//! search is over `d` alone:
//!
//! 1. **Global search over the fringe order.** `χ²(d)` has a local minimum every quarter
//!    fringe; its minima are at least `λ_min / (4 n_max)` apart. `d` is scanned from
//!    `d_min` to `d_max` in steps of an eighth of that, so no minimum is stepped over,
//!    and the best [`CANDIDATES`] local minima of the scan are refined.
//! 2. **Refinement.** Golden-section search on each candidate's bracket, then the best.
//! 3. **Confidence interval.** With `s² = χ²/(N − 2)` (the residual variance) and the
//!    Jacobian `J = [∂R/∂d, 1]`, the statistical standard error is
//!    `σ_d = s √((JᵀJ)⁻¹)_dd`; a stated wavelength-calibration uncertainty `δλ` adds the
//!    systematic half-width `|d(λ + δλ) − d(λ − δλ)| / 2` (the fit redone on shifted
//!    wavelengths). The interval is `d ± (z σ_d + systematic)` with `z = 1.96` (95 %).
//!
//! The residual (RMS), the offset and the runner-up minimum's thickness and `χ²` are
//! reported, so an ambiguous fringe order shows as a runner-up with nearly the same `χ²`.
//!
//! [`fit_thickness_and_index`] also fits the layer's Cauchy index (see [`cauchy`]).

use crate::fresnel::{Num, OpticsError};
use crate::incidence::Incidence;
use crate::tmm::Stack;

mod cauchy;

pub use cauchy::{A_GRID, CauchyRange, Estimate, IndexFit, fit_thickness_and_index};

/// Local minima of the scan refined by golden-section search.
pub const CANDIDATES: usize = 4;
/// The most model reflectances the global scan may compute (scan points × wavelengths):
/// a thickness range far wider than the spectrum's fringes, or a huge index, would
/// otherwise allocate and compute without bound.
pub const MAX_SCAN_EVALUATIONS: f64 = 1e8;
/// The normal quantile of a two-sided 95 % interval.
pub const Z_95: f64 = 1.959_963_984_540_054;

/// A measured spectrum and what is known about it.
#[derive(Clone, Debug)]
pub struct Measurement<'a> {
    /// Vacuum wavelengths in nm.
    pub wavelength_nm: &'a [f64],
    /// Measured reflectance at each wavelength (unpolarised).
    pub reflectance: &'a [f64],
    /// The incidence direction.
    pub incidence: Incidence,
    /// Uncertainty of the wavelength calibration in nm (0 if none is known).
    pub wavelength_uncertainty_nm: f64,
}

/// The thickness range searched and the largest index of the model (for the scan step).
#[derive(Clone, Copy, Debug)]
pub struct Search {
    /// Thinnest thickness considered, nm.
    pub min_nm: f64,
    /// Thickest thickness considered, nm.
    pub max_nm: f64,
    /// The largest real index of the unknown layer over the spectrum.
    pub n_max: f64,
}

/// A fitted thickness.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fit {
    /// The best thickness, nm.
    pub thickness_nm: f64,
    /// Lower end of the 95 % interval, nm.
    pub low_nm: f64,
    /// Upper end of the 95 % interval, nm.
    pub high_nm: f64,
    /// The statistical standard error, nm.
    pub sigma_nm: f64,
    /// The systematic half-width from the wavelength uncertainty, nm.
    pub systematic_nm: f64,
    /// The fitted offset added to the model.
    pub offset: f64,
    /// Root-mean-square residual.
    pub rms_residual: f64,
    /// The runner-up local minimum's thickness, nm (NaN if there was none).
    pub runner_up_nm: f64,
    /// Its root-mean-square residual.
    pub runner_up_rms: f64,
}

impl Fit {
    /// The names of [`Fit::values`], in order (the field names).
    pub const FIELDS: [&'static str; 9] = [
        "thickness_nm",
        "low_nm",
        "high_nm",
        "sigma_nm",
        "systematic_nm",
        "offset",
        "rms_residual",
        "runner_up_nm",
        "runner_up_rms",
    ];

    /// Every number of the fit, in the order of [`Fit::FIELDS`].
    pub fn values(&self) -> [f64; 9] {
        [
            self.thickness_nm,
            self.low_nm,
            self.high_nm,
            self.sigma_nm,
            self.systematic_nm,
            self.offset,
            self.rms_residual,
            self.runner_up_nm,
            self.runner_up_rms,
        ]
    }
}

/// Fits the thickness `d` of `model(d)` to `measured`.
///
/// # Errors
/// Unequal or too short (< 3) slices, a non-finite value (named with its index), a bad
/// search range or uncertainty, or what the model returns.
pub fn fit_thickness(
    model: impl Fn(f64) -> Result<Stack, OpticsError>,
    measured: &Measurement<'_>,
    search: Search,
) -> Result<Fit, OpticsError> {
    validate(measured, search)?;
    let curve = Curve {
        model: &model,
        incidence: measured.incidence,
        reflectance: measured.reflectance,
    };
    let (best, runner_up) = curve.global(measured.wavelength_nm, search)?;
    let (d, sse) = best;
    let n = measured.wavelength_nm.len() as f64;
    let (_, offset) = curve.model_and_offset(measured.wavelength_nm, d)?;
    // Jacobian column ∂R/∂d by central differences (the offset's column is all ones).
    let h = (d.abs() * 1e-6).max(1e-4);
    let (up, _) = curve.model_and_offset(measured.wavelength_nm, d + h)?;
    let (down, _) = curve.model_and_offset(measured.wavelength_nm, (d - h).max(0.0))?;
    let step = d + h - (d - h).max(0.0);
    let dr: Vec<f64> = up.iter().zip(&down).map(|(a, b)| (a - b) / step).collect();
    let mean_dr = dr.iter().sum::<f64>() / n;
    // (JᵀJ)⁻¹_dd for J = [dr, 1] is 1 / Σ(dr − mean)².
    let spread: f64 = dr.iter().map(|g| (g - mean_dr).powi(2)).sum();
    let s2 = sse / (n - 2.0);
    let sigma_nm = if spread > 0.0 {
        (s2 / spread).sqrt()
    } else {
        f64::INFINITY
    };
    let systematic_nm = if measured.wavelength_uncertainty_nm > 0.0 {
        let shifted = |delta: f64| -> Result<f64, OpticsError> {
            let wl: Vec<f64> = measured.wavelength_nm.iter().map(|w| w + delta).collect();
            Ok(curve
                .refine(&wl, d, search, 4.0 * quarter_step(&wl, search))?
                .0)
        };
        let delta = measured.wavelength_uncertainty_nm;
        (shifted(delta)? - shifted(-delta)?).abs() / 2.0
    } else {
        0.0
    };
    let half = Z_95 * sigma_nm + systematic_nm;
    Ok(Fit {
        thickness_nm: d,
        low_nm: (d - half).max(0.0),
        high_nm: d + half,
        sigma_nm,
        systematic_nm,
        offset,
        rms_residual: (sse / n).sqrt(),
        runner_up_nm: runner_up.map_or(f64::NAN, |(d, _)| d),
        runner_up_rms: runner_up.map_or(f64::NAN, |(_, sse)| (sse / n).sqrt()),
    })
}

fn validate(measured: &Measurement<'_>, search: Search) -> Result<(), OpticsError> {
    let len = measured.wavelength_nm.len();
    if measured.reflectance.len() != len {
        return Err(OpticsError::Length {
            what: "reflectance",
            len: measured.reflectance.len(),
            expected: len,
        });
    }
    if len < 3 {
        return Err(OpticsError::Length {
            what: "wavelength_nm",
            len,
            expected: 3,
        });
    }
    for (what, values) in [
        ("wavelength_nm", measured.wavelength_nm),
        ("reflectance", measured.reflectance),
    ] {
        if let Some((index, &value)) = values.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(OpticsError::NotFinite { what, index, value });
        }
    }
    let bad = |reason: String| Err(OpticsError::Fit { reason });
    let u = measured.wavelength_uncertainty_nm;
    if !(u.is_finite() && u >= 0.0) {
        return bad(format!(
            "wavelength uncertainty {} nm is not finite and >= 0",
            Num(u)
        ));
    }
    let Search {
        min_nm,
        max_nm,
        n_max,
    } = search;
    if !(min_nm.is_finite() && max_nm.is_finite() && 0.0 <= min_nm && min_nm < max_nm) {
        return bad(format!(
            "thickness range [{}, {}] nm is not 0 <= min < max",
            Num(min_nm),
            Num(max_nm)
        ));
    }
    if !(n_max.is_finite() && n_max > 0.0) {
        return bad(format!("n_max {} is not finite and > 0", Num(n_max)));
    }
    check_scan_work(measured.wavelength_nm, search)
}

/// Refuses a scan of more than [`MAX_SCAN_EVALUATIONS`] model reflectances.
fn check_scan_work(wavelength_nm: &[f64], search: Search) -> Result<(), OpticsError> {
    let points = (search.max_nm - search.min_nm) / quarter_step(wavelength_nm, search);
    let evaluations = points * wavelength_nm.len() as f64;
    if evaluations <= MAX_SCAN_EVALUATIONS {
        return Ok(());
    }
    Err(OpticsError::Fit {
        reason: format!(
            "thickness range [{}, {}] nm scanned at {} points (a step of {} nm for the \
             shortest wavelength and index {}) over {} wavelengths needs {} reflectance \
             evaluations, more than {}: narrow the range",
            Num(search.min_nm),
            Num(search.max_nm),
            Num(points.ceil()),
            Num(quarter_step(wavelength_nm, search)),
            Num(search.n_max),
            wavelength_nm.len(),
            Num(evaluations.ceil()),
            Num(MAX_SCAN_EVALUATIONS)
        ),
    })
}

/// The scan step: an eighth of the closest spacing of `χ²`'s minima, `λ_min / (4 n_max)`.
fn quarter_step(wavelength_nm: &[f64], search: Search) -> f64 {
    let lambda_min = wavelength_nm.iter().fold(f64::INFINITY, |m, &w| m.min(w));
    lambda_min / (4.0 * search.n_max) / 8.0
}

struct Curve<'a, F> {
    model: &'a F,
    incidence: Incidence,
    reflectance: &'a [f64],
}

impl<F: Fn(f64) -> Result<Stack, OpticsError>> Curve<'_, F> {
    /// The model's spectrum at `d` and the best offset.
    fn model_and_offset(
        &self,
        wavelength_nm: &[f64],
        d: f64,
    ) -> Result<(Vec<f64>, f64), OpticsError> {
        let stack = (self.model)(d)?;
        let r = wavelength_nm
            .iter()
            .map(|&w| Ok(stack.try_response_at(w, self.incidence)?.r()))
            .collect::<Result<Vec<f64>, OpticsError>>()?;
        let offset = self
            .reflectance
            .iter()
            .zip(&r)
            .map(|(m, r)| m - r)
            .sum::<f64>()
            / r.len() as f64;
        Ok((r, offset))
    }

    /// The sum of squared residuals at `d`, the offset fitted.
    fn sse(&self, wavelength_nm: &[f64], d: f64) -> Result<f64, OpticsError> {
        let (r, offset) = self.model_and_offset(wavelength_nm, d)?;
        Ok(self
            .reflectance
            .iter()
            .zip(&r)
            .map(|(m, r)| (m - r - offset).powi(2))
            .sum())
    }

    /// The best and the runner-up refined minima over the search range.
    #[allow(clippy::type_complexity)]
    fn global(
        &self,
        wavelength_nm: &[f64],
        search: Search,
    ) -> Result<((f64, f64), Option<(f64, f64)>), OpticsError> {
        let step = quarter_step(wavelength_nm, search);
        let count = ((search.max_nm - search.min_nm) / step).ceil().max(2.0) as usize;
        let ds: Vec<f64> = (0..=count)
            .map(|k| search.min_nm + (search.max_nm - search.min_nm) * k as f64 / count as f64)
            .collect();
        let values = ds
            .iter()
            .map(|&d| self.sse(wavelength_nm, d))
            .collect::<Result<Vec<_>, _>>()?;
        // Local minima of the scan (the ends count when they are lowest).
        let mut minima: Vec<usize> = (0..ds.len())
            .filter(|&k| {
                (k == 0 || values[k] <= values[k - 1])
                    && (k + 1 == ds.len() || values[k] <= values[k + 1])
            })
            .collect();
        minima.sort_by(|&a, &b| values[a].total_cmp(&values[b]));
        minima.truncate(CANDIDATES);
        let mut refined = minima
            .iter()
            .map(|&k| self.refine(wavelength_nm, ds[k], search, step))
            .collect::<Result<Vec<_>, _>>()?;
        refined.sort_by(|a, b| a.1.total_cmp(&b.1));
        // Two candidates that refine to one minimum are one.
        let best = refined[0];
        let runner_up = refined
            .iter()
            .copied()
            .find(|&(d, _)| (d - best.0).abs() > step);
        Ok((best, runner_up))
    }

    /// Golden-section search for the minimum in `[d − bracket, d + bracket]` ∩ range.
    fn refine(
        &self,
        wavelength_nm: &[f64],
        d: f64,
        search: Search,
        bracket: f64,
    ) -> Result<(f64, f64), OpticsError> {
        let inv_phi = (5f64.sqrt() - 1.0) / 2.0;
        let (mut a, mut b) = (
            (d - bracket).max(search.min_nm),
            (d + bracket).min(search.max_nm),
        );
        let mut c = b - inv_phi * (b - a);
        let mut e = a + inv_phi * (b - a);
        let (mut fc, mut fe) = (self.sse(wavelength_nm, c)?, self.sse(wavelength_nm, e)?);
        while b - a > 1e-7 * (1.0 + d.abs()) {
            if fc < fe {
                (b, e, fe) = (e, c, fc);
                c = b - inv_phi * (b - a);
                fc = self.sse(wavelength_nm, c)?;
            } else {
                (a, c, fc) = (c, e, fe);
                e = a + inv_phi * (b - a);
                fe = self.sse(wavelength_nm, e)?;
            }
        }
        let d = 0.5 * (a + b);
        Ok((d, self.sse(wavelength_nm, d)?))
    }
}
