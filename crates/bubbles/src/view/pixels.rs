//! The frame on its way to the window: tone-mapped into 0RGB words and scaled to the
//! window's size, both without allocating once the buffers have grown.

use rayon::prelude::*;
use render_scene::Srgb8Encoder;

/// Pixels per rayon task when tone-mapping: a few rows, so splitting costs little (a
/// multiple of `TONE_MAP_LANES`, so no task ends in a partial group).
const TONE_MAP_PIXELS_PER_TASK: usize = 4096;
/// Rows per rayon task when upscaling.
const UPSCALE_ROWS_PER_TASK: usize = 16;

/// Tone-maps linear radiance into 0RGB words, pixel for pixel, up to the shorter of the
/// two slices.
///
/// In parallel, eight pixels' tone curves at a time, with the exact table encoder
/// ([`Srgb8Encoder`]): one `powf` per channel had made this the costliest step of a
/// 1280×720 frame. Each pixel is independent, so the result does not depend on the thread
/// count, and it equals `Frame::to_srgb8`'s.
fn tone_map_into(out: &mut [u32], rgb: &[[f32; 3]], exposure_ev: f32, tonemap: raster::ToneMap) {
    let scale = exposure_ev.exp2();
    let encoder = Srgb8Encoder::get();
    out.par_chunks_mut(TONE_MAP_PIXELS_PER_TASK)
        .zip(rgb.par_chunks(TONE_MAP_PIXELS_PER_TASK))
        .for_each(|(words, pixels)| {
            encoder.encode_pixels(words, pixels, scale, tonemap, |[r, g, b]| {
                (u32::from(r) << 16) | (u32::from(g) << 8) | u32::from(b)
            });
        });
}

/// The window's pixels from a linear frame: tone-mapped straight into the window's buffer
/// when the frame is the window's size, else into `internal` and upscaled from there.
#[derive(Debug, Default)]
pub(super) struct WindowPixels {
    internal: Vec<u32>,
    upscaler: Upscaler,
}

impl WindowPixels {
    /// Fills the `window_size` buffer `window` from the `internal_size` frame `rgb`.
    pub(super) fn fill(
        &mut self,
        window: &mut [u32],
        window_size: (usize, usize),
        rgb: &[[f32; 3]],
        internal_size: (usize, usize),
        (exposure_ev, tonemap): (f32, raster::ToneMap),
    ) {
        if internal_size == window_size {
            tone_map_into(window, rgb, exposure_ev, tonemap);
        } else {
            self.internal.resize(rgb.len(), 0);
            tone_map_into(&mut self.internal, rgb, exposure_ev, tonemap);
            self.upscaler
                .upscale(&self.internal, internal_size, window, window_size);
        }
    }
}

/// Nearest-neighbour upscaling, with each window column's source column kept between
/// frames (recomputed only when the widths change).
#[derive(Debug, Default)]
struct Upscaler {
    /// `source_column[x]`: the internal image's column shown in window column `x`.
    source_column: Vec<u32>,
    /// The (internal, window) widths `source_column` was made for.
    widths: (usize, usize),
}

impl Upscaler {
    /// Scales the `iw`×`ih` image `src` into the `w`×`h` image `dst` (rows in parallel);
    /// a plain copy when the sizes match.
    fn upscale(
        &mut self,
        src: &[u32],
        (iw, ih): (usize, usize),
        dst: &mut [u32],
        (w, h): (usize, usize),
    ) {
        if (iw, ih) == (w, h) {
            let n = (w * h).min(dst.len()).min(src.len());
            dst[..n].copy_from_slice(&src[..n]);
            return;
        }
        if self.widths != (iw, w) || self.source_column.len() != w {
            self.source_column.clear();
            self.source_column
                .extend((0..w).map(|x| (x * iw / w).min(iw - 1) as u32));
            self.widths = (iw, w);
        }
        let columns = &self.source_column;
        dst.par_chunks_exact_mut(w)
            .take(h)
            .with_min_len(UPSCALE_ROWS_PER_TASK)
            .enumerate()
            .for_each(|(y, row)| {
                let sy = (y * ih / h).min(ih - 1);
                let src_row = &src[sy * iw..(sy + 1) * iw];
                for (px, &sx) in row.iter_mut().zip(columns) {
                    *px = src_row[sx as usize];
                }
            });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The upscale as it was before the column table: every pixel's source by formula.
    fn upscale_by_formula(src: &[u32], iw: usize, ih: usize, w: usize, h: usize) -> Vec<u32> {
        let mut dst = vec![0; w * h];
        for (y, row) in dst.chunks_exact_mut(w).enumerate() {
            let sy = (y * ih / h).min(ih - 1);
            for (x, px) in row.iter_mut().enumerate() {
                *px = src[sy * iw + (x * iw / w).min(iw - 1)];
            }
        }
        dst
    }

    #[test]
    fn the_upscaler_matches_the_formula_through_size_changes() {
        let mut upscaler = Upscaler::default();
        let sizes = [
            (3, 2, 7, 5),
            (160, 120, 640, 480),
            (97, 61, 640, 480),
            (640, 480, 640, 480),
        ];
        for (iw, ih, w, h) in sizes.into_iter().chain(sizes) {
            let src: Vec<u32> = (0..(iw * ih) as u32)
                .map(|i| i.wrapping_mul(2_654_435_761))
                .collect();
            let mut dst = vec![0; w * h];
            upscaler.upscale(&src, (iw, ih), &mut dst, (w, h));
            assert_eq!(
                dst,
                upscale_by_formula(&src, iw, ih, w, h),
                "{iw}x{ih} to {w}x{h}"
            );
        }
    }

    #[test]
    fn tone_mapped_words_are_the_powf_curves_codes() {
        let rgb: Vec<[f32; 3]> = (0..10_000)
            .map(|i| [i as f32 * 1e-4, (i % 97) as f32 * 0.03, f32::NAN])
            .collect();
        for tonemap in [raster::ToneMap::AcesFitted, raster::ToneMap::Reinhard] {
            let mut words = vec![0; rgb.len()];
            tone_map_into(&mut words, &rgb, 0.5, tonemap);
            let scale = 0.5f32.exp2();
            let expected: Vec<u32> = rgb
                .iter()
                .map(|px| {
                    let [r, g, b] = render_scene::tone_map(px.map(|c| c * scale), tonemap)
                        .map(|c| u32::from(render_scene::linear_to_srgb8_reference(c)));
                    (r << 16) | (g << 8) | b
                })
                .collect();
            assert_eq!(words, expected, "{tonemap:?}");
        }
    }
}
