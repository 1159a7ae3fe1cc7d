//! Which cube-map levels a bubble pixel reads: the reflected direction's derivatives per
//! pixel, the anisotropic tap plan and the one LOD formula (ported to WGSL by the GPU
//! backend with these constants).
//!
//! At a bubble's rim the reflected direction turns by up to half a radian per pixel; read
//! with one bilinear tap of the full-resolution cube map, everything it sweeps over aliases.
//! The mip level whose texels are as wide as the pixel's footprint averages it instead.

use glam::Vec3A;

use crate::index_f32::index_f32;

/// Levels added to the computed level of detail: −log2 √3. A bilinear tap of a level
/// whose texels are `T` wide (box-averaged from level 0) is a box of width `T` convolved
/// with a tent of half-width `T`, a kernel of standard deviation `T/2`; the pixel's own
/// footprint `f` is a box of standard deviation `f/√12`. They match at `T = f/√3`. At 0 the
/// rims blur half again too much (crates/raster/tests/rim_aliasing.rs measured it).
pub const LOD_BIAS: f32 = -0.792_481_25;

/// Footprints below this many level-0 texels read level 0 alone (one bilinear tap).
pub const MIN_FOOTPRINT_TEXELS: f32 = 1.0;

/// Level of detail (fractional mip level, ≥ 0) of a cube-map read whose direction turns by
/// `footprint_rad` per pixel, at face coordinates `(s, t)` of a cube with level-0 faces of
/// `face_size` texels.
///
/// A texel at `(s, t)` subtends the solid angle `(2/N)² / (1 + s² + t²)^{3/2}`; its square
/// root is the texel's angular width, so the footprint spans
/// `footprint · N/2 · (1 + s² + t²)^{3/4}` level-0 texels, and level `log2` of that has
/// texels as wide as the footprint. The caller clamps to the levels it has.
#[inline]
pub fn cube_lod(footprint_rad: f32, face_size: usize, s: f32, t: f32) -> f32 {
    let q = 1.0 + s * s + t * t;
    let q34 = q.sqrt() * q.sqrt().sqrt();
    let texels = footprint_rad * index_f32(face_size) * 0.5 * q34;
    // NaN compares false: it reads level 0, as a zero footprint would.
    if texels > MIN_FOOTPRINT_TEXELS {
        (log2_at_least_one(texels) + LOD_BIAS).max(0.0)
    } else {
        0.0
    }
}

/// `log2 x` for `x >= 1` (+∞ reads as 128), within 2e-7 of the exact value (relative
/// above 2, absolute below; f32 rounding of the sum is most of it): the LOD
/// formula's logarithm, inlined where libm's `log2f` is a call (2.6 % of a `paper` frame).
///
/// `x = m·2^e` with `m` in `[√½, √2)`, and `log2 m = 2·atanh(s)/ln 2` with
/// `s = (m − 1)/(m + 1)`, `|s| ≤ 0.172`, whose odd series converges to 1e-9 by `s⁹`.
#[inline(always)]
pub(crate) fn log2_at_least_one(x: f32) -> f32 {
    const SQRT_HALF_BITS: u32 = 0x3f35_04f3;
    // 2/ln 2 and its multiples 1/3, 1/5, 1/7, 1/9.
    const C: [f32; 5] = [2.885_39, 0.961_796_7, 0.577_078, 0.412_198_6, 0.320_598_9];
    let bits = x.to_bits();
    let e = (bits.wrapping_sub(SQRT_HALF_BITS) as i32) >> 23;
    let m = f32::from_bits(bits.wrapping_sub((e as u32) << 23));
    let s = (m - 1.0) / (m + 1.0);
    let s2 = s * s;
    let series = s * (C[0] + s2 * (C[1] + s2 * (C[2] + s2 * (C[3] + s2 * C[4]))));
    e as f32 + series
}

/// Most taps one lookup spreads along the footprint's long axis (a GPU's anisotropy clamp).
pub const MAX_ANISOTROPY: usize = 8;

/// How one footprint-filtered lookup is made: `taps` (the axis ratio, rounded) trilinear
/// taps spaced evenly along the longer of the two per-pixel derivatives, each filtered
/// over `footprint_rad` (the longer derivative over `taps`, never less than the shorter).
///
/// An isotropic filter as wide as the longer derivative would blur a bubble's rim along
/// the silhouette as much as across it (there they differ tenfold); spreading taps along
/// the long axis filters each axis by its own width, as a GPU's anisotropic filter does.
#[inline]
pub fn anisotropic_taps(major_rad: f32, minor_rad: f32) -> (usize, f32) {
    let ratio = major_rad / minor_rad.max(1e-12);
    // Rounded: below 1.5 one tap (isotropic, as wide as the longer axis). NaN → one tap;
    // the float-to-int conversion saturates.
    let taps = ((ratio + 0.5) as usize).clamp(1, MAX_ANISOTROPY);
    (taps, (major_rad / index_f32(taps)).max(minor_rad))
}

/// Change per pixel of the unit reflected direction along screen x and y.
///
/// `d` is the (unnormalised) view ray and `dd` its change per pixel along x and y;
/// `n_raw` is the interpolated (unnormalised) normal and `dn_raw` its change per pixel.
/// The normal is turned to face the viewer as the shading does. Exact derivatives of
/// `r = v − 2(v·n)n` with `v = d/|d|`, `n = ±n_raw/|n_raw|`; zero where not finite.
/// (`Vec3A`: lane-wise the same operations as `Vec3`, in fewer instructions.)
#[inline]
pub fn reflection_derivatives(
    d: Vec3A,
    dd: [Vec3A; 2],
    n_raw: Vec3A,
    dn_raw: [Vec3A; 2],
) -> [Vec3A; 2] {
    let (d_len, n_len) = (d.length(), n_raw.length());
    let v = d / d_len;
    let n_hat = n_raw / n_len;
    let sign = if v.dot(n_hat) > 0.0 { -1.0 } else { 1.0 };
    let n = n_hat * sign;
    let c = v.dot(n);
    // A literal pair, not `array::from_fn`, whose closure does not inline here.
    let along = |dd: Vec3A, dn_raw: Vec3A| {
        let dv = (dd - v * v.dot(dd)) / d_len;
        let dn = (dn_raw - n_hat * n_hat.dot(dn_raw)) * (sign / n_len);
        let dc = dv.dot(n) + v.dot(dn);
        let dr = dv - (n * dc + dn * c) * 2.0;
        if dr.is_finite() { dr } else { Vec3A::ZERO }
    };
    [along(dd[0], dn_raw[0]), along(dd[1], dn_raw[1])]
}

#[cfg(test)]
mod tests {
    use super::*;
    // The derivatives take `Vec3A`; these tests read as plain vectors.
    use glam::Vec3A as Vec3;
    use proptest::prelude::*;

    fn reflect(d: Vec3, n_raw: Vec3) -> Vec3 {
        let v = d.normalize();
        let mut n = n_raw.normalize();
        if v.dot(n) > 0.0 {
            n = -n;
        }
        v - n * (2.0 * v.dot(n))
    }

    proptest! {
        #[test]
        fn footprint_matches_finite_differences_of_the_reflected_direction(
            d in prop::array::uniform3(-1.0f32..1.0),
            dd in prop::array::uniform3(-0.05f32..0.05),
            ee in prop::array::uniform3(-0.05f32..0.05),
            n in prop::array::uniform3(-1.0f32..1.0),
            dn in prop::array::uniform3(-0.05f32..0.05),
            en in prop::array::uniform3(-0.05f32..0.05),
        ) {
            let (d, n) = (Vec3::from(d) + Vec3::Z * 1.5, Vec3::from(n));
            prop_assume!(n.length() > 0.3);
            // Away from grazing, where the facing flip would make r jump.
            prop_assume!(d.normalize().dot(n.normalize()).abs() > 0.2);
            let dd = [Vec3::from(dd), Vec3::from(ee)];
            let dn = [Vec3::from(dn), Vec3::from(en)];
            let h = 1e-2f32;
            let got = reflection_derivatives(d, dd, n, dn);
            for k in 0..2 {
                let plus = reflect(d + dd[k] * h, n + dn[k] * h);
                let minus = reflect(d - dd[k] * h, n - dn[k] * h);
                let fd = (plus - minus) / (2.0 * h);
                prop_assert!(
                    (got[k] - fd).length() <= 2e-3 + 1e-2 * fd.length(),
                    "axis {}: analytic {} vs finite differences {} (difference {})",
                    k, got[k], fd, (got[k] - fd).length()
                );
            }
        }
    }

    #[test]
    fn footprint_of_a_mirror_sphere_seen_head_on_is_twice_the_normals_turn() {
        // Centre of a sphere of radius R px: the normal turns 1/R rad per pixel, the view
        // ray not at all (orthographic limit), so r turns 2/R.
        let r_px = 50.0;
        let got = reflection_derivatives(
            Vec3::NEG_Z,
            [Vec3::ZERO; 2],
            Vec3::Z,
            [Vec3::X / r_px, Vec3::Y / r_px],
        );
        for (k, axis) in [Vec3::X, Vec3::Y].into_iter().enumerate() {
            let want = axis * (2.0 / r_px);
            assert!(
                (got[k] - want).length() < 1e-6,
                "axis {k}: {} vs {want}",
                got[k]
            );
        }
        let degenerate =
            reflection_derivatives(Vec3::NEG_Z, [Vec3::ZERO; 2], Vec3::ZERO, [Vec3::X; 2]);
        assert_eq!(degenerate, [Vec3::ZERO; 2]);
    }

    #[test]
    fn anisotropic_taps_cover_the_long_axis_at_the_short_axis_width() {
        assert_eq!(anisotropic_taps(0.01, 0.01), (1, 0.01));
        assert_eq!(anisotropic_taps(0.014, 0.01), (1, 0.014));
        assert_eq!(anisotropic_taps(0.0, 0.0), (1, 0.0));
        // 4:1 → four taps, each as wide as the short axis.
        assert_eq!(anisotropic_taps(0.4, 0.1), (4, 0.1));
        // Beyond the clamp the taps widen instead.
        let (taps, width) = anisotropic_taps(1.0, 0.001);
        assert_eq!(taps, MAX_ANISOTROPY);
        assert!((width - 1.0 / MAX_ANISOTROPY as f32).abs() < 1e-7);
        assert_eq!(anisotropic_taps(f32::NAN, 0.1).0, 1);
    }

    #[test]
    fn inline_log2_is_within_2e7_of_the_exact_logarithm() {
        let mut worst = 0.0f64;
        let mut x = 1.0f32;
        while x < 1e30 {
            for y in [x, x.next_up(), x * std::f32::consts::SQRT_2, x * 1.000_37] {
                let exact = f64::from(y).log2();
                let err = (f64::from(log2_at_least_one(y)) - exact).abs() / exact.max(1.0);
                worst = worst.max(err);
            }
            x *= 1.0137;
        }
        assert!(
            worst < 2e-7,
            "worst error {worst:e} (relative, or absolute below 1)"
        );
        assert_eq!(log2_at_least_one(1.0), 0.0);
        assert_eq!(log2_at_least_one(1024.0), 10.0);
        assert_eq!(log2_at_least_one(f32::INFINITY), 128.0);
    }

    #[test]
    fn lod_is_zero_for_small_footprints_and_log2_of_the_texel_span_otherwise() {
        assert_eq!(cube_lod(0.0, 128, 0.0, 0.0), 0.0);
        assert_eq!(cube_lod(f32::NAN, 128, 0.0, 0.0), 0.0);
        // At the face centre a texel is 2/N rad wide: 8 texels' worth reads level 3 (+ bias).
        let lod = cube_lod(8.0 * 2.0 / 128.0, 128, 0.0, 0.0);
        assert!((lod - 3.0 - LOD_BIAS).abs() < 1e-5, "lod {lod}");
        assert!((3.0f32.sqrt().log2() + LOD_BIAS).abs() < 1e-6);
        // Towards a corner texels subtend less: the same footprint spans more of them.
        assert!(cube_lod(0.1, 128, 0.9, 0.9) > cube_lod(0.1, 128, 0.0, 0.0));
    }
}
