//! Where a pixel's camera rays go: a 2-D Sobol sequence with hash-based Owen scrambling
//! (Burley 2020), scrambled per pixel from the seed.
//!
//! The first `2^m` points of the unscrambled sequence put one point in every elementary
//! interval of area `2^-m` (a (0, m, 2)-net); Owen scrambling keeps that and makes each
//! pixel's points an independent random net. So every power-of-two prefix is stratified
//! in rows, columns and every shape between, and each doubling of the count fills the
//! strata the previous points left: the adaptive loop in `lib.rs` can stop at any
//! doubling with a stratified estimate. Scrambling depends only on the seed, the pixel
//! and the dimension, so the image does not depend on the thread count.

/// Point `index` of pixel `(x, y)`'s scrambled sequence for `seed`, in `[0, 1)²`.
pub(crate) fn pixel_point(seed: u64, x: usize, y: usize, index: u32) -> (f32, f32) {
    let pixel = hash64(hash64(seed ^ 0x5851_F42D_4C95_7F2D) ^ ((x as u64) << 32 | y as u64));
    let (s0, s1) = (pixel as u32, (pixel >> 32) as u32);
    let a = owen(van_der_corput(index), s0);
    let b = owen(sobol_dim1(index), s1 ^ 0x68E3_1DA4);
    (unit(a), unit(b))
}

/// Sobol dimension 0: the bits of the index mirrored about the binary point.
fn van_der_corput(index: u32) -> u32 {
    index.reverse_bits()
}

/// Sobol dimension 1 (primitive polynomial x + 1: direction numbers `v_k = v_{k−1} ^ v_{k−1} >> 1`).
fn sobol_dim1(mut index: u32) -> u32 {
    let mut v = 1u32 << 31;
    let mut out = 0;
    while index != 0 {
        if index & 1 == 1 {
            out ^= v;
        }
        index >>= 1;
        v ^= v >> 1;
    }
    out
}

/// Nested uniform (Owen) scramble of a 32-bit fraction: Burley's Laine–Karras hash on the
/// reversed bits, so each bit is flipped by a hash of the bits above it.
fn owen(x: u32, seed: u32) -> u32 {
    let mut v = x.reverse_bits();
    v ^= v.wrapping_mul(0x3D20_ADEA);
    v = v.wrapping_add(seed);
    v = v.wrapping_mul((seed >> 16) | 1);
    v ^= v.wrapping_mul(0x0552_6C56);
    v ^= v.wrapping_mul(0x53A2_2864);
    v.reverse_bits()
}

/// The top 24 bits as a float in `[0, 1)` (exact in f32).
fn unit(v: u32) -> f32 {
    (v >> 8) as f32 / (1u32 << 24) as f32
}

/// SplitMix64's finaliser.
pub(crate) fn hash64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every power-of-two prefix up to 256 points has one point in each of its
    /// `2^a × 2^b` elementary intervals (a + b = m), for several pixels and seeds.
    #[test]
    fn prefixes_are_nets_in_every_pixel() {
        for (seed, x, y) in [(0, 0, 0), (1, 17, 3), (99, 400, 399)] {
            for m in 0..=8u32 {
                let n = 1u32 << m;
                let pts: Vec<_> = (0..n).map(|i| pixel_point(seed, x, y, i)).collect();
                for a in 0..=m {
                    let (cols, rows) = (1u32 << a, 1u32 << (m - a));
                    let mut seen = vec![false; n as usize];
                    for &(u, v) in &pts {
                        let cell = (u * cols as f32) as u32 * rows + (v * rows as f32) as u32;
                        assert!(
                            !seen[cell as usize],
                            "seed {seed}, 2^{m} points, {cols}×{rows}"
                        );
                        seen[cell as usize] = true;
                    }
                }
            }
        }
    }

    #[test]
    fn pixels_and_seeds_get_different_points() {
        let p = pixel_point(0, 5, 5, 0);
        assert_ne!(p, pixel_point(0, 6, 5, 0));
        assert_ne!(p, pixel_point(0, 5, 6, 0));
        assert_ne!(p, pixel_point(1, 5, 5, 0));
    }
}
