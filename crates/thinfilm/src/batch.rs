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

use crate::fresnel::{self, OpticsError, check_len};

mod cells;
pub(crate) mod film_f32;
pub(crate) mod film_f64;
mod kernel;
pub(crate) mod stack_f64;
pub(crate) mod stack_real_f64;
mod term;
mod trig_f64;

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

/// One table's spectrum as cells ([`crate::cells`]) for [`try_weighted_cell_row`]:
/// `edge_nm.len() == weights.len() + 1`, the other slices one entry per cell.
#[derive(Clone, Copy, Debug)]
pub struct CellSpectrum<'a> {
    /// Cell edges in nm, strictly increasing.
    pub edge_nm: &'a [f64],
    /// The film's index at each edge.
    pub n_film_edge: &'a [f64],
    /// The film's index at each cell's node, for its Fresnel coefficients.
    pub n_film_cell: &'a [f64],
    /// Weight of each cell's mean reflectance.
    pub weights: &'a [[f32; 3]],
}

/// For one incidence angle: `out[i] = Σ_c weights[c] · mean_c R(thickness_nm[i])`, the mean
/// of the symmetric film's reflectance over cell c, exact however narrow its spectral lines
/// (the f32 form of [`crate::cells::cell_mean_reflectance`], which it matches to about 1e-5).
///
/// # Errors
/// [`OpticsError`] naming the bad input: `n_outside` or an index not finite and `> 0`,
/// `cos_theta_outside` outside (0, 1], the film within reach of its critical angle at some
/// edge (`cos² θ_t < 1e-4`), edges not finite, positive and increasing, a non-finite weight,
/// a thickness not finite and `> 0`, or mismatched lengths. On error `out` is untouched.
pub fn try_weighted_cell_row(
    n_outside: f32,
    cos_theta_outside: f32,
    spectrum: &CellSpectrum<'_>,
    thickness_nm: &[f32],
    out: &mut [[f32; 3]],
) -> Result<(), OpticsError> {
    let (edge_q, row_cells) = cell_terms(n_outside as f64, cos_theta_outside as f64, spectrum)?;
    check_len("out", out.len(), thickness_nm.len())?;
    for &d in thickness_nm {
        if !(d.is_finite() && d > 0.0) {
            return Err(OpticsError::Thickness {
                thickness_nm: d as f64,
            });
        }
    }
    let half_weights: Vec<[f32; 3]> = spectrum
        .weights
        .iter()
        .map(|w| w.map(|x| 0.5 * x))
        .collect();
    let row = cells::CellRow {
        edge_q: &edge_q,
        cells: &row_cells,
        half_weights: &half_weights,
    };
    cells::weighted_cell_row(&row, thickness_nm, out);
    Ok(())
}

/// Validates a cell row and works out each edge's phase rate and each cell's constants.
fn cell_terms(
    n_outside: f64,
    cos_outside: f64,
    spectrum: &CellSpectrum<'_>,
) -> Result<(Vec<term::Split>, Vec<cells::Cell>), OpticsError> {
    fresnel::check_real_index("n_outside", n_outside)?;
    if !(cos_outside > 0.0 && cos_outside <= 1.0) {
        return Err(OpticsError::Cosine {
            what: "cos_theta_outside (cell means need 0 < cos θ <= 1)",
            value: cos_outside,
        });
    }
    let k = spectrum.weights.len();
    check_len("edge_nm", spectrum.edge_nm.len(), k + 1)?;
    check_len("n_film_edge", spectrum.n_film_edge.len(), k + 1)?;
    check_len("n_film_cell", spectrum.n_film_cell.len(), k)?;
    let sin2 = 1.0 - cos_outside * cos_outside;
    let cos_in_film = |n: f64| -> Result<f64, OpticsError> {
        fresnel::check_real_index("n_film", n)?;
        let cos2 = 1.0 - (n_outside / n).powi(2) * sin2;
        if cos2 < crate::cells::MIN_COS2_IN_FILM {
            return Err(OpticsError::Cosine {
                what: "cos_theta_outside (the film is near its critical angle there)",
                value: cos_outside,
            });
        }
        Ok(cos2.sqrt())
    };
    let mut edge_q = Vec::with_capacity(k + 1);
    let mut q = Vec::with_capacity(k + 1);
    for (i, (&wavelength_nm, &n)) in spectrum
        .edge_nm
        .iter()
        .zip(spectrum.n_film_edge)
        .enumerate()
    {
        fresnel::check_wavelength(wavelength_nm)?;
        if i > 0 && wavelength_nm <= spectrum.edge_nm[i - 1] {
            return Err(OpticsError::NotFinite {
                what: "edge_nm (must increase)",
                index: i,
                value: wavelength_nm,
            });
        }
        let rate = 2.0 * n * cos_in_film(n)? / wavelength_nm;
        q.push(rate);
        edge_q.push(term::Split::of_f64(rate));
    }
    let mut row_cells = Vec::with_capacity(k);
    for (c, (&n, w)) in spectrum
        .n_film_cell
        .iter()
        .zip(spectrum.weights)
        .enumerate()
    {
        if let Some(bad) = w.iter().find(|x| !x.is_finite()) {
            return Err(not_finite("weights", c, *bad));
        }
        let cos1 = cos_in_film(n)?;
        let (a_s, b_s) = crate::cells::line_area(n_outside * cos_outside, n * cos1);
        let (a_p, b_p) = crate::cells::line_area(n_outside * cos1, n * cos_outside);
        row_cells.push(cells::Cell {
            area: [a_s, b_s, a_p, b_p].map(|x| x as f32),
            inv_span: (1.0 / (std::f64::consts::PI * (q[c] - q[c + 1]))) as f32,
        });
    }
    Ok((edge_q, row_cells))
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

fn not_finite(what: &'static str, index: usize, value: f32) -> OpticsError {
    OpticsError::NotFinite {
        what,
        index,
        value: value as f64,
    }
}
