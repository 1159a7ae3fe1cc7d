//! [`Texture`]: a linear-light RGB image with bilinear lookups, and the image loader.

use std::path::Path;

use crate::RenderError;
use crate::index_f32::index_f32;

/// A linear-light RGB f32 image, row 0 at the top.
///
/// # Guarantees
/// - `1 <= width, height <= 65536` and `texels.len() == width * height`;
/// - every texel is finite and non-negative.
#[derive(Debug, Clone, PartialEq)]
pub struct Texture {
    width: usize,
    height: usize,
    texels: Vec<[f32; 3]>,
}

/// Largest accepted side of an image, in texels.
const MAX_SIDE: usize = 65536;

impl Texture {
    /// Builds a texture from row-major linear RGB texels, checking every guarantee.
    pub fn try_new(
        width: usize,
        height: usize,
        texels: Vec<[f32; 3]>,
    ) -> Result<Self, RenderError> {
        if !(1..=MAX_SIDE).contains(&width) || !(1..=MAX_SIDE).contains(&height) {
            return Err(RenderError::scene(
                "texture",
                format!("size {width}x{height} must be 1..={MAX_SIDE} on each side"),
            ));
        }
        if texels.len() != width * height {
            return Err(RenderError::scene(
                "texture",
                format!("{} texels for a {width}x{height} image", texels.len()),
            ));
        }
        check_texels("texture", &texels, width)?;
        Ok(Self {
            width,
            height,
            texels,
        })
    }

    /// A 1×1 texture of one colour; `None` unless finite and non-negative.
    pub fn solid(rgb: [f32; 3]) -> Option<Self> {
        Self::try_new(1, 1, vec![rgb]).ok()
    }

    /// Loads an image file: PNG (sRGB-encoded, decoded to linear) or EXR (already linear).
    pub fn load(path: impl AsRef<Path>) -> Result<Self, RenderError> {
        let path = path.as_ref();
        let (width, height, texels) = read_linear_rgb(path)?;
        Self::try_new(width, height, texels).map_err(|e| RenderError::ImageRead {
            path: path.to_path_buf(),
            message: e.to_string(),
        })
    }

    /// Width in texels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in texels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// Row-major texels, row 0 at the top.
    pub fn texels(&self) -> &[[f32; 3]] {
        &self.texels
    }

    /// Bilinear lookup at `(u, v)` in `[0, 1]²` (v down), repeating outside; NaN reads as 0.
    #[inline]
    pub fn sample_repeat(&self, u: f32, v: f32) -> [f32; 3] {
        let (x0, x1, tx) = split_repeat(u, self.width);
        let (y0, y1, ty) = split_repeat(v, self.height);
        self.bilinear(x0, x1, tx, y0, y1, ty)
    }

    /// Bilinear lookup at `(u, v)` in `[0, 1]²` (v down), clamped to the edges; NaN reads as 0.
    #[inline]
    pub fn sample_clamp(&self, u: f32, v: f32) -> [f32; 3] {
        let (x0, x1, tx) = split_clamp(u, self.width);
        let (y0, y1, ty) = split_clamp(v, self.height);
        self.bilinear(x0, x1, tx, y0, y1, ty)
    }

    /// Equirectangular lookup of a direction: `u` follows longitude, `v` the polar angle from +Y.
    ///
    /// `u = 0.5 + atan2(x, −z) / 2π`, so −Z is the image centre and +X lies to its right.
    #[inline]
    pub fn sample_equirect(&self, dir: glam::Vec3) -> [f32; 3] {
        let len = dir.length();
        let y = if len > 0.0 {
            (dir.y / len).clamp(-1.0, 1.0)
        } else {
            1.0
        };
        let u = 0.5 + dir.x.atan2(-dir.z) * (0.5 / std::f32::consts::PI);
        let v = y.acos() * std::f32::consts::FRAC_1_PI;
        let (x0, x1, tx) = split_repeat(u, self.width);
        let (y0, y1, ty) = split_clamp(v, self.height);
        self.bilinear(x0, x1, tx, y0, y1, ty)
    }

    #[inline]
    fn bilinear(&self, x0: usize, x1: usize, tx: f32, y0: usize, y1: usize, ty: f32) -> [f32; 3] {
        let w = self.width;
        let a = self.texels[y0 * w + x0];
        let b = self.texels[y0 * w + x1];
        let c = self.texels[y1 * w + x0];
        let d = self.texels[y1 * w + x1];
        bilerp(a, b, c, d, tx, ty)
    }
}

/// Texel pair and weight for a repeating axis of `n` texels (texel centres at `(i + 0.5) / n`).
#[inline]
fn split_repeat(t: f32, n: usize) -> (usize, usize, f32) {
    let x = t * index_f32(n) - 0.5;
    let x = if x.is_finite() { x } else { 0.0 };
    let f = x.floor();
    let i0 = (f as i64).rem_euclid(n as i64) as usize;
    let i1 = if i0 + 1 == n { 0 } else { i0 + 1 };
    (i0, i1, x - f)
}

/// Texel pair and weight for a clamped axis of `n` texels.
#[inline]
fn split_clamp(t: f32, n: usize) -> (usize, usize, f32) {
    let x = (t * index_f32(n) - 0.5).clamp(0.0, index_f32(n - 1));
    let x = if x.is_nan() { 0.0 } else { x };
    let i0 = x as usize;
    let i1 = (i0 + 1).min(n - 1);
    (i0, i1, x - index_f32(i0))
}

/// The sRGB decoding curve (IEC 61966-2-1) for one channel in `[0, 1]`.
pub(crate) fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Reads an image file as linear RGB: float formats as stored, integer formats through the sRGB curve.
pub(crate) fn read_linear_rgb(path: &Path) -> Result<(usize, usize, Vec<[f32; 3]>), RenderError> {
    let err = |message: String| RenderError::ImageRead {
        path: path.to_path_buf(),
        message,
    };
    let reader = image::ImageReader::open(path).map_err(|e| err(e.to_string()))?;
    let reader = reader
        .with_guessed_format()
        .map_err(|e| err(e.to_string()))?;
    let img = reader.decode().map_err(|e| err(e.to_string()))?;
    let is_float = matches!(
        img,
        image::DynamicImage::ImageRgb32F(_) | image::DynamicImage::ImageRgba32F(_)
    );
    let rgb = img.to_rgb32f();
    let (w, h) = (rgb.width() as usize, rgb.height() as usize);
    let texels = rgb
        .pixels()
        .map(|p| {
            let c = p.0;
            if is_float {
                [c[0].max(0.0), c[1].max(0.0), c[2].max(0.0)]
            } else {
                [
                    srgb_to_linear(c[0]),
                    srgb_to_linear(c[1]),
                    srgb_to_linear(c[2]),
                ]
            }
        })
        .collect();
    Ok((w, h, texels))
}

/// Checks that every texel of a row-major image `width` wide is finite and non-negative,
/// naming `what` and the first bad texel's position otherwise.
pub(crate) fn check_texels(
    what: &str,
    texels: &[[f32; 3]],
    width: usize,
) -> Result<(), RenderError> {
    match texels
        .iter()
        .position(|t| t.iter().any(|c| !(c.is_finite() && *c >= 0.0)))
    {
        Some(k) => Err(RenderError::scene(
            format!("{what} texel ({}, {})", k % width, k / width),
            format!("{:?} is not finite and non-negative", texels[k]),
        )),
        None => Ok(()),
    }
}

/// Bilinear blend of the texels `a b` (top row) and `c d` (bottom row), in the one
/// operation order every sampler uses, so their results stay bit-identical.
#[inline(always)]
pub(crate) fn bilerp(
    a: [f32; 3],
    b: [f32; 3],
    c: [f32; 3],
    d: [f32; 3],
    tx: f32,
    ty: f32,
) -> [f32; 3] {
    let mut out = [0.0; 3];
    for k in 0..3 {
        let top = a[k] + (b[k] - a[k]) * tx;
        let bottom = c[k] + (d[k] - c[k]) * tx;
        out[k] = top + (bottom - top) * ty;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid() -> Texture {
        let texels = (0..12).map(|k| [k as f32, 0.0, 1.0]).collect();
        Texture::try_new(4, 3, texels).unwrap()
    }

    #[test]
    fn exact_at_texel_centres() {
        let t = grid();
        for j in 0..3 {
            for i in 0..4 {
                let u = (i as f32 + 0.5) / 4.0;
                let v = (j as f32 + 0.5) / 3.0;
                assert_eq!(
                    t.sample_repeat(u, v)[0],
                    (j * 4 + i) as f32,
                    "texel ({i},{j})"
                );
                assert_eq!(
                    t.sample_clamp(u, v)[0],
                    (j * 4 + i) as f32,
                    "texel ({i},{j})"
                );
            }
        }
    }

    #[test]
    fn repeat_wraps_between_last_and_first_column() {
        let t = grid();
        // u = 0 lies halfway between column 3 and column 0 of row 0.
        let got = t.sample_repeat(0.0, 0.5 / 3.0)[0];
        assert!((got - 1.5).abs() < 1e-6, "got {got}, want 1.5");
        assert_eq!(t.sample_clamp(0.0, 0.5 / 3.0)[0], 0.0);
    }

    #[test]
    fn nan_and_infinite_coordinates_do_not_panic() {
        let t = grid();
        for &(u, v) in &[
            (f32::NAN, 0.5),
            (f32::INFINITY, f32::NEG_INFINITY),
            (1e30, -1e30),
        ] {
            let a = t.sample_repeat(u, v);
            let b = t.sample_clamp(u, v);
            assert!(a.iter().chain(b.iter()).all(|c| c.is_finite()), "({u},{v})");
        }
        let e = t.sample_equirect(glam::Vec3::ZERO);
        assert!(e.iter().all(|c| c.is_finite()));
    }

    #[test]
    fn rejects_bad_texels() {
        assert!(Texture::try_new(2, 1, vec![[0.0; 3]]).is_err());
        assert!(Texture::try_new(1, 1, vec![[f32::NAN, 0.0, 0.0]]).is_err());
        assert!(Texture::try_new(1, 1, vec![[-1.0, 0.0, 0.0]]).is_err());
        assert!(Texture::try_new(0, 1, vec![]).is_err());
    }

    #[test]
    fn srgb_decoding_hits_known_points() {
        assert_eq!(srgb_to_linear(0.0), 0.0);
        assert!((srgb_to_linear(1.0) - 1.0).abs() < 1e-6);
        // 0.5 encodes 0.21404 linear (IEC 61966-2-1).
        assert!((srgb_to_linear(0.5) - 0.214_041).abs() < 1e-5);
    }
}
