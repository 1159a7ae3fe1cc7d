//! The tests' comparison to the bit: the AVX2 and portable builds, and fused passes and
//! the passes apart, must give the same numbers exactly, not within a tolerance.

/// How many of the places `a` and `b` both hold differ in their bits.
pub(crate) fn differing_bits(a: &[f64], b: &[f64]) -> usize {
    a.iter()
        .zip(b)
        .filter(|(a, b)| a.to_bits() != b.to_bits())
        .count()
}
