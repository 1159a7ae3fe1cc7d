//! The f32 row kernel of [`crate::grid::FilmGrid`]'s fast fill: one thickness over every
//! (angle, wavelength) cell the f32 form takes, f64 out. The phase is reduced as in the
//! per-sample kernel ([`super::kernel::reduced_periods`], whole periods cancelling exactly,
//! with the cell's `q` and the thickness both split from f64), `sin²` is the degree-9
//! polynomial [`super::kernel::sin2_pi`], and one division gives R and T of both
//! polarisations. The loop autovectorises (8 lanes with AVX2, picked at run time; no FMA
//! contraction, so bit-identical to the portable build).
//!
//! Cells near the film's critical angle or grazing incidence (the limits of
//! [`super::term::term`]) are left to the f64 path; the caller fills them.

use super::film_f64::Which;
use super::kernel::{nonzero, reduced_periods, sin2_pi};
use super::term::{MAX_PERIODS, MIN_COS_OUTSIDE, MIN_COS2_IN_FILM, Split, a_and_b};

/// Largest phase `q · d`, in periods, the row takes (`2^21`, as the per-sample kernel).
pub(crate) const MAX_PERIODS_F32: f64 = MAX_PERIODS;

/// The sharpest fringes the f32 form takes, as `a / b` (`4ρ / (1 − ρ)²`): `R`'s slope in
/// the phase peaks near `√(a/b)`, which multiplies the f32 phase's rounding (up to 3e-8
/// of a period); 64 keeps that product near 1e-6. Soap in air reaches it near 87°.
const MAX_SHARPNESS: f32 = 64.0;

/// Per-cell f32 constants, structure of arrays: the phase rate `q = 2 n₁ cos θ₁ / λ`
/// (periods per nm, split `hi + lo`, and rounded), and `a = 4ρ`, `b = (1 − ρ)²` for s and
/// p (`ρ` the single interface's reflectance): `R = a s² / (b + a s²)`, `T = b / (b + a s²)`.
#[derive(Clone, Debug, Default)]
pub(crate) struct Cells32 {
    pub q_hi: Vec<f32>,
    pub q_lo: Vec<f32>,
    pub q_full: Vec<f32>,
    pub a_s: Vec<f32>,
    pub b_s: Vec<f32>,
    pub a_p: Vec<f32>,
    pub b_p: Vec<f32>,
}

impl Cells32 {
    /// Appends one cell: the film `n_outside | n_film | n_outside` lit at `cos_outside`,
    /// refracted to `cos_film` (real, inside the film), at `wavelength_nm`. Returns `false`
    /// (and appends zeros, `R = 0`, `T = 1`) where the f32 form is not accurate: within
    /// reach of the film's critical angle or of grazing incidence, or fringes sharper than
    /// [`MAX_SHARPNESS`].
    pub(crate) fn push(
        &mut self,
        n_outside: f64,
        n_film: f64,
        cos_outside: f64,
        cos_film: f64,
        wavelength_nm: f64,
    ) -> bool {
        let propagating = cos_film * cos_film >= MIN_COS2_IN_FILM && cos_outside >= MIN_COS_OUTSIDE;
        let (s, p) = (
            a_and_b(n_outside * cos_outside, n_film * cos_film),
            a_and_b(n_outside * cos_film, n_film * cos_outside),
        );
        let blunt = |(a, b): (f32, f32)| a <= MAX_SHARPNESS * b;
        let ok = propagating && blunt(s) && blunt(p);
        let (q, (a_s, b_s), (a_p, b_p)) = if ok {
            (2.0 * n_film * cos_film / wavelength_nm, s, p)
        } else {
            (0.0, (0.0, 1.0), (0.0, 1.0))
        };
        let q = Split::of_f64(q);
        self.q_hi.push(q.hi);
        self.q_lo.push(q.lo);
        self.q_full.push(q.full);
        self.a_s.push(a_s);
        self.b_s.push(b_s);
        self.a_p.push(a_p);
        self.b_p.push(b_p);
        ok
    }

    /// The largest `q` over the cells, periods per nm.
    pub(crate) fn max_q(&self) -> f64 {
        self.q_full
            .iter()
            .fold(0.0, |m: f64, &q| m.max(f64::from(q)))
    }
}

/// `R` and `T` of a film `thickness_nm` thick at cells `first..first + r.len()`; requires
/// `max q · thickness_nm ≤ MAX_PERIODS_F32` (with margin for `q`'s rounding), `t` as long
/// as `r` and the cells in range.
pub(crate) fn row(
    cells: &Cells32,
    first: usize,
    thickness_nm: f64,
    which: Which,
    r: &mut [f64],
    t: &mut [f64],
) {
    let end = first + r.len();
    let cells = Ref {
        q_hi: &cells.q_hi[first..end],
        q_lo: &cells.q_lo[first..end],
        q_full: &cells.q_full[first..end],
        a_s: &cells.a_s[first..end],
        b_s: &cells.b_s[first..end],
        a_p: &cells.a_p[first..end],
        b_p: &cells.b_p[first..end],
    };
    let d = Split::of_f64(thickness_nm);
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU supports AVX2, checked just above.
        unsafe { row_avx2(&cells, d, which, r, t) };
        return;
    }
    row_body(&cells, d, which, r, t);
}

/// A range of [`Cells32`].
struct Ref<'a> {
    q_hi: &'a [f32],
    q_lo: &'a [f32],
    q_full: &'a [f32],
    a_s: &'a [f32],
    b_s: &'a [f32],
    a_p: &'a [f32],
    b_p: &'a [f32],
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn row_avx2(cells: &Ref<'_>, d: Split, which: Which, r: &mut [f64], t: &mut [f64]) {
    row_body(cells, d, which, r, t);
}

/// Points computed together in f32 before they are widened to f64: the f32 loop then
/// runs 8 lanes wide (with the f64 stores in the same loop LLVM picks 4).
const BLOCK: usize = 64;

#[inline(always)]
fn row_body(c: &Ref<'_>, d: Split, which: Which, r: &mut [f64], t: &mut [f64]) {
    let n = c.q_hi.len();
    let (r, t) = (&mut r[..n], &mut t[..n]);
    let (mut r32, mut t32) = ([0.0f32; BLOCK], [0.0f32; BLOCK]);
    let mut start = 0;
    while start < n {
        let len = BLOCK.min(n - start);
        let range = start..start + len;
        let block = Ref {
            q_hi: &c.q_hi[range.clone()],
            q_lo: &c.q_lo[range.clone()],
            q_full: &c.q_full[range.clone()],
            a_s: &c.a_s[range.clone()],
            b_s: &c.b_s[range.clone()],
            a_p: &c.a_p[range.clone()],
            b_p: &c.b_p[range.clone()],
        };
        block_f32(&block, d, which, &mut r32[..len], &mut t32[..len]);
        for (out, v) in r[range.clone()].iter_mut().zip(&r32[..len]) {
            *out = f64::from(*v);
        }
        for (out, v) in t[range].iter_mut().zip(&t32[..len]) {
            *out = f64::from(*v);
        }
        start += len;
    }
}

/// One block of [`row_body`] in f32.
#[inline(always)]
fn block_f32(c: &Ref<'_>, d: Split, which: Which, r: &mut [f32], t: &mut [f32]) {
    let n = r.len();
    let (q_hi, q_lo, q_full) = (&c.q_hi[..n], &c.q_lo[..n], &c.q_full[..n]);
    let t = &mut t[..n];
    let s2 = |i: usize| {
        let q = Split {
            hi: q_hi[i],
            lo: q_lo[i],
            full: q_full[i],
        };
        sin2_pi(reduced_periods(&q, &d))
    };
    match which {
        Which::S | Which::P => {
            let (a, b) = match which {
                Which::S => (&c.a_s[..n], &c.b_s[..n]),
                _ => (&c.a_p[..n], &c.b_p[..n]),
            };
            for i in 0..n {
                let num = a[i] * s2(i);
                let inv = 1.0 / nonzero(b[i] + num);
                r[i] = num * inv;
                t[i] = b[i] * inv;
            }
        }
        Which::Mean => {
            let (a_s, b_s) = (&c.a_s[..n], &c.b_s[..n]);
            let (a_p, b_p) = (&c.a_p[..n], &c.b_p[..n]);
            for i in 0..n {
                let s2 = s2(i);
                let (num_s, num_p) = (a_s[i] * s2, a_p[i] * s2);
                let (den_s, den_p) = (b_s[i] + num_s, b_p[i] + num_p);
                let half_inv = 0.5 / nonzero(den_s * den_p);
                r[i] = (num_s * den_p + num_p * den_s) * half_inv;
                t[i] = (b_s[i] * den_p + b_p[i] * den_s) * half_inv;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cells() -> Cells32 {
        let mut cells = Cells32::default();
        for k in 0..301 {
            let cos_outside = 1.0 - k as f64 / 310.0;
            let sin2 = 1.0 - cos_outside * cos_outside;
            let n_film = 1.2 + 0.01 * (k % 50) as f64;
            let cos_film = (1.0 - sin2 / (n_film * n_film)).sqrt();
            cells.push(1.0, n_film, cos_outside, cos_film, 360.0 + 1.57 * k as f64);
        }
        cells
    }

    #[test]
    fn dispatched_and_portable_builds_are_bit_identical() {
        let cells = cells();
        for which in [Which::S, Which::P, Which::Mean] {
            for d in [0.0, 7.25, 333.3, 1999.0, 123_456.7] {
                let n = cells.q_hi.len();
                let (mut r1, mut t1) = (vec![0.0; n], vec![0.0; n]);
                let (mut r2, mut t2) = (vec![0.0; n], vec![0.0; n]);
                row(&cells, 0, d, which, &mut r1, &mut t1);
                let all = Ref {
                    q_hi: &cells.q_hi,
                    q_lo: &cells.q_lo,
                    q_full: &cells.q_full,
                    a_s: &cells.a_s,
                    b_s: &cells.b_s,
                    a_p: &cells.a_p,
                    b_p: &cells.b_p,
                };
                row_body(&all, Split::of_f64(d), which, &mut r2, &mut t2);
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&r1), bits(&r2), "R at d = {d}");
                assert_eq!(bits(&t1), bits(&t2), "T at d = {d}");
            }
        }
    }

    #[test]
    fn cells_the_f32_form_cannot_hold_are_refused() {
        let mut cells = Cells32::default();
        assert!(cells.push(1.0, 1.33, 0.5, 0.9, 500.0));
        assert!(
            !cells.push(1.33, 1.0, 0.9, 0.005, 500.0),
            "inside the film, 89.7°"
        );
        assert!(!cells.push(1.0, 1.33, 1e-7, 0.6, 500.0), "grazing");
        // Soap at 86° (a/b = 43) and 88° (a/b = 160): sharp fringes.
        let soap = |deg: f64| {
            let cos = deg.to_radians().cos();
            (cos, (1.0 - (1.0 - cos * cos) / (1.33 * 1.33)).sqrt())
        };
        let ((c86, f86), (c88, f88)) = (soap(86.0), soap(88.0));
        assert!(Cells32::default().push(1.0, 1.33, c86, f86, 500.0), "86°");
        assert!(!Cells32::default().push(1.0, 1.33, c88, f88, 500.0), "88°");
        assert_eq!(cells.a_s[1], 0.0);
        assert_eq!(cells.b_s[2], 1.0);
    }
}
