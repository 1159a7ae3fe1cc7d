//! FNV-1a 64-bit checksums that `lut.json` records for every texture file.
//!
//! Uncompressed EXR decodes happily after a flipped bit, so the decoder alone cannot
//! see corruption; the checksum of the decoded values can.

const OFFSET_BASIS: u64 = 0xcbf2_9ce4_8422_2325;
const PRIME: u64 = 0x0000_0100_0000_01b3;

/// FNV-1a over the little-endian bytes of every `f32` of every texel, in row-major order.
pub(crate) fn texels_fnv1a64(texels: &[[f32; 3]]) -> u64 {
    texels
        .iter()
        .flatten()
        .fold(OFFSET_BASIS, |h, v| feed(h, &v.to_bits().to_le_bytes()))
}

/// FNV-1a over the little-endian bytes of every 16-bit code, in row-major order.
pub(crate) fn codes_fnv1a64(codes: &[u16]) -> u64 {
    codes
        .iter()
        .fold(OFFSET_BASIS, |h, v| feed(h, &v.to_le_bytes()))
}

fn feed(mut hash: u64, bytes: &[u8]) -> u64 {
    for &b in bytes {
        hash ^= u64::from(b);
        hash = hash.wrapping_mul(PRIME);
    }
    hash
}

/// The 16-hex-digit form written to `lut.json`.
pub(crate) fn to_hex(hash: u64) -> String {
    format!("{hash:016x}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_published_fnv1a64_vectors() {
        // Reference values from the FNV authors' test suite.
        assert_eq!(feed(OFFSET_BASIS, b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(feed(OFFSET_BASIS, b"a"), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(feed(OFFSET_BASIS, b"foobar"), 0x8594_4171_f739_67e8);
    }

    #[test]
    fn one_flipped_bit_changes_the_sum() {
        let a = [[0.25f32, 0.5, 1.0]; 4];
        let mut b = a;
        b[2][1] = f32::from_bits(b[2][1].to_bits() ^ 1);
        assert_ne!(texels_fnv1a64(&a), texels_fnv1a64(&b));
    }
}
