//! Graded-index layers: an index that varies with depth, `n(z)` for `z` from the layer's
//! front face (0) to its back face (`thickness_nm`), sliced into homogeneous layers.
//!
//! Slice `k` of `N` takes the profile's value at its midpoint, `z = (k + ½) d / N`: the
//! staircase's error in `r` and `t` is `O(N⁻²)` for a smooth profile (the midpoint rule of
//! the Riccati equation for `r(z)`). [`GradedLayer::converged_response`] doubles `N` until
//! the Richardson estimate of the remaining error, `|R_2N − R_N| / 3` (and the same for
//! `T`), is below the asked tolerance, and reports that estimate as its error bound.
//!
//! ```
//! use thinfilm::graded::{GradedLayer, Profile};
//! use thinfilm::{Complex64, Incidence, Stack};
//!
//! // A 500 nm linear ramp from glass (1.52) to air, on glass: an anti-reflection layer.
//! let ramp = GradedLayer::try_new(Profile::Linear { front: 1.0.into(), back: 1.52.into() }, 500.0).unwrap();
//! let out = ramp
//!     .converged_response(|layers| Stack::new(1.0, layers, 1.52), 550.0, Incidence::NORMAL, 1e-9)
//!     .unwrap();
//! assert!(out.response.r() < 0.002 && out.error_bound <= 1e-9);
//! ```

use crate::fresnel::{self, OpticsError, Response};
use crate::incidence::Incidence;
use crate::tmm::{Layer, Stack};
use num_complex::Complex64;

/// How the index varies through the layer.
#[derive(Clone, Debug, PartialEq)]
pub enum Profile {
    /// `n(z)` linear from `front` (z = 0) to `back` (z = d), real and imaginary parts alike.
    Linear {
        /// Index at the front face.
        front: Complex64,
        /// Index at the back face.
        back: Complex64,
    },
    /// `n(z) = front · (back / front)^(z/d)` (real indices: a constant gradient of `ln n`).
    Exponential {
        /// Index at the front face (real, > 0).
        front: f64,
        /// Index at the back face (real, > 0).
        back: f64,
    },
    /// `1/n(z)` linear from `1/front` to `1/back` (real): the profile whose wave equation
    /// at normal incidence is a Cauchy–Euler equation, solvable in closed form.
    Reciprocal {
        /// Index at the front face (real, > 0).
        front: f64,
        /// Index at the back face (real, > 0).
        back: f64,
    },
    /// Tabulated `(z_frac, n)` with `z_frac` = z/d from 0 to 1 strictly increasing,
    /// linear in between (see [`Profile::from_csv`]).
    Table(Vec<(f64, Complex64)>),
}

impl Profile {
    /// A profile from `z_nm,n,k` CSV text (header line, then rows; `#` comments and blank
    /// lines skipped), with `z_nm` from 0 (front) strictly increasing to the layer's
    /// thickness, which is returned with it.
    ///
    /// # Errors
    /// [`OpticsError::Table`] naming the line and the bad value.
    pub fn from_csv(text: &str) -> Result<(Profile, f64), OpticsError> {
        let bad = |line: usize, what: String| OpticsError::Table {
            reason: format!("profile line {line}: {what}"),
        };
        let mut rows: Vec<(f64, Complex64)> = Vec::new();
        let mut header = true;
        for (k, line) in text.lines().enumerate() {
            let line_no = k + 1;
            let line = line.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            if header {
                header = false;
                if line
                    .split(',')
                    .next()
                    .is_some_and(|f| f.trim().parse::<f64>().is_err())
                {
                    continue;
                }
            }
            let fields: Vec<&str> = line.split(',').map(str::trim).collect();
            if fields.len() != 3 {
                return Err(bad(line_no, format!("`{line}` is not `z_nm,n,k`")));
            }
            let num = |f: &str| {
                f.parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| bad(line_no, format!("`{f}` is not a number")))
            };
            let (z, n, kappa) = (num(fields[0])?, num(fields[1])?, num(fields[2])?);
            let index = Complex64::new(n, kappa);
            fresnel::check_complex_index("profile index", index)
                .map_err(|e| bad(line_no, e.to_string()))?;
            match rows.last() {
                None if z != 0.0 => return Err(bad(line_no, format!("z_nm {z} must start at 0"))),
                Some(&(prev, _)) if z <= prev => {
                    return Err(bad(
                        line_no,
                        format!("z_nm {z} does not increase (after {prev})"),
                    ));
                }
                _ => rows.push((z, index)),
            }
        }
        let Some(&(thickness_nm, _)) = rows.last().filter(|_| rows.len() >= 2) else {
            return Err(OpticsError::Table {
                reason: "a profile needs at least two rows".into(),
            });
        };
        let table = rows
            .into_iter()
            .map(|(z, n)| (z / thickness_nm, n))
            .collect();
        Ok((Profile::Table(table), thickness_nm))
    }

    /// The index at `z_frac` = z/d ∈ [0, 1].
    pub fn index_at(&self, z_frac: f64) -> Complex64 {
        match self {
            Profile::Linear { front, back } => front + (back - front) * z_frac,
            Profile::Exponential { front, back } => {
                Complex64::new(front * (back / front).powf(z_frac), 0.0)
            }
            Profile::Reciprocal { front, back } => Complex64::new(
                1.0 / (1.0 / front + (1.0 / back - 1.0 / front) * z_frac),
                0.0,
            ),
            Profile::Table(rows) => {
                let at = rows
                    .partition_point(|&(z, _)| z <= z_frac)
                    .clamp(1, rows.len() - 1);
                let ((z0, n0), (z1, n1)) = (rows[at - 1], rows[at]);
                n0 + (n1 - n0) * ((z_frac - z0) / (z1 - z0))
            }
        }
    }

    fn validate(&self) -> Result<(), OpticsError> {
        match self {
            Profile::Linear { front, back } => {
                fresnel::check_complex_index("profile front", *front)?;
                fresnel::check_complex_index("profile back", *back)
            }
            Profile::Exponential { front, back } | Profile::Reciprocal { front, back } => {
                fresnel::check_real_index("profile front", *front)?;
                fresnel::check_real_index("profile back", *back)
            }
            Profile::Table(rows) => {
                let ordered = rows.len() >= 2
                    && rows[0].0 == 0.0
                    && rows[rows.len() - 1].0 == 1.0
                    && rows.windows(2).all(|w| w[0].0 < w[1].0);
                if !ordered {
                    return Err(OpticsError::Table {
                        reason: "profile z_frac must rise strictly from 0 to 1".into(),
                    });
                }
                rows.iter()
                    .try_for_each(|&(_, n)| fresnel::check_complex_index("profile index", n))
            }
        }
    }
}

/// A graded-index layer: a [`Profile`] over `thickness_nm`.
#[derive(Clone, Debug, PartialEq)]
pub struct GradedLayer {
    profile: Profile,
    thickness_nm: f64,
}

/// A response computed to a stated error bound.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Converged {
    /// The response with the finest slicing used.
    pub response: Response,
    /// The estimated error of every `R` and `T` in it: `max |X_2N − X_N| / 3`.
    pub error_bound: f64,
    /// The number of slices of the finest slicing.
    pub slices: usize,
}

/// The first slicing tried by [`GradedLayer::converged_response`].
pub const FIRST_SLICES: usize = 8;
/// The most slices [`GradedLayer::converged_response`] tries.
pub const MAX_SLICES: usize = 1 << 16;

impl GradedLayer {
    /// A validated graded layer.
    ///
    /// # Errors
    /// A bad index in the profile or a thickness that is not finite and `≥ 0`.
    pub fn try_new(profile: Profile, thickness_nm: f64) -> Result<GradedLayer, OpticsError> {
        profile.validate()?;
        fresnel::check_thickness(thickness_nm)?;
        Ok(GradedLayer {
            profile,
            thickness_nm,
        })
    }

    /// The layer's thickness in nm.
    pub fn thickness_nm(&self) -> f64 {
        self.thickness_nm
    }

    /// `count` homogeneous slices, each at the profile's value at its midpoint.
    pub fn slices(&self, count: usize) -> Vec<Layer> {
        let count = count.max(1);
        let width = self.thickness_nm / count as f64;
        (0..count)
            .map(|k| {
                let n = self.profile.index_at((k as f64 + 0.5) / count as f64);
                Layer::new(n, width)
            })
            .collect()
    }

    /// The response of the stack `stack_with(slices)` (the caller places the slices among
    /// its other layers) at `wavelength_nm` and `incidence`, slices doubled from
    /// [`FIRST_SLICES`] until the error estimate is `≤ tolerance`.
    ///
    /// # Errors
    /// What `stack_with` or the stack returns, or [`OpticsError::Graded`] for a tolerance
    /// that is not finite and `> 0` or one that [`MAX_SLICES`] slices do not reach.
    pub fn converged_response(
        &self,
        stack_with: impl Fn(Vec<Layer>) -> Result<Stack, OpticsError>,
        wavelength_nm: f64,
        incidence: Incidence,
        tolerance: f64,
    ) -> Result<Converged, OpticsError> {
        if !(tolerance.is_finite() && tolerance > 0.0) {
            return Err(OpticsError::Graded {
                reason: format!("tolerance {tolerance} is not finite and > 0"),
            });
        }
        let at = |count: usize| {
            stack_with(self.slices(count))?.try_response_at(wavelength_nm, incidence)
        };
        let mut count = FIRST_SLICES;
        let mut coarse = at(count)?;
        loop {
            let fine = at(2 * count)?;
            let error_bound = [
                (fine.r_s, coarse.r_s),
                (fine.r_p, coarse.r_p),
                (fine.t_s, coarse.t_s),
                (fine.t_p, coarse.t_p),
            ]
            .iter()
            .map(|(a, b)| (a - b).abs() / 3.0)
            .fold(0.0, f64::max);
            count *= 2;
            if error_bound <= tolerance {
                return Ok(Converged {
                    response: fine,
                    error_bound,
                    slices: count,
                });
            }
            if count >= MAX_SLICES {
                return Err(OpticsError::Graded {
                    reason: format!(
                        "not converged to {tolerance} with {count} slices \
                         (error estimate {error_bound:e})"
                    ),
                });
            }
            coarse = fine;
        }
    }
}
