//! Everything about one (angle, wavelength, index) that does not depend on thickness,
//! worked out once in f64 so the per-thickness loop is a sine and two divisions.

use crate::airy::ThinFilm;
use crate::dispersion::RefractiveIndex;
use num_complex::Complex64;

/// Below this `cos² θ_t` the film is at, beyond or too near its critical angle for the
/// f32 form (its `1 − ρ²` and `sin(δ/2)` vanish together); the f64 reference is used.
pub(crate) const MIN_COS2_IN_FILM: f64 = 1e-4;

/// Below this (non-zero) `cos θ_outside` the product of the f32 denominators could underflow.
pub(crate) const MIN_COS_OUTSIDE: f64 = 1e-6;

/// Largest phase, in periods, that the f32 path reduces (it rounds via `1.5 · 2^23`).
pub(crate) const MAX_PERIODS: f64 = (1u64 << 21) as f64;

/// How one (angle, wavelength, index) is evaluated across thicknesses.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Term {
    /// Reflectance and transmittance that do not depend on thickness (no interface, or
    /// exactly grazing incidence).
    Uniform {
        /// Unpolarised reflectance.
        r: f32,
        /// Unpolarised transmittance.
        t: f32,
    },
    /// A propagating wave in the film: the f32 closed form.
    Wave(Wave),
    /// Evaluate [`ThinFilm::response`] in f64 at each thickness.
    Exact(ThinFilm, f64, f64),
}

/// The thickness-independent part of `R_pol = a s² / (b + a s²)`, `T_pol = b / (b + a s²)`,
/// `s = sin(π · q · d)`, with `a = 4ρ²`, `b = (1 − ρ²)²` for one interface's
/// amplitude reflectance `ρ` (symmetric lossless film, Airy sum of all orders).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Wave {
    pub a_s: f32,
    pub b_s: f32,
    pub a_p: f32,
    pub b_p: f32,
    /// `q = 2 n_film cos θ_t / λ` periods per nm: round-trip phase `δ = 2π q d`.
    pub periods_per_nm: Split,
}

/// An f32 split `hi + lo` of a value: `hi` has 12 significant bits, so its product with
/// another 12-bit `hi` is exact in f32. `full` is the value rounded to f32.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Split {
    pub hi: f32,
    pub lo: f32,
    pub full: f32,
}

impl Split {
    /// Splits an f32 exactly: `hi + lo == x`.
    #[inline(always)]
    pub(crate) fn of_f32(x: f32) -> Split {
        let hi = f32::from_bits(x.to_bits() & 0xFFFF_F000);
        Split {
            hi,
            lo: x - hi,
            full: x,
        }
    }

    /// Splits an f64: `hi + lo` equals `x` to about 2^-36 relative.
    #[inline(always)]
    pub(crate) fn of_f64(x: f64) -> Split {
        let full = x as f32;
        let hi = f32::from_bits(full.to_bits() & 0xFFFF_F000);
        Split {
            hi,
            lo: (x - hi as f64) as f32,
            full,
        }
    }
}

/// `(4ρ², (1 − ρ²)²)` for `ρ = (x − y)/(x + y)`, with `1 − ρ² = 4xy/(x + y)²` so that
/// near-total reflection keeps its relative precision.
#[inline(always)]
pub(crate) fn a_and_b(x: f64, y: f64) -> (f32, f32) {
    let inv_sum = 1.0 / (x + y);
    let rho = (x - y) * inv_sum;
    let one_minus_rho2 = 4.0 * x * y * inv_sum * inv_sum;
    (
        (4.0 * rho * rho) as f32,
        (one_minus_rho2 * one_minus_rho2) as f32,
    )
}

/// The term for a symmetric film `n_outside | n_film | n_outside` at one angle and
/// wavelength, for thicknesses up to `max_thickness_nm`. Inputs must be validated.
pub(crate) fn term(
    n_outside: f64,
    n_film: f64,
    cos_outside: f64,
    wavelength_nm: f64,
    max_thickness_nm: f64,
) -> Term {
    if n_outside == n_film {
        return Term::Uniform { r: 0.0, t: 1.0 };
    }
    if cos_outside == 0.0 {
        return Term::Uniform { r: 1.0, t: 0.0 };
    }
    let ratio = n_outside / n_film;
    let cos2_film = 1.0 - ratio * ratio * (1.0 - cos_outside * cos_outside);
    let cos_film = cos2_film.max(0.0).sqrt();
    let periods_per_nm = 2.0 * n_film * cos_film / wavelength_nm;
    if cos2_film < MIN_COS2_IN_FILM
        || cos_outside < MIN_COS_OUTSIDE
        || periods_per_nm * max_thickness_nm > MAX_PERIODS
    {
        let film = ThinFilm {
            n_outside,
            n_film: RefractiveIndex::Constant(n_film),
            n_substrate: Complex64::new(n_outside, 0.0),
            thickness_nm: 0.0,
        };
        return Term::Exact(film, cos_outside, wavelength_nm);
    }
    let (a_s, b_s) = a_and_b(n_outside * cos_outside, n_film * cos_film);
    let (a_p, b_p) = a_and_b(n_outside * cos_film, n_film * cos_outside);
    Term::Wave(Wave {
        a_s,
        b_s,
        a_p,
        b_p,
        periods_per_nm: Split::of_f64(periods_per_nm),
    })
}

impl Term {
    /// Unpolarised `(R, T)` at one thickness, by the term's own method (scalar).
    pub(crate) fn evaluate(&self, thickness_nm: f32) -> (f32, f32) {
        match *self {
            Term::Uniform { r, t } => (r, t),
            Term::Wave(wave) => super::kernel::mean_r_t(&wave, Split::of_f32(thickness_nm)),
            Term::Exact(film, cos_outside, wavelength_nm) => {
                let film = ThinFilm {
                    thickness_nm: thickness_nm as f64,
                    ..film
                };
                let response = film.response(wavelength_nm, cos_outside);
                (response.r() as f32, response.t() as f32)
            }
        }
    }
}
