//! The f64 row kernel of [`crate::grid::FilmGrid`]: one thickness over every closed-form
//! (angle, wavelength) cell, exact to a few ulp, autovectorised (4 lanes with AVX2, picked
//! at run time; no FMA contraction, so bit-identical to the portable build). `sin²β` comes
//! from [`super::trig_f64`], without a libm call.

use super::trig_f64::sin_squared;

/// Largest `|β|` the row takes (see [`super::trig_f64::MAX_ARG`]).
pub(crate) const MAX_BETA: f64 = super::trig_f64::MAX_ARG;

/// Per-cell constants, structure of arrays: `β/nm`, then `ρ` and `(1 − ρ)²` for s and p.
#[derive(Clone, Debug)]
pub(crate) struct Cells {
    pub beta_per_nm: Vec<f64>,
    pub rho_s: Vec<f64>,
    pub gap_s: Vec<f64>,
    pub rho_p: Vec<f64>,
    pub gap_p: Vec<f64>,
}

/// Which output the row wants.
#[derive(Clone, Copy)]
pub(crate) enum Which {
    S,
    P,
    Mean,
}

/// `R` and `T` of a film `thickness_nm` thick at cells `first..first + r.len()`; requires
/// `max |β/nm| · thickness_nm ≤ MAX_BETA`, `t` as long as `r` and the cells in range.
pub(crate) fn row(
    cells: &Cells,
    first: usize,
    thickness_nm: f64,
    which: Which,
    r: &mut [f64],
    t: &mut [f64],
) {
    let n = r.len();
    let end = first + n;
    let cells = CellsRef {
        beta_per_nm: &cells.beta_per_nm[first..end],
        rho_s: &cells.rho_s[first..end],
        gap_s: &cells.gap_s[first..end],
        rho_p: &cells.rho_p[first..end],
        gap_p: &cells.gap_p[first..end],
    };
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU supports AVX2, checked just above.
        unsafe { row_avx2(&cells, thickness_nm, which, r, t) };
        return;
    }
    row_body(&cells, thickness_nm, which, r, t);
}

/// A range of [`Cells`].
struct CellsRef<'a> {
    beta_per_nm: &'a [f64],
    rho_s: &'a [f64],
    gap_s: &'a [f64],
    rho_p: &'a [f64],
    gap_p: &'a [f64],
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn row_avx2(cells: &CellsRef<'_>, thickness_nm: f64, which: Which, r: &mut [f64], t: &mut [f64]) {
    row_body(cells, thickness_nm, which, r, t);
}

#[inline(always)]
fn row_body(cells: &CellsRef<'_>, d: f64, which: Which, r: &mut [f64], t: &mut [f64]) {
    let n = cells.beta_per_nm.len();
    let (beta, r, t) = (&cells.beta_per_nm[..n], &mut r[..n], &mut t[..n]);
    match which {
        Which::S | Which::P => {
            let (rho, gap) = match which {
                Which::S => (&cells.rho_s[..n], &cells.gap_s[..n]),
                _ => (&cells.rho_p[..n], &cells.gap_p[..n]),
            };
            for i in 0..n {
                let bounce = 4.0 * rho[i] * sin_squared(beta[i] * d);
                let inv = 1.0 / (gap[i] + bounce);
                r[i] = bounce * inv;
                t[i] = gap[i] * inv;
            }
        }
        Which::Mean => {
            let (rho_s, gap_s) = (&cells.rho_s[..n], &cells.gap_s[..n]);
            let (rho_p, gap_p) = (&cells.rho_p[..n], &cells.gap_p[..n]);
            for i in 0..n {
                let four_sin2 = 4.0 * sin_squared(beta[i] * d);
                let (bs, bp) = (rho_s[i] * four_sin2, rho_p[i] * four_sin2);
                let (ds, dp) = (gap_s[i] + bs, gap_p[i] + bp);
                let half_inv = 0.5 / (ds * dp);
                r[i] = (bs * dp + bp * ds) * half_inv;
                t[i] = (gap_s[i] * dp + gap_p[i] * ds) * half_inv;
            }
        }
    }
}
