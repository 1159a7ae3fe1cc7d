//! The f32 cell-mean kernel: `Σ_c w_c · mean_c(R)` over thicknesses, the fast form of
//! [`crate::cells::cell_mean_reflectance`]. Per texel and cell edge: one phase reduction,
//! a sine and a cosine polynomial; per cell and polarisation one `atan2` of the product
//! of the two edges' complex numbers (so `θ_lo − θ_hi` comes out directly, in (−π, π)).
//! Same IEEE operations in the same order in the AVX2 and portable builds.

use super::kernel::{CHUNK, reduced_periods};
use super::term::Split;

/// Odd polynomial for `sin(π f)` on `f ∈ [−½, ½]` (the batch kernel's, 4.6e-9).
const SIN_PI: [f32; 5] = [
    std::f32::consts::PI,
    -5.167_71,
    2.550_067_4,
    -0.598_217_84,
    0.077_505_276,
];

/// Taylor series of `cos(π f)` in `f²`, `(−π²)^k / (2k)!`, to 6e-9 on `[−½, ½]`.
const COS_PI: [f32; 7] = [
    1.0,
    -4.934_802,
    4.058_712_3,
    -1.335_262_8,
    0.235_330_63,
    -0.025_806_89,
    0.001_929_574_3,
];

/// `atan(t) / t` as a polynomial in `t²` on `t ∈ [0, 1]` (Chebyshev fit, 1.0e-7 in atan).
const ATAN: [f32; 8] = [
    0.999_999_9,
    -0.333_319_6,
    0.199_692_35,
    -0.140_165_85,
    0.099_060_97,
    -0.059_367_1,
    0.024_166_19,
    -0.004_668_773,
];

#[inline(always)]
fn horner<const N: usize>(coefficients: &[f32; N], x: f32) -> f32 {
    let mut acc = coefficients[N - 1];
    for &c in coefficients[..N - 1].iter().rev() {
        acc = acc * x + c;
    }
    acc
}

/// `(sin πf, cos πf)` of a reduced phase `f ∈ [−½, ½]`.
#[inline(always)]
fn sin_cos_pi(f: f32) -> (f32, f32) {
    let f2 = f * f;
    (f * horner(&SIN_PI, f2), horner(&COS_PI, f2))
}

/// `atan2(y, x)` in (−π, π], to about 2e-7.
#[inline(always)]
pub(crate) fn atan2(y: f32, x: f32) -> f32 {
    let (ax, ay) = (x.abs(), y.abs());
    let big = ax.max(ay).max(f32::MIN_POSITIVE);
    let t = ax.min(ay) / big;
    let mut a = t * horner(&ATAN, t * t);
    if ay > ax {
        a = std::f32::consts::FRAC_PI_2 - a;
    }
    if x < 0.0 {
        a = std::f32::consts::PI - a;
    }
    a.copysign(y)
}

/// One cell of one row: what does not depend on thickness.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Cell {
    /// `A` and `1 − A` for s and p: `[A_s, 1 − A_s, A_p, 1 − A_p]`.
    pub area: [f32; 4],
    /// `1 / (π (q_lo − q_hi))`: divided by d, one over the cell's phase span in radians/π.
    pub inv_span: f32,
}

/// The inputs of one row of the cell kernel.
pub(crate) struct CellRow<'a> {
    /// Periods per nm at each edge, `q = 2 n cos θ_t / λ`.
    pub edge_q: &'a [Split],
    pub cells: &'a [Cell],
    /// Weights already halved (the polarisation mean).
    pub half_weights: &'a [[f32; 3]],
}

/// `out[i] = Σ_c w_c · mean_c R(d_i)` for thicknesses `> 0`.
pub(crate) fn weighted_cell_row(row: &CellRow<'_>, thickness_nm: &[f32], out: &mut [[f32; 3]]) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU supports AVX2, checked just above.
        unsafe { weighted_cell_row_avx2(row, thickness_nm, out) };
        return;
    }
    weighted_cell_row_body(row, thickness_nm, out);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn weighted_cell_row_avx2(row: &CellRow<'_>, thickness_nm: &[f32], out: &mut [[f32; 3]]) {
    weighted_cell_row_body(row, thickness_nm, out);
}

/// Sine and cosine of the phase at one edge, for a chunk of thicknesses.
struct Edge {
    s: [f32; CHUNK],
    c: [f32; CHUNK],
}

impl Edge {
    #[inline(always)]
    fn at(q: &Split, d_hi: &[f32], d_lo: &[f32], edge: &mut Edge) {
        let n = d_hi.len();
        for (((s, c), &hi), &lo) in edge.s[..n]
            .iter_mut()
            .zip(&mut edge.c[..n])
            .zip(d_hi)
            .zip(d_lo)
        {
            (*s, *c) = sin_cos_pi(reduced_periods(q, &Split { hi, lo, full: 0.0 }));
        }
    }
}

#[inline(always)]
pub(crate) fn weighted_cell_row_body(
    row: &CellRow<'_>,
    thickness_nm: &[f32],
    out: &mut [[f32; 3]],
) {
    let mut d_hi = [0.0f32; CHUNK];
    let mut d_lo = [0.0f32; CHUNK];
    let mut inv_d = [0.0f32; CHUNK];
    let mut lo = Edge {
        s: [0.0; CHUNK],
        c: [0.0; CHUNK],
    };
    let mut hi = Edge {
        s: [0.0; CHUNK],
        c: [0.0; CHUNK],
    };
    for (chunk_index, d_chunk) in thickness_nm.chunks(CHUNK).enumerate() {
        let n = d_chunk.len();
        for (((hi, lo), inv), &d) in d_hi.iter_mut().zip(&mut d_lo).zip(&mut inv_d).zip(d_chunk) {
            let split = Split::of_f32(d);
            (*hi, *lo, *inv) = (split.hi, split.lo, 1.0 / d);
        }
        let mut acc = [[0.0f32; CHUNK]; 3];
        Edge::at(&row.edge_q[0], &d_hi[..n], &d_lo[..n], &mut lo);
        for (k, (cell, w)) in row.cells.iter().zip(row.half_weights).enumerate() {
            Edge::at(&row.edge_q[k + 1], &d_hi[..n], &d_lo[..n], &mut hi);
            accumulate_cell(cell, *w, (&lo, &hi), &inv_d[..n], &mut acc);
            std::mem::swap(&mut lo, &mut hi);
        }
        let start = chunk_index * CHUNK;
        for (i, px) in out[start..start + n].iter_mut().enumerate() {
            *px = [acc[0][i], acc[1][i], acc[2][i]];
        }
    }
}

/// `R_pol` mean over the cell for one polarisation, from the edges' sine and cosine.
#[inline(always)]
fn mean_r(a: f32, one_minus_a: f32, lo: (f32, f32), hi: (f32, f32), scale: f32) -> f32 {
    // z = (A c² + s²) + i (1 − A) s c has argument θ; θ_lo − θ_hi = arg(z_lo · conj(z_hi)).
    let (x_lo, y_lo) = (a * lo.1 * lo.1 + lo.0 * lo.0, one_minus_a * lo.0 * lo.1);
    let (x_hi, y_hi) = (a * hi.1 * hi.1 + hi.0 * hi.0, one_minus_a * hi.0 * hi.1);
    let dtheta = atan2(y_lo * x_hi - x_lo * y_hi, x_lo * x_hi + y_lo * y_hi);
    one_minus_a - a * dtheta * scale
}

#[inline(always)]
fn accumulate_cell(
    cell: &Cell,
    w: [f32; 3],
    (lo, hi): (&Edge, &Edge),
    inv_d: &[f32],
    acc: &mut [[f32; CHUNK]; 3],
) {
    let n = inv_d.len();
    let [a_s, b_s, a_p, b_p] = cell.area;
    let [r0, r1, r2] = acc;
    let edges = lo.s[..n]
        .iter()
        .zip(&lo.c[..n])
        .zip(hi.s[..n].iter().zip(&hi.c[..n]));
    let rows = edges
        .zip(inv_d)
        .zip(&mut r0[..n])
        .zip(&mut r1[..n])
        .zip(&mut r2[..n]);
    for (((((lo, hi), &inv_d), a0), a1), a2) in rows {
        let (lo, hi) = ((*lo.0, *lo.1), (*hi.0, *hi.1));
        let scale = cell.inv_span * inv_d;
        let r = mean_r(a_s, b_s, lo, hi, scale) + mean_r(a_p, b_p, lo, hi, scale);
        *a0 += w[0] * r;
        *a1 += w[1] * r;
        *a2 += w[2] * r;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn polynomials_match_libm() {
        let (mut sin, mut cos, mut atan) = (0.0f64, 0.0f64, 0.0f64);
        for k in 0..=20_000 {
            let f = -0.5 + k as f32 / 20_000.0;
            let (s, c) = sin_cos_pi(f);
            let x = std::f64::consts::PI * f as f64;
            sin = sin.max((s as f64 - x.sin()).abs());
            cos = cos.max((c as f64 - x.cos()).abs());
            let angle = std::f64::consts::TAU * f as f64;
            let (y, x) = (angle.sin() as f32 * 3.7, angle.cos() as f32 * 3.7);
            let exact = (y as f64).atan2(x as f64);
            atan = atan.max((atan2(y, x) as f64 - exact).abs());
        }
        assert!(
            sin < 3e-7 && cos < 3e-7,
            "sin off by {sin:e}, cos by {cos:e}"
        );
        assert!(atan < 5e-7, "atan2 off by {atan:e}");
    }
}
