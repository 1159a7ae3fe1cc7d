//! RGB matrices and the sRGB transfer function against their published forms.

use proptest::prelude::*;
use thinfilm::colorspace::{
    DISPLAY_P3_FROM_XYZ, REC2020_FROM_XYZ, SRGB_FROM_XYZ, XYZ_FROM_DISPLAY_P3, XYZ_FROM_REC2020,
    XYZ_FROM_SRGB, apply, hex, srgb_decode, srgb_encode, srgb8_from_linear,
};

type Matrix = [[f64; 3]; 3];

/// Asserts every entry within `tol`, printing the worst difference.
fn assert_matrix_close(actual: &Matrix, expected: &Matrix, tol: f64, what: &str) {
    let mut worst = (0.0, 0, 0);
    for r in 0..3 {
        for c in 0..3 {
            let d = (actual[r][c] - expected[r][c]).abs();
            if d > worst.0 {
                worst = (d, r, c);
            }
        }
    }
    let (d, r, c) = worst;
    assert!(
        d <= tol,
        "{what}[{r}][{c}]: got {}, expected {}, |diff| = {d:e} > {tol:e}",
        actual[r][c],
        expected[r][c]
    );
}

fn multiply(a: &Matrix, b: &Matrix) -> Matrix {
    std::array::from_fn(|r| std::array::from_fn(|c| (0..3).map(|k| a[r][k] * b[k][c]).sum()))
}

const IDENTITY: Matrix = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

#[test]
fn srgb_matrix_matches_iec_61966_2_1() {
    // IEC 61966-2-1:1999 eq. (7): the normative linear sRGB → XYZ matrix, 4 decimals.
    let iec_xyz_from_srgb = [
        [0.4124, 0.3576, 0.1805],
        [0.2126, 0.7152, 0.0722],
        [0.0193, 0.1192, 0.9505],
    ];
    assert_matrix_close(&XYZ_FROM_SRGB, &iec_xyz_from_srgb, 1e-4, "XYZ_FROM_SRGB");
    // The standard's printed inverse (eq. 8) is the inverse of the *rounded*
    // matrix above, so the 4th-decimal rounding is amplified by the inverse's
    // condition number: it matches only to 4e-4 (3.2406 vs 3.24097 here).
    let iec_srgb_from_xyz = [
        [3.2406, -1.5372, -0.4986],
        [-0.9689, 1.8758, 0.0415],
        [0.0557, -0.2040, 1.0570],
    ];
    assert_matrix_close(&SRGB_FROM_XYZ, &iec_srgb_from_xyz, 4e-4, "SRGB_FROM_XYZ");
    // Y row is the luminance of the primaries: Rec. 709 luma coefficients.
    assert_matrix_close(
        &[XYZ_FROM_SRGB[1]; 3],
        &[[0.2126, 0.7152, 0.0722]; 3],
        1e-4,
        "luminance row",
    );
}

#[test]
fn display_p3_and_rec2020_match_published_matrices() {
    // CSS Color Module Level 4, §"Predefined colour spaces" (derived with the
    // same D65 xy = 0.3127, 0.3290), 7 decimals.
    let css_xyz_from_p3 = [
        [0.486_570_9, 0.265_667_7, 0.198_217_3],
        [0.228_974_6, 0.691_738_5, 0.079_286_9],
        [0.0, 0.045_113_4, 1.043_944_4],
    ];
    assert_matrix_close(
        &XYZ_FROM_DISPLAY_P3,
        &css_xyz_from_p3,
        1e-7,
        "XYZ_FROM_DISPLAY_P3",
    );
    // ITU-R BT.2087 / SMPTE RP 177 derivation for BT.2020.
    let xyz_from_rec2020 = [
        [0.636_958_0, 0.144_616_9, 0.168_881_0],
        [0.262_700_2, 0.677_998_1, 0.059_301_7],
        [0.0, 0.028_072_7, 1.060_985_1],
    ];
    assert_matrix_close(
        &XYZ_FROM_REC2020,
        &xyz_from_rec2020,
        1e-7,
        "XYZ_FROM_REC2020",
    );
}

#[test]
fn forward_and_inverse_matrices_multiply_to_identity() {
    for (m, inv, what) in [
        (XYZ_FROM_SRGB, SRGB_FROM_XYZ, "sRGB"),
        (XYZ_FROM_DISPLAY_P3, DISPLAY_P3_FROM_XYZ, "P3"),
        (XYZ_FROM_REC2020, REC2020_FROM_XYZ, "Rec2020"),
    ] {
        assert_matrix_close(&multiply(&m, &inv), &IDENTITY, 1e-14, what);
        assert_matrix_close(&multiply(&inv, &m), &IDENTITY, 1e-14, what);
    }
}

#[test]
fn rgb_white_is_d65_with_unit_luminance() {
    let d65 = [0.3127 / 0.3290, 1.0, (1.0 - 0.3127 - 0.3290) / 0.3290];
    for m in [XYZ_FROM_SRGB, XYZ_FROM_DISPLAY_P3, XYZ_FROM_REC2020] {
        let w = apply(&m, [1.0; 3]);
        for c in 0..3 {
            assert!((w[c] - d65[c]).abs() < 1e-14, "white {w:?} vs {d65:?}");
        }
    }
}

#[test]
fn srgb_transfer_function_matches_published_points() {
    // IEC 61966-2-1: the linear segment joins the power segment at 0.0031308 ↔ 0.04045.
    assert!((srgb_encode(0.003_130_8) - 0.040_45).abs() < 1e-6);
    assert_eq!(srgb_encode(0.0), 0.0);
    assert!((srgb_encode(1.0) - 1.0).abs() < 1e-15);
    // Mid grey: 18 % linear encodes to about 46.1 %.
    assert!((srgb_encode(0.18) - 0.461_356).abs() < 1e-6);
    assert_eq!(
        srgb8_from_linear([0.0, 1.0, srgb_decode(128.0 / 255.0)]),
        [0, 255, 128]
    );
    assert_eq!(hex(srgb8_from_linear([1.0, 0.5, 0.0])), "#ffbc00");
}

proptest! {
    #[test]
    fn srgb_encode_round_trips(linear in 0.0f64..=1.0) {
        let back = srgb_decode(srgb_encode(linear));
        prop_assert!((back - linear).abs() <= 1e-12, "{linear} -> {back}");
    }

    #[test]
    fn srgb_encode_is_monotone(a in 0.0f64..=1.0, b in 0.0f64..=1.0) {
        let (lo, hi) = if a < b { (a, b) } else { (b, a) };
        prop_assert!(srgb_encode(lo) <= srgb_encode(hi));
    }

    #[test]
    fn matrix_round_trip_is_identity(r in -1.0f64..2.0, g in -1.0f64..2.0, b in -1.0f64..2.0) {
        let back = apply(&SRGB_FROM_XYZ, apply(&XYZ_FROM_SRGB, [r, g, b]));
        for (x, y) in back.iter().zip([r, g, b]) {
            prop_assert!((x - y).abs() < 1e-12, "{back:?} vs {:?}", [r, g, b]);
        }
    }

    #[test]
    fn srgb8_is_total(r in proptest::num::f64::ANY, g in proptest::num::f64::ANY) {
        // Any input, NaN and infinities included, gives some 8-bit colour.
        let _ = srgb8_from_linear([r, g, 0.5]);
    }
}
