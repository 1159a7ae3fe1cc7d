//! The f64 row kernel of [`crate::grid::FilmGrid`]: one thickness over every closed-form
//! (angle, wavelength) cell, exact to a few ulp, autovectorised (4 lanes with AVX2, picked
//! at run time; no FMA contraction, so bit-identical to the portable build).
//!
//! `sin²β` is evaluated without a libm call: `β` is reduced by `k π/2` with a three-part
//! Cody–Waite split of π/2 (the first two parts have 33 significant bits, so `k · part` is
//! exact for `|k| < 2^20`), then `sin r` on `|r| ≤ π/4` is fdlibm's degree-13 minimax
//! polynomial (relative error below 2^-58) and `sin²β = sin²r` for even `k`, `1 − sin²r`
//! for odd `k` (at least 1/2 there, so no cancellation). Callers keep `|β| ≤ MAX_BETA`.

/// Largest `|β|` the reduction takes: `|k| ≤ 2^19`, far inside the exact range.
pub(crate) const MAX_BETA: f64 = 8.0e5;

const TWO_OVER_PI: f64 = std::f64::consts::FRAC_2_PI;
#[allow(clippy::excessive_precision)] // fdlibm's published digits
const PIO2_1: f64 = 1.570_796_326_734_125_614_17e+00;
#[allow(clippy::excessive_precision)] // fdlibm's published digits
const PIO2_2: f64 = 6.077_100_506_303_965_976_60e-11;
#[allow(clippy::excessive_precision)] // fdlibm's published digits
const PIO2_3: f64 = 2.022_266_248_711_166_455_80e-21;
#[allow(clippy::excessive_precision)] // fdlibm's published digits
const S1: f64 = -1.666_666_666_666_663_243_48e-01;
#[allow(clippy::excessive_precision)] // fdlibm's published digits
const S2: f64 = 8.333_333_333_322_489_461_24e-03;
#[allow(clippy::excessive_precision)] // fdlibm's published digits
const S3: f64 = -1.984_126_982_985_794_931_34e-04;
#[allow(clippy::excessive_precision)] // fdlibm's published digits
const S4: f64 = 2.755_731_370_707_006_767_89e-06;
#[allow(clippy::excessive_precision)] // fdlibm's published digits
const S5: f64 = -2.505_076_025_340_686_341_95e-08;
#[allow(clippy::excessive_precision)] // fdlibm's published digits
const S6: f64 = 1.589_690_995_211_550_102_21e-10;
/// `1.5 · 2^52`: adding and subtracting it rounds to the nearest integer (`|y| < 2^51`).
const ROUND: f64 = 6_755_399_441_055_744.0;

/// `sin²x` for `|x| ≤ MAX_BETA`.
#[inline(always)]
pub(crate) fn sin_squared(x: f64) -> f64 {
    let shifted = x * TWO_OVER_PI + ROUND;
    let odd = (shifted.to_bits() & 1) as f64;
    let k = shifted - ROUND;
    let r = ((x - k * PIO2_1) - k * PIO2_2) - k * PIO2_3;
    let z = r * r;
    let s = r + r * z * (S1 + z * (S2 + z * (S3 + z * (S4 + z * (S5 + z * S6)))));
    let s2 = s * s;
    s2 + odd * (1.0 - 2.0 * s2)
}

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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sin_squared_matches_libm_over_its_range() {
        let mut worst = 0.0f64;
        let mut x = -MAX_BETA;
        let mut k = 0u64;
        while x <= MAX_BETA {
            let exact = x.sin() * x.sin();
            worst = worst.max((sin_squared(x) - exact).abs());
            k += 1;
            // An irregular step, so that every quadrant and phase is visited.
            x += 0.377 + (k % 7) as f64 * 0.0131;
        }
        for x in [
            0.0,
            1e-300,
            1e-8,
            std::f64::consts::FRAC_PI_4,
            std::f64::consts::PI,
        ] {
            worst = worst.max((sin_squared(x) - x.sin() * x.sin()).abs());
        }
        assert!(worst < 4.0 * f64::EPSILON, "worst |diff| {worst:e}");
    }
}
