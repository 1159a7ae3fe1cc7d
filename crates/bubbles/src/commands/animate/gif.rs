//! A GIF preview: each frame gets its own 256-colour NeuQuant palette and Floyd–Steinberg
//! error diffusion, streamed into a temporary file renamed into place at the end. The
//! palette error is measured as CIEDE2000 against the exact frame.

use super::sink::{Rgb8, temporary_beside};
use color_quant::NeuQuant;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use thinfilm::colorspace::{XYZ_FROM_SRGB, apply, srgb_decode};
use thinfilm::{Lab, ciede2000, lab_from_xyz};

/// NeuQuant learns from every `SAMPLE_FACTOR`-th pixel (1 = all; 10 is its own default).
const SAMPLE_FACTOR: i32 = 3;
/// At most this many pixels per frame enter the ΔE mean (an even stride over the frame).
const DELTA_E_SAMPLES: usize = 40_000;

/// A GIF being written, with the running colour error of its palettes.
pub struct GifSink {
    path: PathBuf,
    tmp: tempfile::NamedTempFile,
    encoder: Option<gif::Encoder<BufWriter<File>>>,
    delay_cs: u16,
    dither: bool,
    error: DeltaE,
}

/// Running mean and maximum of CIEDE2000 between exact and palette colours.
#[derive(Debug, Default, Clone, Copy)]
pub struct DeltaE {
    sum: f64,
    count: u64,
    max: f64,
}

impl DeltaE {
    /// Mean ΔE₀₀ so far (0 before any pixel).
    pub fn mean(&self) -> f64 {
        if self.count == 0 {
            0.0
        } else {
            self.sum / self.count as f64
        }
    }

    /// Largest ΔE₀₀ so far.
    pub fn max(&self) -> f64 {
        self.max
    }

    fn add(&mut self, e: f64) {
        self.sum += e;
        self.count += 1;
        self.max = self.max.max(e);
    }
}

impl GifSink {
    /// The file this sink writes (renamed into place at the end).
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Starts `path` for frames of `width` × `height` at `fps`, looping for ever.
    ///
    /// # Errors
    /// A frame side above 65 535 (the GIF limit) or an I/O failure.
    pub fn create(
        path: &Path,
        width: usize,
        height: usize,
        fps: f64,
        dither: bool,
    ) -> Result<Self, String> {
        let side = |v: usize| {
            u16::try_from(v).map_err(|_| format!("a GIF side is at most 65535 pixels, not {v}"))
        };
        let (w, h) = (side(width)?, side(height)?);
        let tmp = temporary_beside(path)?;
        let file = tmp.reopen().map_err(|e| e.to_string())?;
        let mut encoder =
            gif::Encoder::new(BufWriter::new(file), w, h, &[]).map_err(|e| e.to_string())?;
        encoder
            .set_repeat(gif::Repeat::Infinite)
            .map_err(|e| e.to_string())?;
        Ok(Self {
            path: path.to_path_buf(),
            tmp,
            encoder: Some(encoder),
            delay_cs: (100.0 / fps).round().clamp(1.0, 65_535.0) as u16,
            dither,
            error: DeltaE::default(),
        })
    }

    /// Quantises and appends one frame.
    pub fn push(&mut self, frame: &Rgb8) -> Result<(), String> {
        let (palette, indices) = quantize(frame, self.dither);
        measure(frame, &palette, &indices, &mut self.error);
        let mut gif_frame = gif::Frame::from_palette_pixels(
            frame.width as u16,
            frame.height as u16,
            indices,
            palette,
            None,
        );
        gif_frame.delay = self.delay_cs;
        let encoder = self.encoder.as_mut().ok_or("the GIF is already finished")?;
        encoder.write_frame(&gif_frame).map_err(|e| e.to_string())
    }

    /// Writes the trailer, renames the file into place and returns the palette error.
    pub fn finish(mut self) -> Result<DeltaE, String> {
        let encoder = self.encoder.take().ok_or("the GIF is already finished")?;
        let mut writer = encoder.into_inner().map_err(|e| e.to_string())?;
        std::io::Write::flush(&mut writer).map_err(|e| e.to_string())?;
        self.tmp.as_file().sync_all().map_err(|e| e.to_string())?;
        self.tmp
            .persist(&self.path)
            .map_err(|e| e.error.to_string())?;
        Ok(self.error)
    }
}

/// A 256-colour palette (RGB triples) for `frame` and each pixel's index into it.
pub fn quantize(frame: &Rgb8, dither: bool) -> (Vec<u8>, Vec<u8>) {
    let rgba: Vec<u8> = frame
        .bytes
        .chunks_exact(3)
        .flat_map(|p| [p[0], p[1], p[2], 255])
        .collect();
    let quant = NeuQuant::new(SAMPLE_FACTOR, 256, &rgba);
    let palette = quant.color_map_rgb();
    let indices = if dither {
        diffuse(frame, &quant, &palette)
    } else {
        rgba.chunks_exact(4)
            .map(|p| quant.index_of(p) as u8)
            .collect()
    };
    (palette, indices)
}

/// Floyd–Steinberg error diffusion in 8-bit sRGB, serpentine so that no drift builds up
/// along one direction.
fn diffuse(frame: &Rgb8, quant: &NeuQuant, palette: &[u8]) -> Vec<u8> {
    let (w, h) = (frame.width, frame.height);
    let mut work: Vec<[f32; 3]> = frame
        .bytes
        .chunks_exact(3)
        .map(|p| [p[0], p[1], p[2]].map(f32::from))
        .collect();
    let mut indices = vec![0u8; w * h];
    for y in 0..h {
        let forward = y % 2 == 0;
        for i in 0..w {
            let x = if forward { i } else { w - 1 - i };
            let want = work[y * w + x].map(|c| c.clamp(0.0, 255.0));
            let probe = [want[0] as u8, want[1] as u8, want[2] as u8, 255];
            let index = quant.index_of(&probe);
            indices[y * w + x] = index as u8;
            let got = &palette[3 * index..3 * index + 3];
            let err = [0, 1, 2].map(|c| want[c] - f32::from(got[c]));
            let ahead = if forward { x + 1 } else { x.wrapping_sub(1) };
            let behind = if forward { x.wrapping_sub(1) } else { x + 1 };
            let mut spread = |xx: usize, yy: usize, weight: f32| {
                if xx < w && yy < h {
                    let px = &mut work[yy * w + xx];
                    for c in 0..3 {
                        px[c] += err[c] * weight;
                    }
                }
            };
            spread(ahead, y, 7.0 / 16.0);
            spread(behind, y + 1, 3.0 / 16.0);
            spread(x, y + 1, 5.0 / 16.0);
            spread(ahead, y + 1, 1.0 / 16.0);
        }
    }
    indices
}

/// Adds the CIEDE2000 between each sampled exact pixel and its palette colour to `error`.
fn measure(frame: &Rgb8, palette: &[u8], indices: &[u8], error: &mut DeltaE) {
    let stride = (indices.len() / DELTA_E_SAMPLES).max(1);
    for (p, &i) in frame.bytes.chunks_exact(3).zip(indices).step_by(stride) {
        let i = usize::from(i);
        let q = &palette[3 * i..3 * i + 3];
        error.add(ciede2000(lab_of_srgb8(p), lab_of_srgb8(q)));
    }
}

/// CIELAB (D65 white) of an 8-bit sRGB colour.
pub fn lab_of_srgb8(rgb: &[u8]) -> Lab {
    let linear = [0, 1, 2].map(|c| srgb_decode(f64::from(rgb[c]) / 255.0));
    let white = apply(&XYZ_FROM_SRGB, [1.0; 3]);
    lab_from_xyz(apply(&XYZ_FROM_SRGB, linear), white)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A horizontal ramp of saturated hues, like interference fringes.
    fn fringes(width: usize, height: usize) -> Rgb8 {
        let bytes = (0..height)
            .flat_map(|_| {
                (0..width).flat_map(move |x| {
                    let phase = x as f64 / width as f64 * 12.0;
                    [0.0, 2.1, 4.2].map(|o: f64| (127.5 + 127.0 * (phase + o).sin()) as u8)
                })
            })
            .collect();
        Rgb8 {
            width,
            height,
            bytes,
        }
    }

    #[test]
    fn palette_error_of_a_fringe_ramp_is_small_and_zero_for_few_colours() {
        let frame = fringes(256, 8);
        let (palette, indices) = quantize(&frame, false);
        let mut e = DeltaE::default();
        measure(&frame, &palette, &indices, &mut e);
        assert!(e.mean() < 2.0, "mean ΔE00 {:.3} on a fringe ramp", e.mean());

        let flat = Rgb8 {
            width: 64,
            height: 64,
            bytes: (0..64 * 64)
                .flat_map(|i| [(i % 4) as u8 * 60, 10, 200])
                .collect(),
        };
        let (palette, indices) = quantize(&flat, false);
        let mut e = DeltaE::default();
        measure(&flat, &palette, &indices, &mut e);
        assert!(
            e.max() < 1.0,
            "4 colours should map almost exactly: max ΔE00 {}",
            e.max()
        );
    }

    #[test]
    fn dithering_keeps_the_local_mean_colour() {
        let frame = fringes(240, 16);
        let (palette, indices) = quantize(&frame, true);
        // Over a 4×4 block the diffused error cancels: the mean palette colour stays close.
        let w = frame.width;
        let mut worst: f64 = 0.0;
        for bx in (0..w).step_by(4) {
            let mut exact = [0.0; 3];
            let mut got = [0.0; 3];
            for y in 4..8 {
                for x in bx..bx + 4 {
                    let i = usize::from(indices[y * w + x]);
                    for c in 0..3 {
                        exact[c] += f64::from(frame.bytes[3 * (y * w + x) + c]) / 16.0;
                        got[c] += f64::from(palette[3 * i + c]) / 16.0;
                    }
                }
            }
            for c in 0..3 {
                worst = worst.max((exact[c] - got[c]).abs());
            }
        }
        assert!(worst < 6.0, "a 4×4 block mean moved by {worst:.2}/255");
    }

    #[test]
    fn lab_of_white_is_l_100() {
        let lab = lab_of_srgb8(&[255, 255, 255]);
        assert!(
            (lab.l - 100.0).abs() < 1e-9 && lab.a.abs() < 1e-9 && lab.b.abs() < 1e-9,
            "{lab:?}"
        );
    }
}
