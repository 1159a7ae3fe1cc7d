//! [`index_f32`]: an index or size as `f32`, in the conversion x86-64 does cheaply.

/// `i as f32` for an index or size below 2³¹, through `i32`: the same value (both round
/// the same integer to nearest), in one instruction, where `usize` (an unsigned 64-bit
/// integer) takes about eight on x86-64 without AVX-512 and does not vectorise.
#[inline(always)]
pub fn index_f32(i: usize) -> f32 {
    i as i32 as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn index_f32_equals_the_direct_conversion_below_two_to_the_31() {
        let mut i = 1usize;
        while i < 1 << 31 {
            for j in [i - 1, i, i + 1, i + i / 3] {
                if j < 1 << 31 {
                    assert_eq!(index_f32(j).to_bits(), (j as f32).to_bits(), "{j}");
                }
            }
            i = i * 3 / 2 + 1;
        }
    }
}
