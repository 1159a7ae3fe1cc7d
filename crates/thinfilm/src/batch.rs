//! The f32 fast path: slices in, slices out, for baking tables and rendering.
//!
//! Every function here treats the soap-bubble case, a symmetric lossless film
//! `outside | film | outside`, with the exact Airy sum of all orders:
//! per polarisation `R = 4ρ² sin²(δ/2) / ((1 − ρ²)² + 4ρ² sin²(δ/2))` and
//! `T = (1 − ρ²)² / ((1 − ρ²)² + 4ρ² sin²(δ/2))` (the same as
//! `2ρ²(1 − cos δ)/(1 + ρ⁴ − 2ρ² cos δ)`, without its cancellations), averaged over s and p,
//! with `δ = 4π n_film d cos θ_t / λ` and θ_t the angle inside the film. Everything that
//! does not depend on thickness is computed once in f64. Per sample the work is f32 only:
//! the phase `q·d` (periods) is reduced with `q` and `d` split into 12-bit halves so the
//! whole periods cancel exactly, then a degree-9 polynomial gives `sin²(δ/2)` and one
//! division gives `R_s + R_p`. The loops autovectorise (8 lanes with AVX2, picked at run
//! time, bit-identical to the portable build). Results agree with
//! [`crate::airy::ThinFilm`] to 2e-7 (worst over a soap-film sweep, measured by the ignored
//! test `report_worst_batch_error`).
//!
//! A film at, beyond or near its own critical angle (refracted angle within 0.6° of 90°,
//! possible only when the film is optically thinner than the outside), near-grazing light
//! (`0 < cos θ < 1e-6`) and phases beyond `2^21` periods (about 0.3 m of soap) are
//! evaluated with the f64 reference instead: correct, but slow.
//!
//! Each function has a `try_` form that returns an [`OpticsError`] naming a bad input;
//! the plain form panics with that message.

use crate::fresnel::{self, OpticsError};

mod kernel;
mod term;

use kernel::{RowOut, Samples};
use term::Term;

/// Per-sample reflectance of a symmetric film: `out_r[i] = R(thickness_nm[i], cos_theta[i],
/// wavelength_nm[i])` for `n_outside | n_film | n_outside`.
///
/// # Panics
/// If the slice lengths differ or any input is invalid (see [`try_reflectance`]).
pub fn reflectance(
    n_outside: f32,
    n_film: f32,
    thickness_nm: &[f32],
    cos_theta: &[f32],
    wavelength_nm: &[f32],
    out_r: &mut [f32],
) {
    try_reflectance(
        n_outside,
        n_film,
        thickness_nm,
        cos_theta,
        wavelength_nm,
        out_r,
    )
    .unwrap_or_else(|err| panic!("{err}"));
}

/// [`reflectance`], or an error naming the bad input: indices not finite and `> 0`,
/// a thickness not finite and `≥ 0`, a cosine outside [0, 1], a wavelength not finite and
/// `> 0`, or a slice whose length differs from `thickness_nm`'s. On error `out_r` is untouched.
pub fn try_reflectance(
    n_outside: f32,
    n_film: f32,
    thickness_nm: &[f32],
    cos_theta: &[f32],
    wavelength_nm: &[f32],
    out_r: &mut [f32],
) -> Result<(), OpticsError> {
    let samples = checked_samples(n_outside, n_film, thickness_nm, cos_theta, wavelength_nm)?;
    check_len("out_r", out_r.len(), thickness_nm.len())?;
    if samples.n_outside == samples.n_film {
        out_r.fill(0.0);
        return Ok(());
    }
    kernel::samples::<false>(&samples, out_r, &mut []);
    Ok(())
}

/// Per-sample reflectance and transmittance (each from its own formula, not `1 − R`) of a
/// symmetric film; the inputs and errors are those of [`try_reflectance`].
pub fn try_reflectance_transmittance(
    n_outside: f32,
    n_film: f32,
    thickness_nm: &[f32],
    cos_theta: &[f32],
    wavelength_nm: &[f32],
    out_r: &mut [f32],
    out_t: &mut [f32],
) -> Result<(), OpticsError> {
    let samples = checked_samples(n_outside, n_film, thickness_nm, cos_theta, wavelength_nm)?;
    check_len("out_r", out_r.len(), thickness_nm.len())?;
    check_len("out_t", out_t.len(), thickness_nm.len())?;
    if samples.n_outside == samples.n_film {
        out_r.fill(0.0);
        out_t.fill(1.0);
        return Ok(());
    }
    kernel::samples::<true>(&samples, out_r, out_t);
    Ok(())
}

/// For one incidence angle: `out[i] = Σ_k weights[k] · R(thickness_nm[i], λ_k)`, with
/// `n_film[k]` the film index at `wavelength_nm[k]` (dispersion). The kernel the LUT baker
/// calls for every row.
///
/// # Panics
/// If `n_film` or `weights` differ in length from `wavelength_nm`, `out` from
/// `thickness_nm`, or any input is invalid (see [`try_weighted_reflectance_row`]).
pub fn weighted_reflectance_row(
    n_outside: f32,
    cos_theta_outside: f32,
    wavelength_nm: &[f32],
    n_film: &[f32],
    weights: &[[f32; 3]],
    thickness_nm: &[f32],
    out: &mut [[f32; 3]],
) {
    let row = Row {
        n_outside,
        cos_theta_outside,
        wavelength_nm,
        n_film,
        weights,
        thickness_nm,
    };
    try_weighted_reflectance_row_impl(&row, out).unwrap_or_else(|err| panic!("{err}"));
}

/// [`weighted_reflectance_row`], or an error naming the bad input: `n_outside` or an
/// `n_film[k]` not finite and `> 0`, `cos_theta_outside` outside [0, 1], a wavelength not
/// finite and `> 0`, a non-finite weight, a thickness not finite and `≥ 0`, or mismatched
/// lengths. On error `out` is untouched.
pub fn try_weighted_reflectance_row(
    n_outside: f32,
    cos_theta_outside: f32,
    wavelength_nm: &[f32],
    n_film: &[f32],
    weights: &[[f32; 3]],
    thickness_nm: &[f32],
    out: &mut [[f32; 3]],
) -> Result<(), OpticsError> {
    let row = Row {
        n_outside,
        cos_theta_outside,
        wavelength_nm,
        n_film,
        weights,
        thickness_nm,
    };
    try_weighted_reflectance_row_impl(&row, out)
}

/// [`try_weighted_reflectance_row`] that also fills
/// `out_t[i] = Σ_k weights[k] · T(thickness_nm[i], λ_k)`, transmittance from its own formula.
#[allow(clippy::too_many_arguments)]
pub fn try_weighted_response_row(
    n_outside: f32,
    cos_theta_outside: f32,
    wavelength_nm: &[f32],
    n_film: &[f32],
    weights: &[[f32; 3]],
    thickness_nm: &[f32],
    out_r: &mut [[f32; 3]],
    out_t: &mut [[f32; 3]],
) -> Result<(), OpticsError> {
    let row = Row {
        n_outside,
        cos_theta_outside,
        wavelength_nm,
        n_film,
        weights,
        thickness_nm,
    };
    let (terms, half_weights) = row.prepare()?;
    check_len("out_r", out_r.len(), thickness_nm.len())?;
    check_len("out_t", out_t.len(), thickness_nm.len())?;
    let out = RowOut { r: out_r, t: out_t };
    kernel::weighted_row::<true>(&terms, &half_weights, thickness_nm, out);
    Ok(())
}

/// The inputs of one weighted row.
struct Row<'a> {
    n_outside: f32,
    cos_theta_outside: f32,
    wavelength_nm: &'a [f32],
    n_film: &'a [f32],
    weights: &'a [[f32; 3]],
    thickness_nm: &'a [f32],
}

impl Row<'_> {
    /// Validates the row and works out each wavelength's term and halved weights.
    fn prepare(&self) -> Result<(Vec<Term>, Vec<[f32; 3]>), OpticsError> {
        let n_outside = self.n_outside as f64;
        fresnel::check_real_index("n_outside", n_outside)?;
        fresnel::check_cos("cos_theta_outside", self.cos_theta_outside as f64)?;
        let k = self.wavelength_nm.len();
        check_len("n_film", self.n_film.len(), k)?;
        check_len("weights", self.weights.len(), k)?;
        let max_thickness_nm = check_thicknesses(self.thickness_nm)?;
        let mut terms = Vec::with_capacity(k);
        let mut half_weights = Vec::with_capacity(k);
        for (i, ((&wavelength_nm, &n_film), w)) in self
            .wavelength_nm
            .iter()
            .zip(self.n_film)
            .zip(self.weights)
            .enumerate()
        {
            fresnel::check_wavelength(wavelength_nm as f64)?;
            fresnel::check_real_index("n_film", n_film as f64)?;
            if let Some(bad) = w.iter().find(|x| !x.is_finite()) {
                return Err(not_finite("weights", i, *bad));
            }
            terms.push(term::term(
                n_outside,
                n_film as f64,
                self.cos_theta_outside as f64,
                wavelength_nm as f64,
                max_thickness_nm,
            ));
            half_weights.push(w.map(|x| 0.5 * x));
        }
        Ok((terms, half_weights))
    }
}

fn try_weighted_reflectance_row_impl(
    row: &Row<'_>,
    out: &mut [[f32; 3]],
) -> Result<(), OpticsError> {
    let (terms, half_weights) = row.prepare()?;
    check_len("out", out.len(), row.thickness_nm.len())?;
    let out = RowOut { r: out, t: &mut [] };
    kernel::weighted_row::<false>(&terms, &half_weights, row.thickness_nm, out);
    Ok(())
}

/// Validates per-sample inputs and widens the indices.
fn checked_samples<'a>(
    n_outside: f32,
    n_film: f32,
    thickness_nm: &'a [f32],
    cos_theta: &'a [f32],
    wavelength_nm: &'a [f32],
) -> Result<Samples<'a>, OpticsError> {
    fresnel::check_real_index("n_outside", n_outside as f64)?;
    fresnel::check_real_index("n_film", n_film as f64)?;
    let n = thickness_nm.len();
    check_len("cos_theta", cos_theta.len(), n)?;
    check_len("wavelength_nm", wavelength_nm.len(), n)?;
    check_thicknesses(thickness_nm)?;
    for (i, &c) in cos_theta.iter().enumerate() {
        if !(0.0..=1.0).contains(&c) {
            return Err(not_finite("cos_theta", i, c));
        }
    }
    for (i, &l) in wavelength_nm.iter().enumerate() {
        if !(l.is_finite() && l > 0.0) {
            return Err(not_finite("wavelength_nm", i, l));
        }
    }
    Ok(Samples {
        n_outside: n_outside as f64,
        n_film: n_film as f64,
        thickness_nm,
        cos_theta,
        wavelength_nm,
    })
}

/// Checks every thickness is finite and `≥ 0`; returns the largest (0 for none).
fn check_thicknesses(thickness_nm: &[f32]) -> Result<f64, OpticsError> {
    let mut max = 0.0f32;
    for (i, &d) in thickness_nm.iter().enumerate() {
        if !(d.is_finite() && d >= 0.0) {
            return Err(not_finite("thickness_nm", i, d));
        }
        max = max.max(d);
    }
    Ok(max as f64)
}

fn check_len(what: &'static str, len: usize, expected: usize) -> Result<(), OpticsError> {
    if len == expected {
        Ok(())
    } else {
        Err(OpticsError::Length {
            what,
            len,
            expected,
        })
    }
}

fn not_finite(what: &'static str, index: usize, value: f32) -> OpticsError {
    OpticsError::NotFinite {
        what,
        index,
        value: value as f64,
    }
}
