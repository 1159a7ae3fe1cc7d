//! The photo as the inverse sees it: sRGB-encoded values (the camera's own, roughly
//! perceptual scale, where quantisation noise is even), with saturated pixels marked.

use crate::error::InverseError;
use thinfilm::colorspace::{srgb_decode, srgb_encode};

/// The largest photo (pixels): 64 Mpx, the project's image limit.
pub const MAX_PIXELS: u64 = 1 << 26;

/// A photo of a film in reflection.
///
/// # Guarantees
/// `width × height` pixels (both ≥ 1, at most [`MAX_PIXELS`]); every value finite and ≥ 0.
#[derive(Clone, Debug)]
pub struct Photo {
    width: u32,
    height: u32,
    encoded: Vec<[f32; 3]>,
    saturated: Vec<bool>,
    /// Whether every value is a multiple of 1/255 (an 8-bit photo): decoded by table.
    eight_bit: bool,
}

/// Linear values of the 256 8-bit codes.
fn decode8() -> &'static [f64; 256] {
    static TABLE: std::sync::OnceLock<[f64; 256]> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| std::array::from_fn(|k| srgb_decode(k as f64 / 255.0)))
}

impl Photo {
    /// An 8-bit sRGB photo from interleaved RGB bytes; a channel at 255 marks its pixel
    /// saturated.
    ///
    /// # Errors
    /// A size of zero or beyond [`MAX_PIXELS`], or a buffer that is not `3 × width × height` long.
    pub fn try_from_srgb8(width: u32, height: u32, rgb: &[u8]) -> Result<Photo, InverseError> {
        let n = check_size(width, height, rgb.len(), "pixels")?;
        let encoded = rgb
            .chunks_exact(3)
            .map(|p| [0, 1, 2].map(|c| f32::from(p[c]) / 255.0))
            .collect();
        let saturated = rgb.chunks_exact(3).map(|p| p.contains(&255)).collect();
        let mut photo = Photo::checked(width, height, encoded, saturated, n);
        photo.eight_bit = true;
        Ok(photo)
    }

    /// A 16-bit sRGB photo from interleaved RGB words; a channel at 65535 marks saturation.
    ///
    /// # Errors
    /// As [`Photo::try_from_srgb8`].
    pub fn try_from_srgb16(width: u32, height: u32, rgb: &[u16]) -> Result<Photo, InverseError> {
        let n = check_size(width, height, rgb.len(), "pixels")?;
        let encoded = rgb
            .chunks_exact(3)
            .map(|p| [0, 1, 2].map(|c| f32::from(p[c]) / 65535.0))
            .collect();
        let saturated = rgb.chunks_exact(3).map(|p| p.contains(&u16::MAX)).collect();
        Ok(Photo::checked(width, height, encoded, saturated, n))
    }

    /// A linear photo (for example from EXR), interleaved RGB; nothing is saturated.
    ///
    /// # Errors
    /// As [`Photo::try_from_srgb8`], or a value that is negative or not finite (named).
    pub fn try_from_linear(width: u32, height: u32, rgb: &[f32]) -> Result<Photo, InverseError> {
        let n = check_size(width, height, rgb.len(), "pixels")?;
        if let Some(i) = rgb.iter().position(|v| !(v.is_finite() && *v >= 0.0)) {
            let px = i / 3;
            return Err(InverseError::Photo(format!(
                "pixel ({}, {}) has the value {} in channel {}: a linear photo needs finite values ≥ 0",
                px % width as usize,
                px / width as usize,
                rgb[i],
                i % 3
            )));
        }
        let encoded = rgb
            .chunks_exact(3)
            .map(|p| [0, 1, 2].map(|c| srgb_encode(f64::from(p[c])) as f32))
            .collect();
        Ok(Photo::checked(width, height, encoded, vec![false; n], n))
    }

    fn checked(w: u32, h: u32, encoded: Vec<[f32; 3]>, saturated: Vec<bool>, n: usize) -> Photo {
        debug_assert_eq!(encoded.len(), n);
        Photo {
            width: w,
            height: h,
            encoded,
            saturated,
            eight_bit: false,
        }
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Number of pixels.
    pub fn len(&self) -> usize {
        self.encoded.len()
    }

    /// Whether the photo has no pixel (never: see the guarantees).
    pub fn is_empty(&self) -> bool {
        self.encoded.is_empty()
    }

    /// The sRGB-encoded values, row-major.
    pub fn encoded(&self) -> &[[f32; 3]] {
        &self.encoded
    }

    /// Whether each pixel has a channel at the format's maximum.
    pub fn saturated(&self) -> &[bool] {
        &self.saturated
    }

    /// The linear value of pixel `i`.
    pub fn linear(&self, i: usize) -> [f64; 3] {
        if self.eight_bit {
            let table = decode8();
            return self.encoded[i].map(|v| table[(v * 255.0).round() as usize]);
        }
        self.encoded[i].map(|v| srgb_decode(f64::from(v)))
    }
}

/// Checks a photo's size and an interleaved buffer's length; returns the pixel count.
fn check_size(
    width: u32,
    height: u32,
    len: usize,
    what: &'static str,
) -> Result<usize, InverseError> {
    let pixels = u64::from(width) * u64::from(height);
    if pixels == 0 || pixels > MAX_PIXELS {
        return Err(InverseError::Setting {
            name: "photo size",
            value: format!("{width}x{height}"),
            allowed: format!("1 to {MAX_PIXELS} pixels"),
        });
    }
    let n = pixels as usize;
    if len != 3 * n {
        return Err(InverseError::Size {
            what,
            len,
            expected: 3 * n,
        });
    }
    Ok(n)
}
