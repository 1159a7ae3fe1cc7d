//! f64 sine and cosine without libm calls, for the autovectorised kernels of
//! [`super::film_f64`] and [`super::stack_f64`] (libm's calls stop the loops vectorising).
//!
//! The argument is reduced by `k π/2` with a three-part Cody–Waite split of π/2 (the first
//! two parts have 33 significant bits, so `k · part` is exact for `|k| < 2^20`), then
//! `sin r` and `cos r` on `|r| ≤ π/4` are fdlibm's degree-13 and degree-14 minimax
//! polynomials (relative error below 2^-58), and the quadrant `k mod 4` swaps and signs
//! them with selects and sign-bit flips, never by arithmetic that could round. Callers keep
//! `|x| ≤ MAX_ARG`.

/// Largest `|x|` the reduction takes: `|k| ≤ 2^19`, far inside the exact range.
pub(crate) const MAX_ARG: f64 = 8.0e5;

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
#[allow(clippy::excessive_precision)] // fdlibm's published digits
const C1: f64 = 4.166_666_666_666_660_190_37e-02;
#[allow(clippy::excessive_precision)] // fdlibm's published digits
const C2: f64 = -1.388_888_888_887_410_957_49e-03;
#[allow(clippy::excessive_precision)] // fdlibm's published digits
const C3: f64 = 2.480_158_728_947_672_941_78e-05;
#[allow(clippy::excessive_precision)] // fdlibm's published digits
const C4: f64 = -2.755_731_435_139_066_330_35e-07;
#[allow(clippy::excessive_precision)] // fdlibm's published digits
const C5: f64 = 2.087_572_321_298_174_827_90e-09;
#[allow(clippy::excessive_precision)] // fdlibm's published digits
const C6: f64 = -1.135_964_755_778_819_482_65e-11;
/// `1.5 · 2^52`: adding and subtracting it rounds to the nearest integer (`|y| < 2^51`).
const ROUND: f64 = 6_755_399_441_055_744.0;

/// `sin²x` for `|x| ≤ MAX_ARG`.
#[inline(always)]
pub(crate) fn sin_squared(x: f64) -> f64 {
    let shifted = x * TWO_OVER_PI + ROUND;
    // All ones in an odd quadrant (where sin² x = cos² r = 1 − sin² r), else zero: a
    // select by bits, which vectorises without an integer-to-float conversion.
    let odd = (shifted.to_bits() & 1).wrapping_neg();
    let k = shifted - ROUND;
    let r = ((x - k * PIO2_1) - k * PIO2_2) - k * PIO2_3;
    let z = r * r;
    let s = r + r * z * (S1 + z * (S2 + z * (S3 + z * (S4 + z * (S5 + z * S6)))));
    let s2 = s * s;
    f64::from_bits((s2.to_bits() & !odd) | ((1.0 - s2).to_bits() & odd))
}

/// `(sin x, cos x)` for `|x| ≤ MAX_ARG`, each within 2 ulp of libm's.
#[inline(always)]
pub(crate) fn sin_cos(x: f64) -> (f64, f64) {
    let shifted = x * TWO_OVER_PI + ROUND;
    // `ROUND` is a multiple of 4, so the low bits are `k mod 4` for either sign of `k`.
    let quadrant = shifted.to_bits() & 3;
    let k = shifted - ROUND;
    let r = ((x - k * PIO2_1) - k * PIO2_2) - k * PIO2_3;
    let z = r * r;
    let sin_r = r + r * z * (S1 + z * (S2 + z * (S3 + z * (S4 + z * (S5 + z * S6)))));
    let half_z = 0.5 * z;
    let w = 1.0 - half_z;
    let poly = z * (C1 + z * (C2 + z * (C3 + z * (C4 + z * (C5 + z * C6)))));
    // fdlibm's `w + ((1 − w) − z/2 + z·poly)`: `1 − z/2` rounded, plus what it lost.
    let cos_r = w + (((1.0 - w) - half_z) + z * poly);
    let swap = quadrant & 1 == 1;
    let (sin_abs, cos_abs) = if swap { (cos_r, sin_r) } else { (sin_r, cos_r) };
    // sin is negative in quadrants 2 and 3, cos in quadrants 1 and 2.
    let sin_flip = (quadrant >> 1) << 63;
    let cos_flip = (((quadrant + 1) >> 1) & 1) << 63;
    (
        f64::from_bits(sin_abs.to_bits() ^ sin_flip),
        f64::from_bits(cos_abs.to_bits() ^ cos_flip),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sin_squared_matches_libm_over_its_range() {
        let mut worst = 0.0f64;
        let mut x = -MAX_ARG;
        let mut k = 0u64;
        while x <= MAX_ARG {
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

    #[test]
    fn sin_cos_matches_libm_over_its_range() {
        let (mut worst_sin, mut worst_cos) = (0.0f64, 0.0f64);
        let mut x = -MAX_ARG;
        let mut k = 0u64;
        let mut check = |x: f64| {
            let (s, c) = sin_cos(x);
            worst_sin = worst_sin.max((s - x.sin()).abs());
            worst_cos = worst_cos.max((c - x.cos()).abs());
        };
        while x <= MAX_ARG {
            check(x);
            k += 1;
            x += 0.377 + (k % 7) as f64 * 0.0131;
        }
        for x in [
            0.0, -0.0, 1e-300, 1e-8, 0.785, 0.786, 1.57, 3.2, -2.0, 4.0, 5.5,
        ] {
            check(x);
        }
        assert!(
            worst_sin < 2.0 * f64::EPSILON,
            "sin: worst |diff| {worst_sin:e}"
        );
        assert!(
            worst_cos < 2.0 * f64::EPSILON,
            "cos: worst |diff| {worst_cos:e}"
        );
    }
}
