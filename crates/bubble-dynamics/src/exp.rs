//! `eˣ` without a branch or a library call, so that a loop over cells that takes one
//! per cell vectorises: the warmed film's evaporation takes `exp` of every cell's
//! temperature each step ([`ThermalParams::evaporation_factor`]), and libm's scalar
//! `exp` cost 1.35 M instructions a step at n = 64, 8 % of the `swirl` scene's film
//! step (docs/performance.md, "Fifteenth round").
//!
//! The method is Cody and Waite's: `x = k ln 2 + r` with `k` the nearest integer to
//! `x / ln 2` and `|r| ≤ ln 2 / 2`, `ln 2` split in two so that `k ln 2` is exact in its
//! high part; `eʳ` by its Taylor series to `r¹³/13!` (the remainder below 5e-18 of it);
//! `2ᵏ` put together from its bits. Each step is an IEEE operation in a fixed order, so
//! the answer is the same on every target and in every build (the portable one and
//! AVX2), as libm's need not be.
//!
//! [`ThermalParams::evaporation_factor`]: crate::film_flow::ThermalParams::evaporation_factor

/// `ln 2`'s high part: its leading 32 bits, so that `k · LN_2_HIGH` is exact for every
/// `|k| < 2²⁰`.
const LN_2_HIGH: f64 = f64::from_bits(0x3fe6_2e42_fee0_0000);
/// `ln 2 − LN_2_HIGH`.
const LN_2_LOW: f64 = 1.908_214_929_270_587_7e-10;
/// Adding and subtracting `1.5 · 2⁵²` rounds a number below `2⁵¹` in magnitude to the
/// nearest integer (ties to even), and leaves the integer in the sum's low bits.
const ROUNDER: f64 = 6_755_399_441_055_744.0;
/// `1/n!` for `n` = 2 … 13, the Taylor series' coefficients past `1 + r`.
const INVERSE_FACTORIALS: [f64; 12] = [
    1.0 / 2.0,
    1.0 / 6.0,
    1.0 / 24.0,
    1.0 / 120.0,
    1.0 / 720.0,
    1.0 / 5_040.0,
    1.0 / 40_320.0,
    1.0 / 362_880.0,
    1.0 / 3_628_800.0,
    1.0 / 39_916_800.0,
    1.0 / 479_001_600.0,
    1.0 / 6_227_020_800.0,
];
/// The arguments below which `eˣ` is taken at this one (about 3e-308, where the
/// subnormals begin), and above which at this one (about 8e307, short of `f64::MAX`).
const LOWEST: f64 = -708.0;
/// See [`LOWEST`].
const HIGHEST: f64 = 709.0;

/// `eˣ` within 2 units in the last place of the rounded value for `x` in
/// [−708, 709] (`e⁻⁷⁰⁸` below it, `e⁷⁰⁹` above it); NaN for NaN.
#[inline(always)]
pub(crate) fn exp(x: f64) -> f64 {
    // `clamp`, not `max`/`min`: a NaN goes through to the answer.
    let x = x.clamp(LOWEST, HIGHEST);
    let shifted = x * std::f64::consts::LOG2_E + ROUNDER;
    let k = shifted - ROUNDER;
    let r = (x - k * LN_2_HIGH) - k * LN_2_LOW;
    let mut series = INVERSE_FACTORIALS[11];
    for c in INVERSE_FACTORIALS[..11].iter().rev() {
        series = series * r + c;
    }
    let e_r = 1.0 + r + (r * r) * series;
    // `shifted`'s bits are `ROUNDER`'s plus `k` (an integer in [−1022, 1023] here).
    let k_bits = shifted.to_bits().wrapping_sub(ROUNDER.to_bits());
    let two_to_k = f64::from_bits(k_bits.wrapping_add(1023) << 52);
    e_r * two_to_k
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// How many representable numbers lie between `a` and `b` (both finite, positive).
    fn ulps_apart(a: f64, b: f64) -> u64 {
        a.to_bits().abs_diff(b.to_bits())
    }

    fn assert_within_2_ulps(x: f64) {
        let (ours, libm) = (exp(x), x.exp());
        let apart = ulps_apart(ours, libm);
        assert!(
            apart <= 2,
            "exp({x:e}) = {ours:e} against libm's {libm:e}: {apart} ulps apart"
        );
    }

    proptest! {
        /// Within 2 ulps of libm (itself within 1 of the true value) over the whole
        /// range.
        #[test]
        fn agrees_with_libm_over_the_range(x in LOWEST..HIGHEST) {
            assert_within_2_ulps(x);
        }

        /// And where the evaporation factor takes it: |x| up to about 2.
        #[test]
        fn agrees_with_libm_near_zero(x in -3.0..3.0_f64) {
            assert_within_2_ulps(x);
        }
    }

    #[test]
    fn exact_and_edge_values() {
        assert_eq!(exp(0.0), 1.0);
        assert_within_2_ulps(1.0);
        assert_within_2_ulps(-1e-300);
        // Halfway cases of the rounding to k, where r reaches ±ln 2 / 2.
        for k in [-3.0, -1.0, 1.0, 7.0] {
            assert_within_2_ulps((k + 0.5) * std::f64::consts::LN_2);
        }
        assert_eq!(exp(-1000.0), exp(LOWEST));
        assert_eq!(exp(1000.0), exp(HIGHEST));
        assert!(exp(HIGHEST).is_finite() && exp(LOWEST) > 0.0);
        assert!(exp(f64::NAN).is_nan());
        assert_eq!(exp(f64::NEG_INFINITY), exp(LOWEST));
    }
}
