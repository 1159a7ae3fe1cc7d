//! [`Frame`]: the linear HDR result, its timings, tone mapping and PNG/EXR output.

use std::io::{BufWriter, Write};
use std::path::Path;

use crate::{RenderError, ToneMap};

/// Wall-clock seconds spent in each phase of a frame.
///
/// The opaque, bubble and resolve phases run fused, strip by strip (so each strip's samples
/// stay in cache); their wall time is split between them by their shares of CPU time.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct FrameTimings {
    /// Validation, tessellation, triangle setup and binning.
    pub setup_s: f64,
    /// Rendering the dynamic cube maps (zero in the other reflection modes).
    pub cube_maps_s: f64,
    /// Environment, ground and opaque objects of the main view.
    pub opaque_s: f64,
    /// The bubble blend pass.
    pub bubbles_s: f64,
    /// Averaging the samples of each pixel.
    pub resolve_s: f64,
}

impl FrameTimings {
    /// Sum of all phases.
    pub fn total_s(&self) -> f64 {
        self.setup_s + self.cube_maps_s + self.opaque_s + self.bubbles_s + self.resolve_s
    }
}

/// A rendered image: linear HDR RGB radiance, row-major, row 0 at the top.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Frame {
    width: usize,
    height: usize,
    rgb: Vec<[f32; 3]>,
    /// How long each phase took.
    pub timings: FrameTimings,
}

impl Frame {
    /// A frame holding `rgb` (row-major, row 0 at the top), or `None` unless
    /// `rgb.len() == width * height` with both sides non-zero.
    ///
    /// # Guarantees
    /// The returned frame's pixel count matches its size; its timings are zero.
    pub fn try_from_rgb(width: usize, height: usize, rgb: Vec<[f32; 3]>) -> Option<Frame> {
        let matches = width > 0 && height > 0 && width.checked_mul(height) == Some(rgb.len());
        matches.then(|| Frame {
            width,
            height,
            rgb,
            timings: FrameTimings::default(),
        })
    }

    /// Resizes the frame to `width × height` pixels, keeping its allocation, and returns
    /// its pixels (row-major) for a renderer to overwrite; the old contents are unspecified.
    pub fn resize_pixels(&mut self, width: usize, height: usize) -> &mut [[f32; 3]] {
        self.width = width;
        self.height = height;
        self.rgb.resize(width * height, [0.0; 3]);
        &mut self.rgb
    }

    /// Width in pixels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// Linear HDR pixels, row-major.
    pub fn rgb(&self) -> &[[f32; 3]] {
        &self.rgb
    }

    /// The pixel at column `x`, row `y`.
    ///
    /// # Panics
    /// Panics if `x >= width` or `y >= height`.
    pub fn pixel(&self, x: usize, y: usize) -> [f32; 3] {
        assert!(
            x < self.width && y < self.height,
            "pixel ({x}, {y}) out of range"
        );
        self.rgb[y * self.width + x]
    }

    /// Tone-mapped 8-bit sRGB, interleaved RGB, row-major.
    pub fn to_srgb8(&self, exposure_ev: f32, tonemap: ToneMap) -> Vec<u8> {
        let scale = exposure_ev.exp2();
        let mut out = vec![[0; 3]; self.rgb.len()];
        Srgb8Encoder::get().encode_pixels(&mut out, &self.rgb, scale, tonemap, |px| px);
        out.into_flattened()
    }

    /// Writes the tone-mapped image as an 8-bit sRGB PNG (temporary file, then rename).
    pub fn write_png(
        &self,
        path: impl AsRef<Path>,
        exposure_ev: f32,
        tonemap: ToneMap,
    ) -> Result<(), RenderError> {
        let bytes = self.to_srgb8(exposure_ev, tonemap);
        let (w, h) = (self.width as u32, self.height as u32);
        write_atomically(path.as_ref(), |file| {
            let encoder = image::codecs::png::PngEncoder::new(BufWriter::new(file));
            image::ImageEncoder::write_image(encoder, &bytes, w, h, image::ExtendedColorType::Rgb8)
                .map_err(|e| e.to_string())
        })
    }

    /// Writes the linear HDR radiance as a 32-bit float EXR (temporary file, then rename).
    pub fn write_exr(&self, path: impl AsRef<Path>) -> Result<(), RenderError> {
        let floats: Vec<f32> = self.rgb.iter().flatten().copied().collect();
        let (w, h) = (self.width as u32, self.height as u32);
        write_atomically(path.as_ref(), |file| {
            let mut writer = BufWriter::new(file);
            let encoder = image::codecs::openexr::OpenExrEncoder::new(&mut writer);
            image::ImageEncoder::write_image(
                encoder,
                &bytemuck_f32(&floats),
                w,
                h,
                image::ExtendedColorType::Rgb32F,
            )
            .map_err(|e| e.to_string())?;
            writer.flush().map_err(|e| e.to_string())
        })
    }
}

/// The f32 samples as native-endian bytes, as `image` expects for float formats.
fn bytemuck_f32(floats: &[f32]) -> Vec<u8> {
    floats.iter().flat_map(|f| f.to_ne_bytes()).collect()
}

/// Writes through a temporary file in the target's directory, renamed over the target only on success.
fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut std::fs::File) -> Result<(), String>,
) -> Result<(), RenderError> {
    let err = |message: String| RenderError::Write {
        path: path.to_path_buf(),
        message,
    };
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let mut builder = tempfile::Builder::new();
    builder.prefix(".raster-").suffix(".tmp");
    // Temporary files are private (0600); the finished image should be readable like any other.
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o644));
    let mut tmp = builder.tempfile_in(dir).map_err(|e| err(e.to_string()))?;
    write(tmp.as_file_mut()).map_err(err)?;
    tmp.as_file_mut()
        .sync_all()
        .map_err(|e| err(e.to_string()))?;
    tmp.persist(path).map_err(|e| err(e.error.to_string()))?;
    Ok(())
}

/// Applies the tone curve to linear RGB, giving display-linear values in `[0, 1]`.
pub fn tone_map(rgb: [f32; 3], tonemap: ToneMap) -> [f32; 3] {
    tone_map_lanes(rgb.map(|c| [c]), tonemap).map(|[c]| c)
}

/// [`tone_map`] of `N` pixels at once, channel-major (`rgb[channel][pixel]`). Every lane
/// goes through the same operations in the same order as [`tone_map`] (which is this
/// with one lane), so the results are identical; the layout lets the compiler run the
/// lanes side by side in SIMD registers.
#[inline]
pub fn tone_map_lanes<const N: usize>(mut rgb: [[f32; N]; 3], tonemap: ToneMap) -> [[f32; N]; 3] {
    // By comparison, not `f32::max`: the sign of max(−0, 0) is unspecified, and release
    // builds gave −0.0 one pixel at a time and +0.0 in SIMD lanes. NaN and −0.0 give +0.0.
    for_lanes(&mut rgb, |c| if c > 0.0 { c } else { 0.0 });
    match tonemap {
        ToneMap::Clamp => for_lanes(&mut rgb, |c| c.min(1.0)),
        ToneMap::Reinhard => for_lanes(
            &mut rgb,
            |c| if c.is_infinite() { 1.0 } else { c / (1.0 + c) },
        ),
        ToneMap::AcesFitted => rgb = aces_fitted(rgb),
    }
    rgb
}

/// Applies `f` to every lane of every channel. Plain loops: `array::map` here was left as
/// calls through `try_map`, not vectorised.
#[inline(always)]
fn for_lanes<const N: usize>(rgb: &mut [[f32; N]; 3], f: impl Fn(f32) -> f32) {
    for channel in rgb.iter_mut() {
        for c in channel.iter_mut() {
            *c = f(*c);
        }
    }
}

/// sRGB → ACES AP1-ish input matrix of Stephen Hill's fit (shared with the wgpu backend).
pub const ACES_FROM_SRGB: [[f32; 3]; 3] = [
    [0.59719, 0.35458, 0.04823],
    [0.07600, 0.90834, 0.01566],
    [0.02840, 0.13383, 0.83777],
];
/// Its output matrix back to linear sRGB.
pub const SRGB_FROM_ACES: [[f32; 3]; 3] = [
    [1.60475, -0.53108, -0.07367],
    [-0.10208, 1.10813, -0.00605],
    [-0.00327, -0.07276, 1.07602],
];
/// RRT+ODT rational fit `(x (x + a0) − a1) / (x (b0 x + b1) + b2)`: `[a0, a1]`.
pub const ACES_NUMERATOR: [f32; 2] = [0.024_578_6, 0.000_090_537];
/// Its denominator's `[b0, b1, b2]`.
pub const ACES_DENOMINATOR: [f32; 3] = [0.983_729, 0.432_951, 0.238_081];
/// Inputs are clamped here first, so the rational fit never sees infinity.
pub const ACES_INPUT_MAX: f32 = 1e6;
/// sRGB encoding (IEC 61966-2-1): below this linear value the curve is linear...
pub const SRGB_LINEAR_MAX: f32 = 0.003_130_8;
/// ...with this slope; above it `scale · c^(1/gamma) − offset`.
pub const SRGB_LINEAR_SLOPE: f32 = 12.92;
/// The encoding's power-law scale.
pub const SRGB_SCALE: f32 = 1.055;
/// The encoding's power-law offset.
pub const SRGB_OFFSET: f32 = 0.055;
/// The encoding's gamma.
pub const SRGB_GAMMA: f32 = 2.4;

/// Stephen Hill's ACES fit: sRGB → ACES AP1-ish input matrix, RRT+ODT rational fit, back.
#[inline(always)]
fn aces_fitted<const N: usize>(mut rgb: [[f32; N]; 3]) -> [[f32; N]; 3] {
    let [a0, a1] = ACES_NUMERATOR;
    let [b0, b1, b2] = ACES_DENOMINATOR;
    for_lanes(&mut rgb, |c| c.min(ACES_INPUT_MAX));
    let mut v = mat3_mul(&ACES_FROM_SRGB, &rgb);
    for_lanes(&mut v, |x| {
        let a = x * (x + a0) - a1;
        let b = x * (b0 * x + b1) + b2;
        a / b
    });
    let mut out = mat3_mul(&SRGB_FROM_ACES, &v);
    for_lanes(&mut out, |c| c.clamp(0.0, 1.0));
    out
}

/// `m` times each lane's RGB vector.
#[inline(always)]
fn mat3_mul<const N: usize>(m: &[[f32; 3]; 3], v: &[[f32; N]; 3]) -> [[f32; N]; 3] {
    let mut out = [[0.0; N]; 3];
    for (row, channel) in m.iter().zip(&mut out) {
        for (l, c) in channel.iter_mut().enumerate() {
            *c = row[0] * v[0][l] + row[1] * v[1][l] + row[2] * v[2][l];
        }
    }
    out
}

/// The sRGB encoding curve (IEC 61966-2-1) for one channel in `[0, 1]`.
pub fn linear_to_srgb(c: f32) -> f32 {
    let c = c.clamp(0.0, 1.0);
    if c <= SRGB_LINEAR_MAX {
        c * SRGB_LINEAR_SLOPE
    } else {
        SRGB_SCALE * c.powf(1.0 / SRGB_GAMMA) - SRGB_OFFSET
    }
}

/// The 8-bit code of [`linear_to_srgb`]: `(linear_to_srgb(c) * 255.0 + 0.5) as u8`, the
/// one quantisation every 8-bit output uses ([`Srgb8Encoder`] is its fast, identical form).
pub fn linear_to_srgb8_reference(c: f32) -> u8 {
    (linear_to_srgb(c) * 255.0 + 0.5) as u8
}

/// Pixels [`Srgb8Encoder::encode_pixels`] tone-maps together: two SSE registers a channel.
pub const TONE_MAP_LANES: usize = 8;

/// The bits of 1.0. A non-negative f32's bits order like its value, so `[+0, 1]` is the
/// bit range `[0, ONE_BITS]`.
const ONE_BITS: u32 = 0x3F80_0000;
/// A bucket is `bits >> SRGB8_BUCKET_SHIFT`: 128 buckets per octave, each narrower than
/// the gap between two neighbouring codes' thresholds (checked when the table is built),
/// so within a bucket the code rises by at most one.
const SRGB8_BUCKET_SHIFT: u32 = 16;
/// Buckets in the table: a power of two above `ONE_BITS >> SRGB8_BUCKET_SHIFT`, so a
/// masked index needs no bounds check.
const SRGB8_BUCKETS: usize = 1 << 14;

/// [`linear_to_srgb8_reference`] without `powf`: a table lookup and one comparison,
/// bit-identical for every f32 input (NaN, negatives and values above 1 included).
///
/// The tables are found from [`linear_to_srgb8_reference`] itself (bisection over f32 bit
/// patterns for the 255 thresholds where the code steps up), so the curve keeps one
/// definition; identity relies on that function being monotone in its input, which the
/// exhaustive test `srgb8_matches_the_reference_for_every_f32` checks.
#[derive(Debug, Clone)]
pub struct Srgb8Encoder {
    /// `next_bits[k]`: the smallest f32 bits whose code exceeds `k` (`u32::MAX` for 255).
    next_bits: [u32; 256],
    /// The code at the first bits of each bucket.
    bucket_code: [u8; SRGB8_BUCKETS],
}

static SRGB8: std::sync::LazyLock<Srgb8Encoder> = std::sync::LazyLock::new(Srgb8Encoder::build);

impl Srgb8Encoder {
    /// The process's encoder, built on first use (about 8000 calls of `powf`).
    pub fn get() -> &'static Srgb8Encoder {
        &SRGB8
    }

    /// The 8-bit sRGB code of linear `c`, equal to [`linear_to_srgb8_reference`]`(c)`.
    #[inline]
    pub fn encode(&self, c: f32) -> u8 {
        let bits = c.to_bits();
        // Negatives and NaN fold to code 0 and everything from 1 up to 255, as the
        // reference's clamp (NaN stays NaN there and casts to 0) does.
        let bits = if bits < ONE_BITS {
            bits
        } else if c >= 1.0 {
            ONE_BITS
        } else {
            0
        };
        let code = self.bucket_code[(bits >> SRGB8_BUCKET_SHIFT) as usize & (SRGB8_BUCKETS - 1)];
        code + u8::from(bits >= self.next_bits[usize::from(code)])
    }

    /// One pixel's tone-mapped 8-bit sRGB: linear `rgb` times `exposure_scale`, through
    /// [`tone_map`], encoded.
    #[inline]
    pub fn pixel(&self, rgb: [f32; 3], exposure_scale: f32, tonemap: ToneMap) -> [u8; 3] {
        tone_map(rgb.map(|c| c * exposure_scale), tonemap).map(|c| self.encode(c))
    }

    /// Tone-maps and encodes `rgb` (linear, times `exposure_scale`) into `out`, pixel for
    /// pixel up to the shorter slice, `pack` making each output element from a pixel's
    /// three codes. [`Srgb8Encoder::pixel`] for each pixel, [`TONE_MAP_LANES`] at a time.
    #[inline]
    pub fn encode_pixels<T>(
        &self,
        out: &mut [T],
        rgb: &[[f32; 3]],
        exposure_scale: f32,
        tonemap: ToneMap,
        pack: impl Fn([u8; 3]) -> T,
    ) {
        let mut out_chunks = out.chunks_exact_mut(TONE_MAP_LANES);
        let mut rgb_chunks = rgb.chunks_exact(TONE_MAP_LANES);
        for (slots, pixels) in (&mut out_chunks).zip(&mut rgb_chunks) {
            let mut lanes = [[0.0; TONE_MAP_LANES]; 3];
            for (l, px) in pixels.iter().enumerate() {
                for (channel, c) in lanes.iter_mut().zip(px) {
                    channel[l] = c * exposure_scale;
                }
            }
            let [r, g, b] = tone_map_lanes(lanes, tonemap);
            for (l, slot) in slots.iter_mut().enumerate() {
                *slot = pack([r[l], g[l], b[l]].map(|c| self.encode(c)));
            }
        }
        let rest = out_chunks.into_remainder().iter_mut();
        for (slot, &px) in rest.zip(rgb_chunks.remainder()) {
            *slot = pack(self.pixel(px, exposure_scale, tonemap));
        }
    }

    /// The thresholds' bits, lowest first: `thresholds()[k]` is the first f32 (as bits)
    /// whose code is `k + 1`.
    pub fn thresholds(&self) -> &[u32] {
        &self.next_bits[..255]
    }

    fn build() -> Srgb8Encoder {
        let mut next_bits = [u32::MAX; 256];
        for (k, bits) in next_bits.iter_mut().take(255).enumerate() {
            *bits = first_bits_reaching(k as u8 + 1);
        }
        let mut bucket_code = [u8::MAX; SRGB8_BUCKETS];
        let mut code = 0;
        for (i, slot) in bucket_code.iter_mut().enumerate() {
            let first = (i as u32) << SRGB8_BUCKET_SHIFT;
            while first >= next_bits[code] {
                code += 1;
            }
            *slot = code as u8;
            let last = first | ((1 << SRGB8_BUCKET_SHIFT) - 1);
            assert!(
                next_bits.get(code + 1).is_none_or(|&b| last < b),
                "two sRGB thresholds in one bucket: narrow SRGB8_BUCKET_SHIFT"
            );
        }
        Srgb8Encoder {
            next_bits,
            bucket_code,
        }
    }
}

/// The smallest f32 bits in `[0, ONE_BITS]` whose code is at least `code` (≥ 1): bisection,
/// exact while the reference is monotone.
fn first_bits_reaching(code: u8) -> u32 {
    let (mut below, mut reached) = (0u32, ONE_BITS);
    while reached - below > 1 {
        let mid = below + (reached - below) / 2;
        if linear_to_srgb8_reference(f32::from_bits(mid)) >= code {
            reached = mid;
        } else {
            below = mid;
        }
    }
    reached
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::texture::srgb_to_linear;

    fn frame(rgb: Vec<[f32; 3]>, width: usize) -> Frame {
        Frame {
            width,
            height: rgb.len() / width,
            rgb,
            timings: FrameTimings::default(),
        }
    }

    #[test]
    fn srgb_curves_invert_each_other() {
        for k in 0..=100 {
            let x = k as f32 / 100.0;
            let back = srgb_to_linear(linear_to_srgb(x));
            assert!((back - x).abs() < 1e-5, "{x}: off by {}", back - x);
        }
    }

    #[test]
    fn tone_maps_are_monotone_bounded_and_nan_free() {
        for tm in [ToneMap::Clamp, ToneMap::Reinhard, ToneMap::AcesFitted] {
            let mut prev = -1.0;
            for k in 0..200 {
                let x = (k as f32 * 0.1).exp2() * 1e-4;
                let y = tone_map([x; 3], tm)[1];
                assert!(
                    (0.0..=1.0).contains(&y) && y >= prev,
                    "{tm:?} at {x}: {y} after {prev}"
                );
                prev = y;
            }
            for bad in [f32::NAN, f32::INFINITY, -1.0] {
                assert!(
                    tone_map([bad; 3], tm)
                        .iter()
                        .all(|c| (0.0..=1.0).contains(c)),
                    "{tm:?} {bad}"
                );
            }
        }
        // Reinhard of 1 is exactly one half.
        assert_eq!(tone_map([1.0; 3], ToneMap::Reinhard), [0.5; 3]);
    }

    /// Where `encoder` and the reference disagree within `reach` bits of a threshold (or
    /// the thresholds are not where the reference steps), the first such input's bits.
    fn srgb8_misses_near_thresholds(encoder: &Srgb8Encoder, reach: u32) -> Option<u32> {
        let mut last = 0;
        for (k, &t) in encoder.thresholds().iter().enumerate() {
            let steps_here = linear_to_srgb8_reference(f32::from_bits(t)) == k as u8 + 1
                && linear_to_srgb8_reference(f32::from_bits(t - 1)) == k as u8;
            if !steps_here || t <= last {
                return Some(t);
            }
            last = t;
            let near = t.saturating_sub(reach)..=t.saturating_add(reach);
            if let Some(bits) = near.into_iter().find(|&b| {
                let c = f32::from_bits(b);
                encoder.encode(c) != linear_to_srgb8_reference(c)
            }) {
                return Some(bits);
            }
        }
        None
    }

    fn srgb8_agrees(encoder: &Srgb8Encoder, bits: u32) -> bool {
        let c = f32::from_bits(bits);
        encoder.encode(c) == linear_to_srgb8_reference(c)
    }

    #[test]
    fn srgb8_matches_the_reference_around_every_threshold() {
        let encoder = Srgb8Encoder::get();
        assert_eq!(srgb8_misses_near_thresholds(encoder, 64), None);
        // A threshold moved by one bit either way is caught: the check can fail.
        for (k, shift) in [(0, 1i64), (100, 1), (100, -1), (254, -1)] {
            let mut wrong = encoder.clone();
            wrong.next_bits[k] = (i64::from(wrong.next_bits[k]) + shift) as u32;
            assert!(
                srgb8_misses_near_thresholds(&wrong, 4).is_some(),
                "threshold {k} moved by {shift} went unnoticed"
            );
        }
    }

    #[test]
    fn srgb8_matches_the_reference_on_special_values_and_a_dense_sample() {
        let encoder = Srgb8Encoder::get();
        let special = [
            0.0,
            -0.0,
            1.0,
            -1.0,
            f32::MIN_POSITIVE,
            f32::EPSILON,
            1.0 - f32::EPSILON / 2.0,
            1.0 + f32::EPSILON,
            f32::MAX,
            f32::MIN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            -f32::NAN,
            SRGB_LINEAR_MAX,
        ];
        for c in special
            .into_iter()
            .chain((0..=2560).map(|i| i as f32 / 2048.0))
        {
            assert!(
                srgb8_agrees(encoder, c.to_bits()),
                "{c} ({:#x})",
                c.to_bits()
            );
        }
        for bits in [1, 0x7f80_0001, 0x7fff_ffff, 0xffc0_0000, 0x8000_0001] {
            assert!(srgb8_agrees(encoder, bits), "{bits:#x}");
        }
        // Every 997th bit pattern of [0, 1], then a pseudo-random sample of all 2^32.
        assert!((0..ONE_BITS).step_by(997).all(|b| srgb8_agrees(encoder, b)));
        let mut x = 0x9e37_79b9_u32;
        for _ in 0..200_000 {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            assert!(srgb8_agrees(encoder, x), "{x:#x}");
        }
    }

    /// `tone_map` as it was written before [`tone_map_lanes`], one pixel at a time.
    fn tone_map_one_pixel(rgb: [f32; 3], tonemap: ToneMap) -> [f32; 3] {
        // NaN and everything up to zero, −0.0 included, to +0.0 (see `tone_map_lanes`).
        let rgb = rgb.map(|c| if c > 0.0 { c } else { 0.0 });
        let mat3_mul = |m: &[[f32; 3]; 3], v: [f32; 3]| {
            m.map(|row| row[0] * v[0] + row[1] * v[1] + row[2] * v[2])
        };
        let [a0, a1] = ACES_NUMERATOR;
        let [b0, b1, b2] = ACES_DENOMINATOR;
        match tonemap {
            ToneMap::Clamp => rgb.map(|c| c.min(1.0)),
            ToneMap::Reinhard => rgb.map(|c| if c.is_infinite() { 1.0 } else { c / (1.0 + c) }),
            ToneMap::AcesFitted => {
                let v = mat3_mul(&ACES_FROM_SRGB, rgb.map(|c| c.min(ACES_INPUT_MAX)));
                let v = v.map(|x| (x * (x + a0) - a1) / (x * (b0 * x + b1) + b2));
                mat3_mul(&SRGB_FROM_ACES, v).map(|c| c.clamp(0.0, 1.0))
            }
        }
    }

    #[test]
    fn negative_zero_tone_maps_to_positive_zero_alone_and_in_lanes() {
        // Release builds once gave −0.0 one pixel at a time and +0.0 in lanes (`f32::max`
        // leaves the sign of a zero unspecified).
        for tonemap in [ToneMap::Clamp, ToneMap::Reinhard, ToneMap::AcesFitted] {
            let alone = tone_map([-0.0, f32::NAN, -3.0], tonemap);
            assert_eq!(
                alone.map(f32::to_bits),
                [0; 3],
                "{tonemap:?} alone: {alone:?}"
            );
            let lanes = tone_map_lanes([[-0.0f32; TONE_MAP_LANES]; 3], tonemap);
            assert!(
                lanes.iter().flatten().all(|c| c.to_bits() == 0),
                "{tonemap:?} lanes: {lanes:?}"
            );
        }
    }

    #[test]
    fn eight_lanes_tone_map_and_encode_as_one_pixel_at_a_time() {
        let odd = [
            f32::NAN,
            -f32::NAN,
            f32::INFINITY,
            -1.0,
            1e30,
            1e-40,
            -0.0,
            0.5,
        ];
        let mut x = 0x2545_f491_u32;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            // Mostly [0, 4), some of the odd values.
            if x % 29 == 0 {
                odd[(x >> 8) as usize % odd.len()]
            } else {
                (x >> 8) as f32 / (1u32 << 22) as f32
            }
        };
        let rgb: Vec<[f32; 3]> = (0..20_003).map(|_| [next(), next(), next()]).collect();
        let encoder = Srgb8Encoder::get();
        for tonemap in [ToneMap::Clamp, ToneMap::Reinhard, ToneMap::AcesFitted] {
            let mut lanes = vec![[0; 3]; rgb.len()];
            encoder.encode_pixels(&mut lanes, &rgb, 1.7, tonemap, |px| px);
            for (i, (&px, got)) in rgb.iter().zip(&lanes).enumerate() {
                let one =
                    tone_map_one_pixel(px.map(|c| c * 1.7), tonemap).map(linear_to_srgb8_reference);
                assert_eq!(*got, one, "{tonemap:?} pixel {i} {px:?}");
            }
            for chunk in rgb.chunks_exact(TONE_MAP_LANES).take(500) {
                let lanes = std::array::from_fn(|ch| std::array::from_fn(|l| chunk[l][ch]));
                let mapped: [[f32; TONE_MAP_LANES]; 3] = tone_map_lanes(lanes, tonemap);
                for (l, &px) in chunk.iter().enumerate() {
                    let one = tone_map_one_pixel(px, tonemap).map(f32::to_bits);
                    assert_eq!(tone_map(px, tonemap).map(f32::to_bits), one, "{px:?}");
                    assert_eq!(mapped.map(|ch| ch[l].to_bits()), one, "{tonemap:?} {px:?}");
                }
            }
        }
    }

    /// Every one of the 2^32 f32 bit patterns (about 1.07e9 of them in [0, 1]):
    /// `cargo test --release -p render-scene srgb8 -- --ignored` (17 s on the 2-core machine).
    #[test]
    #[ignore = "exhaustive: 2^32 inputs, run in release"]
    fn srgb8_matches_the_reference_for_every_f32() {
        let encoder = Srgb8Encoder::get();
        let threads = std::thread::available_parallelism().map_or(1, |n| n.get()) as u64;
        let chunk = (1u64 << 32).div_ceil(threads);
        let misses: u64 = std::thread::scope(|scope| {
            let handles: Vec<_> = (0..threads)
                .map(|t| {
                    let range = t * chunk..((t + 1) * chunk).min(1 << 32);
                    scope.spawn(move || {
                        range
                            .filter(|&b| !srgb8_agrees(encoder, b as u32))
                            .inspect(|b| eprintln!("mismatch at {b:#x}"))
                            .count() as u64
                    })
                })
                .collect();
            handles.into_iter().map(|h| h.join().unwrap()).sum()
        });
        assert_eq!(misses, 0);
    }

    #[test]
    fn frame_from_rgb_checks_its_size() {
        assert!(Frame::try_from_rgb(2, 2, vec![[0.0; 3]; 3]).is_none());
        assert!(Frame::try_from_rgb(0, 0, Vec::new()).is_none());
        assert_eq!(
            Frame::try_from_rgb(2, 1, vec![[0.0; 3]; 2])
                .unwrap()
                .width(),
            2
        );
    }

    #[test]
    fn exposure_doubles_per_stop() {
        let f = frame(vec![[0.1, 0.2, 0.05]], 1);
        let a = f.to_srgb8(1.0, ToneMap::Clamp);
        let b = frame(vec![[0.2, 0.4, 0.1]], 1).to_srgb8(0.0, ToneMap::Clamp);
        assert_eq!(a, b);
    }

    #[test]
    fn png_and_exr_round_trip_and_errors_name_the_path() {
        let dir = tempfile::tempdir().unwrap();
        let f = frame(vec![[0.0, 0.5, 1.0], [2.0, 0.25, 0.125]], 2);
        let png = dir.path().join("out.png");
        f.write_png(&png, 0.0, ToneMap::Clamp).unwrap();
        let img = image::open(&png).unwrap().to_rgb8();
        assert_eq!(img.as_raw(), &f.to_srgb8(0.0, ToneMap::Clamp));
        let exr = dir.path().join("out.exr");
        f.write_exr(&exr).unwrap();
        let back = image::open(&exr).unwrap().to_rgb32f();
        let flat: Vec<f32> = f.rgb.iter().flatten().copied().collect();
        assert_eq!(back.as_raw(), &flat);
        let leftovers: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(leftovers.len(), 2, "temporary files left: {leftovers:?}");
        let bad = dir.path().join("no/such/dir/out.png");
        let msg = f
            .write_png(&bad, 0.0, ToneMap::Clamp)
            .unwrap_err()
            .to_string();
        assert!(msg.contains("no/such/dir"), "{msg}");
    }
}
