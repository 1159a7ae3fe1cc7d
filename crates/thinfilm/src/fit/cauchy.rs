//! Fitting one layer's thickness together with its Cauchy index `n(λ) = a + b/λ²`.
//!
//! Fringe positions fix the optical thickness `n(λ) d` and its change across the spectrum
//! (the dispersion `b`); fringe contrast fixes `n` itself (the interfaces' reflectance).
//! The offset `c` is eliminated as in [`super::fit_thickness`].
//!
//! 1. **Global.** For [`A_GRID`] values of `a` across its range (with `b` at the middle of
//!    its range) the thickness is searched globally as [`super::fit_thickness`] does;
//!    the best [`super::CANDIDATES`] `(d, a)` pairs over all of them are kept, so an
//!    index guessed wrong cannot lock in a wrong fringe order.
//! 2. **Local.** Levenberg–Marquardt over `(d, a, b)` from each candidate, within the
//!    given ranges; the lowest `χ²` wins.
//! 3. **Intervals.** The covariance `s² (JᵀJ)⁻¹` of the Jacobian `J = [∂R/∂d, ∂R/∂a,
//!    ∂R/∂b, 1]` gives each standard error (`s² = χ²/(N − 4)`); a wavelength-calibration
//!    uncertainty `δλ` adds half the change of each parameter when the fit is redone on
//!    wavelengths shifted by `±δλ`. Each interval is `x ± (1.96 σ + systematic)`. A film
//!    too thin to show a fringe leaves `d` and `a` correlated, and the intervals say so.

use super::{Curve, Measurement, Search, Z_95, validate};
use crate::dispersion::RefractiveIndex;
use crate::fresnel::{Num, OpticsError};
use crate::tmm::Stack;

/// Values of `a` at which the global thickness search runs.
pub const A_GRID: usize = 3;
/// Levenberg–Marquardt iterations at most, per start.
const MAX_ITERATIONS: usize = 200;

/// The ranges searched for the unknown layer's `n(λ) = a + b_nm2/λ²`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CauchyRange {
    /// `[lowest, highest]` `a`.
    pub a: [f64; 2],
    /// `[lowest, highest]` `b` in nm².
    pub b_nm2: [f64; 2],
}

/// One fitted parameter with its 95 % interval.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate {
    /// The best value.
    pub value: f64,
    /// Lower end of the 95 % interval.
    pub low: f64,
    /// Upper end of the 95 % interval.
    pub high: f64,
    /// The statistical standard error.
    pub sigma: f64,
    /// The systematic half-width from the wavelength uncertainty.
    pub systematic: f64,
}

impl Estimate {
    fn new(value: f64, sigma: f64, systematic: f64) -> Estimate {
        let half = Z_95 * sigma + systematic;
        Estimate {
            value,
            low: value - half,
            high: value + half,
            sigma,
            systematic,
        }
    }
}

/// A thickness fitted together with its layer's Cauchy index.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IndexFit {
    /// The layer's thickness, nm.
    pub thickness_nm: Estimate,
    /// Cauchy's `a`.
    pub a: Estimate,
    /// Cauchy's `b`, nm².
    pub b_nm2: Estimate,
    /// The fitted offset added to the model.
    pub offset: f64,
    /// Root-mean-square residual.
    pub rms_residual: f64,
}

impl IndexFit {
    /// The names of [`IndexFit::values`], in order.
    pub const FIELDS: [&'static str; 17] = [
        "thickness_nm",
        "low_nm",
        "high_nm",
        "sigma_nm",
        "systematic_nm",
        "a",
        "a_low",
        "a_high",
        "a_sigma",
        "a_systematic",
        "b_nm2",
        "b_low",
        "b_high",
        "b_sigma",
        "b_systematic",
        "offset",
        "rms_residual",
    ];

    /// Every number of the fit, in the order of [`IndexFit::FIELDS`]: each estimate's
    /// value, low, high, sigma and systematic, then the offset and the residual.
    pub fn values(&self) -> [f64; 17] {
        let mut out = [0.0; 17];
        for (k, e) in [self.thickness_nm, self.a, self.b_nm2].iter().enumerate() {
            out[5 * k..5 * k + 5].copy_from_slice(&[e.value, e.low, e.high, e.sigma, e.systematic]);
        }
        (out[15], out[16]) = (self.offset, self.rms_residual);
        out
    }
}

/// Fits the thickness `d` and the Cauchy index of the layer that `model(d, index)` builds
/// to `measured`, with `d` in `[min_nm, max_nm]` and the index within `range`.
///
/// # Errors
/// What [`super::fit_thickness`] refuses, a bad `range` (named), or what the model
/// returns.
pub fn fit_thickness_and_index(
    model: impl Fn(f64, RefractiveIndex) -> Result<Stack, OpticsError>,
    measured: &Measurement<'_>,
    min_nm: f64,
    max_nm: f64,
    range: CauchyRange,
) -> Result<IndexFit, OpticsError> {
    check_range(range)?;
    let lambda_min = measured
        .wavelength_nm
        .iter()
        .fold(f64::INFINITY, |m, &w| m.min(w));
    let search = Search {
        min_nm,
        max_nm,
        n_max: range.a[1] + range.b_nm2[1].max(0.0) / (lambda_min * lambda_min),
    };
    validate(measured, search)?;
    let bounds = Bounds {
        low: [min_nm, range.a[0], range.b_nm2[0]],
        high: [max_nm, range.a[1], range.b_nm2[1]],
    };
    let problem = Problem {
        model: &model,
        measured,
        bounds,
    };
    let starts = problem.global_starts(search)?;
    let wl = measured.wavelength_nm;
    let mut best: Option<([f64; 3], f64)> = None;
    for start in starts {
        let local = problem.levenberg_marquardt(wl, start)?;
        if best.is_none_or(|(_, sse)| local.1 < sse) {
            best = Some(local);
        }
    }
    let (p, sse) = best.expect("the global search yields at least one start");
    problem.finish(p, sse)
}

fn check_range(range: CauchyRange) -> Result<(), OpticsError> {
    let [a_lo, a_hi] = range.a;
    let [b_lo, b_hi] = range.b_nm2;
    let ok = a_lo.is_finite() && a_hi.is_finite() && 0.0 < a_lo && a_lo <= a_hi;
    if !ok {
        return Err(OpticsError::Fit {
            reason: format!(
                "Cauchy a range [{}, {}] is not 0 < low <= high",
                Num(a_lo),
                Num(a_hi)
            ),
        });
    }
    if !(b_lo.is_finite() && b_hi.is_finite() && b_lo <= b_hi) {
        return Err(OpticsError::Fit {
            reason: format!(
                "Cauchy b range [{}, {}] nm² is not finite with low <= high",
                Num(b_lo),
                Num(b_hi)
            ),
        });
    }
    Ok(())
}

/// The box the parameters `(d, a, b)` stay in.
#[derive(Clone, Copy)]
struct Bounds {
    low: [f64; 3],
    high: [f64; 3],
}

impl Bounds {
    fn clamp(&self, p: [f64; 3]) -> [f64; 3] {
        std::array::from_fn(|k| p[k].clamp(self.low[k], self.high[k]))
    }
}

struct Problem<'a, F> {
    model: &'a F,
    measured: &'a Measurement<'a>,
    bounds: Bounds,
}

impl<F: Fn(f64, RefractiveIndex) -> Result<Stack, OpticsError>> Problem<'_, F> {
    /// The index `a + b/λ²` over the measured wavelengths (widened for the shifted fits).
    fn index(&self, wl: &[f64], a: f64, b_nm2: f64) -> Result<RefractiveIndex, OpticsError> {
        let (lo, hi) = wl.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &w| {
            (lo.min(w), hi.max(w))
        });
        RefractiveIndex::cauchy_over(a, b_nm2, 0.0, [lo, hi])
    }

    /// The residuals `R_model + c − R_measured` at `p`, with the best offset `c`, and `c`.
    fn residuals(&self, wl: &[f64], p: [f64; 3]) -> Result<(Vec<f64>, f64), OpticsError> {
        let index = self.index(wl, p[1], p[2])?;
        let curve = Curve {
            model: &|d: f64| (self.model)(d, index),
            incidence: self.measured.incidence,
            reflectance: self.measured.reflectance,
        };
        let (r, offset) = curve.model_and_offset(wl, p[0])?;
        let residuals = (r.iter().zip(self.measured.reflectance))
            .map(|(r, m)| r + offset - m)
            .collect();
        Ok((residuals, offset))
    }

    fn sse(&self, wl: &[f64], p: [f64; 3]) -> Result<f64, OpticsError> {
        Ok(self.residuals(wl, p)?.0.iter().map(|r| r * r).sum())
    }

    /// The best `(d, a, b)` starts of the global thickness search over the `a` grid.
    fn global_starts(&self, search: Search) -> Result<Vec<[f64; 3]>, OpticsError> {
        let wl = self.measured.wavelength_nm;
        let b = 0.5 * (self.bounds.low[2] + self.bounds.high[2]);
        let [a_lo, a_hi] = [self.bounds.low[1], self.bounds.high[1]];
        let grid = if a_lo == a_hi { 1 } else { A_GRID };
        let mut found: Vec<([f64; 3], f64)> = Vec::new();
        for k in 0..grid {
            let a = a_lo + (a_hi - a_lo) * k as f64 / (grid - 1).max(1) as f64;
            let index = self.index(wl, a, b)?;
            let curve = Curve {
                model: &|d: f64| (self.model)(d, index),
                incidence: self.measured.incidence,
                reflectance: self.measured.reflectance,
            };
            let (best, runner_up) = curve.global(wl, search)?;
            found.extend(
                [Some(best), runner_up]
                    .into_iter()
                    .flatten()
                    .map(|(d, sse)| ([d, a, b], sse)),
            );
        }
        found.sort_by(|x, y| x.1.total_cmp(&y.1));
        found.truncate(super::CANDIDATES);
        Ok(found.into_iter().map(|(p, _)| p).collect())
    }

    /// The Jacobian of the residuals by central differences within the bounds (one-sided
    /// at a bound; a parameter pinned by its bounds gets a zero column), each column
    /// centred (which eliminates the offset's column).
    fn jacobian(&self, wl: &[f64], p: [f64; 3]) -> Result<[Vec<f64>; 3], OpticsError> {
        let steps = [
            (p[0].abs() * 1e-6).max(1e-4),
            1e-6,
            (p[2].abs() * 1e-6).max(1e-2),
        ];
        let mut columns: [Vec<f64>; 3] = Default::default();
        for (k, column) in columns.iter_mut().enumerate() {
            let (mut up, mut down) = (p, p);
            up[k] = (p[k] + steps[k]).min(self.bounds.high[k]);
            down[k] = (p[k] - steps[k]).max(self.bounds.low[k]);
            let width = up[k] - down[k];
            if width <= 0.0 {
                *column = vec![0.0; wl.len()];
                continue;
            }
            let (r_up, _) = self.residuals(wl, up)?;
            let (r_down, _) = self.residuals(wl, down)?;
            *column = (r_up.iter().zip(&r_down))
                .map(|(u, d)| (u - d) / width)
                .collect();
            let mean = column.iter().sum::<f64>() / column.len() as f64;
            column.iter_mut().for_each(|x| *x -= mean);
        }
        Ok(columns)
    }

    /// Levenberg–Marquardt from `start`, kept within the bounds: `(p, χ²)`.
    fn levenberg_marquardt(
        &self,
        wl: &[f64],
        start: [f64; 3],
    ) -> Result<([f64; 3], f64), OpticsError> {
        let mut p = self.bounds.clamp(start);
        let mut sse = self.sse(wl, p)?;
        let mut damping = 1e-3;
        for _ in 0..MAX_ITERATIONS {
            let (residuals, _) = self.residuals(wl, p)?;
            let jac = self.jacobian(wl, p)?;
            let (normal, gradient) = normal_equations(&jac, &residuals);
            let mut improved = false;
            while damping < 1e12 {
                let mut damped = normal;
                (0..3).for_each(|k| damped[k][k] *= 1.0 + damping);
                let Some(step) = solve3(damped, gradient.map(|g| -g)) else {
                    damping *= 10.0;
                    continue;
                };
                let trial = self.bounds.clamp(std::array::from_fn(|k| p[k] + step[k]));
                let trial_sse = self.sse(wl, trial)?;
                if trial_sse < sse {
                    let gain = (sse - trial_sse) / sse.max(f64::MIN_POSITIVE);
                    (p, sse, improved) = (trial, trial_sse, true);
                    damping = (damping / 3.0).max(1e-12);
                    if gain < 1e-13 {
                        return Ok((p, sse));
                    }
                    break;
                }
                damping *= 4.0;
            }
            if !improved {
                break;
            }
        }
        Ok((p, sse))
    }

    /// The intervals and the offset at the best `p`.
    fn finish(&self, p: [f64; 3], sse: f64) -> Result<IndexFit, OpticsError> {
        let wl = self.measured.wavelength_nm;
        let n = wl.len() as f64;
        let jac = self.jacobian(wl, p)?;
        let (normal, _) = normal_equations(&jac, &vec![0.0; wl.len()]);
        let s2 = sse / (n - 4.0).max(1.0);
        let pinned: [bool; 3] = std::array::from_fn(|k| jac[k].iter().all(|&x| x == 0.0));
        let sigma: [f64; 3] = std::array::from_fn(|k| {
            if pinned[k] {
                return 0.0;
            }
            let mut unit = [0.0; 3];
            unit[k] = 1.0;
            solve3(normal, unit).map_or(f64::INFINITY, |column| (s2 * column[k]).max(0.0).sqrt())
        });
        let systematic = self.systematic(p)?;
        let (_, offset) = self.residuals(wl, p)?;
        Ok(IndexFit {
            thickness_nm: Estimate::new(p[0], sigma[0], systematic[0]),
            a: Estimate::new(p[1], sigma[1], systematic[1]),
            b_nm2: Estimate::new(p[2], sigma[2], systematic[2]),
            offset,
            rms_residual: (sse / n).sqrt(),
        })
    }

    /// Half the change of each parameter when the wavelengths shift by `±δλ`.
    fn systematic(&self, p: [f64; 3]) -> Result<[f64; 3], OpticsError> {
        let delta = self.measured.wavelength_uncertainty_nm;
        if delta == 0.0 {
            return Ok([0.0; 3]);
        }
        let shifted = |by: f64| -> Result<[f64; 3], OpticsError> {
            let wl: Vec<f64> = self.measured.wavelength_nm.iter().map(|w| w + by).collect();
            Ok(self.levenberg_marquardt(&wl, p)?.0)
        };
        let (up, down) = (shifted(delta)?, shifted(-delta)?);
        Ok(std::array::from_fn(|k| (up[k] - down[k]).abs() / 2.0))
    }
}

/// `JᵀJ` and `Jᵀr` for three columns; a zero column (a pinned parameter) gets a unit
/// diagonal, so that its step is zero and the system stays solvable.
fn normal_equations(jac: &[Vec<f64>; 3], residuals: &[f64]) -> ([[f64; 3]; 3], [f64; 3]) {
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    let mut normal: [[f64; 3]; 3] =
        std::array::from_fn(|i| std::array::from_fn(|j| dot(&jac[i], &jac[j])));
    for (k, row) in normal.iter_mut().enumerate() {
        if row[k] == 0.0 {
            row[k] = 1.0;
        }
    }
    let gradient = std::array::from_fn(|i| dot(&jac[i], residuals));
    (normal, gradient)
}

/// `m x = v` by Gaussian elimination with partial pivoting; `None` if singular.
fn solve3(mut m: [[f64; 3]; 3], mut v: [f64; 3]) -> Option<[f64; 3]> {
    for col in 0..3 {
        let pivot = (col..3).max_by(|&a, &b| m[a][col].abs().total_cmp(&m[b][col].abs()))?;
        if m[pivot][col] == 0.0 || m[pivot][col].is_nan() {
            return None;
        }
        m.swap(col, pivot);
        v.swap(col, pivot);
        for row in col + 1..3 {
            let factor = m[row][col] / m[col][col];
            let pivot_row = m[col];
            for (x, p) in m[row].iter_mut().zip(pivot_row).skip(col) {
                *x -= factor * p;
            }
            v[row] -= factor * v[col];
        }
    }
    let mut x = [0.0; 3];
    for row in (0..3).rev() {
        let tail: f64 = (row + 1..3).map(|k| m[row][k] * x[k]).sum();
        x[row] = (v[row] - tail) / m[row][row];
    }
    x.iter().all(|x| x.is_finite()).then_some(x)
}
