//! The per-thickness loops of the f32 fast path, written so LLVM autovectorises them,
//! and the one place with explicit SIMD: an AVX2 build of the same loops chosen at run
//! time, with the portable build as fallback. Both perform the same IEEE operations in
//! the same order (no fused multiply-adds), so they give bit-identical results.

use super::term::{
    MAX_PERIODS, MIN_COS_OUTSIDE, MIN_COS2_IN_FILM, Split, Term, Wave, a_and_b, term,
};

/// Thicknesses processed together: accumulators for one chunk stay in L1.
pub(crate) const CHUNK: usize = 256;

/// `1.5 · 2^23`: adding and subtracting it rounds an f32 below `2^22` to an integer.
const ROUND_MAGIC: f32 = 12_582_912.0;

/// Odd minimax polynomial for `sin(π f)` on `f ∈ [−½, ½]`: `f (c1 + f²(c3 + f²(c5 + f²(c7 + f² c9))))`,
/// max absolute error 4.6e-9 before f32 rounding.
const SIN_PI: [f32; 5] = [
    std::f32::consts::PI,
    -5.167_71,
    2.550_067_4,
    -0.598_217_84,
    0.077_505_276,
];

/// The round-trip phase `q · d` in periods, reduced to `[−½, ½]` (up to rounding), all in
/// f32: `d.hi · q.hi` is exact, so the whole periods cancel exactly and the fraction keeps
/// an absolute error of about `q·d · 2^-36` periods (1e-9 for a 3 µm film).
/// Requires `q · d < 2^21`.
#[inline(always)]
pub(crate) fn reduced_periods(q: &Split, d: &Split) -> f32 {
    let exact = d.hi * q.hi;
    let rest = d.hi * q.lo + d.lo * q.full;
    let nearest = ((exact + rest) + ROUND_MAGIC) - ROUND_MAGIC;
    (exact - nearest) + rest
}

/// `sin²(π f)` for a reduced phase `f`. `sin²` has period 1, so no quadrant bookkeeping.
#[inline(always)]
pub(crate) fn sin2_pi(f: f32) -> f32 {
    let f2 = f * f;
    let [c1, c3, c5, c7, c9] = SIN_PI;
    let s = f * (c1 + f2 * (c3 + f2 * (c5 + f2 * (c7 + f2 * c9))));
    s * s
}

/// Keeps a denominator off zero: it is zero only when its numerator is too (a lossless
/// film at an exact resonance of a total reflector), where the answer is 0.
#[inline(always)]
pub(super) fn nonzero(den: f32) -> f32 {
    if den > f32::MIN_POSITIVE {
        den
    } else {
        f32::MIN_POSITIVE
    }
}

/// `(4ρ_s² s², 4ρ_p² s², (1 − ρ_s²)² + 4ρ_s² s², (1 − ρ_p²)² + 4ρ_p² s²)` for `s2 = sin²(δ/2)`.
#[inline(always)]
fn parts(wave: &Wave, s2: f32) -> (f32, f32, f32, f32) {
    let num_s = wave.a_s * s2;
    let num_p = wave.a_p * s2;
    (num_s, num_p, wave.b_s + num_s, wave.b_p + num_p)
}

/// `R_s + R_p` (a sum, not the mean) over one common denominator: one division.
#[inline(always)]
fn sum_r(wave: &Wave, s2: f32) -> f32 {
    let (num_s, num_p, den_s, den_p) = parts(wave, s2);
    (num_s * den_p + num_p * den_s) / nonzero(den_s * den_p)
}

/// `T_s + T_p` (a sum, not the mean), from its own numerator `(1 − ρ²)²`, not `1 − R`.
#[inline(always)]
fn sum_t(wave: &Wave, s2: f32) -> f32 {
    let (_, _, den_s, den_p) = parts(wave, s2);
    (wave.b_s * den_p + wave.b_p * den_s) / nonzero(den_s * den_p)
}

/// Unpolarised `(R, T)` of one wave at one thickness.
#[inline(always)]
pub(crate) fn mean_r_t(wave: &Wave, thickness_nm: Split) -> (f32, f32) {
    let s2 = sin2_pi(reduced_periods(&wave.periods_per_nm, &thickness_nm));
    (0.5 * sum_r(wave, s2), 0.5 * sum_t(wave, s2))
}

/// Output rows for [`weighted_row`]: reflectance, and transmittance when `WITH_T`.
pub(crate) struct RowOut<'a> {
    pub r: &'a mut [[f32; 3]],
    pub t: &'a mut [[f32; 3]],
}

/// `out.r[i] = Σ_k w_k R_k(d_i)` (and `out.t` likewise when `WITH_T`), where `half_weights`
/// are the weights already halved (the polarisation mean).
pub(crate) fn weighted_row<const WITH_T: bool>(
    terms: &[Term],
    half_weights: &[[f32; 3]],
    thickness_nm: &[f32],
    out: RowOut<'_>,
) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU supports AVX2, checked just above.
        unsafe { weighted_row_avx2::<WITH_T>(terms, half_weights, thickness_nm, out) };
        return;
    }
    weighted_row_body::<WITH_T>(terms, half_weights, thickness_nm, out);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn weighted_row_avx2<const WITH_T: bool>(
    terms: &[Term],
    half_weights: &[[f32; 3]],
    thickness_nm: &[f32],
    out: RowOut<'_>,
) {
    weighted_row_body::<WITH_T>(terms, half_weights, thickness_nm, out);
}

/// Accumulators for one chunk of thicknesses, per colour channel.
struct Acc {
    r: [[f32; CHUNK]; 3],
    t: [[f32; CHUNK]; 3],
}

#[inline(always)]
pub(crate) fn weighted_row_body<const WITH_T: bool>(
    terms: &[Term],
    half_weights: &[[f32; 3]],
    thickness_nm: &[f32],
    out: RowOut<'_>,
) {
    let mut d_hi = [0.0f32; CHUNK];
    let mut d_lo = [0.0f32; CHUNK];
    for (chunk_index, d_chunk) in thickness_nm.chunks(CHUNK).enumerate() {
        let n = d_chunk.len();
        for ((hi, lo), &d) in d_hi.iter_mut().zip(&mut d_lo).zip(d_chunk) {
            let split = Split::of_f32(d);
            (*hi, *lo) = (split.hi, split.lo);
        }
        let mut acc = Acc {
            r: [[0.0; CHUNK]; 3],
            t: [[0.0; CHUNK]; 3],
        };
        for (term, &w) in terms.iter().zip(half_weights) {
            match term {
                Term::Wave(wave) => {
                    accumulate_wave::<WITH_T>(wave, w, (&d_hi[..n], &d_lo[..n]), &mut acc)
                }
                other => accumulate_scalar::<WITH_T>(other, w, d_chunk, &mut acc),
            }
        }
        let start = chunk_index * CHUNK;
        write_chunk(&acc.r, &mut out.r[start..start + n]);
        if WITH_T {
            write_chunk(&acc.t, &mut out.t[start..start + n]);
        }
    }
}

fn write_chunk(acc: &[[f32; CHUNK]; 3], out: &mut [[f32; 3]]) {
    for (i, px) in out.iter_mut().enumerate() {
        *px = [acc[0][i], acc[1][i], acc[2][i]];
    }
}

/// The hot loop: one wavelength over a chunk of thicknesses (split as `hi + lo`).
#[inline(always)]
fn accumulate_wave<const WITH_T: bool>(
    wave: &Wave,
    w: [f32; 3],
    (d_hi, d_lo): (&[f32], &[f32]),
    acc: &mut Acc,
) {
    let n = d_hi.len();
    let q = wave.periods_per_nm;
    let [r0, r1, r2] = &mut acc.r;
    let [t0, t1, t2] = &mut acc.t;
    let d = d_hi.iter().zip(&d_lo[..n]);
    let rows = d.zip(&mut r0[..n]).zip(&mut r1[..n]).zip(&mut r2[..n]);
    let phase =
        |(&hi, &lo): (&f32, &f32)| sin2_pi(reduced_periods(&q, &Split { hi, lo, full: 0.0 }));
    if WITH_T {
        let t_rows = t0[..n].iter_mut().zip(&mut t1[..n]).zip(&mut t2[..n]);
        for ((((d, a0), a1), a2), ((b0, b1), b2)) in rows.zip(t_rows) {
            let s2 = phase(d);
            let (r, t) = (sum_r(wave, s2), sum_t(wave, s2));
            *a0 += w[0] * r;
            *a1 += w[1] * r;
            *a2 += w[2] * r;
            *b0 += w[0] * t;
            *b1 += w[1] * t;
            *b2 += w[2] * t;
        }
    } else {
        for (((d, a0), a1), a2) in rows {
            let r = sum_r(wave, phase(d));
            *a0 += w[0] * r;
            *a1 += w[1] * r;
            *a2 += w[2] * r;
        }
    }
}

/// Terms that are not a plain wave: thickness-independent, or the f64 reference.
fn accumulate_scalar<const WITH_T: bool>(term: &Term, w: [f32; 3], d: &[f32], acc: &mut Acc) {
    for (i, &thickness_nm) in d.iter().enumerate() {
        let (r, t) = term.evaluate(thickness_nm);
        // `evaluate` gives means; the weights are halved, so double back.
        let (r, t) = (2.0 * r, 2.0 * t);
        for (c, w_c) in w.iter().enumerate() {
            acc.r[c][i] += w_c * r;
            if WITH_T {
                acc.t[c][i] += w_c * t;
            }
        }
    }
}

/// Inputs of the per-sample path: one symmetric film, per-sample geometry.
pub(crate) struct Samples<'a> {
    pub n_outside: f64,
    pub n_film: f64,
    pub thickness_nm: &'a [f32],
    pub cos_theta: &'a [f32],
    pub wavelength_nm: &'a [f32],
}

/// Per-sample `(R, T)` for a symmetric film, `out_t` filled when `WITH_T`.
pub(crate) fn samples<const WITH_T: bool>(
    input: &Samples<'_>,
    out_r: &mut [f32],
    out_t: &mut [f32],
) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU supports AVX2, checked just above.
        unsafe { samples_avx2::<WITH_T>(input, out_r, out_t) };
        return;
    }
    samples_body::<WITH_T>(input, out_r, out_t);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn samples_avx2<const WITH_T: bool>(input: &Samples<'_>, out_r: &mut [f32], out_t: &mut [f32]) {
    samples_body::<WITH_T>(input, out_r, out_t);
}

/// Branch-free pass assuming a propagating film, then a fix-up pass for the samples
/// that need another method (see [`super::term::term`]).
#[inline(always)]
pub(crate) fn samples_body<const WITH_T: bool>(
    input: &Samples<'_>,
    out_r: &mut [f32],
    out_t: &mut [f32],
) {
    let (n0, n1) = (input.n_outside, input.n_film);
    let ratio2 = (n0 / n1) * (n0 / n1);
    let n = input.thickness_nm.len();
    let (thickness_nm, cos_theta) = (&input.thickness_nm[..n], &input.cos_theta[..n]);
    let wavelength_nm = &input.wavelength_nm[..n];
    let out_r = &mut out_r[..n];
    let out_t = if WITH_T { &mut out_t[..n] } else { out_t };
    for i in 0..n {
        let cos0 = cos_theta[i] as f64;
        let cos2_film = 1.0 - ratio2 * (1.0 - cos0 * cos0);
        let cos1 = cos2_film.max(MIN_COS2_IN_FILM).sqrt();
        let (a_s, b_s) = a_and_b(n0 * cos0, n1 * cos1);
        let (a_p, b_p) = a_and_b(n0 * cos1, n1 * cos0);
        let wave = Wave {
            a_s,
            b_s,
            a_p,
            b_p,
            periods_per_nm: Split::of_f64(2.0 * n1 * cos1 / wavelength_nm[i] as f64),
        };
        let (r, t) = mean_r_t(&wave, Split::of_f32(thickness_nm[i]));
        out_r[i] = r;
        if WITH_T {
            out_t[i] = t;
        }
    }
    for i in 0..n {
        let (d, cos0, wavelength_nm) = (
            thickness_nm[i] as f64,
            cos_theta[i] as f64,
            wavelength_nm[i] as f64,
        );
        let cos2_film = 1.0 - ratio2 * (1.0 - cos0 * cos0);
        // Conservative (cos θ_t ≤ 1): a sample flagged needlessly is still evaluated right.
        let flagged = cos2_film < MIN_COS2_IN_FILM
            || cos0 < MIN_COS_OUTSIDE
            || 2.0 * n1 * d / wavelength_nm > MAX_PERIODS;
        if flagged {
            let (r, t) = term(n0, n1, cos0, wavelength_nm, d).evaluate(d as f32);
            out_r[i] = r;
            if WITH_T {
                out_t[i] = t;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sin2_polynomial_matches_libm() {
        let mut worst = 0.0f64;
        for k in 0..=20_000 {
            let f = -0.5 + k as f32 / 20_000.0;
            let exact = (std::f64::consts::PI * f as f64).sin().powi(2);
            worst = worst.max((sin2_pi(f) as f64 - exact).abs());
        }
        // A few f32 ulps of 1.0 from the Horner steps; the polynomial itself is good to 5e-9.
        assert!(worst < 5e-7, "worst |sin² error| = {worst:e}");
    }

    #[test]
    fn phase_reduction_keeps_the_fraction_exact() {
        let mut worst = 0.0f64;
        for i in 0..4000 {
            let q = 0.001 + 0.017 * (i as f64 * 0.618_034).fract();
            let d = (i as f32 * 97.31) % 200_000.0;
            let exact = q * d as f64;
            let f = reduced_periods(&Split::of_f64(q), &Split::of_f32(d)) as f64;
            assert!(f.abs() <= 0.5 + 1e-6, "q {q} d {d}: fraction {f}");
            let off = (f - (exact - exact.round())).abs();
            worst = worst.max(off.min(1.0 - off));
        }
        assert!(worst < 2e-7, "worst phase error {worst:e} periods");
    }

    #[test]
    fn dispatched_and_portable_builds_are_bit_identical() {
        let wavelengths = [380.0, 455.5, 532.0, 611.0, 700.0, 829.0];
        let terms: Vec<Term> = wavelengths
            .iter()
            .map(|&l| term(1.0, 1.33 + 0.01 * (l - 380.0) / 450.0, 0.37, l, 5000.0))
            .collect();
        let weights: Vec<[f32; 3]> = (0..terms.len())
            .map(|k| [0.1 * k as f32, 0.3, 1.0 / (1.0 + k as f32)])
            .collect();
        let thickness: Vec<f32> = (0..700).map(|i| i as f32 * 7.123).collect();
        let run = |portable: bool| {
            let mut r = vec![[0.0f32; 3]; thickness.len()];
            let mut t = vec![[0.0f32; 3]; thickness.len()];
            let out = RowOut {
                r: &mut r,
                t: &mut t,
            };
            if portable {
                weighted_row_body::<true>(&terms, &weights, &thickness, out);
            } else {
                weighted_row::<true>(&terms, &weights, &thickness, out);
            }
            (r, t)
        };
        let (a, b) = (run(true), run(false));
        for (i, d) in thickness.iter().enumerate() {
            assert_eq!(
                a.0[i].map(f32::to_bits),
                b.0[i].map(f32::to_bits),
                "R d={d}"
            );
            assert_eq!(
                a.1[i].map(f32::to_bits),
                b.1[i].map(f32::to_bits),
                "T d={d}"
            );
        }
    }

    #[test]
    fn sin2_reduction_is_exact_at_whole_periods() {
        for m in [0.0, 1.0, 17.0, 123_456.0, 2_000_000.0] {
            let d = Split::of_f32(m);
            let q = Split::of_f64(1.0);
            assert_eq!(sin2_pi(reduced_periods(&q, &d)), 0.0, "periods {m}");
        }
    }
}
