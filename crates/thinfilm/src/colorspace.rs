//! RGB colour spaces with a D65 white: XYZ ↔ linear RGB matrices and the sRGB
//! transfer function.
//!
//! The matrices are derived at compile time from each space's primaries and
//! white chromaticity (so they are exactly consistent with each other) and are
//! checked against the published ones by the tests. Matrices are named
//! `destination_from_source`: `SRGB_FROM_XYZ` takes XYZ (white Y = 1) to linear sRGB.

/// The D65 white chromaticity of sRGB, Display P3 and Rec. 2020 (IEC 61966-2-1).
pub const D65_WHITE_XY: [f64; 2] = [0.3127, 0.3290];
/// sRGB / Rec. 709 primaries, red, green, blue (IEC 61966-2-1).
pub const SRGB_PRIMARIES_XY: [[f64; 2]; 3] = [[0.64, 0.33], [0.30, 0.60], [0.15, 0.06]];
/// Display P3 primaries (DCI-P3 primaries with a D65 white).
pub const DISPLAY_P3_PRIMARIES_XY: [[f64; 2]; 3] = [[0.680, 0.320], [0.265, 0.690], [0.150, 0.060]];
/// Rec. 2020 primaries (ITU-R BT.2020).
pub const REC2020_PRIMARIES_XY: [[f64; 2]; 3] = [[0.708, 0.292], [0.170, 0.797], [0.131, 0.046]];

/// Linear sRGB → XYZ.
pub const XYZ_FROM_SRGB: [[f64; 3]; 3] = xyz_from_rgb(SRGB_PRIMARIES_XY, D65_WHITE_XY);
/// XYZ → linear sRGB.
pub const SRGB_FROM_XYZ: [[f64; 3]; 3] = invert(XYZ_FROM_SRGB);
/// Linear Display P3 → XYZ.
pub const XYZ_FROM_DISPLAY_P3: [[f64; 3]; 3] = xyz_from_rgb(DISPLAY_P3_PRIMARIES_XY, D65_WHITE_XY);
/// XYZ → linear Display P3.
pub const DISPLAY_P3_FROM_XYZ: [[f64; 3]; 3] = invert(XYZ_FROM_DISPLAY_P3);
/// Linear Rec. 2020 → XYZ.
pub const XYZ_FROM_REC2020: [[f64; 3]; 3] = xyz_from_rgb(REC2020_PRIMARIES_XY, D65_WHITE_XY);
/// XYZ → linear Rec. 2020.
pub const REC2020_FROM_XYZ: [[f64; 3]; 3] = invert(XYZ_FROM_REC2020);

/// XYZ (Y = 1) of the chromaticity `xy`.
pub const fn xyz_from_xy(xy: [f64; 2]) -> [f64; 3] {
    [xy[0] / xy[1], 1.0, (1.0 - xy[0] - xy[1]) / xy[1]]
}

/// The RGB → XYZ matrix of a space with the given primaries whose white
/// (RGB = 1, 1, 1) has chromaticity `white_xy` and Y = 1.
///
/// Each column is a primary's XYZ, scaled so the columns sum to the white.
pub const fn xyz_from_rgb(primaries_xy: [[f64; 2]; 3], white_xy: [f64; 2]) -> [[f64; 3]; 3] {
    let r = xyz_from_xy(primaries_xy[0]);
    let g = xyz_from_xy(primaries_xy[1]);
    let b = xyz_from_xy(primaries_xy[2]);
    let unscaled = [[r[0], g[0], b[0]], [r[1], g[1], b[1]], [r[2], g[2], b[2]]];
    let scale = apply(&invert(unscaled), xyz_from_xy(white_xy));
    let mut m = unscaled;
    let mut row = 0;
    while row < 3 {
        let mut col = 0;
        while col < 3 {
            m[row][col] *= scale[col];
            col += 1;
        }
        row += 1;
    }
    m
}

/// The inverse of a 3×3 matrix by cofactors (the matrices here are well conditioned).
pub const fn invert(m: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let [[a, b, c], [d, e, f], [g, h, i]] = m;
    let co = [e * i - f * h, f * g - d * i, d * h - e * g];
    let det = a * co[0] + b * co[1] + c * co[2];
    [
        [co[0] / det, (c * h - b * i) / det, (b * f - c * e) / det],
        [co[1] / det, (a * i - c * g) / det, (c * d - a * f) / det],
        [co[2] / det, (b * g - a * h) / det, (a * e - b * d) / det],
    ]
}

/// The product `m · v`.
pub const fn apply(m: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    [
        m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2],
        m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
        m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2],
    ]
}

/// The sRGB transfer function (IEC 61966-2-1): linear light → encoded value.
///
/// Defined for all inputs: negative values stay on the linear segment.
pub fn srgb_encode(linear: f64) -> f64 {
    if linear <= 0.003_130_8 {
        12.92 * linear
    } else {
        1.055 * linear.powf(1.0 / 2.4) - 0.055
    }
}

/// The inverse of [`srgb_encode`]: encoded value → linear light.
pub fn srgb_decode(encoded: f64) -> f64 {
    if encoded <= 0.040_45 {
        encoded / 12.92
    } else {
        ((encoded + 0.055) / 1.055).powf(2.4)
    }
}

/// 8-bit sRGB of linear sRGB, each channel clamped to [0, 1] first (NaN → 0).
pub fn srgb8_from_linear(rgb: [f64; 3]) -> [u8; 3] {
    rgb.map(|c| {
        let clamped = if c > 0.0 { c.min(1.0) } else { 0.0 };
        // In [0, 255] after rounding, so the cast cannot truncate.
        (srgb_encode(clamped) * 255.0).round() as u8
    })
}

/// `"#rrggbb"` in lower-case hex.
pub fn hex(rgb8: [u8; 3]) -> String {
    format!("#{:02x}{:02x}{:02x}", rgb8[0], rgb8[1], rgb8[2])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hex_formats_lower_case() {
        assert_eq!(hex([255, 0, 171]), "#ff00ab");
        assert_eq!(srgb8_from_linear([1.0, 0.0, 2.0]), [255, 0, 255]);
        assert_eq!(srgb8_from_linear([f64::NAN, -1.0, 0.5]), [0, 0, 188]);
    }
}
